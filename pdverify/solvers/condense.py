"""Elimination of prescribed unknowns (scikit-fem's ``condense`` is the model): the system
left after u[fixed] = values, and the map from its solution back to every unknown. No
solver here: :func:`pdverify.solvers.front.solve_with_dirichlet` condenses, solves and
expands."""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp


class Expansion:
    """The way back from a condensed system: ``free`` (the unknowns kept, ascending) and
    ``values`` (every unknown, the prescribed ones holding their values, the free ones 0).
    ``expansion(u_free)`` is the full solution (a new array)."""

    def __init__(self, free: np.ndarray, values: np.ndarray):
        self.free = free
        self.values = values

    def __call__(self, u_free) -> np.ndarray:
        u = self.values.copy()
        u[self.free] = u_free
        return u


def condense(K, f, fixed, values):
    """The system left after prescribing u[fixed] = values: ``(K_ff, f_f, expand)``.

    ``K_ff`` is K's block of the other (free) unknowns, ``f_f = f[free] - K[free, fixed]
    values``; the prescribed unknowns' own rows (their reactions) are dropped.
    ``expand`` (:class:`Expansion`) turns a solution of the condensed system into the
    full vector and names the free unknowns (``expand.free``)."""
    n = K.shape[0]
    keep = np.ones(n, dtype=bool)
    keep[fixed] = False
    free = np.flatnonzero(keep)          # np.setdiff1d's answer without its np.unique
    u = np.zeros(n)
    u[fixed] = values
    K = sp.csr_matrix(K)
    if K.has_canonical_format:
        # rows, then columns, in CSR: no conversion of K. The same matrix as the CSC route
        # below, entry for entry, and the same sums in the same order, a third of its time
        # (record indentation-2026-11-27-condense-csr); tests/pdverify/test_condense.py
        rows = K[free]
        K_free = rows[:, free]
        r = f[free] - rows[:, fixed] @ u[fixed] if np.size(fixed) else f[free]
        return K_free, r, Expansion(free, u)
    Kc = K.tocsc()
    K_free = Kc[:, free].tocsr()[free]
    r = f[free] - (Kc[:, fixed] @ u[fixed])[free] if np.size(fixed) else f[free]
    return K_free, r, Expansion(free, u)
