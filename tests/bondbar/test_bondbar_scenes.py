"""The seed-004 scenes end to end: Table 12, Fig. 3's constraint cases, the vibrating bar."""
from fractions import Fraction

import numpy as np
import pytest

from pdverify.errors import InputError
from pdverify.scenes import get_scene
from pdverify.scenes.bar1d_bondbased import TABLE12

EPS = np.finfo(float).eps
HOMOG = get_scene("bar1d-homogenization")
CONSTR = get_scene("bar1d-constraints")
VIB = get_scene("bar1d-vibration")


def ok(result):
    assert result.status == "ok", result.message
    return result


# ------------------------------------------------------------------ bar1d-homogenization

def test_every_cell_of_tables_6_7_11_14_is_run_and_reproduced():
    """Each printed cell of seed 004 Tables 6, 7, 11 (the homogenising factors) and 14 (the
    end load coefficient C) is beside a run of the report's cases, and equals it."""
    cells = [pub for pub in HOMOG.published
             if pub.metric.startswith("end_factor_") or pub.metric == "end_load_C"]
    assert len(cells) == 10 + 9 + 10 + 11   # the cells of Tables 6, 7, 11 and 14
    runs = [HOMOG.run(method, over) for method, over in HOMOG.cases(quick=True)]
    for pub in cells:
        hits = [r for r in runs if pub.applies(r.method, r.params)]
        assert hits, pub
        for r in hits:
            # the factors come from a least-squares solve with integer data and C from c1:
            # rationals to a few hundred ulps (measured <= 1.3e-15 relative)
            assert ok(r).metrics[pub.metric] == pytest.approx(float(Fraction(pub.value)),
                                                               rel=1e3 * EPS), pub


@pytest.mark.parametrize("key", sorted(TABLE12))
def test_table12_cells_run_and_carry_the_printed_value(key):
    ratio, weight = key
    cell = TABLE12[key]
    params = {"horizon_ratio": ratio, "end_weight": weight, "nodes": cell.nodes}
    none = ok(HOMOG.run("none", params))
    homog = ok(HOMOG.run("homogenized", params))
    # f(2m+1) >= 1 + 1e-3 for every non-trivial cell (Table 12), = 1 to 1e-12 homogenised
    assert none.metrics["strain_factor"] > 1.001
    assert abs(homog.metrics["strain_factor"] - 1.0) <= 1e-12
    paper = HOMOG.published_for("none", none.params)["strain_factor"]
    assert paper.value.startswith(cell.text)
    assert ("ERRATA" in paper.source) == bool(cell.erratum)
    assert HOMOG.published_for("homogenized", homog.params)["strain_factor"].value == 1


def test_erratum_cell_reports_five_thirds():
    r = ok(HOMOG.run("none", {"horizon_ratio": 3.0, "end_weight": "half", "nodes": 7}))
    assert r.metrics["strain_factor"] == pytest.approx(5 / 3, abs=1e-12)  # (N+3)/(N-1)
    pub = HOMOG.published_for("none", r.params)["strain_factor"]
    assert pub.value == "1.043" and "5/3" in pub.source and pub.expected == pytest.approx(5 / 3)


def test_homogenized_at_1001_points_is_classical():
    r = ok(HOMOG.run("homogenized", {"horizon_ratio": 8.5, "nodes": 1001}))
    assert abs(r.metrics["strain_factor"] - 1.0) <= 1e-12
    # the whole field is the classical one: 1000 gaps summed, ~1000 eps of the end value
    assert r.metrics["max_error_pct"] <= 100 * 1000 * EPS
    np.testing.assert_array_less(np.abs(r.fields["sweep_f"] - 1.0), 1e-12)


# ------------------------------------------------------------------ bar1d-constraints

def test_homogenized_half_bar_with_end_point_held_is_the_full_bars_half():
    # Sec. 6.2: u_b = u_a for the homogenised bar. Three direct solves of systems with
    # 1-norm condition estimates < 1e3 (checked): round-off below 1e3 * eps = 2.2e-13.
    r = ok(CONSTR.run("homogenized"))
    assert max(v for k, v in r.diagnostics.items() if k.endswith("condition_estimate")) < 1e3
    assert r.metrics["half_vs_full_max_diff"] <= 1e3 * EPS
    assert r.metrics["max_error_pct"] <= 100 * 1e3 * EPS  # and bar (a) is the classical bar
    # ... but the delta-constraint (m points held) is not a symmetry half
    assert r.metrics["horizon_constraint_vs_full_max_diff"] > 1e-3


