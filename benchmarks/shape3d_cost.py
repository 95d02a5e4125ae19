"""What the two 3D shape scenes (issue 55) add to a report: their runs' times and peak
memory, the FEM references cold (an empty cache) and warm.

Plain script (no test runner):

    python benchmarks/shape3d_cost.py [--jobs N] [--no-record] [--tag TAG]

Runs ``python -m pdverify report --only cylinder3d-tension block3d-cavity`` twice in a
fresh process: first with an empty FEM cache (a temporary ``PDVERIFY_CACHE_DIR``), then
warm (the same cache), and records the wall time of each report and, per run, the
run's total time and peak memory from its ``results.json``. The machine's load (the
harness header) says how far the numbers are from an idle machine's.

Measured 2026-11-28 under load (load average 14-18 on the 2 cores shared with five other
sessions; record ``shape3d_cost-2026-11-28-default.json``): cold 88.6 s wall (runs 131 s
summed; the FEM studies 14.6 s cylinder, 39.2 s cavity), warm 57.0 s wall (runs 80.5 s;
PD runs 5.6-14.3 s each), every run's peak at most 0.59 GB. The same load scaled a
reference run, body3d-traction's ``none`` (2.15 s in the full report of 674b0c4), to
8.5-11.2 s, i.e. 4-5 times: alone the two scenes' warm runs would take ~16-20 s summed
(~10 s wall on 2 workers) and the cold FEM studies ~12 s more. The quick report runs
them at twice the spacing: 10 runs, 5.1 s critical path under the same load.
"""
from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import harness

SCENES = ("cylinder3d-tension", "block3d-cavity")


def one_report(out: Path, cache: Path, jobs: int) -> dict:
    env = {**os.environ, "PDVERIFY_CACHE_DIR": str(cache),
           "PYTHONPATH": str(harness.ROOT) + os.pathsep + os.environ.get("PYTHONPATH", "")}
    t0 = time.perf_counter()
    subprocess.run([sys.executable, "-m", "pdverify", "report", "--only", *SCENES,
                    "--out", str(out), "--jobs", str(jobs)], env=env, check=True,
                   cwd=harness.ROOT, capture_output=True)
    wall = time.perf_counter() - t0
    res = json.loads((out / "results.json").read_text())
    runs = [{"scene": r["scene"], "method": r["method"], "status": r["status"],
             "total_s": r["timings"].get("total_s"),
             "peak_rss_gb": (r.get("resources") or {}).get("peak_rss_gb")}
            for r in res["runs"]]
    return {"wall_s": wall, "runs_s": sum(r["total_s"] or 0 for r in runs), "runs": runs}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--jobs", type=int, default=2, help="report workers (default 2)")
    harness.add_arguments(ap)
    args = ap.parse_args()
    with harness.Record(__file__, args) as rec, tempfile.TemporaryDirectory() as tmp:
        cache = Path(tmp) / "cache"
        for label in ("cold", "warm"):
            r = one_report(Path(tmp) / label, cache, args.jobs)
            rec[label] = r
            rec.save()
            peak = max(x["peak_rss_gb"] or 0 for x in r["runs"])
            print(f"{label}: report {r['wall_s']:.1f} s wall, runs {r['runs_s']:.1f} s, "
                  f"largest peak {peak:.2f} GB")
            for x in r["runs"]:
                print(f"  {x['scene']:20s} {x['method']:8s} {x['status']:4s} "
                      f"{x['total_s']:6.2f} s {x['peak_rss_gb'] or 0:.2f} GB")


if __name__ == "__main__":
    main()
