"""The checks every direct solve makes (seed 000 Eq. 63's solve and all that followed):
row and column equilibration, a scale-free relative residual, a reproducible 1-norm
condition estimate, and the refusal of non-finite solutions and near-singular systems
(:data:`~pdverify.solvers.policy.CONDITION_LIMIT`)."""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from ..errors import NumericalError
from ..metrics import scaled_norm
from . import policy


def checked_condition(sol, A, lu, where: str) -> float:
    """The condition estimate of the factored ``A``, after refusing a non-finite solution
    or a near-singular system (NumericalError naming ``where``)."""
    if not np.all(np.isfinite(sol)):
        raise NumericalError(f"{where}: solution has non-finite values (singular system)")
    cond = condition_estimate(A, lu)
    refuse_near_singular(cond, where)
    return cond


def refuse_non_finite(where: str, *arrays) -> None:
    """NumericalError naming ``where`` when any of ``arrays`` (dense, or sparse: its stored
    entries) holds a non-finite value: a system is refused before any work on it."""
    for a in arrays:
        data = a.data if sp.issparse(a) else np.asarray(a, dtype=float)
        if not np.all(np.isfinite(data)):
            raise NumericalError(f"{where}: the system has non-finite entries")


def refuse_near_singular(cond: float, where: str) -> None:
    """NumericalError naming ``where`` when the condition estimate ``cond`` of the
    equilibrated system exceeds :data:`~pdverify.solvers.policy.CONDITION_LIMIT`."""
    if cond > policy.CONDITION_LIMIT:
        raise NumericalError(f"{where}: near-singular system (condition estimate {cond:.2e} "
                             f"> {policy.CONDITION_LIMIT:.0e} after equilibration)")


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
    if not A.has_canonical_format:
        A = A.copy()
        A.sum_duplicates()
    counts = np.diff(A.indptr)
    row_max = np.zeros(A.shape[0])
    filled = counts > 0
    row_max[filled] = np.maximum.reduceat(np.abs(A.data), A.indptr[:-1][filled])
    if np.any(row_max == 0):
        raise NumericalError(f"{where}: singular system (equation {int(np.argmin(row_max))} "
                             "has no entries)")
    # the products (1 / row_max) a_ij and then (1 / col_max) of those, as diagonal
    # scalings by sparse products would form them, without the products' copies
    data = A.data * np.repeat(1.0 / row_max, counts)
    col_max = np.zeros(A.shape[1])
    np.maximum.at(col_max, A.indices, np.abs(data))
    if np.any(col_max == 0):
        raise NumericalError(f"{where}: singular system (unknown {int(np.argmin(col_max))} "
                             "appears in no equation)")
    data *= (1.0 / col_max)[A.indices]
    A_s = sp.csr_matrix((data, A.indices.copy(), A.indptr.copy()), shape=A.shape)
    A_s.eliminate_zeros()       # as the products do: stored zeros are no structure
    return A_s, row_max, col_max


#: significant digits a condition estimate keeps. The estimators' NumPy sums can round
#: differently with the arrays' memory alignment (the same system gave 367.962170351635
#: and 367.9621703516349 in two processes), and an estimate good to a factor of a few
#: has no last bit to keep: rounded, it is the same in every process (a 1-ulp spread
#: straddles a 6-digit rounding boundary with probability ~1e-10).
ESTIMATE_DIGITS = 6


def rounded_estimate(value: float) -> float:
    return float(f"{value:.{ESTIMATE_DIGITS}g}")


def condition_estimate(A, lu) -> float:
    """kappa_1(A) ~ ||A||_1 ||A^-1||_1: ||A||_1 exactly, ||A^-1||_1 by Higham's estimator
    on the LU solves. The estimator draws random +-1 start vectors from NumPy's global
    generator; it is seeded here (and the caller's state restored) so that the same system
    always gets the same estimate, and hence the same accept/refuse verdict."""
    n = A.shape[0]
    if n <= 2:
        return rounded_estimate(np.linalg.cond(A.toarray(), 1))
    inv = spla.LinearOperator(A.shape, matvec=lu.solve, rmatvec=lambda v: lu.solve(v, trans="T"),
                              dtype=float)
    norm_a = float(abs(A).sum(axis=0).max())
    state = np.random.get_state()
    try:
        np.random.seed(20211121)
        return rounded_estimate(norm_a * float(spla.onenormest(inv)))
    finally:
        np.random.set_state(state)
