"""Seed 001 scenes through the CLI: bad input exits 2 with one line; the time budget."""
import os
import subprocess
import sys
import time

import pytest

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


def _cli(*args, timeout=120):
    env = dict(os.environ, PYTHONPATH=ROOT)
    return subprocess.run([sys.executable, "-m", "pdverify", *args], cwd=ROOT, env=env,
                          capture_output=True, text=True, timeout=timeout)


UNSUPPORTED = [
    ("body3d-manufactured", ["--method", "surface-nodes", "--set", "order=4"], "order"),
    ("plate2d-plane-strain", ["--method", "surface-nodes", "--set", "order=0"], "order"),
    ("body3d-traction", ["--set", "geometry=cylinder"], "geometry"),
    ("plate2d-plane-strain", ["--method", "surface-nodes", "--set", "m_ratio=2.5"], "m_ratio"),
    ("body3d-traction", ["--set", "spacing=0.03"], "spacing"),
    ("body3d-manufactured", ["--method", "surface-nodes", "--set", "order=3", "--set",
                             "lz=0.2"], "l_z"),
    ("plate2d-plane-strain", ["--set", "plane=axisymmetric"], "plane"),
    ("body3d-manufactured", ["--method", "none", "--set", "load_point=edge"], "load_point"),
    ("plate2d-plane-strain", ["--set", "quadrature=exact"], "quadrature"),
    ("body3d-manufactured", ["--set", "surface_load=edge"], "surface_load"),
]


@pytest.fixture(scope="module")
def unsupported_runs(cli_concurrently):
    """Every case in its own interpreter, one per core at a time (issue 32)."""
    return cli_concurrently([("run", scene, *args) for scene, args, _ in UNSUPPORTED],
                            env=dict(os.environ, PYTHONPATH=ROOT), cwd=ROOT)


@pytest.mark.parametrize("scene,args,needle", UNSUPPORTED)
def test_unsupported_input_exits_2_with_one_line(scene, args, needle, unsupported_runs):
    r = unsupported_runs[("run", scene, *args)]
    assert r.returncode == 2, r.stderr
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1 and needle in lines[0], r.stderr
    assert "Traceback" not in r.stderr


def test_plate_runs_through_the_cli(tmp_path):
    out = tmp_path / "plate.json"
    r = _cli("run", "plate2d-plane-strain", "--method", "surface-nodes", "--json", str(out))
    assert r.returncode == 0, r.stderr
    assert "max_error_v_pct" in r.stdout and out.exists()


@pytest.mark.bench
def test_manufactured_order_3_within_60_s_end_to_end():
    """Issue 7 speed budget: body3d-manufactured, N = 3, default size, < 60 s on 2 cores."""
    t0 = time.perf_counter()
    r = _cli("run", "body3d-manufactured", "--method", "surface-nodes", "--set", "order=3",
             timeout=300)
    elapsed = time.perf_counter() - t0
    print(r.stdout)
    print(f"end to end: {elapsed:.1f} s")
    assert r.returncode == 0, r.stderr
    assert elapsed < 60.0
