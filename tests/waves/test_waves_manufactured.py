"""Manufactured 2D and 3D waves (issue 56): exact in space, second order in time, per treatment."""
import math

import numpy as np
import pytest
import scipy.sparse as sp
from numpy.testing import assert_allclose

from pdverify.errors import NumericalError
from pdverify.scenes import get_scene
from pdverify.solvers.dynamics import (DynamicSystem, newmark, stable_step, velocity_verlet)

EPS = np.finfo(float).eps

#: the fitted rate of a second-order integrator over the step halvings dt .. dt/8: the
#: error is C dt^2 (1 + O((w dt)^2)) for the field's frequency (w dt <= 0.25 at the base
#: step: < 1 % off the slope), but the O(dt^2) mismatch of the start also excites the
#: lattice's top modes, whose phase error at w_max dt = 1.8 (the base step) is outside
#: the asymptotic range (measured: the base pair's slope reaches 2.43 in 3D, the finer
#: pairs 1.98-2.04). Band 2 +- 0.25: a first-order scheme (slope 1) fails it, as
#: test_a_first_order_scheme_fails_the_band shows.
RATE_BAND = (1.75, 2.25)


def run(scene, method, **over):
    r = get_scene(scene).run(method, over)
    assert r.status == "ok", r.message
    return r


@pytest.mark.parametrize("scene", ["wave2d-manufactured", "wave3d-manufactured"])
@pytest.mark.parametrize("integrator", ["verlet", "newmark"])
def test_quadratic_motion_is_exact_to_round_off(scene, integrator):
    # Both integrators reproduce a motion quadratic in time exactly, and the discrete body
    # force makes P_h g(t) the semi-discrete solution: what remains is round-off. Each
    # step adds a few eps of the K u row sums (condition of K ~ 1e3 at these lattices)
    # over ~30 steps x 8 at the finest level: 1e-9 of the field's scale is 1e6 eps, far
    # above round-off and far below any time error (the sine's is 1e-3).
    r = run(scene, "none", operator="discrete", time_function="quadratic",
            integrator=integrator)
    assert r.metrics["max_error_pct"] < 1e-9 * 100
    assert max(r.diagnostics["time_levels_max_error"]) < 1e-9
    assert "time_rate" not in r.metrics      # nothing above round-off to fit


@pytest.mark.parametrize("scene", ["wave2d-manufactured", "wave3d-manufactured"])
@pytest.mark.parametrize("integrator", ["verlet", "newmark"])
def test_second_order_in_time(scene, integrator):
    r = run(scene, "none", operator="discrete", integrator=integrator)
    assert RATE_BAND[0] <= r.metrics["time_rate"] <= RATE_BAND[1]
    assert r.diagnostics["time_rate_levels"] == 4
    # the step stated in the record, below the explicit limit at the safety factor
    assert r.metrics["dt"] <= 0.9 * r.metrics["dt_limit"] * (1 + 1e-12)
    assert r.diagnostics["dt"] == r.metrics["dt"]


@pytest.mark.parametrize("method", ["energy", "volume", "surface-nodes", "pals"])
def test_every_carried_treatment_is_exact_in_space(method):
    # The quadratic motion with each treatment's own operator: round-off (bound as above).
    r = run("wave2d-manufactured", method, operator="discrete", time_function="quadratic")
    assert r.metrics["max_error_pct"] < 1e-9 * 100


def test_treatment_boundary_error_shows_against_none():
    # With the continuum operator's body force the field is not the lattice's own: the
    # uncorrected model's boundary error dominates (most of it within a horizon of the
    # surface), the surface nodes' is several times smaller (a finding, not a tolerance:
    # measured 15.7 % against 1.5 % at h = 0.1)
    none = run("wave2d-manufactured", "none")
    snm = run("wave2d-manufactured", "surface-nodes")
    assert none.metrics["boundary_max_error_pct"] > none.metrics["interior_max_error_pct"]
    assert snm.metrics["max_error_pct"] < 0.5 * none.metrics["max_error_pct"]
    # the time integration is not what errs: the finest step's error is the base's
    # within the base's own time error with the discrete operator (~0.2 % of the scale)
    assert abs(none.metrics["finest_max_error_pct"] - none.metrics["max_error_pct"]) < 1.0


def test_static_only_treatments_are_refused_with_their_reason():
    scene = get_scene("wave2d-manufactured")
    offered = scene.offered()
    assert {"none", "energy", "volume", "surface-nodes", "pals"} <= set(offered)
    from pdverify.corrections.registry import from_name
    for name in ("taylor-fictitious", "mirror-nodes", "pddo"):
        why = from_name(name).why_not(scene)
        assert why and why.startswith("static only:"), (name, why)


# ------------------------------------------------------------------- the integrators
def oscillators():
    w2 = np.array([1.0, 4.0, 9.0, 2.0])
    mass = np.array([2.0, 1.0, 0.5, 1.0])
    K = sp.diags(w2 * mass).tocsr()
    return K, mass, w2


