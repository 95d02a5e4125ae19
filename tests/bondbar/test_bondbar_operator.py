"""The bar operator against seed 004's printed equilibrium equations (34)-(98) and Eq. (33)."""
import numpy as np
import pytest

from pdverify.corrections.homogenized import bond_bar
from pdverify.scenes.bar1d_bondbased import end_force_displacement, equation_rows
from pdverify.solvers.lu import solve_constrained

EPS = np.finfo(float).eps


def paper_rows(ratio, weight, a=1.0, b=1.0, g=1.0):
    """Rows 1..m+1 of the paper's S u = -scale b/(c1 A), with its end-bond factors a, b, g.

    Half weight: Eqs. (34)-(36) / (41) [x4], (42)-(45) / (51) [x12, Eq. (45) with the
    ERRATA fix (2/3)(u_3 - u_4)], (52)-(56) / (63) [x24]. Full weight: (65)-(66), (68)
    [x6], (69)-(71), (73) [x12]. Between elements: (75)-(78), (80) [x10], (81)-(86), (88)
    [x42], (89)-(96), (98) [x108]. Returns (scale, rows) with rows padded by zeros.
    """
    table = {
        (2.0, "half"): (4, [[-2 * a, 2 * a],
                            [a, -(a + 2), 2],
                            [0, 2, -4, 2]]),
        (3.0, "half"): (12, [[-(8 * a + 2 * b), 8 * a, 2 * b],
                             [4 * a, -(4 * a + 10), 8, 2],
                             [b, 8, -(b + 18), 8, 2],
                             [0, 2, 8, -20, 8, 2]]),
        (4.0, "half"): (24, [[-(18 * a + 6 * b + 2 * g), 18 * a, 6 * b, 2 * g],
                             [9 * a, -(9 * a + 26), 18, 6, 2],
                             [3 * b, 18, -(3 * b + 44), 18, 6, 2],
                             [g, 6, 18, -(g + 50), 18, 6, 2],
                             [0, 2, 6, 18, -52, 18, 6, 2]]),
        (3.0, "full"): (6, [[-(4 * a + b), 4 * a, b],
                            [4 * a, -(4 * a + 5), 4, 1],
                            [b, 4, -(b + 9), 4, 1],
                            [0, 1, 4, -10, 4, 1]]),
        (4.0, "full"): (12, [[-(9 * a + 3 * b + g), 9 * a, 3 * b, g],
                             [9 * a, -(9 * a + 13), 9, 3, 1],
                             [3 * b, 9, -(3 * b + 22), 9, 3, 1],
                             [g, 3, 9, -(g + 25), 9, 3, 1],
                             [0, 1, 3, 9, -26, 9, 3, 1]]),
        (2.5, "full"): (10, [[-(6 * a + 1), 6 * a, 1],
                             [6 * a, -(6 * a + 7), 6, 1],
                             [1, 6, -14, 6, 1]]),
        (3.5, "full"): (42, [[-(30 * a + 9 * b + 2), 30 * a, 9 * b, 2],
                             [30 * a, -(30 * a + 41), 30, 9, 2],
                             [9 * b, 30, -(9 * b + 71), 30, 9, 2],
                             [2, 9, 30, -82, 30, 9, 2]]),
        (4.5, "full"): (108, [[-(84 * a + 30 * b + 12 * g + 3), 84 * a, 30 * b, 12 * g, 3],
                              [84 * a, -(84 * a + 129), 84, 30, 12, 3],
                              [30 * b, 84, -(30 * b + 213), 84, 30, 12, 3],
                              [12 * g, 30, 84, -(12 * g + 243), 84, 30, 12, 3],
                              [3, 12, 30, 84, -258, 84, 30, 12, 3]]),
    }
    scale, rows = table[(ratio, weight)]
    width = max(len(r) for r in rows)
    return scale, np.array([r + [0] * (width - len(r)) for r in rows], dtype=float)


#: The paper's homogenising parameters (Eqs. 40, 50, 62, 67, 72, 79, 87, 97).
PAPER_FACTORS = {(2.0, "half"): (2,), (3.0, "half"): (3, 2), (4.0, "half"): (4, 3, 2),
                 (3.0, "full"): (1.5, 1), (4.0, "full"): (2, 1.5, 1), (2.5, "full"): (4 / 3,),
                 (3.5, "full"): (9 / 5, 4 / 3), (4.5, "full"): (16 / 7, 9 / 5, 4 / 3)}


