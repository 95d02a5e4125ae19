"""Seed 004 §7's remark on the constant micromodulus (finding 004-constant-limit in
pdverify.deviations): f(N) = f(inf) + b/(N - 1) exactly, and f(inf) does not depend on the
end weight in either calibration; the triangular micromodulus' f(inf) = 1 (§7, Table 12)
holds for every Table 12 cell."""
import numpy as np
import pytest

from pdverify.pd.bar1d import micromodulus_factor
from pdverify.scenes import get_scene
from pdverify.scenes.bar1d_bondbased import CONSTANT_LIMIT, TABLE12, strain_factor_limit

SCENE = get_scene("bar1d-homogenization")
#: f(inf) is a sum of ~N bond forces' effect on the cut system (condition < 1e6 on these
#: bars): 1e-9 relative is round-off x 1e6, rounded up (the scene's LIMIT_AGREEMENT)
ROUND_OFF = 1e-9


def _limit(**over):
    r = SCENE.run("none", over)
    assert r.status == "ok", r.message
    return r.metrics["strain_factor_limit"], r.metrics["strain_factor"]


#: the continuum calibration takes c_inf = 2E/(A delta^2) instead of the discrete horizon's
#: c1(m), so the bulk is softer by c1(m)/c_inf: seed 004's f_1(m) (Eq. 27, Table 1), 1.0125
#: at delta = 4.5 Delta
CONTINUUM_LIMIT = micromodulus_factor(CONSTANT_LIMIT["horizon_ratio"], "constant")


@pytest.mark.parametrize("calibration, expected", [("discrete", 1.0),
                                                   ("continuum", CONTINUUM_LIMIT)])
def test_constant_micromodulus_limit_does_not_depend_on_the_end_weight(calibration, expected):
    full, f_full = _limit(**CONSTANT_LIMIT, end_weight="full", calibration=calibration)
    half, f_half = _limit(**CONSTANT_LIMIT, end_weight="half", calibration=calibration)
    # the claim ([1]): the classical limit only with full-weight ends; ours: the same
    # limit for both, the bulk's (1 from the discrete horizon, f_1(m) from the continuum)
    assert abs(full - half) <= ROUND_OFF
    assert abs(full - expected) <= ROUND_OFF * expected
    # the end weight changes the O(1/N) term only: the half-weight bar is further off
    assert f_half - half > f_full - full > 0


def test_the_limit_is_the_form_f_inf_plus_b_over_n_minus_1():
    """Doubling N - 1 halves f - f(inf) (the form), on a constant-micromodulus bar."""
    p = SCENE.resolve("none", {**CONSTANT_LIMIT, "end_weight": "half"})
    n = np.array([251, 501, 1001, 2001])
    f = np.array([SCENE.strain_factor(SCENE.end_loaded("none", p, k, 1.0 / (k - 1)), p)[0]
                  for k in n])
    limit, spread = strain_factor_limit(n, f)
    assert spread <= ROUND_OFF
    # f - f(inf) ~ 1e-2 .. 1e-3 against f's round-off ~1e-12 (ROUND_OFF's argument):
    # the ratio is 2 to ~1e-9; 1e-6 leaves that a thousandfold margin
    np.testing.assert_allclose((f[:-1] - limit) / (f[1:] - limit), 2.0, rtol=1e-6)


def test_the_limit_is_refused_where_the_form_does_not_hold():
    n = np.array([5, 9, 17, 33, 65])
    assert strain_factor_limit(n, 1.0 + 1.0 / (n - 1) ** 2)[0] is None  # 1/N^2: not the form
    assert strain_factor_limit(n[:3], 1.0 + 1.0 / (n[:3] - 1))[0] is None  # too short
    # the exact form: the two-point limit is 1 to round-off (four terms of order 1)
    assert strain_factor_limit(n, 1.0 + 3.0 / (n - 1))[0] == pytest.approx(1.0, abs=1e-12)


@pytest.mark.parametrize("key", sorted(TABLE12))
def test_triangular_limit_is_one_for_every_table_12_cell(key):
    ratio, weight = key
    limit, _ = _limit(horizon_ratio=ratio, end_weight=weight, nodes=2 * int(ratio) + 1)
    # seed 004 §7: f(inf) = 1 both for half and full weight end elements (Table 12)
    assert abs(limit - 1.0) <= ROUND_OFF
