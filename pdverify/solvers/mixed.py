"""Mixed precision: a solve by an approximate (single-precision) factor, refined in double
as LAPACK's dsgesv does, with a random probe refined alongside that tells a converged
refinement from a near-singular system and gives the condition estimate. The factor is the
caller's (:func:`~pdverify.solvers.nested.single_precision_factor` for nested
dissection).

When that refinement stalls (condition near 1/eps_single = 1.7e7, where each step gains
little or the float32 round-off of the factor outweighs it), the same factor preconditions
GMRES in double for each correction (GMRES-based iterative refinement, Carson and Higham,
SIAM J. Sci. Comput. 40 (2018) A817): the corrections are computed to
:data:`GMRES_INNER_TOL` and the outer refinement stops as the plain one does. Only when
that fails too does the caller factor the system in double."""
from __future__ import annotations

import numpy as np

from .checks import rounded_estimate


def scaled_solve(b, trans: str, solve):
    """``solve(b / s, trans) * s`` for a single-precision factor's solve (``trans`` "N"
    or "T"): each column of ``b`` scaled by a power of two near its largest entry (exact),
    so that single precision neither overflows nor underflows: refinement residuals are
    ~1e-16 of the solution, the equilibrated right-hand side can be of any size."""
    b = np.asarray(b, dtype=float)
    if trans not in ("N", "T"):
        raise ValueError(f"trans={trans!r}: 'N' or 'T'")
    big = np.abs(b).max(axis=0)
    scale = np.exp2(np.round(np.log2(np.where(big > 0, big, 1.0))))
    return solve(b / scale, trans) * scale


#: LAPACK's mixed-precision dsgesv: at most 30 refinement steps, converged when
#: ||r||_inf <= ||x||_inf ||A||_inf eps sqrt(n); otherwise the double LU takes over.
REFINE_MAX_STEPS = 30
#: ... and a solution is refined on to this relative residual (that measure), the level of
#: a backward-stable double solve (|r| <= c eps |A| |x| with c ~ 1; the double LU reaches
#: 1.4 eps on the plate's mirror-node system at h = 0.0125): stopping at dsgesv's test
#: leaves up to sqrt(n) times more, visible in metrics at round-off level (7x on that
#: system's exact solution).
REFINE_STOP = 2 * np.finfo(float).eps


def refine_with_probe(A, b, lu):
    """Refine A x = b (``A`` equilibrated) with the approximate factor ``lu`` (its
    ``solve(B, trans)``): ``(x, condition estimate, diagnostics)``, or ``(None, None,
    diagnostics)`` with the reason in ``diagnostics['mixed_precision']`` when the
    refinement does not converge, by plain refinement nor by GMRES-IR (the double LU must
    take over). The diagnostics record the plain refinement's steps and relative residuals
    (``refinement_steps``, ``refinement_residuals``), the probe's final residual
    (``refinement_probe_residual``) and, when GMRES-IR took over, its outer residuals, the
    GMRES iterations of each correction and of the condition estimator's solves
    (``gmres_ir_residuals``, ``gmres_ir_iterations``, ``gmres_ir_estimator_iterations``;
    ``refinement = 'GMRES-IR'``).

    A converged probe no longer bounds the condition once GMRES-IR takes over (it converges
    far beyond 1/eps_single), so the estimate must be as good as with exact solves: its
    three solves must reach :data:`ESTIMATOR_RESIDUAL` (true residuals), else the double LU
    decides."""
    # a second, random (normal) right-hand side is refined alongside: a consistent
    # right-hand side of a (near-)singular system can converge, a generic one cannot, and
    # its convergence is what makes the single-precision condition estimate trustworthy
    probe = np.random.default_rng(20211121).standard_normal(b.size)
    tol = np.sqrt(b.size) * np.finfo(float).eps        # the probe: to dsgesv's test
    rhs = np.column_stack([b, probe])
    Y, steps, history, ok = refine(A, rhs, lu.solve, stop=[REFINE_STOP, tol])
    diag = {"refinement_steps": steps, "refinement_residuals": [h[0] for h in history],
            "refinement_probe_residual": history[-1][1]}
    if ok:
        return Y[:, 0], probe_condition_estimate(A, lu, probe, Y[:, 1]), diag
    gmres = GmresIR(A, lu)
    start = np.where(np.isfinite(Y), Y, 0.0)        # a non-finite float32 solve: from zero
    Y, steps, history, ok = refine(A, rhs, gmres.correction, stop=[REFINE_STOP, tol],
                                   max_steps=GMRES_OUTER_STEPS, start=start)
    diag.update(refinement="GMRES-IR", gmres_ir_residuals=[h[0] for h in history],
                gmres_ir_iterations=list(gmres.iterations),
                refinement_probe_residual=history[-1][1])
    if not ok:
        diag["mixed_precision"] = ("not used: refinement of the single-precision factor "
                                   "did not converge, nor GMRES-IR; double LU")
        return None, None, diag
    # the estimator's three solves by GMRES on the factor too (the factor's own solves are
    # off by ~kappa eps_single, of order 1 here), each one GMRES pass (GmresIR.solve,
    # allowed more iterations than a correction: ESTIMATOR_MAX_ITERATIONS)
    done = len(gmres.iterations)
    cond = probe_condition_estimate(A, gmres, probe, Y[:, 1])
    diag["gmres_ir_estimator_iterations"] = gmres.iterations[done:]
    if gmres.worst_residual > ESTIMATOR_RESIDUAL:
        diag["mixed_precision"] = (f"not used: GMRES-IR converged, but the condition "
                                   f"estimator's solves did not (relative residual "
                                   f"{gmres.worst_residual:.1e}); double LU")
        return None, None, diag
    return Y[:, 0], cond, diag


