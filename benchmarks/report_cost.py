"""Where a report's time goes: runs, figures, VTU export, pages (issue 17's budget:
figures and VTU export under 15 % of the report's total time), the run time per scene,
the wall time and the peak memory (issue 32).

Plain script (no test runner):

    python benchmarks/report_cost.py [--repeat N] [--json FILE] [--full] [--only SCENE ...]
                                     [--args "ARGS"] [--against SRC [--against-args "ARGS"]]
                                     [--keep FILE]

Runs ``python -m pdverify report --quick`` (``--full``: the full report; ``--args``:
further report arguments, e.g. ``--jobs 1``) ``--repeat`` times (default 3) into a
temporary folder, each in a fresh process, and reads the phase times the report records
in results.json (``report_phases``: runs_s, figures_s, fields_s, pages_s, total_s) and
each run's ``total_s``. Prints the median of each phase, its share of the total, the
share of figures + VTU export against the 15 % budget, the median run time of each
scene (the sum over its runs, on all workers), the median wall time of the whole
command, its peak memory and the report's ``critical path:`` line. The peak memory is
the largest sum, over the report's process and its workers, of each process's
proportional set size (``Pss`` of /proc/PID/smaps_rollup: pages shared by the forked
workers counted once), sampled every 0.1 s; next to it, the largest single process's
peak resident size (``ru_maxrss``), and the report process's own peak resident size
(``VmHWM`` of /proc/PID/status, sampled likewise), so that the report process's share
and its workers' are told apart (benchmarks/records/report_cost-2026-11-26-stop40.json).
``--against SRC``: also run the report of another
source tree (e.g. ``git archive`` of an earlier commit unpacked, put first on
PYTHONPATH; ``--against-args``: its report arguments), alternating with this one, and
print both and the ratios.
"""
from __future__ import annotations

import argparse
import json
import os
import resource
import shlex
import shutil
import subprocess
import sys
import tempfile
import threading
import time

import harness

PHASES = ("runs_s", "figures_s", "fields_s", "pages_s")
BUDGET = 0.15   # issue 17: figures and VTU export < 15 % of the report's total time


def _tree(pid) -> list[int]:
    """``pid`` and its descendants (from /proc/PID/task/*/children)."""
    out, todo = [], [pid]
    while todo:
        p = todo.pop()
        out.append(p)
        try:
            for task in os.listdir(f"/proc/{p}/task"):
                with open(f"/proc/{p}/task/{task}/children") as fh:
                    todo.extend(int(c) for c in fh.read().split())
        except OSError:
            pass
    return out


def _kb_field(path, key) -> int:
    """The ``key:`` line of a /proc file in bytes (its kB value; 0 if the process is gone)."""
    try:
        with open(path) as fh:
            for line in fh:
                if line.startswith(key + ":"):
                    return int(line.split()[1]) * 1024
    except OSError:
        pass
    return 0


def _pss(pid) -> int:
    """Proportional set size of one process in bytes (0 if it is gone)."""
    return _kb_field(f"/proc/{pid}/smaps_rollup", "Pss")


def _hwm(pid) -> int:
    """Peak resident size of one process so far in bytes (0 if it is gone)."""
    return _kb_field(f"/proc/{pid}/status", "VmHWM")


def _sample_peak(proc, peak: list, tmp, every=0.1) -> None:
    """peak[0]: the largest sum of Pss over the tree; peak[1]: the report process's
    own peak resident size."""
    while proc.poll() is None:
        peak[0] = max(peak[0], sum(_pss(p) for p in _tree(proc.pid)))
        peak[1] = max(peak[1], _hwm(proc.pid))
        time.sleep(every)


def one_report(full: bool, only, src=None, args=(), keep=None) -> dict:
    env = dict(os.environ)
    if src:
        env["PYTHONPATH"] = os.pathsep.join([os.path.abspath(src), env.get("PYTHONPATH", "")])
    with tempfile.TemporaryDirectory() as tmp:
        out = os.path.join(tmp, "report")
        cmd = [sys.executable, "-m", "pdverify", "report", "--out", out]
        cmd += [] if full else ["--quick"]
        cmd += ["--only", *only] if only else []
        cmd += list(args)
        peak = [0, 0]
        t0 = time.perf_counter()
        proc = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE,
                                env=env, cwd=tmp, text=True)
        sampler = threading.Thread(target=_sample_peak, args=(proc, peak, tmp), daemon=True)
        sampler.start()
        err = proc.communicate()[1]
        wall = time.perf_counter() - t0
        sampler.join()
        with open(os.path.join(out, "results.json")) as fh:
            doc = json.load(fh)
        if keep:    # the last round's results.json, e.g. for `pdverify compare`
            shutil.copyfile(os.path.join(out, "results.json"), keep)
    scenes = {}
    for r in doc["runs"]:
        scenes[r["scene"]] = scenes.get(r["scene"], 0.0) + r["timings"]["total_s"]
    path = [x for x in err.splitlines() if x.startswith("critical path:")]
    return {"runs": len(doc["runs"]), **doc["report_phases"], "wall_s": wall,
            "peak_pss": peak[0], "report_rss": peak[1], "scenes": scenes,
            "critical_path": path[-1] if path else "",
            # the largest single child so far (this script's children, all rounds)
            "max_child_rss": resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss * 1024}


