"""block2d-indentation FEM: the half model (x >= 0, u_x = 0 on the axis) equals the full
block, and the Newton with a kept factorisation the plain one (issue 32)."""
import numpy as np
import pytest

from reference_fem.indentation import (NEWTON_RTOL, IndentationParams, mesh_coordinates,
                                       solve_level, solve_level_finite)

#: a short run on the coarsest mesh: 5 output depths to full depth, several catches each
SHORT = dict(n_steps=5, substeps=2)


def _same_block(full, half, rtol):
    np.testing.assert_allclose(half["forces"], full["forces"], rtol=rtol, atol=0)
    np.testing.assert_array_equal(half["counts"], full["counts"])
    scale = full["widths"][-1]
    np.testing.assert_allclose(half["widths"], full["widths"], rtol=0, atol=rtol * scale)
    np.testing.assert_allclose(half["bottom_reaction"], full["bottom_reaction"], rtol=rtol)
    np.testing.assert_allclose(half["contact_x"], np.sort(full["contact_x"]), rtol=0,
                               atol=rtol * scale)
    u_scale = np.abs(full["field"].values).max()
    np.testing.assert_array_equal(half["field"].coords[0], full["field"].coords[0])
    np.testing.assert_allclose(half["field"].values, full["field"].values, rtol=0,
                               atol=rtol * u_scale)


def test_mesh_is_symmetric_about_the_axis():
    for level in range(3):
        xs, _ = mesh_coordinates(IndentationParams(), level)
        c = xs.size // 2
        assert xs.size % 2 == 1 and xs[c] == 0.0
        # the graded line is built from both ends the same way: mirror images to round-off
        np.testing.assert_allclose(-xs[::-1], xs, rtol=0, atol=4 * np.finfo(float).eps * xs[-1])


def test_half_model_equals_full_small_strain():
    full = solve_level(IndentationParams(symmetry="full", **SHORT), 0, check_steps=True)
    half = solve_level(IndentationParams(symmetry="half", **SHORT), 0, check_steps=True)
    assert half["model"].basis.N < 0.6 * full["model"].basis.N
    # two different linear systems solved by LU: round-off amplified by the condition
    # number of K (measured 3e-14 on the forces; 1e-10 leaves a factor of 3000)
    _same_block(full, half, rtol=1e-10)
    np.testing.assert_allclose(half["step_change_pct"], full["step_change_pct"], rtol=1e-8)


def test_half_model_equals_full_finite_strain():
    kw = dict(kinematics="finite", **SHORT)
    full = solve_level_finite(IndentationParams(symmetry="full", **kw), 0, newton="plain")
    half = solve_level_finite(IndentationParams(symmetry="half", **kw), 0, newton="plain")
    # the same Newton iterates on the two models: round-off as above (measured 2e-15 at
    # the default 80 increments)
    _same_block(full, half, rtol=1e-10)
    assert half["n_solves"] == full["n_solves"]
    np.testing.assert_allclose(half["min_jacobian"], full["min_jacobian"], rtol=1e-12)


def test_kept_factorisation_converges_to_the_same_curve():
    kw = dict(kinematics="finite", **SHORT)
    plain = solve_level_finite(IndentationParams(symmetry="half", **kw), 0, newton="plain")
    reuse = solve_level_finite(IndentationParams(symmetry="half", **kw), 0, newton="reuse")
    # both stop at a free residual below NEWTON_RTOL of the force scale: the curves agree
    # to that order; 1000 NEWTON_RTOL leaves room for the stiffness's amplification of a
    # residual (measured 3.4e-11 at the default 80 increments)
    _same_block(plain, reuse, rtol=1e3 * NEWTON_RTOL)
    # the kept factorisation is used: plain Newton factorises at every iterate, the other
    # at least once per change of the stuck set (measured 17 and 56 here)
    assert reuse["n_factorisations"] < plain["n_factorisations"] == plain["n_solves"]


def test_symmetry_and_newton_are_checked():
    with pytest.raises(ValueError, match="symmetry must be one of half, full, got 'left'"):
        IndentationParams(symmetry="left")
    with pytest.raises(ValueError, match="newton must be one of reuse, plain, got 'x'"):
        solve_level_finite(IndentationParams(kinematics="finite"), 0, newton="x")
