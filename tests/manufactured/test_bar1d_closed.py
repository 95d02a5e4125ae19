"""Seed 000 closed forms (Tables 1, 2, B1; Eqs. 65-68) against their defining integrals."""
import numpy as np
import pytest
from scipy.integrate import quad

from manufactured import bar1d as closed

DELTA, L = 0.15, 1.0


def m_ratio_quad(x):
    # Eq. (8)/(27): m(x) = A delta int_{H cap [0, l]} |x' - x| dx', over m_inf = A delta^3
    lo, hi = max(0.0, x - DELTA), min(L, x + DELTA)
    val = quad(lambda xp: abs(xp - x), lo, hi, points=[x])[0]
    return DELTA * val / DELTA ** 3


def flux_quad(xpp):
    # Eq. (24): tau / (E eps) = A delta int_{x''-delta}^{x''} int_{x''}^{x+delta} (1/m + 1/m') dx' dx
    def inner(x):
        lo, hi = xpp, min(x + DELTA, L)
        if hi <= lo:
            return 0.0
        kinks = [p for p in (DELTA, L - DELTA) if lo < p < hi]  # 1/m has kinks there
        return quad(lambda xp: 1 / m_ratio_quad(x) + 1 / m_ratio_quad(xp), lo, hi, limit=200,
                    points=kinks or None)[0]
    lo = max(0.0, xpp - DELTA)
    kinks = [p for p in (DELTA, L - DELTA) if lo < p < xpp]
    val = quad(inner, lo, xpp, limit=200, points=kinks or None)[0]
    return DELTA * val / DELTA ** 3


def body_quad(x):
    # Eqs. (4), (22): b = -E eps A delta int_{H cap Omega} (1/m + 1/m') sign(x' - x) dx';
    # normalised by tau_inf / delta.
    lo, hi = max(0.0, x - DELTA), min(L, x + DELTA)
    f = lambda xp: (1 / m_ratio_quad(x) + 1 / m_ratio_quad(xp)) * np.sign(xp - x)
    val = quad(f, lo, hi, points=[p for p in (x, DELTA, L - DELTA) if lo < p < hi], limit=200)[0]
    return -DELTA * DELTA * val / DELTA ** 3


POINTS = [0.0, 0.02, 0.07, 0.11, 0.149, 0.151, 0.2, 0.26, 0.299, 0.5, 0.8, 0.93, 0.99]


@pytest.mark.parametrize("x", POINTS)
def test_table1_weighted_volume(x):
    # quadrature of a piecewise-smooth integrand: agreement to 1e-10 (quad's tolerance)
    assert closed.weighted_volume_ratio(np.array([x]), horizon=DELTA, length=L)[0] == \
        pytest.approx(m_ratio_quad(x), abs=1e-10)


@pytest.mark.parametrize("x", POINTS)
def test_table2_force_flux(x):
    # nested adaptive quadrature: 1e-8 absolute (tau/tau_inf ~ 1)
    assert closed.force_flux_ratio(np.array([x]), horizon=DELTA, length=L)[0] == \
        pytest.approx(flux_quad(x), abs=1e-8)


@pytest.mark.parametrize("x", [p for p in POINTS if 0 < p < L])
def test_tableB1_body_force(x):
    assert closed.body_force_ratio(np.array([x]), horizon=DELTA, length=L)[0] == \
        pytest.approx(body_quad(x), abs=1e-8)


def test_flux_features_match_the_paper():
    # seed 000 §2.2 / issue #2: peak 1.26285 tau_inf at x/delta = 0.77160, tau = tau_inf
    # at 0.39403 (to 1e-5, the printed digits).
    peak, at, crossing = closed.flux_features()
    assert peak == pytest.approx(1.26285, abs=1e-5)
    assert at == pytest.approx(0.77160, abs=1e-5)
    assert crossing == pytest.approx(0.39403, abs=1e-5)


@pytest.mark.parametrize("fn, key", [(closed.uniform_load_displacement, "b0"),
                                     (closed.linear_load_displacement, "b1"),
                                     (closed.sine_load_displacement, "bs")])
def test_classical_solutions_solve_the_bar_equation(fn, key):
    # Eqs. (66)-(68): E u'' + b = 0, u(0) = 0, u'(l) = 0. Second differences with
    # h = 1e-3 are exact for the polynomials and O(h^2) ~ 1e-6 relative for the sine;
    # the central first difference at l errs by at most h^2/6 max|u'''| = h^2/6 max|b'|/E.
    E, h = 1e9, 1e-3
    x = np.linspace(0.1, 0.9, 9)
    u = lambda z: fn(z, **{key: 1e6}, E=E, length=1.0)
    upp = (u(x + h) - 2 * u(x) + u(x - h)) / h ** 2
    b = {"b0": 1e6 + 0 * x, "b1": 1e6 * x, "bs": 1e6 * np.sin(np.pi * x)}[key]
    np.testing.assert_allclose(E * upp, -b, rtol=1e-5)
    assert u(np.array([0.0]))[0] == 0.0
    assert (u(np.array([1.0 + h]))[0] - u(np.array([1.0 - h]))[0]) / (2 * h) == \
        pytest.approx(0.0, abs=h ** 2 / 6 * 1e6 * np.pi / E * (1 + 1e-6))
