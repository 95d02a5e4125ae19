"""The solvers' front door (scikit-fem's ``solve(*condense(A, b, D=D), solver=...)`` is
the model): a :class:`~pdverify.pd.problem.LinearSystem` in, its solution and the
solver's diagnostics out. Three things are kept apart: the elimination of prescribed
unknowns (:mod:`~pdverify.solvers.condense`), the choice of solver and every threshold
of it (:mod:`~pdverify.solvers.policy`), and the implementations (``lu``, ``dense``,
``nested``, ``mixed``, ``iterative``). This module only dispatches: which
implementation for which solver name."""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from . import policy
from .condense import condense
from .dense import solve_dense
from .iterative import solve_spd
from .lu import solve_constrained
from .nested import solve_nested

__all__ = ["solve", "solve_with_dirichlet", "solve_square", "solve_constrained"]


def solve(system, *, where: str, ordering: str = "COLAMD"):
    """Solve ``system``: constraint rows by Lagrange multipliers when it has them (no
    prescribed unknowns then), else the prescribed unknowns eliminated and the rest
    solved by ``system.solver``; ``ordering``: SuperLU's column ordering of a direct
    solve. Returns ``(x, info)``; ``x`` holds every unknown of the system (multipliers
    dropped). A system that names its own ``ordering`` (``LinearSystem.ordering``) is
    solved with that one."""
    ordering = getattr(system, "ordering", None) or ordering
    if system.B is not None:
        if np.size(system.fixed):
            raise ValueError(f"{where}: a system with constraint rows has no eliminated "
                             "unknowns")
        x, _lam, info = solve_constrained(system.K, system.rhs, system.B, system.c,
                                          where=where, ordering=ordering)
        return x, info
    coords = None if system.solver == "direct" else system.coords
    return solve_with_dirichlet(system.K, system.rhs, system.fixed, system.values,
                                where=where, solver=system.solver, coords=coords,
                                ordering=ordering)


def solve_square(K, f, *, where: str = "static solve", spd: bool = False,
                 ordering: str = "COLAMD"):
    """The ``direct`` solver: K u = f by the dense LAPACK LU
    (:func:`~pdverify.solvers.dense.solve_dense`) when K is full enough
    (:func:`~pdverify.solvers.policy.dense_lu`), else by SuperLU
    (:func:`~pdverify.solvers.lu.solve_constrained` without constraints; ``spd``: its
    symmetric mode, ``ordering``: its column ordering). Returns ``(u, info)``."""
    K = sp.csr_matrix(K)
    n = K.shape[0]
    if not policy.dense_lu(n, K.nnz):
        u, _, info = solve_constrained(K, f, where=where, spd=spd, ordering=ordering)
        return u, info
    return solve_dense(K, f, where=where)


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
    ordering, :func:`~pdverify.solvers.nested.solve_nested`; needs the unknowns'
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
    if use_nd:
        u_free, info = solve_nested(K_free, r, lattice.take(free).x, where=where)
    elif solver == "nested-dissection":
        if coords is None:
            raise ValueError(f"{where}: solver=nested-dissection needs the unknowns' coordinates")
        u_free, info = solve_nested(K_free, r, np.asarray(coords)[free], where=where)
    elif use_cg:
        u_free, info = solve_spd(K_free, r, lattice.take(free), aggregate_width, where=where)
    else:
        u_free, info = solve_square(K_free, r, where=where, spd=spd, ordering=ordering)
    if solver == "auto":
        info["solver_choice"] = policy.lattice_note(use_cg, free.size, use_nd)
    return expand(u_free), info
