"""The benchmarks' one harness: alternatives timed alternating (in this process or each
call in a fresh one), medians and ratios, and the record every script writes.

A record is ``benchmarks/records/<script>-<date>-<tag>.json``: a header (the machine:
CPU model, cores, RAM; the load: ``os.getloadavg()`` at start and end, and the CPU time
other processes took while the script ran, with the busiest of them; the libraries:
Python, numpy, scipy, the BLAS as threadpoolctl sees it, scikit-fem and the optional
solver libraries that are installed; the git commit and whether the tree was clean; the
command line) and the script's results, written again after every case
(``Record.save``) so that an interrupted run keeps what it measured. ``--no-record``
switches it off; ``--tag`` names it (default: the script's options).

    ap = argparse.ArgumentParser(...); harness.add_arguments(ap); args = ap.parse_args()
    with harness.Record(__file__, args) as rec:
        t = harness.alternate({"a": f, "b": g}, repeat=3)    # {name: Timing}, alternating
        rec["case"] = harness.summary(t, base="a")            # medians, ratios, all times
        rec.save()                                           # after every case
    harness.fresh([sys.executable, "-c", CODE])              # last JSON line of a child
    harness.fresh_call(module_level_fn, *args)               # its return, spawned process

Plain module, no test runner; the scripts import it from their own folder.
"""
from __future__ import annotations

import argparse
import datetime as _dt
import gc
import json
import os
import platform
import re
import resource
import statistics
import subprocess
import sys
import time
from importlib import metadata
from pathlib import Path
from typing import Any, Callable, NamedTuple

ROOT = Path(__file__).resolve().parents[1]
RECORDS = ROOT / "benchmarks" / "records"

#: optional libraries named in every header when installed (distribution names)
OPTIONAL = ("scikit-umfpack", "python-mumps", "pypardiso", "petsc4py", "mkl", "threadpoolctl",
            "matplotlib", "pyamg")

#: a process counts as busy when it took more than this share of one core during the run
BUSY_SHARE = 0.05


# ------------------------------------------------------------------------------ timing
class Timing(NamedTuple):
    """One alternative: the median seconds, every round's seconds, every round's result."""
    median: float
    times: list
    results: list

    @property
    def last(self):
        return self.results[-1] if self.results else None


def median(values) -> float:
    return float(statistics.median(list(values)))


def ratios(medians: dict, base: str) -> dict:
    """Each alternative's median over ``base``'s (> 1: slower than ``base``)."""
    ref = medians[base]
    return {k: (v / ref if ref else float("nan")) for k, v in medians.items()}


def alternate(alternatives: dict[str, Callable[[], Any]], repeat: int, *,
              rotate: bool = True, collect: bool = True) -> dict[str, Timing]:
    """Run each ``name -> fn()`` in turn, ``repeat`` rounds, so that drift hits every
    alternative alike; the order rotates by one each round (``rotate``) so none is
    always first. Wall seconds of each call (``gc.collect()`` before it if ``collect``)
    and its result. A ``fn`` that runs a fresh process (:func:`fresh`,
    :func:`fresh_call`) makes every call its own process."""
    names = list(alternatives)
    times = {k: [] for k in names}
    results = {k: [] for k in names}
    for r in range(repeat):
        order = names[r % len(names):] + names[:r % len(names)] if rotate else names
        for name in order:
            if collect:
                gc.collect()
            t0 = time.perf_counter()
            out = alternatives[name]()
            times[name].append(time.perf_counter() - t0)
            results[name].append(out)
    return {k: Timing(median(times[k]) if times[k] else float("nan"), times[k], results[k])
            for k in names}


def summary(timings: dict[str, Timing], base: str | None = None) -> dict:
    """A record's entry for one case: medians, every round's times, ratios to ``base``."""
    med = {k: t.median for k, t in timings.items()}
    out = {"median_s": med, "times_s": {k: t.times for k, t in timings.items()}}
    if base is not None:
        out[f"ratio_to_{base}"] = ratios(med, base)
    return out


