"""What the 2D pulse scene (issue 56) adds to a report: its runs' times and peak memory,
the FEM reference cold (an empty cache) and warm, and the quick report's runs.

Plain script (no test runner):

    python benchmarks/wave_pulse_cost.py [--jobs N] [--no-record] [--tag TAG]

Runs ``python -m pdverify report --only wave2d-pulse`` in a fresh process three times:
with an empty FEM cache (a temporary ``PDVERIFY_CACHE_DIR``), then warm (the same
cache), then ``--quick`` warm, and records the wall and CPU time (user + system, the
report's processes) of each report and, per run,
the run's total time and peak memory from its ``results.json``. The machine's load (the
harness header) says how far the numbers are from an idle machine's.

Measured 2026-11-28 under load (load average 14-17 on the 2 cores shared with seven
other sessions; record ``wave_pulse_cost-2026-11-28-final.json``): cold 104 s wall and
25.0 s CPU (the FEM study 21.6 s wall of it), warm 84 s wall and 20.2 s CPU (PD runs at
h = 0.01 21-44 s wall each, the surface nodes' documented failure 6 s), --quick warm
25 s wall and 6.1 s CPU; every run's peak at most 0.82 GB.
"""
from __future__ import annotations

import argparse
import json
import os
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import harness

SCENE = "wave2d-pulse"


def one_report(out: Path, cache: Path, jobs: int, quick: bool) -> dict:
    env = {**os.environ, "PDVERIFY_CACHE_DIR": str(cache),
           "PYTHONPATH": str(harness.ROOT) + os.pathsep + os.environ.get("PYTHONPATH", "")}
    t0 = time.perf_counter()
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    subprocess.run([sys.executable, "-m", "pdverify", "report", "--only", SCENE,
                    "--out", str(out), "--jobs", str(jobs)] + (["--quick"] if quick else []),
                   env=env, check=False, cwd=harness.ROOT, capture_output=True)
    wall = time.perf_counter() - t0
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    # the CPU time of the report and its workers (user + system): what an idle machine's
    # run would take at most, load or not
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    res = json.loads((out / "results.json").read_text())
    runs = [{"method": r["method"], "spacing": r["params"].get("spacing"),
             "status": r["status"], "total_s": r["timings"].get("total_s"),
             "peak_rss_gb": (r.get("resources") or {}).get("peak_rss_gb")}
            for r in res["runs"]]
    return {"wall_s": wall, "cpu_s": cpu, "runs_s": sum(r["total_s"] or 0 for r in runs), "runs": runs}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--jobs", type=int, default=2, help="report workers (default 2)")
    harness.add_arguments(ap)
    args = ap.parse_args()
    with harness.Record(__file__, args) as rec, tempfile.TemporaryDirectory() as tmp:
        cache = Path(tmp) / "cache"
        for label, quick in (("cold", False), ("warm", False), ("quick-warm", True)):
            r = one_report(Path(tmp) / label, cache, args.jobs, quick)
            rec[label] = r
            rec.save()
            peak = max(x["peak_rss_gb"] or 0 for x in r["runs"])
            print(f"{label}: report {r['wall_s']:.1f} s wall, {r['cpu_s']:.1f} s CPU, runs {r['runs_s']:.1f} s, "
                  f"largest peak {peak:.2f} GB")
            for x in r["runs"]:
                print(f"  {x['method']:14s} h={x['spacing']} {x['status']:6s} "
                      f"{x['total_s'] or 0:6.2f} s {x['peak_rss_gb'] or 0:.2f} GB")


if __name__ == "__main__":
    main()
