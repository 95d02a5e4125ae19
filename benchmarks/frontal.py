"""The 3D runs' whole-matrix float32 factor: SuperLU (``single_precision_factor`` without
the tree, the path before) against the multifrontal
:class:`~pdverify.solvers.frontal.FrontalLU`, side by side.

Plain script (no test runner):

    python benchmarks/frontal.py --dir DIR [--case NAME ...] [--repeat N] [--merge M ...]

A case is a system as ``solve_nested(A, rhs, coords)`` receives it, saved as
``DIR/NAME/{A.npz,b.npy,c.npy}`` (see ``benchmarks/mixed_precision.py`` for how a run's
system is captured). Each alternative runs in a fresh process (its peak memory,
``ru_maxrss``, is its own), one BLAS thread (as the report's workers), the alternatives
alternating, median of ``--repeat`` (default 3): the factor's time and stored entries,
then ``refine_with_probe`` on it: plain steps, whether GMRES-IR was needed, its time, and
the refined solution's largest difference to SuperLU's refined solution, relative to the
largest entry, on the displacements (the first 8,000 entries: a Taylor system's remaining
unknowns are not unique) and on all entries.

``--merge M ...``: instead, in one process per case, FrontalLU's factor time and entries
for each merge size (subtrees of at most M unknowns one front), alternating, median of
``--repeat``, and the float32 factor's accuracy: the largest error of its solve with A and
with A^T of A x = b for a random x, relative to max |x| (SuperLU's float32 factor for
comparison, once).
"""
from __future__ import annotations

import argparse
import json
import os
import resource
import sys
import tempfile
import time

import numpy as np

import harness

#: per case, how many leading entries of x are the displacements (the Taylor systems'
#: remaining unknowns are not unique: two exact solvers differ there by up to 2e-2)
CASES = {"traction-taylor1": 8000, "manufactured-taylor2": 8000, "manufactured-snm3": 8000}
ALTERNATIVES = ("superlu", "frontal")


def _load(directory, case):
    import scipy.sparse as sp
    d = os.path.join(directory, case)
    return (sp.load_npz(os.path.join(d, "A.npz")).tocsr(), np.load(os.path.join(d, "b.npy")),
            np.load(os.path.join(d, "c.npy")))


def worker(directory, case, alternative, out, merge):
    """One alternative in this (fresh) process: prints a JSON line, saves the solution."""
    from threadpoolctl import threadpool_limits

    from pdverify.solvers.frontal import FrontalLU
    from pdverify.solvers.mixed import refine_with_probe
    from pdverify.solvers.nested import ordered_system, single_precision_factor
    A, b, c = _load(directory, case)
    A_p, b_p, perm, (n1, n2), col_max, tree = ordered_system(A, b, c, case, tree=True)
    del A
    with threadpool_limits(1):
        t = time.perf_counter()
        if alternative == "superlu":
            lu, _ = single_precision_factor(A_p, n1, n2)
        else:
            lu = FrontalLU(A_p, tree, merge=merge)
        t_factor = time.perf_counter() - t
        t = time.perf_counter()
        y, cond, diag = refine_with_probe(A_p, b_p, lu)
        t_refine = time.perf_counter() - t
    x = np.full(b.size, np.nan)
    if y is not None:
        x[perm] = y
        x /= col_max
    np.save(out, x)
    print(json.dumps(dict(factor_s=t_factor, entries=int(lu.factor_entries),
                          steps=diag.get("refinement_steps"),
                          gmres=diag.get("refinement") == "GMRES-IR",
                          refine_s=t_refine, condition=cond,
                          maxrss_mb=resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024)))


def _run(directory, case, alternative, out, merge):
    return harness.fresh([sys.executable, __file__, "--worker", directory, case, alternative,
                          out, str(merge)], threads=1)


