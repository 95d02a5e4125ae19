"""The report sets each run's fields aside on disk (pdverify.spill, issue 32): the report
process holds one scene's or one run's fields at a time, and the outputs are the same."""
import os

import numpy as np
import pytest

from pdverify import export, outputs, report, spill
from pdverify.report import build_report
from pdverify.scenes import get_scene


def _result():
    scene = get_scene("bar1d-traction")
    return scene.run(scene.default_method)


def test_spilled_fields_come_back_bit_for_bit_and_load_only_on_access(tmp_path):
    r = _result()
    assert r.fields
    before = dict(r.fields)
    s = spill.Spill(str(tmp_path))
    s.spill(r)
    f = r.fields
    assert isinstance(f, spill.SpilledFields)
    assert list(f) == list(before) and len(f) == len(before) and f
    assert "x" in f and not f.loaded          # the keys need no load
    for k, v in before.items():
        got = f[k]
        if isinstance(v, np.ndarray):
            # exact: pickle keeps the array's bytes, dtype and shape
            assert got.dtype == v.dtype and got.shape == v.shape
            assert got.tobytes() == v.tobytes()
        else:
            assert got == v
    assert f.loaded
    spill.release([r])
    assert not f.loaded
    with pytest.raises(KeyError):
        f["no such field"]
    assert os.listdir(tmp_path) == [spill.FOLDER]
    s.close()
    assert os.listdir(tmp_path) == []


def test_a_run_without_fields_is_not_spilled(tmp_path):
    r = _result()
    r.fields = {}
    s = spill.Spill(str(tmp_path))
    assert s.spill(r).fields == {}
    s.close()
    assert os.listdir(tmp_path) == []


def test_vtu_files_of_spilled_fields_equal_those_of_the_fields_in_memory(tmp_path):
    r = _result()
    a = export.write_run_fields(r, str(tmp_path / "a" / "run"))
    spill.Spill(str(tmp_path)).spill(r)
    assert isinstance(r.fields, spill.SpilledFields)
    b = export.write_run_fields(r, str(tmp_path / "b" / "run"))
    assert [os.path.basename(p) for p in a] == [os.path.basename(p) for p in b] and a
    for p, q in zip(a, b):
        with open(p, "rb") as fa, open(q, "rb") as fb:
            assert fa.read() == fb.read()   # exact: same bytes


def test_a_killed_reports_staging_folder_with_its_spill_is_pdverifys_leftover(tmp_path):
    staging = tmp_path / ".rep.staging-x"
    (staging / spill.FOLDER).mkdir(parents=True)
    (staging / spill.FOLDER / "00000.pickle").write_bytes(b"\x80")
    (staging / "results.json").write_text("{}")
    assert outputs.is_own_leftover(str(staging))


def test_the_report_process_holds_one_runs_fields_at_a_time(tmp_path, monkeypatch):
    """After the runs phase every run's fields are on disk, none loaded; the figures and
    pages (drawn in the report process with jobs=1) release what they load, and each
    VTU export finds only its own run's fields loaded. The spill folder is gone at the
    end and the report is as before (figures, VTU files listed in results.json)."""
    seen = {}
    real_run_cases = report.run_cases

    def recording(*args, **kwargs):
        results = real_run_cases(*args, **kwargs)
        seen["results"] = results
        seen["kinds"] = {type(r.fields).__name__ for r in results if r.fields}
        seen["loaded"] = [r for r in results
                          if isinstance(r.fields, spill.SpilledFields) and r.fields.loaded]
        return results
    monkeypatch.setattr(report, "run_cases", recording)
    real_write, loaded_at_write = export.write_run_fields, []

    def counting(result, stem):
        paths = real_write(result, stem)
        loaded_at_write.append(sum(isinstance(r.fields, spill.SpilledFields)
                                   and r.fields.loaded for r in seen["results"]))
        return paths
    monkeypatch.setattr(export, "write_run_fields", counting)
    out = tmp_path / "rep"
    assert build_report(out=str(out), quick=True, only=["bar1d-sine-load", "bar1d-traction"],
                        jobs=1) == 0
    assert seen["kinds"] == {"SpilledFields"}
    assert seen["loaded"] == []
    with_fields = [r for r in seen["results"] if r.fields]
    assert len(loaded_at_write) == len(with_fields) > 1
    assert set(loaded_at_write) == {1}          # the run being written, no other
    assert not any(r.fields.loaded for r in with_fields)
    assert spill.FOLDER not in os.listdir(out)
    assert sorted(os.listdir(tmp_path)) == [".rep.lock", "rep"]   # no staging left
    assert os.listdir(out / "figures") and os.listdir(out / "fields")
