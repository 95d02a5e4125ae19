"""Time the seed-000 clamped plate: SuperLU orderings on its Lagrange system, and whole runs.

Plain script (no test runner): python benchmarks/plate_solvers.py [--repeat N] [--json FILE]
1. The Lagrange system [[K, B^T], [B, 0]] of ``taylor-fictitious`` (order 2, m = 3) at
   spacing 0.05 m and 0.025 m (the issue's "4x finer grid", 9,600 real nodes), equilibrated
   as ``solve_constrained`` does, factored with each ordering: median of N alternating
   runs, ratio to SuperLU's default COLAMD. Supports ``pdverify.scenes.plate2d.ORDERING``.
2. Whole runs (``Scene.run``: setup, solve, errors; FEM reference from the cache) at
   Table 4's size (600 real nodes) and 4x finer, against the budgets of 1 s and 10 s.
"""
from __future__ import annotations

import argparse

import scipy.sparse as sp

import harness
from _splu_timing import time_splu
from pdverify.corrections.taylor_fictitious import assemble_taylor
from pdverify.scenes import get_scene
from pdverify.solvers.checks import equilibrate

ORDERINGS = ("COLAMD", "MMD_AT_PLUS_A", "MMD_ATA")


def lagrange_system(spacing, order=2):
    """The scene's own Taylor system (``taylor_fictitious.assemble_taylor`` of its problem)."""
    scene = get_scene("plate2d-clamped")
    problem = scene.problem({**scene.default_params(), "spacing": spacing}, "benchmark")
    system = assemble_taylor(problem, order)
    A = sp.bmat([[system.K, system.B.T], [system.B, None]], format="csr")
    A_s, _, _ = equilibrate(A, "benchmark")
    return A_s.tocsc()


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--json", default=None, help="write the medians to this file")
    harness.add_arguments(ap)
    args = ap.parse_args(argv)
    with harness.Record(__file__, args, argv=argv) as rec:
        rec.update({"orderings": {}, "runs": {}})
        _measure(args, rec)
        if args.json:
            harness.write_json(args.json, rec.results)


def _measure(args, rec):
    out = rec.results
    for h in (0.05, 0.025):
        A = lagrange_system(h)
        medians = time_splu(A, {name: {"permc_spec": name} for name in ORDERINGS}, args.repeat)
        base = medians["COLAMD"]
        print(f"spacing {h} m: {A.shape[0]} unknowns, {A.nnz} non-zeros; median of {args.repeat}")
        for name, med in medians.items():
            print(f"  splu {name:15s} {med:7.2f} s   speed-up vs COLAMD {base / med:5.2f}x")
            out["orderings"][f"{h}/{name}"] = med
        rec.save()
    scene = get_scene("plate2d-clamped")
    cases = [("Table 4 (600 real nodes)", 0.1, 1.0), ("4x finer (9,600 real nodes)", 0.025, 10.0)]
    for label, h, budget in cases:
        for method, extra in (("none", {}), ("taylor-fictitious", {"order": 1}),
                              ("taylor-fictitious", {"order": 3})):
            t = harness.alternate({"run": lambda: scene.run(method, {"spacing": h, **extra})},
                                  args.repeat)["run"]
            assert all(r.status == "ok" for r in t.results), t.last.message
            med, r = t.median, t.last
            tag = f"{method} {extra.get('order', '')}".strip()
            print(f"{label:28s} {tag:20s} run {med:6.2f} s (budget {budget:g} s: "
                  f"{'met' if med < budget else 'MISSED'}); setup {r.timings['setup_s']:.2f} s, "
                  f"solve {r.timings['solve_s']:.2f} s")
            out["runs"][f"{h}/{tag}"] = med
            rec.save()


if __name__ == "__main__":
    main()
