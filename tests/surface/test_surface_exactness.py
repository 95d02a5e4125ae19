"""Surface node method: the discrete pipeline recovers polynomial fields of degree <= N.

Discrete manufactured solution: body forces and surface loads are the discrete operator
applied to the exact field at every node (fictitious nodes included, their dilatations
from complete neighbourhoods), so the solve must return the field to round-off when the
Taylor extrapolation of order N (displacements) and N - 1 (dilatations) is exact.
"""

import numpy as np
import pytest

from pdverify.corrections.surface_nodes import surface_node_model
from pdverify.corrections.taylor import monomial_exponents
from pdverify.pd import StateBasedConstants
from pdverify.solvers.front import solve_with_dirichlet
from descriptions import box_problem

EPS = np.finfo(float).eps


def surface_box(lengths, origin, h, m_ratio, c, order):
    """``(model, P)`` of the surface node method of ``order`` on a box described with no
    conditions (gaussian influence, partial volumes): the tests impose their own."""
    return surface_node_model(box_problem(lengths, origin, h, m_ratio, c), order)


def _poly_field(rng, dim, degree, scale):
    """Random vector polynomial of total degree <= degree (coefficients ~ scale)."""
    exps = np.vstack([np.zeros((1, dim), dtype=int), monomial_exponents(dim, degree)])
    coef = rng.uniform(-1, 1, size=(exps.shape[0], dim)) * scale

    def u(x):
        x = np.asarray(x, dtype=float)
        mono = np.prod(x[..., None, :] ** exps, axis=-1)
        return mono @ coef
    return u


CASES = [("plane-strain", (0.4, 0.3), (0.0, 0.0), 0.05, n) for n in (1, 2, 3)] + \
        [("3d", (0.4, 0.3, 0.3), (0.0, -0.15, -0.15), 0.05, n) for n in (1, 2, 3)]


@pytest.mark.parametrize("kind,lengths,origin,h,order", CASES)
def test_polynomial_field_recovered_to_round_off(rng, kind, lengths, origin, h, order):
    c = StateBasedConstants(kind, 200e9, 0.3)
    model, P = surface_box(lengths, origin, h, 3.0, c, order)
    g = model.grid
    d, ni, nu_ = g.dim, g.n_interior, model.n_unknown_nodes
    u = _poly_field(rng, d, order, 1e-3)
    U = u(g.x)
    theta = model.dilatation_of_field(u, g.x)
    rhs = model.rows_of_state(U, theta, P)         # loads = discrete operator of the field
    exact = np.concatenate([U[g.interior_ids], u(g.surface_x)]).T.ravel()
    # Dirichlet on the surface nodes of face 0 (all components), force flux elsewhere
    s0 = np.flatnonzero(g.surface_face == 0)
    fixed = np.sort(np.concatenate([k * nu_ + ni + s0 for k in range(d)]))
    sol, info = solve_with_dirichlet(model.stiffness(P), rhs, fixed, exact[fixed], where="exactness")
    err = np.linalg.norm(sol - exact) / np.linalg.norm(exact)
    # forward error <= cond * eps times a modest factor for the size of the system
    # (LU backward error ~ n^(1/2) eps in practice; we allow 10 * sqrt(n))
    bound = 10 * np.sqrt(sol.size) * info["condition_estimate"] * EPS
    assert err < bound, (err, bound, info)
    assert err < 1e-8  # and, independently, far below any discretisation error


def test_extrapolation_is_exact_for_degree_n_only(rng):
    """Order N reproduces degree N in the fictitious layer, not degree N + 1."""
    c = StateBasedConstants("plane-strain", 200e9, 0.3)
    for order in (1, 2, 3):
        model, _ = surface_box((0.4, 0.3), (0.0, 0.0), 0.05, 3.0, c, order)
        g = model.grid
        fict = ~g.is_interior
        for degree, exact in ((order, True), (order + 1, False)):
            u = _poly_field(rng, 2, degree, 1.0)
            ut = np.concatenate([u(g.x[g.interior_ids]), u(g.surface_x)]).T.ravel()
            U = (model.A_U_full @ ut).reshape(2, -1).T
            dev = np.abs(U - u(g.x))[fict].max() / np.abs(u(g.x)).max()
            # Taylor weights are O(10) with O(1) coordinates: 1e-12 is ~5000 eps
            assert (dev < 1e-12) == exact, (order, degree, dev)


def test_face_crossing_weights_give_the_discrete_stress(rng):
    """Force flux of a uniform strain = discrete virial stress on every surface node.

    Eq. (35) with alpha = 1, 1/2, 1/4 counts each bond family |k_a| times per cell face,
    so a homogeneous strain gives the same flux on every node of a face, corners included.
    """
    c = StateBasedConstants("3d", 200e9, 0.3)
    model, P = surface_box((0.3, 0.25, 0.3), (0.0, 0.0, 0.0), 0.05, 3.0, c, 1)
    g = model.grid
    eps = rng.uniform(-1, 1, (3, 3)) * 1e-3
    eps = eps + eps.T

    def u(x):
        return x @ eps.T
    rows = model.rows_of_state(u(g.x), model.dilatation_of_field(u, g.x), P)
    flux = rows.reshape(3, -1).T[g.n_interior:] / g.face_area
    for face in range(6):
        f = flux[g.surface_face == face]
        # same sum of the same bonds up to summation order: 1e-12 of the face's flux
        np.testing.assert_allclose(f, np.broadcast_to(f.mean(axis=0), f.shape), rtol=0,
                                   atol=1e-12 * np.abs(f).max())
    # and interior nodes are in equilibrium (no body force for a uniform strain)
    interior = rows.reshape(3, -1).T[:g.n_interior]
    assert np.abs(interior).max() < 1e-12 * np.abs(flux).max() * g.face_area


@pytest.mark.parametrize("order", [1, 3])
def test_the_map_multiplied_in_last_gives_the_same_rows(order):
    """``StateBasedModel.unknown_rows``: (R A_e) A_U (``map_last``, the 3D surface nodes'
    assembly) and R (A_e A_U) are the same rows over the unknowns, to the round-off of
    their sums. Bound (Higham, Accuracy and Stability of Numerical Algorithms, 2nd ed.,
    Eq. 3.13, |fl(AB) - AB| <= gamma_n |A||B|, applied to both products of each order):
    entrywise |difference| <= 2 gamma_n |R||A_e||A_U| with n the largest number of terms
    along the chain, gamma_n = n u / (1 - n u), u = eps / 2."""
    c = StateBasedConstants("3d", 200e9, 0.3)
    model, P = surface_box((0.4, 0.3, 0.3), (0.0, -0.15, -0.15), 0.05, 3.0, c, order)
    rows = [P @ model.K_e, model.A_theta]
    ref = model.unknown_rows(rows)
    new = model.unknown_rows(rows, map_last=True)
    most = lambda A: int(np.diff(A.tocsr().indptr).max())  # noqa: E731
    for R, a, b in zip(rows, ref, new):
        n = most(R) + most(model.A_e) + most(model.A_U_full)
        gamma = n * EPS / 2 / (1 - n * EPS / 2)
        bound = 2 * gamma * (abs(R) @ abs(model.A_e) @ abs(model.A_U_full)).toarray()
        diff = abs(a - b).toarray()
        assert np.all(diff <= bound), (order, float((diff - bound).max()))
        # the bound is a round-off bound, far below the rows' own size
        assert bound.max() < 1e-12 * abs(a).max()
