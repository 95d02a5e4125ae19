"""The four FEM references: published numbers, closed forms and convergence."""
import numpy as np
import pytest

import reference_fem as rf
from reference_fem.clamped_sheet import observed_rate
from reference_fem.field import midpoint_refined


@pytest.fixture(scope="module")
def cache_env(fem_cache_dir):
    """The session's cache folder (conftest; never the user's cache): a reference another
    test of the session computed with the same parameters is read, not computed again
    (issue 32); the cache's round trip is tests/reference_fem/test_fem_cache.py's."""
    assert rf.cache.cache_dir() == fem_cache_dir


@pytest.fixture(scope="module")
def plate(cache_env):
    return rf.clamped_plate()


@pytest.fixture(scope="module")
def tension(cache_env):
    return rf.tension_sheet()


@pytest.fixture(scope="module")
def clamped(cache_env):
    return rf.clamped_sheet()


@pytest.fixture(scope="module")
def indent(cache_env):
    return rf.indentation()


# --- plate2d-clamped (seed 000 Sec. 6.2) -------------------------------------------------

def test_plate_converged(plate):
    # issue 5: change of max displacement over the last refinement below 0.1 %
    assert plate.refinement_change_pct < 0.1
    # Q2 point values converge like h^3 for this (nearly smooth) solution; margin 0.5
    q = np.array([r.quantity for r in plate.refinement])
    d = np.abs(np.diff(q))
    rates = np.log2(d[:-1] / d[1:])
    assert np.all(rates > 2.5), rates
    # the Eq. (70) measure between the last two levels, on the 0.1 m PD grid: far below
    # the 0.1 % budget of the compared quantity
    assert plate.refinement[-1].extra["field_change_pct"] < 0.1


def test_plate_symmetry_and_maximum(plate):
    p = plate.params
    L, W = p["length"], p["width"]
    rng = np.random.default_rng(7)
    pts = rng.uniform([0, 0], [L, W], size=(300, 2))
    u = plate.evaluate(pts)
    # body load along x on a doubly symmetric domain: u_x even, u_y odd about both axes
    mirrored = plate.evaluate(np.stack([L - pts[:, 0], pts[:, 1]], axis=1))
    scale = plate.max_displacement
    np.testing.assert_allclose(mirrored[:, 0], u[:, 0], rtol=0, atol=1e-10 * scale)
    np.testing.assert_allclose(mirrored[:, 1], -u[:, 1], rtol=0, atol=1e-10 * scale)
    centre = plate.evaluate(np.array([[L / 2, W / 2]]))[0]
    np.testing.assert_allclose(centre[0], plate.max_displacement, rtol=1e-12)
    # clamped edges (Dirichlet imposed exactly at the nodes, hence along every edge)
    edge = np.array([[0.0, 0.7], [L, 1.3], [1.1, 0.0], [2.9, W]])
    np.testing.assert_allclose(plate.evaluate(edge), 0.0, atol=1e-14 * scale)


# --- sheet2d-tension (seed 003 Sec. 4.1.1) -----------------------------------------------

def test_tension_sheet_matches_closed_form(tension):
    # issue 5: closed form to 1e-10 relative (the linear field lies in the Q2 space)
    assert tension.max_error_pct < 1e-10 * 100
    for row in tension.refinement:
        assert max(row.extra["max_error_ux_pct"], row.extra["max_error_uy_pct"]) < 1e-8
    # the minimal supports carry no load (closed form satisfies them): reactions are
    # round-off against the end force 1 MPa * 50 mm * 1 m = 5e4 N
    assert tension.max_reaction_n < 1e-10 * 5e4
    assert tension.refinement_change_pct < 1e-8


def test_tension_sheet_plane_strain_closed_form(cache_env):
    res = rf.tension_sheet(mode="plane_strain", nu=0.3, levels=2, spacing=0.025)
    pts = np.array([[0.025, 0.05], [-0.01, -0.03]])
    np.testing.assert_allclose(res.evaluate(pts), res.closed_form(pts), rtol=1e-10)


# --- sheet2d-clamped (seed 003 Sec. 4.1.2) -----------------------------------------------

def test_clamped_sheet_reproduces_table_2(clamped):
    # seed 003 Table 2: FEM reference 10.32 MPa; issue 5 tolerance +-0.02 MPa
    assert abs(clamped.tensile_stress_mpa - 10.32) <= 0.02
    # bounds: free lateral contraction gives E eps = 10 MPa, fully suppressed
    # contraction E eps / (1 - nu^2) = 11.25 MPa (plane stress); clamping lies between
    assert 10.0 < clamped.tensile_stress_mpa < 11.25
    # equilibrium: top and bottom reactions agree to round-off
    np.testing.assert_allclose(clamped.bottom_stress_mpa, clamped.tensile_stress_mpa, rtol=1e-9)


