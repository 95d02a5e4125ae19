"""Bring your own method: a plugin package (tests/plugins/demo_plugin) registers a
correction through the entry point group ``pdverify.methods`` and runs in ``list``,
``run`` and ``report`` like a built-in one."""
import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

PLUGIN = Path(__file__).resolve().parents[1] / "plugins" / "demo_plugin"


def _install(target: Path) -> str:
    """pip install --target (the user's way); offline, where pip cannot fetch the build
    backend, lay out what that install writes: the package and its dist-info with the
    entry points."""
    r = subprocess.run([sys.executable, "-m", "pip", "install", "-q", "--no-deps",
                        "--target", str(target), str(PLUGIN)], capture_output=True, text=True)
    if r.returncode == 0:
        return "pip"
    shutil.copytree(PLUGIN / "pdverify_demo_plugin", target / "pdverify_demo_plugin")
    info = target / "pdverify_demo_plugin-0.1.0.dist-info"
    info.mkdir()
    (info / "METADATA").write_text("Metadata-Version: 2.1\nName: pdverify-demo-plugin\n"
                                   "Version: 0.1.0\n")
    (info / "entry_points.txt").write_text(
        "[pdverify.methods]\ndemo-uniform = pdverify_demo_plugin:METHOD\n")
    return "dist-info"


@pytest.fixture(scope="module")
def plugin_env(tmp_path_factory):
    target = tmp_path_factory.mktemp("site")
    _install(target)
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join([str(target), env.get("PYTHONPATH", "")])
    return env


def cli(env, *args):
    return subprocess.run([sys.executable, "-m", "pdverify", *args], capture_output=True,
                          text=True, env=env)


def test_plugin_in_list(plugin_env):
    r = cli(plugin_env, "list")
    assert r.returncode == 0, r.stderr
    assert "method demo-uniform" in r.stdout
    assert "bond method demo-uniform: plugin pdverify_demo_plugin:METHOD" in r.stdout
    matrix = r.stdout.split("method x scene:\n", 1)[1].splitlines()
    head = matrix[0]
    row = next(line for line in matrix if line.startswith("stiffness2d-sheet "))
    i = head.index("demo-uniform")
    assert row[i:i + len("demo-uniform")].strip() == "x"


def test_plugin_in_run_and_report(plugin_env, tmp_path):
    """Factor 1 is the uncorrected model, so the plugin's run reproduces ``none`` to the
    last bit; factor 2 doubles every bond, so W_i / W_bulk = 2 in the bulk."""
    r = cli(plugin_env, "run", "stiffness2d-sheet", "--method", "demo-uniform",
            "--set", "factor=2", "--set", "spacing=0.0025")
    assert r.returncode == 0, r.stderr
    assert "interior_energy_error_pct 100" in r.stdout
    out = tmp_path / "rep"
    r = cli(plugin_env, "report", "--only", "stiffness2d-sheet", "--out", str(out))
    assert r.returncode == 0, r.stderr
    runs = json.loads((out / "results.json").read_text())["runs"]
    by = {x["method"]: x for x in runs}
    assert by["demo-uniform"]["status"] == "ok"
    assert by["demo-uniform"]["metrics"] == by["none"]["metrics"]
    assert "demo-uniform" in (out / "index.html").read_text()


def test_without_the_plugin_the_method_is_bad_input():
    r = subprocess.run([sys.executable, "-m", "pdverify", "run", "stiffness2d-sheet",
                        "--method", "demo-uniform"], capture_output=True, text=True)
    assert r.returncode == 2
    assert "not supported by this scene; allowed: none, energy-directional" in r.stderr


def test_broken_plugin_is_listed_not_fatal(monkeypatch):
    import importlib.metadata as md

    from pdverify.corrections import registry

    class EP:
        name, value, group = "broken", "no_such_module:X", registry.ENTRY_POINT_GROUP

        def load(self):
            raise ImportError("No module named 'no_such_module'")

    monkeypatch.setattr(md, "entry_points", lambda group=None: [EP()])
    registry.reload()
    try:
        methods = registry.bond_methods()
        assert {"energy", "volume"} <= set(methods)
        assert "No module named" in registry.BROKEN["broken"]
    finally:
        monkeypatch.undo()
        registry.reload()
