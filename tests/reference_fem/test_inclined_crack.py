"""The FEM reference of the plate with the inclined centre crack (plate-inclined-crack,
issue 54): Williams' auxiliary fields, the interaction integral on the exact field, the
refinement study, the beta = 0 limit against the centre crack's reference, the point
symmetry, the handbook check on a large plate, the cache and the parameters."""
import math
import sys

import numpy as np
import pytest

import reference_fem as rf
from reference_fem import cache
from reference_fem.elasticity import Material
from reference_fem.mesh_elasticity import MeshElasticity

ic = sys.modules["reference_fem.inclined_crack"]
cp = sys.modules["reference_fem.crack_plate"]

#: the reference's own error budget on K_I and K_II, as a fraction of K_0 = sigma
#: sqrt(pi a): the centre crack's (a tenth of Tada's stated 0.1 %, crack_plate)
BUDGET = 1e-4


@pytest.fixture(scope="module")
def inclined(fem_cache_dir):
    return rf.inclined_crack()


# --- Williams' fields ------------------------------------------------------------------------

def textbook_stress(mode, K, r, th):
    """Anderson, Fracture Mechanics (3rd ed.), Table 2.1: the near-tip stress of mode I
    and mode II, (s11, s22, s12)."""
    f = K / np.sqrt(2 * np.pi * r)
    c, s = np.cos(th / 2), np.sin(th / 2)
    c3, s3 = np.cos(3 * th / 2), np.sin(3 * th / 2)
    if mode == 1:
        return f * c * (1 - s * s3), f * c * (1 + s * s3), f * c * s * c3
    return -f * s * (2 + c * c3), f * s * c * c3, f * c * (1 - s * s3)


def stress_of(grad, E, nu):
    lam, mu = E * nu / (1 - nu ** 2), E / (2 * (1 + nu))
    eps = 0.5 * (grad + np.swapaxes(grad, 0, 1))
    tr = eps[0, 0] + eps[1, 1]
    return lam * tr + 2 * mu * eps[0, 0], lam * tr + 2 * mu * eps[1, 1], 2 * mu * eps[0, 1]


@pytest.mark.parametrize("mode", [1, 2])
def test_first_williams_term_is_the_textbook_field(mode):
    """n = 1 with b_1 = K / sqrt(2 pi): Hooke's law of its analytic gradient gives
    Anderson's near-tip stress to round-off (an independent check of the displacement
    formulas and of the derivative)."""
    E, nu = 1e9, 0.3
    mu, kappa = E / (2 * (1 + nu)), (3 - nu) / (1 + nu)
    r = np.array([1e-3, 0.1, 0.7, 2.0])[:, None]
    th = np.linspace(-np.pi, np.pi, 13)[None, :]
    _, g = ic.williams(mode, 1, r, th, kappa, mu)
    got = stress_of(g / math.sqrt(2 * math.pi), E, nu)
    want = textbook_stress(mode, 1.0, r, th)
    for a, b in zip(got, want):
        np.testing.assert_allclose(a, b, rtol=1e-12, atol=1e-12 * np.abs(b).max())


@pytest.mark.parametrize("mode", [1, 2])
@pytest.mark.parametrize("n", [1, 2, 3, 4, 5])
def test_williams_terms_are_traction_free_and_in_equilibrium(mode, n):
    """Every term: the faces theta = +-pi are free (sigma_22 = sigma_12 = 0, to
    round-off) and div sigma = 0 (central differences of the analytic gradient, step
    1e-5 r: truncation O(step^2) ~ 1e-10 of the stress scale / r)."""
    E, nu = 1e9, 0.3
    mu, kappa = E / (2 * (1 + nu)), (3 - nu) / (1 + nu)
    for th in (np.pi, -np.pi):
        _, g = ic.williams(mode, n, 0.3, th, kappa, mu)
        s11, s22, s12 = stress_of(g, E, nu)
        scale = 2 * mu * np.abs(g).max()
        assert abs(s22) < 1e-12 * scale and abs(s12) < 1e-12 * scale
    x = np.array([[0.3, 0.2], [-0.25, 0.1], [0.05, -0.4]])
    d = 1e-5 * 0.3

    def sig(p):
        r, th = np.hypot(p[:, 0], p[:, 1]), np.arctan2(p[:, 1], p[:, 0])
        return np.array(stress_of(ic.williams(mode, n, r, th, kappa, mu)[1], E, nu))
    dx = (sig(x + [d, 0]) - sig(x - [d, 0])) / (2 * d)
    dy = (sig(x + [0, d]) - sig(x - [0, d])) / (2 * d)
    # the stress scale of the gradient (mode II, n = 2 is a rigid rotation: no stress)
    r0, t0 = np.hypot(x[:, 0], x[:, 1]), np.arctan2(x[:, 1], x[:, 0])
    scale = 2 * mu * np.abs(ic.williams(mode, n, r0, t0, kappa, mu)[1]).max() / 0.3
    assert np.abs(dx[0] + dy[2]).max() < 1e-7 * scale
    assert np.abs(dx[2] + dy[1]).max() < 1e-7 * scale


