"""Elasticity helpers: patch tests, reactions, energy density, evaluation, VTU, independence."""
import subprocess
import sys
from pathlib import Path

import meshio
import numpy as np
import pytest

from reference_fem import FieldSolution, Material, TensorElasticity
from reference_fem.meshing import fine_then_geometric, power_graded, uniform

ROOT = Path(__file__).resolve().parents[2]
# Round-off bound for fields that lie in the Q2 space: the condensed systems here have
# condition numbers below ~1e6, so 1e-9 relative leaves three digits of margin over
# eps * cond (dolfinx-style exactness check).
EXACT_RTOL = 1e-9


def _linear_field(pts, A):
    return pts @ A.T


def _patch(mode, coords, A):
    """Impose u = A x on the whole boundary; the FEM must reproduce it everywhere."""
    dim = len(coords)
    mat = Material(1e9, 0.3, mode, 0.05)
    model = TensorElasticity(coords, mat)
    lo = np.array([c[0] for c in coords])
    hi = np.array([c[-1] for c in coords])
    tol = 1e-9

    def on_boundary(*x):
        return np.any([(x[k] < lo[k] + tol) | (x[k] > hi[k] - tol) for k in range(dim)], axis=0)

    fixed = model.dofs(on_boundary)
    exact = _linear_field(model.dof_coords.T, A)
    values = exact[np.arange(model.basis.N), model.dof_component]
    u = model.solve(np.zeros(model.basis.N), fixed, values[fixed])
    return model, u


@pytest.mark.parametrize("mode", ["plane_stress", "plane_strain"])
def test_patch_2d_graded_mesh_is_exact(mode, rng):
    coords = (power_graded(0, 1, 6, 2.0), fine_then_geometric(-1, 0, -0.3, 0, 0.1, 1.4))
    A = np.array([[1e-3, -2e-4], [5e-4, 2e-3]])
    model, u = _patch(mode, coords, A)
    fld = model.field(u)
    pts = rng.uniform([0, -1], [1, 0], size=(500, 2))
    np.testing.assert_allclose(fld.evaluate(pts), _linear_field(pts, A), rtol=0,
                               atol=EXACT_RTOL * np.abs(A).max())
    G = fld.gradient(pts)
    np.testing.assert_allclose(G, np.broadcast_to(A, G.shape), rtol=0,
                               atol=EXACT_RTOL * np.abs(A).max())
    # interior DOFs carry no force: K u - f vanishes off the boundary (f = 0)
    r = model.reactions(u)
    interior = model.dofs(lambda x, y: (x > 1e-9) & (x < 1 - 1e-9) & (y > -1 + 1e-9) & (y < -1e-9))
    assert np.abs(r[interior]).max() < EXACT_RTOL * np.abs(r).max()


def test_patch_3d_is_exact(rng):
    coords = (uniform(0, 1, 2), uniform(0, 0.5, 2), power_graded(0, 0.5, 2, 2.0))
    A = np.array([[1e-3, 2e-4, 0], [0, -3e-4, 1e-4], [2e-4, 0, 5e-4]])
    model, u = _patch("3d", coords, A)
    fld = model.field(u)
    pts = rng.uniform([0, 0, 0], [1, 0.5, 0.5], size=(200, 3))
    np.testing.assert_allclose(fld.evaluate(pts), _linear_field(pts, A), rtol=0,
                               atol=EXACT_RTOL * np.abs(A).max())


def test_uniaxial_reaction_energy_and_thickness_scaling():
    """Bar 2 x 1 m pulled by u = 1e-3 m at x = 2 with free lateral contraction (supports:
    u_x = 0 on x = 0, u_y = 0 at the origin). Closed form: reaction sigma A = E eps h W,
    energy density E eps^2 / 2."""
    E, eps, thick = 2e9, 5e-4, 0.05
    model = TensorElasticity((uniform(0, 2, 4), uniform(0, 1, 2)),
                             Material(E, 0.25, "plane_stress", thick))
    left = model.dofs(lambda x, y: x < 1e-9, [0])
    right = model.dofs(lambda x, y: x > 2 - 1e-9, [0])
    origin = model.dofs(lambda x, y: (x < 1e-9) & (y < 1e-9), [1])
    fixed = np.concatenate([left, right, origin])
    vals = np.concatenate([np.zeros(left.size), np.full(right.size, 2 * eps), [0.0]])
    u = model.solve(np.zeros(model.basis.N), fixed, vals)
    r = model.reactions(u)
    np.testing.assert_allclose(r[right].sum(), E * eps * thick * 1.0, rtol=EXACT_RTOL)
    np.testing.assert_allclose(r[left].sum(), -E * eps * thick * 1.0, rtol=EXACT_RTOL)
    fld = model.field(u)
    w = fld.strain_energy_density(np.array([[0.3, 0.4], [1.9, 0.9]]))
    np.testing.assert_allclose(w, 0.5 * E * eps ** 2, rtol=EXACT_RTOL)
    # total energy 1/2 u.K u = W * volume (2 m x 1 m x thickness)
    np.testing.assert_allclose(model.strain_energy(u), 0.5 * E * eps ** 2 * 2 * thick,
                               rtol=EXACT_RTOL)