def fresh(cmd: list, *, env: dict | None = None, cwd=None, timeout: float | None = None,
          threads: int | None = None, check: bool = True) -> Any:
    """Run ``cmd`` in a fresh process; its last stdout line parsed as JSON (None if it
    printed nothing). ``threads``: OMP/OPENBLAS/MKL_NUM_THREADS for the child."""
    env = dict(os.environ if env is None else env)
    if threads is not None:
        for var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
            env[var] = str(threads)
    done = subprocess.run([str(c) for c in cmd], env=env, cwd=cwd, capture_output=True,
                          text=True, timeout=timeout)
    if check and done.returncode != 0:
        raise RuntimeError(f"{' '.join(map(str, cmd))[:200]} failed "
                           f"(exit {done.returncode}): {done.stderr.strip()[-2000:]}")
    lines = done.stdout.strip().splitlines()
    return json.loads(lines[-1]) if lines else None


def _call_into(queue, target, args):
    try:
        queue.put(("ok", target(*args)))
    except BaseException as exc:            # noqa: BLE001 -- reported to the parent
        queue.put(("error", f"{type(exc).__name__}: {exc}"))
        raise


def fresh_call(target: Callable, *args, timeout: float | None = None) -> Any:
    """``target(*args)`` in a fresh (spawned) process; its return value. ``target`` must
    be a module-level function of an importable module or of the running script."""
    import multiprocessing as mp
    from queue import Empty
    ctx = mp.get_context("spawn")
    queue = ctx.Queue()
    p = ctx.Process(target=_call_into, args=(queue, target, args))
    p.start()
    t0 = time.monotonic()
    while True:     # a child that dies (an exception, memory) would leave get() waiting
        try:
            status, out = queue.get(timeout=5)
            break
        except Empty:
            if not p.is_alive():
                raise RuntimeError(f"{target.__name__} died in its process "
                                   f"(exit code {p.exitcode})") from None
            if timeout is not None and time.monotonic() - t0 > timeout:
                p.kill()
                raise TimeoutError(f"{target.__name__}: over {timeout} s") from None
    p.join()
    if status == "error":
        raise RuntimeError(f"{target.__name__} failed in its process: {out}")
    return out


def peak_rss_mb() -> float:
    """This process's peak resident memory (``ru_maxrss``), MB."""
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024


# ------------------------------------------------------------------------------ header
def machine() -> dict:
    cpu = ""
    try:
        with open("/proc/cpuinfo") as fh:
            cpu = next((ln.split(":", 1)[1].strip() for ln in fh
                        if ln.startswith("model name")), "")
    except OSError:
        pass
    ram = None
    try:
        with open("/proc/meminfo") as fh:
            kb = next(int(ln.split()[1]) for ln in fh if ln.startswith("MemTotal"))
        ram = round(kb / 1024 ** 2, 2)
    except (OSError, StopIteration, ValueError):
        pass
    try:
        usable = len(os.sched_getaffinity(0))
    except AttributeError:
        usable = os.cpu_count()
    return {"cpu": cpu or platform.processor(), "cores": os.cpu_count(),
            "cores_usable": usable, "ram_gb": ram, "system": platform.platform()}


def _version(dist: str) -> str | None:
    try:
        return metadata.version(dist)
    except metadata.PackageNotFoundError:
        return None


def libraries() -> dict:
    """Python, numpy, scipy, the BLAS (threadpoolctl, if installed), scikit-fem and the
    optional libraries that are installed; the thread variables as set."""
    import numpy
    import scipy
    out = {"python": platform.python_version(), "numpy": numpy.__version__,
           "scipy": scipy.__version__, "scikit-fem": _version("scikit-fem")}
    try:
        from threadpoolctl import threadpool_info
        out["blas"] = [{k: i.get(k) for k in ("internal_api", "version", "num_threads",
                                              "threading_layer", "architecture")}
                       | {"library": os.path.basename(i.get("filepath", ""))}
                       for i in threadpool_info()]
    except ImportError:
        cfg = getattr(numpy, "show_config", None)
        out["blas"] = "threadpoolctl not installed" if cfg else None
    out["optional"] = {d: v for d in OPTIONAL if (v := _version(d))}
    out["threads_env"] = {v: os.environ[v] for v in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS",
                                                     "MKL_NUM_THREADS") if v in os.environ}
    return out


