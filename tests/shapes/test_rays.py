"""Seed 003's ray distance a (Eq. 14) on bodies that are not boxes (issue 55,
``pdverify.pd.rays``): the slab form on a box to round-off, closed forms on the hole, the
L, a crack, the cylinder and the cavity, and on random rays of every shape scene's body
the crossing lies on the boundary with the body (uncut) before it."""
import numpy as np
import pytest

from pdverify.corrections.energy_directional import (box_factors, directional_closure,
                                                     ray_distance)
from pdverify.pd import BoxGrid, StateBasedConstants, StateBasedModel, get_influence
from pdverify.pd.rays import exit_distance
from pdverify.pd.shapes import Crack, l_shape, polygon, quarter_hole
from pdverify.pd.shapes3d import Planar, Shape3D, cavity_octant, quarter_cylinder
from pdverify.pd.statebased import state_based_stencil
from pdverify.scenes import get_scene

EPS = np.finfo(float).eps
#: a closed form and the code form the same distance by different roundings (a square
#: root, a quotient of differences of numbers of order 1): a few ulp of the body's size
CLOSED = 16 * EPS


def _directions(rng, n, dim):
    e = rng.normal(size=(n, dim))
    return e / np.linalg.norm(e, axis=1)[:, None]


def _box3d(A, B, C) -> Shape3D:
    ex, ey, ez = np.eye(3)
    parts = []
    for k, (u, v, size) in enumerate(((ey, ez, (B, C)), (ex, ez, (A, C)), (ex, ey, (A, B)))):
        n = np.eye(3)[k]
        top = np.array([A, B, C]) * n
        parts += [Planar(f"{'xyz'[k]}-", (0.0, 0.0, 0.0), tuple(u), tuple(v), tuple(-n),
                         "rect", size),
                  Planar(f"{'xyz'[k]}+", tuple(top), tuple(u), tuple(v), tuple(n), "rect",
                         size)]
    return Shape3D(tuple(parts), lambda x: np.all((x > 0) & (x < [A, B, C]), axis=1),
                   (0.0, 0.0, 0.0), (A, B, C), "box")


@pytest.mark.parametrize("sides", [(2.0, 1.0), (0.3, 0.7), (2.0, 1.0, 4.0), (0.3, 0.7, 1.1)])
def test_on_a_box_the_ray_distance_is_the_slab_form(sides):
    """A rectangle (four segments) or a block (six planes) as a shape: the first
    crossing equals ``ray_distance``'s slab form bit for bit in 3D and on power-of-two
    sides in 2D (the products of the cross products are exact there), else within two
    ulp (a quotient of two rounded products against the quotient of their factors),
    rays along the axes and the diagonals included."""
    rng = np.random.default_rng(1)
    D = len(sides)
    upper = np.array(sides)
    x = rng.uniform(0, 1, size=(20000, D)) * upper
    e = _directions(rng, len(x), D)
    e[:D * 500] = np.repeat(np.eye(D), 500, axis=0)          # along each axis
    e[D * 500:D * 1000] = -np.repeat(np.eye(D), 500, axis=0)
    e[D * 1000:D * 1000 + 500] = 1 / np.sqrt(D)                # the diagonal
    if D == 2:
        A, B = sides
        shape = polygon([(0, 0), (A, 0), (A, B), (0, B)], ("y-", "x+", "y+", "x-"))
    else:
        shape = _box3d(*sides)
    got = exit_distance(shape, x, e)
    want = ray_distance(x, e, np.zeros(D), upper)
    exact = D == 3 or all(np.log2(s) % 1 == 0 for s in sides)
    if exact:
        assert np.array_equal(got, want)
    else:
        assert np.max(np.abs(got - want) / want) <= 2 * EPS


