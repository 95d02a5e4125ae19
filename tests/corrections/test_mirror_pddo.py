"""The mirror node method and the PDDO boundary layer (seed 001 §5.2-5.3): affine fields
reproduced where each claims it, and the §5 comparison on the plane-strain plate."""
import numpy as np
import pytest

from pdverify.corrections.mirror_nodes import MirrorNodes, peridynamic_gradient
from pdverify.corrections.pddo import derivative_operators, monomial_orders, pddo_system
from pdverify.pd import (BoxGrid, StateBasedConstants, StateBasedModel, get_influence,
                         state_based_stencil)
from pdverify.pd.faces import face_names
from pdverify.report.figures.surface_nodes import mnm_pattern, where_max
from pdverify.scenes import get_scene
from pdverify.solvers.front import solve_with_dirichlet

H, L = 0.1, (1.0, 0.8)
C = StateBasedConstants("plane-strain", 200e9, 0.3)
LAM, MU = C.moduli()
GRAD = np.array([[1e-3, 2e-4], [-3e-4, 5e-4]])
SHIFT = np.array([1e-4, -2e-4])
ALL_FACES = [(f, k) for f in face_names(2) for k in range(2)]
#: exactness after a sparse LU solve, relative to the largest displacement: machine
#: epsilon times the systems' condition (measured: 8.7e3 for the mirror traction
#: problem, 7 and 17 for the Dirichlet ones), with a margin of about fifty
SOLVED = 1e-10
#: the same claim in percent (the scenes' metrics)
SOLVED_PCT = 100 * SOLVED


def affine(x):
    return x @ GRAD.T + SHIFT


def affine_traction(x, n, face):
    eps = 0.5 * (GRAD + GRAD.T)
    sig = LAM * np.trace(eps) * np.eye(2) + 2 * MU * eps
    return n @ sig.T


def stencil(quadrature="partial-volume"):
    return state_based_stencil(2, 3.0, H, get_influence("gaussian"), quadrature)


def solve_mirror(dirichlet, **kw):
    st = stencil()
    g = BoxGrid(L, (0.0, 0.0), H, st.reach)
    mn = MirrorNodes(g, st, dirichlet, affine, affine_traction, (LAM, MU), **kw)
    m = StateBasedModel(g, st, C, get_influence("gaussian"), mn.closure())
    U_c = mn.constant_displacements()
    rhs = -m.rows_of_state(U_c, m.A_Theta @ (m.A_theta @ (m.A_e @ U_c.T.ravel())))
    x = g.x[g.interior_ids]
    ni = x.shape[0]
    fixed = np.zeros(0, dtype=int) if dirichlet else np.array([0, ni, 1])
    values = np.zeros(0) if dirichlet else np.r_[affine(x[:1])[0], affine(x[1:2])[0, 0]]
    u, _ = solve_with_dirichlet(m.stiffness(), rhs, fixed, values, "test")
    return np.abs(u.reshape(2, ni).T - affine(x)).max() / np.abs(affine(x)).max(), mn, g


def test_peridynamic_gradient_is_the_inward_normal_on_a_face():
    """A fictitious node beside the middle of a face sees the body straight ahead."""
    st = stencil()
    g = BoxGrid(L, (0.0, 0.0), H, st.reach)
    n = peridynamic_gradient(g, st)
    mid = np.flatnonzero(np.isclose(g.x[:, 0], -0.05) & np.isclose(g.x[:, 1], 0.45))
    assert np.allclose(n[mid], [[1.0, 0.0]], atol=1e-15)  # a unit vector: a few ulps


