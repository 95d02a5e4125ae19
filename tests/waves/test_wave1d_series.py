"""The analytic side of seed 002: psi of Eq. (12), projection coefficients, PD and classical series."""
import subprocess
import sys
from math import erfc, pi, sqrt
from pathlib import Path

import mpmath
import numpy as np
import pytest
from numpy.testing import assert_allclose
from scipy.integrate import quad

from manufactured import wave1d as wv

ROOT = Path(__file__).resolve().parents[2]
EPS = np.finfo(float).eps
V = 5000.0   # sqrt(200e9 / 8000), seed 002
DELTA = 0.1  # 0.1 l, seed 002


def test_psi_matches_high_precision_closed_form_across_the_series_switch():
    # Eq. (12) in 40-digit arithmetic; our float closed form (k delta >= 1) and power series
    # (k delta < 1) must both agree with it. Tolerance: closed form loses at most ~ 1/z^2
    # digits to cancellation near z = 1 -> 64 eps relative (a few ulps times the loss).
    mpmath.mp.dps = 40
    z = np.array([1e-6, 1e-3, 0.1, 0.5, 0.999, 1.0, 1.001, 2.0, 7.85, 31.4, 250.0])
    k = z / DELTA
    exact = np.array([float(2 / mpmath.mpf(DELTA) ** 2
                            * (mpmath.mpf(zz) * mpmath.si(zz) + mpmath.cos(zz) - 1)) for zz in z])
    assert_allclose(wv.nonlocal_factor(k, DELTA), exact, rtol=64 * EPS, atol=0)


def test_psi_tends_to_k_squared_with_the_errata_rate():
    # ERRATA seed 002: psi ~ k^2 - k^4 delta^2 / 36; the series is alternating with the next
    # term k^2 z^4 / 1800 (z = k delta), which bounds the remainder for z < 1.
    k = np.array([pi, 5 * pi, 20 * pi])
    for delta in (1e-1 / 8, 1e-2, 1e-3, 1e-4):
        z = k * delta
        psi = wv.nonlocal_factor(k, delta)
        two_term = k ** 2 - k ** 4 * delta ** 2 / 36
        assert np.all(np.abs(psi - two_term) <= k ** 2 * z ** 4 / 1800 + 4 * EPS * k ** 2)
    assert_allclose(wv.nonlocal_factor(k, 0.0), k ** 2, rtol=0, atol=0)
    assert np.all(wv.nonlocal_factor(k, 1e-7) / k ** 2 > 1 - 1e-9)


@pytest.mark.parametrize("k", [pi, 5 * pi, 20 * pi, 79 * pi])
def test_operator_eigenvalue_on_sine_by_quadrature_is_minus_v2_psi(k):
    # Eq. (2) applied to sin(kx) at an interior point, integrated by adaptive quadrature
    # (symmetric form, no principal value): (v^2/delta) int_0^delta [u(x+xi) + u(x-xi) -
    # 2u(x)] / xi^2 dxi = -v^2 psi sin(kx) (ERRATA: psi > 0, so the eigenvalue is negative).
    # Tolerance: quad's epsrel = 1e-12 plus the round-off of the numerator near xi -> 0.
    x = 0.37
    def integrand(xi):
        return (np.sin(k * (x + xi)) + np.sin(k * (x - xi)) - 2 * np.sin(k * x)) / xi ** 2
    val, abserr = quad(integrand, 0.0, DELTA, epsabs=0.0, epsrel=1e-12, limit=500)
    eig = V ** 2 / DELTA * val / np.sin(k * x)
    expected = -V ** 2 * wv.nonlocal_factor(k, DELTA)
    assert expected < 0
    assert_allclose(eig, expected, rtol=1e-9)


def test_paper_coefficients_equal_the_projection():
    # Eq. (11)'s closed form integrates the Gaussian over the whole line; the projection on
    # [0, 1] differs by the tails beyond |x - 1/2| > 1/2: |db| <= 2 * 0.02 sqrt(pi)/10 erfc(5).
    tails = 2 * 0.02 * sqrt(pi) / 10 * erfc(5.0)
    b = wv.sine_coefficients(wv.gaussian_pulse, n_terms=80)
    assert_allclose(b, wv.paper_coefficients(80), rtol=0, atol=tails + 16 * EPS * 0.02)
    assert np.all(np.abs(b[1::2]) < tails)  # even modes vanish for a pulse centred at l/2