def test_williams_mode_must_be_i_or_ii():
    with pytest.raises(ValueError, match="mode must be 1 or 2"):
        ic.williams(3, 1, 1.0, 0.0, 2.0, 1.0)


# --- the extraction on the exact field -------------------------------------------------------

def test_interaction_integral_recovers_k_of_the_exact_williams_field():
    """The Q2 interpolant (no solve) of a mixed-mode Williams field about the right tip
    (K_I, K_II and the higher terms n = 2, 3 of both modes) on the default mesh: every
    domain recovers K_I and K_II within the budget (1e-4 K_0) at level 3, and the error
    falls from level 2; J = (K_I^2 + K_II^2) / E' within the same budget."""
    p = ic.InclinedCrackParams()
    K0 = ic.k0(p)
    K1, K2 = 0.8 * K0, -0.45 * K0
    mu, kappa = p.E / (2 * (1 + p.nu)), (3 - p.nu) / (1 + p.nu)
    R = np.array([p.direction, [-p.direction[1], p.direction[0]]])
    errs = []
    for level in (2, 3):
        model = MeshElasticity(ic.crack_mesh(p, p.cells * 2 ** level),
                               Material(p.E, p.nu, "plane_stress", 1.0), ic.domain(p))
        d = R @ (model.dof_coords_scalar - p.tip[:, None])
        r, th = np.hypot(d[0], d[1]), np.arctan2(d[1], d[0])
        # the crack's nodes behind the tip: theta = pi on the upper face's copies, -pi on
        # the lower's (arctan2 of a round-off +-0 would pick either)
        on = (np.abs(d[1]) < 1e-12) & (d[0] < 0)
        th[on] = np.pi
        th[lower_face_nodes(model, p)] = -np.pi
        ul = np.zeros((2, r.size))
        for mode, n, c in ((1, 1, K1 / math.sqrt(2 * math.pi)),
                           (2, 1, K2 / math.sqrt(2 * math.pi)),
                           (1, 2, 0.3 * K0), (2, 3, 0.2 * K0), (1, 3, -0.1 * K0)):
            ul += c * ic.williams(mode, n, r, th, kappa, mu)[0]
        u = np.zeros(model.basis.N)
        u[model.split[0]], u[model.split[1]] = R.T @ ul
        err = 0.0
        for frac in p.j_radii:
            k = ic.interaction_integrals(model, u, p.tip, p.direction, frac * p.tip_length)
            err = max(err, abs(k["k1"] - K1) / K0, abs(k["k2"] - K2) / K0,
                      abs(k["j"] * p.E - K1 ** 2 - K2 ** 2) / K0 ** 2)
        errs.append(err)
    print("\nWilliams field: max |K - K_exact| / K_0 by level", errs)
    assert errs[1] < errs[0]
    assert errs[1] < BUDGET


def lower_face_nodes(model, p):
    """The Q2 nodes on the crack behind the right tip that belong to the lower block
    only (the slit's second copies): those of elements whose centre lies below the
    crack line."""
    xy = model.dof_coords_scalar
    e = p.direction
    along, off = xy.T @ e, xy.T @ np.array([-e[1], e[0]])
    on = (np.abs(off) < 1e-12) & (along < p.crack - 1e-12) & (along > -p.crack + 1e-12)
    el = model.elements
    centre = xy[:, el[:, 4]]
    below = (centre.T @ np.array([-e[1], e[0]])) < 0
    nodes = np.unique(el[below].ravel())
    return nodes[on[nodes]]


# --- the converged reference -----------------------------------------------------------------

def test_refinement_converges_within_the_budget(inclined):
    """The changes of K_I and K_II fall by about 10 per level (power grading 4, as the
    centre crack) and the last is within the budget; the domains agree to a tenth of it;
    J agrees with K_I^2 + K_II^2; the field has converged on the PD default grid."""
    rows = inclined.refinement
    print("\nK_I/K_0, K_II/K_0 by level",
          [(round(r.extra["k1_over_k0"], 7), round(r.extra["k2_over_k0"], 7)) for r in rows],
          "changes % of K_0", [f"{r.change_pct:.2g}" for r in rows[1:]],
          "field changes %", [f"{r.extra['field_change_pct']:.2g}" for r in rows[1:]])
    ch = [r.change_pct for r in rows[1:]]
    assert all(x > 3 * y for x, y in zip(ch, ch[1:]))
    assert inclined.refinement_change_pct / 100 < BUDGET
    assert inclined.domain_spread_pct / 100 < BUDGET / 10
    assert abs(inclined.j_consistency_pct) / 100 < BUDGET
    fc = [r.extra["field_change_pct"] for r in rows[1:]]
    assert all(x > 3 * y for x, y in zip(fc, fc[1:]))
    # the field: the PD scene's field errors are reported in per cent (two digits); the
    # reference must change by less than a twentieth of 1 % over its last level
    # (measured 0.031 %: a point 0.03 m from a tip, and the area-mean rigid rotation)
    assert inclined.field_change_pct < 0.05
    assert inclined.k1 == inclined.quantity
    k1h, k2h = ic.handbook_k(ic.InclinedCrackParams(**inclined.params))
    assert (inclined.k1_handbook, inclined.k2_handbook) == (k1h, k2h)


