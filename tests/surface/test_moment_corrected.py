"""Moment-corrected partial volumes (our addition to seed 001 §3.1) and face resultants."""
import numpy as np
import pytest

from pdverify.pd.bonds import (fourth_moment_anisotropy, moment_corrected_volumes,
                               partial_volumes, stencil_offsets)
from pdverify.pd.problem import face_resultant
from pdverify.corrections.surface_nodes import surface_node_model
from pdverify.pd import StateBasedConstants
from descriptions import box_problem

# Sums of a few hundred terms of size <= 1: 1e-13 is ~500 eps of summation round-off.
SUM_ATOL = 1e-13


def _weights(dim, m_ratio):
    k = stencil_offsets(dim, m_ratio)
    r = np.linalg.norm(k, axis=1)
    return k, partial_volumes(k, m_ratio), np.exp(-(r / m_ratio) ** 2) * r ** 2


@pytest.mark.parametrize("dim", [2, 3])
@pytest.mark.parametrize("m_ratio", [3.0, 4.0, 5.0])
def test_correction_makes_the_fourth_moment_isotropic(dim, m_ratio):
    k, beta, w = _weights(dim, m_ratio)
    eta0 = fourth_moment_anisotropy(k, w * beta)
    corrected = moment_corrected_volumes(k, beta, w)
    eta1 = fourth_moment_anisotropy(k, w * corrected)
    print(f"dim {dim}, m {m_ratio:g}: anisotropy {eta0:.3e} -> {eta1:.1e}")
    assert abs(eta0) > 1e-4            # the exact fractions are measurably anisotropic
    assert abs(eta1) < SUM_ATOL        # one linear condition, met to round-off
    full_or_empty = (beta == 1.0) | (beta == 0.0)
    np.testing.assert_array_equal(corrected[full_or_empty], beta[full_or_empty])
    assert np.all((corrected > 0) & (corrected <= 1))
    # a small change: the lattice error it removes is ~1 % (2D, m = 3) or less
    assert np.abs(corrected - beta).max() < 0.02
    # the correction keeps the lattice symmetry: beta'(k) = beta'(-k) = beta'(perm k)
    lookup = {tuple(v): b for v, b in zip(k, corrected)}
    perm = k[:, ::-1]
    np.testing.assert_allclose([lookup[tuple(-v)] for v in k], corrected, atol=1e-15)
    np.testing.assert_allclose([lookup[tuple(v)] for v in perm], corrected, atol=1e-15)


def _discrete_moduli(kind, quadrature, m_ratio=3.0):
    """(C11, C12, C44) of the discrete material, read off the force flux of unit strains."""
    c = StateBasedConstants(kind, 200e9, 0.3)
    dim = 3 if kind == "3d" else 2
    h = 0.02
    L = (h * 8,) * dim
    model, P = surface_node_model(box_problem(L, (0.0,) * dim, h, m_ratio, c,
                                              quadrature=quadrature), 1)
    g = model.grid
    out = []
    shear = np.zeros((dim, dim))
    shear[0, 1] = shear[1, 0] = 0.5                # engineering shear strain 1 in 1-2
    for eps in (np.diag([1.0] + [0.0] * (dim - 1)), shear):
        def u(x, eps=eps):
            return x @ eps.T
        rows = model.rows_of_state(u(g.x), model.dilatation_of_field(u, g.x), P)
        flux = rows.reshape(dim, -1).T[g.n_interior:] / g.face_area
        out.append(flux)
    uni, shear = out
    mid = g.face_start[1] + (g.face_start[2] - g.face_start[1]) // 2  # a face x = l_x node
    mid_y = g.face_start[3] + (g.face_start[4] - g.face_start[3]) // 2  # y = l_y
    return uni[mid, 0], uni[mid_y, 1], shear[mid, 1]


@pytest.mark.parametrize("kind", ["plane-strain", "plane-stress", "3d"])
def test_corrected_discrete_material_has_the_continuum_moduli(kind):
    E, nu = 200e9, 0.3
    mu = E / (2 * (1 + nu))
    lam = {"plane-strain": E * nu / ((1 + nu) * (1 - 2 * nu)),
           "plane-stress": E * nu / (1 - nu ** 2),
           "3d": E * nu / ((1 + nu) * (1 - 2 * nu))}[kind]
    want = np.array([lam + 2 * mu, lam, mu])
    got_pv = np.array(_discrete_moduli(kind, "partial-volume"))
    got_mc = np.array(_discrete_moduli(kind, "moment-corrected"))
    print(kind, "relative moduli error, exact fractions:", got_pv / want - 1,
          "corrected:", got_mc / want - 1)
    assert np.abs(got_pv / want - 1).max() > 1e-4   # the lattice error exists ...
    # ... and is gone: linear field, sums of ~1e3 bond forces (1e-10 ~ 1e6 eps)
    np.testing.assert_allclose(got_mc, want, rtol=1e-10)


def _mono_mean(lo, hi, k):
    """Exact mean of x^k over [lo, hi]."""
    return (hi ** (k + 1) - lo ** (k + 1)) / ((k + 1) * (hi - lo))


@pytest.mark.parametrize("dim", [2, 3])
def test_face_resultant_is_the_face_mean_of_a_polynomial_traction(dim):
    h = 0.1
    centres = np.array([[0.3, 0.45, 0.25][:dim], [0.0, 0.15, -0.05][:dim]])
    normals = np.zeros_like(centres)
    normals[0, 0], normals[1, 1] = 1.0, -1.0
    # traction components as sums of monomials, total degree <= 5 on every face
    terms = [[(1.0, (2, 0, 3)), (1.0, (0, 4, 0))], [(1.0, (0, 5, 0)), (-1.0, (1, 0, 0))],
             [(1.0, (1, 0, 1))]][:dim]

    def t(x, n):
        return np.stack([sum(c * np.prod(x ** np.array(e[:dim]), axis=1) for c, e in comp)
                         for comp in terms], axis=1)

    got = face_resultant(t, centres, normals, h)
    for i in range(2):
        axis = int(np.argmax(np.abs(normals[i])))
        want = []
        for comp in terms:  # exact mean: the normal coordinate is fixed on the face
            total = 0.0
            for c, e in comp:
                f = c
                for a in range(dim):
                    x0 = centres[i, a]
                    f *= x0 ** e[a] if a == axis else _mono_mean(x0 - h / 2, x0 + h / 2, e[a])
                total += f
            want.append(total)
        # 3-point Gauss is exact to degree 5 per axis: agreement to round-off
        np.testing.assert_allclose(got[i], want, rtol=1e-13, atol=1e-15)
    # negative control: the centre value misses h^2/12 t'' of the quadratic part
    assert np.abs(t(centres, None) - got).max() > 1e-5