def free_system(K, mass, load=None):
    n = K.shape[0]
    return DynamicSystem(K, mass, np.arange(n),
                         load or (lambda t: np.zeros(n)),
                         lambda t: (np.zeros(0), np.zeros(0), np.zeros(0)))


def test_stable_step_is_the_operators_own():
    # 2 / omega_max of uncoupled oscillators is 2 / max(w) exactly (dense eigenvalues)
    K, mass, w2 = oscillators()
    lim = stable_step(free_system(K, mass), where="t")
    assert_allclose(lim.dt_limit, 2 / np.sqrt(w2.max()), rtol=1e-14)
    assert lim.gershgorin >= w2.max()


def test_verlet_refuses_a_step_above_the_limit():
    K, mass, w2 = oscillators()
    system = free_system(K, mass)
    dt = 2 / np.sqrt(w2.max()) * (1 + 1e-6)
    with pytest.raises(NumericalError, match="exceeds the explicit stability limit"):
        velocity_verlet(system, np.ones(4), np.zeros(4), dt, 10, where="t")


@pytest.mark.parametrize("integ", ["verlet", "newmark"])
def test_oscillators_follow_the_exact_discrete_solution(integ):
    # Velocity Verlet's positions obey the central-difference recurrence,
    # u_n = u0 cos(n th) + v0 dt sin(n th)/sin(th), cos th = 1 - w^2 dt^2/2; Newmark's
    # average acceleration rotates by the Cayley angle, tan(th/2) = w dt / 2, no decay.
    # Tolerance: round-off growing with the step count, 8 n eps of the amplitude.
    K, mass, w2 = oscillators()
    system = free_system(K, mass)
    u0, v0 = np.array([1.0, -0.5, 0.2, 0.1]), np.array([0.3, 0.0, -1.0, 0.5])
    dt, n = 0.05, 400
    if integ == "verlet":
        res = velocity_verlet(system, u0, v0, dt, n, sample_steps=[0, 1, 17, n], where="t")
        th = np.arccos(1 - w2 * dt ** 2 / 2)
        amp_v = v0 * dt / np.sin(th)
    else:
        res = newmark(system, u0, v0, dt, n, sample_steps=[0, 1, 17, n], where="t")
        w = np.sqrt(w2)
        th = 2 * np.arctan(w * dt / 2)
        amp_v = v0 / w
    k = res.steps[:, None]
    if integ == "verlet":
        exact = u0 * np.cos(k * th) + amp_v * np.sin(k * th)
    else:
        exact = u0 * np.cos(k * th) + amp_v * np.sin(k * th)
    amp = np.abs(u0) + np.abs(amp_v)
    assert_allclose(res.u, exact, rtol=0, atol=8 * n * EPS * amp.max())


def test_newmark_conserves_the_energy_of_a_free_system():
    # The trapezoidal rule conserves the discrete energy of M u'' + K u = 0 exactly (the
    # work is zero): the balance is round-off (a few eps per step, 1e-12 over 400 steps)
    K, mass, _ = oscillators()
    res = newmark(free_system(K, mass), np.ones(4), np.zeros(4), 0.3, 400, where="t")
    assert res.energy_balance() < 1e-12


def forward_euler(system, u0, v0, dt, n_steps, sample_steps):
    """First order in time (u' = u + dt v, v' = v + dt a(u)): the control for the band.
    (Symplectic Euler would not do: its positions are the central-difference recurrence,
    second order.)"""
    u, v = np.array(u0, float), np.array(v0, float)
    out = []
    samples = set(int(s) for s in sample_steps)
    for step in range(n_steps + 1):
        if step in samples:
            out.append(u.copy())
        if step == n_steps:
            break
        t = step * dt
        a = (system.load(t) - system.K @ u) / system.mass
        u, v = u + dt * v, v + dt * a
    return np.array(out)


def test_a_first_order_scheme_fails_the_band():
    # The same forced oscillators, u = sin t exact with f = (k - m) sin t: velocity
    # Verlet's fitted slope lies in RATE_BAND, forward Euler's (first order) does not.
    K, mass, w2 = oscillators()
    shape = (w2 - 1.0) * mass

    system = free_system(K, mass, load=lambda t: shape * math.sin(t))
    T, base = 2.0, 40
    errs = {"verlet": [], "euler": []}
    dts = []
    for k in range(4):
        n = base * 2 ** k
        dt = T / n
        dts.append(dt)
        steps = np.arange(base + 1) * 2 ** k
        ref = np.sin(steps * dt)[:, None] * np.ones(4)
        vv = velocity_verlet(system, np.zeros(4), np.ones(4), dt, n, sample_steps=steps,
                             where="t").u
        eu = forward_euler(system, np.zeros(4), np.ones(4), dt, n, steps)
        errs["verlet"].append(np.abs(vv - ref).max())
        errs["euler"].append(np.abs(eu - ref).max())
    rate = {k: np.polyfit(np.log(dts), np.log(e), 1)[0] for k, e in errs.items()}
    assert RATE_BAND[0] <= rate["verlet"] <= RATE_BAND[1]
    assert not RATE_BAND[0] <= rate["euler"] <= RATE_BAND[1]