def test_uncorrected_half_bars_are_not_symmetry_halves():
    # Sec. 6.2: "u_c(x_i) != u_b(x_i) != u_a(x_i > 0)" for non-homogenised bars; we ask
    # for a difference ten orders of magnitude above round-off, and that the
    # delta-constraint is the closer one (Conclusions).
    r = ok(CONSTR.run("none"))
    assert r.metrics["half_vs_full_max_diff"] > 1e-3
    m = r.metrics
    assert 1e-3 < m["horizon_constraint_vs_full_max_diff"] < m["half_vs_full_max_diff"]


@pytest.mark.parametrize("ratio, weight", [(3.0, "full"), (4.5, "full"), (4.0, "half")])
def test_symmetry_half_holds_for_other_homogenised_bars(ratio, weight):
    m = int(ratio)
    r = ok(CONSTR.run("homogenized", {"horizon_ratio": ratio, "end_weight": weight,
                                      "nodes": 4 * m + 3}))
    assert max(v for k, v in r.diagnostics.items() if k.endswith("condition_estimate")) < 1e3
    assert r.metrics["half_vs_full_max_diff"] <= 1e3 * EPS


# ------------------------------------------------------------------ bar1d-vibration

@pytest.mark.parametrize("ratio", [4.0, 6.0])
def test_homogenized_frequency_is_closer_to_rao(ratio):
    none = ok(VIB.run("none", {"horizon_ratio": ratio}))
    homog = ok(VIB.run("homogenized", {"horizon_ratio": ratio}))
    for key in ("frequency_error_pct", "modal_frequency_error_pct"):
        assert abs(homog.metrics[key]) < abs(none.metrics[key])
    assert homog.metrics["max_error_pct"] < none.metrics["max_error_pct"]


@pytest.mark.parametrize("weight", ["full", "half"])
def test_homogenized_first_mode_carries_only_the_end_mass_offset(weight):
    # A full-weight free end point carries half an element more mass than the continuum
    # bar: Rayleigh's quotient gives omega/omega_1 = 1 - Delta/(2L) + O((Delta/L)^2); with
    # half-weight ends the first-order term vanishes. The rest is second order in Delta/L
    # (the next end-mass term, and the nonlocal dispersion ~(q delta)^2 with delta = 4 Delta,
    # q = pi/(2L)); we allow 100 (Delta/L)^2 percent, about 1e-2 % at N = 100.
    N = 100
    r = ok(VIB.run("homogenized", {"end_weight": weight, "nodes": N}))
    h = 1.0 / (N - 1)
    first_order = -100 * h / 2 if weight == "full" else 0.0
    assert abs(r.metrics["modal_frequency_error_pct"] - first_order) < 100 * h * h
    # the fit of the free-end history agrees with the eigenvalue to the same order
    m = r.metrics
    assert abs(m["frequency_error_pct"] - m["modal_frequency_error_pct"]) < 100 * h * h


def test_time_step_above_the_limit_fails_the_run_with_a_clear_message():
    r = VIB.run("homogenized", {"dt_factor": 1.5})
    assert r.status == "failed"
    assert "exceeds the stability limit" in r.message and "ratio 1.5" in r.message


# ------------------------------------------------------------------ bad input

@pytest.mark.parametrize("scene, method, overrides, match", [
    (HOMOG, "homogenized", {"horizon_ratio": 1.5, "nodes": 5}, "m >= 2"),
    (HOMOG, "none", {"horizon_ratio": 4.0, "nodes": 8}, "nodes=8 must be >= 9"),
    (HOMOG, "none", {"end_weight": "quarter"}, "allowed: full, half"),
    (HOMOG, "homogenized", {"horizon_ratio": 2.5, "end_weight": "half", "nodes": 5}, "no factors"),
    (HOMOG, "none", {"horizon_ratio": 2.3}, "half-whole"),
    (CONSTR, "none", {"nodes": 16}, "must be odd"),
    (CONSTR, "homogenized", {"nodes": 15}, "nodes=15 must be >= 17"),
    (VIB, "homogenized", {"horizon_ratio": 6.0, "nodes": 12}, "nodes=12 must be >= 13"),
    (VIB, "none", {"periods": 0.5}, ">= 1.0"),
])
def test_bad_input_is_one_line_before_any_work(scene, method, overrides, match):
    with pytest.raises(InputError, match=match) as info:
        scene.resolve(method, overrides)
    assert "\n" not in str(info.value)
