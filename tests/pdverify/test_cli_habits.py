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
    assert "not offered here" in out and "virtual-nodes: bond-based (seed 003" in out
    assert "homogenized: 1D bond-based bars only (seed 004 derives its factors" in out
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


# ------------------------------------------------------------------ Ctrl-C

def test_ctrl_c_during_a_report_prints_no_worker_traceback(tmp_path):
    # the terminal sends SIGINT to the whole process group: the report and its workers.
    # A heartbeat every 0.3 s shows when runs are in flight; then Ctrl-C.
    env = {**os.environ, "PYTHONPATH": str(ROOT), "PDVERIFY_HEARTBEAT_S": "0.3"}
    proc = subprocess.Popen([sys.executable, "-m", "pdverify", "report", "--quick", "--only",
                             "sheet2d-tension", "--jobs", "2", "--out", str(tmp_path / "r")],
                            cwd=ROOT, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            text=True, start_new_session=True,
                            # as from a terminal: Ctrl-C at its default even when the suite
                            # itself was started with SIGINT ignored (a background job of a
                            # non-interactive shell), which the report would inherit
                            preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))
    lines = []
    try:
        deadline = time.monotonic() + 300
        while time.monotonic() < deadline:
            line = proc.stderr.readline()
            if not line:
                break
            lines.append(line)
            if line.startswith("... running: sheet2d-tension"):
                os.killpg(proc.pid, signal.SIGINT)
                break
        rest, _ = proc.communicate(timeout=60)[1], None
    finally:
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGKILL)
    err = "".join(lines) + rest
    assert any(x.startswith("... running: ") for x in lines), err
    assert "Traceback" not in err and "KeyboardInterrupt" not in err, err
    assert err.rstrip().endswith("pdverify: interrupted"), err
    assert proc.returncode == 130
    assert not (tmp_path / "r").exists()            # nothing published


# ------------------------------------------------------------------ report --method, --failed

def test_report_method_selects_the_methods(tmp_path, capsys):
    from pdverify.report import build_report
    out = tmp_path / "rep"
    assert build_report(out=str(out), quick=True, only=["bar1d-traction"],
                        methods=["none", "volume"]) == 0
    runs = json.loads((out / "results.json").read_text())["runs"]
    assert {r["method"] for r in runs} == {"none", "volume"}


def test_report_method_default_folder_is_its_own():
    from pdverify.report import default_out
    assert default_out(["bar1d-traction"], True, ["volume"]) == \
        os.path.join("reports", "quick-only-bar1d-traction-method-volume")
    assert default_out(None, False, ["volume"]) == os.path.join("reports", "method-volume")