@pytest.mark.parametrize("homogenized", [False, True])
@pytest.mark.parametrize("key", sorted(PAPER_FACTORS))
def test_rows_match_the_printed_equations(key, homogenized):
    ratio, weight = key
    factors = PAPER_FACTORS[key] if homogenized else ()
    letters = dict(zip("abg", factors))
    scale, expected = paper_rows(ratio, weight, **letters)
    m = int(ratio)
    # long enough that rows 1..m+1 do not reach the other end
    bar = bond_bar(nodes=4 * m + 3, spacing=0.1, horizon_ratio=ratio, E=2.0, area=0.5,
                    end_weight=weight, end_factors=factors)
    ours = equation_rows(bar)[: expected.shape[0], : expected.shape[1]] * scale
    # integer-valued rationals up to 258 * 16/7 from a handful of float operations
    np.testing.assert_allclose(ours, expected, rtol=0, atol=64 * EPS * np.abs(expected).max())


def naive_rows(nodes, ratio, weight, shape):
    """Eq. (33) / (c1 A) assembled point by point (a slow, independent reference)."""
    w = np.ones(nodes)
    if weight == "half":
        w[[0, -1]] = 0.5
    m = int(ratio)
    S = np.zeros((nodes, nodes))
    for i in range(nodes):
        for p in range(nodes):
            k = abs(p - i)
            if k == 0 or k > ratio:
                continue
            c = 1 - k / ratio if shape == "triangular" else 1.0
            partial = 0.5 if (k == m and ratio == m) else 1.0  # the element the horizon halves
            S[i, p] += c / k * partial * w[p]
            S[i, i] -= c / k * partial * w[p]
    return S


@pytest.mark.parametrize("shape", ["triangular", "constant"])
@pytest.mark.parametrize("ratio, weight", [(2.0, "half"), (5.0, "full"), (8.0, "half"),
                                           (1.5, "full"), (6.5, "full"), (8.5, "half")])
@pytest.mark.parametrize("nodes_over", [1, 3])
def test_vectorised_assembly_equals_pointwise_eq33(ratio, weight, shape, nodes_over):
    nodes = nodes_over * (2 * int(ratio) + 1) + 2
    bar = bond_bar(nodes=nodes, spacing=0.2, horizon_ratio=ratio, E=1.0, end_weight=weight,
                    micromodulus=shape)
    expected = naive_rows(nodes, ratio, weight, shape)
    np.testing.assert_allclose(equation_rows(bar), expected, rtol=0,
                               atol=32 * EPS * np.abs(expected).max())


@pytest.mark.parametrize("ratio, weight", [(4.0, "half"), (4.5, "full"), (7.0, "full")])
def test_stiffness_is_symmetric_with_only_the_rigid_mode(ratio, weight):
    bar = bond_bar(nodes=30, spacing=0.1, horizon_ratio=ratio, E=1.0, end_weight=weight,
                    end_factors=(1.7, 1.2))
    K = bar.K.toarray()
    np.testing.assert_array_equal(K, K.T)  # assembled from symmetric bond entries
    scale = np.abs(K).max()
    np.testing.assert_allclose(K @ np.ones(30), 0.0, rtol=0, atol=64 * EPS * scale)
    lam = np.linalg.eigvalsh(K)
    assert abs(lam[0]) < 1e3 * EPS * scale < lam[1]


@pytest.mark.parametrize("ratio, weight", [(3.0, "half"), (4.5, "full")])
def test_cut_form_equals_a_pinned_displacement_solve(ratio, weight):
    # Two routes to the same equations: K u = f with the centre pinned (condition number
    # ~ N^2 ~ 2e3 at N = 41, so ~1e-12 agreement), and the cut system of the model.
    N = 41
    bar = bond_bar(nodes=N, spacing=0.05, horizon_ratio=ratio, E=3.0, end_weight=weight)
    f = np.zeros(N)
    f[0], f[-1] = -2.0, 2.0
    B = np.zeros((1, N))
    B[0, N // 2] = 1.0
    u_pinned, _, info = solve_constrained(bar.K, f, B, [0.0])
    u_cut = end_force_displacement(bar, 2.0)
    np.testing.assert_allclose(u_cut, u_pinned, rtol=0,
                               atol=10 * EPS * info["condition_estimate"] * np.abs(u_pinned).max())


def test_bad_model_input_is_rejected():
    with pytest.raises(ValueError, match="2m \\+ 1"):
        bond_bar(nodes=8, spacing=1.0, horizon_ratio=4.0, E=1.0)
    with pytest.raises(ValueError, match="end_weight"):
        bond_bar(nodes=9, spacing=1.0, horizon_ratio=4.0, E=1.0, end_weight="quarter")
    with pytest.raises(ValueError, match="no bond"):
        bond_bar(nodes=9, spacing=1.0, horizon_ratio=1.0, E=1.0)
