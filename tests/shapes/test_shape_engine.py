"""Shapes cut from a grid (issue 35): geometry, cut cells, boundary samples, the grid's
layers and jitter, the uncorrected model on a shape that is a box, and Taylor's
fictitious nodes along the local normal (exact for the fields its order claims)."""
import numpy as np
import pytest

from pdverify.corrections.assembly import boundary_nodes
from pdverify.corrections.plain import assemble_plain
from pdverify.corrections.taylor_fictitious import assemble_taylor
from pdverify.pd import StateBasedConstants, get_influence, state_based_stencil
from pdverify.pd.build import Body
from pdverify.pd.problem import FaceCondition, StaticProblem
from pdverify.pd.shapes import l_shape, polygon, quarter_hole
from pdverify.solvers.front import solve

H = 0.025
E, NU = 1e9, 0.3
CONSTANTS = StateBasedConstants("plane-stress", E, NU)
INF = get_influence("hyperbolic")
LAM, MU = CONSTANTS.moduli()


def test_arc_closest_points_and_normals():
    s = quarter_hole(1.0, 0.2)
    x = np.array([[0.2, 0.15], [0.05, 0.15], [0.5, 0.5]])
    p, n, dist, part = s.closest(x)
    on_hole = part == s.part_names.index("hole")
    assert on_hole.tolist() == [True, True, False]
    # closed form: the closest point of a circle lies on the ray from its centre
    np.testing.assert_allclose(np.linalg.norm(p[on_hole], axis=1), 0.2, rtol=1e-15)
    np.testing.assert_allclose(n[on_hole], -x[on_hole] / np.linalg.norm(x[on_hole], axis=1)[:, None],
                               rtol=1e-15)
    np.testing.assert_allclose(dist[:2], np.abs(np.linalg.norm(x[:2], axis=1) - 0.2), rtol=1e-14)


def test_cut_cell_fractions_add_up_to_the_area():
    s = quarter_hole(1.0, 0.2)
    g = Body((1.0, 1.0), (0.0, 0.0), H, shape=s).grid(0)
    every = s.fractions(g.lattice_x, H)
    area = 1.0 - np.pi * 0.04 / 4
    # sampled on a 16 x 16 sub-grid per cut cell: the error per cell is at most the cut
    # length times h/16 (module docstring), ~ pi a / 2 * h / 16 = 9.8e-4 h summed; the
    # midpoint rule's errors largely cancel along a smooth arc (measured 2e-7)
    assert abs(every.sum() * H * H - area) < np.pi * 0.2 / 2 * H / 16 * H
    # the L-shape's edges lie on cell faces: whole cells exactly
    gl = Body((1.0, 1.0), (0.0, 0.0), H, shape=l_shape(1.0)).grid(0)
    assert set(np.unique(gl.node_volume[gl.interior_ids])) == {H * H}
    assert gl.n_interior == 1200


def test_boundary_samples_integrate_each_part_and_land_on_the_nearest_layer():
    s = quarter_hole(1.0, 0.2)
    g = Body((1.0, 1.0), (0.0, 0.0), H, shape=s).grid(0)
    P, W, N, part, node = boundary_nodes(g, s)
    for k, q in enumerate(s.parts):
        # Gauss weights sum to the length: round-off of a few hundred terms, 1e-13
        assert abs(W[part == k].sum() - q.length) < 1e-13 * q.length
    x = g.x[g.interior_ids]
    top = node[part == s.part_names.index("y+")]
    assert np.allclose(x[top, 1], 1.0 - H / 2)          # the layer nearest the face
    hole = node[part == s.part_names.index("hole")]
    r = np.linalg.norm(x[hole], axis=1)
    assert np.all(r > 0.2) and np.all(r < 0.2 + H * np.sqrt(2))   # the cut cells' nodes