def compare(directory, cases, repeat, merge, rec):
    with tempfile.TemporaryDirectory() as tmp:
        for case in cases:
            # alternating, the order swapped every round (harness.alternate rotates it)
            timed = harness.alternate(
                {a: (lambda a=a: _run(directory, case, a, os.path.join(tmp, f"{case}-{a}.npy"),
                                      merge)) for a in ALTERNATIVES}, repeat)
            rows = {a: t.results for a, t in timed.items()}
            sols = {a: np.load(os.path.join(tmp, f"{case}-{a}.npy")) for a in ALTERNATIVES}
            unique = CASES.get(case)
            ref = sols["superlu"][:unique]
            print(f"{case} ({sols['superlu'].size} unknowns; compared: "
                  f"{ref.size} entries), medians of {repeat}, one BLAS thread")
            print(f"  {'':8s} {'factor s':>9s} {'entries M':>10s} {'steps':>6s} "
                  f"{'GMRES-IR':>8s} {'refine s':>9s} {'peak MB':>8s} {'diff u':>9s} "
                  f"{'diff all':>9s}")
            for a in ALTERNATIVES:
                med = {k: harness.median(row[k] for row in rows[a])
                       for k in ("factor_s", "refine_s", "maxrss_mb")}
                diff = np.max(np.abs(sols[a][:unique] - ref)) / np.max(np.abs(ref))
                whole = (np.max(np.abs(sols[a] - sols["superlu"]))
                         / np.max(np.abs(sols["superlu"])))
                print(f"  {a:8s} {med['factor_s']:9.2f} {rows[a][0]['entries'] / 1e6:10.1f} "
                      f"{rows[a][0]['steps']!s:>6s} {rows[a][0]['gmres']!s:>8s} "
                      f"{med['refine_s']:9.2f} {med['maxrss_mb']:8.0f} {diff:9.1e} "
                      f"{whole:9.1e}")
                print(f"    factor times {[round(x['factor_s'], 2) for x in rows[a]]}, "
                      f"condition {rows[a][0]['condition']:.2e}")
                rec[f"{case} {a}"] = {"median": med, "rounds": rows[a], "diff_u": diff,
                                      "diff_all": whole}


def merges(directory, cases, repeat, sizes, rec):
    from threadpoolctl import threadpool_limits

    from pdverify.solvers.frontal import FrontalLU
    from pdverify.solvers.nested import ordered_system, single_precision_factor
    for case in cases:
        A, b, c = _load(directory, case)
        A_p, _, _, (n1, n2), _, tree = ordered_system(A, b, c, case, tree=True)
        times = {m: [] for m in sizes}
        entries = {}
        errors = {}
        x = np.random.default_rng(0).standard_normal(A_p.shape[0])
        A_t = A_p.T.tocsr()

        def accuracy(lu):
            return [np.max(np.abs(lu.solve(M @ x, trans=t) - x)) / np.max(np.abs(x))
                    for M, t in ((A_p, "N"), (A_t, "T"))]
        with threadpool_limits(1):
            t = time.perf_counter()
            lu, _ = single_precision_factor(A_p, n1, n2)
            print(f"{case} SuperLU float32: factor {time.perf_counter() - t:6.2f} s, "
                  f"{lu.factor_entries / 1e6:.1f} M entries, solve error "
                  f"{accuracy(lu)[0]:.1e} (A), {accuracy(lu)[1]:.1e} (A^T)")
            del lu

            def one(m):
                t = time.perf_counter()
                lu = FrontalLU(A_p, tree, merge=m)
                times[m].append(time.perf_counter() - t)
                entries[m] = (lu.factor_entries, len(lu.fronts))
                errors[m] = accuracy(lu)
            harness.alternate({m: (lambda m=m: one(m)) for m in sizes}, repeat)
        for m in sizes:
            rec[f"{case} merge {m}"] = {"factor_s": times[m], "entries": entries[m][0],
                                        "fronts": entries[m][1], "solve_errors": errors[m]}
            print(f"{case} merge {m:5d}: factor {harness.median(times[m]):6.2f} s "
                  f"(median of {repeat}), {entries[m][0] / 1e6:.1f} M entries, "
                  f"{entries[m][1]} fronts, solve error {errors[m][0]:.1e} (A), "
                  f"{errors[m][1]:.1e} (A^T)")


def main(argv=None):
    argv = sys.argv[1:] if argv is None else argv
    if argv and argv[0] == "--worker":
        directory, case, alternative, out, merge = argv[1:6]
        worker(directory, case, alternative, out, int(merge))
        return
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--dir", required=True,
                   help="the folder of the saved systems, one subfolder NAME each")
    p.add_argument("--case", nargs="*", default=list(CASES))
    p.add_argument("--repeat", type=int, default=3)
    p.add_argument("--merge", type=int, nargs="*")
    harness.add_arguments(p)
    args = p.parse_args(argv)
    with harness.Record(__file__, args, argv=argv) as rec:
        if args.merge:
            merges(args.dir, args.case, args.repeat, args.merge, rec)
        else:
            from pdverify.solvers.frontal import MERGE_SIZE
            rec["merge_size"] = MERGE_SIZE
            compare(args.dir, args.case, args.repeat, MERGE_SIZE, rec)


if __name__ == "__main__":
    main()
