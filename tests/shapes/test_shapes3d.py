"""3D shapes (issue 55): closest points on the surface to round-off, unit outward normals,
signed distance, cut-cell volumes to their stated accuracy, surface samples that
integrate each part's area."""
import numpy as np
import pytest

from pdverify.pd.shapes3d import FRACTION_SAMPLES, cavity_octant, quarter_cylinder

SHAPES = {"cylinder": lambda: quarter_cylinder(0.5, 1.0),
          "cavity": lambda: cavity_octant(1.0, 0.3)}


def _points(shape, n=4000, seed=0):
    rng = np.random.default_rng(seed)
    lo, hi = np.asarray(shape.lower), np.asarray(shape.upper)
    return lo - 0.2 + rng.random((n, 3)) * (hi - lo + 0.4)


def _on_part(shape, k, p):
    """How far each point p is from part k's surface (its defining equation), and
    whether it lies within its extent (to round-off)."""
    q = shape.parts[k]
    name = q.name
    if name == "mantle":
        return np.abs(np.hypot(p[:, 0], p[:, 1]) - q.radius)
    if name == "cavity":
        return np.abs(np.linalg.norm(p, axis=1) - q.radius)
    o, n = np.asarray(q.origin), np.asarray(q.normal)
    return np.abs((p - o) @ n)


@pytest.mark.parametrize("which", SHAPES)
def test_closest_points_lie_on_the_surface_and_normals_are_unit_and_outward(which):
    s = SHAPES[which]()
    x = _points(s)
    p, n, dist, part = s.closest(x)
    # on the part's surface: round-off of the projection (a few ulp of the size 1)
    for k in range(len(s.parts)):
        on = part == k
        assert np.all(_on_part(s, k, p[on]) < 1e-14), s.parts[k].name
    # every closest point lies on the body's closure: 1e-9 toward a point the whole
    # surface sees from inside (both bodies are star-shaped about it) is inside
    c = 0.4 * np.asarray(s.upper)
    assert s.inside(p + 1e-9 * (c - p)).all()
    np.testing.assert_allclose(np.linalg.norm(n, axis=1), 1.0, rtol=0, atol=1e-15)
    # outward: a step along n from the closest point leaves the body, against n enters
    # (away from edges, where the step could cross another part: 1e-6 of the size)
    step = 1e-6
    assert not s.inside(p + step * n).any()
    interior = dist > 0
    assert np.all(np.linalg.norm(x - p, axis=1) == dist)
    # the closest point is no farther than any of the other parts' closest points
    for q in s.parts:
        pq, _ = q.closest(x)
        assert np.all(dist <= np.linalg.norm(x - pq, axis=1) + 1e-15)
    sd = s.sdf(x)
    assert np.all((sd < 0) == s.inside(x)) and np.all(np.abs(sd) == dist)
    assert interior.any()


def test_closest_points_closed_forms():
    c = quarter_cylinder(0.5, 1.0)
    x = np.array([[0.3, 0.2, 0.5], [0.6, 0.0, 0.5], [0.1, 0.1, 0.98]])
    p, n, d, part = c.closest(x)
    names = [c.part_names[k] for k in part]
    assert names == ["mantle", "mantle", "top"]
    r = np.hypot(0.3, 0.2)
    np.testing.assert_allclose(p[0], [0.3 / r * 0.5, 0.2 / r * 0.5, 0.5], rtol=1e-15)
    np.testing.assert_allclose(d[:2], [0.5 - r, 0.1], rtol=1e-14)
    b = cavity_octant(1.0, 0.3)
    x = np.array([[0.2, 0.1, 0.1], [0.0005, 0.2, 0.3]])
    p, n, d, part = b.closest(x)
    assert [b.part_names[k] for k in part] == ["cavity", "x-"]
    np.testing.assert_allclose(n[0], -x[0] / np.linalg.norm(x[0]), rtol=1e-15)
    np.testing.assert_allclose(d[0], 0.3 - np.linalg.norm(x[0]), rtol=1e-14)
    # a point of the symmetry plane inside the quarter disk: pushed out radially
    q = b.parts[b.part_names.index("x-")]
    pp, _ = q.closest(np.array([[0.1, 0.1, 0.1]]))
    np.testing.assert_allclose(pp[0], [0.0, 0.3 / np.sqrt(2), 0.3 / np.sqrt(2)], rtol=1e-15)


