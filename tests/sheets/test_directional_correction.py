"""Seed 003 §3: the directional energy correction, continuum (Eq. 14) and discrete (Eq. 5)."""
import numpy as np
import pytest

from pdverify.corrections.energy_directional import (directional_factor, own_factor_energy_density,
                                                     ray_distance)
from pdverify.pd import BondBasedModel, BoxGrid, Closure, bond_micromodulus, build_stencil, get_influence
from pdverify.scenes.sheets import lattice_moduli

DELTA = 1.0
# Gauss-Legendre on [0, d] is exact for c(xi) xi^2 (degree <= 3 for both micromoduli)
GL = np.polynomial.legendre.leggauss(4)


def _truncated_radial(c, d):
    """int_0^d c(xi) xi^2 dxi by Gauss-Legendre (exact: polynomial integrand)."""
    t, w = GL
    xi = 0.5 * d[:, None] * (t + 1.0)
    return np.sum(0.5 * d[:, None] * w * c(xi) * xi ** 2, axis=1)


def _tensor(point, lower, upper, influence, n_angles=720):
    """I = int_Omega P(e) phi(x, e) int_0^d c xi^2 dxi dOmega, D = 2 (Eqs. 9-11, 13-14).

    Angles on a uniform grid offset by half a step (no direction lies in a face); the
    trapezoid rule is exact for P, a trigonometric polynomial of degree 4 (n_angles >= 5).
    Directions leaving the body at once (d = 0: no material) contribute nothing.
    """
    inf = get_influence(influence)
    theta = (np.arange(n_angles) + 0.5) * 2 * np.pi / n_angles
    e = np.stack([np.cos(theta), np.sin(theta)], axis=1)
    x = np.tile(point, (n_angles, 1))
    d = np.minimum(ray_distance(x, e, lower, upper), DELTA)
    radial = np.zeros(n_angles)
    inside = d > 0
    radial[inside] = (directional_factor(x[inside], e[inside], lower, upper, DELTA, inf, 2)
                      * _truncated_radial(lambda s: inf.omega(s, DELTA), d[inside]))
    P = np.einsum("ti,tj,tk,tl->tijkl", e, e, e, e)
    return np.einsum("t,tijkl->ijkl", radial, P) * 2 * np.pi / n_angles


def _bulk(influence):
    return _tensor(np.array([0.0, 0.0]), np.array([-5.0, -5.0]), np.array([5.0, 5.0]), influence)


@pytest.mark.parametrize("influence", ["constant", "conical"])
@pytest.mark.parametrize("depth", [0.05, 0.3, 0.5, 0.77, 0.999])
def test_factor_restores_the_bulk_tensor_in_a_half_plane(influence, depth):
    # a point at distance 0 < h < delta from the face y = 0 of a wide body: Eq. (14) makes
    # every direction's truncated radial integral the bulk one, so I = H to round-off
    got = _tensor(np.array([0.0, depth]), np.array([-50.0, 0.0]), np.array([50.0, 50.0]), influence)
    np.testing.assert_allclose(got, _bulk(influence), rtol=1e-12, atol=1e-12 * _bulk(influence).max())


@pytest.mark.parametrize("influence", ["constant", "conical"])
@pytest.mark.parametrize("point", [(0.1, 0.2), (0.5, 0.5), (0.9, 0.05)])
def test_factor_restores_the_bulk_tensor_at_a_corner(influence, point):
    got = _tensor(np.array(point), np.array([0.0, 0.0]), np.array([4.0, 4.0]), influence)
    np.testing.assert_allclose(got, _bulk(influence), rtol=1e-12, atol=1e-12 * _bulk(influence).max())


@pytest.mark.parametrize("influence", ["constant", "conical"])
def test_a_point_on_the_surface_recovers_exactly_half(influence):
    # h = 0: the outward half of the directions has no material and no factor can restore
    # it; the inward half is complete (d = delta), so I = H / 2 (P(e) = P(-e))
    got = _tensor(np.array([0.0, 0.0]), np.array([-50.0, 0.0]), np.array([50.0, 50.0]), influence)
    np.testing.assert_allclose(got, 0.5 * _bulk(influence), rtol=1e-12,
                               atol=1e-12 * _bulk(influence).max())


def test_phi_is_the_power_law_for_a_constant_micromodulus():
    # Eq. (14): (delta / d)^(D + 1) for constant c; the conical one differs (ERRATA)
    x, e = np.array([[0.0, 0.4]]), np.array([[0.0, -1.0]])
    lo, hi = np.array([-9.0, 0.0]), np.array([9.0, 9.0])
    assert directional_factor(x, e, lo, hi, DELTA, get_influence("constant"), 2)[0] == \
        pytest.approx((1 / 0.4) ** 3, rel=1e-14)
    conical = directional_factor(x, e, lo, hi, DELTA, get_influence("conical"), 2)[0]
    assert conical == pytest.approx((1 / 3 - 1 / 4) / (0.4 ** 3 / 3 - 0.4 ** 4 / 4), rel=1e-14)


