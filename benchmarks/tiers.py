"""The two test tiers' wall time and peak total memory, serial against parallel (issue 32:
the README's test command, the fast tier, in <= 5 min wall and <= 2.5 GB on a quiet
2-core machine from a clean clone).

Plain script (no test runner):

    python benchmarks/tiers.py [--tier fast|slow|both] [--repeat N] [--modes serial,parallel]
                               [--trace [DIR]]

Each measurement is a fresh ``python -m pytest -q`` (the fast tier) or
``python -m pytest -q --runslow -m slow`` (the slow tier) in the source tree, started
from this script: ``serial`` adds ``-p no:xdist``, ``parallel`` is the command as the
README gives it (tests/conftest.py starts a pytest-xdist worker per core). Every test
session starts with an empty FEM cache of its own (tests/conftest.py), as on a clean
clone. The modes alternate within each round (their order swapped every other round,
so neither always runs after the other), ``--repeat`` rounds (default 1); medians.

Memory: every 0.2 s the script reads /proc for the pytest process and all its
descendants (xdist's workers, the reports' worker pools, the subprocesses the tests
start) and sums their resident set (RSS) and their proportional set (PSS, from
``smaps_rollup``: pages shared among the processes, such as a forked pool's
copy-on-write pages, counted once in all; read every fifth sample, every 1 s, as
walking the pages costs the sampler CPU time). The peak of each sum over the run is
printed; the RSS sum counts a shared page once per process, so it is the upper bound,
the PSS sum the memory the tree held. ``/usr/bin/time`` gives the largest single
process only (printed too, as ``largest process``).

CPU: the user and system time of the pytest process and every descendant it waited
for (``RUSAGE_CHILDREN``), steadier than the wall time on a loaded machine: on 2 quiet
cores the parallel wall time is about half of it, or the longest file if that is more.

``--trace``: what made the peak. Each test process then logs its tests' starts and ends
(tests/conftest.py, ``PDVERIFY_TEST_TRACE``), and the script prints, for the sample with
the largest PSS sum, each process's PSS and RSS, the test process it runs under (an xdist
worker or the pytest process itself: forked pools and subprocesses are counted with the
test that started them), the test that worker was running and the files it had run
before (whose freed memory it may still hold), and then the tests whose process reached
the largest resident set while running them (each test's own peak, its setup and
teardown included: Linux's VmHWM, reset as it starts; the processes it starts not
counted), with the process's resident set as the test started (what earlier tests left).
``--trace DIR`` keeps the logs, one file per test process, a line
``start|end TIME RSS PEAK NODEID`` per test: the RSS at a file's last ``end`` against its
first ``start`` is what the file left resident.

The machine is shared: the load average is printed before and after each run.
"""
from __future__ import annotations

import argparse
import os
import resource
import subprocess
import sys
import tempfile
import threading
import time

import harness

HERE = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
PAGE = os.sysconf("SC_PAGE_SIZE")
TIERS = {"fast": ["-q"], "slow": ["-q", "--runslow", "-m", "slow"]}
MODES = {"serial": ["-p", "no:xdist"], "parallel": []}


def _children_map():
    """{parent pid: [child pids]} over every process now visible in /proc."""
    kids = {}
    for pid, stat in harness.proc_stats():
        # the command name (field 2) may hold spaces: the fields after its ')' are plain
        ppid = int(stat.rsplit(")", 1)[1].split()[1])
        kids.setdefault(ppid, []).append(pid)
    return kids


def _tree(pid, parents=None):
    """The pids of ``pid`` and all its descendants; ``parents`` (a dict), if given,
    receives each one's parent."""
    kids, todo, seen = _children_map(), [pid], []
    while todo:
        p = todo.pop()
        seen.append(p)
        for c in kids.get(p, ()):
            todo.append(c)
            if parents is not None:
                parents[c] = p
    return seen


def _rss_pss(pid, pss_too=True):
    """(RSS, PSS) of one process in bytes; (0, 0) once it has gone; PSS 0 unless
    ``pss_too`` (``smaps_rollup`` costs the kernel a walk of the process's pages)."""
    try:
        with open(f"/proc/{pid}/statm") as fh:
            rss = int(fh.read().split()[1]) * PAGE
        pss = 0
        if not pss_too:
            return rss, pss
        with open(f"/proc/{pid}/smaps_rollup") as fh:
            for line in fh:
                if line.startswith("Pss:"):
                    pss = int(line.split()[1]) * 1024
                    break
        return rss, pss
    except (OSError, ValueError, IndexError):
        return 0, 0


def _cmd(pid):
    try:
        with open(f"/proc/{pid}/cmdline", "rb") as fh:
            return fh.read().replace(b"\0", b" ").decode(errors="replace")[:90]
    except OSError:
        return "?"


