"""The command line's habits (issue 34): close-match suggestions, a quiet closed pipe,
Ctrl-C without a worker traceback, compare's differing parameters, list SCENE / --json."""
import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from pdverify.cli import main
from pdverify.errors import did_you_mean

ROOT = Path(__file__).resolve().parents[2]


def cli(*args, timeout=120, cwd=ROOT):
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    return subprocess.run([sys.executable, "-m", "pdverify", *args], capture_output=True,
                          text=True, timeout=timeout, cwd=cwd, env=env)


# ------------------------------------------------------------------ close matches

def test_did_you_mean_names_the_close_matches_only():
    assert did_you_mean("bar1d-tracton", ["bar1d-traction", "plate2d-clamped"]) == \
        " (did you mean bar1d-traction?)"
    assert did_you_mean("ENERGY", ["energy", "volume"]) == " (did you mean energy?)"
    assert did_you_mean("zzz", ["energy", "volume"]) == ""


SUGGESTED = [
    (["run", "bar1d-tracton"], "unknown scene 'bar1d-tracton' (did you mean bar1d-traction"),
    (["run", "bar1d-traction", "--method", "taylor-fictitous"],
     "'taylor-fictitous' (did you mean taylor-fictitious?)"),
    (["run", "bar1d-traction", "--set", "lenght=2"], "'lenght' (did you mean length?)"),
    (["run", "plate2d-plane-strain", "--set", "plane=strian"], "(did you mean strain?)"),
    (["report", "--only", "bar1d-tracton"], "(did you mean bar1d-traction"),
    (["report", "--only", "bar1d-traction", "--method", "surface-node"],
     "(did you mean surface-nodes"),
    (["list", "bar1d-tracton"], "(did you mean bar1d-traction"),
    (["reprot"], "(did you mean report?)"),
    (["run", "bar1d-traction", "--metod", "none"], "(did you mean --method?)"),
]


@pytest.mark.parametrize("args, text", SUGGESTED, ids=[" ".join(a) for a, _ in SUGGESTED])
def test_a_mistyped_name_gets_its_close_match(args, text, capsys, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    assert main(args) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1, err
    assert text in err, err
    assert not (tmp_path / "reports").exists()


# ------------------------------------------------------------------ a closed pipe

@pytest.mark.parametrize("args", [["list"], ["list", "--json"]])
def test_a_closed_pipe_ends_quietly(args):
    # `pdverify list | head -1`: the reader goes away after one line; no traceback
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    proc = subprocess.Popen([sys.executable, "-m", "pdverify", *args], cwd=ROOT, env=env,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    proc.stdout.readline()
    proc.stdout.close()        # the reader is gone before the listing is complete
    err = proc.stderr.read().decode()
    proc.wait(timeout=60)
    assert "Traceback" not in err and "BrokenPipeError" not in err, err
    assert err == ""
    assert proc.returncode == 141


# ------------------------------------------------------------------ compare

def _doc(runs):
    return {"schema": "pdverify.results/1", "runs": runs}


def _run(params, value):
    return {"scene": "bar1d-traction", "method": "taylor-fictitious", "params": params,
            "status": "ok", "metrics": {"max_error_pct": value}}


def test_compare_shows_the_parameters_that_differ_from_the_defaults(tmp_path, capsys):
    from pdverify.scenes import get_scene
    from pdverify.results import _plain
    defaults = _plain(get_scene("bar1d-traction").resolve("taylor-fictitious", {}))
    order2 = {**defaults, "order": 2}
    base, new = tmp_path / "base.json", tmp_path / "new.json"
    base.write_text(json.dumps(_doc([_run(defaults, 1.0), _run(order2, 1.0)])))
    new.write_text(json.dumps(_doc([_run(defaults, 2.0), _run(order2, 3.0)])))
    assert main(["compare", str(base), str(new)]) == 1
    out = capsys.readouterr().out
    rows = [line for line in out.splitlines() if line.startswith("regression")]
    assert len(rows) == 2
    # the default run says so, the other names only its differing parameter
    assert "  defaults  " in rows[0] and "order=2" not in rows[0]
    assert "  order=2  " in rows[1]
    assert "spacing=" not in out and "influence=" not in out   # no default parameter


# ------------------------------------------------------------------ list SCENE, --json

def test_list_scene_shows_units_methods_and_why_not(capsys):
    assert main(["list", "plate2d-plane-strain"]) == 0
    out = capsys.readouterr().out
    assert out.startswith("plate2d-plane-strain: ")
    assert "    E=2e+11 Pa: Young's modulus [Pa]" in out
    assert "    spacing=0.02 m: " in out
    assert "    nu=0.3: " in out                 # dimensionless: no unit
    assert "    surface-nodes  - " in out and "        order=1: " in out
    assert "not offered here" in out and "homogenized: bond-based only" in out
    assert "bar1d-traction" not in out           # one scene only


def test_list_json_is_machine_readable(capsys):
    assert main(["list", "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    assert doc["schema"] == "pdverify.list/1"
    from pdverify.scenes import all_scenes
    assert [s["id"] for s in doc["scenes"]] == [s.id for s in all_scenes()]
    bar = next(s for s in doc["scenes"] if s["id"] == "bar1d-traction")
    params = {p["name"]: p for p in bar["params"]}
    assert params["E"]["unit"] == "Pa" and params["E"]["default"] == 1e9
    assert params["area"]["unit"] == "m^2" and params["nu"]["unit"] is None
    assert params["influence"]["choices"] and params["influence"]["unit"] is None
    assert "taylor-fictitious" in [m["name"] for m in bar["methods"]]
    assert bar["default_method"] == "none"
    assert main(["list", "bar1d-traction", "--json"]) == 0
    one = json.loads(capsys.readouterr().out)
    assert [s["id"] for s in one["scenes"]] == ["bar1d-traction"]


def test_every_physical_length_modulus_and_force_has_a_unit():
    # the units are data: the bracket of each declaration's doc
    from pdverify.scenes import all_scenes
    expect = {"E": "Pa", "spacing": "m", "horizon": "m", "lx": "m", "force": "N"}
    for scene in all_scenes():
        for p in scene.params:
            if p.name in expect and isinstance(p.default, float):
                assert p.unit == expect[p.name], (scene.id, p.name, p.doc)
