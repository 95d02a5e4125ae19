"""Bad input, table-driven (issue 18): exit 2, one line naming the input, no traceback,
nothing written, before any work."""
import json
import os

import pytest

from pdverify.cli import main

GOOD_RUN = {"scene": "bar1d-traction", "method": "none", "params": {}, "reference": "analytic",
            "status": "ok", "message": "", "metrics": {"max_error_pct": 1.0}}


def _doc(runs, schema="pdverify.results/1"):
    return {"schema": schema, "runs": runs}


FIFO = "<a FIFO>"   # files: create a named pipe there
DEEP = 200_000      # nesting that Python's JSON reader cannot follow (issue 31)


def _nested(depth):
    value = 1
    for _ in range(depth):
        value = [value]
    return value


#: (id, argv, files to create first {name: content or None for a folder}, text expected)
CASES = [
    # ---------------------------------------------------------------- run: scene, method
    ("unknown-scene", ["run", "no-such-scene"], {}, "unknown scene"),
    ("unknown-method", ["run", "bar1d-traction", "--method", "nope"], {},
     "not supported by this scene; allowed: none"),
    ("method-not-on-scene", ["run", "stiffness3d-box", "--method", "virtual-nodes"], {},
     "stiffness3d-box: method 'virtual-nodes' is not supported by this scene; allowed: "
     "none, taylor-fictitious, surface-nodes, mirror-nodes, energy, energy-directional, volume"),
    ("unknown-command", ["frobnicate"], {}, "invalid choice"),
    ("unknown-flag", ["run", "bar1d-traction", "--fast"], {}, "unrecognized"),
    # ---------------------------------------------------------------- run: --set syntax
    ("set-no-equals", ["run", "bar1d-traction", "--set", "force"], {}, "expected KEY=VALUE"),
    ("set-empty-key", ["run", "bar1d-traction", "--set", "=3"], {}, "expected KEY=VALUE"),
    ("set-twice", ["run", "bar1d-traction", "--set", "force=1", "--set", "force=2"], {},
     "given twice"),
    ("set-unknown-key", ["run", "bar1d-traction", "--set", "colour=1"], {}, "unknown key"),
    # ---------------------------------------------------------------- run: values
    ("int-overflow", ["run", "bar1d-traction", "--method", "taylor-fictitious", "--set",
                      "order=1e400"], {}, "order='1e400'"),
    ("int-fraction", ["run", "bar1d-traction", "--method", "taylor-fictitious", "--set",
                      "order=2.5"], {}, "order='2.5'"),
    ("int-zero", ["run", "bar1d-traction", "--method", "taylor-fictitious", "--set", "order=0"],
     {}, "order='0'"),
    ("int-text", ["run", "bar1d-traction", "--method", "taylor-fictitious", "--set",
                  "order=two"], {}, "order='two'"),
    ("load-inf", ["run", "bar1d-traction", "--set", "force=inf"], {}, "force='inf'"),
    ("load-nan", ["run", "bar1d-traction", "--set", "force=nan"], {}, "force='nan'"),
    ("load-overflow", ["run", "bar1d-traction", "--set", "force=1e999"], {}, "force='1e999'"),
    ("load-zero", ["run", "bar1d-traction", "--set", "force=0"], {}, "force=0"),
    ("full-width-digits", ["run", "bar1d-traction", "--set", "nu=０.３"], {}, "ASCII"),
    ("negative-spacing", ["run", "bar1d-traction", "--set", "spacing=-1"], {}, "spacing='-1'"),
    ("zero-spacing", ["run", "bar1d-traction", "--set", "spacing=0"], {}, "spacing='0'"),
    ("text-spacing", ["run", "bar1d-traction", "--set", "spacing=abc"], {}, "spacing='abc'"),
    ("spacing-not-dividing", ["run", "bar1d-traction", "--set", "spacing=0.07"], {},
     "must divide"),
    ("nu-half", ["run", "bar1d-traction", "--set", "nu=0.5"], {}, "nu='0.5'"),
    ("nu-below", ["run", "bar1d-traction", "--set", "nu=-1"], {}, "nu='-1'"),
    ("m-ratio-small", ["run", "bar1d-traction", "--set", "m_ratio=0.5"], {}, "m_ratio='0.5'"),
    ("length-inf", ["run", "bar1d-traction", "--set", "length=inf"], {}, "length='inf'"),
    ("area-negative", ["run", "bar1d-traction", "--set", "area=-0.01"], {}, "area='-0.01'"),
    ("E-zero", ["run", "bar1d-traction", "--set", "E=0"], {}, "E='0'"),
    ("influence-unknown", ["run", "bar1d-traction", "--set", "influence=nope"], {},
     "influence='nope'"),
    ("sheet-solver-not-offered", ["run", "sheet2d-tension", "--method", "none", "--set",
                                  "solver=nested-dissection"], {}, "solver='nested-dissection'"),
    ("plate-solver-not-offered", ["run", "plate2d-plane-strain", "--set", "solver=cg"], {},
     "solver='cg'"),
    ("order-too-large-1d", ["run", "bar1d-sine-load", "--method", "taylor-fictitious",
                            "--set", "order=10"], {}, "order=10 is too large"),
    ("plate-order-too-large", ["run", "plate2d-clamped", "--method", "taylor-fictitious",
                               "--set", "order=10"], {}, "order=10 is too large for 20 nodes"),
    ("plate-spacing", ["run", "plate2d-clamped", "--method", "none", "--set",
                       "spacing=0.07"], {}, "spacing=0.07 must divide"),
    ("plate-corners", ["run", "plate2d-clamped", "--method", "taylor-fictitious", "--set",
                       "corners=diagonal"], {}, "corners='diagonal'"),
    ("plate-body-force", ["run", "plate2d-clamped", "--method", "none", "--set",
                          "body_force=0"], {}, "body_force=0"),
    ("plate-ring-value", ["run", "plate2d-clamped", "--method", "none", "--set",
                          "ring_value=maybe"], {}, "ring_value='maybe'"),
    ("fem-levels", ["run", "plate2d-clamped", "--set", "levels=1"], {}, "levels"),
    ("sheet-nu", ["run", "sheet2d-tension", "--method", "none", "--set", "nu=0.3"], {},
     "nu=0.3 is not allowed"),
    ("sheet-m-ratio", ["run", "sheet2d-clamped", "--method", "none", "--set",
                       "m_ratio=1.5"], {}, "m_ratio=1.5"),
    ("sheet-virtual-m", ["run", "sheet2d-clamped", "--method", "virtual-nodes", "--set",
                         "m_ratio=6.3"], {}, "m_ratio"),
    ("box-spacing", ["run", "body3d-traction", "--method", "none", "--set", "spacing=0.07"],
     {}, "must divide"),
    ("box-order", ["run", "body3d-traction", "--method", "surface-nodes", "--set", "order=4"],
     {}, "order='4'"),
    ("manufactured-influence", ["run", "body3d-manufactured", "--method", "none", "--set",
                                "influence=hyperbolic"], {}, "influence=hyperbolic"),
    ("indent-substeps", ["run", "block2d-indentation", "--method", "none", "--set",
                         "substeps=0"], {}, "substeps='0'"),
    ("indent-kinematics", ["run", "block2d-indentation", "--method", "none", "--set",
                           "kinematics=large"], {}, "kinematics='large'"),
    ("indent-spacing", ["run", "block2d-indentation", "--method", "none", "--set",
                        "spacing=0.0003"], {}, "spacing=0.0003 must divide"),
    ("indent-odd-width", ["run", "block2d-indentation", "--method", "none", "--set",
                          "spacing=0.008", "--set", "horizon=0.016"], {},
     "even number of spacings"),
    ("indent-increments", ["run", "block2d-indentation", "--method", "energy-directional",
                           "--set", "n_steps=200", "--set", "substeps=20"], {}, "at most 2000"),
    ("indent-nu", ["run", "block2d-indentation", "--method", "none", "--set", "nu=0.3"], {},
     "nu=0.3 is not allowed"),
    ("indent-radius", ["run", "block2d-indentation", "--method", "none", "--set",
                       "radius=0.03"], {}, "radius must not exceed width / 2"),
    ("bool-text", ["run", "sheet2d-clamped", "--method", "virtual-nodes", "--set",
                   "correct_sides=perhaps"], {}, "correct_sides='perhaps'"),
    # ---------------------------------------------------------------- run: --json
    ("json-empty", ["run", "bar1d-traction", "--json", ""], {}, "--json ''"),
    ("json-folder", ["run", "bar1d-traction", "--json", "adir"], {"adir": None}, "is a folder"),
    ("json-trailing-slash", ["run", "bar1d-traction", "--json", "new/"], {}, "is a folder"),
    ("json-proc", ["run", "bar1d-traction", "--json", "/proc/nope/x.json"], {},
     "cannot write there"),
    ("json-under-file", ["run", "bar1d-traction", "--json", "afile/x.json"],
     {"afile": "x"}, "is a file"),
    # ---------------------------------------------------------------- report
    ("out-empty", ["report", "--out", ""], {}, "--out ''"),
    ("out-file", ["report", "--out", "afile"], {"afile": "x"}, "is a file"),
    ("out-proc", ["report", "--out", "/proc/nope"], {}, "cannot write there"),
    ("out-results-folder", ["report", "--out", "r"], {"r": None, "r/results.json": None},
     "results.json there is a folder"),
    ("out-index-folder", ["report", "--out", "r"], {"r": None, "r/index.html": None},
     "index.html there is a folder"),
    ("out-figures-file", ["report", "--out", "r"], {"r": None, "r/figures": "x"},
     "figures there is a file"),
    ("jobs-zero", ["report", "--jobs", "0"], {}, "--jobs=0"),
    ("jobs-negative", ["report", "--jobs", "-1"], {}, "--jobs=-1"),
    ("jobs-huge", ["report", "--jobs", "1000"], {}, "--jobs=1000"),
    ("jobs-text", ["report", "--jobs", "many"], {}, "--jobs"),
    ("only-unknown", ["report", "--only", "no-such"], {}, "unknown scene"),
    ("only-twice", ["report", "--only", "bar1d-traction", "bar1d-traction"], {}, "given twice"),
    ("only-empty", ["report", "--only"], {}, "--only"),
    # ---------------------------------------------------------------- resource budget
    ("size-bar-nodes", ["run", "bar1d-traction", "--set", "spacing=1e-9"], {},
     "needs ~5.03 TB of memory (1e+09 nodes"),
    ("size-box-3d", ["run", "body3d-traction", "--set", "spacing=0.005"], {}, "of memory"),
    ("size-sheet-horizon", ["run", "sheet2d-tension", "--method", "none", "--set",
                            "spacing=0.0001"], {}, "of memory"),
    ("size-fem-levels", ["run", "plate2d-clamped", "--method", "fem", "--set", "levels=7",
                         "--set", "spacing=0.05"], {}, "Q2 elements"),
    ("size-wave-steps", ["run", "wave1d-surface-nodes", "--set", "dt=1e-15"], {},
     "needs ~2e+11 time steps"),
    ("size-vibration-steps", ["run", "bar1d-vibration", "--set", "dt_factor=1e-9"], {},
     "time steps"),
    ("max-memory-small", ["run", "body3d-traction", "--max-memory", "1G"], {},
     "above the limit of 1.07 GB (--max-memory)"),
    ("max-memory-text", ["run", "bar1d-traction", "--max-memory", "lots"], {},
     "--max-memory='lots'"),
    ("max-memory-tiny", ["report", "--max-memory", "10k"], {}, "at least 1M"),
    ("report-over-budget", ["report", "--only", "body3d-traction", "--max-memory", "500M"], {},
     "body3d-traction --method none: needs"),
    # ---------------------------------------------------------------- compare
    ("cmp-missing", ["compare", "missing.json", "b.json"], {"b.json": json.dumps(_doc([]))},
     "does not exist"),
    ("cmp-folder", ["compare", "adir", "b.json"], {"adir": None, "b.json": json.dumps(_doc([]))},
     "is a folder"),
    ("cmp-not-json", ["compare", "a.json", "b.json"],
     {"a.json": "{not json", "b.json": json.dumps(_doc([]))}, "not valid JSON"),
    ("cmp-binary", ["compare", "a.json", "b.json"],
     {"a.json": b"\xff\xfe\x00", "b.json": json.dumps(_doc([]))}, "a.json"),
    ("cmp-schema", ["compare", "a.json", "b.json"],
     {"a.json": json.dumps(_doc([], "other/1")), "b.json": json.dumps(_doc([]))}, "schema"),
    ("cmp-runs-not-list", ["compare", "a.json", "b.json"],
     {"a.json": json.dumps({"schema": "pdverify.results/1", "runs": {}}),
      "b.json": json.dumps(_doc([]))}, "'runs' must be a list"),
    ("cmp-run-string", ["compare", "a.json", "b.json"],
     {"a.json": json.dumps(_doc(["run"])), "b.json": json.dumps(_doc([]))},
     "runs[0] must be an object"),
    ("cmp-metrics-null", ["compare", "a.json", "b.json"],
     {"a.json": json.dumps(_doc([{**GOOD_RUN, "metrics": None}])),
      "b.json": json.dumps(_doc([]))}, "runs[0].metrics must be an object"),
    ("cmp-missing-scene", ["compare", "a.json", "b.json"],
     {"a.json": json.dumps(_doc([{k: v for k, v in GOOD_RUN.items() if k != "scene"}])),
      "b.json": json.dumps(_doc([]))}, "has no 'scene'"),
    ("cmp-bad-status", ["compare", "a.json", "b.json"],
     {"a.json": json.dumps(_doc([{**GOOD_RUN, "status": "fine"}])),
      "b.json": json.dumps(_doc([]))}, "status must be"),
    ("cmp-metric-list", ["compare", "a.json", "b.json"],
     {"a.json": json.dumps(_doc([GOOD_RUN])),
      "b.json": json.dumps(_doc([{**GOOD_RUN, "metrics": {"max_error_pct": [1]}}]))},
     "b.json: runs[0].metrics.max_error_pct"),
    ("cmp-rtol-negative", ["compare", "a.json", "a.json", "--rtol", "-1"],
     {"a.json": json.dumps(_doc([GOOD_RUN]))}, "--rtol=-1"),
    ("cmp-rtol-nan", ["compare", "a.json", "a.json", "--rtol", "nan"],
     {"a.json": json.dumps(_doc([GOOD_RUN]))}, "--rtol=nan"),
    ("cmp-atol-inf", ["compare", "a.json", "a.json", "--atol", "inf"],
     {"a.json": json.dumps(_doc([GOOD_RUN]))}, "--atol=inf"),
    ("cmp-summary-empty", ["compare", "a.json", "a.json", "--summary", ""],
     {"a.json": json.dumps(_doc([GOOD_RUN]))}, "--summary ''"),
    ("cmp-summary-folder", ["compare", "a.json", "a.json", "--summary", "adir"],
     {"a.json": json.dumps(_doc([GOOD_RUN])), "adir": None}, "is a folder"),
    # ---------------------------------------------------------------- compare (issue 31)
    ("cmp-duplicate-run", ["compare", "a.json", "b.json"],
     {"a.json": json.dumps(_doc([{**GOOD_RUN, "metrics": {"max_error_pct": 9.0}}, GOOD_RUN])),
      "b.json": json.dumps(_doc([GOOD_RUN]))},
     "baseline 'a.json': runs[1] repeats runs[0] (scene 'bar1d-traction', method 'none'"),
    ("cmp-duplicate-run-new", ["compare", "a.json", "b.json"],
     {"a.json": json.dumps(_doc([GOOD_RUN])),
      "b.json": json.dumps(_doc([GOOD_RUN, {**GOOD_RUN, "status": "failed"}]))},
     "new results 'b.json': runs[1] repeats runs[0]"),
    ("cmp-int-401-digits", ["compare", "a.json", "b.json"],
     {"a.json": json.dumps(_doc([{**GOOD_RUN, "metrics": {"n": 10 ** 400}}])),
      "b.json": json.dumps(_doc([GOOD_RUN]))},
     "a.json: runs[0].metrics.n is an integer of 401 digits, beyond the range of a float"),
    ("cmp-int-5000-digits", ["compare", "a.json", "b.json"],
     {"a.json": '{"schema": "pdverify.results/1", "runs": [{"metrics": {"n": 1' + "0" * 5000
      + "}}]}", "b.json": json.dumps(_doc([GOOD_RUN]))},
     "a.json: not a results file (Exceeds the limit (4300 digits)"),
    ("cmp-surrogate-scene", ["compare", "a.json", "b.json"],
     {"a.json": json.dumps(_doc([{**GOOD_RUN, "scene": "bar\ud800"}])),
      "b.json": json.dumps(_doc([GOOD_RUN]))},
     "a.json: runs[0].scene holds a lone surrogate '\\ud800' (not valid Unicode)"),
    ("cmp-surrogate-key", ["compare", "a.json", "b.json"],
     {"a.json": json.dumps(_doc([GOOD_RUN])),
      "b.json": json.dumps(_doc([{**GOOD_RUN, "metrics": {"e\udfff": 1.0}}]))},
     "b.json: runs[0].metrics: a key holds a lone surrogate"),
    ("cmp-deep-array", ["compare", "a.json", "b.json"],
     {"a.json": '{"schema": "pdverify.results/1", "runs": ' + "[" * DEEP + "]" * DEEP + "}",
      "b.json": json.dumps(_doc([GOOD_RUN]))}, "a.json: JSON nested too deeply to read"),
    ("cmp-deep-params", ["compare", "a.json", "b.json"],
     {"a.json": json.dumps(_doc([{**GOOD_RUN, "params": {"p": _nested(40)}}])),
      "b.json": json.dumps(_doc([GOOD_RUN]))}, "nests deeper than 32 levels"),
    ("cmp-fifo", ["compare", "pipe", "b.json"], {"pipe": FIFO, "b.json": json.dumps(_doc([]))},
     "baseline 'pipe' is a FIFO, not a file"),
    ("cmp-device", ["compare", "a.json", "/dev/null"], {"a.json": json.dumps(_doc([]))},
     "new results '/dev/null' is a character device, not a file"),
    ("cmp-summary-is-baseline", ["compare", "a.json", "b.json", "--summary", "a.json"],
     {"a.json": json.dumps(_doc([GOOD_RUN])), "b.json": json.dumps(_doc([GOOD_RUN]))},
     "--summary 'a.json' is the baseline of this command"),
    ("cmp-summary-is-new-forced", ["compare", "a.json", "b.json", "--summary", "b.json",
                                   "--force"],
     {"a.json": json.dumps(_doc([GOOD_RUN])), "b.json": json.dumps(_doc([GOOD_RUN]))},
     "--summary 'b.json' is the new results file of this command"),
    ("cmp-summary-foreign", ["compare", "a.json", "a.json", "--summary", "notes.md"],
     {"a.json": json.dumps(_doc([GOOD_RUN])), "notes.md": "# my notes"},
     "--summary 'notes.md' exists and was not written by pdverify"),
    ("cmp-summary-fifo", ["compare", "a.json", "a.json", "--summary", "pipe", "--force"],
     {"a.json": json.dumps(_doc([GOOD_RUN])), "pipe": FIFO}, "is a FIFO, not a file"),
    # ---------------------------------------------------------------- outputs (issue 31)
    ("json-foreign", ["run", "bar1d-traction", "--json", "mine.json"], {"mine.json": "{}"},
     "--json 'mine.json' exists and was not written by pdverify"),
    ("json-device", ["run", "bar1d-traction", "--json", "/dev/null"], {},
     "--json '/dev/null' is a character device, not a file"),
    ("vtu-foreign", ["run", "bar1d-traction", "--vtu", "f.vtu"], {"f.vtu": "<?xml?>"},
     "--vtu 'f.vtu' exists and was not written by pdverify"),
    ("vtu-foreign-suffix", ["run", "bar1d-traction", "--vtu", "f.vtu"], {"f_a.vtu": "x"},
     "f_a.vtu' exists and was not written by pdverify"),
    ("vtu-is-json", ["run", "bar1d-traction", "--json", "f.vtu", "--vtu", "f.vtu"], {},
     "--vtu 'f.vtu' is also the --json file"),
    ("out-foreign", ["report", "--out", "proj"], {"proj": None, "proj/a.py": "x"},
     "--out 'proj' is a folder pdverify did not create (it holds 'a.py' and no "
     ".pdverify-report marker)"),
    # (the table's cache folder is inside the current folder; test_data_safety covers
    # the current folder alone)
    ("out-current", ["report", "--out", "."], {}, "--out '.' contains the cache folder"),
    ("out-in-cache", ["report", "--out", ".cache-unused/r"], {},
     "is inside the cache folder"),
    ("out-report-with-stray", ["report", "--out", "r"],
     {"r": None, "r/.pdverify-report": json.dumps(
         {"schema": "pdverify.report-folder/1", "entries": [".pdverify-report"]}),
      "r/mine.txt": "x"}, "is a pdverify report, but it holds 'mine.txt'"),
    ("cache-is-file", ["run", "bar1d-traction"], {".cache-unused": "x"},
     ".cache-unused' is a file, not a folder"),
]


