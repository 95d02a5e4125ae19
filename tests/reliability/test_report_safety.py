"""The report folder is swapped in whole (kills leave the previous report intact), and
results are reproducible bit for bit (issue 18)."""
import json
import os
import re
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
SCENES = ["bar1d-traction", "bar1d-uniform-load", "plate2d-clamped", "sheet2d-tension"]


def _report(out, *extra, env=None):
    return subprocess.Popen([sys.executable, "-m", "pdverify", "report", "--quick", "--out",
                             str(out), "--only", *SCENES, *extra],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env)


def _strip(doc):
    doc = dict(doc)
    for key in ("created", "machine"):
        doc.pop(key)
    # the costs (times, peak memory) are the machine's, not the run's numbers
    doc["runs"] = [{k: v for k, v in r.items() if k not in ("timings", "resources")}
                   for r in doc["runs"]]
    doc.pop("report_phases")          # times
    doc["convergence"] = [{**e, "levels": [{k: v for k, v in lv.items() if k != "total_s"}
                                           for lv in e["levels"]]}
                          for e in doc["convergence"]]
    return doc


@pytest.fixture(scope="module")
def env(tmp_path_factory):
    e = dict(os.environ, PDVERIFY_CACHE_DIR=str(tmp_path_factory.mktemp("cache")))
    return e


@pytest.mark.slow  # slow tier (issue 32): 361 s of the suite's 3811 s (loaded machine)
def test_results_are_bitwise_reproducible_across_runs_and_jobs(tmp_path, env):
    docs = []
    for k, jobs in enumerate((1, 1, 2)):
        p = _report(tmp_path / f"r{k}", "--jobs", str(jobs), env=env)
        p.communicate()
        assert p.returncode == 0
        docs.append(json.loads((tmp_path / f"r{k}" / "results.json").read_text()))
    # the first run computed the FEM references and perifit's weights, the others read
    # them from the cache
    for d in docs:
        for r in d["runs"]:
            r["diagnostics"].pop("from_cache", None)
            r["diagnostics"].pop("perifit_weights", None)
    assert json.dumps(_strip(docs[0])) == json.dumps(_strip(docs[1])) == json.dumps(_strip(docs[2]))


def _kill_after_last_run(out, sig, env):
    """Start a report into ``out`` and send ``sig`` as soon as its last run's progress
    line ([N/N], on stderr, one line per finished run) appears: the figure phase."""
    p = _report(out, env=env)
    seen = []
    for line in p.stderr:
        seen.append(line)
        m = re.match(r"\[(\d+)/(\d+)\]", line)
        if m and m.group(1) == m.group(2):
            p.send_signal(sig)
            break
    _, err = p.communicate()
    return p, "".join(seen) + err


def _leftovers(parent, name):
    return [e for e in os.listdir(parent) if e.startswith(f".{name}.staging-")
            or e.startswith(f".{name}.old-") or e.startswith(".tmp-")]


@pytest.mark.slow  # slow tier (issue 32): 559 s of the suite's 3811 s (loaded machine)
def test_killed_reports_leave_the_previous_one_intact(tmp_path, env):
    out = tmp_path / "rep"
    for _ in range(2):              # the second run is timed: FEM references cached
        t0 = time.perf_counter()
        p = _report(out, env=env)
        p.communicate()
        duration = time.perf_counter() - t0
        assert p.returncode == 0
    before = {n: (out / n).read_bytes() for n in ("results.json", "index.html")}
    figures = sorted(os.listdir(out / "figures"))
    points = [0.1, 0.25, 0.4, 0.55, 0.7, 0.8, 0.86, 0.9, 0.94, 0.97, 0.99, 1.02]
    for k, frac in enumerate(points):
        sig = signal.SIGKILL if k % 2 else signal.SIGTERM
        p = _report(out, env=env)
        time.sleep(frac * duration)
        p.send_signal(sig)
        _, err = p.communicate()
        if p.returncode == 0:       # it finished before the signal: a new, whole report
            assert "report:" in err
            before = {n: (out / n).read_bytes() for n in ("results.json", "index.html")}
            assert sorted(os.listdir(out / "figures")) == figures
            continue
        # 143: SIGTERM unwound the report; -15: it arrived while the interpreter was
        # exiting after a finished report (handlers are reset then); -9: SIGKILL
        assert p.returncode in (143, -signal.SIGTERM, -signal.SIGKILL), (p.returncode,
                                                                       err[-300:])
        now = {n: (out / n).read_bytes() for n in before}
        assert sorted(os.listdir(out / "figures")) == figures
        if now != before:
            # the signal came after the swap: then the new report is whole (it printed its
            # summary, which precedes the swap, and has every run), never a mix
            assert "report:" in err
            assert (len(json.loads(now["results.json"])["runs"])
                    == len(json.loads(before["results.json"])["runs"]))
            before = now
            continue
        if sig == signal.SIGTERM:   # unwinds: its staging folder is gone at once
            assert _leftovers(tmp_path, "rep") == []
    # a kill after the last run, in the figure phase, by construction rather than by
    # timing (the fractions above land there only when the machine's load holds still)
    for sig in (signal.SIGTERM, signal.SIGKILL):
        p, err = _kill_after_last_run(out, sig, env)
        assert p.returncode in (143, -signal.SIGTERM, -signal.SIGKILL), (p.returncode,
                                                                       err[-300:])
        now = {n: (out / n).read_bytes() for n in before}
        assert sorted(os.listdir(out / "figures")) == figures
        if now != before:           # only a whole new report may replace it
            assert "report:" in err
            before = now
        elif sig == signal.SIGTERM:
            assert _leftovers(tmp_path, "rep") == []
    # a SIGKILL cannot clean up; the next report into the folder removes what it left
    p = _report(out, env=env)
    p.communicate()
    assert p.returncode == 0
    assert _leftovers(tmp_path, "rep") == []


