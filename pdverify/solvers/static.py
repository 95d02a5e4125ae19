"""Direct sparse static solve with constraints by Lagrange multipliers (seed 000 Eq. 63)."""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from ..errors import NumericalError
from ..metrics import scaled_norm
from .ordering import nested_dissection

#: Above this 1-norm condition estimate the solution has lost (almost) every digit of
#: double precision (eps ~ 2.2e-16), so the run is refused as near-singular.
CONDITION_LIMIT = 1e14
#: Above this condition estimate a run stays ``ok`` but carries a warning: its solution is
#: trustworthy only to about kappa * eps >= 1e-6 relative, so smaller errors it reports
#: are round-off, not the method (e.g. bar1d-traction order 20 at 100 cells: 2.3e12).
WARN_CONDITION = 1e-6 / np.finfo(float).eps


#: SuperLU options for a symmetric positive definite K (no constraint rows): minimum
#: degree on A + A^T and diagonal pivots, which keep the symmetric fill; on a 2D
#: bond-based sheet (10k unknowns, 1.5 M non-zeros) 0.74 s against 1.87 s with the
#: default COLAMD column ordering (benchmarks/sheet_solvers.py).
SPD_OPTIONS = dict(permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.0,
                   options=dict(SymmetricMode=True))

# ``ordering`` of solve_constrained is SuperLU's permc_spec (COLAMD, MMD_AT_PLUS_A,
# MMD_ATA, NATURAL). Measured, not assumed (benchmarks/plate_solvers.py): minimum degree
# on A + A^T is ~3x faster than the default COLAMD on the seed-000 plate's Lagrange system,
# but ~1.6x slower on the seed-001 surface-node plate, so each scene states its choice.


def solve_constrained(K, f, B=None, c=None, *, where: str = "static solve", spd: bool = False,
                      ordering: str = "COLAMD"):
    """Solve [[K, B^T], [B, 0]] [u; lam] = [f; c] with a sparse LU factorisation.

    ``spd=True`` (only without constraints) declares K symmetric positive definite and
    factors it in SuperLU's symmetric mode (:data:`SPD_OPTIONS`); the residual and
    condition checks below guard the claim. Otherwise ``ordering`` is SuperLU's column
    ordering (``permc_spec``), with partial pivoting.

    Returns ``(u, lam, info)``; ``info`` holds the system size, the relative residual
    and a 1-norm condition estimate. Singular or near-singular systems, and non-finite
    solutions, raise :class:`NumericalError` naming ``where``.
    """
    K = sp.csr_matrix(K)
    n = K.shape[0]
    if B is not None and np.size(B):
        B = sp.csr_matrix(np.atleast_2d(B) if not sp.issparse(B) else B)
        c = np.atleast_1d(np.asarray(c, dtype=float))
        A = sp.bmat([[K, B.T], [B, None]], format="csc")
        rhs = np.concatenate([np.asarray(f, dtype=float), c])
    else:
        A = K.tocsc()
        rhs = np.asarray(f, dtype=float)
    if not np.all(np.isfinite(A.data)) or not np.all(np.isfinite(rhs)):
        raise NumericalError(f"{where}: the system has non-finite entries")
    A_s, row_max, col_max = equilibrate(A, where)
    A_s = A_s.tocsc()
    lu = _factor(A_s, where, **(SPD_OPTIONS if spd and B is None else {"permc_spec": ordering}))
    sol = lu.solve(rhs / row_max) / col_max
    cond = _checked_condition(sol, A_s, lu, where)
    info = {"unknowns": int(A.shape[0]), "relative_residual": relative_residual(A, sol, rhs),
            "condition_estimate": float(cond),  # of the equilibrated system
            "solver": "sparse LU (SuperLU, " + ("symmetric mode)" if spd and B is None
                                                else f"{ordering} ordering)")}
    return sol[:n], sol[n:], info


#: SuperLU's diagonal pivot threshold under the nested-dissection ordering: a diagonal
#: entry is kept as pivot unless it is below 1e-3 of its column's largest, so the ordering
#: survives. Measured on the plane-strain plate's augmented system at h = 0.01 (a side
#: measurement): 1e-3 and 1e-2 give the same accuracy (solution error 7e-13, PARDISO's
#: 6e-13); 0.1 is 1.7x slower, and 1.0 (full partial pivoting) 9.8x slower with 3.3x the
#: fill.
ND_PIVOT_THRESHOLD = 1e-3


