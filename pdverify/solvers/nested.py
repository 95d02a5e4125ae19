"""Sparse LU under a geometric nested-dissection ordering
(:func:`pdverify.solvers.ordering.nested_dissection`), in double precision or, from
:data:`~pdverify.solvers.policy.MIXED_FROM_UNKNOWNS` unknowns, as a single-precision
:class:`SingleLU` (SuperLU's; in 3D the multifrontal
:class:`~pdverify.solvers.frontal.FrontalLU`) refined in double (:mod:`pdverify.solvers.mixed`)."""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from . import policy
from .checks import (checked_condition, equilibrate, refuse_near_singular, refuse_non_finite,
                     relative_residual)
from .lu import factor
from .frontal import FrontalLU
from .mixed import refine_with_probe, scaled_solve
from .ordering import nested_dissection

#: SuperLU's diagonal pivot threshold under the nested-dissection ordering: a diagonal
#: entry is kept as pivot unless it is below 1e-3 of its column's largest, so the ordering
#: survives; 1e-2 is as accurate, full partial pivoting 9.8x slower (record
#: solvers-2026-11-22-nd-pivot-threshold).
ND_PIVOT_THRESHOLD = 1e-3
ND_OPTIONS = dict(permc_spec="NATURAL", diag_pivot_thresh=ND_PIVOT_THRESHOLD,
                  options=dict(SymmetricMode=True))

#: ... and the single-precision factor's (:class:`SingleLU`): 0.1 (issue 32), which bounds
#: the element growth that eps_single multiplies: on the 3D boxes' systems whose plain
#: refinement stalls at 1e-3 it converges, and the report's five 3D runs that took
#: GMRES-IR at 1e-3 ran 1.3-2.8x faster (record mixed_precision-2026-11-26-threshold). At
#: 1e-3 (ND_PIVOT_THRESHOLD, kept for the double factor) the symmetric 576-unknown
#: operator with 200 small eigenvalues of tests/pdverify/test_split_lu.py (kappa 1e8)
#: converges by GMRES-IR, at 0.1 by neither refinement (the double LU then solves it).
FLOAT32_PIVOT_THRESHOLD = 0.1


def _options(dtype):
    """SuperLU's options of a :class:`SingleLU` factor of this ``dtype``."""
    if np.dtype(dtype) == np.float32:
        return {**ND_OPTIONS, "diag_pivot_thresh": FLOAT32_PIVOT_THRESHOLD}
    return ND_OPTIONS


#: The float32 factor of a system whose top separator is large (the 3D boxes:
#: :func:`~pdverify.solvers.policy.frontal_factor`) is the multifrontal
#: :class:`~pdverify.solvers.frontal.FrontalLU` (dense BLAS-3 fronts), with SuperLU's as
#: the fallback when it fails (issue 32): body3d-traction's order-1 Taylor factor 27.7 ->
#: 6.3 s, the report's metrics the same to 1e-9 relative (record
#: frontal-2026-11-27-superlu-frontal).
FRONTAL_FACTOR = True


