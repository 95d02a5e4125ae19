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


def test_every_dependency_imported_is_declared():
    # a missing install step would pass here (same machine) but fail on a fresh one
    toml = (ROOT / "pyproject.toml").read_text()
    for pkg in ("numpy", "scipy", "scikit-fem", "meshio", "pyvista", "matplotlib", "sympy",
                "rich"):
        assert f'"{pkg}' in toml, pkg
