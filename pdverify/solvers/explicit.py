"""Explicit central-difference time integration with a checked stable time step (seed 002 Eqs. 4-7)."""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Callable

import numpy as np
import scipy.sparse as sp
from scipy.sparse.linalg import ArpackError, ArpackNoConvergence, eigs

from ..errors import NumericalError
from .modal import exact_stability_limit


@dataclass
class StabilityLimit:
    """The central-difference limit dt <= 2 / sqrt(lambda_max) of M^-1 K.

    ``lambda_max`` is the Gershgorin bound max_i sum_j |(M^-1 K)_ij| (``estimate =
    "gershgorin"``: an upper bound on every |lambda|, so 2 / sqrt of it is a sufficient
    limit) or the eigenvalue of largest magnitude (``"arpack"`` or ``"dense"``: the sharp
    limit). ``gershgorin`` is always recorded; ``imag_ratio`` = |Im lambda| / |lambda| and
    ``real_part`` of the extreme eigenvalue flag a spectrum no step can make stable.
    """

    dt_limit: float
    lambda_max: float
    estimate: str
    gershgorin: float
    imag_ratio: float = 0.0
    real_part: float = 0.0



def ratio_above_one(ratio: float) -> str:
    """``ratio`` (> 1) with the fewest significant digits (3 at least) that still show it
    above 1: 1.0003 is "1.0003", not "1"."""
    for digits in range(3, 18):
        text = f"{ratio:.{digits}g}"
        if float(text) > 1.0:
            return text
    return repr(ratio)

def _scaled(stiffness, mass):
    K = sp.csr_matrix(stiffness)
    if mass is None:
        return K
    return (sp.diags(1.0 / np.asarray(mass, dtype=float)) @ K).tocsr()


def gershgorin_limit(stiffness, mass=None) -> StabilityLimit:
    """Sufficient limit 2 / sqrt(max_i sum_j |(M^-1 K)_ij|): cheap, never above the sharp one."""
    KM = _scaled(stiffness, mass)
    gersh = float(np.max(np.asarray(abs(KM).sum(axis=1)).ravel())) if KM.shape[0] else 0.0
    if gersh == 0.0:
        return StabilityLimit(np.inf, 0.0, "zero operator", 0.0)
    return StabilityLimit(2.0 / np.sqrt(gersh), gersh, "gershgorin", gersh, 0.0, gersh)


def stability_limit(stiffness, mass=None) -> StabilityLimit:
    """Sharp central-difference limit for M u'' + K u = f (M lumped, diagonal).

    For every eigenvalue lambda of M^-1 K the scheme is stable iff lambda is real and
    0 <= lambda <= 4 / dt^2, so dt_limit = 2 / sqrt(|lambda|_max). K may be non-symmetric
    (Taylor-extrapolated fictitious nodes). The extreme eigenvalue comes from ARPACK
    (relative tolerance 1e-6; a Ritz value of a symmetric matrix lies below the true one, so
    the limit is accurate to about that), dense eigenvalues below 65 unknowns, and the
    Gershgorin bound if ARPACK does not converge.
    """
    bound = gershgorin_limit(stiffness, mass)
    if bound.gershgorin == 0.0:
        return bound
    KM = _scaled(stiffness, mass)
    n = KM.shape[0]
    try:
        if n <= 64:
            vals = np.linalg.eigvals(KM.toarray())
            top, how = vals[np.argmax(np.abs(vals))], "dense"
        else:
            v0 = np.cos(np.arange(n) * 0.7071) + 1.5  # deterministic: runs repeat exactly
            top = eigs(KM, k=1, which="LM", tol=1e-6, v0=v0, ncv=min(n - 1, 40),
                       maxiter=20 * n, return_eigenvectors=False)[0]
            how = "arpack"
    except (ArpackNoConvergence, ArpackError):
        return bound
    lam = float(abs(top))
    return StabilityLimit(2.0 / np.sqrt(lam), lam, how, bound.gershgorin,
                          float(abs(top.imag) / lam), float(top.real))


