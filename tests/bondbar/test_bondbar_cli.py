"""Seed-004 scenes through ``python -m pdverify`` in a subprocess: exit codes, one-line errors."""
import json
import pathlib
import subprocess
import sys

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]


def pdverify(*args, timeout=120):
    return subprocess.run([sys.executable, "-m", "pdverify", *args], cwd=ROOT,
                          capture_output=True, text=True, timeout=timeout)


@pytest.mark.parametrize("args, fragment", [
    (["bar1d-homogenization", "--method", "homogenized", "--set", "horizon_ratio=1.5",
      "--set", "nodes=5"], "m >= 2"),
    (["bar1d-homogenization", "--set", "nodes=7"], "nodes=7 must be >= 9"),
    (["bar1d-constraints", "--set", "end_weight=quarter"], "allowed: full, half"),
    (["bar1d-homogenization", "--method", "homogenized", "--set", "horizon_ratio=3.5",
      "--set", "end_weight=half", "--set", "nodes=7"], "no factors"),
    (["bar1d-vibration", "--set", "horizon_ratio=x"], "not a valid float"),
])
def test_bad_input_exits_2_with_one_line(args, fragment):
    done = pdverify("run", *args)
    assert done.returncode == 2
    lines = done.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("pdverify: error:") and fragment in lines[0]
    assert done.stdout == ""


def test_unstable_time_step_is_a_failed_run_exit_1():
    done = pdverify("run", "bar1d-vibration", "--method", "homogenized", "--set", "dt_factor=1.5")
    assert done.returncode == 1
    assert "failed" in done.stdout and "exceeds the stability limit" in done.stdout


def test_run_writes_results_json(tmp_path):
    out = tmp_path / "r.json"
    done = pdverify("run", "bar1d-homogenization", "--method", "homogenized", "--set",
                    "nodes=1001", "--json", str(out))
    assert done.returncode == 0, done.stderr
    run = json.loads(out.read_text())["runs"][0]
    assert run["status"] == "ok" and abs(run["metrics"]["strain_factor"] - 1) <= 1e-12


def test_list_shows_the_three_scenes():
    done = pdverify("list")
    assert done.returncode == 0
    for scene in ("bar1d-homogenization", "bar1d-constraints", "bar1d-vibration"):
        assert scene in done.stdout
    assert "method homogenized" in done.stdout