class Sampler(threading.Thread):
    """Samples the process tree under ``pid`` every ``interval`` seconds until stopped."""

    def __init__(self, pid, interval=0.2):
        super().__init__(daemon=True)
        self.pid, self.interval = pid, interval
        self.peak_rss = self.peak_pss = self.peak_one = 0
        self.peak_procs = 0
        self.at_peak = []
        self.at_pss_peak = (0.0, [])   # (monotonic time, [(pid, parent, rss, pss, cmd)])
        self.samples = 0
        self._done = threading.Event()

    def run(self):
        while not self._done.is_set():
            parents = {}
            pids = _tree(self.pid, parents)
            sizes = [_rss_pss(p, self.samples % 5 == 0) for p in pids]
            if sum(r for r, _ in sizes) > self.peak_rss:
                self.at_peak = sorted(((r, _cmd(p)) for p, (r, _) in zip(pids, sizes)),
                                      reverse=True)
            if sum(p for _, p in sizes) > self.peak_pss:
                self.at_pss_peak = (time.monotonic(),
                                    [(p, parents.get(p), r, s, _cmd(p))
                                     for p, (r, s) in zip(pids, sizes)])
            self.peak_rss = max(self.peak_rss, sum(r for r, _ in sizes))
            self.peak_pss = max(self.peak_pss, sum(p for _, p in sizes))
            self.peak_one = max([self.peak_one] + [r for r, _ in sizes])
            self.peak_procs = max(self.peak_procs, len(sizes))
            self.samples += 1
            self._done.wait(self.interval)

    def stop(self):
        self._done.set()
        self.join()


def _read_trace(folder):
    """{pid: [(kind, time, rss, peak, nodeid)]} from the test processes' logs
    (tests/conftest.py)."""
    logs = {}
    for name in os.listdir(folder):
        with open(os.path.join(folder, name)) as fh:
            logs[int(name.split(".")[0])] = [
                (kind, float(t), int(rss), int(peak), node) for kind, t, rss, peak, node in
                (line.rstrip("\n").split(" ", 4) for line in fh)]
    return logs


#: how many tests :func:`_largest_tests` lists
LARGEST_TESTS = 15


def _largest_tests(logs):
    """Lines naming the tests whose process reached the largest resident set while it ran
    them (setup and teardown included; the processes they start not counted), largest
    first, each with the process's resident set at the test's start."""
    ends = sorted(((peak, node, pid) for pid, events in logs.items()
                   for kind, _, _, peak, node in events if kind == "end"), reverse=True)
    starts = {(pid, node): rss for pid, events in logs.items()
              for kind, _, rss, _, node in events if kind == "start"}
    out = [f"    the {LARGEST_TESTS} tests with the largest peak resident set of their process:"]
    for peak, node, pid in ends[:LARGEST_TESTS]:
        out.append(f"      {peak / 1e9:5.2f} GB (from {starts.get((pid, node), 0) / 1e9:4.2f})"
                   f"  {node}")
    return out


def _at_peak_trace(root, when, procs, logs):
    """Lines naming, for each process at the PSS peak, its size, the test process it runs
    under (the pytest process or an xdist worker: the child of ``root``) and the test
    that process was running at ``when``, with the test files it had run before."""
    parent = {pid: ppid for pid, ppid, *_ in procs}

    def test_process(pid):
        while pid != root and parent.get(pid) not in (root, None):
            pid = parent[pid]
        return pid

    out = [f"    at the PSS peak ({sum(p[3] for p in procs) / 1e9:.2f} GB):"]
    for pid, ppid, rss, pss, cmd in sorted(procs, key=lambda x: -x[3]):
        owner = test_process(pid)
        events = [e for e in logs.get(owner, []) if e[1] <= when]
        now = events[-1][4] if events and events[-1][0] == "start" else \
            (f"between tests, after {events[-1][4]}" if events else "before its first test")
        out.append(f"      pid {pid:7d} (under {owner:7d})  PSS {pss / 1e9:5.2f} GB  "
                   f"RSS {rss / 1e9:5.2f} GB  {cmd[:60]}")
        if pid == owner and owner != root:
            files = []
            for kind, _, _, _, node in events:
                f = node.split("::")[0]
                if kind == "start" and f not in files:
                    files.append(f)
            out.append(f"          running: {now}")
            out.append(f"          its files so far: {', '.join(files)}")
    return out