@pytest.mark.parametrize("layers", [0, 3])
def test_no_bond_of_a_real_node_ends_on_a_void_node(layers):
    from pdverify.pd.build import StateMaterial, build_model
    s = quarter_hole(1.0, 0.2)
    body = Body((1.0, 1.0), (0.0, 0.0), H, shape=s)
    st = state_based_stencil(2, 3.0, H, INF, "partial-volume")
    g = body.grid(layers)
    model = build_model(body, st, StateMaterial(CONSTANTS, INF), None, grid=g)
    ends = np.r_[model.bond_a, model.bond_b]
    assert not np.any(g.is_void[ends])
    if layers == 0:
        assert np.all(g.is_interior[ends])
    else:   # every stencil neighbour of a real node is real or fictitious
        from pdverify.pd.bonds import bond_pairs
        a, b, _ = bond_pairs(g.ext_shape, st.offsets[st.half])
        real = g.is_interior[a] | g.is_interior[b]
        assert not np.any(g.is_void[a[real]] | g.is_void[b[real]])


def test_jitter_is_seeded_bounded_and_off_by_default():
    s = quarter_hole(1.0, 0.2)
    g0 = Body((1.0, 1.0), (0.0, 0.0), H, shape=s).grid(0)
    g1 = Body((1.0, 1.0), (0.0, 0.0), H, shape=s, jitter=0.3, jitter_seed=7).grid(0)
    g2 = Body((1.0, 1.0), (0.0, 0.0), H, shape=s, jitter=0.3, jitter_seed=7).grid(0)
    ids = g1.interior_ids
    move = g1.x[ids] - g0.x[ids]
    assert np.array_equal(g1.x, g2.x)
    assert np.all(np.abs(move) <= 0.15 * H * (1 + 1e-12)) and np.abs(move).max() > 0.1 * H
    assert np.all(s.inside(g1.x[ids]))
    a, b = ids[:-1], ids[1:]
    # no jitter: the lattice's bond vectors, index differences times h, bit for bit
    assert np.array_equal(g0.bond_vectors(a, b), (g0.index[b] - g0.index[a]) * H)
    np.testing.assert_allclose(g1.bond_vectors(a, b), g1.x[b] - g1.x[a], rtol=0, atol=0)


def _box_problem(shape, conditions, **kw):
    st = state_based_stencil(2, 3.0, H, INF, kw.pop("quadrature", "partial-volume"))
    lengths = tuple(np.subtract(shape.upper, shape.lower)) if shape is not None else kw.pop("lengths")
    return StaticProblem(lengths, (0.0, 0.0), H, st, CONSTANTS, INF, conditions,
                         solver="direct", shape=shape, **kw)


def test_the_uncorrected_model_on_a_rectangle_shape_is_the_box_model():
    """The same lattice, volumes, prescribed layer and (constant) traction loads: the
    solutions agree to round-off (the loads are summed in another order: 3 Gauss points
    per cell face against 8 sub-segments per cell)."""
    rect = polygon([(0, 0), (0.5, 0), (0.5, 0.25), (0, 0.25)], ("y-", "x+", "y+", "x-"))
    exact = lambda x: np.zeros_like(x)     # noqa: E731
    pull = FaceCondition(traction=lambda x, n: np.c_[np.full(len(x), 1e6), np.zeros(len(x))])
    conds = {"x-": FaceCondition(prescribed=(0, 1)), "x+": pull}
    a = assemble_plain(_box_problem(rect, conds, exact=exact))
    b = assemble_plain(_box_problem(None, conds, exact=exact, lengths=(0.5, 0.25)))
    assert abs(a.K - b.K).max() == 0.0
    np.testing.assert_array_equal(a.fixed, b.fixed)
    np.testing.assert_allclose(a.rhs, b.rhs, rtol=1e-13, atol=1e-13 * np.abs(b.rhs).max())
    xa, xb = solve(a, where="a")[0], solve(b, where="b")[0]
    # the loads' round-off (1e-16 relative) through K's condition (~1e4 here)
    np.testing.assert_allclose(xa, xb, rtol=0, atol=1e-11 * np.abs(xb).max())


