"""Taylor extrapolation (seed 000 Eqs. 42-47): exact for polynomials of degree <= n."""
import numpy as np
import pytest

from pdverify.corrections.taylor import taylor_extrapolation_weights
from pdverify.corrections.taylor_fictitious import boundary_value_rows
from descriptions import bar_system

EPS = np.finfo(float).eps


@pytest.mark.parametrize("order", [1, 2, 3, 4, 5])
def test_fictitious_displacements_reproduce_polynomials(order, rng):
    # seed 000 §3: a Taylor series of order n is exact for degree <= n. Tolerance:
    # eps times the extrapolation amplification ||W||_inf (sum of |weights|) times the
    # size of the field, the round-off of evaluating W @ u.
    bar = bar_system("taylor-fictitious", order=order).model
    A_U = bar.A_U.toarray()
    amp = np.abs(A_U).sum(axis=1).max()
    for _ in range(3):
        for degree in range(order + 1):
            coef = rng.normal(size=degree + 1)
            u_all = np.polyval(coef, bar.grid.x[:, 0])
            got = A_U @ u_all[bar.grid.interior_ids]
            np.testing.assert_allclose(got, u_all, rtol=0,
                                       atol=50 * EPS * amp * np.abs(u_all).max())
    # and not beyond its order: degree n + 1 is not reproduced
    u_all = bar.grid.x[:, 0] ** (order + 1)
    assert np.abs(A_U @ u_all[bar.grid.interior_ids] - u_all).max() > 1e-8 * np.abs(u_all).max()


@pytest.mark.parametrize("order", [1, 2, 3, 4, 5])
def test_fictitious_dilatations_reproduce_degree_n_minus_1(order, rng):
    # seed 000 Eq. (47): dilatations are extrapolated with order n - 1.
    bar = bar_system("taylor-fictitious", order=order).model
    A = bar.A_Theta.toarray()
    amp = np.abs(A).sum(axis=1).max()
    coef = rng.normal(size=order)
    th = np.polyval(coef, bar.grid.x[:, 0])
    np.testing.assert_allclose(A @ th[bar.grid.interior_ids], th, rtol=0, atol=50 * EPS * amp * np.abs(th).max())


@pytest.mark.parametrize("order", [1, 3, 5])
def test_boundary_value_row_is_exact(order, rng):
    # seed 000 Eq. (58): the Dirichlet row extrapolates u to x = 0 exactly for degree <= n.
    g = bar_system("taylor-fictitious", order=order).model.grid
    coef = rng.normal(size=order + 1)
    for face, point in (("x-", 0.0), ("x+", 1.0)):
        row = boundary_value_rows(g, order, face)[0].toarray()[0]
        got = row @ np.polyval(coef, g.x[g.interior_ids, 0])
        assert got == pytest.approx(np.polyval(coef, point),
                                    abs=50 * EPS * np.abs(row).sum() * np.abs(coef).sum())


def test_weights_match_equation_49():
    # seed 000 Eq. (49): linear extrapolation to x_f from nodes 1 and 2.
    x1, x2, xf = 0.025, 0.075, -0.125
    w = taylor_extrapolation_weights([x1, x2], [xf], 1, anchor=x1, scale=0.05)[0]
    np.testing.assert_allclose(w, [-(xf - x2) / (x2 - x1), (xf - x1) / (x2 - x1)], rtol=1e-14)
