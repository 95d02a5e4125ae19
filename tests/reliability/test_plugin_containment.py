"""Plugins are contained (issue 31): a plugin that exits at import, in its closure, in a
function its closure hands the model or in a parameter check, or whose parameter is named
like a scene's, is listed as broken or makes its own run fail naming it; pdverify, its
built-in methods and the other runs of a report go on."""
import json
import subprocess
import sys

import pytest

import plugin_site

ENTRY_POINTS = {
    "pdverify_exit_at_import": ["exit-at-import = pdverify_exit_at_import:METHOD"],
    "pdverify_misbehaving": [f"{name} = pdverify_misbehaving:{attr}" for name, attr in (
        ("closure-exit", "CLOSURE_EXIT"), ("factor-exit", "FACTOR_EXIT"),
        ("not-a-closure", "NOT_A_CLOSURE"), ("spacing-clash", "SPACING_CLASH"),
        ("check-exit", "CHECK_EXIT"), ("not-a-method", "NOT_A_METHOD"))],
}


@pytest.fixture(scope="module")
def plugin_env(tmp_path_factory):
    """The two packages and their dist-info, as ``pip install --target`` lays them out."""
    return plugin_site.install(tmp_path_factory.mktemp("site"), ENTRY_POINTS)


def cli(env, *args, cwd=None):
    return subprocess.run([sys.executable, "-m", "pdverify", *args], capture_output=True,
                          text=True, env=env, timeout=300, cwd=cwd)


#: the ``run`` commands of the tests below, each a process of its own (the test of each
#: reads its own): started together, one per core (conftest's cli_concurrently; issue 32)
EXIT_IN_A_RUN = [
    ("closure-exit", "plugin method closure-exit (pdverify_misbehaving:CLOSURE_EXIT): its "
                     "closure raised SystemExit(0)"),
    ("factor-exit", "plugin method factor-exit (pdverify_misbehaving:FACTOR_EXIT): "
                    "force_factor raised SystemExit(4)"),
    ("not-a-closure", "its closure returned str, not a pdverify Closure"),
]
BROKEN_RUN = [
    ("exit-at-import", "stiffness2d-sheet/exit-at-import: the plugin failed to load: "
                       "pdverify_exit_at_import:METHOD: SystemExit(3) at import"),
    ("spacing-clash", "stiffness2d-sheet/spacing-clash: the plugin failed to load: plugin "
                      "pdverify_misbehaving:SPACING_CLASH: its parameter 'spacing' is a "
                      "parameter of scene"),
]
REFUSED = [
    (["--method", "check-exit", "--set", "gain=2"],
     "plugin method check-exit (pdverify_misbehaving:CHECK_EXIT): the check of its "
     "parameter gain raised SystemExit(5)"),
]
RUNS = ([("run", "stiffness2d-sheet", "--method", m, "--set", "spacing=0.0025")
         for m, _ in EXIT_IN_A_RUN]
        + [("run", "stiffness2d-sheet", "--set", "spacing=0.0025")]
        + [("run", "stiffness2d-sheet", "--method", m) for m, _ in BROKEN_RUN]
        + [("run", "stiffness2d-sheet", *argv) for argv, _ in REFUSED])


@pytest.fixture(scope="module")
def runs(plugin_env, cli_concurrently):
    return cli_concurrently(RUNS, env=plugin_env, timeout=300)


def test_list_names_every_broken_plugin_and_goes_on(plugin_env):
    r = cli(plugin_env, "list")
    assert r.returncode == 0, r.stderr
    out = r.stdout
    assert ("plugin exit-at-import: failed to load (pdverify_exit_at_import:METHOD: "
            "SystemExit(3) at import)") in out
    assert "plugin spacing-clash: failed to load (plugin pdverify_misbehaving:SPACING_CLASH: " \
           "its parameter 'spacing' is a parameter of scene" in out
    assert "plugin not-a-method: failed to load (pdverify_misbehaving:NOT_A_METHOD: " \
           "TypeError: object is not a pdverify Treatment)" in out
    # the scenes keep their own spacing default (0.001 m on the sheet), not the plugin's 0.5
    assert "params: width=0.05 m, length=0.1 m, spacing=0.001 m" in out
    assert "bond method energy: built-in" in out and "bond method closure-exit: plugin" in out


@pytest.mark.parametrize("method, needle", EXIT_IN_A_RUN)
def test_a_plugin_that_exits_in_a_run_is_a_failed_run(runs, method, needle):
    r = runs[("run", "stiffness2d-sheet", "--method", method, "--set", "spacing=0.0025")]
    assert r.returncode == 1, (r.stdout, r.stderr)
    first = r.stdout.splitlines()[0]
    assert first.startswith(f"stiffness2d-sheet --method {method} (reference: analytic): "
                            "failed (stiffness2d-sheet/"), first
    assert needle in first, first


def test_built_in_methods_run_beside_broken_plugins(runs):
    r = runs[("run", "stiffness2d-sheet", "--set", "spacing=0.0025")]
    assert r.returncode == 0, r.stderr
    assert ": ok" in r.stdout.splitlines()[0]


@pytest.mark.parametrize("method, needle", BROKEN_RUN)
def test_a_run_of_a_broken_plugin_is_a_failed_run_naming_it(runs, method, needle):
    r = runs[("run", "stiffness2d-sheet", "--method", method)]
    assert r.returncode == 1, (r.stdout, r.stderr)
    first = r.stdout.splitlines()[0]
    assert ": failed (" in first and needle in first, first


@pytest.mark.parametrize("argv, needle", REFUSED)
def test_a_broken_plugin_is_refused_in_one_line(runs, argv, needle):
    r = runs[("run", "stiffness2d-sheet", *argv)]
    assert r.returncode == 2, (r.stdout, r.stderr)
    assert r.stderr.count("\n") == 1 and needle in r.stderr, r.stderr
    assert r.stdout == ""


def test_a_plugin_exit_in_a_report_worker_is_a_failed_run(plugin_env, tmp_path):
    """Two worker processes: the plugins' SystemExit must come back as failed runs naming
    the plugin, not as a worker that died ("native code"), and the built-ins stay ok."""
    out = tmp_path / "rep"
    r = cli(plugin_env, "report", "--quick", "--only", "bar1d-traction", "--jobs", "2",
            "--out", str(out))
    assert r.returncode == 1, r.stderr           # failed runs: exit 1
    runs = {x["method"]: x for x in json.loads((out / "results.json").read_text())["runs"]}
    for method, what in (("closure-exit", "its closure raised SystemExit(0)"),
                         ("factor-exit", "force_factor raised SystemExit(4)")):
        assert runs[method]["status"] == "failed"
        assert f"plugin method {method}" in runs[method]["message"]
        assert what in runs[method]["message"]
        assert "native code" not in runs[method]["message"]
    assert runs["none"]["status"] == "ok" and runs["energy"]["status"] == "ok"
    assert "spacing-clash" not in runs and "exit-at-import" not in runs


def test_scene_run_contains_a_system_exit(monkeypatch):
    """The last guard, for code outside the plugin guards: a SystemExit inside ``solve``
    is a failed run (a report's worker would otherwise end)."""
    from pdverify.scenes import get_scene
    scene = get_scene("bar1d-traction")

    def solve(method, params, timer):
        raise SystemExit(7)

    monkeypatch.setattr(scene, "solve", solve)
    res = scene.run("none", {})
    assert res.status == "failed"
    assert res.message == "bar1d-traction/none: the run tried to end the process (SystemExit(7))"