class NestedFactor:
    """Sparse LU of the square ``A`` under a geometric nested-dissection ordering
    (:func:`pdverify.solvers.ordering.nested_dissection`; ``coords``: one row per
    unknown), after the equilibration of :func:`~pdverify.solvers.checks.equilibrate`.

    ``mixed`` (default: :func:`~pdverify.solvers.policy.mixed_precision`): factor in single
    precision (:func:`single_precision_factor`: SuperLU's, or
    :class:`~pdverify.solvers.frontal.FrontalLU` when the top separator is large) and
    refine each solve in double as LAPACK's dsgesv does, or, when that stalls (condition ~1/eps_single = 1.7e7), by GMRES preconditioned
    with the same factor (:mod:`~pdverify.solvers.mixed`); a system whose single-precision
    factor fails or that neither refinement solves is factored in double instead (once),
    with the reason in the diagnostics (``mixed_precision``). A random right-hand side is
    refined alongside (a near-singular system cannot converge on it) and gives the
    condition estimate (:func:`~pdverify.solvers.mixed.probe_condition_estimate`).
    :meth:`solve` checks each solution (:class:`NumericalError` naming ``where``) and
    leaves its diagnostics in :attr:`info`: the refinement's steps and relative residuals
    (``refinement_steps``, ``refinement_residuals``, the probe's final residual
    ``refinement_probe_residual``), the top separator's size and the separator rows
    pivoted into a half."""

    def __init__(self, A, coords, *, where: str = "static solve", mixed: bool | None = None):
        A = sp.csr_matrix(A)
        refuse_non_finite(where, A)
        self.A, self.where = A, where
        n = A.shape[0]
        self.A_p, self.row_max, self.perm, (n1, n2), self.col_max, tree = ordered_matrix(
            A, coords, where)
        self.mixed = policy.mixed_precision(n) if mixed is None else mixed
        self.single = self.single_note = self.single_failed = None
        if self.mixed:
            try:
                self.single, self.single_note = single_precision_factor(self.A_p, n1, n2, tree)
            except RuntimeError as exc:  # "Factor is exactly singular" in single precision
                self.single_failed = (f"not used: single-precision factor failed ({exc}); "
                                      "double LU")
        self.double = None
        self.info: dict = {}

    def _double(self):
        """SuperLU's double factor (made once, when first needed)."""
        if self.double is None:
            # SuperLU takes CSC: the CSR copy goes before the factor is made (memory)
            self.A_p = self.A_p.tocsc()
            self.double = factor(self.A_p, self.where, **ND_OPTIONS)
        return self.double

    def solve(self, rhs) -> np.ndarray:
        rhs = np.asarray(rhs, dtype=float)
        refuse_non_finite(self.where, rhs)
        b_p = (rhs / self.row_max)[self.perm]
        info: dict = {"unknowns": int(self.A.shape[0])}
        y = None
        if self.single is not None:
            y, cond, diag = _refined(self.A_p, b_p, self.single, self.single_note)
            info.update(diag)
        elif self.single_failed is not None:
            info["mixed_precision"] = self.single_failed
        if y is None:
            lu = self._double()
            y = lu.solve(b_p)
            cond = checked_condition(y, self.A_p, lu, self.where)
            info["factor_entries"] = int(lu.nnz)
            info["solver"] = "sparse LU (SuperLU, nested-dissection ordering)"
        else:
            refuse_near_singular(cond, self.where)
        sol = np.empty_like(y)
        sol[self.perm] = y
        sol /= self.col_max
        info["relative_residual"] = relative_residual(self.A, sol, rhs)
        info["condition_estimate"] = float(cond)   # of the equilibrated system
        self.info = info
        return sol


def solve_nested(A, rhs, coords, *, where: str = "static solve", mixed: bool | None = None):
    """Solve the square system A x = rhs by :class:`NestedFactor` (its docstring: the
    ordering, ``mixed``, the checks and the diagnostics). Returns ``(x, info)``."""
    rhs = np.asarray(rhs, dtype=float)
    refuse_non_finite(where, rhs)         # A: by the factor, before its work
    lu = NestedFactor(A, coords, where=where, mixed=mixed)
    x = lu.solve(rhs)
    return x, lu.info


def ordered_matrix(A, coords, where: str):
    """``(A_p, row_max, perm, (n1, n2), col_max, tree)``: ``A`` equilibrated
    (:func:`~pdverify.solvers.checks.equilibrate`) and permuted to the geometric
    nested-dissection order (``perm``; the top split's halves ``n1``, ``n2``; the
    ordering's separator tree); the solution of ``A x = rhs`` is ``x[perm] = y / col_max``
    for ``A_p y = (rhs / row_max)[perm]``."""
    A_s, row_max, col_max = equilibrate(A, where)
    perm, halves, tree = nested_dissection(A_s, coords, top_split=True, tree=True)
    A_p = A_s[perm][:, perm].tocsr()
    del A_s     # memory: one copy of the system fewer while it is factored (issue 32)
    return A_p, row_max, perm, halves, col_max, tree


