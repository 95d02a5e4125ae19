"""PALS (seed 001 §5.1; Mitchell, Silling and Littlewood 2015): the matching deformations
are reproduced at every node, surface nodes included, and the force state is the
derivative of its energy."""
import numpy as np
import pytest

from pdverify.pd.work import work_density
from pdverify.corrections.pals import matching_basis, pals_closure
from pdverify.errors import NumericalError
from pdverify.pd import (BoxGrid, StateBasedConstants, StateBasedModel, get_influence,
                         state_based_stencil)
from pdverify.scenes import get_scene
from pdverify.scenes.stiffness import strain_states

EPS = 1e-12  # machine-epsilon claims, relative (sums of a few hundred O(1) terms)

CASES = [("3d", (6.0, 5.0, 4.0), 2.0, "partial-volume"),
         ("plane-strain", (10.0, 8.0), 3.0, "partial-volume"),
         ("plane-stress", (9.0, 7.0), 3.0, "moment-corrected")]


def pals_model(kind, cells, m, quadrature="partial-volume", influence="gaussian"):
    inf = get_influence(influence)
    d = len(cells)
    g = BoxGrid(cells, (0.0,) * d, 1.0, 0)
    st = state_based_stencil(d, m, 1.0, inf, quadrature)
    return StateBasedModel(g, st, StateBasedConstants(kind, 1.0, 0.3), inf, pals_closure())


def continuum_energy(model, eps):
    lam, mu = model.constants.moduli()
    return 0.5 * lam * np.trace(eps) ** 2 + mu * np.sum(eps * eps)


@pytest.mark.parametrize("kind,cells,m,quad", CASES)
def test_matching_deformations_at_every_node(kind, cells, m, quad):
    """theta_i = tr(eps) for any homogeneous strain (its constraints span them), and the
    node energy is the continuum W under each matching deformation, corner nodes
    included; machine epsilon (the constraints are solved exactly)."""
    model = pals_model(kind, cells, m, quad)
    pals = model.closure.constitutive
    rng = np.random.default_rng(0)
    d = model.dim
    A = rng.normal(size=(d, d))
    W, theta = pals.node_energy(model, 0.5 * (A + A.T))
    assert np.allclose(theta, np.trace(A), rtol=0, atol=EPS * abs(np.trace(A)) + EPS)
    for _, eps in strain_states(d):
        W, theta = pals.node_energy(model, eps)
        assert np.allclose(W, continuum_energy(model, eps), rtol=EPS, atol=0)
        # the bulk reference and the engine's work attribution say the same
        assert model.bulk_work_density(eps) == pytest.approx(continuum_energy(model, eps),
                                                             rel=EPS)
        assert np.allclose(work_density(model, eps), W, rtol=EPS, atol=0)


def test_force_state_is_the_energy_derivative():
    """K is symmetric (the force state derives from a quadratic energy) and
    1/2 u.K u is the summed node energy sum V_i W_i under a homogeneous strain."""
    model = pals_model("3d", (6.0, 5.0, 4.0), 2.0)
    K = model.stiffness()
    assert abs(K - K.T).max() <= EPS * abs(K).max()
    eps = np.array([[1.0, 0.3, 0.0], [0.3, -0.2, 0.1], [0.0, 0.1, 0.5]])
    x = model.grid.x[model.grid.interior_ids]
    u = (x @ eps.T).T.ravel()
    W, _ = model.closure.constitutive.node_energy(model, eps)
    # P = minus the internal force: 1/2 u.K u is the energy
    # round-off of u.Ku, a sum of ~1e5 products of mixed sign (two orders above EPS)
    assert 0.5 * u @ (K @ u) == pytest.approx(np.sum(W * model.node_volume), rel=1e-11)


def test_bulk_dilatation_influence_is_lps():
    """Away from the surface omega_i is LPS's d omega / m_inf (its constraints hold on a
    complete lattice, so the multipliers vanish) to round-off."""
    model = pals_model("plane-strain", (14.0, 14.0), 3.0)
    om_a, _, _, _ = model.closure.constitutive.influences(model)
    g = model.grid
    far = g.distance_to_surface(g.x)[model.bond_a] > model.horizon
    lps = 2 * model.influence.omega(model.bond_x, model.horizon) / model.m_inf
    # the bulk multipliers are the round-off of the constraint residual (1 minus a sum
    # of O(1) terms) through systems scaled to unit diagonal (condition <= 7.2 here,
    # measured): a hundred times EPS leaves a wide margin
    assert np.allclose(om_a[far], lps[far], rtol=1e-10, atol=0)


def test_two_dimensional_deviators():
    """In 2D the y stretch's deviatoric extension is minus the x stretch's, so only one is
    a constraint (the pair would make the system singular)."""
    xi = np.array([[1.0, 2.0], [0.5, -1.0]])
    E, D, tr, rhs_dev = matching_basis(xi)
    assert E.shape == (2, 3) and D.shape == (2, 2)
    r = np.linalg.norm(xi, axis=1)
    assert np.allclose(D[:, 0], (xi[:, 0] ** 2 - xi[:, 1] ** 2) / (2 * r), rtol=EPS)
    assert rhs_dev.tolist() == [0.5, 2.0]


def test_singular_node_is_a_numerical_error():
    """A strip one cell wide: every bond is along x, the y matching deformations cannot be
    met; the failure names the node."""
    with pytest.raises(NumericalError, match=r"dilatation Lagrange system of the node at"):
        pals_model("plane-strain", (10.0, 1.0), 3.0)


@pytest.mark.parametrize("scene,over", [("stiffness2d-plate", {"spacing": 0.05}),
                                        ("stiffness3d-box", {"spacing": 0.1})])
def test_pals_stiffness_scene_is_exact(scene, over):
    """The stiffness scenes' strain states are PALS's matching deformations: no error at
    any node (machine epsilon, in percent)."""
    r = get_scene(scene).run("pals", over)
    assert r.status == "ok", r.message
    # EPS in percent (1e-10), with a factor 10 for the bulk reference's own round-off
    assert r.metrics["surface_energy_error_pct"] < 1e-9
    assert r.metrics["interior_energy_error_pct"] < 1e-9


def test_augmented_system_carries_both_nodal_scalars():
    """PALS has two nodal scalars (theta and the sigma-weighted sum), so its augmented
    system (solver=nested-dissection) has 2 n_interior extra rows: it must give the
    direct solve's answer (it once indexed past the right-hand side)."""
    scene = get_scene("plate2d-plane-strain")
    over = {"spacing": 0.05}
    direct = scene.run("pals", {**over, "solver": "direct"})
    nd = scene.run("pals", {**over, "solver": "nested-dissection"})
    assert direct.status == nd.status == "ok", nd.message
    # two sparse LUs of the same system: round-off of a 1e3-conditioned solve
    assert nd.metrics["rel_l2_error"] == pytest.approx(direct.metrics["rel_l2_error"], rel=1e-9)
