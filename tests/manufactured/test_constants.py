"""PD constants, radial and angular moments against the closed forms quoted in the seeds."""
import pytest
import sympy as sp

from manufactured.constants import DELTA, E_SYM, NU_SYM, classical_moduli, constants, derive_constants
from manufactured.influence import (INFLUENCES, radial_moment, sphere_moment, weighted_volume)

E, nu, delta = E_SYM, NU_SYM, DELTA
LAM = E * nu / ((1 + nu) * (1 - 2 * nu))
MU = E / (2 * (1 + nu))


def _same(a, b):
    return sp.simplify(a - b) == 0


# ---------------------------------------------------------------- moments

def test_gaussian_delta1_delta2_closed_forms():
    # seed 001, Eqs. (53) and (55): exact closed forms
    delta1 = (sp.Rational(3, 8) * sp.sqrt(sp.pi) * sp.erf(1) - sp.Rational(5, 4) * sp.exp(-1)) * delta**5
    delta2 = (sp.Rational(15, 32) * sp.sqrt(sp.pi) * sp.erf(1) - sp.Rational(29, 16) * sp.exp(-1)) * delta**7
    assert _same(radial_moment("gaussian", 4, delta), delta1)
    assert _same(radial_moment("gaussian", 6, delta) / 2, delta2)


def test_gaussian_delta1_delta2_numbers():
    # ERRATA 001: Delta_1/delta^5 = 0.1002687981, Delta_2/delta^7 = 0.0333661374, printed to
    # 10 decimals, so atol = half a unit in the last printed digit.
    assert abs(float(radial_moment("gaussian", 4, 1)) - 0.1002687981) <= 5e-11
    assert abs(float(radial_moment("gaussian", 6, 1)) / 2 - 0.0333661374) <= 5e-11


@pytest.mark.slow  # slow tier (issue 32): 23 s: sympy's integrals (loaded machine)
def test_radial_moments_against_direct_integration():
    # exact: sympy integrates int_0^delta omega l^k dl directly (independent of the recurrence
    # and closed forms in influence.py); also seed 001, Eq. (54) (double integral = Delta_1).
    l, s, r = sp.symbols("l s r", positive=True)
    d = sp.Symbol("d", positive=True)
    omegas = {"gaussian": sp.exp(-l**2 / d**2), "hyperbolic": d / l,
              "constant": sp.Integer(1), "conical": 1 - l / d}
    for name, omega in omegas.items():
        for k in (1, 2, 3, 4, 5, 6, 7):
            direct = sp.integrate(omega * l**k, (l, 0, d))
            assert _same(direct, radial_moment(name, k, d)), (name, k)
    g = sp.exp(-r**2 / d**2)
    eq54 = sp.integrate(sp.integrate(g * r**3, (r, s, d)), (s, 0, d))
    assert _same(eq54, radial_moment("gaussian", 4, d))
    eq55 = sp.integrate(sp.integrate(g * r**3 * (r**2 - 3 * s * r + 3 * s**2), (r, s, d)), (s, 0, d))
    assert _same(eq55, radial_moment("gaussian", 6, d) / 2)


def test_hyperbolic_zeroth_moment_diverges():
    with pytest.raises(ValueError, match="influence"):
        radial_moment("hyperbolic", 0, 1)


def test_sphere_moments_3d_match_eqs_48_to_52():
    # seed 001, Eqs. (48)-(52), exact
    assert sphere_moment((0, 0, 0)) == 4 * sp.pi
    assert sphere_moment((2, 0, 0)) == 4 * sp.pi / 3
    assert sphere_moment((0, 0, 4)) == 4 * sp.pi / 5
    assert sphere_moment((2, 2, 0)) == 4 * sp.pi / 15
    assert sphere_moment((4, 0, 2)) == 4 * sp.pi / 35
    assert sphere_moment((1, 2, 0)) == 0