def ordered_system(A, rhs, coords, where: str, *, tree: bool = False):
    """:func:`ordered_matrix` with the right-hand side permuted alongside:
    ``(A_p, b_p, perm, (n1, n2), col_max)`` (``tree=True``: and the separator tree)."""
    A_p, row_max, perm, halves, col_max, sep_tree = ordered_matrix(A, coords, where)
    out = (A_p, (np.asarray(rhs, dtype=float) / row_max)[perm], perm, halves, col_max)
    return out + ((sep_tree,) if tree else ())


def single_precision_factor(A_p, n1: int, n2: int, tree=None):
    """``(lu, note)``: the float32 factor of the equilibrated, permuted ``A_p``: given the
    ordering's separator ``tree``, the multifrontal
    :class:`~pdverify.solvers.frontal.FrontalLU` when the top separator (``A_p``'s
    unknowns beyond the halves ``n1``, ``n2``) is large
    (:func:`~pdverify.solvers.policy.frontal_factor`; :data:`FRONTAL_FACTOR`), else (and
    when that fails) SuperLU's (:class:`SingleLU`); ``note`` says which and why. Raises
    RuntimeError when SuperLU's float32 factor fails."""
    note = ""
    separator = A_p.shape[0] - n1 - n2
    if (FRONTAL_FACTOR and tree is not None and n1 and n2
            and policy.frontal_factor(separator, A_p.shape[0])):
        note = f" (multifrontal: top separator of {separator} unknowns)"
        try:
            return FrontalLU(A_p, tree), note
        except RuntimeError as exc:
            note = f" (SuperLU: the multifrontal factor failed: {exc})"
    return SingleLU(A_p), note


def _refined(A_p, b_p, lu, note: str):
    """Refinement in double (:func:`~pdverify.solvers.mixed.refine_with_probe`) of the
    equilibrated, permuted ``A_p y = b_p`` with the single-precision factor ``lu``
    (:func:`single_precision_factor`, whose ``note`` says how it was made):
    ``(y, condition estimate, diagnostics)``, or ``(None, None, diagnostics)`` with the
    reason in ``diagnostics['mixed_precision']`` when the double LU must take over."""
    y, cond, diag = refine_with_probe(A_p, b_p, lu)
    if y is None:
        return None, None, diag
    gmres = diag.get("refinement") == "GMRES-IR"
    diag.update(mixed_precision="float32 LU" + note + (
                    ", refined in float64 by GMRES-IR (plain refinement stalled)" if gmres
                    else ", refined in float64 (LAPACK dsgesv's test)"),
                factor_entries=lu.factor_entries,
                solver=f"sparse LU ({getattr(lu, 'kind', 'SuperLU')} in float32 + "
                       + ("GMRES-IR" if gmres else
                                                             "refinement")
                       + ", nested-dissection ordering)")
    return y, cond, diag


class SingleLU:
    """SuperLU's LU of the whole ``A`` in single precision (``dtype``), under the
    nested-dissection order ``A`` is given in (SuperLU's ``NATURAL`` column order,
    symmetric mode, :data:`FLOAT32_PIVOT_THRESHOLD`). ``solve(B, trans="N")`` takes one or
    several right-hand sides, each column scaled by a power of two
    (:func:`~pdverify.solvers.mixed.scaled_solve`); ``trans="T"`` solves with A^T
    (SuperLU's convention). Raises RuntimeError (from SuperLU) when the factor fails.

    It replaced ``SplitLU`` (the two halves of the top split factored in two threads, the
    separator by a dense Schur complement; issue 51): on the report's seven largest 2D
    float32 runs it took 6.9 s of CPU against SplitLU's 8.9 s, with less memory (record
    split_lu-2026-11-28-all-cases): under ``report --jobs`` every core is busy, so the
    split's second thread bought nothing."""

    kind = "SuperLU"

    def __init__(self, A, dtype=np.float32):
        self.dtype = dtype
        self.lu = spla.splu(sp.csc_matrix(A).astype(dtype), **_options(dtype))
        self.factor_entries = int(self.lu.nnz)

    def solve(self, b, trans: str = "N"):
        return scaled_solve(b, trans, self._solve)

    def _solve(self, b, trans):
        return self.lu.solve(np.asarray(b, dtype=self.dtype), trans=trans).astype(float)
