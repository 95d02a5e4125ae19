"""Cracks in the shape layer (issue 54): a straight slit of zero width whose faces are
named parts, whose crossing bonds the model drops (``Closure.bond_mask``), with the
conventions of ``pdverify.pd.shapes`` at the tip and on the crack's line."""
import dataclasses
from fractions import Fraction

import numpy as np
import pytest

from pdverify.corrections.assembly import boundary_nodes
from pdverify.corrections.plain import assemble_plain
from pdverify.pd import StateBasedConstants, build_stencil, get_influence, state_based_stencil
from pdverify.pd.bonds import bond_pairs
from pdverify.pd.build import BondMaterial, Body, StateMaterial, build_model
from pdverify.pd.problem import FaceCondition, StaticProblem
from pdverify.pd.shapes import Crack, polygon, quarter_hole
from pdverify.solvers.front import solve

H = 0.025
CONSTANTS = StateBasedConstants("plane-stress", 1e9, 0.3)
INF = get_influence("hyperbolic")


def _box(W=0.5, Hb=0.25):
    return polygon([(0, 0), (W, 0), (W, Hb), (0, Hb)], ("y-", "x+", "y+", "x-"), "box")


def _cracked(shape, *cracks):
    return shape.with_cracks(*cracks)


def _models(shape, layers=0):
    """State- and bond-based uncorrected models of ``shape`` (its bounding box's lattice)."""
    lengths = tuple(np.subtract(shape.upper, shape.lower))
    body = Body(lengths, tuple(shape.lower), H, shape=shape)
    g = body.grid(layers)
    state = build_model(body, state_based_stencil(2, 3.0, H, INF, "partial-volume"),
                        StateMaterial(CONSTANTS, INF), None, grid=g)
    bond = build_model(body, build_stencil(2, 3.0), BondMaterial(1.0, get_influence("constant")),
                       None, grid=g)
    return g, state, bond


def _pairs(model):
    return set(zip(model.bond_a.tolist(), model.bond_b.tolist()))


# ------------------------------------------------------------------ zero length
def test_a_crack_of_zero_length_is_the_uncracked_shape_bit_for_bit():
    plain = quarter_hole(1.0, 0.2)
    dot = _cracked(plain, Crack("crack", (0.6, 0.5), (0.6, 0.5)))
    assert dot.parts == plain.parts and dot.part_names == plain.part_names
    x = np.random.default_rng(0).uniform(0.0, 1.0, (500, 2))
    for got, want in zip(dot.closest(x), plain.closest(x)):
        np.testing.assert_array_equal(got, want)
    for got, want in zip(dot.samples(H), plain.samples(H)):
        np.testing.assert_array_equal(got, want)
    g0, s0, b0 = _models(plain, layers=3)
    g1, s1, b1 = _models(dot, layers=3)
    for name in ("x", "node_volume", "kind", "interior_ids"):
        np.testing.assert_array_equal(getattr(g1, name), getattr(g0, name))
    for m1, m0 in ((s1, s0), (b1, b0)):
        np.testing.assert_array_equal(m1.bond_a, m0.bond_a)
        np.testing.assert_array_equal(m1.bond_b, m0.bond_b)
        np.testing.assert_array_equal(m1.bond_beta, m0.bond_beta)
    np.testing.assert_array_equal(s1.m, s0.m)
    assert abs(b1.K - b0.K).max() == 0.0


def test_a_crack_of_zero_length_solves_plate_hole_bit_for_bit():
    """The static solve of the plate-hole problem (symmetry planes, remote traction) with
    the uncorrected model: the same solution to the last bit."""
    plain = quarter_hole(1.0, 0.2)
    pull = FaceCondition(traction=lambda x, n: np.c_[np.full(len(x), 1e6), np.zeros(len(x))])
    conds = {"x-": FaceCondition(prescribed=(0,)), "y-": FaceCondition(prescribed=(1,)),
             "x+": pull}
    out = []
    for shape in (plain, _cracked(plain, Crack("crack", (0.6, 0.5), (0.6, 0.5)))):
        st = state_based_stencil(2, 3.0, H, INF, "partial-volume")
        problem = StaticProblem((1.0, 1.0), (0.0, 0.0), H, st, CONSTANTS, INF, conds,
                                exact=lambda x: np.zeros_like(x), solver="direct",
                                shape=shape)
        out.append(solve(assemble_plain(problem), where="zero-length crack")[0])
    np.testing.assert_array_equal(out[1], out[0])
    assert np.abs(out[0]).max() > 0