def test_on_a_box_the_closure_from_a_shape_equals_the_box_closure():
    """The bond factors of an LPS box model from its rectangle as a shape equal the box
    form's bit for bit (power-of-two sides, above): the box scenes' numbers cannot move."""
    inf = get_influence("gaussian")
    grid = BoxGrid((2.0, 1.0), (0.0, 0.0), 1 / 16)
    stencil = state_based_stencil(2, 3.0, 1 / 16, inf, "partial-volume")
    model = StateBasedModel(grid, stencil, StateBasedConstants("plane-strain", 1.0, 0.25), inf)
    rect = polygon([(0, 0), (2, 0), (2, 1), (0, 1)], ("y-", "x+", "y+", "x-"))
    args = (grid, (0.0, 0.0), (2.0, 1.0), model.horizon, inf)
    bonds = (model.bond_a, model.bond_b, model.bond_n)
    box = directional_closure(*args, moment=3).bond_factor(*bonds)
    shaped = directional_closure(*args, moment=3, shape=rect).bond_factor(*bonds)
    assert np.array_equal(box, shaped) and np.any(box > 1)
    assert np.array_equal(box_factors(model), box)


def test_closed_forms_at_the_hole():
    """Quarter plate [0, 1]^2 without r < 0.3: a ray to the centre meets the arc at
    r - a; a horizontal ray to the left at height y < a meets it at x - sqrt(a^2 - y^2);
    above the hole (y > a) it reaches the symmetry edge x = 0 at x; a ray past the hole's
    end angle (pointing down from y < a beside it) reaches y = 0."""
    W, a = 1.0, 0.3
    s = quarter_hole(W, a)
    rng = np.random.default_rng(2)
    r = rng.uniform(a + 0.01, 0.9, 400)
    th = rng.uniform(0.01, 0.5 * np.pi - 0.01, 400)
    x = np.c_[r * np.cos(th), r * np.sin(th)]
    assert np.allclose(exit_distance(s, x, -x / r[:, None]), r - a, rtol=0, atol=CLOSED)
    y = rng.uniform(0.0, 0.29, 400)
    x0 = rng.uniform(0.31, 0.9, 400)
    left = np.tile([-1.0, 0.0], (400, 1))
    assert np.allclose(exit_distance(s, np.c_[x0, y], left), x0 - np.sqrt(a * a - y * y),
                       rtol=0, atol=CLOSED)
    y = rng.uniform(0.31, 0.9, 400)
    assert np.allclose(exit_distance(s, np.c_[x0, y], left), x0, rtol=0, atol=CLOSED)
    down = np.tile([0.0, -1.0], (400, 1))
    assert np.allclose(exit_distance(s, np.c_[x0, y], down), y, rtol=0, atol=CLOSED)


def test_closed_forms_on_the_l_plate():
    """L = 1, notch (1/2, 1]^2: from the lower-left square along (1, 1)/sqrt 2 the ray
    crosses the line of the nearer gap inside an arm and meets the notch's side x = 1/2
    (above the diagonal) or y = 1/2 (below) at sqrt 2 times the farther gap, the
    re-entrant corner itself on the diagonal; upward from the
    lower-right arm it meets y = 1/2, not the box's top y = 1."""
    s = l_shape(1.0)
    rng = np.random.default_rng(3)
    p = rng.uniform(0.01, 0.49, size=(600, 2))
    p[:50, 1] = p[:50, 0]                                      # on the diagonal
    diag = np.tile([1.0, 1.0], (600, 1)) / np.sqrt(2)
    want = np.sqrt(2) * (0.5 - np.minimum(p[:, 0], p[:, 1]))
    assert np.allclose(exit_distance(s, p, diag), want, rtol=0, atol=CLOSED)
    q = np.c_[rng.uniform(0.51, 0.99, 300), rng.uniform(0.01, 0.49, 300)]
    up = np.tile([0.0, 1.0], (300, 1))
    assert np.allclose(exit_distance(s, q, up), 0.5 - q[:, 1], rtol=0, atol=CLOSED)


