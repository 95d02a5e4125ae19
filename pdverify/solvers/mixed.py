"""Mixed precision: a solve by an approximate (single-precision) factor, refined in double
as LAPACK's dsgesv does, with a random probe refined alongside that tells a converged
refinement from a near-singular system and gives the condition estimate. The factor is the
caller's (:class:`~pdverify.solvers.nested.SplitLU` for nested dissection)."""
from __future__ import annotations

import numpy as np

from .checks import rounded_estimate

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
    refinement does not converge (the double LU must take over). The diagnostics record
    the refinement's steps and relative residuals (``refinement_steps``,
    ``refinement_residuals``) and the probe's final residual
    (``refinement_probe_residual``)."""
    # a second, random (normal) right-hand side is refined alongside: a consistent
    # right-hand side of a (near-)singular system can converge, a generic one cannot, and
    # its convergence is what makes the single-precision condition estimate trustworthy
    probe = np.random.default_rng(20211121).standard_normal(b.size)
    tol = np.sqrt(b.size) * np.finfo(float).eps        # the probe: to dsgesv's test
    Y, steps, history, ok = refine(A, np.column_stack([b, probe]), lu.solve,
                                   stop=[REFINE_STOP, tol])
    y = Y[:, 0]
    diag = {"refinement_steps": steps, "refinement_residuals": [h[0] for h in history],
            "refinement_probe_residual": history[-1][1]}
    if not ok:
        diag["mixed_precision"] = ("not used: refinement of the single-precision factor "
                                   "did not converge; double LU")
        return None, None, diag
    return y, probe_condition_estimate(A, lu, probe, Y[:, 1]), diag


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


def refine(A, b, solve, *, stop=None, max_steps: int = REFINE_MAX_STEPS):
    """Iterative refinement of A x = b with an approximate inverse ``solve`` (residuals in
    double), one or several right-hand sides (columns of ``b``): ``(x, steps, history,
    converged)``, ``history`` per step the relative residuals ||r||_inf / (||A||_inf
    ||x||_inf) of the iterates (a list per step for several columns).

    Converged, as LAPACK's dsgesv, when every column's residual reaches sqrt(n) eps. A
    column is refined until its residual is at most ``stop`` (per column; default
    :data:`REFINE_STOP`, a backward-stable double solve's level: stopping at dsgesv's test
    would leave up to sqrt(n) times that) or a step fails to halve it; each column's best
    iterate is returned. Unconverged: a non-finite residual, or a column stalled above
    dsgesv's test."""
    n = A.shape[0]
    B = np.asarray(b, dtype=float)
    B2 = B.reshape(n, -1)
    norm_a = float(abs(A).sum(axis=1).max())
    tol = np.sqrt(n) * np.finfo(float).eps
    stop = np.broadcast_to(REFINE_STOP if stop is None else np.asarray(stop, float),
                           B2.shape[1:])
    X = solve(B2)
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