def git() -> dict:
    def run(*a):
        try:
            return subprocess.run(["git", "-C", str(ROOT), *a], capture_output=True,
                                  text=True, timeout=20).stdout.strip()
        except (OSError, subprocess.SubprocessError):
            return ""
    changed = [ln for ln in run("status", "--porcelain", "--untracked-files=no").splitlines()
               if ln.strip()]
    return {"commit": run("rev-parse", "HEAD") or None,
            "branch": run("rev-parse", "--abbrev-ref", "HEAD") or None,
            "tracked_files_changed": len(changed)}


def _cpu_jiffies() -> tuple[int, int]:
    """(busy, total) jiffies of the whole machine (/proc/stat)."""
    with open("/proc/stat") as fh:
        f = [int(x) for x in fh.readline().split()[1:]]
    idle = f[3] + (f[4] if len(f) > 4 else 0)
    return sum(f) - idle, sum(f)


def proc_stats():
    """``(pid, /proc/pid/stat text)`` of every process now readable in /proc."""
    for d in os.listdir("/proc"):
        if not d.isdigit():
            continue
        try:
            with open(f"/proc/{d}/stat") as fh:
                yield int(d), fh.read()
        except OSError:
            continue


def _processes() -> dict:
    """pid -> (command name, CPU jiffies so far) of every readable process."""
    out = {}
    for d, s in proc_stats():
        name = s[s.find("(") + 1:s.rfind(")")]
        f = s[s.rfind(")") + 2:].split()
        out[int(d)] = (name, int(f[11]) + int(f[12]))
    return out


def _own_tree() -> set:
    """This process and its descendants (by parent pid)."""
    parents = {}
    for d in os.listdir("/proc"):
        if d.isdigit():
            try:
                with open(f"/proc/{d}/stat") as fh:
                    s = fh.read()
                parents[int(d)] = int(s[s.rfind(")") + 2:].split()[1])
            except (OSError, ValueError, IndexError):
                continue
    mine = {os.getpid()}
    grew = True
    while grew:
        new = {p for p, pp in parents.items() if pp in mine} - mine
        mine |= new
        grew = bool(new)
    return mine


class Load:
    """The machine's load over a script's run: load averages at start and end, and the
    CPU time that processes other than this script (and its children) took meanwhile."""

    def __init__(self):
        self.tick = os.sysconf("SC_CLK_TCK")
        self.start = os.getloadavg()
        self.t0 = time.monotonic()
        self.own0 = self._own_cpu()
        try:
            self.jiffies0, self.procs0 = _cpu_jiffies(), _processes()
        except OSError:                      # no /proc: load averages only
            self.jiffies0 = self.procs0 = None

    @staticmethod
    def _own_cpu() -> float:
        s, c = resource.getrusage(resource.RUSAGE_SELF), resource.getrusage(resource.RUSAGE_CHILDREN)
        return s.ru_utime + s.ru_stime + c.ru_utime + c.ru_stime

    def at_start(self) -> dict:
        return {"loadavg_start": list(self.start)}

    def at_end(self) -> dict:
        wall = time.monotonic() - self.t0
        out = {"loadavg_start": list(self.start), "loadavg_end": list(os.getloadavg()),
               "wall_s": round(wall, 3)}
        if self.jiffies0 is None or wall <= 0:
            return out
        busy1, _ = _cpu_jiffies()
        own = self._own_cpu() - self.own0
        machine_cpu = (busy1 - self.jiffies0[0]) / self.tick
        others = max(machine_cpu - own, 0.0)
        procs1 = _processes()
        mine = _own_tree()
        busy = []
        for pid, (name, j1) in procs1.items():
            if pid in mine:
                continue
            j0 = self.procs0.get(pid, (name, 0))[1]
            cpu = (j1 - j0) / self.tick
            if cpu > BUSY_SHARE * wall:
                busy.append({"pid": pid, "name": name, "cpu_s": round(cpu, 2)})
        busy.sort(key=lambda b: -b["cpu_s"])
        out.update({"own_cpu_s": round(own, 2), "others_cpu_s": round(others, 2),
                    "others_cores_busy": round(others / wall, 2),
                    "others_busy": others / wall > 0.25,
                    "busy_processes": busy[:10]})
        return out


