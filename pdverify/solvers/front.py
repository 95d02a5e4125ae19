"""The solvers' front door (scikit-fem's ``solve(*condense(A, b, D=D), solver=...)`` is
the model): a :class:`~pdverify.pd.problem.LinearSystem` in, its solution and the
solver's diagnostics out. Three things are kept apart: the elimination of prescribed
unknowns (:mod:`~pdverify.solvers.condense`), the choice of solver and every threshold
of it (:mod:`~pdverify.solvers.policy`), and the implementations (``lu``, ``dense``,
``nested``, ``mixed``, ``iterative``). This module only dispatches: which
implementation for which solver name.

Every direct solve goes through one door, :func:`factor`: ``factor(A, precision) ->
Factor``, whose ``solve(b)`` returns the solution and leaves the checks' diagnostics in
``Factor.info`` (the same for every implementation: unknowns, relative residual,
condition estimate of the equilibrated matrix, which solver)."""
from __future__ import annotations

from typing import Protocol, runtime_checkable

import numpy as np
import scipy.sparse as sp

from . import policy
from .checks import refuse_non_finite
from .condense import condense
from .dense import DenseFactor, solve_dense
from .iterative import CondensedOperator, solve_condensed, solve_spd
from .lu import SuperLUFactor, solve_constrained
from .nested import NestedFactor, solve_nested

__all__ = ["factor", "Factor", "PRECISIONS", "solve", "solve_with_dirichlet", "solve_square",
           "solve_constrained", "solve_dense", "solve_nested"]

#: ``factor``'s precisions: ``double`` (an LU in float64), ``mixed`` (a float32 LU whose
#: solves are refined in float64, :mod:`~pdverify.solvers.mixed`; needs the unknowns'
#: coordinates), ``auto`` (``mixed`` from
#: :data:`~pdverify.solvers.policy.MIXED_FROM_UNKNOWNS` unknowns when coordinates are
#: given, else ``double``)
PRECISIONS = ("auto", "double", "mixed")


@runtime_checkable
class Factor(Protocol):
    """What :func:`factor` returns: ``solve(b)`` solves A x = b (and checks x), and
    ``info`` holds the last solve's diagnostics."""

    info: dict

    def solve(self, b) -> np.ndarray: ...


def factor(A, precision: str = "auto", *, where: str, coords=None, spd: bool = False,
           ordering: str = "COLAMD") -> Factor:
    """The factor of the square matrix ``A`` that the solve needs:

    - with the unknowns' ``coords``: sparse LU under their geometric nested-dissection
      ordering (:class:`~pdverify.solvers.nested.NestedFactor`), in ``precision``;
    - without: LAPACK's dense LU when ``A`` is full enough
      (:func:`~pdverify.solvers.policy.dense_lu`;
      :class:`~pdverify.solvers.dense.DenseFactor`), else SuperLU
      (:class:`~pdverify.solvers.lu.SuperLUFactor`; ``spd``: its symmetric mode,
      ``ordering``: its column ordering), both in double.

    Every factor equilibrates ``A`` first and refuses a singular or near-singular one
    (:class:`~pdverify.errors.NumericalError` naming ``where``)."""
    if precision not in PRECISIONS:
        raise ValueError(f"precision={precision!r}: allowed {PRECISIONS}")
    if coords is not None:
        mixed = None if precision == "auto" else precision == "mixed"
        return NestedFactor(A, coords, where=where, mixed=mixed)
    if precision == "mixed":
        raise ValueError(f"{where}: precision='mixed' needs the unknowns' coordinates "
                         "(a nested-dissection ordering)")
    K = sp.csr_matrix(A)
    if policy.dense_lu(K.shape[0], K.nnz):
        return DenseFactor(K, where=where)
    return SuperLUFactor(K, where=where, spd=spd, ordering=ordering)


