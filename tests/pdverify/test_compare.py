"""compare: regressions give exit 1, improvements and noise do not."""
import copy
import json

import pytest

from pdverify.cli import main
from pdverify.report import build_report


@pytest.fixture(scope="module")
def baseline(tmp_path_factory):
    out = tmp_path_factory.mktemp("base")
    assert build_report(out=str(out), only=["bar1d-traction", "bar1d-uniform-load"]) == 0
    return json.loads((out / "results.json").read_text())


def write(tmp_path, name, doc):
    path = tmp_path / name
    path.write_text(json.dumps(doc))
    return str(path)


def test_identical_files_pass(tmp_path, baseline, capsys):
    p = write(tmp_path, "a.json", baseline)
    assert main(["compare", p, p]) == 0


def test_grown_error_is_a_regression(tmp_path, baseline, capsys):
    new = copy.deepcopy(baseline)
    new["runs"][1]["metrics"]["max_error_pct"] = 0.5  # exact method now 0.5 % off
    assert main(["compare", write(tmp_path, "a.json", baseline), write(tmp_path, "b.json", new)]) == 1
    out = capsys.readouterr().out
    assert "regression" in out and "max_error_pct" in out and "bar1d-traction" in out


def test_shrunk_error_is_an_improvement(tmp_path, baseline, capsys):
    new = copy.deepcopy(baseline)
    new["runs"][0]["metrics"]["max_error_pct"] /= 2
    assert main(["compare", write(tmp_path, "a.json", baseline), write(tmp_path, "b.json", new)]) == 0
    assert "improved" in capsys.readouterr().out


def test_round_off_noise_is_not_a_regression(tmp_path, baseline):
    # machine-precision metrics may differ by factors across BLAS/platforms: below atol
    new = copy.deepcopy(baseline)
    new["runs"][1]["metrics"]["max_error_pct"] *= 3
    new["runs"][1]["metrics"]["rel_l2_error"] *= 3
    assert main(["compare", write(tmp_path, "a.json", baseline), write(tmp_path, "b.json", new)]) == 0


def test_missing_run_and_failed_run_are_regressions(tmp_path, baseline):
    a = write(tmp_path, "a.json", baseline)
    fewer = copy.deepcopy(baseline)
    fewer["runs"] = fewer["runs"][1:]
    assert main(["compare", a, write(tmp_path, "b.json", fewer)]) == 1
    failed = copy.deepcopy(baseline)
    failed["runs"][0]["status"] = "failed"
    assert main(["compare", a, write(tmp_path, "c.json", failed)]) == 1


def test_changed_non_error_metric_is_a_regression(tmp_path, baseline):
    new = copy.deepcopy(baseline)
    new["runs"][0]["metrics"]["reaction_force"] *= 1.01
    assert main(["compare", write(tmp_path, "a.json", baseline), write(tmp_path, "b.json", new)]) == 1


def test_bad_files_exit_2(tmp_path, capsys):
    assert main(["compare", str(tmp_path / "nope.json"), str(tmp_path / "nope.json")]) == 2
    junk = tmp_path / "junk.json"
    junk.write_text("{\"schema\": \"other\"}")
    assert main(["compare", str(junk), str(junk)]) == 2
    assert "schema" in capsys.readouterr().err


def test_a_parameter_added_at_its_default_keeps_the_baseline(tmp_path, baseline, capsys):
    # a baseline written before a scene gained a parameter: the new runs carry it at its
    # default (the old behaviour), so they still match, and the match is reported
    old = copy.deepcopy(baseline)
    for run in old["runs"]:
        assert run["params"].pop("influence") == "hyperbolic"
    assert main(["compare", write(tmp_path, "a.json", old), write(tmp_path, "b.json", baseline)]) == 0
    out = capsys.readouterr().out
    assert "0 regression(s), 0 other change(s)" in out
    assert f"{len(old['runs'])} baseline run(s) matched with parameters added since" in out
    assert "influence" in out


def test_a_parameter_added_off_its_default_does_not_match(tmp_path, baseline, capsys):
    old = copy.deepcopy(baseline)
    new = copy.deepcopy(baseline)
    for run in old["runs"]:
        run["params"].pop("influence")
    new["runs"][0]["params"]["influence"] = "gaussian"   # not the old behaviour
    assert main(["compare", write(tmp_path, "a.json", old), write(tmp_path, "b.json", new)]) == 1
    out = capsys.readouterr().out
    assert "missing" in out and "1 regression(s)" in out


def test_the_same_infinity_is_no_change(tmp_path, capsys):
    """Infinity against Infinity is equal (inf - inf is NaN, which passed no threshold);
    pdverify's own spelling of a non-finite metric, the string 'inf', counts as the float;
    infinity against the other infinity, or against a number, is a change (issue 31)."""
    from pdverify.compare import compare_docs

    def doc(value):
        return {"schema": "pdverify.results/1", "runs": [
            {"scene": "bar1d-traction", "method": "none", "params": {}, "status": "ok",
             "metrics": {"condition": value, "max_error_pct": 1.0}}]}
    inf = float("inf")
    assert compare_docs(doc(inf), doc(inf)) == []
    assert compare_docs(doc(-inf), doc(-inf)) == []
    assert compare_docs(doc("inf"), doc(inf)) == []
    assert [c.verdict for c in compare_docs(doc(inf), doc(-inf))] == ["regression"]
    assert [c.verdict for c in compare_docs(doc(inf), doc(5.0))] == ["regression"]
    a = tmp_path / "a.json"
    a.write_text(json.dumps(doc(inf)))           # written as the JSON literal Infinity
    assert "Infinity" in a.read_text()
    assert main(["compare", str(a), str(a)]) == 0
    assert "no changes beyond the thresholds" in capsys.readouterr().out
