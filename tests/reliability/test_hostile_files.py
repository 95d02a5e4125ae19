"""Issue 50, files: what pdverify reads is data, not instructions. A marker, an included
record or a previous report's results file that names a path outside its folder is
refused in one line; export is as safe as report (lock, staging folder, checks before
work, no solver memory estimate); score checks a file's size and encoding before reading
it; compare --against-published judges by the package's catalogue, never the file's."""
from __future__ import annotations

import errno
import json
import os

import pytest

from pdverify import outputs
from pdverify.cli import main
from pdverify.errors import InputError

SCENE = "bar1d-traction"          # the cheapest export: 20 nodes, analytic


def _export(out, fmt="csv"):
    return main(["export", SCENE, "--format", fmt, "--out", str(out)])


def _one_line(capsys) -> str:
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "Traceback" not in err, err
    return err


# ------------------------------------------------------------------------------ markers
@pytest.mark.parametrize("entry", ["../victim.txt", "ABSOLUTE"])
def test_an_export_marker_naming_a_file_outside_never_deletes_it(tmp_path, capsys, entry):
    victim = tmp_path / "victim.txt"
    victim.write_text("mine")
    out = tmp_path / "ex"
    assert _export(out) == 0
    marker = out / ".pdverify-export"
    doc = json.loads(marker.read_text())
    doc["entries"].append(str(victim) if entry == "ABSOLUTE" else entry)
    marker.write_text(json.dumps(doc))
    capsys.readouterr()
    assert _export(out) == 2
    err = _one_line(capsys)
    assert "is not a path inside" in err and "victim.txt" in err
    assert victim.read_text() == "mine"


def test_a_report_marker_naming_a_path_outside_makes_the_folder_foreign(tmp_path):
    folder = tmp_path / "rep"
    folder.mkdir()
    outputs.write_marker(str(folder), complete=True)
    doc = json.loads((folder / outputs.MARKER).read_text())
    doc["entries"].append("../../etc/passwd")
    (folder / outputs.MARKER).write_text(json.dumps(doc))
    state, why = outputs.folder_state(str(folder))
    assert state == "foreign" and "../../etc/passwd" in why


# ------------------------------------------------------------------------------ records
def _record(path, files):
    from pdverify.results import RunResult, write_results
    r = RunResult(scene=SCENE, method="external:x", params={}, reference="analytic",
                  metrics={"max_error_pct": 1.0}, files=list(files))
    write_results(path, [r])


def test_an_included_record_whose_files_point_outside_is_refused(tmp_path):
    from pdverify.exchange import load_external
    rec = tmp_path / "ext.json"
    _record(rec, ["../../victim.txt"])
    with pytest.raises(InputError, match=r"runs\[0\]\.files lists '../../victim.txt'"):
        load_external([str(rec)])


def test_report_failed_refuses_a_previous_results_file_with_files_outside(tmp_path):
    from pdverify.report.rerun import rerun_plan
    from pdverify.runner import plan
    out = tmp_path / "rep"
    out.mkdir()
    _record(out / "results.json", ["../victim.vtu"])
    outputs.write_marker(str(out), complete=True)
    with pytest.raises(InputError, match=r"runs\[0\]\.files lists '../victim.vtu'"):
        rerun_plan(plan(only=[SCENE], quick=True), str(out))


def test_kept_fields_are_never_read_or_written_outside_the_reports(tmp_path):
    from pdverify.report.files import keep_fields
    from pdverify.results import RunResult
    final, staging = tmp_path / "final", tmp_path / "staging"
    final.mkdir()
    staging.mkdir()
    (tmp_path / "victim-x.vtu").write_text("mine")
    r = RunResult(scene=SCENE, method="none", params={}, reference="analytic",
                  files=["../victim-x.vtu"])
    keep_fields([r], str(final), str(staging))
    assert r.files == [] and sorted(os.listdir(tmp_path)) == ["final", "staging",
                                                              "victim-x.vtu"]


# ------------------------------------------------------------------------------ export
def test_a_second_export_into_a_locked_folder_exits_2(tmp_path, capsys):
    from pdverify.outputs import output_lock      # report's lock is export's
    out = tmp_path / "ex"
    with output_lock(str(out)):
        assert _export(out) == 2
    assert "is being written by pdverify" in _one_line(capsys)
    assert not out.exists()


def test_a_failed_export_write_leaves_the_previous_export_whole(tmp_path, capsys,
                                                                 monkeypatch):
    out = tmp_path / "ex"
    assert _export(out) == 0
    before = {p: (out / p).read_bytes() for p in os.listdir(out)}

    def full(*a, **k):
        raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))
    monkeypatch.setattr("pdverify.decks.write_vtu", full)
    capsys.readouterr()
    assert _export(out, "vtu") == 1
    assert "previous export" in _one_line(capsys)
    assert {p: (out / p).read_bytes() for p in os.listdir(out)} == before
    assert [e for e in os.listdir(tmp_path) if "staging" in e] == []
    assert _export(out, "csv") == 0                       # nothing blocks the next one


