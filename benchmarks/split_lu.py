"""The 2D float32 factor: the whole matrix factored by SuperLU in float32 (``SingleLU``,
today's) against the multifrontal ``FrontalLU`` (the 3D boxes' float32 factor;
``policy.frontal_factor`` made always true sends every system there), on the report's
largest float32 runs. The record ``split_lu-2026-11-28-all-cases`` was taken at commit
d1d468f with a third variant, ``SplitLU`` (the two halves of the top split factored by
SuperLU in two threads, the separator by a dense Schur complement), the 2D factor of
that time, since removed: its rows are that variant's ``split``, ``superlu-whole`` is
today's ``SingleLU``.

Each run in a fresh process per variant, the variants alternating (rotated) per round:
the run's solve seconds (wall), the process's CPU seconds (all its threads: what a run
costs when ``report --jobs`` keeps every core busy), its peak resident memory, and the
largest relative difference of its metrics from the split's.

Usage: python benchmarks/split_lu.py [--repeat 2] [--cases N] [--no-record]
"""
from __future__ import annotations

import argparse
import os
import sys

os.environ.setdefault("OMP_NUM_THREADS", "1")   # as the report's workers
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import harness  # noqa: E402

#: the report's float32 runs with the longest solves (full report of 4757a2f)
CASES = [
    ("plate2d-plane-strain", "taylor-fictitious", {"spacing": 0.0125, "order": 2}),
    ("plate2d-plane-strain", "surface-nodes", {"spacing": 0.0125}),
    ("plate2d-plane-strain", "pals", {"spacing": 0.0125}),
    ("sheet2d-tension", "energy-directional", {"quadrature": "partial-volume"}),
    ("plate2d-plane-strain", "mirror-nodes", {"spacing": 0.0125}),
    ("sheet2d-tension", "none", {"quadrature": "partial-volume"}),
    ("plate2d-clamped", "none", {}),
]
VARIANTS = ("superlu-whole", "frontal")


def one_run(scene_id, method, overrides, variant):
    """In a fresh process: the run under ``variant``; its solve s, CPU s, peak MB, metrics."""
    import resource
    import time
    sys.path.insert(0, harness.ROOT.as_posix())
    from pdverify.solvers import nested, policy
    from pdverify.scenes import get_scene
    if variant == "frontal":
        policy.frontal_factor = lambda separator, unknowns: True
    nested.FRONTAL_FACTOR = variant == "frontal"
    c0 = time.process_time()
    result = get_scene(scene_id).run(method, overrides)
    cpu = time.process_time() - c0
    return {"status": result.status, "solve_s": result.timings.get("solve_s"),
            "cpu_s": cpu, "peak_mb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024,
            "solver": result.diagnostics.get("solver"),
            "metrics": {k: v for k, v in result.metrics.items() if isinstance(v, float)}}


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=2)
    ap.add_argument("--cases", type=int, default=len(CASES))
    harness.add_arguments(ap)
    args = ap.parse_args(argv)
    with harness.Record(__file__, args) as rec:
        total = {v: {"solve_s": 0.0, "cpu_s": 0.0} for v in VARIANTS}
        for scene_id, method, overrides in CASES[:args.cases]:
            runs = {v: [] for v in VARIANTS}
            for k in range(args.repeat):
                order = VARIANTS[k % len(VARIANTS):] + VARIANTS[:k % len(VARIANTS)]
                for v in order:
                    runs[v].append(harness.fresh_call(one_run, scene_id, method, overrides, v))
            base = runs[VARIANTS[0]][0]["metrics"]
            row = {}
            for v in VARIANTS:
                med = {q: harness.median([r[q] for r in runs[v]])
                       for q in ("solve_s", "cpu_s", "peak_mb")}
                diff = max((abs(runs[v][0]["metrics"][m] - b) / abs(b) for m, b in base.items()
                            if b and m in runs[v][0]["metrics"]), default=0.0)
                row[v] = {**med, "metrics_max_rel_diff": diff, "solver": runs[v][0]["solver"],
                          "status": runs[v][0]["status"]}
                total[v]["solve_s"] += med["solve_s"]
                total[v]["cpu_s"] += med["cpu_s"]
            key = f"{scene_id} --method {method} {overrides}"
            rec[key] = row
            rec["total"] = total
            rec.save()
            print(key)
            for v in VARIANTS:
                r = row[v]
                print(f"  {v:14s} solve {r['solve_s']:6.2f} s  cpu {r['cpu_s']:6.2f} s  "
                      f"peak {r['peak_mb']:6.0f} MB  metrics {r['metrics_max_rel_diff']:.1e}  "
                      f"{r['status']}", flush=True)
        print("total:", {v: {q: round(x, 2) for q, x in t.items()} for v, t in total.items()})


if __name__ == "__main__":
    main()
