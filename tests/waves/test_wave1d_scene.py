"""Scene wave1d-surface-nodes (seed 002): the issue's must-show items, end to end."""
import json
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from numpy.testing import assert_allclose

from pdverify.scenes.wave1d import wave_bar
from pdverify.corrections.registry import from_name
from pdverify.report.figures import draw
from pdverify.scenes import get_scene


def surface_nodes(order=1):
    """The surface node method's ``wave-bar`` extension at Taylor ``order`` (its role)."""
    return from_name("surface-nodes").build_for("wave-bar", None, {"order": order})


ROOT = Path(__file__).resolve().parents[2]
SCENE = "wave1d-surface-nodes"
PAPER_M = (10, 25, 100)  # seed 002, Fig. 5


@pytest.fixture(scope="module")
def scene():
    return get_scene(SCENE)


@pytest.fixture(scope="module")
def surface_runs(scene):
    return [scene.run("surface-nodes", {"m_ratio": m}) for m in PAPER_M]


def cli(*args):
    return subprocess.run([sys.executable, "-m", "pdverify", *args], capture_output=True,
                          text=True, timeout=120, cwd=ROOT)


def test_surface_nodes_converge_to_the_pd_series_at_first_order(surface_runs):
    # Convergence argument: the one-point quadrature of Eq. (3) misses the node's own cell,
    # psi - psi_h = k^2/(2m) (test_wave1d_operator), so the error falls like 1/m: fitted
    # order above 0.8 (the margin), strictly decreasing, and at m = 100 no more
    # than first order from m = 10 predicts (e(10) / 10).
    assert all(r.status == "ok" for r in surface_runs), [r.message for r in surface_runs]
    err = np.array([r.metrics["max_error_pct"] for r in surface_runs])
    order = -np.polyfit(np.log(PAPER_M), np.log(err), 1)[0]
    print(f"\nsurface-nodes max_error_pct at m = {PAPER_M}: {err}, fitted order {order:.3f}")
    assert np.all(np.diff(err) < 0)
    assert order > 0.8
    assert err[-1] <= err[0] / 10


def test_surface_nodes_beat_truncated_neighbourhoods_at_the_boundary(scene, surface_runs):
    # The issue: boundary_error_pct (nodes within 2 delta of an end) smaller with surface
    # nodes than with the uncorrected model at m = 25.
    none = scene.run("none", {"m_ratio": 25})
    sn = surface_runs[1]
    b_sn, b_none = sn.metrics["boundary_error_pct"], none.metrics["boundary_error_pct"]
    print(f"\nboundary_error_pct at m = 25: surface-nodes {b_sn:.4g}, none {b_none:.4g}")
    assert b_sn < b_none


def test_classical_series_is_no_reference_for_pd(surface_runs):
    # Fig. 5's point: with delta = 0.1 l the classical solution differs from the PD one far
    # more than the discretisation error at the finest grid.
    r = surface_runs[-1]
    assert r.metrics["classical_gap_pct"] > 10 * r.metrics["max_error_pct"]


def test_results_are_json_ready_and_sampled_at_the_papers_instants(surface_runs):
    r = surface_runs[0]
    json.dumps(r.to_json(), allow_nan=False)
    assert_allclose(r.diagnostics["sample_times"], [5e-5, 1e-4, 1.5e-4, 2e-4], rtol=1e-12)
    assert r.size["real_nodes"] == 100 and r.diagnostics["n_steps"] == 1000


def test_step_above_the_stability_limit_fails_the_run_naming_the_limit():
    # m = 10: the sharp limit 2/sqrt(lambda_max) from LAPACK's eigenvalues of the operator;
    # a step 2 % above it is refused through the CLI (exit 1, failed run), one 2 % below
    # it (but above the Gershgorin bound) runs.
    bar = wave_bar(1.0, 0.1, 10, 5000.0, surface_nodes(1))
    limit = 2 / np.sqrt(np.max(np.abs(np.linalg.eigvals(-bar.A.toarray()))))
    proc = cli("run", SCENE, "--set", "m_ratio=10", "--set", f"dt={1.02 * limit:.6e}")
    assert proc.returncode == 1, proc.stdout + proc.stderr
    msg = proc.stdout.splitlines()[0]
    assert "failed" in msg and "stability limit" in msg
    named = float(re.search(r"= ([0-9.e+-]+) s", msg).group(1))
    assert_allclose(named, limit, rtol=1e-5)  # printed to 6 digits
    ok = get_scene(SCENE).run("surface-nodes", {"m_ratio": 10, "dt": 0.98 * limit})
    assert ok.status == "ok", ok.message


BAD_INPUT = [
    (["--set", "horizon=0.3", "--set", "m_ratio=7"], "must divide length"),
    (["--set", "dt=1e-4"], "the first sampled instant"),
    (["--set", "order=50"], "order=50 needs"),
    (["--method", "none", "--set", "order=2"], "unknown key 'order'"),
]


@pytest.fixture(scope="module")
def bad_input_runs(cli_concurrently):
    """Every case in its own interpreter, one per core at a time (issue 32)."""
    return cli_concurrently([("run", SCENE, *args) for args, _ in BAD_INPUT], cwd=ROOT)


@pytest.mark.parametrize("args, phrase", BAD_INPUT)
def test_bad_input_exits_2_with_one_line(args, phrase, bad_input_runs):
    proc = bad_input_runs[("run", SCENE, *args)]
    assert proc.returncode == 2, proc.stdout + proc.stderr
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and phrase in lines[0], proc.stderr


def test_report_figures_are_drawn(scene, surface_runs, tmp_path):
    runs = surface_runs + [scene.run("none", {"m_ratio": 25})]
    files = draw(scene, runs, str(tmp_path))
    names = [f for f, _ in files]
    assert f"{SCENE}-convergence.png" in names
    assert f"{SCENE}-surface-nodes-order1-snapshots.png" in names
    assert all((tmp_path / f).stat().st_size > 0 for f in names)