def test_too_little_disk_is_exit_2_before_work(tmp_path, capsys, monkeypatch):
    out = tmp_path / "ex"
    assert _export(out) == 0
    before = sorted(os.listdir(out))
    monkeypatch.setattr(outputs, "free_bytes", lambda folder: 1000)
    capsys.readouterr()
    assert _export(out, "vtu") == 2
    err = _one_line(capsys)           # the export's own disk, before the cache's
    assert err.startswith("pdverify: error: --out") and "free on its disk" in err
    assert sorted(os.listdir(out)) == before


def test_a_long_name_or_a_file_as_parent_is_exit_2_before_work(tmp_path, capsys):
    assert _export(tmp_path / ("a" * 300)) == 2
    assert "above the file system's limit" in _one_line(capsys)
    (tmp_path / "plain").write_text("x")
    assert _export(tmp_path / "plain" / "ex") == 2
    assert "is a file, not a folder" in _one_line(capsys)


def test_export_is_not_refused_by_the_solvers_memory_estimate(tmp_path, monkeypatch):
    from pdverify import budget
    monkeypatch.setattr(budget, "memory_limit", lambda: (1000, "a test's limit"))
    assert main(["run", SCENE]) == 2                       # a solve is refused ...
    assert _export(tmp_path / "ex") == 0                   # ... export solves nothing


# ------------------------------------------------------------------------------ score
def test_score_refuses_a_file_too_large_for_the_export_before_reading(tmp_path, capsys):
    from pdverify import exchange
    SCORE_BYTES_FIXED = getattr(exchange, "SCORE_BYTES_FIXED", 64 << 20)
    big = tmp_path / "big.csv"
    with open(big, "wb") as fh:                            # sparse: no disk used
        fh.truncate(SCORE_BYTES_FIXED + (8 << 20))
    assert main(["score", SCENE, str(big), "--name", "c"]) == 2
    err = _one_line(capsys)
    assert f"holds {SCORE_BYTES_FIXED + (8 << 20)} bytes" in err and "at most" in err


def test_score_names_a_utf16_byte_order_mark(tmp_path, capsys):
    f = tmp_path / "u16.csv"
    f.write_bytes("x,ux\n0.025,1e-9\n".encode("utf-16"))
    assert main(["score", SCENE, str(f), "--name", "c"]) == 2
    assert "UTF-16 byte-order mark" in _one_line(capsys)


# ------------------------------------------------------------------------------ published
@pytest.fixture
def clamped_record(tmp_path):
    """A results file with the run of seed 003 Table 2, row 2 (sheet2d-clamped, none):
    our value as the full report gives it, 4.1374 MPa (a known difference, 4.14)."""
    from pdverify.results import RunResult, write_results
    from pdverify.scenes import get_scene
    from pdverify.scenes.sheets import PAPER, TABLE2_GRID
    scene = get_scene("sheet2d-clamped")
    params = scene.resolve("none", {**PAPER, **TABLE2_GRID, "node_volumes": "partial"})
    r = RunResult(scene=scene.id, method="none", params=params, reference="fem",
                  metrics={"tensile_stress_mpa": 4.1374},
                  published=[p.entry() for p in
                             scene.published_for("none", params).values()])
    path = tmp_path / "r.json"
    write_results(path, [r])
    return path


def _edit(path, fn):
    doc = json.loads(path.read_text())
    fn(doc["runs"][0])
    path.write_text(json.dumps(doc))


def test_a_known_difference_still_bounds_ours(clamped_record, capsys):
    assert main(["compare", "--against-published", str(clamped_record)]) == 0
    assert "1 known differences" in capsys.readouterr().out
    _edit(clamped_record, lambda r: r["metrics"].update(tensile_stress_mpa=999.0))
    assert main(["compare", "--against-published", str(clamped_record)]) == 1
    assert "ours reproduces 4.14 within 0.005" in capsys.readouterr().out


def test_a_tolerance_widened_in_the_file_has_no_effect(clamped_record, capsys):
    def widen(r):
        r["metrics"]["tensile_stress_mpa"] = 999.0
        for e in r["published"]:
            e.update(tolerance=1e9, known_difference=False, target=999.0, reproduced=999.0)
    _edit(clamped_record, widen)
    assert main(["compare", "--against-published", str(clamped_record)]) == 1
    assert "1 fail" in capsys.readouterr().out


@pytest.mark.parametrize("field,value,needle", [
    ("tolerance", float("nan"), "tolerance is nan"),
    ("tolerance", -1.0, "a tolerance is 0 or more"),
    ("target", 10 ** 400, "an integer of 401 digits")])
def test_absurd_numbers_of_an_entry_are_one_line(clamped_record, capsys, field, value,
                                                 needle):
    _edit(clamped_record, lambda r: r["published"][0].update({field: value}))
    assert main(["compare", "--against-published", str(clamped_record)]) == 2
    assert needle in _one_line(capsys)
