"""Time integration of M u'' + K u = f(t) with prescribed unknowns: velocity Verlet (explicit) and Newmark average acceleration (implicit).

Both integrators take one :class:`DynamicSystem`: a sparse K over every unknown (free and
prescribed), a lumped mass, the free unknowns, the load f(t) and the prescribed motion
(u, v, a)(t) of the others. Per step the explicit one does one sparse product K u (the
free rows give the accelerations, the prescribed rows the reactions) and no loop over
nodes; the implicit one reuses one factorisation of K_ff + 4/dt^2 M_ff. Both return the
samples asked for, the energy
balance (kinetic + strain - work of the loads and reactions) at every step, and an
``info`` that states the step, the stable step of the explicit scheme and how it was
estimated.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Callable

import numpy as np
import scipy.sparse as sp

from ..errors import NumericalError

#: the explicit step is this fraction of the stable limit 2 / omega_max unless a run
#: asks for another: omega_max comes from the operator itself (Lanczos to machine
#: precision, or ARPACK's 1e-6 for a non-symmetric K), so the margin is not for the
#: estimate but for round-off growth near the limit, where the amplification of the
#: top mode is 1 (the usual 0.8-0.9 of explicit PD codes)
SAFETY = 0.9


@dataclass
class DynamicSystem:
    """M u'' + K u = f(t) over ``n`` unknowns, ``free`` of them integrated.

    ``K``: sparse (n, n); ``mass``: lumped (n,), > 0 on every free unknown; ``load(t)``:
    the force vector (n,) (only its free entries are read); ``prescribed(t)``: ``(u, v,
    a)`` of the prescribed unknowns (the complement of ``free``, in index order) at time
    t."""

    K: sp.spmatrix
    mass: np.ndarray
    free: np.ndarray
    load: Callable[[float], np.ndarray]
    prescribed: Callable[[float], tuple]

    def __post_init__(self):
        self.K = sp.csr_matrix(self.K)
        self.mass = np.asarray(self.mass, dtype=float)
        free = np.zeros(self.K.shape[0], dtype=bool)
        free[np.asarray(self.free, dtype=int)] = True
        self.free_mask = free
        self.free = np.flatnonzero(free)
        self.fixed = np.flatnonzero(~free)

    @property
    def K_ff(self):
        return self.K[self.free][:, self.free]

    def asymmetry(self) -> float:
        """max |K - K^T| / max |K| over the free block (0 for a symmetric operator)."""
        K = self.K_ff
        top = abs(K).max() if K.nnz else 0.0
        return float(abs(K - K.T).max() / top) if top else 0.0


@dataclass
class StableStep:
    """The explicit scheme's limit dt <= 2 / omega_max, omega_max^2 the largest eigenvalue
    of M_ff^-1 K_ff; ``estimate`` says how it was found, ``gershgorin`` the row-sum bound
    on omega_max^2 (always recorded: 2 / sqrt of it is a sufficient limit)."""

    dt_limit: float
    omega_max: float
    estimate: str
    gershgorin: float


def stable_step(system: DynamicSystem, *, where: str) -> StableStep:
    """The explicit limit 2 / omega_max of ``system``'s free unknowns.

    Symmetric K_ff (every treatment whose system is an energy's Hessian): omega_max^2 is
    the largest eigenvalue of the mass-scaled M^-1/2 K M^-1/2, by LAPACK for small systems
    and Lanczos (``eigsh``) to machine precision otherwise
    (:func:`pdverify.solvers.modal.max_angular_frequency`). Otherwise ARPACK on M^-1 K
    (:func:`pdverify.solvers.explicit.stability_limit`), which also refuses a complex or
    negative extreme eigenvalue (no stable step exists)."""
    from .explicit import gershgorin_limit, stability_limit
    from .modal import max_angular_frequency
    K, m = system.K_ff, system.mass[system.free]
    bound = gershgorin_limit(K, m)
    if system.asymmetry() <= 1e-12:
        w = max_angular_frequency(K, m)
        return StableStep(2.0 / w if w > 0 else np.inf, w, "eigsh (symmetric, mass-scaled)",
                          bound.gershgorin)
    lim = stability_limit(K, m)
    if lim.imag_ratio > 1e-6 or lim.real_part < 0:
        raise NumericalError(f"{where}: M^-1 K has the extreme eigenvalue {lim.real_part:.6g}"
                             f" (|Im|/|lambda| = {lim.imag_ratio:.2g}); no explicit step is "
                             "stable")
    return StableStep(lim.dt_limit, float(np.sqrt(lim.lambda_max)), f"{lim.estimate} "
                      "(non-symmetric, M^-1 K)", bound.gershgorin)


@dataclass
class Trajectory:
    """What an integrator returns: ``u`` at the ``steps`` asked for (rows, every unknown),
    their ``times``; ``energy``: per step the kinetic and strain energies and the work
    done on the system (loads on the free unknowns, reactions on the prescribed ones), as
    rows (kinetic, strain, work); ``info``: the step, the step count and the scheme."""

    steps: np.ndarray
    times: np.ndarray
    u: np.ndarray
    energy: np.ndarray
    info: dict = field(default_factory=dict)

    def energy_balance(self) -> float:
        """max over the steps of |E_kin + E_strain - W - E(0)| over max (E_kin +
        E_strain): the share of the energy that the integration creates or loses."""
        kin, strain, work = self.energy
        total = kin + strain
        scale = np.max(np.abs(total))
        if scale == 0.0:
            return 0.0
        return float(np.max(np.abs(total - work - total[0])) / scale)


def _start(system, u0, v0):
    u = np.array(u0, dtype=float)
    v = np.array(v0, dtype=float)
    uc, vc, _ = system.prescribed(0.0)
    u[system.fixed], v[system.fixed] = uc, vc
    return u, v


def _accel(system, Ku, t):
    """Accelerations: M^-1 (f - K u) on the free unknowns, the prescribed ones' own."""
    a = np.empty_like(Ku)
    f = system.load(t)
    a[system.free] = (f[system.free] - Ku[system.free]) / system.mass[system.free]
    a[system.fixed] = system.prescribed(t)[2]
    return a


def _energies(system, u, v, a, Ku):
    """(kinetic, strain, power): the power of the loads and reactions v . (M a + K u)."""
    kin = 0.5 * np.dot(system.mass * v, v)
    strain = 0.5 * np.dot(u, Ku)
    power = np.dot(v, system.mass * a + Ku)
    return kin, strain, power


def _samples(sample_steps, n_steps):
    s = np.asarray(sorted(set(int(k) for k in sample_steps)), dtype=int)
    if s.size and (s[0] < 0 or s[-1] > n_steps):
        raise ValueError(f"sample steps must lie in 0..{n_steps}")
    return s


def _finite(u, step, dt, where):
    if not np.isfinite(u).all():
        raise NumericalError(f"{where}: displacements became non-finite near step {step} "
                             f"(t = {step * dt:.6g} s)")


def velocity_verlet(system: DynamicSystem, u0, v0, dt: float, n_steps: int, *,
                    sample_steps=(), where: str, limit: StableStep | None = None,
                    check_every: int = 50) -> Trajectory:
    """Velocity Verlet: v+ = v + dt/2 a, u' = u + dt v+, a' = M^-1 (f(t') - K u'),
    v' = v+ + dt/2 a' (free unknowns; the prescribed ones follow their motion).

    Second order in time; exact for a motion quadratic in time (the position update is
    Taylor's to dt^2, and the mean of two constant accelerations is exact). The step is
    refused before any work when it exceeds ``limit`` (default: :func:`stable_step`).
    The work integral is the trapezoidal rule of the power, so the balance it closes is
    itself second order."""
    if not (dt > 0 and np.isfinite(dt)):
        raise ValueError(f"dt={dt} must be a finite number > 0")
    limit = stable_step(system, where=where) if limit is None else limit
    if dt > limit.dt_limit:
        raise NumericalError(f"{where}: time step dt={dt:.6g} s exceeds the explicit stability "
                             f"limit 2/omega_max = {limit.dt_limit:.6g} s ({limit.estimate})")
    samples = _samples(sample_steps, n_steps)
    out = np.empty((samples.size, system.K.shape[0]))
    energy = np.empty((3, n_steps + 1))
    u, v = _start(system, u0, v0)
    Ku = system.K @ u
    a = _accel(system, Ku, 0.0)
    kin, strain, power = _energies(system, u, v, a, Ku)
    energy[:, 0] = kin, strain, 0.0
    work = 0.0
    nxt = 0
    free, fixed = system.free, system.fixed
    with np.errstate(over="raise", invalid="raise"):
        try:
            for step in range(n_steps + 1):
                while nxt < samples.size and samples[nxt] == step:
                    out[nxt] = u
                    nxt += 1
                if step == n_steps:
                    break
                t1 = (step + 1) * dt
                v_half = v[free] + 0.5 * dt * a[free]
                u[free] += dt * v_half
                uc, vc, ac = system.prescribed(t1)
                u[fixed] = uc
                Ku = system.K @ u
                a = _accel(system, Ku, t1)
                v[free] = v_half + 0.5 * dt * a[free]
                v[fixed] = vc
                kin, strain, p1 = _energies(system, u, v, a, Ku)
                work += 0.5 * dt * (power + p1)
                power = p1
                energy[:, step + 1] = kin, strain, work
                if (step + 1) % check_every == 0:
                    _finite(u, step + 1, dt, where)
        except FloatingPointError as exc:
            raise NumericalError(f"{where}: the explicit integration overflowed near step "
                                 f"{step} (t = {step * dt:.6g} s): {exc}") from None
    _finite(u, n_steps, dt, where)
    info = {"integrator": "velocity-verlet", "dt": dt, "n_steps": int(n_steps),
            "dt_limit": limit.dt_limit, "dt_over_limit": dt / limit.dt_limit,
            "dt_limit_estimate": limit.estimate, "omega_max": limit.omega_max,
            "gershgorin_dt_limit": 2.0 / np.sqrt(limit.gershgorin)
            if limit.gershgorin > 0 else np.inf}
    return Trajectory(samples, samples * dt, out, energy, info)


def newmark(system: DynamicSystem, u0, v0, dt: float, n_steps: int, *, sample_steps=(),
            where: str, omega_max: float | None = None) -> Trajectory:
    """Newmark's average acceleration (beta = 1/4, gamma = 1/2; trapezoidal rule):
    (K_ff + 4/dt^2 M_ff) u'_f = f_f(t') - K_fc u'_c + M_ff (4/dt^2 u + 4/dt v + a)_f, then
    a' = 4/dt^2 (u' - u) - 4/dt v - a and v' = v + dt/2 (a + a').

    Unconditionally stable and second order (period error (omega dt)^2 / 12, no amplitude
    error); exact for a motion quadratic in time. One factorisation of the effective
    matrix serves every step: SuperLU (``scipy.sparse.linalg.splu``) without the static
    solves' per-solve condition check, because the mass-scaled effective matrix
    I + dt^2/4 M^-1/2 K M^-1/2 has the condition 1 + (omega_max dt)^2 / 4 at most (K
    symmetric positive semi-definite), which ``info`` records when ``omega_max`` is
    given; a non-finite solution still fails the run."""
    from scipy.sparse.linalg import splu
    if not (dt > 0 and np.isfinite(dt)):
        raise ValueError(f"dt={dt} must be a finite number > 0")
    samples = _samples(sample_steps, n_steps)
    out = np.empty((samples.size, system.K.shape[0]))
    energy = np.empty((3, n_steps + 1))
    free, fixed = system.free, system.fixed
    K = system.K
    K_fc = K[free][:, fixed]
    c0 = 4.0 / dt ** 2
    m_f = system.mass[free]
    lu = splu((system.K_ff + sp.diags(c0 * m_f)).tocsc())
    u, v = _start(system, u0, v0)
    Ku = K @ u
    a = _accel(system, Ku, 0.0)
    kin, strain, power = _energies(system, u, v, a, Ku)
    energy[:, 0] = kin, strain, 0.0
    work = 0.0
    nxt = 0
    for step in range(n_steps + 1):
        while nxt < samples.size and samples[nxt] == step:
            out[nxt] = u
            nxt += 1
        if step == n_steps:
            break
        t1 = (step + 1) * dt
        uc, vc, ac = system.prescribed(t1)
        rhs = (system.load(t1)[free] - K_fc @ uc
               + m_f * (c0 * u[free] + (4.0 / dt) * v[free] + a[free]))
        u_f = lu.solve(rhs)
        a_f = c0 * (u_f - u[free]) - (4.0 / dt) * v[free] - a[free]
        v[free] += 0.5 * dt * (a[free] + a_f)
        u[free], a[free] = u_f, a_f
        u[fixed], v[fixed], a[fixed] = uc, vc, ac
        Ku = K @ u
        kin, strain, p1 = _energies(system, u, v, a, Ku)
        work += 0.5 * dt * (power + p1)
        power = p1
        energy[:, step + 1] = kin, strain, work
    _finite(u, n_steps, dt, where)
    info = {"integrator": "newmark", "dt": dt, "n_steps": int(n_steps),
            "newmark_beta": 0.25, "newmark_gamma": 0.5,
            "factor": "sparse LU (SuperLU), once"}
    if omega_max is not None:
        info["effective_condition_bound"] = 1.0 + (omega_max * dt) ** 2 / 4.0
    return Trajectory(samples, samples * dt, out, energy, info)
