"""Explicit central-difference time integration of M u'' + K u = f with a stability check."""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import scipy.sparse as sp

from ..errors import NumericalError
from .modal import max_angular_frequency

#: Steps between finiteness checks inside the time loop (a check costs one pass over u).
CHECK_EVERY = 1000


def stability_limit(stiffness, mass, *, fixed=()) -> float:
    """Largest stable step of central differences, 2 / omega_max (inf without stiffness)."""
    omega = max_angular_frequency(stiffness, mass, fixed=fixed)
    return np.inf if omega == 0 else 2.0 / omega


@dataclass
class ExplicitRun:
    """Result of :func:`central_difference`.

    ``u``, ``v``: final displacement and velocity; ``times``: the n_steps + 1 sample
    times; ``history``: u[record] at those times (rows), or ``None`` without ``record``;
    ``info``: steps, dt, dt_limit, omega_max, method.
    """

    u: np.ndarray
    v: np.ndarray
    times: np.ndarray
    history: np.ndarray | None
    info: dict = field(default_factory=dict)


def central_difference(stiffness, mass, u0, v0, dt: float, n_steps: int, *, force=None,
                       fixed=(), record=None, callback=None, dt_limit: float | None = None,
                       where: str = "central difference") -> ExplicitRun:
    """Integrate M u'' + K u = f by explicit central differences (leapfrog form).

    Parameters
    ----------
    stiffness : sparse (n, n)
        Symmetric stiffness K (internal force -K u); any sparse format, used as CSR.
    mass : (n,) array
        Lumped (diagonal) masses, > 0 on the free unknowns.
    u0, v0 : (n,) arrays
        Initial displacement and velocity.
    dt, n_steps : float, int
        Time step and number of steps.
    force : (n,) array, optional
        Constant external force f.
    fixed : indices
        Unknowns held at their initial value (zero velocity and acceleration).
    record : indices, optional
        Unknowns whose displacement is sampled at every step into ``history``.
    callback : callable(step, t, u), optional
        Called after every step with a read-only view of u.
    dt_limit : float, optional
        The stability limit 2/omega_max, if already known; else computed from K and M.

    The scheme is u_{n+1} = 2 u_n - u_{n-1} + dt^2 M^-1 (f - K u_n), written with
    half-step velocities: v_{n+1/2} = v_{n-1/2} + dt a_n, u_{n+1} = u_n + dt v_{n+1/2},
    started with v_{1/2} = v_0 + dt/2 a_0; it is stable for dt <= 2/omega_max.

    Raises :class:`NumericalError` for dt above the stability limit (before any step)
    and for non-finite displacements (checked every ``CHECK_EVERY`` steps and at the end).
    """
    K = sp.csr_matrix(stiffness)
    n = K.shape[0]
    mass = np.asarray(mass, dtype=float)
    fixed = np.asarray(fixed, dtype=int)
    if not (dt > 0 and np.isfinite(dt)) or n_steps < 0:
        raise NumericalError(f"{where}: need dt > 0 and n_steps >= 0 (dt={dt}, n_steps={n_steps})")
    free = np.ones(n, dtype=bool)
    free[fixed] = False
    if np.any(mass[free] <= 0):
        raise NumericalError(f"{where}: free unknowns need positive masses")
    if dt_limit is None:
        dt_limit = stability_limit(K, mass, fixed=fixed)
    if dt > dt_limit:
        raise NumericalError(f"{where}: time step dt={dt:.4g} s exceeds the stability limit "
                             f"2/omega_max={dt_limit:.4g} s of the discrete operator "
                             f"(ratio {dt / dt_limit:.3g} > 1); use dt <= {dt_limit:.4g} s")
    dt_inv_mass = np.zeros(n)
    dt_inv_mass[free] = dt / mass[free]
    f = np.zeros(n) if force is None else np.asarray(force, dtype=float)

    u = np.array(u0, dtype=float)
    v_half = np.array(v0, dtype=float)
    v_half[fixed] = 0.0
    v_half += 0.5 * dt_inv_mass * (f - K @ u)
    record = None if record is None else np.asarray(record, dtype=int)
    history = None
    if record is not None:
        history = np.empty((n_steps + 1, record.size))
        history[0] = u[record]
    for step in range(1, n_steps + 1):
        u += dt * v_half
        v_half += dt_inv_mass * (f - K @ u)
        if history is not None:
            history[step] = u[record]
        if callback is not None:
            view = u.view()
            view.flags.writeable = False
            callback(step, step * dt, view)
        if step % CHECK_EVERY == 0 and not np.all(np.isfinite(u)):
            raise NumericalError(f"{where}: displacements became non-finite by step {step} "
                                 f"(t = {step * dt:.4g} s)")
    if not np.all(np.isfinite(u)):
        raise NumericalError(f"{where}: displacements became non-finite by step {n_steps}")
    v = v_half - 0.5 * dt_inv_mass * (f - K @ u)  # back from t_{n+1/2} to t_n
    omega_max = 2.0 / dt_limit if np.isfinite(dt_limit) else 0.0
    info = {"method": "central-difference", "steps": int(n_steps), "dt": float(dt),
            "dt_limit": float(dt_limit), "omega_max": float(omega_max)}
    return ExplicitRun(u=u, v=v, times=np.arange(n_steps + 1) * dt, history=history, info=info)