def test_sphere_moments_against_direct_integration():
    # exact: int over the circle / sphere in polar / spherical coordinates by sympy
    phi, th = sp.symbols("phi theta")
    for a, b in [(0, 0), (2, 0), (4, 0), (2, 2), (4, 2), (6, 0)]:
        direct = sp.integrate(sp.cos(phi)**a * sp.sin(phi)**b, (phi, 0, 2 * sp.pi))
        assert _same(direct, sphere_moment((a, b))), (a, b)
    for a, b, c in [(2, 2, 2), (4, 2, 0), (0, 2, 4), (6, 0, 0)]:
        m = (sp.sin(th) * sp.cos(phi), sp.sin(th) * sp.sin(phi), sp.cos(th))
        direct = sp.integrate(m[0]**a * m[1]**b * m[2]**c * sp.sin(th), (phi, 0, 2 * sp.pi), (th, 0, sp.pi))
        assert _same(direct, sphere_moment((a, b, c))), (a, b, c)
    assert sphere_moment((0,)) == 2 and sphere_moment((2,)) == 2  # 1D: {-1, +1}


def test_weighted_volumes():
    # seed 001, Eq. (56): m = 4 pi Delta_1 (3D Gaussian); seed 000, Eq. (25): m = delta^3
    # (1D hyperbolic, unit area). Exact.
    assert _same(weighted_volume("gaussian", 3, delta), 4 * sp.pi * radial_moment("gaussian", 4, delta))
    assert _same(weighted_volume("hyperbolic", 1, delta), delta**3)


# ---------------------------------------------------------------- state-based constants

@pytest.mark.parametrize("influence", INFLUENCES)
def test_state_based_3d_constants_match_seed001(influence):
    # seed 001, Sec. 2.1 below Eq. (11): c_theta = 3, k_theta = -3(1-4nu)E/(2(1+nu)(1-2nu)),
    # k_e = 15E/(2(1+nu)) ("k_rho" in the text is k_e, ERRATA 001). Exact.
    c = derive_constants("state-based", 3, influence)
    assert c["c_theta"] == 3
    assert _same(c["k_theta"], -3 * (1 - 4 * nu) * E / (2 * (1 + nu) * (1 - 2 * nu)))
    assert _same(c["k_e"], 15 * E / (2 * (1 + nu)))
    # ERRATA 001 identities: k_theta/3 + k_e/15 = lambda, k_theta/3 + k_e/5 = lambda + 2 mu
    assert _same(c["k_theta"] / 3 + c["k_e"] / 15, LAM)
    assert _same(c["k_theta"] / 3 + c["k_e"] / 5, LAM + 2 * MU)


@pytest.mark.parametrize("influence", INFLUENCES)
def test_state_based_plane_strain_constants_match_seed001_sec5(influence):
    # seed 001, Sec. 5 (plane strain per ERRATA 001): c_theta = 2,
    # k_theta = -(1-4nu)E/((1+nu)(1-2nu)), k_e = 4E/(1+nu). Exact.
    c = derive_constants("state-based", 2, influence, "strain")
    assert c["c_theta"] == 2
    assert _same(c["k_theta"], -(1 - 4 * nu) * E / ((1 + nu) * (1 - 2 * nu)))
    assert _same(c["k_e"], 4 * E / (1 + nu))


@pytest.mark.parametrize("influence", INFLUENCES)
def test_state_based_plane_stress_constants(influence):
    # closed form: plane stress replaces lambda by lambda* = E nu/(1-nu^2) (classical), so
    # k_theta = 2(lambda* - mu) = -(1-3nu)E/(1-nu^2), k_e = 8 mu = 4E/(1+nu). Exact.
    c = derive_constants("state-based", 2, influence, "stress")
    lam_star, mu = classical_moduli(2, "stress")
    assert c["c_theta"] == 2
    assert _same(c["k_theta"], 2 * (lam_star - mu))
    assert _same(c["k_theta"], -(1 - 3 * nu) * E / (1 - nu**2))
    assert _same(c["k_e"], 4 * E / (1 + nu))


@pytest.mark.parametrize("influence", INFLUENCES)
def test_state_based_1d_constants_match_seed000(influence):
    # seed 000, Eq. (13)-(14): c_theta = 1 - 2 nu; Eq. (19): k_theta = nu E/((1-2nu)(1+nu)),
    # k_e = E/(1+nu); Eq. (22): c_theta k_theta + k_e = E. Exact.
    c = derive_constants("state-based", 1, influence)
    assert _same(c["c_theta"], 1 - 2 * nu)
    assert _same(c["k_theta"], nu * E / ((1 - 2 * nu) * (1 + nu)))
    assert _same(c["k_e"], E / (1 + nu))
    assert _same(c["c_theta"] * c["k_theta"] + c["k_e"], E)


