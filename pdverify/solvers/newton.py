"""Newton's method with a line search for f(u) = 0 on the free unknowns, with prescribed
(Dirichlet) unknowns that may change between solves (contact), and a linear solver that
reuses its work across iterations and load steps.

The tangent keeps one sparsity pattern; prescribed unknowns are handled in place on that
pattern (their rows and columns zeroed, their diagonal kept), so the system keeps its size
and a preconditioner built once stays applicable when the prescribed set grows.
"""
from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np

from ..errors import NumericalError
from .condense import condense
from .front import solve_square
from .iterative import Lattice, TwoLevelPreconditioner, cg_solve

#: Newton stops when ||f_free|| <= NEWTON_RTOL * max(||f_free|| at its start, ||reactions||):
#: eight digits of the force balance (the reported forces are sums of reactions, compared
#: with a reference at the percent level).
NEWTON_RTOL = 1e-8
#: Iterations before Newton is declared stalled.
NEWTON_MAXITER = 30
#: Step halvings before the line search gives up (the step is then 2^-12 of Newton's).
LINE_SEARCH_HALVINGS = 12
#: Forcing term of inexact Newton with CG: the linear solve's relative residual is
#: min(FORCING_MAX, ||f|| / scale), which keeps Newton's quadratic convergence (the
#: forcing term is O(||f||); Eisenstat and Walker 1996) and spends no iterations far away;
#: it is never tighter than the last step to the stopping rule needs.
#: The tangent predictor's solve uses it too; solved to 1e-3 instead it saved no
#: measurable time and moved the forces past the compare rule (record
#: indentation-2026-11-27-predictor-forcing).
FORCING_MAX = 1e-2
#: Floor of the CG tolerance (the reference tolerance of the solver layer).
FORCING_MIN = 1e-10
#: The CG preconditioner, built on the first tangent (and the first set of prescribed
#: unknowns), is refreshed on the current one (:meth:`TwoLevelPreconditioner.refresh`: its
#: diagonal, products and coarse matrix; the aggregates and prolongator stay) once the
#: iterations it has lost since its build or last refresh exceed REBUILD_FACTOR refreshes.
#: The loss of a solve is its iterations minus those the best rate seen since (iterations
#: per decade of residual reduction) would have needed; the best rate is an optimistic
#: estimate of a fresh one's, hence the factor. Counted in iterations, not seconds, so
#: that a run is reproducible bit for bit.
REBUILD_FACTOR = 3.0
#: What a refresh costs in CG iterations (0.45 s against ~18 ms an iteration on the paper
#: grid's half indentation; refreshing took its corrected curve from 1004 CG iterations to
#: 775: record indentation-2026-11-26-refresh-cost).
REFRESH_COST_ITERATIONS = 25


@dataclass
class LinearStats:
    solves: int = 0
    iterations: int = 0
    rebuilds: int = 0
    refreshes: int = 0
    setup_s: float = 0.0
    solve_s: float = 0.0


