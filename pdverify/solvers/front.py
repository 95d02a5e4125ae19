"""The solvers' front door (scikit-fem's ``solve(*condense(A, b, D=D), solver=...)`` is
the model): a :class:`~pdverify.pd.problem.LinearSystem` in, its solution and the
solver's diagnostics out. Elimination of prescribed unknowns and the choice of solver
happen here, the factorisations in the solver modules."""
from __future__ import annotations

import numpy as np

from .dense import solve_with_dirichlet
from .static import solve_constrained


def solve(system, *, where: str, ordering: str = "COLAMD"):
    """Solve ``system``: constraint rows by Lagrange multipliers when it has them (no
    prescribed unknowns then), else the prescribed unknowns eliminated and the rest
    solved by ``system.solver``; ``ordering``: SuperLU's column ordering of a direct
    solve. Returns ``(x, info)``; ``x`` holds every unknown of the system (multipliers
    dropped)."""
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