@pytest.mark.parametrize("gradient_at", ["mirror", "boundary"])
def test_mirror_traction_problem_with_an_affine_solution(gradient_at):
    """Traction on every face, the full traction reading: the affine field is reproduced
    to round-off (its tangential derivatives are differenced exactly, at the mirror
    node's cell or at the boundary point's: an affine field has the same gradient
    everywhere; every real node has a complete neighbourhood, where an affine field
    carries no net force)."""
    err, mn, g = solve_mirror([], gradient_at=gradient_at)
    assert err < SOLVED
    # the differences are taken where the reading says: every node of a difference is
    # within one cell of the mirror node's cell or of the boundary point's
    at = (g.index[mn.mirror] if gradient_at == "mirror"
          else np.clip(np.floor((mn.boundary_point + 1e-9 * H) / H).astype(int), 0,
                       np.asarray(g.nodes_per_axis) - 1))
    for mask, _, nodes, _, coef in mn.entries:
        use = mask & (coef != 0)
        assert np.abs(g.index[nodes[use]] - at[use]).max() <= 1


def test_mirror_at_mirror_point_is_not_exact_for_affine_fields():
    """``mirror_point=at-mirror-point`` takes the Neumann step from the mirror point x*
    instead of the mirror node x_m: u_f = u_m + (x_f - x*) . G. Where x* is a node (beside
    a straight face) that is the exact relation; near corners, where the peridynamic
    gradient tilts and x_m is only the node nearest x*, it is wrong by (x* - x_m) . G, so
    the traction problem's affine field is no longer reproduced."""
    err, mn, g = solve_mirror([], mirror_point="at-mirror-point")
    # measured 0.24 (the pure traction problem, held by three values only, spreads
    # the corner mismatch over the body); 1e-6 is far above round-off
    assert err > 1e-6
    star = g.x[mn.fictitious] + 2 * (mn.boundary_point - g.x[mn.fictitious])
    on_node = np.all(np.isclose(star, g.x[mn.mirror], atol=1e-12), axis=1)
    x = g.x[g.interior_ids]
    U = (mn.displacement_map() @ affine(x).T.ravel()).reshape(2, -1).T
    bad = np.abs(U[mn.fictitious] + mn.const - affine(g.x[mn.fictitious])).max(axis=1)
    # values ~1e-3 from sums of a few terms: 1e-15 is a few ulps
    assert np.all(bad[on_node] < 1e-15) and np.all(bad[~on_node] > 1e-9)


@pytest.mark.parametrize("mirror_point,exact", [("corrected", True), ("nearest", False)])
def test_mirror_dirichlet_problem_with_an_affine_solution(mirror_point, exact):
    """Dirichlet on every face: with the mirror mismatch corrected (our variant) the
    affine field is reproduced to round-off; with the nearest node (the method) only the
    fictitious nodes whose mirror point is a node are, and the rest (near the corners,
    where the peridynamic gradient tilts) leave an error."""
    err, mn, g = solve_mirror(ALL_FACES, mirror_point=mirror_point)
    if exact:
        assert err < SOLVED
    else:
        # measured 1.2e-3: far above round-off (a real mismatch), below 1e-2 (a mirror
        # offset of under one cell times the gradient, against the largest value)
        assert 1e-6 < err < 1e-2
        star = g.x[mn.fictitious] + 2 * (mn.boundary_point - g.x[mn.fictitious])
        # coordinates ~1 m: a mirror point on a node agrees to round-off
        on_node = np.all(np.isclose(star, g.x[mn.mirror], atol=1e-12), axis=1)
        assert on_node.any() and not on_node.all()
        x = g.x[g.interior_ids]
        U = (mn.displacement_map() @ affine(x).T.ravel()).reshape(2, -1).T
        U_f = U[mn.fictitious] + mn.const
        # values ~1e-3 from sums of three terms: 1e-15 is a few ulps
        good = np.abs(U_f - affine(g.x[mn.fictitious])).max(axis=1) < 1e-15
        assert np.array_equal(good[on_node], np.ones(on_node.sum(), dtype=bool))