def test_clamped_sheet_graded_convergence(clamped):
    # graded toward the corners, the energy-like stress converges at the optimal Q2 rate
    # h^4 (power grading 3 > k/lambda); margin 1 on the observed last-two-levels rate
    assert clamped.observed_rate > 3.0
    # the uniform meshes are limited by the corner singularity to ~h^(2 lambda), lambda < 1
    assert observed_rate(clamped.uniform_refinement) < 2.0
    # the converged level is far tighter than the +-0.02 MPa comparison tolerance
    assert clamped.refinement_change_pct < 0.01
    # and the uniform study approaches the same limit from above
    q_uniform = clamped.uniform_refinement[-1].quantity
    assert 0 < q_uniform - clamped.tensile_stress_mpa < 0.001


# --- block2d-indentation (seed 003 Sec. 4.2) ---------------------------------------------

@pytest.mark.slow  # slow tier (issue 32): the finite-strain FEM reference, 14 s (loaded machine)
def test_indentation_converged(indent):
    # issue 5: change of the full-depth force over the last refinement below 1 %
    assert indent.refinement_change_pct < 1.0
    # the whole curve stays within the same 1 % budget, also step by step relative to
    # each step's own force, and against doubling the contact increments
    assert indent.curve_change_pct < 1.0
    assert indent.curve_rel_change_pct < 1.0
    assert indent.step_change_pct < 1.0
    assert len(indent.depths) >= 21 and indent.depths[-1] == pytest.approx(0.002, rel=1e-12)


@pytest.mark.slow  # slow tier (issue 32): the finite-strain FEM reference, 14 s (loaded machine)
def test_indentation_curve_monotone_and_width_grows(indent):
    assert indent.force_monotone and np.all(np.diff(indent.forces) > 0)
    w = indent.contact_widths
    assert np.all(np.diff(w) >= 0)          # no separation: stuck nodes never release
    first = w[np.flatnonzero(w > 0)[0]]
    assert w[-1] > 1.5 * first              # and contact spreads as the indenter sinks
    assert np.all(np.diff(indent.contact_nodes) >= 0)
    assert indent.max_force == indent.forces[-1] == indent.quantity
    assert indent.metrics()["force_monotone"] == 1.0


@pytest.mark.slow  # slow tier (issue 32): the finite-strain FEM reference, 14 s (loaded machine)
def test_indentation_contact_kinematics_and_equilibrium(indent):
    p = indent.params
    R, d = p["radius"], p["depth"]
    # stuck nodes lie on the indenter surface at full depth (projection + rigid motion)
    np.testing.assert_allclose(np.hypot(indent.contact_x, indent.contact_y - (R - d)), R,
                               rtol=1e-12)
    assert indent.max_constraint_error < 1e-10
    # the bottom edge carries the indentation force (global equilibrium)
    np.testing.assert_allclose(indent.bottom_reaction, indent.max_force, rtol=1e-8)
    # the centre node, caught first, has moved rigidly with the indenter to (0, -d)
    centre = indent.evaluate(np.array([[0.0, 0.0]]))[0]
    np.testing.assert_allclose(centre, [0.0, -d], atol=1e-9 * d)
    assert indent.contact_x.size == indent.contact_nodes[-1]


@pytest.mark.slow  # slow tier (issue 32): the finite-strain FEM reference, 14 s (loaded machine)
def test_indentation_no_free_node_penetrates(indent):
    p = indent.params
    R, d = p["radius"], p["depth"]
    x_top = midpoint_refined(indent.field.coords[0])
    pts = np.stack([x_top, np.zeros_like(x_top)], axis=1)
    pos = pts + indent.evaluate(pts)
    gap = np.hypot(pos[:, 0], pos[:, 1] - (R - d)) - R
    # catch threshold of the contact law (module docstring): penetration > 1e-9 R
    assert gap.min() >= -1e-9 * R
    assert np.sum(np.abs(gap) < 1e-12 * R) >= indent.contact_nodes[-1]


