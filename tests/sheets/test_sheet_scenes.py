"""Seed 003 §4.1 scenes: Tables 1 and 2, m-convergence, bad input (issue 13)."""
import numpy as np
import pytest


@pytest.fixture(scope="module")
def _run(run_once):
    """One run of the scene, shared through the session (``run_once`` in conftest)."""
    def run(scene, method, **over):
        r = run_once(scene, method, **over)
        assert r.status == "ok", r.message
        return r
    return run


# --------------------------------------------------------------------- Table 2
@pytest.mark.parametrize("method, over, paper", [
    ("none", {}, 4.17),
    ("energy-directional", {}, 10.21),
    ("virtual-nodes", {}, 8.43),
    ("virtual-nodes", {"correct_sides": True}, 8.64),
])
def test_table_2_within_2_pct_of_the_paper(method, over, paper, _run):
    # seed 003 Table 2; issue 13 allows 2 % (the node volumes and the horizon quadrature
    # are unstated: half/quarter volumes per ERRATA, whole cells inside the horizon)
    r = _run("sheet2d-clamped", method, **over)
    assert r.metrics["tensile_stress_mpa"] == pytest.approx(paper, rel=0.02)


def test_table_2_other_readings_are_recorded_not_tuned(_run):
    # ERRATA: full volumes on the boundary nodes give ~6.5 / ~12.1 MPa instead
    full = _run("sheet2d-clamped", "none", node_volumes="full").metrics["tensile_stress_mpa"]
    assert full == pytest.approx(6.5, rel=0.02)
    # exact partial areas: the last row misses 8.64 by more than 2 %
    pv = _run("sheet2d-clamped", "virtual-nodes", correct_sides=True,
              quadrature="partial-volume").metrics["tensile_stress_mpa"]
    assert abs(pv / 8.64 - 1) > 0.02


def test_corrected_clamped_sheet_is_close_to_fem(_run):
    r = _run("sheet2d-clamped", "energy-directional")
    # the paper: "reduces the overall error to about 1 %" (10.21 vs 10.32)
    assert abs(r.metrics["tensile_stress_error_pct"]) < 2.0
    unc = _run("sheet2d-clamped", "none")
    assert r.metrics["rel_l2_error"] < unc.metrics["rel_l2_error"]


# --------------------------------------------------------------------- Table 1
def test_table_1_corrected_is_near_the_paper_and_20_times_better(_run):
    unc = _run("sheet2d-tension", "none")
    cor = _run("sheet2d-tension", "energy-directional")
    u = np.array([unc.metrics["max_error_ux_pct"], unc.metrics["max_error_uy_pct"]])
    c = np.array([cor.metrics["max_error_ux_pct"], cor.metrics["max_error_uy_pct"]])
    # uncorrected of the paper's order (82 % / 291 %: here 301 % / 84 %, the same two
    # magnitudes with the components the other way round, see the scene docstring)
    assert sorted(u) == pytest.approx(sorted([82.0, 291.0]), rel=0.1)
    assert np.all(u / c >= 20)                     # issue 13: at least 20 times smaller
    np.testing.assert_allclose(c, [2.6, 3.2], rtol=0.25)   # "near 2.6 % / 3.2 %"


def test_table_1_equal_end_forces_do_not_reproduce_it(_run):
    # the other load reading (ERRATA: unstated): corner nodes with half a cell get a full
    # share, and the corrected error grows tenfold
    cor = _run("sheet2d-tension", "energy-directional", load_sharing="equal")
    assert cor.metrics["max_error_ux_pct"] > 20


@pytest.mark.slow  # slow tier (issue 32): 14 s: a convergence study (loaded machine)
def test_m_convergence_of_the_corrected_sheet(_run):
    # m = 2, 4, 5 at fixed delta = 5 mm: the corrected error falls (fitted log-log slope of
    # the relative L2 error < -1; measured -2.4) and beats the uncorrected one at every m
    m, cor, unc = [], [], []
    for h in (0.0025, 0.00125, 0.001):
        m.append(0.005 / h)
        cor.append(_run("sheet2d-tension", "energy-directional", spacing=h).metrics["rel_l2_error"])
        unc.append(_run("sheet2d-tension", "none", spacing=h).metrics["rel_l2_error"])
    slope = np.polyfit(np.log(m), np.log(cor), 1)[0]
    assert slope < -1.0, slope
    assert np.all(np.array(cor) < np.array(unc))


# --------------------------------------------------------------------- bad input
BAD_INPUT = [
    (("sheet2d-tension", "--method", "none", "--set", "spacing=0.003"), "must divide"),
    (("sheet2d-tension", "--method", "none", "--set", "horizon=0.0015"), "must be >= 2"),
    (("sheet2d-clamped", "--method", "none", "--set", "m_ratio=1.5"), "must be >= 2"),
    (("sheet2d-clamped", "--method", "none", "--set", "m_ratio=6.3"), "must divide"),
    (("sheet2d-clamped", "--method", "none", "--set", "micromodulus=cubic"),
     "allowed: constant, conical"),
    (("sheet2d-tension", "--method", "virtual-nodes"),
     "allowed: fem, none, taylor-fictitious, surface-nodes, mirror-nodes, pddo, energy, energy-directional"),
    (("sheet2d-clamped", "--method", "energy-directional", "--set", "nu=0.3"), "nu = 1/3"),
]


@pytest.fixture(scope="module")
def bad_input_runs(cli_concurrently):
    """Every case in its own interpreter, one per core at a time (issue 32)."""
    return cli_concurrently([("run", *args) for args, _ in BAD_INPUT])


@pytest.mark.parametrize("args, words", BAD_INPUT)
def test_bad_input_is_one_line_exit_2(args, words, bad_input_runs):
    res = bad_input_runs[("run", *args)]
    assert res.returncode == 2, res.stdout + res.stderr
    lines = res.stderr.strip().splitlines()
    assert len(lines) == 1 and words in lines[0] and "Traceback" not in res.stderr
