"""3D FEM references of issue 55 (reference_fem.solid3d_refs): the cylinder's closed form
to round-off, the field's evaluation and cache round trip, the cavity's refinement and
Goodier's concentration."""
import numpy as np
import pytest

from reference_fem import results
from reference_fem.solid3d import TetField
from reference_fem.solid3d_refs import (CavityParams, CylinderParams, cavity_mesh,
                                        compute_cylinder, cylinder_closed_form,
                                        goodier_scf, large_block_check, solve_cylinder)


def test_the_cylinder_reproduces_the_uniaxial_closed_form_to_round_off():
    """u = (-nu sigma x, -nu sigma y, sigma z) / E is in the P2 span and meets every
    condition of the faceted quarter cylinder exactly: the FEM's error is round-off,
    1e-12 of max |u| bounds it (condition ~1e4 times eps ~1e-16, with margin)."""
    p = CylinderParams()
    model, fld, _, _ = solve_cylinder(p, 1)
    x = np.concatenate([fld.node_coords, np.random.default_rng(0).random((200, 3))
                        * [0.35, 0.35, 1.0]])
    exact = cylinder_closed_form(x, p.E, p.nu, p.traction)
    assert np.max(np.abs(fld.evaluate(x) - exact)) < 1e-12 * np.max(np.abs(exact))
    # the stress is uniaxial: sigma_zz = sigma, the rest round-off
    s = fld.stress(x[:50])
    np.testing.assert_allclose(s[:, 2, 2], p.traction, rtol=1e-10)
    assert np.max(np.abs(s[:, :2, :])) < 1e-8 * p.traction


def test_a_wrong_load_is_seen_by_the_closed_form_check():
    """The check can fail: a traction 1 % too large gives a 1 % error."""
    p = CylinderParams(traction=1.01e6)
    _, fld, _, _ = solve_cylinder(p, 1)
    exact = cylinder_closed_form(fld.node_coords, 1e9, 0.3, 1e6)
    err = np.max(np.abs(fld.values - exact)) / np.max(np.abs(exact))
    assert abs(err - 0.01) < 1e-9


def test_the_tet_field_survives_the_cache_round_trip(tmp_path):
    res = compute_cylinder(CylinderParams(levels=1))
    assert res.closed_form_error_pct < 1e-10
    path = tmp_path / "r.npz"
    results.to_npz(res, path)
    back = results.from_npz(path, {"CylinderResult": type(res)})
    assert isinstance(back.field, TetField)
    x = np.array([[0.1, 0.2, 0.3], [0.49 / np.sqrt(2), 0.49 / np.sqrt(2), 0.9]])
    np.testing.assert_array_equal(back.evaluate(x), res.evaluate(x))


def test_the_cavity_mesh_is_conforming_and_meets_the_sphere():
    """Every vertex on r = a lies on it to round-off; the 24-split is conforming (every
    interior triangle is shared by exactly two tetrahedra, a boundary one by one, and
    the boundary triangles' area sums to the octant's faces plus the faceted sphere)."""
    P, T = cavity_mesh(1.0, 0.3, 2)
    r = np.linalg.norm(P, axis=0)
    near = np.abs(r - 0.3) < 1e-6
    assert np.all(np.abs(r[near] - 0.3) < 1e-15)
    faces = np.sort(np.concatenate([T[[0, 1, 2]], T[[0, 1, 3]], T[[0, 2, 3]],
                                    T[[1, 2, 3]]], axis=1), axis=0)
    _, count = np.unique(faces, axis=1, return_counts=True)
    assert set(count) == {1, 2}
    X = P[:, T]
    vol = np.einsum("ij,ij->j", np.cross(X[:, 1] - X[:, 0], X[:, 2] - X[:, 0], axis=0),
                    X[:, 3] - X[:, 0]) / 6
    assert np.all(vol > 0)
    # the volume: the octant less the ball's octant, short of it by the facets' O(h^2)
    exact = 1.0 - np.pi * 0.3 ** 3 / 6
    assert 0 < vol.sum() - exact < 0.3 ** 3 * np.pi / 6 * 0.1


@pytest.mark.slow   # three solves of a W / a = 8 block: ~15 s on 2 cores under load
def test_a_large_block_approaches_goodier_by_richardson_extrapolation():
    """Goodier's (27 - 15 nu) / (2 (7 - 5 nu)) for the infinite body. The faceted sphere
    makes the equator stress converge at O(h^2) (measured ratios of the errors 1.95 per
    step at n = 2, 3, 4); Richardson at that rate from successive pairs gives two
    extrapolants, and the later one must lie within their difference of Goodier (the
    standard error estimate of an extrapolant; the finite block's O((a/W)^3) = 0.2 % is
    inside it)."""
    out = large_block_check(width_ratio=8.0, cells=(2, 3, 4))
    s2, s3, s4 = out["scf"]
    r23 = (9 * s3 - 4 * s2) / 5
    r34 = (16 * s4 - 9 * s3) / 7
    assert out["goodier"] == goodier_scf(0.3)
    assert abs(r34 - out["goodier"]) < abs(r34 - r23)
    assert s2 < s3 < s4 < out["goodier"]          # from below, monotonically


def test_bad_parameters_are_refused_in_one_line():
    with pytest.raises(ValueError, match="at most 6 cells per block edge"):
        CavityParams(cells=4, levels=4)
    with pytest.raises(ValueError, match="nu must lie"):
        CylinderParams(nu=0.5)