def test_projection_recovers_a_finite_sine_sum_and_its_single_mode_evolution():
    # A sum of modes is its own projection (orthogonality); each mode evolves as
    # cos(v sqrt(psi) t) exactly. Tolerance: quadrature round-off, 64 eps of the amplitudes.
    length = 2.0
    c = {1: 0.3, 4: -0.05, 9: 0.01}

    def initial(x):
        return sum(a * np.sin(m * pi * x / length) for m, a in c.items())

    b = wv.sine_coefficients(initial, length=length, n_terms=12)
    expected = np.zeros(12)
    for m, a in c.items():
        expected[m - 1] = a
    assert_allclose(b, expected, rtol=0, atol=64 * EPS)
    x = np.linspace(0, length, 33)
    t = np.array([0.0, 1.3e-4, 4.1e-4])
    u = wv.pd_wave_displacement(x, t, horizon=DELTA, wave_speed=V, length=length,
                                n_terms=12, initial=initial)
    k = np.array(list(c)) * pi / length
    om = V * np.sqrt(wv.nonlocal_factor(k, DELTA))
    exact = sum(a * np.sin(kk * x)[None, :] * np.cos(w * t)[:, None]
                for a, kk, w in zip(c.values(), k, om))
    assert_allclose(u, exact, rtol=0, atol=64 * EPS)


def test_classical_series_matches_dalembert():
    # The Gaussian is 0.02 e^-25 = 2.8e-13 at the ends: its odd extension jumps by that
    # much, which no truncated series resolves; agreement to a few times the jump.
    jump = 0.02 * np.exp(-25.0)
    x = np.linspace(0, 1, 401)
    for t in (0.0, 3e-5, 1e-4, 1.7e-4, 2e-4):
        cl = wv.classical_wave_displacement(x, t, wave_speed=V)
        assert_allclose(cl, wv.dalembert_displacement(x, t, wave_speed=V), rtol=0, atol=4 * jump)


def test_pd_series_tends_to_classical_as_the_horizon_shrinks():
    # |u_PD - u_CCM| <= sum |b_m| |omega_PD - omega_CCM| t, and omega_CCM - omega_PD
    # <= v k (1 - sqrt(1 - k^2 delta^2 / 36)) from psi >= k^2 - k^4 delta^2/36 (alternating
    # series); the bound shrinks as delta^2.
    x = np.linspace(0, 1, 201)
    t = 2e-4
    s_cl = wv.wave_series(horizon=0.0, wave_speed=V)
    for delta in (1e-2, 1e-3):
        s_pd = wv.wave_series(horizon=delta, wave_speed=V)
        z2 = (s_pd.k * delta) ** 2 / 36
        dw = V * s_pd.k * (1 - np.sqrt(np.clip(1 - z2, 0, None)))
        bound = np.sum(np.abs(s_pd.b) * np.minimum(dw * t, 2.0)) + 1e-15
        gap = np.max(np.abs(s_pd.displacement(x, t) - s_cl.displacement(x, t)))
        assert gap <= bound


def test_default_series_is_the_papers_problem_and_its_tail_is_negligible():
    # t = 0 reproduces the pulse (to the 2.8e-13 end jump, see above); the tail of the
    # 40-mode series (next 40 coefficients) is below that level too.
    s = wv.wave_series(horizon=DELTA, wave_speed=V)
    x = np.linspace(0, 1, 101)
    jump = 0.02 * np.exp(-25.0)
    assert_allclose(s.displacement(x, 0.0), wv.gaussian_pulse(x), rtol=0, atol=4 * jump)
    assert s.tail < 4 * jump
    u = wv.pd_wave_displacement(x, np.array([0.0, 1e-4]), horizon=DELTA, wave_speed=V)
    assert u.shape == (2, x.size)


def test_reference_side_does_not_import_pdverify():
    code = ("import sys, manufactured.wave1d; "
            "bad = [m for m in sys.modules if m.split('.')[0] == 'pdverify']; "
            "print(bad); sys.exit(1 if bad else 0)")
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          timeout=120, cwd=ROOT)
    assert proc.returncode == 0, proc.stdout + proc.stderr
