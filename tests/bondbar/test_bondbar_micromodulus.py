"""Seed 004 §2, App. 1: the discrete micromodulus c1(m) (Eqs. 14, 22, 26, 30), Tables 1, 2, 14."""
import numpy as np
import pytest

from pdverify.corrections.homogenized import bond_bar, bond_profile
from pdverify.pd.bar1d import bar_micromodulus as micromodulus_c1
from pdverify.pd.bar1d import micromodulus_factor, split_horizon_ratio

EPS = np.finfo(float).eps
#: c1 is E over a sum of at most 2m positive O(m^2) terms: a few ulps, at m <= 40 below 1e-14.
RTOL_SUM = 1e-14


def eq14(m, beta):
    """Seed 004 Eq. (14): c1(m) A delta^2 / (6E), 0 <= beta <= 1/2."""
    return (m + beta) ** 3 / (m * (m * m + 3 * beta * m + 6 * beta ** 2 - 1))


def eq22(m, beta):
    """Seed 004 Eq. (22): the same for 1/2 <= beta <= 1 (equal to Eq. 14 at beta = 1/2)."""
    return (m + beta) ** 3 / (m * (m * m + 3 * beta * m + 3 * beta - 1))


def printed_digits_agree(value, printed: str) -> bool:
    """True if ``printed`` is ``value`` rounded or truncated to the printed decimals."""
    decimals = len(printed.split(".")[1]) if "." in printed else 0
    scale = 10 ** decimals
    return float(printed) in (round(value, decimals), np.trunc(value * scale) / scale)


@pytest.mark.parametrize("m", range(2, 41))
def test_c1_through_an_element_is_eq14_and_eq26(m):
    c1 = micromodulus_c1(float(m), E=2.0, area=0.5, spacing=0.1)
    scale = 6 * 2.0 / (0.5 * (m * 0.1) ** 2)
    np.testing.assert_allclose(c1 / scale, eq14(m, 0.0), rtol=RTOL_SUM)
    np.testing.assert_allclose(c1 / scale, 1 / (1 - 1 / m ** 2), rtol=RTOL_SUM)  # Eq. (26)


@pytest.mark.parametrize("m", range(1, 41))
def test_c1_between_elements_is_eq14_eq22_and_eq30(m):
    c1 = micromodulus_c1(m + 0.5, E=3.0, area=2.0, spacing=0.01)
    scale = 6 * 3.0 / (2.0 * ((m + 0.5) * 0.01) ** 2)
    np.testing.assert_allclose(c1 / scale, eq14(m, 0.5), rtol=RTOL_SUM)
    np.testing.assert_allclose(c1 / scale, eq22(m, 0.5), rtol=RTOL_SUM)
    np.testing.assert_allclose(c1 / scale, (1 + 1 / (2 * m)) ** 2 / (1 + 1 / m), rtol=RTOL_SUM)


@pytest.mark.parametrize("m, printed", [(2, "1.333"), (3, "1.125"), (4, "1.067"), (5, "1.042"),
                                        (6, "1.029"), (10, "1.01"), (32, "1.001")])
def test_table1(m, printed):
    assert printed_digits_agree(micromodulus_factor(float(m)), printed)


@pytest.mark.parametrize("m, printed", [(2, "1.042"), (3, "1.021"), (4, "1.0125"), (5, "1.0083"),
                                        (15, "1.001")])
def test_table2(m, printed):
    assert printed_digits_agree(micromodulus_factor(m + 0.5), printed)


def test_thresholds_of_eqs_29_and_32_as_corrected_in_errata():
    # ERRATA seed 004: Eq. (29) needs m >= 11 (not 10) for < 1 %, Eq. (32) m >= 16 (not 15)
    # for < 0.1 %; the text's 32 (through) and 5 (between) are right.
    def first_m(offset, bound):
        return next(m for m in range(2, 200) if micromodulus_factor(m + offset) - 1 < bound)
    assert first_m(0.0, 0.01) == 11
    assert first_m(0.0, 0.001) == 32
    assert first_m(0.5, 0.01) == 5
    assert first_m(0.5, 0.001) == 16


@pytest.mark.parametrize("shape, factor", [("triangular", 6.0), ("constant", 2.0)])
def test_continuum_micromodulus(shape, factor):
    # Seed 004 below Eq. (6) (Bobaru et al.): c_inf = 6E/(A delta^2), constant 2E/(A delta^2).
    c = micromodulus_c1(3.5, E=5.0, area=0.2, spacing=0.1, micromodulus=shape,
                        calibration="continuum")
    np.testing.assert_allclose(c, factor * 5.0 / (0.2 * 0.35 ** 2), rtol=4 * EPS)


@pytest.mark.parametrize("m", range(1, 12))
def test_constant_micromodulus_through_an_element_needs_no_discrete_correction(m):
    # Seed 004 §2 (quoting [1]): the constant micromodulus is independent of the number of
    # points when the horizon halves an element and that element counts half.
    assert micromodulus_factor(float(m), "constant") == pytest.approx(1.0, rel=RTOL_SUM)


@pytest.mark.parametrize("ratio, weight, C", [
    (2.0, "half", 1.0), (3.0, "half", 8 / 3), (4.0, "half", 5.0), (2.5, "half", 2.0),
    (3.5, "half", 4.0), (4.5, "half", 20 / 3), (3.0, "full", 4 / 3), (4.0, "full", 5 / 2),
    (2.5, "full", 1.0), (3.5, "full", 2.0), (4.5, "full", 10 / 3)])
def test_table14_end_equation_coefficient(ratio, weight, C):
    # App. 1, Eq. (A1.7): b_1/(c1 A) = C sigma Delta / E, with b_1 = sigma A / V_1.
    E, sigma, spacing = 7.0, 3.0, 0.25
    bar = bond_bar(nodes=21, spacing=spacing, horizon_ratio=ratio, E=E, area=0.3,
                    end_weight=weight)
    b1 = sigma * bar.thickness / bar.node_volume[0]
    np.testing.assert_allclose(b1 / (bar.c * bar.thickness) / (sigma * spacing / E), C,
                               rtol=RTOL_SUM)


def test_profile_drops_the_triangle_tip_and_keeps_partial_volumes():
    # Eq. (8): relative point values (m + beta - i)/(m + beta); Tables 3-5, 8-10. The
    # weights are 1 - k/delta: one rounding in k/delta <= 1 and one in the difference.
    k, w = bond_profile(4.0)
    np.testing.assert_array_equal(k, [1, 2, 3])
    np.testing.assert_allclose(w, [3 / 4, 1 / 2, 1 / 4], rtol=0, atol=2 * EPS)
    k, w = bond_profile(4.5)
    np.testing.assert_array_equal(k, [1, 2, 3, 4])
    np.testing.assert_allclose(w, [7 / 9, 5 / 9, 3 / 9, 1 / 9], rtol=0, atol=2 * EPS)
    k, w = bond_profile(2.0, "constant")  # the element cut by the horizon counts half
    np.testing.assert_allclose(w, [1.0, 0.5], rtol=0)


@pytest.mark.parametrize("bad", [2.3, 0.0, 0.5, np.nan])
def test_horizon_ratio_must_be_whole_or_half_whole(bad):
    with pytest.raises(ValueError, match="whole or half-whole"):
        split_horizon_ratio(bad)