@pytest.mark.parametrize("which,volume", [
    ("cylinder", np.pi * 0.25 / 4 * 1.0),
    ("cavity", 1.0 - np.pi * 0.3 ** 3 / 6)])
def test_cut_cell_volumes_add_up_to_the_volume_within_the_stated_bound(which, volume):
    s = SHAPES[which]()
    h = 1 / 16
    lo, hi = np.asarray(s.lower), np.asarray(s.upper)
    n = np.round((hi - lo) / h).astype(int)
    idx = np.indices(n).reshape(3, -1).T
    centres = lo + (idx + 0.5) * h
    f = s.fractions(centres, h)
    assert np.all((f >= 0) & (f <= 1))
    err = abs(f.sum() * h ** 3 - volume)
    # stated accuracy (module docstring): sqrt(3) A h / s, A the area of the curved
    # parts (the plane parts lie on cell faces here: exact); measured 3.7e-4 (cylinder),
    # 1.2e-5 (cavity) against bounds of 1.1e-2 and 5.3e-3: the midpoint errors cancel
    curved = sum(q.area for q in s.parts if not q.straight)
    bound = np.sqrt(3) * curved * h / FRACTION_SAMPLES
    assert err < bound, (err, bound)
    # the bound is not vacuous: it is below the volume of one layer of cells over A
    assert bound < curved * h


@pytest.mark.parametrize("which", SHAPES)
def test_samples_integrate_each_part_area(which):
    s = SHAPES[which]()
    P, W, N, part = s.samples(0.05)
    for k, q in enumerate(s.parts):
        on = part == k
        # 3-point Gauss per patch integrates the polar/spherical Jacobians (smooth,
        # analytic) to far below 1e-8 of the area at 4 patches per spacing; round-off
        # of a few thousand terms otherwise
        assert abs(W[on].sum() - q.area) < 1e-8 * q.area, q.name
        assert np.all(_on_part(s, k, P[on]) < 1e-14)
    np.testing.assert_allclose(np.linalg.norm(N, axis=1), 1.0, atol=1e-15)


def test_a_segment_through_the_cavity_is_hidden_and_none_in_the_cylinder():
    """``Shape3D.hides``: from a real node above the cavity's pole the rim point of the
    x- plane's disk is seen only through the cavity (hidden); a point of the same plane
    beside the node, a point of the outer face, and any boundary point of the convex
    quarter cylinder are seen (the crossing at p itself does not count)."""
    import numpy as np

    from pdverify.pd.shapes3d import cavity_octant, quarter_cylinder
    cav = cavity_octant(1.0, 0.3)
    names = cav.part_names
    x = np.array([[0.05, 0.05, 0.35]] * 3)
    r = 0.3 / np.sqrt(2)
    p = np.array([[0.0, r, r], [0.0, 0.05, 0.35], [1.0, 0.05, 0.35]])
    part = np.array([names.index("x-"), names.index("x-"), names.index("x+")])
    assert cav.hides(x, p, part).tolist() == [True, False, False]
    cyl = quarter_cylinder(0.5, 1.0)
    rng = np.random.default_rng(0)
    inner = rng.uniform([0.0, 0.0, 0.0], [0.35, 0.35, 1.0], size=(200, 3))
    P, _, _, k = cyl.closest(rng.uniform(-0.2, 1.2, size=(200, 3)))
    assert not cyl.hides(inner, P, k).any()