class DirichletLinearSolver:
    """Solves T du = -f with du = 0 on the prescribed unknowns, for tangents T given as data
    on one CSR ``pattern`` (see :mod:`pdverify.pd.nonlinear`).

    ``method``: ``direct`` (:func:`~pdverify.solvers.front.solve_square` on the free block,
    a fresh factorisation per solve) or
    ``cg`` (conjugate gradients on the full-size system with the prescribed rows and
    columns replaced by their diagonal, preconditioned by :class:`TwoLevelPreconditioner`
    built on the first tangent and refreshed on the current one when the iterations lost
    since exceed :data:`REBUILD_FACTOR` refreshes' cost). CG needs a symmetric positive
    definite tangent; a tangent
    that has lost definiteness makes CG fail, which is reported as numerical trouble.
    """

    def __init__(self, pattern, method: str, lattice: Lattice | None = None, width: int = 1,
                 describe=None):
        if method not in ("direct", "cg"):
            raise ValueError(f"method={method!r}: allowed direct, cg")
        self.pattern, self.method, self.lattice, self.width = pattern, method, lattice, width
        self.watched = None
        self.describe = describe or (lambda k: f"unknown {k}")
        self.precond = None
        self.fixed = None
        self._diag0 = None
        self.stats = LinearStats()

    def set_fixed(self, fixed: np.ndarray, watched: np.ndarray | None = None) -> None:
        """Mark the prescribed unknowns (boolean per unknown); ``watched``: prescribed ones
        whose own stiffness is still checked like a free one's (a half model's u_x on the
        symmetry plane, free in the whole body, whose diagonal there is the body's)."""
        self.fixed = np.asarray(fixed, dtype=bool)
        self.watched = None if watched is None else np.asarray(watched, dtype=bool)
        P = self.pattern
        # the rows' flags repeated over their entries: fixed[P.row_of] without its
        # gather of 5.6 million entries on the paper grid's half model
        kill = np.repeat(self.fixed, np.diff(P.indptr))
        kill |= self.fixed[P.indices]
        self._kill = np.flatnonzero(kill)

    def masked(self, data):
        """The matrix with the prescribed rows and columns zeroed and their diagonal set to
        that of the first tangent seen (positive, on the scale of the others; a prescribed
        node's own current stiffness may be anything); ``data`` is overwritten."""
        P = self.pattern
        if self._diag0 is None:
            self._diag0 = data[P.diagonal].copy()
        data[self._kill] = 0.0
        data[P.diagonal[self.fixed]] = self._diag0[self.fixed]
        return P.matrix(data)

    def solve(self, data, rhs, rtol: float, where: str) -> np.ndarray:
        """du with T du = rhs on the free unknowns, du = 0 on the prescribed ones (``data``,
        the tangent on the pattern, is overwritten)."""
        free = ~self.fixed
        diag = data[self.pattern.diagonal]
        bad = np.flatnonzero((free if self.watched is None else free | self.watched)
                             & ~(diag > 0))
        if bad.size:
            k = bad[np.argmin(diag[bad])]
            raise NumericalError(f"{where}: the tangent has lost definiteness: "
                                 f"{self.describe(k)} has stiffness {diag[k]:.3g} <= 0 against "
                                 "its own motion (compressed bonds' negative geometric "
                                 "stiffness outweighs their axial stiffness there)")
        r = np.where(free, rhs, 0.0)
        if self.method == "direct":       # the solver layer's checked sparse LU (SPD mode)
            t0 = time.perf_counter()
            K_free, r_free, expand = condense(
                self.pattern.matrix(data), r, np.flatnonzero(self.fixed), 0.0)
            du = expand(solve_square(K_free, r_free, where=where, spd=True)[0])
            self.stats.solves += 1
            self.stats.solve_s += time.perf_counter() - t0
            return du
        T = self.masked(data)
        if self.precond is None:
            self._build(T)
        elif self._stale:
            self._refresh(T)
        du, info = cg_solve(T, r, self.precond, where=where, rtol=rtol)
        self.stats.solves += 1
        self.stats.iterations += info["iterations"]
        self.stats.solve_s += info["cg_solve_s"]
        k = info["iterations"]
        decades = max(-np.log10(max(info["relative_residual"], 1e-16)), 1.0)
        self._best_rate = min(self._best_rate, max(k, 1) / decades)
        self._lost += k - self._best_rate * decades
        if self._lost > REBUILD_FACTOR * REFRESH_COST_ITERATIONS:
            self._stale = True             # the next solve refreshes it on its own tangent
        du[self.fixed] = 0.0
        return du

    def _build(self, T):
        self.precond = TwoLevelPreconditioner(T, self.lattice, self.width, fused=True)
        self._best_rate, self._lost, self._stale = np.inf, 0.0, False
        self.stats.rebuilds += 1
        self.stats.setup_s += self.precond.setup_s

    def _refresh(self, T):
        setup = self.precond.setup_s
        refreshed = self.precond.refresh(T)
        self.stats.setup_s += self.precond.setup_s - setup     # a refused one's check too
        if not refreshed:
            return self._build(T)
        self._best_rate, self._lost, self._stale = np.inf, 0.0, False
        self.stats.refreshes += 1


