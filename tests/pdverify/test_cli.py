"""The command line: exit codes, one-line bad-input messages, run --json, list."""
import json
import subprocess
import sys
from pathlib import Path

import pytest

from pdverify.cli import main

ROOT = Path(__file__).resolve().parents[2]


def cli(*args, timeout=120):
    return subprocess.run([sys.executable, "-m", "pdverify", *args], capture_output=True,
                          text=True, timeout=timeout, cwd=ROOT)


BAD = [
    (["run", "bar1d-traction", "--set", "nu=0.5"], "nu"),
    (["run", "bar1d-traction", "--set", "nu=-1"], "nu"),
    (["run", "bar1d-traction", "--set", "m_ratio=0.5"], "m_ratio"),
    (["run", "bar1d-traction", "--method", "taylor-fictitious", "--set", "order=0"], "order"),
    (["run", "bar1d-traction", "--method", "taylor-fictitious", "--set", "order=10"], "order"),
    (["run", "bar1d-traction", "--set", "length=0"], "length"),
    (["run", "bar1d-traction", "--set", "length=-1"], "length"),
    (["run", "bar1d-traction", "--set", "area=0"], "area"),
    (["run", "bar1d-traction", "--set", "E=-1e9"], "E"),
    (["run", "bar1d-traction", "--set", "spacing=0"], "spacing"),
    (["run", "bar1d-traction", "--set", "spacing=0.03"], "spacing"),
    (["run", "bar1d-sine-load", "--set", "m_ratio=abc"], "m_ratio"),
    (["run", "no-such-scene"], "no-such-scene"),
    (["run", "bar1d-traction", "--method", "no-such-method"], "no-such-method"),
    (["run", "bar1d-traction", "--set", "colour=red"], "colour"),
    (["run", "bar1d-traction", "--method", "none", "--set", "order=2"], "order"),
    (["run", "bar1d-traction", "--set", "novalue"], "novalue"),
    (["report", "--only", "no-such-scene"], "no-such-scene"),
    (["report", "--jobs", "0"], "jobs"),
    (["frobnicate"], "frobnicate"),
]


@pytest.mark.parametrize("args, names", BAD, ids=[" ".join(a) for a, _ in BAD])
def test_bad_input_exits_2_with_one_line(args, names, capsys, tmp_path, monkeypatch):
    # DESIGN.md contract: exit 2, one line naming the offending input, no traceback,
    # before any work starts (no report folder is created).
    monkeypatch.chdir(tmp_path)
    assert main(args) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1, err
    assert names in err
    assert "Traceback" not in err
    assert not (tmp_path / "reports").exists()


def test_bad_input_in_a_subprocess():
    # end to end: the real interpreter exit code and stderr
    proc = cli("run", "bar1d-traction", "--set", "nu=0.7")
    assert proc.returncode == 2
    assert proc.stderr.strip().count("\n") == 0 and "nu" in proc.stderr
    err = cli("run", "nope").stderr
    assert "allowed" in err or "must" in err


def test_run_writes_schema_json(tmp_path):
    out = tmp_path / "r.json"
    proc = cli("run", "bar1d-traction", "--method", "taylor-fictitious", "--set", "order=1",
               "--json", str(out))
    assert proc.returncode == 0, proc.stderr
    doc = json.loads(out.read_text())
    assert doc["schema"] == "pdverify.results/1"
    assert set(doc) >= {"pdverify_version", "created", "machine", "runs"}
    run = doc["runs"][0]
    assert set(run) >= {"scene", "method", "params", "reference", "status", "message",
                        "metrics", "timings", "size"}
    assert run["params"]["order"] == 1 and run["status"] == "ok"
    assert set(run["timings"]) >= {"setup_s", "solve_s", "total_s"}
    assert run["metrics"]["max_error_pct"] < 1e-8  # seed 000 §5.1 (see test_bar1d)


def test_list_names_every_scene_and_method():
    proc = cli("list")
    assert proc.returncode == 0
    for sid in ("bar1d-traction", "bar1d-uniform-load", "bar1d-linear-load", "bar1d-sine-load",
                "bar1d-force-flux"):
        assert sid in proc.stdout
    assert "taylor-fictitious" in proc.stdout and "none" in proc.stdout


def test_numerical_failure_is_exit_1(monkeypatch, capsys):
    # numerical trouble is a failed run (exit 1) with a message saying what and where
    import pdverify.solvers.front as mod
    from pdverify.errors import NumericalError

    def boom(*a, **k):
        raise NumericalError("static solve: singular system of size 22")
    monkeypatch.setattr(mod, "solve_with_dirichlet", boom)   # the bar's none: elimination
    assert main(["run", "bar1d-traction"]) == 1
    assert "singular system" in capsys.readouterr().out