def test_pddo_operators_are_exact_for_quadratics():
    """Every first and second derivative of a quadratic field, at every node (corners and
    edges included), to round-off relative to the field's scale."""
    st = stencil()
    g = BoxGrid(L, (0.0, 0.0), H, 0)
    m = StateBasedModel(g, st, C, get_influence("gaussian"))
    D = derivative_operators(m)
    x, y = g.x[:, 0], g.x[:, 1]
    u = 1 + 2 * x - 3 * y + 4 * x * x - 5 * x * y + 6 * y * y
    want = {(0,): 2 + 8 * x - 5 * y, (1,): -3 - 5 * x + 12 * y,
            (0, 0): 8 + 0 * x, (0, 1): -5 + 0 * x, (1, 1): 12 + 0 * x}
    assert set(D) == set(monomial_orders(2))
    for o, w in want.items():
        # round-off of A^-1 (moment matrices scaled to unit diagonal, condition <= 95
        # here, measured) on sums of O(100) terms, times the largest derivative, 12
        assert np.allclose(D[o] @ u, w, rtol=0, atol=1e-9 * 12)


@pytest.mark.parametrize("bulk_model,exact", [("pddo", True), ("lps", False)])
def test_pddo_bulk_models_on_a_quadratic_field(bulk_model, exact):
    """Dirichlet on every face, a quadratic field under the body force of Navier's
    equation: with the PDDO equilibrium in the bulk too (``bulk_model=pddo``) every row
    is exact for quadratics, so the field is reproduced to round-off; with the LPS bulk
    the discrete lattice's moduli (1 % anisotropic at m = 3 with exact partial areas,
    plate2d-plane-strain's docstring) leave an error."""
    st = state_based_stencil(2, 3.0, H / 2, get_influence("gaussian"))
    g = BoxGrid(L, (0.0, 0.0), H / 2, 0)   # 20 x 16 cells: some nodes beyond 2 delta
    m = StateBasedModel(g, st, C, get_influence("gaussian"))
    q = np.array([[2e-3, -1e-3, 3e-3], [1e-3, 4e-3, -2e-3]])   # u_k: a xx + b xy + c yy

    def quad(x):
        mono = np.stack([x[:, 0] ** 2, x[:, 0] * x[:, 1], x[:, 1] ** 2], axis=1)
        return affine(x) + mono @ q.T
    # grad div u and lap u of the quadratic: constants
    lap = 2 * q[:, 0] + 2 * q[:, 2]
    graddiv = np.array([2 * q[0, 0] + q[1, 1], q[0, 1] + 2 * q[1, 2]])
    b = -((LAM + MU) * graddiv + MU * lap)   # -(lam + mu) grad div u - mu lap u = b
    body = np.tile(b, (g.n_interior, 1)) * m.node_volume[:, None]
    A, rhs, counts = pddo_system(m, ALL_FACES, quad, affine_traction, (LAM, MU), body,
                                 bulk_model=bulk_model)
    assert (counts["bulk_nodes"] == 0) == (bulk_model == "pddo")
    u, _ = solve_with_dirichlet(A, rhs, np.zeros(0, dtype=int), np.zeros(0), "test")
    err = np.abs(u.reshape(2, -1).T - quad(g.x)).max() / np.abs(quad(g.x)).max()
    if exact:
        assert err < SOLVED
    else:   # measured 2.0e-4; above 1e-6 is far from round-off
        assert err > 1e-6


def test_pddo_dirichlet_problem_with_an_affine_solution():
    """Dirichlet on every face: the PDDO boundary rows impose u on the boundary through
    the nodes' Taylor expansion, the layer the PDDO equilibrium, the bulk LPS; the affine
    field satisfies all three exactly (round-off)."""
    st = state_based_stencil(2, 3.0, H / 2, get_influence("gaussian"))
    g = BoxGrid(L, (0.0, 0.0), H / 2, 0)   # 20 x 16 cells: some nodes beyond 2 delta
    m = StateBasedModel(g, st, C, get_influence("gaussian"))
    A, rhs, counts = pddo_system(m, ALL_FACES, affine, affine_traction, (LAM, MU))
    assert min(counts.values()) > 0
    u, _ = solve_with_dirichlet(A, rhs, np.zeros(0, dtype=int), np.zeros(0), "test")
    x = g.x
    assert np.abs(u.reshape(2, -1).T - affine(x)).max() < SOLVED * np.abs(affine(x)).max()


