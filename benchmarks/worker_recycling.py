"""Cost of recycling the report's worker processes (issue 34, worker hygiene): the same
cases through ``run_cases`` with recycling off (one process per worker for the whole
plan) and on (the defaults: a fresh process after ``RUNS_PER_WORKER`` runs or a heavy
run), side by side, alternating, several repeats; medians and their ratio.

Plain script (no test runner):

    python benchmarks/worker_recycling.py [--only SCENE ...] [--jobs N] [--repeat R]

Default: the quick report's plan of the seed-004 bars and the seed-000 bars (many small
runs, where a per-process start costs most relative to the work).
"""
from __future__ import annotations

import argparse
import statistics
import time

import pdverify.runner as runner
from pdverify.runner import plan, run_cases

DEFAULT_ONLY = ["bar1d-homogenization", "bar1d-constraints", "bar1d-traction",
                "bar1d-uniform-load", "bar1d-sine-load"]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--only", nargs="+", default=DEFAULT_ONLY)
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--repeat", type=int, default=3)
    args = ap.parse_args()
    cases = plan(only=args.only, quick=True)
    on = (runner.RUNS_PER_WORKER, runner.HEAVY_FRACTION)
    settings = {"off": (10 ** 9, float("inf")), "on": on}
    times = {k: [] for k in settings}
    slots_used = {}
    for _ in range(args.repeat):
        for name, (runs, heavy) in settings.items():
            runner.RUNS_PER_WORKER, runner.HEAVY_FRACTION = runs, heavy
            slots = []
            t0 = time.perf_counter()
            results = run_cases(cases, jobs=args.jobs, schedule=slots)
            times[name].append(time.perf_counter() - t0)
            slots_used[name] = sum(s.processes for s in slots)
            assert all(r.status != "failed" or r.expected_failure for r in results)
    runner.RUNS_PER_WORKER, runner.HEAVY_FRACTION = on
    print(f"{len(cases)} cases, --jobs {args.jobs}, {args.repeat} repeats "
          f"(RUNS_PER_WORKER={on[0]}, HEAVY_FRACTION={on[1]})")
    for name in settings:
        t = times[name]
        print(f"  recycling {name:3s}: median {statistics.median(t):7.2f} s "
              f"(min {min(t):.2f}, max {max(t):.2f}); worker processes {slots_used[name]}")
    print(f"  ratio on/off: {statistics.median(times['on']) / statistics.median(times['off']):.3f}")


if __name__ == "__main__":
    main()
