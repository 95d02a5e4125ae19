"""GMRES-IR's inner solver: pdverify's flexible GMRES (``pdverify.solvers.mixed._fgmres``,
right preconditioned, the basis of preconditioned vectors kept) against scipy's
``scipy.sparse.linalg.gmres`` preconditioned by the same float32 factor, left
(``M=``, scipy's own) and right (GMRES on A M, z = M y), on ill-conditioned lattice systems
(the test suite's ``ill_conditioned``: a symmetric lattice operator shifted to within
~1/kappa of singular) solved by ``solve_nested(..., mixed=True)``.

For each kappa and variant: what the solve ended with (mixed precision kept, or the double
LU taking over), the refinement path, the solution's error against a double LU, and the
median time of ``--repeat`` runs (one process, alternating variants).

The report's own systems never reach GMRES-IR (its float32 runs all converge by plain
refinement: ``results.json`` records no ``refinement = GMRES-IR``), so this is the piece's
whole use: the fallback for systems near 1/eps_single.

Usage: python benchmarks/gmres_ir.py [--repeat 3] [--no-record]
"""
from __future__ import annotations

import argparse
import statistics
import sys
import time
from pathlib import Path

import numpy as np
import scipy.sparse.linalg as spla

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from pdverify.solvers import mixed  # noqa: E402
from pdverify.solvers.nested import solve_nested  # noqa: E402
# the test suite's ill-conditioned lattice systems (the GMRES-IR tests solve them)
from tests.pdverify.test_split_lu import ill_conditioned  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parent))
import harness  # noqa: E402

OURS = mixed._fgmres


def _scaled(r):
    big = float(np.abs(r).max()) if r.size else 0.0
    if big == 0.0 or not np.isfinite(big):
        return None, 1.0
    return r, float(np.exp2(np.round(np.log2(big))))


def scipy_gmres(A, r, precondition, *, max_iterations=None, extended_tol=0.0, side="left"):
    """scipy's GMRES on the same factor: ``M=`` (``side="left"``, scipy's own), or on the
    operator A M with z = M y (``"right"``; not flexible: M must be linear)."""
    r, scale = _scaled(r)
    if r is None:
        return np.zeros(A.shape[0]), 0
    m = max(mixed.GMRES_MAX_ITERATIONS, max_iterations or 0)
    count = [0]
    M = spla.LinearOperator(A.shape, matvec=precondition, dtype=float)
    op = A if side == "left" else spla.LinearOperator(
        A.shape, matvec=lambda v: A @ precondition(v), dtype=float)
    with np.errstate(all="ignore"):
        y, _ = spla.gmres(op, r / scale, rtol=mixed.GMRES_INNER_TOL, atol=0.0, restart=m,
                          maxiter=1, M=M if side == "left" else None,
                          callback=lambda _r: count.__setitem__(0, count[0] + 1),
                          callback_type="pr_norm")
        z = y if side == "left" else precondition(y)
    return z * scale, count[0]


def scipy_left(A, r, precondition, **kw):
    return scipy_gmres(A, r, precondition, side="left", **kw)


def scipy_right(A, r, precondition, **kw):
    return scipy_gmres(A, r, precondition, side="right", **kw)


VARIANTS = {"pdverify FGMRES": OURS, "scipy gmres, left M": scipy_left,
            "scipy gmres on A M (right)": scipy_right}


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--kappa", type=float, nargs="*", default=[1e7, 1e8, 1e9, 1e10])
    harness.add_arguments(ap)
    args = ap.parse_args(argv)
    with harness.Record(__file__, args) as rec:
        rec["rows"] = _measure(args, rec)


def _measure(args, rec):
    rows = []
    for kappa in args.kappa:
        A, x = ill_conditioned(kappa, n=32)
        b = np.random.default_rng(6).normal(size=A.shape[0])
        exact = spla.spsolve(A.tocsc(), b)
        times = {k: [] for k in VARIANTS}
        outcome = {}
        for _ in range(args.repeat):
            for name, fn in VARIANTS.items():
                mixed._fgmres = fn
                t0 = time.perf_counter()
                u, info = solve_nested(A, b, x, where="bench", mixed=True)
                times[name].append(time.perf_counter() - t0)
                outcome[name] = (info.get("mixed_precision", ""), info.get("refinement", "plain"),
                                 float(np.linalg.norm(u - exact) / np.linalg.norm(exact)))
        mixed._fgmres = OURS
        for name in VARIANTS:
            kept, path, err = outcome[name]
            rows.append({"kappa": kappa, "variant": name, "median_s": statistics.median(times[name]),
                         "kept_float32": kept.startswith("float32"), "path": path,
                         "ended": kept, "error_vs_double_lu": err})
            print(f"kappa {kappa:7.0e}  {name:28s} {statistics.median(times[name]):7.3f} s  "
                  f"{'float32 kept' if kept.startswith('float32') else 'double LU took over':20s}"
                  f"  {path:9s} err {err:.1e}")
        rec["rows"] = rows
        rec.save()
    return rows


if __name__ == "__main__":
    main()