def _affine(x):
    return np.c_[1e-3 * x[:, 0] + 2e-4 * x[:, 1] + 1e-4, -3e-4 * x[:, 0] + 5e-4 * x[:, 1]]


_G = np.array([[1e-3, 2e-4], [-3e-4, 5e-4]])


def _affine_traction(x, n):
    eps = 0.5 * (_G + _G.T)
    return n @ (LAM * np.trace(eps) * np.eye(2) + 2 * MU * eps).T


def _quadratic(x):
    X, Y = x[:, 0], x[:, 1]
    return 1e-3 * np.c_[X * X + 0.5 * X * Y - 0.3 * Y * Y, 0.2 * X * X - X * Y + 0.7 * Y * Y]


def _quadratic_gradient(x):
    a, X, Y = 1e-3, x[:, 0], x[:, 1]
    G = np.empty((len(x), 2, 2))
    G[:, 0, 0], G[:, 0, 1] = a * (2 * X + 0.5 * Y), a * (0.5 * X - 0.6 * Y)
    G[:, 1, 0], G[:, 1, 1] = a * (0.4 * X - Y), a * (-X + 1.4 * Y)
    return G


def _quadratic_traction(x, n):
    G = _quadratic_gradient(x)
    eps = 0.5 * (G + np.transpose(G, (0, 2, 1)))
    S = 2 * MU * eps
    tr = eps[:, 0, 0] + eps[:, 1, 1]
    S[:, 0, 0] += LAM * tr
    S[:, 1, 1] += LAM * tr
    return np.einsum("nij,nj->ni", S, n)


def _quadratic_body_force(x):
    a = 1e-3     # -div sigma of the quadratic field, constant
    bx = (LAM + 2 * MU) * 2 * a + MU * (-0.6 * a) + (LAM + MU) * (-a)
    by = (LAM + 2 * MU) * 1.4 * a + MU * 0.4 * a + (LAM + MU) * 0.5 * a
    return np.tile([-bx, -by], (len(x), 1))


CASES = {"affine": (_affine, None, _affine_traction, 1, "partial-volume"),
         "quadratic": (_quadratic, _quadratic_body_force, _quadratic_traction, 2,
                       "moment-corrected")}


@pytest.mark.parametrize("shape", [quarter_hole(1.0, 0.2), l_shape(1.0)],
                         ids=["hole", "l-plate"])
@pytest.mark.parametrize("field", sorted(CASES))
@pytest.mark.parametrize("mode", ["dirichlet", "mixed"])
def test_taylor_along_the_normal_is_exact_for_its_order(shape, field, mode):
    """Order 1 reproduces an affine field, order 2 a quadratic one with its body force
    (on the moment-corrected stencil, whose complete neighbourhoods are exact for
    quadratics), with every part prescribed or x- prescribed and the rest loaded by the
    field's traction (force flux rows on the straight parts, the fit's traction on the
    hole's arc). Tolerance: round-off through the bordered system's condition
    (estimates ~1.2e7; 1e-16 x 1e7 = 1e-9; measured <= 6e-13)."""
    u, b, t, order, quadrature = CASES[field]
    if mode == "mixed":
        # a traction holds exactly where the lattice's moduli are the continuum's: on
        # partial volumes the flux of an affine field is off by the quadrature's moduli
        # error (0.47 % on this rectangle's box twin, the same with seed 000's box rows)
        quadrature = "moment-corrected"
    names = shape.part_names
    conds = ({k: FaceCondition(prescribed=(0, 1)) for k in names} if mode == "dirichlet"
             else {k: (FaceCondition(prescribed=(0, 1)) if k == "x-"
                       else FaceCondition(traction=t)) for k in names})
    system = assemble_taylor(_box_problem(shape, conds, exact=u, body_force=b,
                                          quadrature=quadrature), order)
    x, _ = solve(system, where=f"{shape.name} {field}")
    g = system.model.grid
    got, want = system.displacements(x)[:g.n_interior], u(g.x[g.interior_ids])
    assert np.abs(got - want).max() < 1e-9 * np.abs(want).max()