@pytest.mark.parametrize("symmetry", ["full", "half"])
def test_indentation_flexibility_solver_matches_direct_condensation(cache_env, symmetry):
    """Cross-check of the G = K^-1 contact solver: the final stuck set imposed as plain
    Dirichlet data (skfem.condense; in the half model also u_x = 0 on the axis)
    reproduces the force (round-off tolerance)."""
    from reference_fem.indentation import IndentationParams, solve_level

    p = IndentationParams(n_steps=20, substeps=2, symmetry=symmetry)
    s = solve_level(p, 0)
    model = s["model"]
    bottom = model.dofs(lambda x, y: y < -p.height + 1e-12)
    if symmetry == "half":
        assert model.coords[0][0] == 0.0
        bottom = np.concatenate([bottom, model.dofs(lambda x, y: x == 0.0, [0])])
    fixed = np.concatenate([bottom, s["stuck_dofs"][0], s["stuck_dofs"][1]])
    vals = np.concatenate([np.zeros(bottom.size), s["stuck_targets"][:, 0],
                           s["stuck_targets"][:, 1]])
    u = model.solve(np.zeros(model.basis.N), fixed, vals)
    force = -model.reactions(u)[s["stuck_dofs"][1]].sum() * (2 if symmetry == "half" else 1)
    np.testing.assert_allclose(force, s["forces"][-1], rtol=1e-9)
    # the returned field is the full block's; its right half is the solved model's
    full = s["field"].values
    np.testing.assert_allclose(model.field(u).values, full[full.shape[0] - model.grid[0].size:],
                               rtol=0, atol=1e-9 * p.depth)


@pytest.mark.slow  # slow tier (issue 32): the finite-strain FEM reference, 14 s (loaded machine)
def test_indentation_fields_at_full_depth(indent):
    p = indent.params
    W, H = p["width"], p["height"]
    xs = np.linspace(-W / 2, W / 2, 41)
    ys = np.linspace(-H, 0, 41)
    pts = np.stack(np.meshgrid(xs, ys, indexing="ij"), axis=-1).reshape(-1, 2)
    u = indent.evaluate(pts)
    w = indent.strain_energy_density(pts)
    assert np.all(np.isfinite(u)) and np.all(w >= 0)
    # fixed bottom, symmetric about x = 0 (u_x odd, u_y even)
    np.testing.assert_allclose(u[pts[:, 1] == -H], 0.0, atol=1e-15)
    mirrored = indent.evaluate(pts * [-1, 1])
    np.testing.assert_allclose(mirrored[:, 0], -u[:, 0], atol=1e-9 * p["depth"])
    np.testing.assert_allclose(mirrored[:, 1], u[:, 1], atol=1e-9 * p["depth"])
    # the energy concentrates under the indenter
    assert np.argmax(w) in np.flatnonzero(pts[:, 1] > -0.005)


# --- results common to all ---------------------------------------------------------------

# the finite-strain indentation reference in the slow tier with its other tests (issue 32)
@pytest.mark.parametrize("name", ["plate", "tension", "clamped",
                                  pytest.param("indent", marks=pytest.mark.slow)])
def test_result_records(name, request):
    res = request.getfixturevalue(name)
    assert res.refinement_change_pct == res.refinement[-1].change_pct
    assert [r.level for r in res.refinement] == list(range(len(res.refinement)))
    dofs = [r.dofs for r in res.refinement]
    assert dofs == sorted(dofs) and len(set(dofs)) == len(dofs)
    assert res.setup_s > 0 and res.solve_s > 0 and res.study_s >= res.setup_s + res.solve_s
    metrics = res.metrics()
    assert metrics["refinement_change_pct"] == res.refinement_change_pct
    assert all(isinstance(v, float) for v in metrics.values())
    assert set(res.timings()) == {"setup_s", "solve_s", "total_s"}
    grid = res.sample_grid((5, 7))
    assert grid["ux"].shape == grid["strain_energy_density"].shape == (5, 7)
    bounds = res.field.bounds
    outside = np.array([[bounds[0, 1] + 1.0, bounds[1, 0]]])
    with pytest.raises(ValueError, match="1 of 1 points lie outside the domain"):
        res.evaluate(outside)
    table = res.refinement_table()
    assert table[-1]["quantity"] == res.quantity


# --- finite-strain indentation reference (issue 14) -----------------------------------------

def _svk_model(level=0, law="saint-venant-kirchhoff"):
    from reference_fem.elasticity import Material, TensorElasticity
    from reference_fem.hyperelastic import LAWS
    from reference_fem.indentation import IndentationParams, mesh_coordinates

    model = TensorElasticity(mesh_coordinates(IndentationParams(), level),
                             Material(1e9, 1 / 3, "plane_stress", 1.0))
    return model, LAWS[law](model)


#: both finite-strain laws (St Venant-Kirchhoff; neo-Hookean with the same Lame
#: parameters, issue 33): the same linear elasticity at rest, consistent tangents
LAW_NAMES = ("saint-venant-kirchhoff", "neo-hookean")


@pytest.mark.parametrize("law", LAW_NAMES)
def test_svk_tangent_at_rest_is_the_linear_stiffness(law):
    model, svk = _svk_model(law=law)
    K0 = svk.tangent(np.zeros(model.basis.N))
    K = model.stiffness
    # the same integrals summed in another order: round-off of the largest entry
    assert abs(K0 - K).max() <= 100 * np.finfo(float).eps * abs(K).max()