def test_closed_forms_at_a_crack():
    """A horizontal crack from (0, 0) to the tip (0.5, 0) in the square [-1, 1]^2: a
    ray down from above it meets the slit at y, one from below going up at -y; a ray
    through the tip point passes round it (the ligament ahead is intact: ``Crack.cuts``)
    and reaches the edge y = -1; a ray beside the crack reaches the edge."""
    sq = polygon([(-1, -1), (1, -1), (1, 1), (-1, 1)], ("y-", "x+", "y+", "x-"))
    s = sq.with_cracks(Crack("c", (0.0, 0.0), (0.5, 0.0)))
    rng = np.random.default_rng(4)
    xs = rng.uniform(0.0, 0.49, 300)
    y = rng.uniform(0.01, 0.9, 300)
    down, up = np.tile([0.0, -1.0], (300, 1)), np.tile([0.0, 1.0], (300, 1))
    assert np.allclose(exit_distance(s, np.c_[xs, y], down), y, rtol=0, atol=CLOSED)
    assert np.allclose(exit_distance(s, np.c_[xs, -y], up), y, rtol=0, atol=CLOSED)
    tip = np.c_[np.full(300, 0.5), y]
    assert np.allclose(exit_distance(s, tip, down), 1 + y, rtol=0, atol=CLOSED)
    beside = np.c_[rng.uniform(0.51, 0.9, 300), y]
    assert np.allclose(exit_distance(s, beside, down), 1 + y, rtol=0, atol=CLOSED)
    # a ray from a point on the crack's line (the + side) into the - side: at once
    on = np.c_[xs, np.zeros(300)]
    assert np.all(exit_distance(s, on, down) == 0) and np.all(exit_distance(s, on, up) == 1)


def test_closed_forms_on_the_3d_shapes():
    """Quarter cylinder R = 0.5, L = 2: radially out at R - r, along +z at L - z; the
    cavity octant W = 1, a = 0.3: towards the centre at r - a."""
    rng = np.random.default_rng(5)
    cyl = quarter_cylinder(0.5, 2.0)
    r = rng.uniform(0.01, 0.49, 300)
    th = rng.uniform(0.01, 0.5 * np.pi - 0.01, 300)
    z = rng.uniform(0.01, 1.99, 300)
    x = np.c_[r * np.cos(th), r * np.sin(th), z]
    radial = np.c_[np.cos(th), np.sin(th), np.zeros(300)]
    assert np.allclose(exit_distance(cyl, x, radial), 0.5 - r, rtol=0, atol=CLOSED)
    axial = np.tile([0.0, 0.0, 1.0], (300, 1))
    assert np.allclose(exit_distance(cyl, x, axial), 2.0 - z, rtol=0, atol=CLOSED)
    cav = cavity_octant(1.0, 0.3)
    d = np.abs(rng.normal(size=(300, 3))) + 0.05
    d /= np.linalg.norm(d, axis=1)[:, None]
    rr = rng.uniform(0.31, 0.95, 300)
    assert np.allclose(exit_distance(cav, rr[:, None] * d, -d), rr - 0.3, rtol=0,
                       atol=CLOSED)


SHAPE_SCENES = ("plate-hole", "plate-l", "plate-crack", "plate-edge-crack",
                "plate-inclined-crack", "cylinder3d-tension", "block3d-cavity")


@pytest.mark.parametrize("scene_id", SHAPE_SCENES)
def test_random_rays_end_on_the_boundary_with_the_body_before(scene_id):
    """Every random ray from inside the scene's body meets a part at a finite t; that
    point lies on the boundary (its closest-point distance within round-off of the
    body's size), and the points at 1 %, 50 % and 99.9 % of t lie inside and are not cut
    off by a crack: the first crossing, not a later one."""
    scene = get_scene(scene_id)
    shape = scene.shape(scene.resolve("none", {}))
    rng = np.random.default_rng(6)
    lo, hi = np.array(shape.lower), np.array(shape.upper)
    x = rng.uniform(lo, hi, size=(4000, shape.dim))
    x = x[shape.inside(x)]
    e = _directions(rng, len(x), shape.dim)
    t = exit_distance(shape, x, e)
    assert np.all(np.isfinite(t)) and np.all(t > 0)
    size = float(np.max(hi - lo))
    assert np.max(shape.closest(x + t[:, None] * e)[2]) <= CLOSED * size
    for f in (0.01, 0.5, 0.999):
        q = x + (f * t)[:, None] * e
        body = shape.inside(q)
        if shape.cracks:
            body &= ~shape.severs(x, q)
        assert np.all(body), (f, np.flatnonzero(~body)[:5])


