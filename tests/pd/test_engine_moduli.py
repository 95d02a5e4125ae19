"""The PD engine's two models reproduce their moduli under homogeneous strain, in 1D, 2D, 3D.

Moduli are read off the virial stress of the centre node of a box 4 horizons wide, where
every node the centre's bonds reach has a complete neighbourhood (uncorrected closure).

State-based (energy of a homogeneous strain, seed 001 Eqs. 8-11): with the discrete
moments m = sum w, A = sum w n_1^4, B = sum w n_1^2 n_2^2 of w = omega |xi|^2 beta V, the
discrete material has C = (k_theta c_theta / d^2) I (x) I + (k_e / m) M, i.e.
C11 = kc + k_e A / m, C12 = kc + k_e B / m, C44 = k_e B / m (kc = k_theta c_theta / d^2).
The continuum has A = 3 m / (d (d + 2)) and B = m / (d (d + 2)); the lattice differs by
its fourth-moment anisotropy eta = A / (3 B) - 1 ("the lattice error at that m"), which
moment-corrected volumes remove. Bond-based: C = (c / 2) M_b with w_b = omega |xi| beta V.
"""
import numpy as np
import pytest

from manufactured import constants as sym
from manufactured import influence as sym_influence
from pdverify.pd import (INFLUENCES, BondBasedModel, BoxGrid, StateBasedConstants,
                         StateBasedModel, bond_micromodulus, build_stencil, get_influence)
from pdverify.pd.bonds import fourth_moment_anisotropy
from pdverify.pd.influence import bond_based_nu
from pdverify.pd.stress import virial_stress

E, NU = 200e9, 0.3
H = 0.01
#: Sums of ~1e2-1e3 bond terms (and, state-based, a dilatation coupling) per stress entry:
#: 1e-10 relative is ~1e6 eps of summation round-off, far below any lattice effect (>1e-5).
RTOL_SUM = 1e-10
KINDS = {"1d": (1, None), "plane-strain": (2, "strain"), "plane-stress": (2, "stress"),
         "3d": (3, None)}


