"""One BLAS thread per run (``pdverify.blas``) against the libraries' default (one thread
per core), side by side in one run.

Plain script (no test runner):

    python benchmarks/blas_threads.py [--repeat N] [--jobs J ...] [--only SCENE ...] [--full]

Runs the report's cases of the given scenes (default: the 2D and 3D scenes whose runs call
BLAS the most, at the quick report's sizes; ``--full``: the full report's) through the
report's supervised worker pool with each ``--jobs`` (default: 1 and 2), alternating the
two settings, ``--repeat`` times (default 3). Prints the wall time of each (median, min,
max), their ratio, whether every metric is bitwise identical across the job counts, and
whether it is between the two settings (it need not be: two threads add a long dot
product in another order than one, which is how the default made a run's numbers depend
on the machine's core count).

The address-space half of the question (a run that exhausts a ``ulimit -v`` with two
BLAS threads and passes with one) is checked with the shell's ``ulimit``, not here:

    (ulimit -v 6000000; python -m pdverify report --out /tmp/capped \\
        --only body3d-manufactured --method surface-nodes)
"""
from __future__ import annotations

import argparse
import contextlib

import harness
from pdverify import blas, runner

SCENES = ("body3d-manufactured", "plate2d-plane-strain", "sheet2d-tension")


def _metrics(results):
    return [(r.scene, r.method, r.status, sorted(r.metrics.items())) for r in results]


class _Silent:
    """The progress sink of ``_run_local`` that shows nothing."""

    tick_s = None

    def started(self, k, timed=True):
        pass

    def finished(self, k, res):
        pass

    def tick(self):
        pass


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--jobs", type=int, nargs="+", default=[1, 2])
    ap.add_argument("--only", nargs="+", default=list(SCENES))
    ap.add_argument("--full", action="store_true", help="the full report's cases")
    harness.add_arguments(ap)
    args = ap.parse_args(argv)
    with harness.Record(__file__, args, argv=argv) as rec:
        _measure(args, rec)


def _measure(args, rec):
    cases = runner.plan(only=args.only, quick=not args.full)
    one = blas.one_thread
    settings = {f"default ({blas.threads()} threads)": contextlib.nullcontext,
                "one thread per run": one}
    seen = {}

    def one_setting(jobs, name):
        blas.one_thread = settings[name]        # forked workers inherit the setting
        try:
            res = runner._run_local(cases, jobs, _Silent())
        finally:
            blas.one_thread = one
        seen.setdefault((jobs, name), _metrics(res))
    timed = harness.alternate({(jobs, name): (lambda jobs=jobs, name=name: one_setting(jobs, name))
                               for jobs in args.jobs for name in settings}, args.repeat,
                              rotate=False)
    times = {k: t.times for k, t in timed.items()}
    print(f"{len(cases)} cases of {', '.join(args.only)} "
          f"({'full' if args.full else 'quick'} sizes), medians of {args.repeat}")
    for jobs in args.jobs:
        meds = []
        for name in settings:
            ts = times[(jobs, name)]
            meds.append(timed[(jobs, name)].median)
            print(f"  --jobs {jobs}  BLAS {name:22s} {meds[-1]:8.2f} s "
                  f"(min {min(ts):.2f}, max {max(ts):.2f})")
        print(f"  --jobs {jobs}  default / one thread: {meds[0] / meds[1]:.2f}x")
    for name in settings:
        same = len({repr(seen[(j, name)]) for j in args.jobs}) == 1
        print(f"  BLAS {name}: metrics bitwise identical across --jobs {args.jobs}: {same}")
    j = args.jobs[0]
    a, b = (seen[(j, name)] for name in settings)
    print(f"  --jobs {j}: metrics bitwise identical between the settings: {a == b}")
    rec.update({"cases": len(cases), "scenes": args.only, "full": args.full,
                "median_s": {f"--jobs {j} {n}": t.median for (j, n), t in timed.items()},
                "times_s": {f"--jobs {j} {n}": t.times for (j, n), t in timed.items()},
                "metrics_identical_between_settings": a == b})


if __name__ == "__main__":
    main()