def solve(system, *, where: str, ordering: str = "COLAMD"):
    """Solve ``system``: constraint rows by Lagrange multipliers when it has them (no
    prescribed unknowns then), else the prescribed unknowns eliminated and the rest
    solved by ``system.solver``; ``ordering``: SuperLU's column ordering of a direct
    solve. Returns ``(x, info)``; ``x`` holds every unknown of the system (multipliers
    dropped). A system that names its own ``ordering`` (``LinearSystem.ordering``) is
    solved with that one. An augmented system (``LinearSystem.scalars``) is solved in the
    form its solver needs (:func:`solve_augmented`)."""
    ordering = getattr(system, "ordering", None) or ordering
    if system.B is not None and np.size(system.fixed):
        raise ValueError(f"{where}: a system with constraint rows has no eliminated "
                         "unknowns")
    if getattr(system, "scalars", 0):
        return solve_augmented(system, where=where, ordering=ordering)
    if system.B is not None:
        x, _lam, info = solve_constrained(system.K, system.rhs, system.B, system.c,
                                          where=where, ordering=ordering)
        return x, info
    coords = None if system.solver == "direct" else system.coords
    return solve_with_dirichlet(system.K, system.rhs, system.fixed, system.values,
                                where=where, solver=system.solver, coords=coords,
                                ordering=ordering)


def condensed(A, scalars: int):
    """``(K, G)``: the augmented ``A = [[A_uu, A_ut], [G, -I]]`` with its last ``scalars``
    unknowns (theta = G u) eliminated, ``K = A_uu + A_ut G``: the products of
    ``StateBasedModel.stiffness`` in its order, so K is that matrix to the last bit."""
    A = sp.csr_matrix(A)
    n = A.shape[0] - int(scalars)
    G = A[n:, :n]
    return (A[:n, :n] + A[:n, n:] @ G).tocsr(), G


def displacement_form(system):
    """``(K, rhs)`` of ``system`` on its displacement unknowns alone: an augmented system
    (``LinearSystem.scalars``) condensed (:func:`condensed`; its scalars' right-hand side
    is zero), any other as it is. For checks that apply K to a displacement field."""
    s = int(getattr(system, "scalars", 0))
    if not s:
        return sp.csr_matrix(system.K), np.asarray(system.rhs, dtype=float)
    K, _ = condensed(system.K, s)
    return K, np.asarray(system.rhs, dtype=float)[:K.shape[0]]


