"""The bond-based static description (pdverify.pd.problem.BondProblem) and its generic
assembly: conditions keyed by named parts become the system's loads and prescribed
unknowns, whichever treatment assembles it."""
import numpy as np
import pytest

from pdverify.pd import build_stencil, get_influence
from pdverify.pd.build import Body, BondMaterial
from pdverify.pd.problem import BondProblem, PartCondition, assemble_bonds
from pdverify.scenes import get_scene


def _sheet(conditions, parts=None):
    return BondProblem(Body((0.02, 0.01), (0.0, 0.0), 0.0025, placement="on-surface"),
                       build_stencil(2, 3.0), BondMaterial(1.0, get_influence("constant")),
                       0.0075, conditions, 1.0, 1 / 3, "plane-stress", parts=parts or {})


def test_a_condition_names_a_face_or_a_declared_part():
    with pytest.raises(ValueError, match="part"):
        _sheet({"middle": PartCondition({0: 0.0})})
    with pytest.raises(ValueError, match="part"):        # 2D: no z faces
        _sheet({"z-": PartCondition({0: 0.0})})


def test_faces_and_scene_parts_become_prescribed_unknowns_and_loads():
    line = {"mid": lambda x: np.isclose(x[:, 0], 0.01)}
    system = assemble_bonds(_sheet(
        {"x-": PartCondition({0: 0.0, 1: 0.5}), "mid": PartCondition({1: -0.25}),
         "y+": PartCondition(force=lambda x: np.tile([0.0, 2.0], (len(x), 1)))}, line))
    g = system.model.grid
    n, x = g.n_ext, g.x
    left = np.flatnonzero(np.isclose(x[:, 0], 0.0))
    mid = np.flatnonzero(np.isclose(x[:, 0], 0.01))
    top = np.flatnonzero(np.isclose(x[:, 1], 0.01))
    assert left.size == mid.size == 5 and top.size == 9
    np.testing.assert_array_equal(system.parts["x-"], left)
    np.testing.assert_array_equal(system.parts["mid"], mid)
    fixed = dict(zip(system.fixed.tolist(), system.values.tolist()))
    assert fixed == {**{int(i): 0.0 for i in left}, **{int(n + i): 0.5 for i in left},
                     **{int(n + i): -0.25 for i in mid}}
    expected = np.zeros(2 * n)
    expected[n + top] = 2.0
    np.testing.assert_array_equal(system.rhs, expected)


def test_virtual_nodes_bring_their_own_clamp_nodes_for_the_clamped_faces():
    # the clamped sheet's description names its faces y- and y+; under virtual nodes
    # (their clamped-sheet role) those parts are the buffer layers beyond the faces, under
    # the baseline the outermost rows of the on-surface grid
    scene = get_scene("sheet2d-clamped")
    p = scene.resolve("virtual-nodes")
    _, own = scene.bond_system("virtual-nodes", p, "test")
    L = p["side_factor"] * p["horizon"]
    y = own.model.grid.x[:, 1]
    assert np.all(y[own.parts["y+"]] > L / 2) and np.all(y[own.parts["y-"]] < -L / 2)
    _, base = scene.bond_system("none", scene.resolve("none"), "test")
    yb = base.model.grid.x[:, 1]
    # cell centres at L/2 ~ 1e-2 m, one rounding of a sum: a few ulp of it (eps 2.2e-16)
    np.testing.assert_allclose(yb[base.parts["y+"]], L / 2, rtol=0, atol=1e-15)