def summary(name, rounds, repeat) -> dict:
    med = {k: harness.median(r.get(k, 0.0) for r in rounds)
           for k in PHASES + ("total_s", "wall_s", "peak_pss", "report_rss")}
    drawn = (med["figures_s"] + med["fields_s"]) / med["total_s"]
    print(f"{name} ({rounds[0]['runs']} runs), median of {repeat}:")
    for k in PHASES:
        print(f"  {k[:-2]:8s} {med[k]:8.2f} s  {100 * med[k] / med['total_s']:5.1f} %")
    print(f"  {'total':8s} {med['total_s']:8.2f} s   (wall time of the command "
          f"{med['wall_s']:.2f} s)")
    print(f"  figures + VTU export: {100 * drawn:.1f} % of the total "
          f"(budget < {100 * BUDGET:.0f} %): {'met' if drawn < BUDGET else 'MISSED'}")
    print(f"  peak memory (sum of Pss over the report's processes): "
          f"{med['peak_pss'] / 1e9:.3f} GB")
    print(f"  the report process's own peak resident size (VmHWM): "
          f"{med['report_rss'] / 1e9:.3f} GB")
    scenes = {s: harness.median(r["scenes"].get(s, 0.0) for r in rounds)
              for s in rounds[0]["scenes"]}
    print("  run time per scene (sum of its runs' total_s):")
    for s, t in sorted(scenes.items(), key=lambda x: -x[1]):
        print(f"    {s:34s} {t:8.2f} s")
    for r in rounds:
        if r["critical_path"]:
            print(f"  {r['critical_path']}")
    return {"median": med, "figures_and_vtu_share": drawn, "scenes": scenes,
            "rounds": rounds}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--full", action="store_true", help="the full report (default: --quick)")
    ap.add_argument("--only", nargs="+", default=None, help="scenes (default: all)")
    ap.add_argument("--json", default=None, help="write the medians and every round here")
    ap.add_argument("--keep", default=None, metavar="FILE",
                    help="copy this tree's last report's results.json to FILE")
    ap.add_argument("--args", default="", help="further arguments of this tree's report")
    ap.add_argument("--against", default=None, metavar="SRC",
                    help="also time the report of this source tree, alternating")
    ap.add_argument("--against-args", default="",
                    help="further arguments of the --against tree's report")
    harness.add_arguments(ap)
    a = ap.parse_args(argv)
    with harness.Record(__file__, a, argv=argv) as rec:
        _measure(a, rec)
    return 0


def _measure(a, rec) -> None:
    kind = "full" if a.full else "quick"
    trees = {f"this tree {a.args}".strip(): (None, shlex.split(a.args)),
             **({f"against {a.against} {a.against_args}".strip():
                 (a.against, shlex.split(a.against_args))} if a.against else {})}
    timed = harness.alternate(
        {name: (lambda src=src, args=args: one_report(a.full, a.only, src, args,
                                                      keep=a.keep if src is None else None))
         for name, (src, args) in trees.items()}, a.repeat, rotate=False)
    rounds = {name: t.results for name, t in timed.items()}
    out = {name: summary(f"report ({kind}), {name}", rs, a.repeat) for name, rs in rounds.items()}
    print(f"largest single process's peak resident size, all rounds: "
          f"{max(r['max_child_rss'] for rs in rounds.values() for r in rs) / 1e9:.3f} GB")
    if a.against:
        (mine, other) = (out[n]["median"] for n in trees)
        for k, unit in (("total_s", "s"), ("runs_s", "s"), ("wall_s", "s")):
            print(f"{k[:-2]}, this tree / against: {mine[k]:.1f} {unit} / {other[k]:.1f} "
                  f"{unit} = {mine[k] / other[k]:.2f}")
        print(f"peak memory, this tree / against: {mine['peak_pss'] / 1e9:.3f} GB / "
              f"{other['peak_pss'] / 1e9:.3f} GB")
        print(f"report process's peak resident size, this tree / against: "
              f"{mine['report_rss'] / 1e9:.3f} GB / {other['report_rss'] / 1e9:.3f} GB")
    rec.update(out)
    if a.json:
        harness.write_json(a.json, out)


if __name__ == "__main__":
    sys.exit(main())
