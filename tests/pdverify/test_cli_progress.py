"""The report a researcher reads at a glance: live progress (plain lines off a terminal),
the end-of-report summary, choices in ``list``, the paper's value in ``run``."""
import io
import json
import sys
import re

import pytest

from pdverify.cli import main
from pdverify.progress import RunProgress, clock, is_terminal
from pdverify.report import build_report
from pdverify.report.summary import SceneSummary, format_summary, summarise
from pdverify.results import RunResult
from pdverify.runner import plan, run_cases
from pdverify.scenes import get_scene

#: today's line, then the elapsed time and the ETA
LINE = re.compile(r"^\[(\d+)/(\d+)\] (\S+) (\S+) .*\.\.\. (ok|FAILED: .*|failed as expected: .*) "
                  r"\(\d+\.\d\d s\).*"
                  r" \| elapsed (\d+:\d\d), ETA (\d+:\d\d|\?)$")
ANSI = re.compile(r"\x1b\[[0-9;?]*[A-Za-z]")


class FakeTTY(io.StringIO):
    """A stream that says it is a terminal, so the live (rich) display is drawn."""

    def isatty(self):
        return True


def _result(scene, method, total_s, status="ok", message=""):
    return RunResult(scene=scene, method=method, params={}, reference="analytic",
                     status=status, message=message, metrics={"rel_l2_error": 0.5},
                     timings={"setup_s": 0.0, "solve_s": total_s, "total_s": total_s})


CASES = [("bar1d-traction", "none", {}), ("bar1d-traction", "taylor-fictitious", {"order": 2}),
         ("bar1d-traction", "energy", {}), ("bar1d-traction", "volume", {}),
         ("bar1d-traction", "none", {"spacing": 0.025})]


def test_clock():
    assert [clock(s) for s in (None, 0, 7.4, 754, 3723)] == ["?", "0:00", "0:07", "12:34",
                                                             "1:02:03"]


def test_eta_is_mean_run_time_times_runs_left_over_workers():
    stream = io.StringIO()
    with RunProgress(CASES, 2, stream) as shown:
        assert not shown.live and shown.eta() is None
        shown.started(0, timed=False)   # its own run time (3 s) stands for its duration
        shown.finished(0, _result("bar1d-traction", "none", 3.0))
        # the ETA formula in floats: pytest.approx's default rel 1e-6 covers its rounding
        assert shown.eta() == pytest.approx(3.0 * 4 / 2)
        shown.started(1, timed=False)
        shown.finished(1, _result("bar1d-traction", "taylor-fictitious", 5.0))
        assert shown.eta() == pytest.approx(4.0 * 3 / 2)
    lines = stream.getvalue().splitlines()
    assert lines[0].startswith("[1/5] bar1d-traction none") and lines[0].endswith(", ETA 0:06")
    assert lines[1].startswith("[2/5] ") and lines[1].endswith(", ETA 0:06")
    assert all(" | elapsed 0:0" in line for line in lines)


def test_plain_lines_off_a_terminal_carry_elapsed_and_eta():
    stream = io.StringIO()
    assert not is_terminal(stream)
    results = run_cases(CASES, jobs=2, progress=stream)
    assert [r.status for r in results] == ["ok"] * len(CASES)
    lines = stream.getvalue().splitlines()
    assert len(lines) == len(CASES)
    matched = [LINE.match(line) for line in lines]
    assert all(matched), lines
    assert [int(m.group(1)) for m in matched] == list(range(1, len(CASES) + 1))
    assert {int(m.group(2)) for m in matched} == {len(CASES)}
    assert all(m.group(7) != "?" for m in matched)  # every line follows a finished run
    assert "\x1b[" not in stream.getvalue()         # no terminal control codes
    # the format older tools parse: "[k/n] scene method ... ok ("
    assert all(re.match(r"^\[\d+/\d+\] bar1d-traction \S+ .*\.\.\. ok \(", x) for x in lines)


def test_live_display_on_a_terminal_shows_runs_in_flight_and_eta():
    stream = FakeTTY()
    assert is_terminal(stream)
    with RunProgress(CASES, 2, stream) as shown:
        assert shown.live and shown.tick_s is not None
        shown.started(0)
        shown.started(1)
        shown.tick()
        first = ANSI.sub("", stream.getvalue())
        assert "0/5 runs" in first and "ETA ?" in first
        assert "running bar1d-traction none" in first
        assert "running bar1d-traction taylor-fictitious order=2" in first
        shown.in_flight[0] = None       # as if queued on a cluster: its run time counts
        shown.finished(0, _result("bar1d-traction", "none", 4.0))
        shown.started(2)
        shown.tick()
    text = ANSI.sub("", stream.getvalue())
    assert "[1/5] bar1d-traction none" in text      # the finished run, above the display
    assert "1/5 runs" in text and "ETA 0:08" in text  # 4 s x 4 left / 2 workers
    assert "running bar1d-traction energy" in text
    assert "\x1b[" in stream.getvalue()             # drawn with terminal control codes


def test_live_display_through_the_worker_pool():
    stream = FakeTTY()
    results = run_cases(CASES[:3], jobs=2, progress=stream)
    assert [r.status for r in results] == ["ok"] * 3
    text = ANSI.sub("", stream.getvalue())
    assert "3/3 runs" in text and "ETA 0:00" in text and "running bar1d-traction" in text
    assert text.count("[3/3] ") == 1


#: the two scenes of the quick report below: a bar whose best methods are exact, a sheet
#: whose best is PDDO read for bond-based PD (issue 55: rel L2 1.51 % against the surface
#: nodes' 1.76 %; before them energy-directional)
ONLY = ["bar1d-traction", "sheet2d-clamped"]