def _snapshot(root):
    out = {}
    for dirpath, dirnames, filenames in os.walk(root):
        for n in dirnames + filenames:
            p = os.path.join(dirpath, n)
            out[os.path.relpath(p, root)] = os.path.getsize(p) if os.path.isfile(p) else None
    return out


def test_at_least_60_distinct_cases():
    assert len({c[0] for c in CASES}) == len(CASES) >= 60


@pytest.mark.parametrize("name, argv, files, needle", CASES, ids=[c[0] for c in CASES])
def test_bad_input(name, argv, files, needle, tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv("PDVERIFY_CACHE_DIR", str(tmp_path / ".cache-unused"))
    for rel, content in files.items():
        p = tmp_path / rel
        if content is None:
            p.mkdir(parents=True, exist_ok=True)
        elif content is FIFO:
            os.mkfifo(p)
        elif isinstance(content, bytes):
            p.write_bytes(content)
        else:
            p.write_text(content)
    before = _snapshot(tmp_path)
    code = main(argv)
    err = capsys.readouterr().err
    assert code == 2
    assert err.count("\n") == 1 and err.startswith("pdverify: error: "), err
    assert "Traceback" not in err
    assert needle in err, err
    assert _snapshot(tmp_path) == before          # nothing written, nothing created


# ==================================================================== issue 31: robustness
# (extreme values, the step budget of every stepping loop, messages that name the cause;
# appended as one block, the outputs/compare cases of issue 31 sit in their own block)
ROBUST_CASES = [
    ("spacing-subnormal", ["run", "bar1d-traction", "--set", "spacing=5e-324"], {},
     "spacing='5e-324' must lie in 2.23e-308..1e+300 (from the smallest normal double"),
    ("length-huge", ["run", "bar1d-traction", "--set", "length=1e308"], {},
     "length='1e308' must lie in 2.23e-308..1e+300"),
    ("cells-overflow", ["run", "bar1d-traction", "--set", "spacing=1e-90", "--set",
                        "length=1e90"], {},
     "spacing=1e-90 and length=1e+90 give length/spacing = 1e+180 cells; allowed: at most "
     "1e+15 cells along an axis"),
    ("m-ratio-3d-huge", ["run", "stiffness3d-box", "--set", "m_ratio=1e300"], {},
     "m_ratio=1e300 makes the run's size overflow"),
    ("m-ratio-2d-huge", ["run", "plate2d-plane-strain", "--set", "m_ratio=1e308"], {},
     "m_ratio=1e+308 gives a horizon of 2e+306 m, longer than the body (1 m)"),
    ("scheduler-inproc", ["report", "--scheduler", "inproc://x"], {},
     "--scheduler='inproc://x': the scheme inproc:// is not supported; allowed: tcp://"),
    ("scheduler-ucx", ["report", "--scheduler", "ucx://10.0.0.5:8786"], {},
     "the scheme ucx:// is not supported"),
    ("force-subnormal", ["run", "bar1d-traction", "--set", "force=1e-320"], {},
     "force=1e-320 is below the smallest |force| allowed, 5e-307: the load of a strain of "
     "5e-314 (below, the displacements keep fewer than 10 digits in a double)"),
    ("body-load-tiny", ["run", "bar1d-uniform-load", "--set", "b0=1e-315"], {},
     "b0=1e-315 is below the smallest |b0| allowed"),
    ("indent-depth-tiny", ["run", "block2d-indentation", "--set", "depth=1e-12"], {},
     "depth=1e-12 is below the smallest allowed, 3e-07 m = n_steps x 1e-06 R"),
    ("indent-depth-tiny-pd", ["run", "block2d-indentation", "--method", "none", "--set",
                              "depth=1e-12"], {}, "depth=1e-12 is below the smallest allowed"),
    ("order-hex", ["run", "bar1d-traction", "--method", "taylor-fictitious", "--set",
                   "order=0x2"], {}, "order='0x2' is not a decimal integer"),
    ("order-underscore", ["run", "bar1d-traction", "--method", "taylor-fictitious", "--set",
                          "order=1_0"], {}, "order='1_0' is not a decimal integer"),
    ("order-fraction-named", ["run", "bar1d-traction", "--method", "taylor-fictitious",
                              "--set", "order=2.5"], {}, "order='2.5' is not a whole number"),
    ("order-overflow-named", ["run", "bar1d-traction", "--method", "taylor-fictitious",
                              "--set", "order=1e400"], {},
     "order='1e400' is out of range for an integer"),
    ("fem-indent-steps", ["run", "block2d-indentation", "--set", "n_steps=100000000"], {},
     "load increments"),
    ("fem-indent-substeps", ["run", "block2d-indentation", "--set", "substeps=100000"], {},
     "above the ceiling of 20000"),
    ("wave-dt-subnormal", ["run", "wave1d-surface-nodes", "--set", "dt=5e-324"], {},
     "dt='5e-324' must lie in 2.23e-308..1e+300"),
    ("vibration-periods-huge", ["run", "bar1d-vibration", "--set", "periods=1e308"], {},
     "inf time steps"),
    ("vibration-nodes-huge", ["run", "bar1d-vibration", "--set", "nodes=1e308"], {},
     "nodes=1e308"),
    ("E-subnormal", ["run", "bar1d-traction", "--set", "E=5e-324"], {},
     "E='5e-324' must lie in 2.23e-308..1e+300"),
    ("area-huge", ["run", "bar1d-traction", "--set", "area=1e308"], {}, "area='1e308'"),
    ("fem-E-huge", ["run", "sheet2d-tension", "--set", "E=1e308"], {},
     "E='1e308' must be 0 or of magnitude 2.23e-308..1e+300"),
    ("fem-thickness-subnormal", ["run", "plate2d-clamped", "--set", "thickness=5e-324"], {},
     "thickness='5e-324'"),
    ("fem-elements-huge", ["run", "sheet2d-clamped", "--set", "elements=1e308"], {},
     "elements=1e308 is outside what this scene can size"),
    ("wave-horizon-subnormal", ["run", "wave1d-surface-nodes", "--set", "horizon=5e-324"],
     {}, "horizon='5e-324'"),
    ("sheet-spacing-subnormal", ["run", "stiffness2d-sheet", "--set", "spacing=5e-324"], {},
     "spacing='5e-324'"),
]


def test_robust_case_names_are_new():
    names = [c[0] for c in CASES + ROBUST_CASES]
    assert len(set(names)) == len(names)


@pytest.mark.parametrize("name, argv, files, needle", ROBUST_CASES,
                         ids=[c[0] for c in ROBUST_CASES])
def test_bad_input_robust(name, argv, files, needle, tmp_path, monkeypatch, capsys):
    test_bad_input(name, argv, files, needle, tmp_path, monkeypatch, capsys)
