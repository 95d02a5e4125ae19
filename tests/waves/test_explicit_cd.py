"""Central differences (seed 002 Eqs. 4-7): exact discrete solutions and the stability checks."""
import numpy as np
import pytest
import scipy.sparse as sp
from numpy.testing import assert_allclose

from pdverify.errors import NumericalError
from pdverify.scenes.wave1d import wave_bar
from pdverify.corrections.registry import from_name
from pdverify.solvers.explicit import central_difference, gershgorin_limit, stability_limit


def surface_nodes(order=1):
    """The surface node method's ``wave-bar`` extension at Taylor ``order`` (its role)."""
    return from_name("surface-nodes").build_for("wave-bar", None, {"order": order})


EPS = np.finfo(float).eps


def test_oscillators_follow_the_exact_discrete_solution():
    # For u'' = -w^2 u the recurrence of Eq. (5), started by Eq. (6), is solved exactly by
    # u_n = u0 cos(n th) + v0 dt sin(n th) / sin(th), cos(th) = 1 - w^2 dt^2 / 2.
    # Tolerance: round-off growing linearly with the step count, 8 n eps of the amplitude.
    w2 = np.array([1.0, 4.0, 9.0])
    mass = np.array([2.0, 1.0, 0.5])
    K = sp.diags(w2 * mass)
    u0, v0 = np.array([1.0, -0.5, 0.2]), np.array([0.3, 0.0, -1.0])
    dt, n = 0.05, 400
    res = central_difference(K, u0, v0, dt, n, mass=mass, sample_steps=[0, 1, 17, 200, n])
    th = np.arccos(1 - w2 * dt ** 2 / 2)
    steps = res.steps[:, None]
    exact = u0 * np.cos(steps * th) + v0 * dt * np.sin(steps * th) / np.sin(th)
    amp = np.abs(u0) + np.abs(v0 * dt / np.sin(th))
    assert_allclose(res.u, exact, rtol=0, atol=8 * n * EPS * amp.max())
    assert_allclose(res.times, res.steps * dt, rtol=0, atol=0)


def test_constant_load_oscillates_about_the_static_solution():
    # u'' + w^2 u = f: u_n = f/w^2 + (u0 - f/w^2) cos(n th) (same recurrence, shifted).
    w2, f, dt, n = 4.0, 3.0, 0.1, 300
    res = central_difference(sp.diags([w2]), [0.0], [0.0], dt, n,
                             load=lambda t: np.array([f]), sample_steps=range(n + 1))
    th = np.arccos(1 - w2 * dt ** 2 / 2)
    exact = f / w2 * (1 - np.cos(np.arange(n + 1) * th))
    assert_allclose(res.u[:, 0], exact, rtol=0, atol=8 * n * EPS * f / w2)


def test_step_above_the_limit_is_refused_naming_the_limit():
    # Stability of Eq. (5): dt <= 2 / w_max; here w_max^2 = 9 exactly, limit 2/3 s.
    K = sp.diags([1.0, 4.0, 9.0])
    central_difference(K, np.ones(3), 0.0, 0.666, 10)  # just below: accepted
    with pytest.raises(NumericalError, match=r"stability limit .* = 0\.666667 s"):
        central_difference(K, np.ones(3), 0.0, 0.667, 10)


def test_steps_between_gershgorin_and_the_sharp_limit_are_accepted():
    # Gershgorin over-estimates lambda_max of the PD operator (every row sum vs the
    # alternating mode); a step between the two limits is stable and must not be refused.
    bar = wave_bar(1.0, 0.1, 100, 5000.0, surface_nodes(1))
    K = -bar.A
    bound, sharp = gershgorin_limit(K), stability_limit(K)
    assert bound.dt_limit < sharp.dt_limit
    dt = 0.5 * (bound.dt_limit + sharp.dt_limit)
    u0 = 0.02 * np.exp(-100 * (bar.x_free - 0.5) ** 2)
    res = central_difference(K, u0, 0.0, dt, 200, sample_steps=[200])
    assert res.info["dt_limit_estimate"] == "arpack"
    assert np.max(np.abs(res.u)) < 0.02  # energy is bounded: no growth
    with pytest.raises(NumericalError, match="stability limit"):
        central_difference(K, u0, 0.0, 1.01 * sharp.dt_limit, 10)


def test_arpack_limit_matches_dense_eigenvalues():
    # ARPACK's extreme eigenvalue at relative tolerance 1e-6 against LAPACK.
    bar = wave_bar(1.0, 0.1, 10, 5000.0, surface_nodes(1))
    lam = np.linalg.eigvals(-bar.A.toarray())
    assert_allclose(stability_limit(-bar.A).lambda_max, np.max(np.abs(lam)), rtol=1e-6)


def test_spectra_no_step_can_stabilise_are_refused():
    # Non-symmetric K: the extreme eigenvalue (+-i, resp. -1) is always examined.
    with pytest.raises(NumericalError, match="complex eigenvalue"):
        central_difference(sp.csr_matrix([[0.0, 1.0], [-1.0, 0.0]]), [1.0, 0.0], 0.0, 0.1, 5)
    with pytest.raises(NumericalError, match="negative eigenvalue"):
        central_difference(sp.csr_matrix([[-1.0, 0.5], [0.0, -0.5]]), [1.0, 1.0], 0.0, 0.1, 5)


def test_blow_up_is_reported_with_its_step():
    # Largest eigenvalue 3.9 is stable at dt = 1, but the mode with -1 grows by
    # (3 + sqrt 5)/2 per step and overflows near step 740.
    K = sp.diags([3.9, -1.0])
    with pytest.raises(NumericalError, match=r"blew up near step \d+"):
        central_difference(K, [0.0, 1.0], 0.0, 1.0, 2000)
