"""Convergence studies: the rate fit, the 1D rates the theory predicts, and a rate (or an
exactness note) for every method of the 1D, 2D and 3D studies in results.json."""
from __future__ import annotations

import json

import numpy as np
import pytest

from pdverify import convergence
from pdverify.report import build_report
from pdverify.runner import run_case

# the fit is a slope of logs: exact data give the rate to round-off of log()
FIT_RTOL = 1e-12


@pytest.mark.parametrize("p", [-1.5, 0.0, 1.0, 2.0, 4.5])
def test_fit_rate_recovers_a_power_law(p):
    h = np.array([0.3, 0.15, 0.075, 0.0375, 0.02])
    assert convergence.fit_rate(h, 7.0 * h**p) == pytest.approx(p, rel=FIT_RTOL, abs=FIT_RTOL)


def test_taylor_bar_converges_at_second_order_in_delta_and_plateaus_in_m():
    runs = [run_case(c) for c in convergence.cases(["bar1d-sine-load"])]  # every level
    entries = {(e["study"], e["method"]): e for e in convergence.collect(runs)}
    # seed 000: with the order-1 Taylor fictitious layer the boundary is consistent and the
    # error is the nonlocal operator's truncation, O(delta^2) for the smooth sine solution
    # (Taylor expansion of the PD operator; measured 1.99 over delta = 0.3 .. 0.0375)
    assert entries[("delta", "taylor-fictitious")]["rate"] == pytest.approx(2.0, abs=0.05)
    # the uncorrected bar keeps an O(delta) surface layer: first order at best
    assert entries[("delta", "none")]["rate"] < 1.0
    # m-refinement at fixed delta converges to the delta = 0.15 model's own error: the
    # last two levels (m = 12, 24) agree to 1 % (measured 0.9 %)
    lv = entries[("m", "taylor-fictitious")]["levels"]
    assert abs(lv[-1]["error"] / lv[-2]["error"] - 1) < 0.01
    # ... while the uncorrected bar's error grows with m (its Dirichlet node moves)
    assert entries[("m", "none")]["rate"] < 0


STUDY_SCENES = list(dict.fromkeys(st.scene for st in convergence.STUDIES))


@pytest.fixture(scope="module")
def quick_report(tmp_path_factory):
    out = tmp_path_factory.mktemp("conv") / "report"
    code = build_report(out=str(out), quick=True, only=STUDY_SCENES)
    assert code == 0
    with open(out / "results.json") as fh:
        return out, json.load(fh)


@pytest.mark.slow  # slow tier (issue 32): its quick report 526 s of the suite's 3811 s (loaded machine)
def test_every_method_has_a_rate_or_is_exact_in_1d_2d_3d(quick_report):
    out, doc = quick_report
    entries = doc["convergence"]
    from pdverify.scenes import get_scene
    for st in convergence.STUDIES:
        want = set(convergence.methods(get_scene(st.scene))) - set(st.skip)
        if not st.used_levels(True):    # a study left out of --quick (the 3D m-refinement)
            want = set()
        got = {e["method"]: e for e in entries if e["scene"] == st.scene and e["study"] == st.kind}
        assert set(got) == want, (st.scene, st.kind)
        for e in got.values():
            # --quick: the two coarsest levels, or the study's own two quick levels
            assert len(e["levels"]) == 2 == len(st.used_levels(True))
            if e["rate"] is None:   # only a method exact at every level has no rate
                assert e["note"].startswith("exact"), e
                assert max(lv["error"] for lv in e["levels"]) < convergence.EXACT
            else:
                assert np.isfinite(e["rate"])
    assert {e["dim"] for e in entries} == {1, 2, 3}
    # the levels are ordinary runs of results.json, at the method's default params
    runs = [(r["scene"], r["method"], r["params"]) for r in doc["runs"]]
    for e in entries:
        for lv in e["levels"]:
            level = {k: v for k, v in lv.items() if k not in convergence.LEVEL_RESULTS}
            assert any(sc == e["scene"] and m == e["method"]
                       and all(p[k] == v for k, v in level.items()) for sc, m, p in runs), lv