# ------------------------------------------------------------------ seed 001 §5
@pytest.fixture(scope="module")
def section5():
    scene = get_scene("plate2d-plane-strain")
    out = {}
    for key, method, over in [("none", "none", {}), ("pals", "pals", {}),
                              ("mnm", "mirror-nodes", {}),
                              ("mnm-normal", "mirror-nodes", {"neumann": "normal-only"}),
                              ("pddo", "pddo", {}), ("snm", "surface-nodes", {"order": 1}),
                              ("mnm-corrected", "mirror-nodes", {"mirror_point": "corrected"}),
                              ("mnm-at-point", "mirror-nodes",
                               {"mirror_point": "at-mirror-point"}),
                              ("mnm-boundary", "mirror-nodes", {"gradient_at": "boundary"}),
                              ("pddo-bulk", "pddo", {"bulk_model": "pddo"})]:
        r = scene.run(method, {"spacing": 0.05, **over})
        assert r.status == "ok", r.message
        out[key] = r.metrics
        out[key + ":fields"] = r.fields
    return out


def test_section5_pals_and_snm(section5):
    """Seed 001 §5: PALS lowers both errors of the uncorrected model (measured at
    h = 0.05: u 17.3 -> 4.9 %, v 12.1 -> 5.6 %) and SNM is below PALS in both (1.2 and
    0.51 %): 'SNM has the smallest errors of the ordinary state-based methods' holds
    against PALS."""
    s = section5
    for k in ("max_error_u_pct", "max_error_v_pct"):
        assert s["pals"][k] < s["none"][k]
        assert s["snm"][k] < s["pals"][k]


def test_section5_mnm_readings(section5):
    """The paper's MNM is 'worst in y'. Our two readings bracket it: with the full
    traction condition the plate's affine solution is reproduced to round-off (better
    than SNM, which carries the discrete material's 1.2 % moduli error); with the normal
    derivatives alone the free face x = l_x is forced to zero normal strain, and MNM is
    worst in both components (u 96 %, v 21 %)."""
    s = section5
    assert s["mnm"]["max_error_pct"] < SOLVED_PCT
    others = [s[k]["max_error_v_pct"] for k in ("pals", "pddo", "snm", "none")]
    assert s["mnm-normal"]["max_error_v_pct"] > max(others)


def test_section5_pddo(section5):
    """The PDDO layer reproduces the plate's affine solution to round-off (its operators
    are exact for quadratics; the bulk's LPS rows carry no force for an affine field):
    'PDDO similar to SNM', here smaller."""
    assert section5["pddo"]["max_error_pct"] < SOLVED_PCT


#: the readings of seed 001 §5's MNM and PDDO that we run (report cases of the plate)
READINGS = ("mnm", "mnm-normal", "mnm-corrected", "mnm-at-point", "mnm-boundary", "pddo",
            "pddo-bulk")


def test_section5_no_reading_gives_the_papers_mnm_pattern(section5):
    """Seed 001 §5.4: MNM 'really close to the analytical solution for the displacements
    in x direction, except in one of the corners', its y errors 'the highest among the
    four analyzed methods'. No reading does both (deviations: '001-s5-mnm-readings'):

    - the readings exact for affine fields (full traction with the nearest or the
      corrected mirror node or the gradient at the boundary point; PDDO with either
      bulk) give round-off: the plate's exact field (Eq. 43) is affine, every real node
      has a complete neighbourhood, where an affine field carries no force whatever the
      lattice, and their boundary relations are the continuum's;
    - normal-only (a wrong boundary strain) moves the whole plate to another homogeneous
      state, worst in both components and worse in u than in v;
    - at-mirror-point (the Neumann step from the mirror point) errs at the corners,
      where the mirror node is only the nearest one, in both components, and its v error
      stays below PALS's, so it is not 'worst in y'.
    """
    s = section5
    yardstick = [s[k] for k in ("pals", "snm", "none")]
    worst_v = max(m["max_error_v_pct"] for m in yardstick)
    for key in READINGS:
        assert not mnm_pattern(s[key], s["pals"], yardstick), key
    for key in ("mnm", "mnm-corrected", "mnm-boundary", "pddo", "pddo-bulk"):
        assert s[key]["max_error_pct"] < SOLVED_PCT, key
    normal = s["mnm-normal"]
    assert normal["max_error_u_pct"] > normal["max_error_v_pct"] > worst_v
    point = s["mnm-at-point"]
    assert point["max_error_pct"] > 1e3 * SOLVED_PCT             # not exact
    assert point["max_error_v_pct"] < s["pals"]["max_error_v_pct"]
    reach = 3.0 * 0.05                                            # one horizon, m = 3
    for k in range(2):
        assert where_max(s["mnm-at-point:fields"], k, reach).startswith("corner"), k