@pytest.mark.parametrize("law", LAW_NAMES)
def test_svk_tangent_matches_finite_differences_and_rotations_are_free(law):
    model, svk = _svk_model(law=law)
    rng = np.random.default_rng(0)
    u = rng.normal(size=model.basis.N) * 1e-5
    d = rng.normal(size=model.basis.N) * 1e-5
    Td = svk.tangent(u) @ d
    fd = (svk.internal_force(u + 1e-4 * d) - svk.internal_force(u - 1e-4 * d)) / 2e-4
    # central differences: O(eps^2) truncation (measured 4e-11 SVK, 7e-11 neo-Hookean,
    # at eps = 1e-4)
    assert np.abs(fd - Td).max() <= 1e-6 * np.abs(Td).max()
    # a finite rigid rotation stores no strain: the internal forces vanish (round-off)
    x, y = model.dof_coords
    th = 0.5
    comp = model.dof_component
    xr = np.where(comp == 0, np.cos(th) * x - np.sin(th) * y - x,
                  np.sin(th) * x + np.cos(th) * y - y)
    scale = np.abs(svk.internal_force(u)).max()
    # round-off: F^T F - I of a rotation is exact to ~eps, against strains of ~1e-2 in u
    # (1e-5 m over 1 mm elements): ~1e-14 relative, with room for the quadrature sums
    assert np.abs(svk.internal_force(xr)).max() <= 1e-8 * scale


def test_finite_strain_indentation_agrees_with_small_strain_at_small_depth(cache_env):
    """At 0.1-0.2 mm (strains of about 1 %) the finite-strain force is within 3 % of the
    small-strain one (second-order terms: measured -1.3 % and -2.2 % on level 0); the mesh
    never folds; the curve grows."""
    from reference_fem.indentation import IndentationParams, solve_level, solve_level_finite

    kw = dict(n_steps=2, depth=0.0002, substeps=4)
    fin = solve_level_finite(IndentationParams(kinematics="finite", **kw), 0)
    small = solve_level(IndentationParams(**kw), 0)
    rel = fin["forces"][1:] / small["forces"][1:] - 1
    assert np.all(np.abs(rel) < 0.03) and np.all(rel < 0)
    assert fin["min_jacobian"] > 0.5 and np.all(np.diff(fin["forces"]) > 0)
    # global equilibrium holds to the free dofs' residual (Newton stops at 1e-10 of the
    # force scale); 1e-7 leaves room for the sums over the ~3,000 dofs
    np.testing.assert_allclose(fin["bottom_reaction"], fin["forces"][-1], rtol=1e-7)


# --- the neo-Hookean law beside St Venant-Kirchhoff (issue 33) ---------------------------

def test_a_folded_state_has_no_neo_hookean_stress():
    """J <= 0: no energy, the stress is NaN (Newton's line search rejects such a step)."""
    model, nh = _svk_model(law="neo-hookean")
    x, y = model.dof_coords
    flip = np.where(model.dof_component == 0, -2.0 * x, 0.0)     # x -> -x: J = -1
    assert np.isnan(nh.internal_force(flip)).any()


def test_the_laws_at_full_depth_against_small_strain(cache_env):
    """At 2 mm the issue's independent code measured St Venant-Kirchhoff at 0.894 x the
    small-strain force and neo-Hookean (same constants) at 1.012 x: most of the gap
    between the references is the law (SVK softens in compression, neo-Hookean
    stiffens), not the geometry. Level 0 here: the ratios change by 2e-4 (NH) and 1.7e-3
    (SVK) from level 0 to 1 (measured), and the independent values carry 3 digits
    (+-5e-4): tolerance 2.5e-3."""
    from reference_fem.indentation import IndentationParams, solve_level, solve_level_finite

    small = solve_level(IndentationParams(), 0)["forces"][-1]
    svk = solve_level_finite(IndentationParams(kinematics="finite"), 0)["forces"][-1]
    nh = solve_level_finite(IndentationParams(kinematics="finite", law="neo-hookean"), 0)
    assert abs(svk / small - 0.894) < 2.5e-3
    assert abs(nh["forces"][-1] / small - 1.012) < 2.5e-3
    assert nh["min_jacobian"] > 0 and np.all(np.diff(nh["forces"]) > 0)


def test_a_law_needs_finite_kinematics():
    from reference_fem.indentation import IndentationParams
    with pytest.raises(ValueError, match="needs kinematics=finite"):
        IndentationParams(law="neo-hookean")
    with pytest.raises(ValueError, match="law must be one of"):
        IndentationParams(kinematics="finite", law="mooney")