def header(load: Load | None = None) -> dict:
    return {"machine": machine(), "load": (load or Load()).at_start(),
            "libraries": libraries(), "git": git()}


# ------------------------------------------------------------------------------ record
def add_arguments(ap: argparse.ArgumentParser, *, record: bool = True) -> None:
    """``--record`` / ``--no-record`` (default: ``record``) and ``--tag``."""
    g = ap.add_argument_group("record (benchmarks/harness.py)")
    g.add_argument("--record", dest="record", action="store_true", default=record,
                   help="write benchmarks/records/<script>-<date>-<tag>.json: the machine, "
                        "its load, the libraries, the git commit and the results"
                        + (" (the default)" if record else ""))
    g.add_argument("--no-record", dest="record", action="store_false",
                   help="write no record")
    g.add_argument("--tag", default=None,
                   help="the record's tag (default: the options given, or 'default')")


def _slug(text: str, limit: int = 60) -> str:
    return re.sub(r"-+", "-", re.sub(r"[^A-Za-z0-9.=]+", "-", text)).strip("-")[:limit] or "default"


class Record:
    """One benchmark run's record; ``rec[key] = value`` adds a result and writes the file
    again (so after every case; ``save()`` writes it explicitly), leaving the ``with`` block writes it with the
    load at the end (and the error, if the script failed)."""

    def __init__(self, script: str, args: argparse.Namespace | None = None, *,
                 tag: str | None = None, enabled: bool | None = None,
                 argv: list | None = None):
        self.script = Path(script).stem
        argv = list(sys.argv[1:] if argv is None else argv)
        if enabled is None:
            enabled = getattr(args, "record", True)
        self.enabled = enabled
        tag = tag or getattr(args, "tag", None) or _slug(
            " ".join(a for a in argv if a not in ("--record", "--no-record")))
        self.started = _dt.datetime.now(_dt.timezone.utc)
        self.path = RECORDS / f"{self.script}-{self.started:%Y-%m-%d}-{_slug(tag)}.json"
        if self.enabled and self.path.exists():          # never overwrite an earlier record
            self.path = self.path.with_name(f"{self.path.stem}-{self.started:%H%M%S}.json")
        self._load = Load()
        self.doc = {"script": f"benchmarks/{self.script}.py", "argv": argv,
                    "started_utc": self.started.isoformat(timespec="seconds"),
                    **header(self._load), "results": {}}

    def __setitem__(self, key, value):
        """A result; the record is written again at once (an interrupted run keeps it)."""
        self.doc["results"][key] = value
        self.save()

    def __getitem__(self, key):
        return self.doc["results"][key]

    def update(self, values: dict) -> None:
        self.doc["results"].update(values)
        self.save()

    @property
    def results(self) -> dict:
        return self.doc["results"]

    def save(self, final: bool = False) -> Path | None:
        if final:
            self.doc["load"] = self._load.at_end()
            self.doc["finished_utc"] = _dt.datetime.now(_dt.timezone.utc).isoformat(
                timespec="seconds")
        if not self.enabled:
            return None
        RECORDS.mkdir(parents=True, exist_ok=True)
        tmp = self.path.with_suffix(".json.part")
        tmp.write_text(json.dumps(self.doc, indent=1, default=_plain) + "\n")
        tmp.replace(self.path)
        return self.path

    def __enter__(self):
        return self

    def __exit__(self, kind, exc, tb):
        if kind is not None:
            self.doc["interrupted"] = f"{kind.__name__}: {exc}"[:500]
        path = self.save(final=True)
        if path is not None and kind is None:
            shown = path.relative_to(ROOT) if path.is_relative_to(ROOT) else path
            print(f"record: {shown}", file=sys.stderr)
        return False


def _plain(obj):
    """JSON for numpy scalars and arrays, paths and tuples-as-keys' values."""
    if hasattr(obj, "tolist"):
        return obj.tolist()
    if isinstance(obj, (Path, set, frozenset)):
        return str(obj) if isinstance(obj, Path) else sorted(obj)
    return str(obj)


def write_json(path, doc) -> None:
    """A script's own ``--json FILE`` (kept beside the record)."""
    with open(path, "w") as fh:
        json.dump(doc, fh, indent=1, default=_plain)
