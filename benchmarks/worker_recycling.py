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

import harness
import pdverify.runner as runner
from pdverify.runner import plan, run_cases

DEFAULT_ONLY = ["bar1d-homogenization", "bar1d-constraints", "bar1d-traction",
                "bar1d-uniform-load", "bar1d-sine-load"]


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--only", nargs="+", default=DEFAULT_ONLY)
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--repeat", type=int, default=3)
    harness.add_arguments(ap)
    args = ap.parse_args(argv)
    with harness.Record(__file__, args, argv=argv) as rec:
        _measure(args, rec)


def _measure(args, rec) -> None:
    cases = plan(only=args.only, quick=True)
    on = (runner.RUNS_PER_WORKER, runner.HEAVY_FRACTION)
    settings = {"off": (10 ** 9, float("inf")), "on": on}
    slots_used = {}

    def one(name):
        runner.RUNS_PER_WORKER, runner.HEAVY_FRACTION = settings[name]
        slots = []
        results = run_cases(cases, jobs=args.jobs, schedule=slots)
        slots_used[name] = sum(s.processes for s in slots)
        assert all(r.status != "failed" or r.expected_failure for r in results)
    try:
        timing = harness.alternate({n: (lambda n=n: one(n)) for n in settings}, args.repeat)
    finally:
        runner.RUNS_PER_WORKER, runner.HEAVY_FRACTION = on
    times = {n: t.times for n, t in timing.items()}
    print(f"{len(cases)} cases, --jobs {args.jobs}, {args.repeat} repeats "
          f"(RUNS_PER_WORKER={on[0]}, HEAVY_FRACTION={on[1]})")
    for name in settings:
        t = times[name]
        print(f"  recycling {name:3s}: median {timing[name].median:7.2f} s "
              f"(min {min(t):.2f}, max {max(t):.2f}); worker processes {slots_used[name]}")
    print(f"  ratio on/off: {timing['on'].median / timing['off'].median:.3f}")
    rec.update({"cases": len(cases), "jobs": args.jobs, "runs_per_worker": on[0],
                "heavy_fraction": on[1], **harness.summary(timing, base="off"),
                "worker_processes": slots_used})


if __name__ == "__main__":
    main()
