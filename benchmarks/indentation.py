"""The indentation scene's speed budgets (issue 14), side by side in one run.

Plain script (no test runner):

    python benchmarks/indentation.py [--repeat N] [--skip-direct]

Times, median of ``--repeat`` (default 3) runs each, alternating:

- the corrected nonlinear curve at the paper's grid (161 x 161 nodes, m = 6, 51,842
  unknowns, 20 depth steps), CG with the preconditioner reused across Newton iterations
  and steps; budget < 60 s for the whole curve, < 1 s per linear solve;
- the same on the quick grid (41 x 41 nodes, spacing 1 mm, m = 6), CG against a sparse
  LU per Newton step (``--skip-direct`` leaves the LU out); budget < 5 s.

The FEM references are computed (and cached) before the clock starts; only the PD solve
phase and the run's total are timed. Prints per case: median total, median solve, linear
solves, CG iterations, preconditioner builds, median and max time per output depth.
"""
from __future__ import annotations

import argparse
import statistics

from pdverify.scenes import get_scene

QUICK = {"spacing": 0.001, "horizon": 0.006}


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--skip-direct", action="store_true")
    args = ap.parse_args()
    scene = get_scene("block2d-indentation")
    cases = [("paper grid, CG", {"solver": "cg"}), ("quick grid, CG", {**QUICK, "solver": "cg"})]
    if not args.skip_direct:
        cases.append(("quick grid, sparse LU", {**QUICK, "solver": "direct"}))
    for _, over in cases:                       # references into the cache, untimed
        scene.fem_reference(scene.resolve("energy-directional", over))
    runs = {name: [] for name, _ in cases}
    for _ in range(args.repeat):
        for name, over in cases:
            r = scene.run("energy-directional", over)
            if r.status != "ok":
                raise SystemExit(f"{name}: {r.message}")
            runs[name].append(r)
    print(f"{'case':24s} {'total s':>8s} {'solve s':>8s} {'solves':>7s} {'CG it':>6s} "
          f"{'builds':>6s} {'s/solve':>8s} {'step med':>8s} {'step max':>8s}")
    base = None
    for name, rs in runs.items():
        total = statistics.median(r.timings["total_s"] for r in rs)
        solve = statistics.median(r.timings["solve_s"] for r in rs)
        d = rs[0].diagnostics
        per = statistics.median(r.diagnostics["linear_solve_s"] / r.diagnostics["linear_solves"]
                                for r in rs)
        print(f"{name:24s} {total:8.2f} {solve:8.2f} {d['linear_solves']:7d} "
              f"{d.get('cg_iterations', 0):6d} {d['preconditioner_builds']:6d} {per:8.3f} "
              f"{statistics.median(r.diagnostics['median_step_s'] for r in rs):8.2f} "
              f"{statistics.median(r.diagnostics['max_step_s'] for r in rs):8.2f}")
        if name.startswith("quick grid, CG"):
            base = total
        elif base is not None:
            print(f"{'':24s} sparse LU / CG on the quick grid: {total / base:.1f}x")


if __name__ == "__main__":
    main()