def solve_nested(A, rhs, coords, *, where: str = "static solve"):
    """Solve the square system A x = rhs by sparse LU under a geometric nested-dissection
    ordering (:func:`pdverify.solvers.ordering.nested_dissection`; ``coords``: one row
    per unknown). Same checks and diagnostics as :func:`solve_constrained`: equilibration,
    a 1-norm condition estimate, :class:`NumericalError` on (near-)singular systems."""
    A = sp.csr_matrix(A)
    rhs = np.asarray(rhs, dtype=float)
    if not np.all(np.isfinite(A.data)) or not np.all(np.isfinite(rhs)):
        raise NumericalError(f"{where}: the system has non-finite entries")
    A_s, row_max, col_max = equilibrate(A, where)
    perm = nested_dissection(A_s, coords)
    A_p = A_s[perm][:, perm].tocsc()
    lu = _factor(A_p, where, permc_spec="NATURAL", diag_pivot_thresh=ND_PIVOT_THRESHOLD,
                 options=dict(SymmetricMode=True))
    y = np.empty_like(rhs)
    y[perm] = lu.solve((rhs / row_max)[perm])
    sol = y / col_max
    cond = _checked_condition(sol, A_p, lu, where)
    return sol, {"unknowns": int(A.shape[0]), "relative_residual": relative_residual(A, sol, rhs),
                 "condition_estimate": float(cond), "factor_entries": int(lu.L.nnz + lu.U.nnz),
                 "solver": "sparse LU (SuperLU, nested-dissection ordering)"}


def _factor(A, where: str, **options):
    """SuperLU of the equilibrated ``A``; an exactly singular factor is a NumericalError."""
    try:
        return spla.splu(A, **options)
    except RuntimeError as exc:  # "Factor is exactly singular"
        raise NumericalError(f"{where}: singular system of size {A.shape[0]} ({exc})") from None


def _checked_condition(sol, A, lu, where: str) -> float:
    """The condition estimate of the factored ``A``, after refusing a non-finite solution
    or a near-singular system (NumericalError naming ``where``)."""
    if not np.all(np.isfinite(sol)):
        raise NumericalError(f"{where}: solution has non-finite values (singular system)")
    cond = _condition_estimate(A, lu)
    if cond > CONDITION_LIMIT:
        raise NumericalError(f"{where}: near-singular system (condition estimate {cond:.2e} "
                             f"> {CONDITION_LIMIT:.0e} after equilibration)")
    return cond


def relative_residual(A, x, b) -> float:
    """||A x - b|| / max(||b||, max|A| ||x||), scale-free: x and b are divided by max |x|
    first (and the norms are :func:`~pdverify.metrics.scaled_norm`), so solutions of
    1e+-300 neither overflow nor underflow."""
    s = float(np.max(np.abs(x))) if np.size(x) else 0.0
    if s == 0.0 or not np.isfinite(s):
        return 0.0 if s == 0.0 and not np.any(b) else float("inf")
    xs, bs = x / s, np.asarray(b, dtype=float) / s
    denom = max(scaled_norm(bs), float(abs(A).max()) * scaled_norm(xs), 1e-300)
    return float(scaled_norm(A @ xs - bs) / denom)


def equilibrate(A, where: str):
    """Row then column max-scaling of a sparse matrix: ``(A_scaled, row_max, col_max)``.

    Constraint rows (dimensionless Dirichlet rows, force-flux rows) and stiffness rows
    differ by many orders of magnitude, which would inflate a condition estimate without
    any loss of accuracy. An empty row or column is a singular system (NumericalError).
    Solve A x = b as A_scaled y = b / row_max, x = y / col_max.
    """
    A = sp.csr_matrix(A)
    row_max = abs(A).max(axis=1).toarray().ravel()
    if np.any(row_max == 0):
        raise NumericalError(f"{where}: singular system (equation {int(np.argmin(row_max))} "
                             "has no entries)")
    A_r = sp.diags(1.0 / row_max) @ A
    col_max = abs(A_r).max(axis=0).toarray().ravel()
    if np.any(col_max == 0):
        raise NumericalError(f"{where}: singular system (unknown {int(np.argmin(col_max))} "
                             "appears in no equation)")
    return (A_r @ sp.diags(1.0 / col_max)).tocsr(), row_max, col_max


def _condition_estimate(A, lu) -> float:
    """kappa_1(A) ~ ||A||_1 ||A^-1||_1: ||A||_1 exactly, ||A^-1||_1 by Higham's estimator
    on the LU solves. The estimator draws random +-1 start vectors from NumPy's global
    generator; it is seeded here (and the caller's state restored) so that the same system
    always gets the same estimate, and hence the same accept/refuse verdict."""
    n = A.shape[0]
    if n <= 2:
        return float(np.linalg.cond(A.toarray(), 1))
    inv = spla.LinearOperator(A.shape, matvec=lu.solve, rmatvec=lambda v: lu.solve(v, trans="T"),
                              dtype=float)
    norm_a = float(abs(A).sum(axis=0).max())
    state = np.random.get_state()
    try:
        np.random.seed(20211121)
        return norm_a * float(spla.onenormest(inv))
    finally:
        np.random.set_state(state)