def test_taylor_along_the_normal_fails_the_quadratic_at_order_one():
    """The exactness above is the order's: order 1 on the quadratic field is off by far
    more than round-off (measured ~1e-3 relative)."""
    u, b, t, _, quadrature = CASES["quadratic"]
    shape = quarter_hole(1.0, 0.2)
    conds = {k: FaceCondition(prescribed=(0, 1)) for k in shape.part_names}
    system = assemble_taylor(_box_problem(shape, conds, exact=u, body_force=b,
                                          quadrature=quadrature), 1)
    x, _ = solve(system, where="order 1")
    g = system.model.grid
    got, want = system.displacements(x)[:g.n_interior], u(g.x[g.interior_ids])
    assert np.abs(got - want).max() > 1e-6 * np.abs(want).max()


def test_taylor_on_a_rectangle_shape_matches_the_box_rows():
    """The shape's rows on a rectangle are seed 000/001's box rows: the Dirichlet value
    at each face's boundary points and the force flux of each boundary cell face (the
    bonds crossing it, half on its edges), so a cubic field with its body force under
    mixed conditions comes out as on the box. Measured at h = 0.05, moment-corrected,
    relative L2 errors: box 1.22e-2 / 7.17e-3 (orders 1 / 2), shape 1.17e-2 / 7.11e-3;
    tolerance: a tenth of the error itself (they are different fits of the same
    extrapolation: the box's along lattice lines, ours least squares about the point)."""
    a, L, Hh = 1e-3, 1.0, 0.5

    def u(x):
        X, Y = x[:, 0], x[:, 1]
        return a * np.c_[X ** 3 + X * Y * Y - 0.5 * Y ** 3, -X * X * Y + 0.3 * X ** 3 + 0.2 * Y ** 3]

    def stress(x):
        X, Y = x[:, 0], x[:, 1]
        G = np.empty((len(x), 2, 2))
        G[:, 0, 0], G[:, 0, 1] = a * (3 * X * X + Y * Y), a * (2 * X * Y - 1.5 * Y * Y)
        G[:, 1, 0], G[:, 1, 1] = a * (-2 * X * Y + 0.9 * X * X), a * (-X * X + 0.6 * Y * Y)
        eps = 0.5 * (G + np.transpose(G, (0, 2, 1)))
        S = 2 * MU * eps
        tr = eps[:, 0, 0] + eps[:, 1, 1]
        S[:, 0, 0] += LAM * tr
        S[:, 1, 1] += LAM * tr
        return S

    def body(x):     # -div sigma, exact: sigma is quadratic, its derivatives linear
        X, Y = x[:, 0], x[:, 1]
        # d/dx sigma_x., d/dy sigma_y. from the gradient's second derivatives
        uxx, uxy, uyy = a * 6 * X, a * 2 * Y, a * (2 * X - 3 * Y)
        vxx, vxy, vyy = a * (-2 * Y + 1.8 * X), a * (-2 * X), a * 1.2 * Y
        bx = (LAM + 2 * MU) * uxx + MU * uyy + (LAM + MU) * vxy
        by = (LAM + 2 * MU) * vyy + MU * vxx + (LAM + MU) * uxy
        return -np.c_[bx, by]

    def traction(x, n):
        return np.einsum("nij,nj->ni", stress(x), n)

    rect = polygon([(0, 0), (L, 0), (L, Hh), (0, Hh)], ("y-", "x+", "y+", "x-"))
    conds = {"x-": FaceCondition(prescribed=(0, 1)), **{k: FaceCondition(traction=traction)
                                                        for k in ("x+", "y-", "y+")}}
    h = 0.05
    st = state_based_stencil(2, 3.0, h, INF, "moment-corrected")
    for order in (1, 2):
        errors = []
        for shape in (None, rect):
            pr = StaticProblem((L, Hh), (0.0, 0.0), h, st, CONSTANTS, INF, conds, exact=u,
                               body_force=body, solver="direct", shape=shape)
            system = assemble_taylor(pr, order)
            x, _ = solve(system, where="rectangle")
            g = system.model.grid
            got, want = system.displacements(x)[:g.n_interior], u(g.x[g.interior_ids])
            errors.append(np.linalg.norm(got - want) / np.linalg.norm(want))
        assert abs(errors[1] - errors[0]) < 0.1 * errors[0], (order, errors)


