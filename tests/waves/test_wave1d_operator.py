"""The discrete operator of seed 002 Eq. (3): symbol, exactness of the fictitious layer, sizes."""
import numpy as np
import pytest
from numpy.testing import assert_allclose

from manufactured.wave1d import nonlocal_factor
from pdverify.scenes.wave1d import lattice_symbol, odd_image, wave_bar
from pdverify.corrections.registry import from_name


def surface_nodes(order=1):
    """The surface node method's ``wave-bar`` extension at Taylor ``order`` (its role)."""
    return from_name("surface-nodes").build_for("wave-bar", None, {"order": order})


#: the bar's extensions by name: surface nodes (the default), truncated (``None``)
EXTENSIONS = {"surface-nodes": surface_nodes(1), "none": None}

EPS = np.finfo(float).eps
V, DELTA, L = 5000.0, 0.1, 1.0  # seed 002


def _roundoff(A, u):
    """Summation bound n eps sum_j |A_ij u_j| per row (Higham's gamma_n, n = entries per row)."""
    n = np.diff(A.indptr).max()
    return 2 * n * EPS * (abs(A) @ np.abs(u))


@pytest.mark.parametrize("m", [10, 25, 100])
def test_paper_grid_sizes(m):
    # seed 002 Sec. "Results": m = 10, 25, 100 <-> Delta = 10, 4, 1 mm, N = 100, 250, 1000
    bar = wave_bar(L, DELTA, m, V, surface_nodes(1))
    assert bar.n_real == 10 * m
    assert_allclose(bar.spacing, DELTA / m, rtol=4 * EPS)
    assert bar.n_fict == m  # the fictitious layer is delta deep
    assert bar.size()["dofs"] == 10 * m
    assert wave_bar(L, DELTA, m, V, None).size()["dofs"] == 10 * m - 2


def test_lattice_symbol_converges_to_psi_at_first_order_in_one_over_m():
    # The one-point quadrature of Eq. (3) omits the node's own cell, where the integrand of
    # Eq. (12) is k^2/2: psi - psi_h = k^2/(2m) + O(m^-2). So m (psi - psi_h) / k^2 -> 1/2
    # and the deviation from 1/2 falls like 1/m (fitted slope -1, margin 0.1).
    ms = np.array([10, 25, 100, 400, 1600])
    for k in (np.pi, 10 * np.pi, 25 * np.pi):
        psi = nonlocal_factor(k, DELTA)
        ph = np.array([lattice_symbol(k, horizon=DELTA, m_ratio=m) for m in ms])
        lead = ms * (psi - ph) / k ** 2
        dev = np.abs(lead - 0.5)
        slope = np.polyfit(np.log(ms), np.log(dev), 1)[0]
        assert abs(slope + 1) < 0.1, slope
        assert dev[-1] < 1e-4


@pytest.mark.parametrize("boundary", ["surface-nodes", "none"])
def test_operator_on_sine_away_from_the_ends_is_minus_v2_psi_h(boundary):
    # Nodes at least delta from both ends see a complete lattice neighbourhood, so sin(kx)
    # is an eigenvector there with eigenvalue -v^2 psi_h (closed form, to round-off).
    bar = wave_bar(L, DELTA, 25, V, EXTENSIONS[boundary])
    x = bar.x_free
    k = 3 * np.pi
    u, s = np.sin(k * x), np.sin(k * bar.x_bc)  # "none" fixes nodes at Delta/2 from the ends
    a = bar.A @ u + bar.A_bc @ s
    inner = (x >= DELTA) & (x <= L - DELTA)
    expected = -V ** 2 * lattice_symbol(k, horizon=DELTA, m_ratio=25) * u
    tol = (_roundoff(bar.A, u) + _roundoff(bar.A_bc, s))[inner].max()
    assert_allclose(a[inner], expected[inner], rtol=0, atol=tol)


def test_order_one_fictitious_layer_keeps_linear_fields_force_free():
    # Eqs. (8)-(9) reproduce linear fields in the fictitious layer exactly, so u = a + b x
    # (with the surface nodes on the same line) has zero acceleration at every real node.
    bar = wave_bar(L, DELTA, 10, V, surface_nodes(1))
    u = 0.3 + 0.7 * bar.x_real
    s = 0.3 + 0.7 * bar.x_bc
    a = bar.A @ u + bar.A_bc @ s
    tol = _roundoff(bar.A, u) + _roundoff(bar.A_bc, s)
    assert np.all(np.abs(a) <= tol)


@pytest.mark.parametrize("order", [2, 3])
def test_order_n_fictitious_layer_is_exact_for_quadratics(order):
    # Taylor order n >= 2 extrapolates x^2 exactly, so every real node sees a complete
    # neighbourhood of x^2: a = sum_k c_k 2 xi_k^2 = 2 v^2 sum_k beta_k Delta / delta
    # = 2 v^2 (1 - 1/(2m)) (beta = 1/2 at the horizon). Order 1 does not (near the ends).
    m = 10
    bar = wave_bar(L, DELTA, m, V, surface_nodes(order))
    u = bar.x_real ** 2
    s = bar.x_bc ** 2
    a = bar.A @ u + bar.A_bc @ s
    tol = _roundoff(bar.A, u) + _roundoff(bar.A_bc, s)
    assert np.all(np.abs(a - 2 * V ** 2 * (1 - 1 / (2 * m))) <= tol)
    low = wave_bar(L, DELTA, m, V, surface_nodes(1))
    a1 = low.A @ u + low.A_bc @ s
    assert np.max(np.abs(a1 - 2 * V ** 2 * (1 - 1 / (2 * m)))) > 1e-3 * V ** 2


def test_surface_node_spectrum_is_real_and_positive_at_order_one():
    # Central differences need a real, non-negative spectrum of -A (Eq. 5); the
    # extrapolation makes A non-symmetric, so check it (dense, m = 10).
    bar = wave_bar(L, DELTA, 10, V, surface_nodes(1))
    lam = np.linalg.eigvals(-bar.A.toarray())
    assert np.max(np.abs(lam.imag)) <= 1e-9 * np.max(np.abs(lam))
    assert lam.real.min() > 0


@pytest.mark.parametrize("j", [1, 4, 13])
def test_odd_image_makes_every_sine_mode_an_exact_eigenvector(j):
    # The odd image about the surface nodes is the extension the series of Eq. (11)
    # implies: sin(j pi x / l) is then an eigenvector at every real node, ends included.
    bar = wave_bar(L, DELTA, 10, V, odd_image)
    k = j * np.pi / L
    u = np.sin(k * bar.x_real)
    a = bar.A @ u
    expected = -V ** 2 * lattice_symbol(k, horizon=DELTA, m_ratio=10) * u
    assert_allclose(a, expected, rtol=0, atol=_roundoff(bar.A, u).max())
