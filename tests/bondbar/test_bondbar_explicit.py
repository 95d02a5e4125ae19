"""The explicit central-difference integrator and its stability limit (solvers.explicit)."""
import numpy as np
import pytest
import scipy.sparse as sp

from pdverify.errors import NumericalError
from pdverify.solvers.explicit import central_difference
from pdverify.solvers.modal import exact_stability_limit as stability_limit
from pdverify.solvers.modal import max_angular_frequency, min_angular_frequency

EPS = np.finfo(float).eps


def chain(n, rng, reach=1):
    """A spring chain fixed beyond its first point, random springs and masses (SPD).

    With ``reach`` > 1 every point is also tied to the point ``reach`` further on, which
    widens the band to ``reach``.
    """
    k = rng.uniform(0.5, 2.0, n)
    main = k + np.r_[k[1:], 0.0]
    K = sp.diags([main, -k[1:], -k[1:]], [0, 1, -1], format="csr")
    if reach > 1:
        i = np.arange(n - reach)
        s = rng.uniform(0.1, 0.3, i.size)
        K = K + sp.csr_matrix((np.r_[s, s, -s, -s], (np.r_[i, i + reach, i, i + reach],
                                                     np.r_[i, i + reach, i + reach, i])),
                              shape=(n, n))
    return K, rng.uniform(0.5, 2.0, n)


def test_single_oscillator_follows_the_exact_discrete_solution():
    # Central differences on m u'' + k u = 0 with u0 = 1, v0 = 0 give exactly
    # u_n = cos(n theta), cos(theta) = 1 - (omega dt)^2 / 2 (the scheme's characteristic roots).
    # Each step adds a few roundings, and they accumulate at most linearly: n * 8 eps.
    k, m, n = 4.0, 1.0, 2000
    omega = np.sqrt(k / m)
    dt = 0.9 * 2 / omega
    run = central_difference(sp.csr_matrix([[k]]), [1.0], [0.0], dt, n, mass=[m], record=[0])
    theta = np.arccos(1 - (omega * dt) ** 2 / 2)
    np.testing.assert_allclose(run.history[:, 0], np.cos(theta * np.arange(n + 1)), rtol=0,
                               atol=8 * n * EPS)
    assert run.info["dt_limit"] == pytest.approx(2 / omega, rel=4 * EPS)


def test_time_step_above_the_limit_is_refused(rng):
    K, mass = chain(50, rng)
    limit = stability_limit(K, mass)
    with pytest.raises(NumericalError, match="exceeds the stability limit"):
        central_difference(K, np.zeros(50), np.zeros(50), 1.5 * limit, 10, mass=mass)
    central_difference(K, np.zeros(50), np.zeros(50), limit, 10, mass=mass)  # at the limit: allowed


def test_the_limit_is_sharp(rng):
    # The limit is the operator's own 2/omega_max, not a conservative bound: just below it
    # the highest mode stays bounded, just above it grows by orders of magnitude.
    K, mass = chain(60, rng)
    limit = stability_limit(K, mass)
    u0 = rng.standard_normal(60) * 1e-3
    below = central_difference(K, u0, np.zeros(60), 0.995 * limit, 4000, mass=mass, record=range(60))
    above = central_difference(K, u0, np.zeros(60), 1.02 * limit, 200, mass=mass, dt_limit=np.inf,
                               record=range(60))
    scale = np.abs(u0).max()
    assert np.abs(below.history).max() < 10 * scale
    assert np.abs(above.history).max() > 1e6 * scale


def test_non_finite_displacements_fail_the_run(rng):
    K, mass = chain(20, rng)
    limit = stability_limit(K, mass)
    with np.errstate(all="ignore"), pytest.raises(NumericalError, match="non-finite"):
        central_difference(K, rng.standard_normal(20), np.zeros(20), 3 * limit, 3000, mass=mass,
                           dt_limit=np.inf)


def test_fixed_unknowns_and_record(rng):
    K, mass = chain(30, rng)
    u0 = np.linspace(0.0, 1.0, 30)
    dt = 0.5 * stability_limit(K, mass, fixed=[0])
    run = central_difference(K, u0, np.zeros(30), dt, 25, mass=mass, fixed=[0], record=[0, 29])
    assert run.history.shape == (26, 2)
    np.testing.assert_array_equal(run.history[:, 0], 0.0)
    assert run.history_times[-1] == pytest.approx(25 * dt, rel=4 * EPS)
    assert run.v_final[0] == 0.0
    assert run.u_final[29] == run.history[-1, 1]


@pytest.mark.parametrize("n, reach", [(120, 1), (900, 1), (900, 100)])  # dense, banded, Lanczos
def test_extreme_frequencies_match_a_dense_eigensolver(n, reach, rng):
    K, mass = chain(n, rng, reach)
    Minv = np.diag(1 / np.sqrt(mass))
    lam = np.linalg.eigvalsh(Minv @ K.toarray() @ Minv)
    # symmetric eigenvalues are accurate to ~eps * ||A||; sqrt halves the relative error,
    # the smallest is relative to ||A|| / lambda_min ~ n^2 larger
    assert max_angular_frequency(K, mass) == pytest.approx(np.sqrt(lam[-1]), rel=1e3 * EPS)
    assert min_angular_frequency(K, mass) == pytest.approx(
        np.sqrt(lam[0]), rel=1e3 * EPS * lam[-1] / lam[0])