@pytest.fixture(scope="module")
def quick_report(tmp_path_factory):
    """(progress text, results.json) of the quick report of ONLY: built once and shared
    by the summary tests below (issue 32: one of them ran the same quick plan again
    through run_cases; the report runs that plan, and its runs are deterministic)."""
    out = tmp_path_factory.mktemp("quick") / "rep"
    stream = io.StringIO()
    assert build_report(out=str(out), quick=True, only=ONLY, progress=stream) == 0
    return stream.getvalue(), json.loads((out / "results.json").read_text())


def test_format_summary_lists_every_scene_with_its_best_method(quick_report):
    only = ONLY
    doc = quick_report[1]
    # the report ran the quick plan, every case of it
    assert [(r["scene"], r["method"]) for r in doc["runs"]] == \
        [(s, m) for s, m, _ in plan(only=only, quick=True)]
    results = [RunResult.from_json(r) for r in doc["runs"]]
    summaries = [summarise(get_scene(s), [r for r in results if r.scene == s]) for s in only]
    text = format_summary(summaries)
    lines = text.splitlines()
    assert lines[0].split()[:3] == ["scene", "best", "method"]
    assert "first failure" not in lines[0]          # no run failed
    for s in summaries:
        assert s.best is not None
        row = next(line for line in lines if line.startswith(s.scene + " "))
        assert row.split()[1] == s.best
        assert f"{100 * s.best_error:.3g} %" in row
        assert row.split()[-2:] == [str(s.runs), "0"]
    # on the traction bar four treatments reproduce the linear field to round-off, so the
    # best is whichever round-off is smallest; it must be one of them, at round-off
    exact = {"taylor-fictitious", "surface-nodes", "mirror-nodes", "pddo"}
    assert summaries[0].best in exact and summaries[0].best_error < 1e-12
    assert summaries[1].best == "pddo"


def test_format_summary_shortens_the_first_failure():
    long = "numerical error: LinAlgError: " + "Singular matrix " * 10
    text = format_summary([
        SceneSummary("a-scene", "rel_l2_error", "energy", 0.0123, 1.5, 3, []),
        SceneSummary("b-scene", "max_error_pct", None, None, None, 2,
                     [("none", long), ("energy", "second")])])
    lines = text.splitlines()
    assert "first failure" in lines[0]
    a = next(line for line in lines if line.startswith("a-scene"))
    b = next(line for line in lines if line.startswith("b-scene"))
    assert "energy" in a and "1.23 %" in a and "1.50 s" in a
    assert "none: numerical error" in b and b.endswith("...") and "second" not in b
    assert len(b) < len(long)


def test_report_prints_the_summary_before_its_last_line(quick_report):
    lines = quick_report[0].splitlines()
    assert lines[-1].startswith("report: ")
    # the machine's load, when it varied (summary.load_note: a loaded machine), before it
    lines = [line for line in lines if not line.startswith("The machine's load varied")]
    # the heaviest run by its measured peak memory (Linux: each run records it)
    memory = [k for k, line in enumerate(lines)
              if line.startswith("largest peak memory of a run: ")]
    if sys.platform.startswith("linux"):
        assert memory == [len(lines) - 2]
    lines = [line for k, line in enumerate(lines) if k not in memory]
    # the critical path: the last worker's runs, the longest of them named
    assert lines[-2].startswith("critical path: worker ") and "sheet2d-clamped" in lines[-2]
    head = next(k for k, line in enumerate(lines) if line.startswith("scene "))
    rows = lines[head + 1:-2]
    # the traction bar's best is one of the four treatments exact for its linear field
    # (their errors are round-off, so which one is smallest is not a property)
    assert [r.split()[0] for r in rows] == ["bar1d-traction", "sheet2d-clamped"]
    assert rows[0].split()[1] in {"taylor-fictitious", "surface-nodes", "mirror-nodes", "pddo"}
    assert rows[1].split()[1] == "pddo"
    # each finished run's line; a heartbeat (progress.HEARTBEAT_S) when a minute passed
    # without one, as on a loaded machine; then the figure phase's lines
    figures = [k for k, line in enumerate(lines[:head]) if line.startswith("figures")]
    assert figures and figures == list(range(figures[0], head))
    assert lines[figures[0]].startswith("figures: drawing ")
    tasks = int(lines[figures[0]].split()[2])
    assert len(figures) == tasks + 1 and lines[head - 1].startswith(f"figures {tasks}/{tasks}: ")
    assert all(LINE.match(line) or line.startswith("... running: ")
               for line in lines[:figures[0]])


def test_list_shows_the_choices_of_a_choice_param(capsys):
    assert main(["list"]) == 0
    out = capsys.readouterr().out
    assert "plane=strain {strain|stress}" in out
    assert "end_weight=full {full|half}" in out
    assert "length=1 m," in out and "length=1 m {" not in out  # no braces without choices


@pytest.mark.parametrize("args, reference, metric, paper", [
    (["sheet2d-clamped", "--method", "none"], "fem", "tensile_stress_mpa",
     "paper: 4.17 (seed 003 Table 2, row 2)"),
    (["bar1d-homogenization", "--method", "homogenized"], "analytic", "micromodulus_factor",
     "paper: 1.067 (seed 004 Table 1, f_1(m))"),
])
def test_run_prints_the_reference_and_the_paper_value(args, reference, metric, paper, capsys):
    assert main(["run", *args]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert f"(reference: {reference}): ok" in lines[0]
    row = next(line for line in lines if line.split()[0] == metric)
    assert row.endswith(paper)
    # a metric the paper does not print has no paper value
    assert any(line.split()[0] == "rel_l2_error" and "paper" not in line for line in lines)
