"""K_I and K_II from a displacement field (``pdverify.pd.cracks.fit_k_mixed``, issue 54):
the Williams fit of both modes in an annulus about the tip recovers known K_I and K_II
from Williams fields sampled at PD node positions on a crack at 30 degrees to the
lattice, to round-off when the field lies in the fitted space and within the bound of
its truncation otherwise."""
import math

import numpy as np
import pytest

from pdverify.pd.cracks import fit_k_mixed, williams_mixed_field, williams_mode2

E, NU = 1e9, 0.3
A_HALF, W = 0.5, 1.0                 # crack half-length and plate half-width (m)
BETA = math.radians(30.0)
DIR = (math.cos(BETA), math.sin(BETA))
TIP = (A_HALF * DIR[0], A_HALF * DIR[1])
K0 = 1e6 * math.sqrt(math.pi * A_HALF)
K1, K2 = 1.007 * K0, 0.535 * K0      # about the FEM's of plate-inclined-crack
#: c_n (2a)^-(n-1)/2: series decaying over the crack's length as a finite plate's
C1 = (1.0, -0.5, 0.25, -0.1, 0.05, -0.02, 0.01, -0.005, 0.002)
C2 = (1.0, 0.3, -0.2, 0.1, -0.05, 0.02, -0.01, 0.005, -0.002)
#: the orders fit_k_mixed fits by default
FITTED = 7


def _nodes(h):
    c = -W + (np.arange(int(round(2 * W / h))) + 0.5) * h
    X, Y = np.meshgrid(c, c, indexing="ij")
    return np.stack([X.ravel(), Y.ravel()], 1)


def _series(k, cs, n):
    a1 = k / math.sqrt(2 * math.pi)
    return [a1 * cs[i] * (2 * A_HALF) ** (-0.5 * i) for i in range(n)]


def _fit(x, u, h, **kw):
    return fit_k_mixed(x, u, TIP, DIR, E=E, nu=NU, plane="plane-stress", horizon=3 * h,
                       reach=0.4, **kw)


def test_first_mode_ii_term_is_the_textbook_field():
    """b_1 = K_II / sqrt(2 pi): Anderson, Fracture Mechanics, Table 2.2 (plane stress
    kappa), to round-off."""
    r = np.array([1e-3, 0.1, 0.7])[:, None]
    th = np.linspace(-np.pi, np.pi, 13)[None, :]
    mu, kap = E / (2 * (1 + NU)), (3 - NU) / (1 + NU)
    c = 1.0 / (2 * mu) * np.sqrt(r / (2 * np.pi))
    ux = c * np.sin(th / 2) * (kap + 1 + 2 * np.cos(th / 2) ** 2)
    uy = -c * np.cos(th / 2) * (kap - 1 - 2 * np.sin(th / 2) ** 2)
    gx, gy = williams_mode2(r, th, 1, E, NU, "plane-stress")
    np.testing.assert_allclose(gx / math.sqrt(2 * math.pi), ux, rtol=1e-12, atol=1e-25)
    np.testing.assert_allclose(gy / math.sqrt(2 * math.pi), uy, rtol=1e-12, atol=1e-25)


def test_mode_ii_second_term_is_a_rigid_rotation():
    x = np.array([[0.3, 0.1], [-0.2, 0.4]])
    u = williams_mixed_field(x, (0, 0), (1, 0), [], [0.0, 1.0], E, NU, "plane-stress")
    # u = c (y, -x): the rotation's field
    c = u[0, 0] / x[0, 1]
    np.testing.assert_allclose(u, c * np.c_[x[:, 1], -x[:, 0]], rtol=1e-14)


@pytest.mark.parametrize("h", [0.025, 1 / 60])
def test_a_field_of_the_fitted_terms_is_recovered_to_round_off(h):
    """Both modes' orders 1..7 and a translation, the crack at 30 degrees to the lattice:
    K_I and K_II to round-off (1e-10 relative: the least squares' condition, a few 1e4,
    times machine epsilon with margin)."""
    x = _nodes(h)
    u = williams_mixed_field(x, TIP, DIR, _series(K1, C1, FITTED), _series(K2, C2, FITTED),
                             E, NU, "plane-stress", translation=(1e-5, -2e-5))
    fit = _fit(x, u, h)
    assert abs(fit.k1 / K1 - 1) < 1e-10 and abs(fit.k2 / K2 - 1) < 1e-10
    assert fit.nodes > 100


@pytest.mark.parametrize("h", [0.025, 1 / 60, 0.0125])
def test_the_truncated_series_stays_inside_its_bound(h):
    """Nine orders of each mode in the field, 1..7 fitted: the error of each K is at
    most its amplification times the largest displacement of the omitted terms (8, 9)
    in the annulus (K is linear in the displacements), and the bound is below 5 % of
    K_0 (it says something; as fit_k's test)."""
    x = _nodes(h)
    s1, s2 = _series(K1, C1, 9), _series(K2, C2, 9)
    u = williams_mixed_field(x, TIP, DIR, s1, s2, E, NU, "plane-stress")
    fit = _fit(x, u, h)
    k = FITTED
    rest = williams_mixed_field(x, TIP, DIR, [0] * k + s1[k:], [0] * k + s2[k:], E, NU,
                                "plane-stress")
    d = x - np.array(TIP)
    r = np.hypot(d[:, 0], d[:, 1])
    inside = (r >= fit.window[0]) & (r <= fit.window[1])
    omitted = np.abs(rest[inside]).max()
    b1, b2 = fit.amplification[0] * omitted, fit.amplification[1] * omitted
    print(f"h={h}: K_I err {(fit.k1 - K1) / K0:.2e}, bound {b1 / K0:.2e}; K_II err "
          f"{(fit.k2 - K2) / K0:.2e}, bound {b2 / K0:.2e}; {fit.nodes} nodes")
    assert abs(fit.k1 - K1) <= b1 and abs(fit.k2 - K2) <= b2
    assert max(b1, b2) / K0 < 0.05


def test_the_faces_are_told_apart_by_the_angle():
    """Swapping the two faces (theta -> -theta of the nodes behind the tip, as a fit that
    did not use the crack's own frame would) changes K_II grossly: the fit depends on
    the side each node is on."""
    h = 0.025
    x = _nodes(h)
    u = williams_mixed_field(x, TIP, DIR, _series(K1, C1, 5), _series(K2, C2, 5), E, NU,
                             "plane-stress")
    bad = _fit(x, u, h)
    assert abs(bad.k2 / K2 - 1) < 1e-10
    flipped = fit_k_mixed(x, u, TIP, (-DIR[0], -DIR[1]), E=E, nu=NU, plane="plane-stress",
                          horizon=3 * h, reach=0.4)
    assert abs(flipped.k2 / K2 - 1) > 0.1


def test_too_few_nodes_and_bad_arguments_are_refused():
    h = 0.025
    x = _nodes(h)
    u = np.zeros_like(x)
    r = np.hypot(*(x - np.array(TIP)).T)
    few = np.zeros(len(x), bool)
    few[np.flatnonzero((r >= 0.2) & (r <= 0.4))[:5]] = True     # 5 nodes, 16 unknowns
    with pytest.raises(ValueError, match="holds 5 nodes"):
        fit_k_mixed(x, u, TIP, DIR, E=E, nu=NU, plane="plane-stress", horizon=3 * h,
                    reach=0.4, mask=few)
    with pytest.raises(ValueError, match="reach"):
        fit_k_mixed(x, u, TIP, DIR, E=E, nu=NU, plane="plane-stress", horizon=3 * h,
                    reach=0.1)