@dataclass
class NewtonReport:
    iterations: int
    residuals: list = field(default_factory=list)   # ||f_free|| per iterate, start first
    line_search_cuts: int = 0
    scale: float = 0.0                               # the force scale of the stopping rule


def newton(model, u, solver: DirichletLinearSolver, *, where: str, previous=None,
           rtol: float = NEWTON_RTOL, maxiter: int = NEWTON_MAXITER,
           line_search: bool = True) -> NewtonReport:
    """Solve model.internal_force(u) = 0 on the free unknowns of ``solver`` in place,
    starting from ``u`` (whose prescribed entries hold their values).

    ``previous``: the equilibrium ``u`` left (same free entries, other prescribed values).
    The start is then the tangent predictor from it: the free unknowns follow the change
    of the prescribed ones through the tangent at ``previous``, du_free = -T_ff^-1 (f_free
    + T_fp du_p). Starting instead from the old free values next to the new prescribed
    ones would compress the bonds between them by the whole increment (40 % of a
    0.25 mm bond for a 0.1 mm indenter step), where the tangent is no longer definite.

    Each step solves tangent du = -f and takes the largest of 1, 1/2, 1/4, ... that
    reduces ||f_free|| by the Armijo fraction 1e-4 of the step. Stops at
    ||f_free|| <= rtol * max(||f_free|| at the start, ||reactions||), the norms weighted
    by ``model.residual_weight`` when it has one (a half model's: the whole body's norms).
    A step the line
    search cannot make, or ``maxiter`` iterations, raise :class:`NumericalError` naming
    ``where`` and the residual reached. ``line_search=False``: every full step is taken
    (plain Newton, as a solver without a line search would), so a residual that grows is
    left to the iteration limit or to non-finite forces.
    """
    free = ~solver.fixed
    weight = getattr(model, "residual_weight", None)

    def norm_of(f, rows):
        if weight is None:
            return float(np.linalg.norm(f[rows]))
        return float(np.sqrt(np.dot(weight[rows] * f[rows], f[rows])))

    def residual(v):
        f = model.internal_force(v)
        if not np.all(np.isfinite(f)):
            raise NumericalError(f"{where}: non-finite internal forces")
        return f, norm_of(f, free)

    if previous is not None:
        change = np.where(solver.fixed, u - previous, 0.0)
        f0 = model.internal_force(previous)
        T0 = solver.pattern.matrix(model.tangent_data(previous))
        du = solver.solve(T0.data, -(f0 + T0 @ change), FORCING_MAX, where)
        u[free] = previous[free] + du[free]
    f, norm = residual(u)
    scale = max(norm, norm_of(f, solver.fixed))
    report = NewtonReport(0, [norm], scale=scale)
    if scale == 0.0:
        return report
    while norm > rtol * scale:
        if report.iterations >= maxiter:
            raise NumericalError(f"{where}: Newton stalled, {maxiter} iterations without "
                                 f"convergence (residual {norm / scale:.1e} of the force scale)")
        # O(||f||) for quadratic convergence, but no tighter than the stopping rule needs:
        # the next residual is about eta ||f||, so eta ~ rtol scale / (2 ||f||) reaches it
        eta = min(FORCING_MAX, max(FORCING_MIN, norm / scale, 0.5 * rtol * scale / norm))
        du = solver.solve(model.tangent_data(u), -f, eta, where)
        step = 1.0
        for _ in range(LINE_SEARCH_HALVINGS + 1):
            trial = u + step * du
            f_t, n_t = residual(trial)
            if not line_search or n_t <= (1.0 - 1e-4 * step) * norm:
                break
            step *= 0.5
            report.line_search_cuts += 1
        else:
            raise NumericalError(f"{where}: Newton stalled, the line search found no step that "
                                 f"reduces the residual ({norm / scale:.1e} of the force scale)")
        u[:] = trial
        f, norm = f_t, n_t
        scale = max(scale, norm_of(f, solver.fixed))
        report.iterations += 1
        report.residuals.append(norm)
    report.scale = scale
    return report
