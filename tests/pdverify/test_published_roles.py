"""Issue 53: published entries of three kinds (values the paper computes, setups it
states, claims in words), counted apart by compare --against-published and the pages."""
from __future__ import annotations

import json

import pytest

from pdverify import published
from pdverify.cli import main
from pdverify.scenes.base import Published


def test_role_defaults_and_explicit():
    assert Published("m", 1.25, "s").entry()["role"] == "value"
    assert Published("m", "< 2", "s").entry()["role"] == "claim"
    assert Published("m", "non-zero", "s", bound=1e-12, check="above",
                     tolerance_source="t").entry()["role"] == "claim"
    assert Published("m", 102, "s", exact=True, role="setup").entry()["role"] == "setup"
    with pytest.raises(ValueError, match="role='spam'"):
        Published("m", 1, "s", exact=True, role="spam").entry()


def _run(metric, value, role, check="equal", target=None, verdict_ok=True):
    target = value if target is None else target
    return {"metric": metric, "value": value, "source": "s", "kind": "printed",
            "check": check, "target": target, "tolerance": 0.0,
            "tolerance_source": "t", "role": role}


def test_compare_against_published_counts_roles_apart(tmp_path, capsys, monkeypatch):
    # three entries that hold, one of each role: the summary counts one reproduced value,
    # one setup "checked, not counted as reproduced" and one claim held; the entries are
    # the package's (the scene's catalogue), the file gives our values only
    from pdverify.scenes import get_scene
    monkeypatch.setattr(get_scene("bar1d-vibration"), "published", (
        Published("a", 1.0, "s", exact=True), Published("b", 102, "s", exact=True,
                                                        role="setup"),
        Published("c", "< 1", "s")))
    run = {"scene": "bar1d-vibration", "method": "none", "params": {}, "status": "ok",
           "metrics": {"a": 1.0, "b": 102, "c": 0.5},
           "published": [_run("a", 1.0, "value"), _run("b", 102, "setup"),
                         _run("c", "< 1", "claim", check="below", target=1.0)]}
    from pdverify.results import document
    doc = document([])
    doc["runs"] = [run]
    path = tmp_path / "r.json"
    path.write_text(json.dumps(doc))
    assert main(["compare", "--against-published", str(path)]) == 0
    out = capsys.readouterr().out
    assert ("values the papers compute: 1 (1 reproduced, 0 known differences, 0 fail); "
            "setups they state: 1 (1 checked, not counted as reproduced, 0 fail); claims "
            "in words: 1 (1 hold") in out
    assert out.splitlines()[1].split()[1] == "value"          # the table's role column


def test_role_of_an_old_results_file_entry():
    # a results file written before roles: a bound or statement is a claim, an equality
    # a value (a setup cannot be told from the file alone)
    assert published.role_of({"check": "equal"}) == "value"
    assert published.role_of({"check": "below"}) == "claim"
    assert published.role_of({"check": "none"}) == "claim"
