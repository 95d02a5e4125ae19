"""Direct sparse LU (SuperLU) of a square system, with constraints by Lagrange multipliers
(seed 000 Eq. 63), under the checks of :mod:`pdverify.solvers.checks`."""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from ..errors import NumericalError
from .checks import checked_condition, equilibrate, refuse_non_finite, relative_residual


#: SuperLU options for a symmetric positive definite K (no constraint rows): minimum
#: degree on A + A^T and diagonal pivots, which keep the symmetric fill: 2.8x faster than
#: the default COLAMD on the tension sheet (record sheet_solvers-2026-11-28-repeat-3;
#: earlier sheet_solvers-2026-11-22-spd-options).
SPD_OPTIONS = dict(permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.0,
                   options=dict(SymmetricMode=True))

# ``ordering`` of solve_constrained is SuperLU's permc_spec (COLAMD, MMD_AT_PLUS_A,
# MMD_ATA, NATURAL). Measured, not assumed: minimum degree on A + A^T is ~3x faster than
# COLAMD on the seed-000 plate's Lagrange system, slower on the seed-001 surface-node
# plate (record plate_solvers-2026-11-22-orderings), so each scene states its choice.


class SuperLUFactor:
    """SuperLU's factor of the equilibrated square ``A`` (:func:`~pdverify.solvers.checks.
    equilibrate`): ``spd=True`` declares A symmetric positive definite and factors it in
    SuperLU's symmetric mode (:data:`SPD_OPTIONS`), otherwise ``ordering`` is SuperLU's
    column ordering (``permc_spec``) with partial pivoting. :meth:`solve` checks each
    solution (non-finite values, the condition estimate; :class:`NumericalError` naming
    ``where``) and leaves its diagnostics in :attr:`info`."""

    def __init__(self, A, *, where: str = "static solve", spd: bool = False,
                 ordering: str = "COLAMD"):
        A = sp.csc_matrix(A)
        refuse_non_finite(where, A)
        self.A, self.where = A, where
        A_s, self.row_max, self.col_max = equilibrate(A, where)
        self.A_s = A_s.tocsc()
        self.lu = factor(self.A_s, where, **(SPD_OPTIONS if spd else {"permc_spec": ordering}))
        self.kind = ("sparse LU (SuperLU, " + ("symmetric mode)" if spd
                                               else f"{ordering} ordering)"))
        self.info: dict = {}

    def solve(self, b) -> np.ndarray:
        b = np.asarray(b, dtype=float)
        refuse_non_finite(self.where, b)
        sol = self.lu.solve(b / self.row_max) / self.col_max
        cond = checked_condition(sol, self.A_s, self.lu, self.where)
        self.info = {"unknowns": int(self.A.shape[0]),
                     "relative_residual": relative_residual(self.A, sol, b),
                     "condition_estimate": float(cond),  # of the equilibrated system
                     "solver": self.kind}
        return sol


def solve_constrained(K, f, B=None, c=None, *, where: str = "static solve", spd: bool = False,
                      ordering: str = "COLAMD"):
    """Solve [[K, B^T], [B, 0]] [u; lam] = [f; c] with a sparse LU factorisation
    (:class:`SuperLUFactor`).

    ``spd=True`` (only without constraints) declares K symmetric positive definite and
    factors it in SuperLU's symmetric mode (:data:`SPD_OPTIONS`); the residual and
    condition checks guard the claim. Otherwise ``ordering`` is SuperLU's column
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
        spd = False
    else:
        A = K.tocsc()
        rhs = np.asarray(f, dtype=float)
    refuse_non_finite(where, rhs)         # A: by the factor, before its work
    lu = SuperLUFactor(A, where=where, spd=spd, ordering=ordering)
    sol = lu.solve(rhs)
    return sol[:n], sol[n:], lu.info


def factor(A, where: str, **options):
    """SuperLU of the equilibrated ``A``; an exactly singular factor is a NumericalError."""
    try:
        return spla.splu(A, **options)
    except RuntimeError as exc:  # "Factor is exactly singular"
        raise NumericalError(f"{where}: singular system of size {A.shape[0]} ({exc})") from None

