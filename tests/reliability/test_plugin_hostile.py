"""Hostile plugins, round four (issue 50): a plugin that exits (``sys.exit``,
``os._exit``), signals itself, hangs in a check, its closure or its import, or whose
``params_for`` raises, is a broken listing, a one-line refusal or a failed run naming it
and its entry point, within the plugin time limit; a report that does not select a plugin
never calls it; a SIGTERM ends pdverify with 143; control characters read from files reach
the terminal escaped."""
import json
import os
import signal
import subprocess
import sys
import time
from concurrent.futures import ThreadPoolExecutor

import pytest

import plugin_site

ENTRY_POINTS = {
    "pdverify_hostile": [f"{name} = pdverify_hostile:{attr}" for name, attr in (
        ("role-check-exit", "ROLE_CHECK_EXIT"), ("check-hang", "CHECK_HANG"),
        ("closure-os-exit", "CLOSURE_OS_EXIT"), ("closure-signal", "CLOSURE_SIGNAL"),
        ("closure-hang", "CLOSURE_HANG"), ("called", "CALLED"),
        ("params-for-raises", "PARAMS_FOR_RAISES"), ("escapes", "ESCAPES"),
        ("esc\x1b[2Jname", "MISSING"))],
    "pdverify_hang_at_import": ["hang-at-import = pdverify_hang_at_import:METHOD"],
}
#: the plugin time limit of these tests (s): short, so that the hangs cost little; the
#: default (60 s) is the same code path with another number
LIMIT = 2
ENTRY = "pdverify_hostile"


@pytest.fixture(scope="module")
def plugin_env(tmp_path_factory):
    """The packages and their dist-info, as ``pip install --target`` lays them out."""
    return plugin_site.install(tmp_path_factory.mktemp("site"), ENTRY_POINTS, PDVERIFY_PLUGIN_TIMEOUT=LIMIT)


def cli(env, *args, cwd=None):
    t0 = time.monotonic()
    r = subprocess.run([sys.executable, "-m", "pdverify", *args], capture_output=True,
                       text=True, env=env, timeout=300, cwd=cwd)
    r.seconds = time.monotonic() - t0
    return r


RUNS = {
    "role-check-exit": (2, "plugin method role-check-exit (pdverify_hostile:ROLE_CHECK_EXIT): "
                           "its check raised SystemExit(3)"),
    "check-hang": (2, "plugin method check-hang (pdverify_hostile:CHECK_HANG): its check did "
                      f"not return within {LIMIT} s"),
    "closure-os-exit": (1, "plugin method closure-os-exit (pdverify_hostile:CLOSURE_OS_EXIT): "
                           "its closure ended the run's process (exit code 3)"),
    "closure-signal": (1, "plugin method closure-signal (pdverify_hostile:CLOSURE_SIGNAL): "
                          "its closure ended the run's process (signal SIGTERM)"),
    "closure-hang": (1, "plugin method closure-hang (pdverify_hostile:CLOSURE_HANG): its "
                        f"closure did not return within {LIMIT} s"),
    "params-for-raises": (2, "method 'params-for-raises' is a plugin that failed to load: "
                             "pdverify_hostile:PARAMS_FOR_RAISES: RuntimeError: params_for "
                             "is broken"),
    "hang-at-import": (2, "method 'hang-at-import' is a plugin that failed to load: "
                          f"pdverify_hang_at_import:METHOD: did not return within {LIMIT} s"),
    "none": (0, "bar1d-traction --method none (reference: analytic): ok"),
}


#: the scene of a method's run where not bar1d-traction
SCENE = {"role-check-exit": "wave1d-surface-nodes"}


@pytest.fixture(scope="module")
def runs(plugin_env):
    with ThreadPoolExecutor(2) as pool:
        done = pool.map(lambda m: cli(plugin_env, "run", SCENE.get(m, "bar1d-traction"),
                                      "--method", m), RUNS)
        return dict(zip(RUNS, done))


@pytest.mark.parametrize("method", list(RUNS))
def test_a_hostile_plugin_is_a_named_failure(runs, method):
    """Each class: one line naming the plugin and its entry point (a refusal, exit 2, or
    a failed run, exit 1), never silent, hung or an internal error; the built-in method
    runs beside them."""
    code, needle = RUNS[method]
    r = runs[method]
    assert r.returncode == code, (r.returncode, r.stdout, r.stderr)
    assert "Traceback" not in r.stderr and "internal error" not in r.stdout + r.stderr
    first = (r.stderr if code == 2 else r.stdout).splitlines()[0]
    assert needle in first, first
    if code == 2:
        assert r.stderr.count("\n") == 1 and r.stdout == ""
    # two plugins hang at load (one at import, one in params_for), each once; the hang in
    # a call waits once more: a few limits, never the whole time out
    assert r.seconds < 6 * LIMIT + 60, r.seconds