# ------------------------------------------------------------------ bond cutting
def _brute_force_cut(g, a, b, c, x0, xt):
    """Candidate pairs a-b whose bond crosses the horizontal slit y = c, x in [x0, xt)
    (lattice units of H, exact fractions), one pair at a time: ends strictly on either
    side of the line (no node lies on it here) and the crossing's x in [x0, xt)."""
    cut = set()
    for i, j in zip(a.tolist(), b.tolist()):
        (xa, ya), (xb, yb) = ([Fraction(2 * int(k) + 1, 2) for k in g.index[n]] for n in (i, j))
        if (ya - c) * (yb - c) >= 0:
            continue
        xs = xa + (c - ya) / (yb - ya) * (xb - xa)
        if x0 <= xs < xt:
            cut.add((i, j))
    return cut


@pytest.mark.parametrize("layers", [0, 3])
def test_a_crack_between_two_node_rows_cuts_exactly_the_bonds_joining_its_sides(layers):
    """An edge crack along y = 5 h (between node rows 4 and 5) from x = 0 to its tip at
    x = 10 h, a lattice vertex: bonds through the tip point itself are kept, bonds
    through its start (the box's edge) cut; checked pair by pair against a loop."""
    box = _box()
    cracked = _cracked(box, Crack("crack", (0.0, 5 * H), (10 * H, 5 * H)))
    g0, s0, b0 = _models(box, layers)
    g1, s1, b1 = _models(cracked, layers)
    st = state_based_stencil(2, 3.0, H, INF, "partial-volume")
    a, b, _ = bond_pairs(g0.ext_shape, st.offsets[st.half])
    live = g0.is_interior[a] | g0.is_interior[b]
    cut = _brute_force_cut(g0, a[live], b[live], 5, 0, 10)
    # bonds through the tip point (10 h, 5 h) exist and are kept
    through_tip = [(i, j) for i, j in _pairs(s0)
                   if np.sum(g0.index[[i, j]], axis=0).tolist() == [19, 9]]
    assert through_tip and not set(through_tip) & cut
    assert len(cut) > 0
    for m0, m1 in ((s0, s1), (b0, b1)):
        assert _pairs(m0) - _pairs(m1) == cut & _pairs(m0)
        assert _pairs(m1) <= _pairs(m0)
        assert len(_pairs(m0)) - len(_pairs(m1)) == len(cut & _pairs(m0))
    print(f"layers={layers}: {len(_pairs(s0))} bonds, {len(cut & _pairs(s0))} cut, "
          f"{len(through_tip)} through the tip kept")


def test_the_conventions_at_the_tip_the_start_and_on_the_line():
    c = Crack("c", (0.0, 0.0), (1.0, 0.0))
    xa = np.array([[0.5, 1.0], [1.0, 1.0], [0.0, 1.0], [1.5, 1.0], [0.5, 0.0], [0.5, 0.0],
                   [0.5, 0.0], [-0.5, 1.0]])
    xb = np.array([[0.5, -1.0], [1.0, -1.0], [0.0, -1.0], [1.5, -1.0], [0.5, -1.0],
                   [0.5, 1.0], [0.7, 0.0], [-0.5, -1.0]])
    #        across, through tip, through start, ahead, on-line to -, on-line to +,
    #        along the line, behind the start
    assert c.cuts(xa, xb).tolist() == [True, False, True, False, True, False, False, False]
    assert c.cuts(xb, xa).tolist() == c.cuts(xa, xb).tolist()    # either direction
    assert c.side(np.array([[0.3, 0.0], [0.3, -1e-3], [2.0, 0.0]])).tolist() == [True, False, True]


# ------------------------------------------------------------------ symmetry
def _mirror_ids(g, axis):
    idx = g.index.copy()
    idx[:, axis] = g.nodes_per_axis[axis] - 1 - idx[:, axis]
    return g.ext_id(idx)


def _cut_set(g0, m0, m1):
    return {frozenset(p) for p in _pairs(m0) - _pairs(m1)}