def test_report_method_not_offered_is_bad_input(capsys, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    assert main(["report", "--only", "bar1d-traction", "--method", "homogenized"]) == 2
    err = capsys.readouterr().err
    assert "--method 'homogenized' is not a method of the scenes of --only" in err
    assert main(["report", "--method", "none", "none"]) == 2
    assert "given twice" in capsys.readouterr().err


def test_report_failed_reruns_the_failed_and_missing_runs_and_merges(tmp_path, capsys):
    from pdverify.report import build_report
    out = tmp_path / "rep"
    assert build_report(out=str(out), quick=True, only=["bar1d-traction"]) == 0
    doc = json.loads((out / "results.json").read_text())
    runs = doc["runs"]
    # make the previous report have one failed run and one missing run
    runs[1]["status"], runs[1]["message"] = "failed", "made to fail by the test"
    missing = runs.pop(2)
    kept_before = {(r["method"], json.dumps(r["params"], sort_keys=True)): r for r in runs}
    (out / "results.json").write_text(json.dumps(doc, indent=1))
    capsys.readouterr()
    assert build_report(out=str(out), quick=True, only=["bar1d-traction"], failed=True) == 0
    err = capsys.readouterr().err
    assert "rerunning 2 run(s)" in err and err.count("[") >= 2
    assert "[1/2]" in err and "[2/2]" in err                 # only the two ran
    after = json.loads((out / "results.json").read_text())["runs"]
    assert len(after) == len(runs) + 1
    assert all(r["status"] == "ok" for r in after)
    assert missing["method"] in [r["method"] for r in after]
    for r in after:   # the kept runs as they were (their previous timings included)
        key = (r["method"], json.dumps(r["params"], sort_keys=True))
        if key in kept_before and kept_before[key]["status"] == "ok":
            assert r["timings"] == kept_before[key]["timings"]
            assert os.path.isfile(out / r["files"][0])          # its VTU copied over
    # nothing left to rerun: the report stays as it is
    before = (out / "results.json").read_text()
    assert build_report(out=str(out), quick=True, only=["bar1d-traction"], failed=True) == 0
    assert "nothing failed or is missing" in capsys.readouterr().err
    assert (out / "results.json").read_text() == before


def test_report_failed_without_a_previous_report_is_exit_2(tmp_path, capsys):
    assert main(["report", "--quick", "--only", "bar1d-traction", "--failed",
                 "--out", str(tmp_path / "none-here")]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1
    assert "--failed" in err and "holds no previous pdverify report" in err
    assert not (tmp_path / "none-here").exists()


# ------------------------------------------------------------------ CSV, log, marker, schema

def _small_report(tmp_path):
    from pdverify.report import build_report
    out = tmp_path / "rep"
    assert build_report(out=str(out), quick=True, only=["bar1d-traction"]) == 0
    return out


def test_report_writes_a_csv_per_scene_and_its_log(tmp_path, capsys):
    import csv
    out = _small_report(tmp_path)
    err = capsys.readouterr().err
    runs = json.loads((out / "results.json").read_text())["runs"]
    rows = list(csv.DictReader((out / "tables" / "bar1d-traction.csv").open()))
    assert len(rows) == len(runs)
    for row, run in zip(rows, runs):
        assert row["method"] == run["method"] and row["status"] == run["status"]
        assert float(row["max_error_pct"]) == run["metrics"]["max_error_pct"]
        assert float(row["spacing"]) == run["params"]["spacing"]
    log = (out / "report.log").read_text()
    assert log == err                                     # the progress lines, all of them
    assert log.count("] bar1d-traction") == len(runs) and "report: " in log
    # the marker lists the new files, so that the next report may replace the folder
    from pdverify import outputs
    marker = outputs.read_marker(str(out))
    assert "tables/bar1d-traction.csv" in marker["entries"]
    assert "report.log" in marker["entries"]
    assert outputs.folder_state(str(out)) == ("report", "")
    (out / "tables" / "mine.csv").write_text("not pdverify's")
    assert outputs.folder_state(str(out))[0] == "foreign"


def test_a_killed_reports_staging_with_tables_and_log_is_its_own(tmp_path):
    from pdverify import outputs
    staging = tmp_path / ".rep.staging-x"
    (staging / "tables").mkdir(parents=True)
    (staging / "tables" / "a.csv").write_text("x")
    (staging / "report.log").write_text("[1/2] ...")
    outputs.write_marker(str(staging), complete=False)
    (staging / "results.json").write_text("{}")
    assert outputs.is_own_leftover(str(staging))
    (staging / "notes.txt").write_text("mine")
    assert not outputs.is_own_leftover(str(staging))


def test_results_json_validates_against_the_published_schema(tmp_path):
    jsonschema = pytest.importorskip("jsonschema")
    from pdverify.results import SCHEMA_FILE
    schema = json.loads(Path(SCHEMA_FILE).read_text())
    jsonschema.Draft202012Validator.check_schema(schema)
    out = _small_report(tmp_path)
    doc = json.loads((out / "results.json").read_text())
    jsonschema.validate(doc, schema)
    lib = doc["machine"]["libraries"]
    assert set(lib) >= {"numpy", "scipy", "scikit-fem", "meshio", "pyvista"}
    import numpy
    assert lib["numpy"] == numpy.__version__
    assert doc["machine"]["blas"] and all("source" in b for b in doc["machine"]["blas"])
    # a corrupted file fails
    for corrupt in (lambda d: d["runs"][0].update(status="maybe"),
                    lambda d: d["runs"][0]["metrics"].update(max_error_pct=[1.0]),
                    lambda d: d["runs"][0].pop("scene"),
                    lambda d: d.update(schema="pdverify.results/2")):
        bad = json.loads(json.dumps(doc))
        corrupt(bad)
        with pytest.raises(jsonschema.ValidationError):
            jsonschema.validate(bad, schema)


def test_the_schema_file_is_package_data():
    try:
        import tomllib
    except ImportError:                       # Python 3.10: the declared backport
        import tomli as tomllib
    with open(ROOT / "pyproject.toml", "rb") as fh:
        data = tomllib.load(fh)["tool"]["setuptools"]["package-data"]["pdverify"]
    assert "schema/*.json" in data


# ------------------------------------------------------------------ sympy only when used

@pytest.mark.parametrize("args", [["--version"], ["list"], ["run", "bar1d-traction"],
                                  ["report", "--quick", "--only", "bar1d-traction", "--out",
                                   "TMP"]])
def test_sympy_is_not_imported_by_the_commands(args, tmp_path):
    args = [str(tmp_path / "rep") if a == "TMP" else a for a in args]
    code = ("import sys, contextlib, io\nfrom pdverify.cli import main\n"
            "with contextlib.redirect_stdout(io.StringIO()):\n"
            f"    try: main({args!r})\n    except SystemExit: pass\n"
            "print('sympy' in sys.modules)")
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          cwd=ROOT, env=env, timeout=120)
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout.strip().splitlines()[-1] == "False"


def test_the_symbolic_engine_still_loads_on_use():
    import manufactured
    assert callable(manufactured.solution)
    assert "sympy" in sys.modules


# ------------------------------------------------------------------ heartbeat and ETA

class _Res:
    status = "ok"
    timings = {"total_s": 0.0}


def test_heartbeat_names_the_runs_in_flight_on_a_non_terminal(monkeypatch):
    import io
    from pdverify import progress
    clock = {"t": 100.0}
    monkeypatch.setattr(progress.time, "monotonic", lambda: clock["t"])
    cases = [("bar1d-traction", "none", {}), ("bar1d-traction", "pddo", {"order": 2})]
    out = io.StringIO()
    with progress.RunProgress(cases, 2, out, heartbeat_s=5.0) as shown:
        shown.started(0)
        clock["t"] += 2.0
        shown.started(1)
        assert 0 < shown.tick_s <= 5.0          # the pool wakes for the next heartbeat
        shown.tick()
        assert out.getvalue() == ""             # not due yet
        clock["t"] += 3.5
        shown.tick()
        beat = out.getvalue()
        assert beat.startswith("... running: bar1d-traction none 0:06; "
                               "bar1d-traction pddo order=2 0:04 | 0/2 done"), beat
        clock["t"] += 1.0
        shown.tick()
        assert out.getvalue() == beat           # the next one 5 s after this one
        shown.finished(0, _Res())
        clock["t"] += 5.0
        shown.tick()
        assert out.getvalue().splitlines()[-1].startswith("... running: bar1d-traction pddo")


def test_heartbeat_interval_from_the_environment(monkeypatch):
    from pdverify import progress
    monkeypatch.setenv(progress.HEARTBEAT_ENV, "0.25")
    assert progress.heartbeat_interval() == 0.25
    monkeypatch.setenv(progress.HEARTBEAT_ENV, "soon")
    assert progress.heartbeat_interval() == progress.HEARTBEAT_S == 60.0


def test_eta_follows_each_cases_cost_not_the_mean(monkeypatch):
    from pdverify import progress
    clock = {"t": 0.0}
    monkeypatch.setattr(progress.time, "monotonic", lambda: clock["t"])
    cases = [("s", "a", {}), ("s", "b", {}), ("s", "c", {}), ("s", "d", {})]
    # the previous report timed a at 1 s, b at 1 s, c at 100 s; d has a size of 50 units
    costs = [("known", 1.0), ("known", 1.0), ("known", 100.0), ("size", 50.0)]
    shown = progress.RunProgress(cases, 1, None, costs=costs)
    assert shown.eta() is None               # d has no calibration and no mean yet
    shown.started(0)
    clock["t"] = 2.0                          # a took 2 s: this machine may be slower
    shown.finished(0, _Res())
    # the speed: a's 2 s against its 1 s, from SPEED_PRIOR_S seconds at speed 1
    speed = (2.0 + progress.SPEED_PRIOR_S) / (1.0 + progress.SPEED_PRIOR_S)
    # b 1 s and c 100 s at that speed, d: no size run finished yet, so the mean, 2 s
    assert shown.eta() == pytest.approx(101.0 * speed + 2.0)
    # the mean would have said 3 runs x 2 s = 6 s
    shown.started(1)
    clock["t"] = 2.0 + 2 * (1.0 + progress.SPEED_PRIOR_S)   # b: far slower, for long
    shown.finished(1, _Res())
    # (2 + 2 (1 + prior) + prior) / (2 + prior): the ratio tends to the runs' own
    speed = (2.0 + 2 * (1.0 + progress.SPEED_PRIOR_S) + progress.SPEED_PRIOR_S) / (
        2.0 + progress.SPEED_PRIOR_S)
    assert shown.eta() == pytest.approx(100.0 * speed + (clock["t"] / 2))


def test_eta_starts_from_the_measured_times_cold_references_included(monkeypatch):
    """Without a previous report, the ETA has a prediction before any run ends: the
    measured run times (schedule.MEASURED_TIMES), a reference run's with its cold cost;
    a reference run that ends at once (a warm cache) does not change the speed."""
    from pdverify import progress
    from pdverify.results import run_key
    from pdverify.scenes import get_scene
    from pdverify.schedule import case_costs
    cases = [("sheet2d-clamped", "fem", {}), ("sheet2d-clamped", "none", {})]
    keys = [run_key(s, m, get_scene(s).resolve(m, o)) for s, m, o in cases]
    costs = case_costs(cases, measured={keys[0]: (0.05, 3.0), keys[1]: (2.0, 0.0)})
    assert costs == [("reference", 3.05), ("known", 2.0)]
    clock = {"t": 0.0}
    monkeypatch.setattr(progress.time, "monotonic", lambda: clock["t"])
    shown = progress.RunProgress(cases, 1, None, costs=costs)
    assert shown.eta() == pytest.approx(5.05)        # from the start
    shown.started(0)
    clock["t"] = 0.05                                # warm: the reference was cached
    shown.finished(0, _Res())
    assert shown.eta() == pytest.approx(2.0)         # the speed is still 1
    # the shipped table covers the report's plans (every case but a new one)
    from pdverify.runner import plan
    from pdverify.schedule import measured_times
    quick = plan(quick=True)
    known = [c for c, (kind, _) in zip(quick, case_costs(quick, measured=measured_times()))
             if kind in ("known", "reference")]
    assert len(known) >= 0.9 * len(quick)


def test_case_costs_use_the_previous_times_then_the_size_model():
    from pdverify.results import run_key
    from pdverify.scenes import get_scene
    from pdverify.schedule import case_costs
    cases = [("bar1d-traction", "none", {}), ("bar1d-traction", "pddo", {})]
    key = run_key("bar1d-traction", "none", get_scene("bar1d-traction").resolve("none", {}))
    costs = case_costs(cases, {key: 3.5}, measured={})
    assert costs[0] == ("known", 3.5)
    assert costs[1][0] in ("size", None)


def test_eta_calibrates_a_size_within_its_scene_only(monkeypatch):
    from pdverify import progress
    clock = {"t": 0.0}
    monkeypatch.setattr(progress.time, "monotonic", lambda: clock["t"])
    cases = [("bar", "a", {}), ("sheet", "b", {}), ("sheet", "c", {}), ("bar", "d", {})]
    costs = [("size", 1.0), ("size", 1000.0), ("size", 4000.0), ("size", 2.0)]
    shown = progress.RunProgress(cases, 1, None, costs=costs)
    shown.started(0)
    clock["t"] = 0.5                        # a small bar run: 0.5 s per unit of size
    shown.finished(0, _Res())
    # d: 2 units x 0.5 s; b and c: no sheet run done, the mean (0.5 s), not 500 s / 2000 s
    assert shown.eta() == pytest.approx(0.5 + 0.5 + 2 * 0.5)
    shown.started(1)
    clock["t"] = 10.5                       # b, 1000 units, took 10 s: c is 4x that
    shown.finished(1, _Res())
    assert shown.eta() == pytest.approx(40.0 + 1.0)
