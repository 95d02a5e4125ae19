"""Dense LU solve (LAPACK) for systems too full for sparse LU, with the static solver's checks."""
from __future__ import annotations

import numpy as np
import scipy.linalg as sl
import scipy.sparse as sp
from scipy.linalg import lapack

from ..errors import NumericalError
from .static import (CONDITION_LIMIT, equilibrate, relative_residual, rounded_estimate,
                     solve_constrained, solve_nested)

#: Above this fill (nnz / n^2) a dense LAPACK LU beats SuperLU: in 3D state-based PD every
#: node couples to all nodes within two horizons, i.e. to a large part of a small body.
DENSE_FILL = 0.1
#: ... and below this many unknowns SuperLU is used whatever the fill
DENSE_MIN_UNKNOWNS = 2000


def solve_square(K, f, *, where: str = "static solve", spd: bool = False,
                 ordering: str = "COLAMD"):
    """Solve the square system K u = f; dense LAPACK LU when K is full enough, else sparse.

    Same contract as :func:`pdverify.solvers.static.solve_constrained` without constraints:
    row then column equilibration, a 1-norm condition estimate of the equilibrated
    matrix (LAPACK gecon), :class:`NumericalError` on singular or near-singular systems.
    ``ordering``: SuperLU's column ordering on the sparse path. Returns ``(u, info)``.
    """
    K = sp.csr_matrix(K)
    n = K.shape[0]
    if n < DENSE_MIN_UNKNOWNS or K.nnz < DENSE_FILL * n * n:
        u, _, info = solve_constrained(K, f, where=where, spd=spd, ordering=ordering)
        return u, info
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
    if cond > CONDITION_LIMIT:
        raise NumericalError(f"{where}: near-singular system (condition estimate {cond:.2e} "
                             f"> {CONDITION_LIMIT:.0e} after equilibration)")
    u = sl.lu_solve((lu, piv), f / row_max, check_finite=False) / col_max
    if not np.all(np.isfinite(u)):
        raise NumericalError(f"{where}: solution has non-finite values (singular system)")
    return u, {"unknowns": int(n), "relative_residual": relative_residual(K, u, f),
               "condition_estimate": float(cond), "solver": "dense LU (LAPACK)"}


#: ``solver="auto"`` picks CG (SPD systems with a lattice) from this many free unknowns:
#: below it the direct solve takes about a second (1.2 s at the sheets' default 10,150
#: unknowns) and is exact to round-off, and the report's default-size runs keep their
#: direct solutions bit for bit.
AUTO_ITERATIVE_UNKNOWNS = 20000
SOLVERS = ("auto", "direct", "cg", "nested-dissection")
#: the choices of a scene whose system is SPD on a lattice (bond-based): no coordinates
#: are passed, so nested dissection is not among them
SPD_LATTICE_SOLVERS = ("auto", "direct", "cg")


def eliminate_dirichlet(K, rhs, fixed, values):
    """The system left after prescribing u[fixed] = values: ``(K_free, rhs_free, free, u)``,
    with ``free`` the other unknowns and ``u`` the full vector holding the values."""
    n = K.shape[0]
    free = np.setdiff1d(np.arange(n), fixed)
    u = np.zeros(n)
    u[fixed] = values
    Kc = K.tocsc()
    K_free = Kc[:, free].tocsr()[free]
    r = rhs[free] - (Kc[:, fixed] @ u[fixed])[free] if fixed.size else rhs[free]
    return K_free, r, free, u


def solve_with_dirichlet(K, rhs, fixed, values, where, spd: bool = False,
                         ordering: str = "COLAMD", *, solver: str = "direct",
                         lattice=None, aggregate_width: int = 1, coords=None):
    """Solve K u = rhs with u[fixed] = values by elimination (their own rows dropped).

    The dropped rows are the equations of the prescribed unknowns (their reactions).
    ``solver``: ``direct`` (:func:`solve_square`), ``cg`` (conjugate gradients with the
    two-level preconditioner of :mod:`pdverify.solvers.iterative`; needs ``spd`` and the
    unknowns' ``lattice``, whose aggregates are ``aggregate_width`` nodes wide) or ``auto``
    (``cg`` from :data:`AUTO_ITERATIVE_UNKNOWNS` free unknowns when it applies, else
    ``direct``), or ``nested-dissection`` (sparse LU under a geometric ordering,
    :func:`~pdverify.solvers.static.solve_nested`; needs the unknowns' ``coords``). Returns the full solution and the solver's diagnostics, which say what
    was chosen and why.
    """
    if solver not in SOLVERS:
        raise ValueError(f"solver={solver!r}: allowed {SOLVERS}")
    K_free, r, free, u = eliminate_dirichlet(K, rhs, fixed, values)
    iterative_ok = spd and lattice is not None
    if solver == "cg" and not iterative_ok:
        raise ValueError(f"{where}: solver=cg needs a symmetric positive definite system "
                         "on a lattice")
    use_cg = solver == "cg" or (solver == "auto" and iterative_ok
                                and free.size >= AUTO_ITERATIVE_UNKNOWNS)
    if solver == "nested-dissection":
        if coords is None:
            raise ValueError(f"{where}: solver=nested-dissection needs the unknowns' coordinates")
        u_free, info = solve_nested(K_free, r, np.asarray(coords)[free], where=where)
    elif use_cg:
        from .iterative import solve_spd
        u_free, info = solve_spd(K_free, r, lattice.take(free), aggregate_width, where=where)
    else:
        u_free, info = solve_square(K_free, r, where=where, spd=spd, ordering=ordering)
    if solver == "auto":
        info["solver_choice"] = (f"auto: {'cg' if use_cg else 'direct'} ({free.size} free "
                                 f"unknowns; cg from {AUTO_ITERATIVE_UNKNOWNS} on SPD systems)")
    u[free] = u_free
    return u, info