def test_body_and_traction_loads_integrate_to_resultants():
    model = TensorElasticity((uniform(0, 3, 3), uniform(0, 2, 4)),
                             Material(1e9, 0.2, "plane_stress", 0.05))
    fb = model.body_load([1e6, -2e6])
    ix, iy = model.dofs(components=[0]), model.dofs(components=[1])
    # resultant = b * area * thickness (exact quadrature of a constant)
    np.testing.assert_allclose([fb[ix].sum(), fb[iy].sum()], [1e6 * 0.3, -2e6 * 0.3], rtol=1e-12)
    ft = model.traction_load(lambda x, y: x > 3 - 1e-9, [0.0, 5e5])
    np.testing.assert_allclose(ft[iy].sum(), 5e5 * 2 * 0.05, rtol=1e-12)


def test_outside_points_raise_clear_error():
    fld = FieldSolution(coords=(uniform(0, 1, 2), uniform(0, 2, 2)),
                        values=np.zeros((5, 5, 2)), lam=1.0, mu=1.0)
    pts = np.array([[0.5, 1.0], [1.0, 2.0], [1.2, 0.5], [0.0, -0.1], [0.0, 0.0]])
    message = r"2 of 5 points lie outside the domain .*first: \(1\.2, 0\.5\)"
    with pytest.raises(ValueError, match=message):
        fld.evaluate(pts)
    with pytest.raises(ValueError, match=r"shape \(n, 2\)"):
        fld.evaluate(np.zeros((3, 3)))
    # boundary points (PD surface nodes) are inside
    assert fld.evaluate(pts[[0, 1, 4]]).shape == (3, 2)


def test_vtu_export_roundtrip(tmp_path):
    model = TensorElasticity((uniform(0, 1, 2), uniform(0, 1, 3)), Material(1e9, 0.3))
    rng = np.random.default_rng(5)
    u = rng.normal(size=model.basis.N) * 1e-4
    fld = model.field(u)
    path = fld.to_vtu(tmp_path / "f.vtu")
    mesh = meshio.read(path)
    assert mesh.points.shape == (5 * 7, 3)
    assert mesh.cells_dict["quad"].shape == (4 * 6, 4)
    np.testing.assert_array_equal(mesh.point_data["displacement"][:, :2], fld.nodal_displacement())
    np.testing.assert_allclose(fld.evaluate(mesh.points[:, :2]), fld.nodal_displacement(),
                               rtol=0, atol=1e-15)


def test_material_validation():
    with pytest.raises(ValueError, match="mode"):
        Material(1e9, 0.3, "axisymmetric")
    with pytest.raises(ValueError, match="nu"):
        Material(1e9, 0.5, "plane_strain")
    with pytest.raises(ValueError, match="needs 3"):
        TensorElasticity((uniform(0, 1, 2), uniform(0, 1, 2)), Material(1e9, 0.3, "3d"))


def test_reference_side_never_imports_pdverify():
    """DESIGN.md: the reference side never imports the PD side."""
    code = ("import sys, reference_fem, reference_fem.indentation; "
            "assert not any(m.split('.')[0] == 'pdverify' for m in sys.modules), 'imported'")
    subprocess.run([sys.executable, "-c", code], cwd=ROOT, check=True, timeout=60)
    for path in (ROOT / "reference_fem").glob("*.py"):
        text = path.read_text()
        assert "import pdverify" not in text and "from pdverify" not in text, path.name