#: GMRES-IR: each correction's GMRES stops at this relative residual (2-norm), so that an
#: outer step gains ~8 digits (two outer steps of 6 iterations reach 4e-16 on
#: body3d-manufactured's order-3 surface-node system: record
#: mixed_precision-2026-11-26-gmres-inner-tol; the flexible GMRES against scipy's: record
#: gmres_ir-2026-11-28) ...
GMRES_INNER_TOL = 1e-8
#: ... within at most this many iterations (no restart: the two bases, V and Z, of 10^4
#: unknowns x 60 are 10 MB); a correction that has not converged by then is used as it
#: is, and the outer refinement judges it
GMRES_MAX_ITERATIONS = 60
#: outer steps of GMRES-IR (each gains ~8 digits when GMRES converges)
GMRES_OUTER_STEPS = 6
#: The condition estimator's GMRES passes may run on beyond :data:`GMRES_MAX_ITERATIONS`,
#: to at most this many iterations, while they have not reached a tenth of
#: :data:`ESTIMATOR_RESIDUAL` (a margin for GMRES's recurrence residual against the true
#: one that :meth:`GmresIR.solve` checks): near kappa ~ 1/eps_single the float32 factor
#: leaves dozens of eigenvalues of the preconditioned matrix far from 1, and GMRES's
#: residual stays at ~1 until it has them all (on body3d-manufactured's order-2 Taylor
#: system for 70 iterations; capped at 60 it was factored again in double: record
#: mixed_precision-2026-11-26-estimator-iterations). Four times the corrections' limit:
#: the bases of 10^4 unknowns x 240 are 40 MB, and only the iterations run are touched.
ESTIMATOR_MAX_ITERATIONS = 4 * GMRES_MAX_ITERATIONS
#: The condition estimator's solves y ~ A^-1 v (one GMRES pass each) must reach this true
#: relative residual ||A y - v|| / ||v|| (2-norm): then y = A^-1 (v + r) with ||r|| <= tau
#: ||v||, and a term of Hager's estimate, within a factor 3 of ||A^-1|| (Higham, Accuracy
#: and Stability, 15.3), is off by at most 3 tau relative: 3e-4 here, far below the
#: estimator's own factor 3. A pass that does not reach it (a near-singular system,
#: whose float32 factor preconditions nothing) leaves the decision to the double LU.
ESTIMATOR_RESIDUAL = 1e-4