@pytest.mark.slow  # slow tier (issue 32): shares the 526 s quick report (loaded machine)
def test_every_corrected_method_has_a_study(quick_report):
    """Every method of every scene (the FEM reference and missing extras aside) is refined
    in some study, with a rate or as exact: issue 17's 'a fitted rate for every corrected
    method'."""
    from pdverify.scenes import all_scenes
    offered = {m for sc in all_scenes() for m in convergence.methods(sc)}
    studied = {e["method"] for e in quick_report[1]["convergence"]
               if e["rate"] is not None or e["note"].startswith("exact")}
    assert offered == studied, offered ^ studied


@pytest.mark.slow  # slow tier (issue 32): shares the 526 s quick report (loaded machine)
def test_rates_and_figures_are_in_the_report(quick_report):
    out, doc = quick_report
    page = (out / "index.html").read_text()
    for scene in STUDY_SCENES:
        assert f'id="{scene}-convergence"' in page
        assert (out / "figures" / f"{scene}-convergence-studies.png").stat().st_size > 0
    e = next(e for e in doc["convergence"] if e["rate"] is not None)
    assert f"{e['rate']:.2f}" in page


def test_a_study_leaves_out_its_costly_methods():
    """body3d-manufactured's studies leave seed 000's 3D fictitious nodes out (35-40 s and
    2 GB a run: convergence.COSTLY_3D); the scene's own cases still run them."""
    from pdverify import convergence
    from pdverify.scenes import get_scene
    runs = convergence.cases(["body3d-manufactured"])
    assert runs and not any(m in convergence.COSTLY_3D for _, m, _ in runs)
    assert any(m == "taylor-fictitious"
               for m, _ in get_scene("body3d-manufactured").report_cases())


def test_methods_that_stop_early_are_fitted_over_the_levels_they_reach():
    """body3d-manufactured's delta-refinement (issue 55): none, volume and pals run its five
    levels (CG from h = 1/24), surface nodes stop at h = 0.05, energy, mirror nodes and
    PDDO at 1/24 (the direct solver's reach) and say why; each rate is the least-squares
    slope over the levels the method ran (here errors made exactly C h^p, so the fitted
    rate is p)."""
    from pdverify import convergence
    from pdverify.results import RunResult
    from pdverify.scenes import get_scene
    scene = get_scene("body3d-manufactured")
    st = next(s for s in convergence.STUDIES
              if s.scene == "body3d-manufactured" and s.kind == "delta")
    cases = [c for c in convergence.cases(["body3d-manufactured"]) if c[2] in st.levels]
    per = {}
    for _, method, level in cases:
        per.setdefault(method, []).append(level["spacing"])
    assert {m for m, hs in per.items() if len(hs) == 5} >= {"none", "volume", "pals"}
    assert min(per["surface-nodes"]) == 0.05 and len(per["surface-nodes"]) == 3
    for m in ("mirror-nodes", "pddo", "energy"):
        assert min(per[m]) == 1 / 24 and len(per[m]) == 4, m
    p = {"none": 0.7, "volume": 0.65, "surface-nodes": 2.0}
    runs = [RunResult(scene=s, method=m, params=scene.resolve(m, lv), reference="analytic",
                      metrics={"rel_l2_error": 0.5 * st.h(lv) ** p.get(m, 1.0)},
                      timings={"total_s": 1.0})
            for s, m, lv in cases]
    entries = {e["method"]: e for e in convergence.collect(runs) if e["study"] == "delta"}
    assert entries["none"]["rate"] == pytest.approx(0.7, rel=1e-12)
    assert len(entries["none"]["levels"]) == 5 and not entries["none"]["note"]
    # the successive pairs' rates: four for five levels, each p for an exact power law
    assert entries["none"]["pair_rates"] == pytest.approx([0.7] * 4, rel=1e-12)
    sn = entries["surface-nodes"]
    assert len(sn["levels"]) == 3 and sn["rate"] == pytest.approx(2.0, rel=1e-12)
    assert sn["note"].startswith("stops at h = 0.15: its system is not symmetric (no CG)")
    assert entries["pddo"]["note"].startswith("stops at h = 0.125: not symmetric")