# --------------------------------------------------------------------- discrete, Eq. 5
STRAINS = {"uniaxial": (1e-3, 0.0, 0.0), "biaxial": (1e-3, 1e-3, 0.0), "shear": (0.0, 0.0, 1e-3)}


def _energy_deviation(m_ratio, strain, corrected=True):
    """max |W_i / W_bulk - 1| per depth (in spacings) on the clamped sheet's lattice."""
    L, h = 4 * 0.005, 0.005 / m_ratio
    lo, hi = np.array([-L / 2, -L / 2]), np.array([L / 2, L / 2])
    g = BoxGrid((L, L), tuple(lo), h, placement="on-surface")
    inf = get_influence("constant")
    model = BondBasedModel(g, build_stencil(2, float(m_ratio), quadrature="full-cells"),
                           bond_micromodulus("constant", 2, 1e9, 0.005, plane="stress"), inf,
                           Closure())
    exx, eyy, gam = strain
    F = np.array([[exx, gam / 2], [gam / 2, eyy]])
    u = (g.x @ F.T).T.ravel()
    if corrected:
        W = own_factor_energy_density(model, u, lo, hi, 0.005)
    else:
        W = model.strain_energy_density(u)
    E, nu = lattice_moduli(model)            # the lattice's C (Voigt): cubic, and a
    C11 = E / (1 - nu ** 2)                  # bond-based one has C66 = C12 (Cauchy)
    C = np.array([[C11, nu * C11, 0], [nu * C11, C11, 0], [0, 0, nu * C11]])
    v = np.array([exx, eyy, gam])
    dev = np.abs(W / (0.5 * v @ C @ v) - 1)
    depth = np.rint(np.minimum(np.abs(g.x - lo), np.abs(hi - g.x)).min(axis=1) / h).astype(int)
    corner = np.all(np.isclose(np.abs(g.x), L / 2), axis=1)
    # nodes along an edge counted from the nearest corner (0 = the corner itself)
    corner_distance = np.rint((L / 2 - np.abs(g.x)).max(axis=1) / h).astype(int)
    return dev, depth, corner, corner_distance


@pytest.mark.parametrize("strain", list(STRAINS))
def test_affine_energy_density_of_the_corrected_lattice(strain):
    # m = 6, the clamped sheet's lattice. Numbers measured and stated (seed 003 claims
    # consistency for the continuum; the discrete one-point quadrature of a truncated ray
    # is what remains):
    dev, depth, corner, corner_distance = _energy_deviation(6, STRAINS[strain])
    unc = _energy_deviation(6, STRAINS[strain], corrected=False)[0]
    # the bulk (a complete discrete horizon: deeper than delta, since the surface row
    # carries half volumes) is exact, the reference being the lattice's own moduli
    # (sums of ~100 bond energies: 1e-12 ~ 1e4 eps)
    assert dev[depth > 6].max() < 1e-12
    # finding 003-directional-surface (pdverify.deviations):
    # on the surface the method's continuum property: a quarter at corners, half on the
    # edges; measured along an edge, the corner's truncation fades within a few spacings:
    # |W / W_bulk - 1/2| <= 0.16, 0.042, 0.02 at 1, 2, >= 3 spacings from a corner
    np.testing.assert_allclose(dev[corner], 0.75, atol=0.05)
    edge = (depth == 0) & ~corner
    for reach, bound in ((1, 0.16), (2, 0.042), (np.inf, 0.02)):
        sel = edge & (corner_distance >= min(reach, 3)) & (corner_distance <= reach)
        assert np.all(np.abs(dev[sel] - 0.5) <= bound), (reach, np.abs(dev[sel] - 0.5).max())
    # first row inside: the discrete truncated ray is a single surface node (<= 35 %);
    # from the second row on the correction holds to <= 8 %, from the third to <= 4 %
    assert dev[depth == 1].max() < 0.36
    assert dev[(depth >= 2)].max() < 0.085
    assert dev[(depth >= 3)].max() < 0.04
    # the uncorrected lattice is off by the full truncation on every near-surface row
    assert unc[depth == 2].max() > 0.2 and unc[depth == 3].max() > dev[depth == 3].max()


@pytest.mark.slow  # slow tier (issue 32): 10 s: a convergence study up to m = 24 (loaded machine)
def test_corrected_energy_converges_at_fixed_depth_with_m():
    # at depth delta / 2 the deviation falls as m grows (delta fixed): 3.7, 2.8, 1.1 %
    devs = []
    for m in (6, 12, 24):
        dev, depth, *_ = _energy_deviation(m, STRAINS["uniaxial"])
        devs.append(dev[depth == m // 2].max())
    assert devs[0] > devs[1] > devs[2]
    assert devs[-1] < 0.015
