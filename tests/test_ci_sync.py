"""The README's two commands and .ci/run stay in sync (the README must stay true)."""
import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def readme_commands():
    text = (ROOT / "README.md").read_text()
    quick = text.split("## Quickstart", 1)[1].split("\n## ", 1)[0]
    return re.findall(r"```(?:bash|sh)?\n(.*?)\n```", quick, re.S)


def test_quickstart_has_exactly_two_commands():
    blocks = readme_commands()
    assert len(blocks) == 2, blocks
    assert "python -m pdverify report" in blocks[0]
    assert "pytest" in blocks[1]


def test_ci_runs_the_readme_test_command_verbatim():
    test_cmd = readme_commands()[1].strip()
    ci = (ROOT / ".ci" / "run").read_text()
    assert test_cmd in ci.splitlines()


def test_ci_then_runs_the_slow_tier():
    # the README's command runs the fast tier; CI adds the tests marked slow after it,
    # as the README says, so that every test runs in CI
    lines = [x for x in (ROOT / ".ci" / "run").read_text().splitlines()
             if x.strip() and not x.startswith("#")]
    test_cmd = readme_commands()[1].strip()
    slow = "python -m pytest -q --runslow -m slow"
    assert lines.index(test_cmd) + 1 == lines.index(next(x for x in lines if x.startswith(slow)))
    assert lines[-1].startswith(slow)
    readme = (ROOT / "README.md").read_text()
    assert "`.ci/run`" in readme and slow in readme
    conftest = (ROOT / "tests" / "conftest.py").read_text()
    assert '"--runslow"' in conftest


def test_every_dependency_imported_is_declared():
    # a missing install step would pass here (same machine) but fail on a fresh one
    toml = (ROOT / "pyproject.toml").read_text()
    for pkg in ("numpy", "scipy", "scikit-fem", "meshio", "pyvista", "matplotlib", "sympy",
                "rich"):
        assert f'"{pkg}' in toml, pkg


def test_slow_tests_run_only_with_runslow(tmp_path):
    import shutil
    import subprocess
    import sys
    shutil.copy(ROOT / "tests" / "conftest.py", tmp_path / "conftest.py")
    (tmp_path / "test_tiers.py").write_text(
        "import pytest\n\n\ndef test_fast():\n    pass\n\n\n"
        "@pytest.mark.slow\ndef test_slow():\n    pass\n")

    import os
    # the tiers are the conftest's alone: the installed plugins (hypothesis, benchmark) are
    # not loaded, which costs 3 s of start-up per run here on a loaded machine (issue 32)
    env = {**os.environ, "PYTEST_DISABLE_PLUGIN_AUTOLOAD": "1"}

    def outcome(*args):
        run = subprocess.run([sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider",
                              "-W", "ignore::pytest.PytestUnknownMarkWarning", *args],
                             cwd=tmp_path, capture_output=True, text=True, env=env)
        return run.returncode, run.stdout.strip().splitlines()[-1]

    code, last = outcome()
    assert code == 0 and "1 passed, 1 skipped" in last, last
    code, last = outcome("--runslow")
    assert code == 0 and "2 passed" in last and "skipped" not in last, last
    code, last = outcome("--runslow", "-m", "slow")
    assert code == 0 and "1 passed, 1 deselected" in last, last


def test_the_tests_use_every_core_unless_asked_to_run_serially(tmp_path):
    # the README: the tests run on one pytest-xdist worker per core the process may use;
    # -n 0 and -p no:xdist run them serially. Each run here records where its test ran.
    import os
    import shutil
    import subprocess
    import sys
    shutil.copy(ROOT / "tests" / "conftest.py", tmp_path / "conftest.py")
    (tmp_path / "test_where.py").write_text(
        "import os\n\n\ndef test_where():\n"
        "    with open('where.txt', 'a') as fh:\n"
        "        fh.write(os.environ.get('PYTEST_XDIST_WORKER', 'serial') + '\\n')\n")
    env = {k: v for k, v in os.environ.items() if not k.startswith("PYTEST_XDIST")}
    env["PYTEST_DISABLE_PLUGIN_AUTOLOAD"] = "1"     # xdist alone, as in a clean install

    def where(*args):
        (tmp_path / "where.txt").unlink(missing_ok=True)
        run = subprocess.run([sys.executable, "-m", "pytest", "-p", "no:cacheprovider", *args],
                             cwd=tmp_path, capture_output=True, text=True, env=env)
        assert run.returncode == 0, run.stdout + run.stderr
        return (tmp_path / "where.txt").read_text().split(), run.stdout

    cores = len(os.sched_getaffinity(0))
    ran, out = where("-p", "xdist")
    if cores > 1:
        assert f"created: {cores}/{cores} workers" in out, out
        assert ran[0].startswith("gw"), ran
    else:
        assert ran == ["serial"]
    assert where("-p", "xdist", "-n", "0")[0] == ["serial"]
    assert where("-p", "no:xdist")[0] == ["serial"]
