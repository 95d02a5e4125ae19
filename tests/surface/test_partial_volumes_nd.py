"""Partial volumes beta in 2D/3D and the discrete weighted volume (seed 001 §3.1, Eq. 22)."""
import numpy as np
import pytest
from scipy.integrate import quad

from pdverify.pd.bonds import (bond_pairs, half_stencil, partial_volumes, rectangle_disk_area,
                               stencil_offsets)
from pdverify.pd import get_influence

# Closed-form sums are exact up to round-off of ~500 terms of size <= 1:
# 1e-12 relative is ~5000 eps, a generous bound on summation error.
SUM_RTOL = 1e-12


@pytest.mark.parametrize("dim", [2, 3])
@pytest.mark.parametrize("m_ratio", [1.7, 2.5, 3.0, 4.0])
def test_fractions_fill_the_ball_exactly(dim, m_ratio):
    k = stencil_offsets(dim, m_ratio)
    beta = partial_volumes(k, m_ratio)
    ball = np.pi * m_ratio ** 2 if dim == 2 else 4.0 / 3.0 * np.pi * m_ratio ** 3
    # the node's own cell is wholly inside for m_ratio >= sqrt(d)/2
    np.testing.assert_allclose(beta.sum() + 1.0, ball, rtol=SUM_RTOL)
    assert np.all((beta > 0) & (beta <= 1))


def test_stencil_is_symmetric_and_halves_pair_up():
    k = stencil_offsets(3, 3.0)
    assert {tuple(v) for v in k} == {tuple(-v) for v in k}
    half = half_stencil(k)
    assert 2 * half.sum() == k.shape[0]
    beta = partial_volumes(k, 3.0)
    # beta(k) = beta(-k) by symmetry of the ball; exact to round-off of the quadrature
    lookup = {tuple(v): b for v, b in zip(k, beta)}
    np.testing.assert_allclose([lookup[tuple(-v)] for v in k], beta, rtol=0, atol=1e-14)


def test_3d_fraction_matches_adaptive_quadrature():
    """Independent check: integrate the exact 2D cross-section with scipy's adaptive quad."""
    R = 3.0
    k = np.array([[3, 1, 0], [2, 2, 1], [3, 2, 1], [1, 2, 2], [0, 3, 1]])
    beta = partial_volumes(k, R)
    for kk, b in zip(k, beta):
        lo, hi = kk - 0.5, kk + 0.5

        def area(x):
            r = np.sqrt(max(R * R - x * x, 0.0))
            return float(rectangle_disk_area(lo[1], hi[1], lo[2], hi[2], r))
        ref, err = quad(area, lo[0], min(hi[0], R), epsabs=1e-14, epsrel=1e-13, limit=200)
        # quad's own error estimate is < 1e-13; both are exact integrals of the same area
        np.testing.assert_allclose(b, ref, rtol=0, atol=1e-12)


def test_2d_fraction_matches_closed_form_segment():
    """A cell cut by the circle along one straight chord: area = circular segment."""
    R = 3.0
    # cell [2.5, 3.5] x [-0.5, 0.5] holds the segment of the disk beyond x = 2.5 within |y| <= 0.5
    beta = partial_volumes(np.array([[3, 0]]), R)[0]
    ref, _ = quad(lambda y: max(np.sqrt(R * R - y * y) - 2.5, 0.0), -0.5, 0.5, epsabs=1e-14)
    np.testing.assert_allclose(beta, ref, rtol=0, atol=1e-13)


@pytest.mark.parametrize("dim", [2, pytest.param(3, marks=pytest.mark.slow)])  # 3D: 17 s
def test_weighted_volume_converges_to_the_analytic_value(dim):
    """m_h = sum omega |xi|^2 beta V -> m (3D: 4 pi Delta_1) as h -> 0 at fixed delta."""
    delta = 1.0
    ms = np.array([3, 4, 6, 8, 12, 16])
    errs = []
    for m in ms:
        k = stencil_offsets(dim, float(m))
        beta = partial_volumes(k, float(m))
        h = delta / m
        r = np.linalg.norm(k, axis=1) * h
        m_h = np.sum(np.exp(-(r / delta) ** 2) * r ** 2 * beta) * h ** dim
        errs.append(abs(m_h / get_influence("gaussian").weighted_volume(dim, delta) - 1.0))
    slope = np.polyfit(np.log(1.0 / ms), np.log(errs), 1)[0]
    # mid-point quadrature with exact cell fractions: second order in h (margin 0.2)
    assert slope > 1.8, (slope, errs)
    # finest level (m = 16): observed ~1e-6 to 4e-6; ceiling one decade above h^2 from m = 3
    assert errs[-1] < 1.5e-3 * (3 / 16) ** 2 * 1.5


def test_weighted_volume_3d_is_4_pi_delta_1():
    # ERRATA seed 001: Delta_1 / delta^5 = 0.1002687981 (10 digits quoted)
    np.testing.assert_allclose(get_influence("gaussian").weighted_volume(3, 1.0), 4 * np.pi * 0.1002687981,
                               rtol=1e-9)


def test_bond_pairs_cover_each_pair_once():
    shape = (4, 3, 5)
    k = stencil_offsets(3, 1.7)
    a, b, which = bond_pairs(shape, k[half_stencil(k)])
    pairs = {(min(x, y), max(x, y)) for x, y in zip(a, b)}
    assert len(pairs) == a.size
    idx = np.indices(shape).reshape(3, -1).T
    np.testing.assert_array_equal(idx[b] - idx[a], k[half_stencil(k)][which])