class GmresIR:
    """Solves with A (or A^T) by GMRES on an approximate factor ``lu``: :meth:`correction`
    is one flexible GMRES solve per column preconditioned on the right by ``lu.solve``
    (FGMRES: the float32 solve is not exactly linear), to :data:`GMRES_INNER_TOL`; the
    refinement (:func:`refine`) calls it for each correction. :meth:`solve` (the
    condition estimator's solves) is one such pass from zero, allowed to run on to
    :data:`ESTIMATOR_MAX_ITERATIONS`, whose true residual it checks (``worst_residual``,
    the largest relative residual of its solves; see :data:`ESTIMATOR_RESIDUAL`; once a
    pass has failed, the later ones return zeros unsolved: the double LU decides).
    Hager's estimator needs A^-1 x to a few digits only (the same estimate in half the
    time of solves refined to round-off: record mixed_precision-2026-11-26-stages).
    ``iterations``: GMRES iterations of each pass, in order."""

    def __init__(self, A, lu):
        self.A, self.lu = A, lu
        self.AT = None
        self.iterations: list[int] = []
        self.worst_residual = 0.0

    def correction(self, R, trans: str = "N", *, max_iterations: int | None = None,
                   extended_tol: float = 0.0):
        R = np.asarray(R, dtype=float)
        if trans == "T" and self.AT is None:
            self.AT = self.A.T.tocsr()
        A = self.AT if trans == "T" else self.A
        cols = [_fgmres(A, r, lambda v: self.lu.solve(v, trans=trans),
                        max_iterations=max_iterations, extended_tol=extended_tol)
                for r in R.reshape(R.shape[0], -1).T]
        self.iterations += [k for _, k in cols]
        return np.stack([x for x, _ in cols], axis=1).reshape(R.shape)

    def solve(self, B, trans: str = "N"):
        B = np.asarray(B, dtype=float)
        if self.worst_residual > ESTIMATOR_RESIDUAL:
            # an earlier pass failed: the double LU decides, whatever this one gives
            return np.zeros_like(B)
        X = self.correction(B, trans, max_iterations=ESTIMATOR_MAX_ITERATIONS,
                            extended_tol=0.1 * ESTIMATOR_RESIDUAL)
        A = self.AT if trans == "T" else self.A
        B2, X2 = B.reshape(B.shape[0], -1), X.reshape(B.shape[0], -1)
        for b, x in zip(B2.T, X2.T):
            scale = np.abs(b).max()
            if scale > 0:
                rel = np.linalg.norm((A @ x - b) / scale) / np.linalg.norm(b / scale)
                self.worst_residual = max(self.worst_residual,
                                          float(rel) if np.isfinite(rel) else np.inf)
        return X


def _fgmres(A, r, precondition, *, max_iterations: int | None = None,
            extended_tol: float = 0.0):
    """``(z, iterations)``: z ~ A^-1 r by flexible GMRES with right preconditioning, the
    basis orthogonalised by classical Gram-Schmidt applied twice (as stable as the modified
    one, in matrix products), to :data:`GMRES_INNER_TOL` or :data:`GMRES_MAX_ITERATIONS`;
    beyond those, up to ``max_iterations`` while the relative residual is above
    ``extended_tol`` (the condition estimator's passes, :data:`ESTIMATOR_MAX_ITERATIONS`)."""
    # r scaled by a power of two near its largest entry (exact), so that its norm neither
    # overflows nor underflows (as the float32 factors' solves scale theirs)
    big = float(np.abs(r).max()) if r.size else 0.0
    if big == 0.0 or not np.isfinite(big):
        return np.zeros_like(r), 0
    scale = float(np.exp2(np.round(np.log2(big))))
    z, k = _fgmres_scaled(A, r / scale, precondition, max_iterations, extended_tol)
    return z * scale, k


def _fgmres_scaled(A, r, precondition, max_iterations, extended_tol):
    beta = float(np.linalg.norm(r))
    first = GMRES_MAX_ITERATIONS
    m = max(first, max_iterations or first)
    V = np.zeros((m + 1, r.size))
    Z = np.zeros((m, r.size))
    H = np.zeros((m + 1, m))
    V[0] = r / beta
    e1 = np.zeros(m + 1)
    e1[0] = beta
    y = np.zeros(0)
    for j in range(m):
        Z[j] = precondition(V[j])
        w = A @ Z[j]
        for _ in range(2):
            h = V[:j + 1] @ w
            w = w - h @ V[:j + 1]
            H[:j + 1, j] += h
        H[j + 1, j] = np.linalg.norm(w)
        if not np.isfinite(H[j + 1, j]):
            break
        y, *_ = np.linalg.lstsq(H[:j + 2, :j + 1], e1[:j + 2], rcond=None)
        res = np.linalg.norm(H[:j + 2, :j + 1] @ y - e1[:j + 2])
        if res <= GMRES_INNER_TOL * beta or H[j + 1, j] == 0.0:
            break
        if j + 1 >= first and res <= extended_tol * beta:
            break
        V[j + 1] = w / H[j + 1, j]
    return y @ Z[:y.size], y.size