def _outside_along(shape, x, p, samples=801):
    """Brute force: whether the segment x -> p has a sample strictly outside the closed
    body before p (farther than 1e-7 from the boundary)."""
    t = np.linspace(0.0, 1.0, samples)[1:-1]
    pts = x[:, None, :] + t[None, :, None] * (p - x)[:, None, :]
    flat = pts.reshape(-1, 2)
    out = ~shape.inside(flat) & (shape.closest(flat)[2] > 1e-7)
    return out.reshape(len(x), -1).any(axis=1)


def test_hides_is_the_segment_leaving_the_body_through_another_part():
    """``Shape.hides`` on the L-shape (straight parts: a segment from inside leaves the
    body before p exactly when it crosses another part) against sampling the segment;
    on the hole plate a chord of the arc dips into the hole and is not hidden, every
    segment to a point of a straight part is (sampled) as on the L."""
    rng = np.random.default_rng(3)
    L = l_shape(1.0)
    x = rng.uniform(0, 1, (1500, 2))
    x = x[L.inside(x)]
    # boundary points of the two notch faces and the others
    s = L.samples(0.05)
    pick = rng.integers(0, len(s[0]), len(x))
    p, part = s[0][pick], s[3][pick]
    got = L.hides(x, p, part)
    want = _outside_along(L, x, p)
    assert got.sum() > 100 and np.array_equal(got, want)
    H = quarter_hole(1.0, 0.2)
    x = rng.uniform(0, 0.5, (1200, 2))
    x = x[H.inside(x)]
    p, _, _, part = H.closest(rng.uniform(-0.1, 0.5, (len(x), 2)))
    got = H.hides(x, p, part)
    arc = part == H.part_names.index("hole")
    assert not got[arc].any() and _outside_along(H, x[arc], p[arc]).any()
    assert np.array_equal(got[~arc], _outside_along(H, x[~arc], p[~arc]))


def test_shadow_ends_with_the_nodes_own_rows_change_nothing():
    """``Closure.shadow`` whose rows are the fictitious nodes' own rows of the maps gives
    the model without it to round-off (the same sums over other columns)."""
    from pdverify.corrections.assembly import model_of
    from pdverify.corrections.shape_fictitious import bridging, normal_closure
    from pdverify.pd.bonds import bond_pairs
    shape = l_shape(1.0)
    problem = _box_problem(shape, {"x-": FaceCondition(prescribed=(0, 1))}, exact=_affine)
    g = problem.body.grid(problem.stencil.reach)
    g.node_volume[g.interior_ids] = g.volume
    closure = normal_closure(g, shape, 2, problem.stencil)
    assert closure.shadow is not None
    pairs = closure.shadow[0]
    a, b, _ = bond_pairs(g.ext_shape, problem.stencil.offsets[problem.stencil.half])
    fict = np.where(g.is_interior[a[pairs]], b[pairs], a[pairs])
    ref = model_of(problem, g, normal_closure(g, shape, 2, problem.stencil))
    closure.shadow = (pairs, closure.displacement_map[fict], closure.dilatation_map[fict])
    same = model_of(problem, g, closure)
    closure.shadow = None
    plain = model_of(problem, g, closure)
    K0, K1 = plain.stiffness(), same.stiffness()
    assert abs(K0 - K1).max() <= 1e-13 * abs(K0).max()
    assert abs(ref.stiffness() - K0).max() > 1e-6 * abs(K0).max()   # the shadow acts
    assert bridging(g, shape, a, b, closure.keep)[0].size == pairs.size
