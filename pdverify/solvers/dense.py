"""Dense LU solve (LAPACK) for systems too full for sparse LU, with the static solver's
checks (:mod:`pdverify.solvers.checks`). Which systems go here is
:func:`pdverify.solvers.policy.dense_lu`'s call, made by the front door."""
from __future__ import annotations

import numpy as np
import scipy.linalg as sl
import scipy.sparse as sp
from scipy.linalg import lapack

from ..errors import NumericalError
from .checks import (equilibrate, refuse_near_singular, refuse_non_finite, relative_residual,
                     rounded_estimate)


class DenseFactor:
    """LAPACK's LU (dgetrf) of the equilibrated square ``K`` (row then column
    max-scaling, :func:`~pdverify.solvers.checks.equilibrate`), refused at once when it is
    singular or near-singular (a 1-norm condition estimate of the equilibrated matrix,
    LAPACK gecon; :class:`NumericalError` naming ``where``). :meth:`solve` checks each
    solution and leaves its diagnostics in :attr:`info`."""

    kind = "dense LU (LAPACK)"

    def __init__(self, K, *, where: str = "static solve"):
        K = sp.csr_matrix(K)
        self.K, self.where = K, where
        n = K.shape[0]
        refuse_non_finite(where, K)
        A_s, self.row_max, self.col_max = equilibrate(K, where)
        A = A_s.toarray()
        anorm = float(np.abs(A).sum(axis=0).max())
        self.lu, self.piv, info_ = lapack.dgetrf(A, overwrite_a=True)
        if info_ > 0:
            raise NumericalError(f"{where}: singular system of size {n} (zero pivot {info_})")
        rcond, _ = lapack.dgecon(self.lu, anorm, norm="1")
        self.cond = np.inf if rcond == 0 else rounded_estimate(1.0 / rcond)
        refuse_near_singular(self.cond, where)
        self.info: dict = {}

    def solve(self, f) -> np.ndarray:
        f = np.asarray(f, dtype=float)
        refuse_non_finite(self.where, f)
        u = sl.lu_solve((self.lu, self.piv), f / self.row_max, check_finite=False) / self.col_max
        if not np.all(np.isfinite(u)):
            raise NumericalError(f"{self.where}: solution has non-finite values (singular "
                                 "system)")
        self.info = {"unknowns": int(self.K.shape[0]),
                     "relative_residual": relative_residual(self.K, u, f),
                     "condition_estimate": float(self.cond), "solver": self.kind}
        return u


def solve_dense(K, f, *, where: str = "static solve"):
    """Solve the square system K u = f by a dense LAPACK LU (:class:`DenseFactor`).

    Same contract as :func:`pdverify.solvers.lu.solve_constrained` without constraints:
    row then column equilibration, a 1-norm condition estimate of the equilibrated
    matrix (LAPACK gecon), :class:`NumericalError` on singular or near-singular systems.
    Returns ``(u, info)``.
    """
    f = np.asarray(f, dtype=float)
    refuse_non_finite(where, f)           # K: by the factor, before its work
    lu = DenseFactor(K, where=where)
    u = lu.solve(f)
    return u, lu.info