def test_point_symmetry(inclined):
    """u(-x) = -u(x) on the sample grid to the solver's round-off (the mesh is point
    symmetric, so the discrete solution is too): machine epsilon times the condition of
    the graded stiffness (elements down to ~1e-7 of the plate; measured 9e-10 of the
    largest displacement), bound 1e-7."""
    p = ic.InclinedCrackParams(**inclined.params)
    pts = ic.sample_points(p)
    u, um = inclined.evaluate(pts), inclined.evaluate(-pts)
    scale = np.abs(u).max()
    assert np.abs(u + um).max() < 1e-7 * scale


def test_left_tip_equals_right_tip():
    p = ic.InclinedCrackParams(levels=3)
    m, u, _, _, _ = ic.solve_level(p, 2)
    r = ic.interaction_integrals(m, u, p.tip, p.direction, 0.2 * p.tip_length)
    left = ic.k_left(m, u, p, 0.2 * p.tip_length)
    K0 = ic.k0(p)
    assert abs(r["k1"] - left["k1"]) < 1e-9 * K0
    assert abs(r["k2"] - left["k2"]) < 1e-9 * K0


def test_zero_angle_is_the_centre_crack(fem_cache_dir):
    """beta = 0 on the centre crack's plate (W = 1, H = 3, a = 0.5): K_I equals the
    centre-crack reference's K (quarter model, J; crack_plate) within that reference's
    budget (1e-4), and K_II vanishes (|K_II| < 1e-4 K_0: by the mirror symmetry about the
    crack line the exact K_II is 0)."""
    r = rf.inclined_crack(angle=0.0, height=3.0)
    c = rf.crack_plate()
    K0 = ic.k0(ic.InclinedCrackParams(angle=0.0, height=3.0))
    print(f"\nbeta = 0: K_I {r.k1:.7g}, centre crack {c.k_j:.7g}, K_II/K_0 {r.k2 / K0:.2g}")
    assert abs(r.k1 / c.k_j - 1) < BUDGET
    assert abs(r.k2) < BUDGET * K0


@pytest.mark.slow   # the docstring's handbook check: four solves of ~120k DOFs (~80 s)
@pytest.mark.parametrize("angle", [30.0, 45.0])
def test_large_plate_matches_the_handbook(angle):
    """A crack of a = 0.5 in the plates W = H / 1.2 = 10 and 20 (level 3): on the larger
    plate K_I, K_II are within Tada's infinite-plate values up to the finite size (at
    most the change from W = 10 to 20, as it decays with W) plus the reference's budget
    (1e-4 K_0); and that sum is below 0.2 % of K_0 (the docstring's claim)."""
    ks = []
    for W in ic.LARGE_PLATES:
        p = ic.InclinedCrackParams(angle=angle, width=W, height=1.2 * W, levels=4)
        m, u, _, _, _ = ic.solve_level(p, 3)
        k = ic.interaction_integrals(m, u, p.tip, p.direction, 0.2 * p.tip_length)
        ks.append(np.array([k["k1"], k["k2"]]))
    K0 = ic.k0(p)
    hb = np.array(ic.handbook_k(p))
    size = np.abs(ks[1] - ks[0]) / K0
    dev = np.abs(ks[1] - hb) / K0
    print(f"\nbeta {angle}: W=10 {ks[0] / K0}, W=20 {ks[1] / K0}, handbook {hb / K0}, "
          f"deviation {dev}, doubling {size}")
    assert np.all(dev < size + BUDGET)
    assert np.all(size + BUDGET < 2e-3)


# --- cache and parameters ------------------------------------------------------------------

def test_cache_round_trip(tmp_path, monkeypatch):
    monkeypatch.setenv(cache.ENV_VAR, str(tmp_path))
    first = rf.inclined_crack(levels=2)
    again = rf.inclined_crack(levels=2)
    assert not first.from_cache and again.from_cache
    assert again.metrics() == first.metrics()
    pts = np.array([[0.1, 0.3], [-0.5, -0.9], [0.9, 0.0]])
    np.testing.assert_array_equal(again.evaluate(pts), first.evaluate(pts))


@pytest.mark.parametrize("over,match", [
    ({"angle": 70.0}, "angle must be in"),
    ({"angle": 45.0}, "W tan"),
    ({"crack": 0.005}, "a cos"),
    ({"levels": 1}, "levels must be"),
    ({"cells": 3}, "cells must be even"),
    ({"j_radii": (0.1, 1.5)}, "j_radii"),
    ({"sample_spacing": 0.3}, "sample_spacing"),
])
def test_bad_parameters_are_refused(over, match):
    with pytest.raises(ValueError, match=match):
        rf.inclined_crack(**over)