def test_a_symmetric_centre_crack_cuts_a_mirror_symmetric_set_of_bonds():
    """A centre crack (two cracks from the box's centre, tips 6 h away) on the horizontal
    mid-line, between node rows: the cut set maps onto itself under both mirrors."""
    box = _box(0.5, 0.5)
    c = (0.25, 0.25)
    cracked = _cracked(box, Crack("right", c, (0.25 + 6 * H, 0.25)),
                       Crack("left", c, (0.25 - 6 * H, 0.25)))
    g0, s0, _ = _models(box, layers=3)
    _, s1, _ = _models(cracked, layers=3)
    cut = _cut_set(g0, s0, s1)
    assert len(cut) > 0
    for axis in (0, 1):
        mid = _mirror_ids(g0, axis)
        assert {frozenset(mid[list(p)].tolist()) for p in cut} == cut
    print(f"centre crack: {len(cut)} bonds cut")


def test_an_inclined_centre_crack_cuts_a_point_symmetric_set_of_bonds():
    """Two cracks from the centre at 30 degrees (tips 6 h away): the cut set maps onto
    itself under the half turn about the centre (the nodes' lattice is symmetric)."""
    box = _box(0.5, 0.5)
    c = np.array([0.25, 0.25])
    t = 6 * H * np.array([np.cos(np.pi / 6), np.sin(np.pi / 6)])
    cracked = _cracked(box, Crack("a", tuple(c), tuple(c + t)), Crack("b", tuple(c), tuple(c - t)))
    g0, s0, _ = _models(box, layers=0)
    _, s1, _ = _models(cracked, layers=0)
    cut = _cut_set(g0, s0, s1)
    turn = _mirror_ids(g0, 0)[_mirror_ids(g0, 1)]
    assert len(cut) > 0
    assert {frozenset(turn[list(p)].tolist()) for p in cut} == cut


# ------------------------------------------------------------------ faces
def test_the_faces_closest_points_normals_samples_and_nodes():
    box = _box(0.5, 0.5)
    start, tip = np.array([0.1, 0.1]), np.array([0.3, 0.2])
    cracked = _cracked(box, Crack("crack", tuple(start), tuple(tip)))
    assert cracked.part_names[-2:] == ("crack+", "crack-")
    e = (tip - start) / np.linalg.norm(tip - start)
    nu = np.array([-e[1], e[0]])                         # the left normal: the + side
    on = start + 0.4 * (tip - start)
    x = np.array([on + 0.01 * nu, on - 0.01 * nu, tip + 0.02 * e + 0.001 * nu,
                  tip + 0.02 * e - 0.001 * nu])
    p, n, dist, part = cracked.closest(x)
    names = [cracked.part_names[k] for k in part]
    assert names == ["crack+", "crack-", "crack+", "crack-"]
    # closed form: the projection onto the slit (the tip ahead of it), the outward normal
    # -nu on the + face, +nu on the - face; round-off of a few operations
    np.testing.assert_allclose(p, [on, on, tip, tip], rtol=0, atol=1e-15)
    np.testing.assert_allclose(n, [-nu, nu, -nu, nu], rtol=0, atol=1e-15)
    np.testing.assert_allclose(dist[:2], 0.01, rtol=1e-12)
    P, W, N, K = cracked.samples(H)
    for k, sign in ((4, -1), (5, 1)):
        # Gauss weights sum to the length: round-off of a few tens of terms
        assert abs(W[K == k].sum() - np.hypot(0.2, 0.1)) < 1e-14
        np.testing.assert_allclose(N[K == k], np.tile(sign * nu, ((K == k).sum(), 1)),
                                   atol=1e-15)
    # the nodes within a horizon on each side
    g = Body((0.5, 0.5), (0.0, 0.0), H, shape=cracked).grid(0)
    xr = g.x[g.interior_ids]
    crack = cracked.cracks[0]
    plus, minus = crack.near(xr, 3 * H)
    by_face = cracked.crack_nodes(xr, 3 * H)
    assert list(by_face) == ["crack+", "crack-"]
    assert np.array_equal(by_face["crack+"], plus) and np.array_equal(by_face["crack-"], minus)
    assert plus.any() and minus.any() and not (plus & minus).any()
    assert np.all(crack.side(xr[plus])) and not np.any(crack.side(xr[minus]))
    d = np.abs((xr - start) @ nu)
    ahead = (xr - start) @ e
    beside = (ahead >= 0) & (ahead <= np.linalg.norm(tip - start))
    # beside the slit the distance is the one to its line (closed form)
    assert np.array_equal((plus | minus)[beside], d[beside] <= 3 * H)


