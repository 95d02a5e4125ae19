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

Usage: python benchmarks/gmres_ir.py [--repeat 3] [--json FILE]
"""
from __future__ import annotations

import argparse
import json
import statistics
import sys
import time
from pathlib import Path

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from pdverify.solvers import mixed  # noqa: E402
from pdverify.solvers.nested import solve_nested  # noqa: E402

OURS = mixed._fgmres


def _scaled(r):
    big = float(np.abs(r).max()) if r.size else 0.0
    if big == 0.0 or not np.isfinite(big):
        return None, 1.0
    return r, float(np.exp2(np.round(np.log2(big))))


def scipy_left(A, r, precondition, *, max_iterations=None, extended_tol=0.0):
    r, scale = _scaled(r)
    if r is None:
        return np.zeros(A.shape[0]), 0
    m = max(mixed.GMRES_MAX_ITERATIONS, max_iterations or 0)
    count = [0]
    M = spla.LinearOperator(A.shape, matvec=precondition, dtype=float)
    with np.errstate(all="ignore"):
        z, _ = spla.gmres(A, r / scale, rtol=mixed.GMRES_INNER_TOL, atol=0.0, restart=m,
                          maxiter=1, M=M, callback=lambda _r: count.__setitem__(0, count[0] + 1),
                          callback_type="pr_norm")
    return z * scale, count[0]


def scipy_right(A, r, precondition, *, max_iterations=None, extended_tol=0.0):
    r, scale = _scaled(r)
    if r is None:
        return np.zeros(A.shape[0]), 0
    m = max(mixed.GMRES_MAX_ITERATIONS, max_iterations or 0)
    count = [0]
    AM = spla.LinearOperator(A.shape, matvec=lambda v: A @ precondition(v), dtype=float)
    with np.errstate(all="ignore"):
        y, _ = spla.gmres(AM, r / scale, rtol=mixed.GMRES_INNER_TOL, atol=0.0, restart=m,
                          maxiter=1, callback=lambda _r: count.__setitem__(0, count[0] + 1),
                          callback_type="pr_norm")
        z = precondition(y)
    return z * scale, count[0]


VARIANTS = {"pdverify FGMRES": OURS, "scipy gmres, left M": scipy_left,
            "scipy gmres on A M (right)": scipy_right}


def lattice_operator(n, reach, seed=1):
    ij = np.stack(np.meshgrid(np.arange(n), np.arange(n), indexing="ij"), -1).reshape(-1, 2)
    d = np.abs(ij[:, None, :] - ij[None, :, :]).max(-1)
    rng = np.random.default_rng(seed)
    A = np.where(d <= reach, rng.uniform(-1, 0, d.shape), 0.0)
    np.fill_diagonal(A, 0.0)
    np.fill_diagonal(A, -A.sum(1) + 1.0)
    return sp.csr_matrix(A), ij.astype(float)


def ill_conditioned(kappa, n=24, reach=2):
    A, x = lattice_operator(n, reach)
    S = 0.5 * (A + A.T).toarray()
    w = np.linalg.eigvalsh(S)
    S = S - (w[0] - w[-1] / kappa) * np.eye(S.shape[0])
    return sp.csr_matrix(S), x


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--kappa", type=float, nargs="*", default=[1e7, 1e8, 1e9, 1e10])
    ap.add_argument("--json", type=Path)
    args = ap.parse_args(argv)
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
    if args.json:
        args.json.write_text(json.dumps(rows, indent=1))


if __name__ == "__main__":
    main()