def _box(dim, m_ratio):
    n = int(4 * np.ceil(m_ratio)) + 1  # centre node: every neighbour's neighbourhood complete
    grid = BoxGrid((n * H,) * dim, (0.0,) * dim, H)
    centre = grid.ext_id([n // 2] * dim)
    return grid, centre


def _strains(dim):
    uni = np.zeros((dim, dim))
    uni[0, 0] = 1.0
    if dim == 1:
        return [uni]
    shear = np.zeros((dim, dim))
    shear[0, 1] = shear[1, 0] = 0.5          # engineering shear strain 1 in 1-2
    return [uni, shear]


def _measured(model, centre):
    """(C11[, C12, C44]) of the discrete material from the centre node's virial stress."""
    g, d = model.grid, model.dim
    out = []
    for eps in _strains(d):
        u = (g.x[g.interior_ids] @ eps.T).T.ravel()   # component-major unknowns
        sigma = virial_stress(model, model.bond_forces(u), centre)[0]
        out.append(sigma)
    if d == 1:
        return np.array([out[0][0, 0]])
    return np.array([out[0][0, 0], out[0][1, 1], out[1][0, 1]])


def _moments(stencil, weight):
    n = stencil.offsets / np.linalg.norm(stencil.offsets, axis=1)[:, None]
    w = weight * stencil.beta
    if stencil.dim == 1:
        return w.sum(), w.sum(), 0.0
    return w.sum(), np.sum(w * n[:, 0] ** 4), np.sum(w * n[:, 0] ** 2 * n[:, 1] ** 2)


def _state_model(kind, influence, m_ratio, quadrature="partial-volume"):
    dim, _ = KINDS[kind]
    inf = get_influence(influence)
    delta = m_ratio * H

    def state_weight(offsets):
        r = np.linalg.norm(offsets, axis=1) * H
        return inf.omega(r, delta) * r ** 2

    stencil = build_stencil(dim, m_ratio, quadrature=quadrature, moment_weight=state_weight)
    grid, centre = _box(dim, m_ratio)
    c = StateBasedConstants(kind, E, NU)
    return StateBasedModel(grid, stencil, c, inf), centre, state_weight(stencil.offsets)


def _continuum_state(kind):
    c = StateBasedConstants(kind, E, NU)
    lam, mu = c.moduli()
    return np.array([E]) if kind == "1d" else np.array([lam + 2 * mu, lam, mu])


@pytest.mark.parametrize("influence", sorted(INFLUENCES))
@pytest.mark.parametrize("kind", list(KINDS))
def test_state_based_moduli_are_the_lattice_moduli(kind, influence):
    model, centre, w = _state_model(kind, influence, 3.0)
    c, d = model.constants, model.dim
    m, A, B = _moments(model.stencil, w * model.grid.volume)
    kc = c.k_theta * c.c_theta / d ** 2
    lattice = np.array([kc + c.k_e * A / m]) if d == 1 else \
        np.array([kc + c.k_e * A / m, kc + c.k_e * B / m, c.k_e * B / m])
    got = _measured(model, centre)
    np.testing.assert_allclose(got, lattice, rtol=RTOL_SUM)
    want = _continuum_state(kind)
    if d == 1:  # a 1D stencil has no anisotropy: the bar has E exactly (seed 000, Eq. 22)
        np.testing.assert_allclose(got, want, rtol=RTOL_SUM)
        return
    eta = fourth_moment_anisotropy(model.stencil.offsets, w * model.stencil.beta)
    print(f"{kind} {influence}: eta = {eta:.3e}, moduli error {got / want - 1}")
    # the lattice error exists at m = 3, is O(eta) and vanishes with it:
    # B / B_cont - 1 = -3 eta / (d + 2 + 3 eta), A / A_cont - 1 = eta (d - 1) / (d + 2 + 3 eta)
    assert abs(eta) > 1e-5
    k_dev = c.k_e / (d * (d + 2))
    dev = np.array([3 * k_dev * eta * (d - 1), -3 * k_dev * 3 * eta, -3 * k_dev * 3 * eta]) \
        / (d + 2 + 3 * eta) * np.array([1, 1 / 3, 1 / 3])
    # got - want is a difference of O(1e11) moduli giving O(1e9): RTOL_SUM of the moduli
    # becomes ~1e-8 of the difference, hence rtol 1e-8 here
    np.testing.assert_allclose(got - want, dev, rtol=1e-8, atol=RTOL_SUM * want.max())


@pytest.mark.parametrize("influence", sorted(INFLUENCES))
@pytest.mark.parametrize("kind", ["plane-strain", "plane-stress", "3d"])
def test_state_based_moment_corrected_moduli_are_the_continuum_moduli(kind, influence):
    model, centre, _ = _state_model(kind, influence, 3.0, "moment-corrected")
    np.testing.assert_allclose(_measured(model, centre), _continuum_state(kind), rtol=RTOL_SUM)


def _bond_model(kind, influence, m_ratio, quadrature, calibration):
    dim, plane = KINDS[kind]
    inf = get_influence(influence)
    delta = m_ratio * H

    def bond_weight(offsets):
        r = np.linalg.norm(offsets, axis=1) * H
        return inf.omega(r, delta) * r

    stencil = build_stencil(dim, m_ratio, quadrature=quadrature, moment_weight=bond_weight)
    c = bond_micromodulus(influence, dim, E, delta, plane=plane, calibration=calibration,
                          stencil=stencil, spacing=H)
    grid, centre = _box(dim, m_ratio)
    return BondBasedModel(grid, stencil, c, inf), centre, bond_weight(stencil.offsets)


def _bond_continuum(kind):
    dim, plane = KINDS[kind]
    if dim == 1:
        return np.array([E])
    mu = E / (2 * (1 + bond_based_nu(dim, plane)))
    return np.array([3 * mu, mu, mu])   # lambda = mu (Cauchy relation)


@pytest.mark.parametrize("influence", sorted(INFLUENCES))
@pytest.mark.parametrize("kind", list(KINDS))
def test_bond_based_moduli_are_the_lattice_moduli(kind, influence):
    model, centre, w = _bond_model(kind, influence, 3.0, "partial-volume", "continuum")
    m, A, B = _moments(model.stencil, w * model.grid.volume)
    lattice = np.array([model.c * A / 2]) if model.dim == 1 else \
        np.array([model.c * A / 2, model.c * B / 2, model.c * B / 2])
    got = _measured(model, centre)
    np.testing.assert_allclose(got, lattice, rtol=RTOL_SUM)
    rel = got / _bond_continuum(kind) - 1
    print(f"{kind} {influence}: continuum-calibrated bond-based moduli error {rel}")
    # a ceiling, not the claim (that is the lattice equality above): measured <= 17 % at
    # m = 3 (1D conical; the same effect as seed 004's f_1(m), Tables 1-2)
    assert np.abs(rel).max() < 0.25


@pytest.mark.parametrize("influence", sorted(INFLUENCES))
@pytest.mark.parametrize("kind", list(KINDS))
def test_bond_based_moduli_with_discrete_calibration(kind, influence):
    # discrete calibration (seed 004, Eqs. 14/22, generalised) fixes the magnitude and the
    # moment correction the anisotropy: the bond-based moduli exactly, nu = 1/4 or 1/3
    quadrature = "partial-volume" if kind == "1d" else "moment-corrected"
    model, centre, _ = _bond_model(kind, influence, 3.0, quadrature, "discrete")
    got = _measured(model, centre)
    np.testing.assert_allclose(got, _bond_continuum(kind), rtol=RTOL_SUM)
    if kind != "1d":
        C11, C12, _ = got
        nu = C12 / C11 if kind == "plane-stress" else C12 / (C11 + C12)
        assert nu == pytest.approx(bond_based_nu(*KINDS[kind]), rel=RTOL_SUM)


# ------------------------------------------------------------------ registry vs sympy
@pytest.mark.parametrize("influence", sorted(INFLUENCES))
@pytest.mark.parametrize("dim", [1, 2, 3])
def test_weighted_volume_closed_forms_match_the_symbolic_engine(influence, dim):
    # manufactured.influence integrates the moments exactly in sympy; ours are closed forms
    want = float(sym_influence.weighted_volume(influence, dim, 0.7))
    assert get_influence(influence).weighted_volume(dim, 0.7) == pytest.approx(want, rel=1e-14)


@pytest.mark.parametrize("kind", list(KINDS))
def test_state_based_constants_match_energy_equivalence(kind):
    dim, plane = KINDS[kind]
    ref = sym.constants(model="state-based", dim=dim, influence="gaussian", horizon=0.1,
                        E=E, nu=NU, plane=plane).as_floats()
    c = StateBasedConstants(kind, E, NU)
    for name in ("c_theta", "k_theta", "k_e"):
        assert getattr(c, name) == pytest.approx(ref[name], rel=1e-14), name


@pytest.mark.parametrize("influence", sorted(INFLUENCES))
@pytest.mark.parametrize("kind", list(KINDS))
def test_bond_micromodulus_matches_energy_equivalence(kind, influence):
    dim, plane = KINDS[kind]
    nu = bond_based_nu(dim, plane) if dim > 1 else NU
    ref = sym.constants(model="bond-based", dim=dim, influence=influence, horizon=0.1,
                        E=E, nu=nu, plane=plane).as_floats()["micromodulus"]
    assert bond_micromodulus(influence, dim, E, 0.1, plane=plane) == pytest.approx(ref, rel=1e-13)


def test_unknown_influence_lists_the_registered_ones():
    with pytest.raises(Exception, match="allowed: conical, constant, gaussian, hyperbolic"):
        get_influence("cubic")