def test_second_report_into_the_same_folder_is_refused(tmp_path, env):
    # the first report is frozen (SIGSTOP) once its first run has finished, so it holds
    # the folder's lock while the second starts, however long the second takes to start on
    # a loaded machine; one cheap scene is enough for that (issue 32: this was a 4-scene
    # report with a cold FEM cache, 113 s on a loaded machine, timed by a 1.5 s sleep)
    out = tmp_path / "rep"
    first = subprocess.Popen([sys.executable, "-m", "pdverify", "report", "--quick", "--out",
                              str(out), "--only", "bar1d-traction"],
                             stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True,
                             env=env)
    try:
        seen = []
        for line in first.stderr:
            seen.append(line)
            if re.match(r"\[1/\d+\]", line):
                first.send_signal(signal.SIGSTOP)
                break
        assert first.poll() is None, "".join(seen)
        second = _report(out, env=env)
        _, err = second.communicate()
    finally:
        first.send_signal(signal.SIGCONT)
    rest = first.stderr.read()
    first.wait()
    assert second.returncode == 2
    assert "is being written by pdverify report (pid" in err and err.count("\n") == 1
    assert f"(pid {first.pid})" in err
    assert first.returncode == 0, "".join(seen) + rest
    assert "report:" in rest


def test_a_stop_inside_exec_or_import_waits_until_it_has_returned(monkeypatch):
    """A KeyboardInterrupt raised inside ``exec`` (dataclasses build their methods so) makes
    CPython 3.11 exit by SIGINT after the CLI caught it, and one raised inside an extension
    module's init becomes an ImportError: the SIGTERM handler defers it there."""
    from pdverify import cli
    from pdverify.errors import STOP_REQUESTED
    monkeypatch.setitem(STOP_REQUESTED, "flag", False)
    timers = []
    monkeypatch.setattr(cli.signal, "setitimer", lambda which, seconds: timers.append(seconds))
    exec("cli._terminate(signal.SIGTERM, sys._getframe())",
         {"cli": cli, "signal": signal, "sys": sys})
    assert STOP_REQUESTED["flag"] and timers == [cli._RETRY_S]
    with pytest.raises(KeyboardInterrupt):      # the retry, back outside: the stop lands
        cli._retry(signal.SIGALRM, sys._getframe())
    STOP_REQUESTED["flag"] = False
    cli._retry(signal.SIGALRM, sys._getframe())  # no stop pending: an alarm does nothing


def test_a_stop_after_main_has_returned_lands_in_a_program_run_from_a_string():
    """``main()`` called in-process leaves its SIGTERM handler; in a program that runs
    from a string (``python -c``, a pytest-xdist worker) a SIGTERM after it has returned
    still ends the process: the program's own outermost string is no ``exec`` that will
    return (it deferred the stop for good: a pool worker forked by a test under xdist
    never ended)."""
    code = ("import os, signal, time\n"
            "from pdverify.cli import main\n"
            "main(['list'])\n"
            "os.kill(os.getpid(), signal.SIGTERM)\n"
            "time.sleep(3)\n"
            "print('survived')\n")
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    p = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                       env=env, timeout=120)
    assert "survived" not in p.stdout
    assert "KeyboardInterrupt" in p.stderr, p.stderr   # unwound like Ctrl-C