def test_every_part_kind_is_known():
    """A part the rays do not know is an error naming it, never a silent miss."""
    class Odd:
        name = "odd"
    s = polygon([(0, 0), (1, 0), (1, 1), (0, 1)], ("y-", "x+", "y+", "x-"))
    from dataclasses import replace
    odd = replace(s, parts=s.parts + (Odd(),))
    with pytest.raises(TypeError, match="odd"):
        exit_distance(odd, [[0.5, 0.5]], [[1.0, 0.0]])


def test_a_ray_across_the_notch_counts_the_material_beyond_it():
    """From (0.45, 0.56) in the L's upper arm along (1, -1)/sqrt 2 the ray leaves the body
    through x = 1/2 at a = 0.05 sqrt 2 and enters the lower arm through y = 1/2 at
    b = 0.06 sqrt 2; the model keeps the bonds across the notch, so Eq. 14's denominator
    is the integral over [0, a] and [b, delta] (``directional_factor``; constant omega,
    xi^3: delta^4 / (a^4 + delta^4 - b^4)), not the first crossing's (delta / a)^4. A
    crack ends the ray instead (nothing past its slit is the point's)."""
    from pdverify.corrections.energy_directional import directional_factor
    from pdverify.pd.rays import inside_intervals
    s, delta = l_shape(1.0), 0.2
    x, e = np.array([[0.45, 0.56]]), np.array([[1.0, -1.0]]) / np.sqrt(2)
    a, b = 0.05 * np.sqrt(2), 0.06 * np.sqrt(2)
    edges, inside = inside_intervals(s, x, e, delta)
    kept = [(lo, hi) for lo, hi, i in zip(edges[0, :-1], edges[0, 1:], inside[0]) if i]
    assert np.allclose(kept, [(0, a), (b, delta)], rtol=0, atol=CLOSED)
    inf = get_influence("constant")
    phi = directional_factor(x, e, None, None, delta, inf, 3, shape=s)
    # the closed form and the code's partial moments: round-off of fourth powers
    np.testing.assert_allclose(phi, delta ** 4 / (a ** 4 + delta ** 4 - b ** 4), rtol=1e-12)
    assert phi[0] < 0.5 * (delta / a) ** 4
    cracked = s.with_cracks(Crack("c", (0.75, 0.4), (0.75, 0.2)))
    x2, e2 = np.array([[0.7, 0.3]]), np.array([[1.0, 0.0]])
    edges, inside = inside_intervals(cracked, x2, e2, delta)
    assert edges[0, -1] == pytest.approx(0.05) and inside[0, 0] and not inside[0, 1:].any()


@pytest.mark.parametrize("scene_id", SHAPE_SCENES)
def test_the_kept_bonds_end_before_their_rays_leave_the_body(scene_id):
    """The rays and the model's bond choice agree: on every shape scene's default model
    no kept bond reaches past either end's first crossing (a bond a crack cuts is
    dropped, one round a tip is kept and its ray passes the tip), except, on the L, the
    bonds that bridge the notch (the model keeps them), exactly those with a point
    outside the body."""
    from pdverify.corrections.assembly import model_of
    scene = get_scene(scene_id)
    p = scene.resolve("none", {})
    problem = scene.problem(p, scene_id)
    model = model_of(problem, problem.body.grid(0), None)
    x, a, b, n = model.grid.x, model.bond_a, model.bond_b, model.bond_n
    length = np.linalg.norm(x[b] - x[a], axis=1)
    past = ((exit_distance(problem.shape, x[a], n) < length * (1 - 1e-12))
            | (exit_distance(problem.shape, x[b], -n) < length * (1 - 1e-12)))
    if scene_id != "plate-l":
        assert not past.any(), np.flatnonzero(past)[:5]
        return
    u = np.linspace(0, 1, 101)[1:-1]
    pts = x[a][:, None, :] + u[None, :, None] * (x[b] - x[a])[:, None, :]
    outside = ~problem.shape.inside(pts.reshape(-1, 2)).reshape(len(a), -1).all(axis=1)
    assert past.any() and np.array_equal(past, outside)