def solve_augmented(system, *, where: str, ordering: str = "COLAMD"):
    """Solve a state-based system given in its augmented form ``A = [[A_uu, A_ut], [G, -I]]``
    (the last ``system.scalars`` unknowns are nodal scalars theta = G u, with zero
    right-hand side; constraint rows ``B = [B_u, B_t]`` may act on them), in the form the
    solver that :func:`~pdverify.solvers.policy.static_solver` chooses for
    ``system.solver`` needs:

    - ``direct``: theta eliminated, ``K = A_uu + A_ut G`` (the same products as
      ``StateBasedModel.stiffness``, so the same matrix to the last bit) and
      ``B_u + B_t G``, solved by :func:`solve_with_dirichlet` (or, with constraint rows,
      :func:`~pdverify.solvers.lu.solve_constrained`); theta = G u appended;
    - ``nested-dissection``: ``A`` as it is under the unknowns' ``system.coords``; with
      constraint rows, bordered ``[[A, B^T], [B, 0]]``, a multiplier placed at the mean
      position of the unknowns its row involves. Rows on theta (``B_t`` not empty) would
      put ``B_t^T lambda`` into theta's rows and solve another problem; the multipliers'
      forces on the displacements must be ``(B_u + B_t G)^T lambda``, kept sparse by
      ``mu = B_t^T lambda`` as more unknowns at the scalars' nodes:
      ``[[A, [G^T; 0], [B_u^T; 0]], [0, I, -B_t^T], [B, 0, 0]]``;
    - ``cg`` (``auto`` in 3D from :data:`~pdverify.solvers.policy.CG3D_FROM_UNKNOWNS`
      unknowns): theta eliminated, K = A_uu + A_ut G applied without forming it
      (:class:`~pdverify.solvers.iterative.CondensedOperator`), Jacobi-preconditioned CG
      (:func:`~pdverify.solvers.iterative.solve_condensed`); where it does not apply
      (constraint rows, or K not symmetric: :func:`~pdverify.solvers.policy.condensed_cg`)
      ``nested-dissection`` instead, and ``solver_choice`` says why.

    Returns ``(x, info)``: ``x`` the augmented unknowns (displacements, then theta; the
    multipliers dropped); ``info`` the solver's diagnostics, with ``matrix_nnz`` (the
    non-zeros of the matrix factored, before eliminating prescribed unknowns),
    ``static_solver`` (the solver used) and, when ``system.solver`` is ``auto``,
    ``solver_choice``."""
    A = sp.csr_matrix(system.K)
    s = int(system.scalars)
    n = A.shape[0] - s
    rhs = np.asarray(system.rhs, dtype=float)
    solver = policy.static_solver(system.solver, system.dim, system.dofs)
    B = None if system.B is None else sp.csr_matrix(system.B)
    fallback = None
    if solver == "cg":
        op = None if B is not None else CondensedOperator(A, rhs, s, system.fixed,
                                                          system.values)
        asymmetry = np.nan if op is None else op.asymmetry()
        fallback = policy.condensed_cg(asymmetry, B is not None)
        if fallback is None:
            x, info = solve_condensed(op, where=where)
            info["symmetry_defect"] = asymmetry
            nnz = A.nnz
        else:
            solver = "nested-dissection"
        del op                   # its blocks: a copy of A's size, not kept past the choice
    if solver == "cg":
        pass                     # solved above
    elif solver == "direct":
        K, G = condensed(A, s)
        r = rhs[:n]
        if np.any(rhs[n:]):
            r = r - A[:n, n:] @ rhs[n:]
        if B is not None:
            B_t = B[:, n:]
            B_c = B[:, :n] if B_t.nnz == 0 else (B[:, :n] + B_t @ G).tocsr()
            u, _lam, info = solve_constrained(K, r, B_c, system.c, where=where,
                                              ordering=ordering)
        else:
            u, info = solve_with_dirichlet(K, r, system.fixed, system.values, where=where,
                                           solver="direct", ordering=ordering)
        x = np.r_[u, G @ u - rhs[n:]]
        nnz = K.nnz
    else:
        coords = np.asarray(system.coords)
        if B is None:
            x, info = solve_with_dirichlet(A, rhs, system.fixed, system.values, where=where,
                                           solver=solver, coords=coords, ordering=ordering)
            nnz = A.nnz
        else:
            absB = abs(B).tocsr()
            at = (absB @ coords) / np.asarray(absB.sum(axis=1))
            B_t = B[:, n:]
            c = np.asarray(system.c, dtype=float)
            if B_t.nnz == 0:
                M = sp.bmat([[A, B.T], [B, None]], format="csr")
                rhs_m, coords_m = np.r_[rhs, c], np.r_[coords, at]
            else:
                G = A[n:, :n]
                M = sp.bmat([[A, sp.vstack([G.T, sp.csr_matrix((s, s))]),
                              sp.vstack([B[:, :n].T, sp.csr_matrix((s, B.shape[0]))])],
                             [None, sp.identity(s, format="csr"), -B_t.T],
                             [B, None, None]], format="csr")
                rhs_m = np.r_[rhs, np.zeros(s), c]
                coords_m = np.r_[coords, coords[n:], at]
            none = np.zeros(0, dtype=int), np.zeros(0)
            x, info = solve_with_dirichlet(M, rhs_m, *none, where=where, solver=solver,
                                           coords=coords_m, ordering=ordering)
            x = x[:A.shape[0]]
            nnz = M.nnz
    info["matrix_nnz"] = int(nnz)
    info["static_solver"] = solver
    if system.solver == "auto":
        info["solver_choice"] = policy.auto_note(solver, system.dofs, fallback)
    return x, info