def probe_condition_estimate(A, lu, probe, solution) -> float:
    """kappa_1(A) ~ ||A||_1 ||A^-1||_1 by one step of Hager's estimator started from the
    refined probe (``solution`` = A^-1 ``probe``): ||A^-1 x||_1 for x = probe / ||probe||_1,
    then for the unit vector e_j at the largest entry of A^-T sign(A^-1 x), and Higham's
    alternating-sign vector (LAPACK dlacn2's last test), the largest of the three. Two
    solves with ``lu`` (one transposed; the two others in one call) against scipy's
    onenormest's four of two columns on the double path; on the plane-strain plate:
    2.005e5 against 2.009e5 (h = 0.01), 1.358e5 against 1.318e5 (h = 0.0125)."""
    n = A.shape[0]
    scale = float(np.abs(probe).sum())
    z = lu.solve(np.sign(solution), trans="T")
    rhs = np.zeros((n, 2))
    rhs[int(np.argmax(np.abs(z))), 0] = 1.0
    rhs[:, 1] = (-1.0) ** np.arange(n) * (1.0 + np.arange(n) / max(n - 1, 1))
    Y = lu.solve(rhs)
    inv_norm = max(float(np.abs(solution).sum()) / scale, float(np.abs(Y[:, 0]).sum()),
                   2.0 * float(np.abs(Y[:, 1]).sum()) / (3.0 * n))
    return rounded_estimate(float(abs(A).sum(axis=0).max()) * inv_norm)


def refine(A, b, solve, *, stop=None, max_steps: int = REFINE_MAX_STEPS, start=None):
    """Iterative refinement of A x = b with an approximate inverse ``solve`` (residuals in
    double), one or several right-hand sides (columns of ``b``): ``(x, steps, history,
    converged)``, ``history`` per step the relative residuals ||r||_inf / (||A||_inf
    ||x||_inf) of the iterates (a list per step for several columns).

    Converged, as LAPACK's dsgesv, when every column's residual reaches sqrt(n) eps. A
    column is refined until its residual is at most ``stop`` (per column; default
    :data:`REFINE_STOP`, a backward-stable double solve's level: stopping at dsgesv's test
    would leave up to sqrt(n) times that) or a step fails to halve it; each column's best
    iterate is returned. Unconverged: a non-finite residual, or a column stalled above
    dsgesv's test. ``start``: the first iterate (default ``solve(b)``)."""
    n = A.shape[0]
    B = np.asarray(b, dtype=float)
    B2 = B.reshape(n, -1)
    norm_a = float(abs(A).sum(axis=1).max())
    tol = np.sqrt(n) * np.finfo(float).eps
    stop = np.broadcast_to(REFINE_STOP if stop is None else np.asarray(stop, float),
                           B2.shape[1:])
    X = solve(B2) if start is None else np.array(start, dtype=float).reshape(B2.shape)
    best, best_rel = X.copy(), np.full(B2.shape[1], np.inf)
    active = np.ones(B2.shape[1], bool)
    history: list = []
    prev = np.full(B2.shape[1], np.inf)
    step = 0
    while True:
        R = B2 - A @ X
        scale = norm_a * np.abs(X).max(axis=0)
        rnorm = np.abs(R).max(axis=0)
        with np.errstate(divide="ignore", invalid="ignore"):
            rel = np.where(scale > 0, rnorm / scale, np.where(rnorm == 0, 0.0, np.inf))
        history.append(rel.tolist() if B.ndim == 2 else float(rel[0]))
        if not np.all(np.isfinite(rel[active])):
            return best.reshape(B.shape), step, history, False
        better = active & (rel < best_rel)
        best[:, better], best_rel[better] = X[:, better], rel[better]
        active &= (rel <= 0.5 * prev) & (rel > stop)
        prev = rel
        if not active.any() or step == max_steps:
            return best.reshape(B.shape), step, history, bool(np.all(best_rel <= tol))
        step += 1
        X[:, active] += solve(R[:, active])