def test_a_grid_aligned_faces_samples_belong_to_the_node_rows_on_either_side():
    """The boundary nodes as plate-hole finds them (``boundary_nodes``: the node of the
    cell that holds each sample, moved inward): the row just above a crack between
    rows for ``crack+``, the row below for ``crack-``."""
    cracked = _cracked(_box(), Crack("crack", (0.0, 5 * H), (10 * H, 5 * H)))
    g = Body((0.5, 0.25), (0.0, 0.0), H, shape=cracked).grid(0)
    *_, part_of, node = boundary_nodes(g, cracked)
    xr = g.x[g.interior_ids]
    for name, y in (("crack+", 5.5 * H), ("crack-", 4.5 * H)):
        at = xr[node[part_of == cracked.part_names.index(name)]]
        assert np.allclose(at[:, 1], y)
        assert np.unique(at[:, 0]).tolist() == pytest.approx((np.arange(10) + 0.5) * H)


def test_a_crack_must_lie_inside_the_shape_and_have_its_own_name():
    with pytest.raises(ValueError, match="inside the shape"):
        _cracked(_box(), Crack("crack", (0.1, 0.1), (0.7, 0.1)))
    one = _cracked(_box(), Crack("crack", (0.1, 0.1), (0.2, 0.1)))
    with pytest.raises(ValueError, match="crack names must differ"):
        one.with_cracks(Crack("crack", (0.1, 0.2), (0.2, 0.2)))
    with pytest.raises(ValueError, match="part names must differ"):
        _cracked(_box(), Crack("y", (0.1, 0.1), (0.2, 0.1)), Crack("y+", (0.1, 0.2), (0.2, 0.2)))
    assert dataclasses.replace(one).parts == one.parts       # faces appended once


def test_the_uncorrected_model_of_a_centre_cracked_plate_opens_the_crack_symmetrically():
    """A square clamped at y = 0 and pulled on y = 0.5 m, with a centre crack on the
    mid-line between node rows (two cracks from the centre, tips 6 h away): the
    uncorrected state-based solve is mirror symmetric about x = 0.25 (u_x odd, u_y even)
    to round-off, and the faces open (the rows either side of the slit move apart more
    than without the crack)."""
    box = _box(0.5, 0.5)
    c = (0.25, 0.25)
    cracked = _cracked(box, Crack("right", c, (0.25 + 6 * H, 0.25)),
                       Crack("left", c, (0.25 - 6 * H, 0.25)))
    pull = FaceCondition(traction=lambda x, n: np.c_[np.zeros(len(x)), np.full(len(x), 1e6)])
    conds = {"y-": FaceCondition(prescribed=(0, 1)), "y+": pull}
    out = {}
    for key, shape in (("plain", box), ("cracked", cracked)):
        st = state_based_stencil(2, 3.0, H, INF, "partial-volume")
        problem = StaticProblem((0.5, 0.5), (0.0, 0.0), H, st, CONSTANTS, INF, conds,
                                exact=lambda x: np.zeros_like(x), solver="direct",
                                shape=shape)
        system = assemble_plain(problem)
        x = solve(system, where=key)[0]
        g = system.model.grid
        out[key] = (g, x[:2 * g.n_interior].reshape(2, -1).T)
    g, u = out["cracked"]
    real = g.index[g.interior_ids]
    mirror = real.copy()
    mirror[:, 0] = g.nodes_per_axis[0] - 1 - mirror[:, 0]
    m = g.interior_number[g.ext_id(mirror)]
    scale = np.abs(u).max()
    # round-off: machine epsilon times the condition of the free block of the augmented
    # K (1.53e9, computed densely at this size, unscaled), 3.4e-7 of max|u| (measured:
    # 6e-15)
    tol = np.finfo(float).eps * 1.53e9 * scale
    np.testing.assert_allclose(u[m, 0], -u[:, 0], rtol=0, atol=tol)
    np.testing.assert_allclose(u[m, 1], u[:, 1], rtol=0, atol=tol)
    col = (real[:, 0] == 9)                      # the column next to the centre
    above, below = col & (real[:, 1] == 10), col & (real[:, 1] == 9)
    opening = {k: (v[1][above, 1] - v[1][below, 1]).item() for k, v in out.items()}
    assert opening["cracked"] > 2 * opening["plain"] > 0
    print(f"opening at the centre: {opening['cracked']:.4g} m cracked, "
          f"{opening['plain']:.4g} m plain; mirror error "
          f"{np.abs(u[m, 0] + u[:, 0]).max() / scale:.2g} of max|u|")
