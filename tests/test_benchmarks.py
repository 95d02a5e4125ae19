"""The benchmark scripts keep their command lines (issue 51: one harness for all of them):
every ``benchmarks/*.py`` runs ``--help`` as ``python benchmarks/NAME.py --help`` would
(one child process for all, so the imports are paid once), the timing scripts offer the
harness's record switch, and the harness's own pieces (alternation, medians and ratios, a
fresh process, the record and its header) do what the scripts rely on."""
import json
import subprocess
import sys
import time
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
BENCH = ROOT / "benchmarks"
SCRIPTS = sorted(p.name for p in BENCH.glob("*.py") if not p.name.startswith("_")
                 and p.name != "harness.py")

#: each script run as ``python benchmarks/NAME.py --help``: its own folder first on the
#: path, ``__main__`` as its name; the exit status and output of each, as one JSON line
DRIVER = r"""
import contextlib, io, json, runpy, sys
bench, names = sys.argv[1], sys.argv[2:]
sys.path.insert(0, bench)
out = {}
for name in names:
    buf, code = io.StringIO(), None
    sys.argv = [f"{bench}/{name}", "--help"]
    try:
        with contextlib.redirect_stdout(buf), contextlib.redirect_stderr(buf):
            runpy.run_path(f"{bench}/{name}", run_name="__main__")
    except SystemExit as exc:
        code = exc.code
    except BaseException as exc:
        code = f"{type(exc).__name__}: {exc}"
    out[name] = {"code": code, "text": buf.getvalue()}
print(json.dumps(out))
"""


@pytest.fixture(scope="module")
def helps():
    done = subprocess.run([sys.executable, "-c", DRIVER, str(BENCH), *SCRIPTS],
                          capture_output=True, text=True, cwd=ROOT, timeout=300)
    assert done.returncode == 0, done.stderr[-2000:]
    return json.loads(done.stdout.strip().splitlines()[-1])


def test_every_script_answers_help(helps):
    assert len(SCRIPTS) >= 30, SCRIPTS
    for name in SCRIPTS:
        got = helps[name]
        assert got["code"] in (0, None), (name, got["code"], got["text"][-500:])
        assert "usage:" in got["text"], (name, got["text"][:300])


def test_timing_scripts_offer_the_record_switch(helps):
    """Every script that writes a harness record names ``--no-record`` and ``--tag`` in
    its help."""
    users = [n for n in SCRIPTS if "harness.Record(" in (BENCH / n).read_text()]
    assert len(users) >= 23, users
    for name in users:
        assert "--no-record" in helps[name]["text"] and "--tag" in helps[name]["text"], name


def _harness():
    sys.path.insert(0, str(BENCH))
    try:
        import harness
    finally:
        sys.path.remove(str(BENCH))
    return harness


def test_alternate_rotates_and_takes_medians():
    h = _harness()
    order = []
    res = h.alternate({"a": lambda: order.append("a") or 1, "b": lambda: order.append("b") or 2,
                       "c": lambda: order.append("c") or 3}, 3)
    # round r starts with the r-th alternative, so none always runs first
    assert order == ["a", "b", "c", "b", "c", "a", "c", "a", "b"]
    assert [len(t.times) for t in res.values()] == [3, 3, 3]
    assert res["b"].results == [2, 2, 2] and res["c"].last == 3
    assert res["a"].median == sorted(res["a"].times)[1]
    assert h.ratios({"x": 2.0, "y": 3.0}, "x") == {"x": 1.0, "y": 1.5}
    fixed = []
    h.alternate({"a": lambda: fixed.append("a"), "b": lambda: fixed.append("b")}, 2,
                rotate=False)
    assert fixed == ["a", "b", "a", "b"]


def test_fresh_reads_the_childs_last_json_line():
    h = _harness()
    got = h.fresh([sys.executable, "-c", "import os; print('noise'); "
                   "print('{\"threads\": \"%s\"}' % os.environ['OMP_NUM_THREADS'])"], threads=1)
    assert got == {"threads": "1"}
    with pytest.raises(RuntimeError, match="exit 3"):
        h.fresh([sys.executable, "-c", "raise SystemExit(3)"])


def test_record_names_machine_load_libraries_and_commit(tmp_path, monkeypatch):
    h = _harness()
    monkeypatch.setattr(h, "RECORDS", tmp_path)
    with h.Record("benchmarks/demo.py", argv=["--repeat", "2"]) as rec:
        rec["case"] = {"median_s": 1.0}
        first = json.loads(rec.path.read_text())          # written after the case already
        time.sleep(0.2)
    assert first["results"] == {"case": {"median_s": 1.0}}
    assert rec.path.parent == tmp_path
    assert rec.path.name.startswith("demo-") and rec.path.name.endswith("-repeat-2.json")
    doc = json.loads(rec.path.read_text())
    assert doc["machine"]["cores"] >= 1 and doc["machine"]["ram_gb"] > 0
    assert {"loadavg_start", "loadavg_end", "others_cpu_s", "others_busy"} <= set(doc["load"])
    libs = doc["libraries"]
    assert libs["numpy"] and libs["scipy"] and libs["python"] == "%d.%d.%d" % sys.version_info[:3]
    assert "blas" in libs and "optional" in libs
    assert len(doc["git"]["commit"]) == 40
    # a second record of the same day and tag keeps the first
    with h.Record("benchmarks/demo.py", argv=["--repeat", "2"]) as again:
        pass
    assert again.path != rec.path and rec.path.exists()
    with h.Record("benchmarks/demo.py", argv=["--no-record"], enabled=False) as off:
        off["x"] = 1
    assert not off.path.exists()


def test_transcribed_records_name_their_source():
    """A record transcribed from a comment says from where (file, lines, commit) and
    carries the comment's text; its numbers are under ``results``."""
    done = list((BENCH / "records").glob("*.json"))
    transcribed = [json.loads(p.read_text()) for p in done]
    transcribed = [d for d in transcribed if "transcribed" in d]
    assert len(transcribed) >= 20
    for d in transcribed:
        src = d["transcribed"]
        assert (ROOT / src["from"]).exists() and len(src["commit"]) == 40, src
        assert d["results"] and d["comment"] and d["date"], src
