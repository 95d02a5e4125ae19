"""Dense LU solve (LAPACK) for systems too full for sparse LU, with the static solver's
checks (:mod:`pdverify.solvers.checks`). Which systems go here is
:func:`pdverify.solvers.policy.dense_lu`'s call, made by the front door."""
from __future__ import annotations

import numpy as np
import scipy.linalg as sl
import scipy.sparse as sp
from scipy.linalg import lapack

from ..errors import NumericalError
from .checks import equilibrate, refuse_near_singular, relative_residual, rounded_estimate


def solve_dense(K, f, *, where: str = "static solve"):
    """Solve the square system K u = f by a dense LAPACK LU (dgetrf).

    Same contract as :func:`pdverify.solvers.lu.solve_constrained` without constraints:
    row then column equilibration, a 1-norm condition estimate of the equilibrated
    matrix (LAPACK gecon), :class:`NumericalError` on singular or near-singular systems.
    Returns ``(u, info)``.
    """
    K = sp.csr_matrix(K)
    n = K.shape[0]
    f = np.asarray(f, dtype=float)
    if not np.all(np.isfinite(K.data)) or not np.all(np.isfinite(f)):
        raise NumericalError(f"{where}: the system has non-finite entries")
    A_s, row_max, col_max = equilibrate(K, where)
    A = A_s.toarray()
    anorm = float(np.abs(A).sum(axis=0).max())
    lu, piv, info_ = lapack.dgetrf(A, overwrite_a=True)
    if info_ > 0:
        raise NumericalError(f"{where}: singular system of size {n} (zero pivot {info_})")
    rcond, _ = lapack.dgecon(lu, anorm, norm="1")
    cond = np.inf if rcond == 0 else rounded_estimate(1.0 / rcond)
    refuse_near_singular(cond, where)
    u = sl.lu_solve((lu, piv), f / row_max, check_finite=False) / col_max
    if not np.all(np.isfinite(u)):
        raise NumericalError(f"{where}: solution has non-finite values (singular system)")
    return u, {"unknowns": int(n), "relative_residual": relative_residual(K, u, f),
               "condition_estimate": float(cond), "solver": "dense LU (LAPACK)"}