def measure(tier, mode, trace=False):
    cmd = [sys.executable, "-m", "pytest", *TIERS[tier], *MODES[mode]]
    env = dict(os.environ, PYTHONPATH=HERE)
    keep = isinstance(trace, str) and trace != ""
    folder = None
    if trace is not False:
        if keep:
            os.makedirs(trace, exist_ok=True)
        folder = tempfile.mkdtemp(prefix=f"{tier}-{mode}-", dir=trace if keep else None)
        env["PDVERIFY_TEST_TRACE"] = folder
    load0 = os.getloadavg()[0]
    ru0 = resource.getrusage(resource.RUSAGE_CHILDREN)
    with tempfile.TemporaryFile("w+") as out:
        t0 = time.perf_counter()
        proc = subprocess.Popen(cmd, cwd=HERE, env=env, stdout=out, stderr=subprocess.STDOUT,
                                text=True)
        sampler = Sampler(proc.pid)
        sampler.start()
        code = proc.wait()
        wall = time.perf_counter() - t0
        sampler.stop()
        ru1 = resource.getrusage(resource.RUSAGE_CHILDREN)
        out.seek(0)
        lines = [x for x in out.read().splitlines() if x.strip()]
    cpu = (ru1.ru_utime + ru1.ru_stime) - (ru0.ru_utime + ru0.ru_stime)
    traced = []
    if trace is not False:
        import shutil
        logs = _read_trace(folder)
        traced = (_at_peak_trace(proc.pid, *sampler.at_pss_peak, logs)
                  + _largest_tests(logs))
        if keep:
            traced.append(f"    the tests' logs: {folder}")
        else:
            shutil.rmtree(folder)
    return {"tier": tier, "mode": mode, "code": code, "wall_s": wall, "cpu_s": cpu,
            "peak_rss_gb": sampler.peak_rss / 1e9, "peak_pss_gb": sampler.peak_pss / 1e9,
            "largest_gb": sampler.peak_one / 1e9, "procs": sampler.peak_procs,
            "load": (load0, os.getloadavg()[0]), "summary": lines[-1] if lines else "",
            "at_peak": sampler.at_peak, "traced": traced}


def show(r):
    print(f"{r['tier']:4s} {r['mode']:8s} exit {r['code']}  wall {r['wall_s']:7.1f} s  "
          f"CPU {r['cpu_s']:7.1f} s  peak total RSS {r['peak_rss_gb']:5.2f} GB  "
          f"PSS {r['peak_pss_gb']:5.2f} GB  "
          f"largest process {r['largest_gb']:5.2f} GB  processes <= {r['procs']:3d}  "
          f"load {r['load'][0]:.2f} -> {r['load'][1]:.2f}  | {r['summary']}", flush=True)
    for rss, cmd in r["at_peak"][:4]:
        print(f"    at the peak: {rss / 1e9:5.2f} GB  {cmd}")
    for line in r["traced"]:
        print(line)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--tier", choices=("fast", "slow", "both"), default="fast")
    ap.add_argument("--repeat", type=int, default=1)
    ap.add_argument("--modes", default="serial,parallel",
                    help="comma-separated, of: serial, parallel")
    ap.add_argument("--trace", nargs="?", const="", default=False, metavar="DIR",
                    help="name each process at the PSS peak, the test its worker was "
                         "running and the files it had run (tests/conftest.py's "
                         "PDVERIFY_TEST_TRACE); with DIR, keep the tests' logs there")
    harness.add_arguments(ap)
    args = ap.parse_args(argv)
    with harness.Record(__file__, args, argv=argv) as rec:
        return _measure(args, rec)


def _measure(args, rec):
    tiers = ("fast", "slow") if args.tier == "both" else (args.tier,)
    modes = args.modes.split(",")
    runs = []

    def one(tier, mode):
        runs.append(measure(tier, mode, args.trace))
        show(runs[-1])
        rec["runs"] = runs                  # the record after every run
    for tier in tiers:
        # rotate: the modes' order changes every round, so neither always runs after the other
        harness.alternate({mode: (lambda mode=mode: one(tier, mode)) for mode in modes},
                          args.repeat)
    print("medians:")
    for tier in tiers:
        for mode in modes:
            mine = [r for r in runs if r["tier"] == tier and r["mode"] == mode]
            med = {key: harness.median(r[key] for r in mine)
                   for key in ("wall_s", "cpu_s", "peak_rss_gb", "peak_pss_gb", "largest_gb")}
            print(f"{tier:4s} {mode:8s} n={len(mine)}  wall {med['wall_s']:7.1f} s  "
                  f"CPU {med['cpu_s']:7.1f} s  peak total RSS {med['peak_rss_gb']:5.2f} GB  "
                  f"PSS {med['peak_pss_gb']:5.2f} GB  "
                  f"largest process {med['largest_gb']:5.2f} GB")
            rec[f"median {tier} {mode}"] = med
    return 0 if all(r["code"] in (0, 5) for r in runs) else 1


if __name__ == "__main__":
    sys.exit(main())