def solve_square(K, f, *, where: str = "static solve", spd: bool = False,
                 ordering: str = "COLAMD"):
    """The ``direct`` solver: K u = f by :func:`factor` in double without coordinates (the
    dense LAPACK LU when K is full enough, else SuperLU; ``spd``: its symmetric mode,
    ``ordering``: its column ordering). Returns ``(u, info)``."""
    return _solved(K, f, where, spd=spd, ordering=ordering)


def solve_with_dirichlet(K, rhs, fixed, values, where, spd: bool = False,
                         ordering: str = "COLAMD", *, solver: str = "direct",
                         lattice=None, aggregate_width: int = 1, coords=None):
    """Solve K u = rhs with u[fixed] = values: condensed
    (:func:`~pdverify.solvers.condense.condense`; the prescribed unknowns' own rows, their
    reactions, dropped), solved, expanded.

    ``solver``: ``direct`` (:func:`solve_square`), ``cg`` (conjugate gradients with the
    two-level preconditioner of :mod:`pdverify.solvers.iterative`; needs ``spd`` and the
    unknowns' ``lattice``, whose aggregates are ``aggregate_width`` nodes wide), ``auto``
    (:func:`~pdverify.solvers.policy.lattice_uses_cg`: ``cg`` from
    :data:`~pdverify.solvers.policy.AUTO_ITERATIVE_UNKNOWNS` free unknowns when it
    applies; else on a 2D lattice nested dissection from
    :data:`~pdverify.solvers.policy.ND_FROM_UNKNOWNS` unless the LU is dense,
    :func:`~pdverify.solvers.policy.lattice_uses_nd`; else ``direct``), or ``nested-dissection`` (sparse LU under a geometric
    ordering, :class:`~pdverify.solvers.nested.NestedFactor`; needs the unknowns'
    ``coords``). Returns the full solution and the solver's diagnostics, which say what
    was chosen and why.
    """
    if solver not in policy.SOLVERS:
        raise ValueError(f"solver={solver!r}: allowed {policy.SOLVERS}")
    K_free, r, expand = condense(K, rhs, fixed, values)
    free = expand.free
    iterative_ok = spd and lattice is not None
    if solver == "cg" and not iterative_ok:
        raise ValueError(f"{where}: solver=cg needs a symmetric positive definite system "
                         "on a lattice")
    use_cg = policy.lattice_uses_cg(solver, iterative_ok, free.size)
    use_nd = lattice is not None and policy.lattice_uses_nd(
        solver, use_cg, lattice.dim, free.size, K_free.nnz)
    if use_nd or solver == "nested-dissection":
        if use_nd:
            at = lattice.take(free).x
        elif coords is None:
            raise ValueError(f"{where}: solver=nested-dissection needs the unknowns' coordinates")
        else:
            at = np.asarray(coords)[free]
        u_free, info = _solved(K_free, r, where, coords=at)
    elif use_cg:
        u_free, info = solve_spd(K_free, r, lattice.take(free), aggregate_width, where=where)
    else:
        u_free, info = _solved(K_free, r, where, spd=spd, ordering=ordering)
    if solver == "auto":
        info["solver_choice"] = policy.lattice_note(use_cg, free.size, use_nd)
    return expand(u_free), info


def _solved(A, b, where: str, **how):
    """``(x, info)`` of A x = b by :func:`factor` (``how``: its keywords)."""
    b = np.asarray(b, dtype=float)
    refuse_non_finite(where, b)           # A: by the factor, before its work
    lu = factor(A, "auto", where=where, **how)
    x = lu.solve(b)
    return x, lu.info