@dataclass
class CentralDifferenceResult:
    """What :func:`central_difference` returns.

    ``steps``, ``times``, ``u``: the sampled steps, their times and u there (rows);
    ``history``: u[record] at every step 0..n_steps (rows; ``None`` without ``record``),
    at ``history_times``; ``u_final``, ``v_final``: the state at the last step (v by the
    central difference (u_{n+1} - u_{n-1}) / 2 dt); ``limit`` and ``info``: the stability
    limit used and a summary.
    """

    steps: np.ndarray
    times: np.ndarray
    u: np.ndarray                       # (len(steps), n)
    limit: StabilityLimit
    info: dict = field(default_factory=dict)
    history: np.ndarray | None = None
    history_times: np.ndarray | None = None
    u_final: np.ndarray | None = None
    v_final: np.ndarray | None = None


def central_difference(stiffness, u0, v0, dt: float, n_steps: int, *, mass=None,
                       load: Callable[[float], np.ndarray] | None = None,
                       sample_steps=(), fixed=(), record=None, dt_limit: float | None = None,
                       where: str = "central difference",
                       check_every: int = 100) -> CentralDifferenceResult:
    """Integrate M u'' + K u = f(t) by central differences (seed 002 Eqs. 4-7).

    u_{n+1} = 2 u_n - u_{n-1} + dt^2 M^-1 (f(t_n) - K u_n) (Eq. 5), started with
    u_{-1} = u_0 - dt v_0 + dt^2/2 a_0 (Eqs. 6-7). ``stiffness`` is sparse (one product per
    step), ``mass`` a lumped mass vector (default 1: K is then minus the acceleration
    operator), ``load(t)`` an optional force vector. ``sample_steps`` are the step
    indices n (0..n_steps) whose u_n is returned; ``record`` are unknowns whose value is
    kept at every step (``history``). ``fixed`` unknowns are held at their initial value
    (no acceleration; the stability limit is then that of the free unknowns).
    ``dt_limit``, when the caller already knows the sharp limit (e.g. from
    :func:`pdverify.solvers.modal.exact_stability_limit` for a symmetric K), replaces the
    estimate below.

    Raises :class:`NumericalError` (i) before any step when ``dt`` exceeds the stability
    limit 2 / sqrt(lambda_max(M^-1 K)), naming the limit: for a symmetric K, steps below the
    Gershgorin bound are accepted at once, others (and every step for a non-symmetric K) are
    checked against the sharp limit of :func:`stability_limit`; (ii) when that extreme
    eigenvalue is complex or negative (no stable step exists; eigenvalues that are not
    extreme are not examined); (iii) when u stops being finite, naming the step.
    """
    K = sp.csr_matrix(stiffness)
    n = K.shape[0]
    u0 = np.array(u0, dtype=float)
    v0 = np.broadcast_to(np.asarray(v0, dtype=float), u0.shape)
    if not (dt > 0 and np.isfinite(dt)):
        raise ValueError(f"dt={dt} must be a finite number > 0")
    sample_steps = np.asarray(sorted(set(int(s) for s in sample_steps)), dtype=int)
    if sample_steps.size and (sample_steps[0] < 0 or sample_steps[-1] > n_steps):
        raise ValueError(f"sample steps must lie in 0..{n_steps}")

    # Symmetric K: the spectrum is real, and below the Gershgorin limit the step is stable
    # for sure, so nothing more is computed; above it the limit is sharpened from the
    # extreme eigenvalue before refusing. Non-symmetric K (extrapolated fictitious nodes):
    # the extreme eigenvalue is always computed, to catch complex or negative ones.
    fixed = np.asarray(fixed, dtype=int)
    free = np.ones(n, dtype=bool)
    free[fixed] = False
    K_free = K[free][:, free] if fixed.size else K
    m_free = None if mass is None else np.asarray(mass, dtype=float)[free]
    if dt_limit is not None:
        limit = StabilityLimit(float(dt_limit), 4.0 / float(dt_limit) ** 2, "given", np.nan)
    else:
        limit = gershgorin_limit(K_free, m_free)
        symmetric = abs(K_free - K_free.T).max() <= 1e-12 * limit.gershgorin if n else True
        if not symmetric:
            limit = stability_limit(K_free, m_free)
        elif dt > limit.dt_limit:
            # symmetric: the operator's own limit, exact to round-off (modal.py)
            m_all = np.ones(K_free.shape[0]) if m_free is None else m_free
            exact = exact_stability_limit(K_free, m_all)
            limit = StabilityLimit(exact, 4.0 / exact ** 2, "exact (symmetric)", limit.gershgorin,
                                   0.0, 4.0 / exact ** 2)
    if limit.imag_ratio > 1e-6:
        raise NumericalError(f"{where}: M^-1 K has a complex eigenvalue (|Im|/|lambda| = "
                             f"{limit.imag_ratio:.2g}); central differences are unstable at any dt")
    if limit.real_part < 0:
        raise NumericalError(f"{where}: M^-1 K has a negative eigenvalue ({limit.real_part:.6g}); "
                             "the semi-discrete system grows exponentially at any dt")
    if dt > limit.dt_limit:
        raise NumericalError(f"{where}: time step dt={dt:.6g} s exceeds the stability limit "
                             f"2/sqrt(lambda_max) = {limit.dt_limit:.6g} s of central differences "
                             f"(ratio {ratio_above_one(dt / limit.dt_limit)} > 1; lambda_max = "
                             f"{limit.lambda_max:.6g} 1/s^2, {limit.estimate})")

    inv_m = np.ones(n) if mass is None else 1.0 / np.asarray(mass, dtype=float)
    inv_m = np.where(free, inv_m, 0.0)
    v0 = np.where(free, v0, 0.0)
    record = None if record is None else np.asarray(record, dtype=int)
    history = None if record is None else np.empty((n_steps + 1, record.size))
    step_op = (sp.diags(-dt * dt * inv_m) @ K).tocsr()   # dt^2 M^-1 (-K), applied once per step
    dt2_inv_m = dt * dt * inv_m

    def increment(u, t):
        out = step_op @ u
        if load is not None:
            out += dt2_inv_m * load(t)
        return out

    samples = np.empty((sample_steps.size, n))
    next_sample = 0

    def keep(step, u):
        nonlocal next_sample
        while next_sample < sample_steps.size and sample_steps[next_sample] == step:
            samples[next_sample] = u
            next_sample += 1
        if history is not None:
            history[step] = u[record]

    step = 0
    with np.errstate(over="raise", invalid="raise"):
        try:
            u = u0.copy()
            keep(0, u)
            # Eq. (6)-(7): u_{-1} = u_0 - dt v_0 + dt^2 a_0 / 2
            u_prev = u0 - dt * v0 + 0.5 * increment(u0, 0.0)
            for step in range(1, n_steps + 1):
                u_next = increment(u, (step - 1) * dt)
                u_next += 2.0 * u
                u_next -= u_prev
                u_prev, u = u, u_next
                keep(step, u)
                if step % check_every == 0 and not np.isfinite(u).all():
                    raise FloatingPointError("non-finite displacement")
            if not np.isfinite(u).all():
                raise FloatingPointError("non-finite displacement")
        except FloatingPointError as exc:
            raise NumericalError(f"{where}: displacements became non-finite: blew up near step {step} "
                                 f"(t = {step * dt:.6g} s): {exc}") from None
    u_next = increment(u, n_steps * dt) + 2.0 * u - u_prev
    v_final = (u_next - u_prev) / (2.0 * dt)
    info = {"dt": dt, "n_steps": int(n_steps), "dt_limit": limit.dt_limit,
            "dt_limit_estimate": limit.estimate, "lambda_max": limit.lambda_max,
            "dt_over_limit": dt / limit.dt_limit}
    if np.isfinite(limit.gershgorin) and limit.gershgorin > 0:
        info["gershgorin_dt_limit"] = 2.0 / np.sqrt(limit.gershgorin)
    return CentralDifferenceResult(steps=sample_steps, times=sample_steps * dt, u=samples,
                                   limit=limit, info=info, history=history,
                                   history_times=np.arange(n_steps + 1) * dt,
                                   u_final=u, v_final=v_final)