def test_mnm_pattern_and_where_max_can_say_yes():
    """The predicate and the locator of the study are not constant: a run close in x and
    worst in y matches; a corner, an edge and the inside are told apart."""
    pals = {"max_error_u_pct": 2.0, "max_error_v_pct": 2.0}
    others = [pals, {"max_error_u_pct": 9.0, "max_error_v_pct": 5.0}]
    assert mnm_pattern({"max_error_u_pct": 0.1, "max_error_v_pct": 6.0}, pals, others)
    assert not mnm_pattern({"max_error_u_pct": 3.0, "max_error_v_pct": 6.0}, pals, others)
    assert not mnm_pattern({"max_error_u_pct": 0.1, "max_error_v_pct": 4.0}, pals, others)
    x = np.array([[0.05, 0.05], [0.95, 0.5], [0.5, 0.5]])
    for i, want in enumerate(("corner x-, y-", "edge x+", "inside")):
        err = np.full((3, 2), 1e-3)
        err[i] = 1.0
        assert where_max({"x": x, "lengths": (1.0, 1.0), "error": err}, 0, 0.1) == want


def test_the_readings_table_names_the_matching_reading(tmp_path):
    """The report's §5 table: one row per reading run plus the yardstick, and a caption
    naming the reading that shows the paper's pattern, or saying none does."""
    from pdverify.report.figures import surface_nodes
    scene = get_scene("plate2d-plane-strain")
    runs = [scene.run(m, {"spacing": 0.1, **o}) for m, o in
            [("none", {}), ("pals", {}), ("surface-nodes", {"order": 1}),
             ("mirror-nodes", {}), ("mirror-nodes", {"neumann": "normal-only"})]]
    assert all(r.status == "ok" for r in runs)
    rows = surface_nodes.section5_readings(runs)
    assert [name for name, *_ in rows] == [
        "MNM: full traction, nearest mirror node (default)", "MNM: normal derivatives only",
        "PALS", "SNM (order 1)", "none (uncorrected)"]
    (name, caption), = surface_nodes._readings_table(scene, runs, str(tmp_path))
    assert (tmp_path / name).exists() and "No reading matches the paper" in caption
    # a run made to show the pattern: the caption names it instead
    normal = runs[-1]
    normal.metrics = {**normal.metrics, "max_error_u_pct": 1e-3}
    (_, caption), = surface_nodes._readings_table(scene, runs, str(tmp_path))
    assert "matches the paper: MNM: normal derivatives only" in caption


@pytest.mark.slow
def test_the_readings_deviation_quotes_the_runs():
    """Deviation '001-s5-mnm-readings' quotes the two readings that are not exact at the
    paper's grid (h = 0.02) as they run now, to the digits it prints."""
    from pdverify.deviations import DEVIATIONS
    d = next(d for d in DEVIATIONS if d.key == "001-s5-mnm-readings")
    scene = get_scene("plate2d-plane-strain")
    runs = [scene.run("mirror-nodes", over)
            for over in ({"neumann": "normal-only"}, {"mirror_point": "at-mirror-point"})]
    text = d.render(runs, scene.id)["text"]   # as the report shows it beside these runs
    for r in runs:
        assert r.status == "ok", r.message
        for k in ("u", "v"):
            assert f"{r.metrics[f'max_error_{k}_pct']:.3g} % in {k}" in text, (r.params, k)
