"""Seed 000 §6.1: the Taylor fictitious closure in 2D (and 3D) is exact for polynomials of
degree <= n, and the corrected plate recovers a discrete manufactured solution (issue 15)."""
from dataclasses import replace

import numpy as np
import pytest
import scipy.sparse as sp

from pdverify.corrections.taylor import monomial_exponents
from pdverify.corrections.taylor_fictitious import (assemble_taylor, clamped_rows,
                                                    extrapolation_map)
from pdverify.errors import NumericalError
from pdverify.pd import BoxGrid, StateBasedConstants
from pdverify.pd.problem import FACES, FaceCondition
from pdverify.scenes.plate2d import ORDERING
from pdverify.solvers.front import solve
from descriptions import box_problem

EPS = np.finfo(float).eps


def random_polynomial(dim, degree, rng, components=2):
    """A vector field whose components are random polynomials of total degree ``degree``."""
    exps = np.vstack([np.zeros((1, dim), int), monomial_exponents(dim, degree)])
    coef = rng.normal(size=(components, exps.shape[0]))

    def field(x):
        mono = np.prod(np.asarray(x, float)[:, None, :] ** exps[None], axis=2)
        return mono @ coef.T
    return field


def _amp(A):
    return np.abs(A).sum(axis=1).max()


@pytest.mark.parametrize("dim, lengths, order", [
    (2, (1.0, 0.7), 1), (2, (1.0, 0.7), 2), (2, (1.0, 0.7), 3), (2, (1.0, 0.7), 4),
    (3, (0.5, 0.4, 0.4), 2)])
def test_extrapolation_reproduces_degree_n_at_edges_and_corners(dim, lengths, order, rng):
    # seed 000 §6.1 / Eq. (69): 1D series along the normal on edges, the d-D series about
    # the corner node with lattice finite differences at corners; both exact for degree
    # <= n. Tolerance: eps x the map's amplification (sum of |weights|) x the field size.
    g = BoxGrid(lengths, (0.0,) * dim, 0.1, layers=3)
    A = extrapolation_map(g, order)
    corner = np.sum((g.index < 0) | (g.index >= np.asarray(g.nodes_per_axis)), axis=1) >= 2
    assert corner.any()
    for degree in range(order + 1):
        u = random_polynomial(dim, degree, rng, 1)(g.x)[:, 0]
        got = A @ u[g.interior_ids]
        np.testing.assert_allclose(got, u, rtol=0, atol=50 * EPS * _amp(A) * np.abs(u).max())
    u = g.x[:, 0] ** (order + 1) + g.x[:, 1] ** (order + 1)
    miss = np.abs(A @ u[g.interior_ids] - u)
    # and not beyond n: a miss 1e8 x above the round-off bound above (field size ~1)
    assert miss[corner].max() > 1e-8 and miss[~corner].max() > 1e-8


@pytest.mark.parametrize("order", [1, 2, 3])
def test_clamped_rows_give_boundary_values(order, rng):
    # Eq. (58) on every line perpendicular to an edge: B u = u at the boundary point
    g = BoxGrid((1.0, 0.7), (0.0, 0.0), 0.1, layers=3)
    B, pts, comp = clamped_rows(g, order, FACES[:4])
    field = random_polynomial(2, order, rng)
    u = field(g.x[g.interior_ids])
    got = B @ u.T.ravel()
    want = field(pts)[np.arange(pts.shape[0]), comp]
    np.testing.assert_allclose(got, want, rtol=0, atol=50 * EPS * _amp(B) * np.abs(u).max())
    # Remark 4: the tangential component is left free on the 8 lines through the corners
    assert B.shape[0] == 2 * (2 * 10 + 2 * 7) - 8


def _plate(order, field=np.zeros_like, corners="normal-only", spacing=0.1):
    """Seed 000's plate clamped all round, described (its edges by name, the prescribed
    values ``field``) and assembled by ``taylor-fictitious`` (Eq. 58's rows as constraints
    B x = c); the tests set the loads."""
    c = StateBasedConstants("plane-stress", 1e9, 0.2)
    clamped = FaceCondition(prescribed=(0, 1))
    problem = box_problem((1.2, 0.8), (0.0, 0.0), spacing, 3.0, c, influence="hyperbolic",
                          conditions={face: clamped for face in FACES[:4]}, exact=field,
                          solver="direct", thickness=0.05)
    return assemble_taylor(problem, order, corners)


def rows_of_state(system, field):
    """K u for the exact field at every node (fictitious included), dilatations of
    complete neighbourhoods: the discrete operator applied to the field itself."""
    m = system.model
    x = m.grid.x
    return m.rows_of_state(field(x), m.dilatation_of_field(field, x))


def solved(system, f):
    """The real nodes' displacements (n, 2) with K u = f and the constraint rows."""
    f = np.r_[f, np.zeros(system.K.shape[0] - np.size(f))]    # the scalars' rows: zero
    x, info = solve(replace(system, rhs=f), where="plate", ordering=ORDERING)
    return x[:system.dofs].reshape(2, -1).T, info


def real_x(system):
    g = system.model.grid
    return g.x[g.interior_ids]


@pytest.mark.parametrize("order", [1, 2, 3])
def test_manufactured_polynomial_is_recovered_to_round_off(order, rng):
    # issue 15, Must show: body forces = the discrete operator applied to a polynomial of
    # degree <= n at every node (fictitious ones included, exact dilatations); boundary
    # values = the polynomial at the constrained boundary points. The order-n model must
    # return the polynomial: exact extrapolation at edges and corners and exact Eq. (58)
    # rows. Tolerance: the solver's backward error (relative residual, ~eps) times its
    # condition estimate bounds the forward error; a factor 100 covers the norm change.
    for degree in range(1, order + 1):
        field = random_polynomial(2, degree, rng)
        plate = _plate(order, field)
        u, info = solved(plate, rows_of_state(plate, field))
        want = field(real_x(plate))
        err = np.abs(u - want).max() / np.abs(want).max()
        assert err < 100 * EPS * info["condition_estimate"], (degree, err)
        assert err < 1e-10   # and absolutely: cond ~1e3 here, so ~1e-11 at most
    # degree n + 1 is not recovered: the test can fail
    field = random_polynomial(2, order + 1, rng)
    plate = _plate(order, field)
    u, _ = solved(plate, rows_of_state(plate, field))
    want = field(real_x(plate))
    # 1e4 x the round-off bound: a real miss, not noise
    assert np.abs(u - want).max() / np.abs(want).max() > 1e-6


def test_both_components_on_corner_lines_over_constrain():
    # Remark 4: constraining u and v on both lines through a corner node over-constrains
    # it; the Lagrange system is then exactly singular, and the run says so
    plate = _plate(1, corners="both")
    f = np.ones(2 * real_x(plate).shape[0])
    with pytest.raises(NumericalError, match="singular"):
        solved(plate, f)
    assert sp.linalg.norm(plate.B) > 0