# ---------------------------------------------------------------- bond-based micromoduli

def test_bond_based_1d_micromoduli_match_seed004():
    # seed 004, text below Eq. (6): constant c = 2E/(A delta^2), triangular (conical)
    # c_1 = 6E/(A delta^2), with the micropotential c s^2 |xi| / 2 of its Eq. (3). Exact (A = 1).
    assert _same(derive_constants("bond-based", 1, "constant")["micromodulus"], 2 * E / delta**2)
    assert _same(derive_constants("bond-based", 1, "conical")["micromodulus"], 6 * E / delta**2)


def test_bond_based_2d_3d_micromoduli_constant_influence():
    # standard closed forms for a constant micromodulus (Silling & Askari 2005; Ha & Bobaru
    # 2010): 3D c = 18K/(pi delta^4) = 12E/(pi delta^4) at nu = 1/4; plane stress
    # c = 9E/(pi delta^3) at nu = 1/3; plane strain c = 48E/(5 pi delta^3) at nu = 1/4. Exact.
    c3 = derive_constants("bond-based", 3, "constant")
    assert c3["required_nu"] == sp.Rational(1, 4)
    K = E / (3 * (1 - 2 * nu))
    assert _same(c3["micromodulus"].subs(nu, sp.Rational(1, 4)),
                 (18 * K / (sp.pi * delta**4)).subs(nu, sp.Rational(1, 4)))
    cs = derive_constants("bond-based", 2, "constant", "stress")
    assert cs["required_nu"] == sp.Rational(1, 3)
    assert _same(cs["micromodulus"].subs(nu, sp.Rational(1, 3)), 9 * E / (sp.pi * delta**3))
    ce = derive_constants("bond-based", 2, "constant", "strain")
    assert ce["required_nu"] == sp.Rational(1, 4)
    assert _same(ce["micromodulus"].subs(nu, sp.Rational(1, 4)), 48 * E / (5 * sp.pi * delta**3))


def test_bond_based_rejects_other_poisson_ratio():
    with pytest.raises(ValueError, match=r"^nu: bond-based .* requires nu = 1/4"):
        constants(model="bond-based", dim=3, influence="gaussian", horizon=0.1, E=1.0, nu=0.3)
    c = constants(model="bond-based", dim=2, plane="stress", influence="gaussian", horizon=0.1,
                  E=1.0, nu=1 / 3)
    assert c.micromodulus is not None


def test_numeric_constants():
    c = constants(model="state-based", dim=3, influence="gaussian", horizon=0.15, E=200e9, nu=0.3)
    f = c.as_floats()
    # closed forms of seed 001, Sec. 2.1 at E = 200 GPa, nu = 0.3; rtol 1e-14 = a few ulp
    assert f["k_e"] == pytest.approx(15 * 200e9 / (2 * 1.3), rel=1e-14)
    assert f["k_theta"] == pytest.approx(-3 * (1 - 1.2) * 200e9 / (2 * 1.3 * 0.4), rel=1e-14)
    assert f["weighted_volume"] == pytest.approx(4 * 3.141592653589793 * 0.1002687981 * 0.15**5, rel=1e-9)


@pytest.mark.parametrize("kwargs, name", [
    (dict(model="bond", dim=3, influence="gaussian"), "model"),
    (dict(model="state-based", dim=4, influence="gaussian"), "dim"),
    (dict(model="state-based", dim=2, influence="gaussian"), "plane"),
    (dict(model="state-based", dim=3, influence="gaussian", plane="strain"), "plane"),
    (dict(model="state-based", dim=3, influence="cubic"), "influence"),
    (dict(model="state-based", dim=3, influence="gaussian", horizon=0.0), "horizon"),
    (dict(model="state-based", dim=3, influence="gaussian", E=-1.0), "E"),
    (dict(model="state-based", dim=3, influence="gaussian", nu=0.5), "nu"),
])
def test_bad_arguments(kwargs, name):
    full = dict(horizon=0.1, E=1.0, nu=0.25)
    full.update(kwargs)
    with pytest.raises(ValueError, match=rf"^{name}: "):
        constants(**full)