def test_list_names_plugins_that_hang_or_raise_at_load(plugin_env):
    r = cli(plugin_env, "list")
    assert r.returncode == 0, r.stderr
    out = r.stdout
    assert ("plugin hang-at-import: failed to load (pdverify_hang_at_import:METHOD: did not "
            f"return within {LIMIT} s") in out
    assert ("plugin params-for-raises: failed to load (pdverify_hostile:PARAMS_FOR_RAISES: "
            "RuntimeError: params_for is broken)") in out
    assert "bond method energy: built-in" in out
    # control characters from the entry points' names and descriptions: escaped
    assert "\x1b" not in out and "\x1b" not in r.stderr
    assert "plugin esc\\x1b[2Jname: failed to load" in out
    assert "evil\\x1b[2J\\x1b[31m red" in out


def test_a_report_that_does_not_select_a_plugin_never_calls_it(plugin_env, tmp_path):
    """``report --method none``: the plugins' checks (one of them hangs, one leaves a trace)
    are never called; the report is whole and its runs are ok."""
    env = dict(plugin_env, PDVERIFY_TEST_CALLED=str(tmp_path / "called.txt"))
    r = cli(env, "report", "--quick", "--only", "bar1d-traction", "--method", "none",
            "--jobs", "1", "--out", str(tmp_path / "rep"))
    assert r.returncode == 0, r.stderr[-2000:]
    assert not (tmp_path / "called.txt").exists()
    runs = json.loads((tmp_path / "rep" / "results.json").read_text())["runs"]
    assert {x["method"] for x in runs} == {"none"}
    assert all(x["status"] == "ok" for x in runs)


def test_a_plugin_in_a_report_fails_its_own_runs_only(plugin_env, tmp_path):
    """``report --method`` with a plugin that exits in its closure and one that hangs in
    its check: their runs fail naming them, the built-in's runs are ok, exit 1."""
    r = cli(plugin_env, "report", "--quick", "--only", "bar1d-traction", "--method", "none",
            "closure-os-exit", "check-hang", "--jobs", "2", "--out", str(tmp_path / "rep"))
    assert r.returncode == 1, r.stderr[-2000:]
    runs = json.loads((tmp_path / "rep" / "results.json").read_text())["runs"]
    by = {}
    for x in runs:
        by.setdefault(x["method"], []).append(x)
    assert all(x["status"] == "ok" for x in by["none"])
    assert all("its closure ended the run's process (exit code 3)" in x["message"]
               for x in by["closure-os-exit"])
    assert all(f"its check did not return within {LIMIT} s" in x["message"]
               for x in by["check-hang"])


def test_sigterm_ends_run_with_143(tmp_path):
    """A SIGTERM at any time into ``run`` (imports, resolve, the solve) ends it with 143,
    never by SIGALRM (-14: the re-check timer of a stop that landed inside an import,
    left armed after main returned)."""
    env = dict(os.environ, PDVERIFY_CACHE_DIR=str(tmp_path / "cache"))
    seen = []
    for delay in (0.3, 0.5, 0.8, 1.0, 1.2, 1.5):
        p = subprocess.Popen([sys.executable, "-m", "pdverify", "run", "stiffness2d-sheet"],
                             stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env)
        time.sleep(delay)
        p.send_signal(signal.SIGTERM)
        out, err = p.communicate(timeout=120)
        seen.append((delay, p.returncode, err[-200:]))
        if p.returncode == 0:      # it finished first
            continue
        if p.returncode == -signal.SIGTERM:
            continue               # the default action: before the interpreter ran pdverify,
            # or while it exited after the output (a shell shows both as 143)
        assert p.returncode == 143, seen
        assert err.rstrip().endswith("pdverify: stopped by SIGTERM"), seen
        assert "Traceback" not in err
    assert any(code == 143 for _, code, _ in seen), seen


def test_compare_escapes_control_characters_of_a_results_file(tmp_path):
    env = dict(os.environ, PDVERIFY_CACHE_DIR=str(tmp_path / "cache"))
    a, b = tmp_path / "a.json", tmp_path / "b.json"
    r = cli(env, "run", "bar1d-traction", "--json", str(a))
    assert r.returncode == 0, r.stderr
    data = json.loads(a.read_text())
    evil = dict(data["runs"][0], method="none\x1b[2J\x1b[31m")
    data["runs"].append(evil)
    b.write_text(json.dumps(data))
    r = cli(env, "compare", str(a), str(b))
    assert "\x1b" not in r.stdout + r.stderr
    assert "none\\x1b[2J\\x1b[31m" in r.stdout
