"""The local pool's schedule (issue 32): both cores by default, longest run first, the
memory budget over the runs in flight together, the critical path, --run-timeout."""
import io
import json
import os
import subprocess
import sys
import time
from pathlib import Path

import pytest

from pdverify import budget, validate
from pdverify.report import build_report
from pdverify.runner import run_cases
from pdverify.schedule import Slot, critical_path, default_jobs, longest_first
from pdverify.scenes import MethodSpec, Outcome, Scene, register
from pdverify.scenes import _REGISTRY

ROOT = Path(__file__).resolve().parents[2]
GIB = 2 ** 30


class _Timed(Scene):
    """Test-only scene: ``sleep`` sleeps far longer than any timeout used here, ``big``
    and ``small`` sleep briefly with a large and a small memory estimate, ``fine``
    returns at once."""

    id = "test-timed"
    title = "test only"
    methods = (MethodSpec("fine"), MethodSpec("sleep"), MethodSpec("big"), MethodSpec("small"))

    def estimate(self, method, params):
        size = {"big": 0.6 * GIB, "small": 0.1 * GIB}.get(method, 0.0)
        return budget.Estimate(size, f"test-only {method}")

    def solve(self, method, params, timer):
        time.sleep({"sleep": 300.0, "big": 0.4, "small": 0.4}.get(method, 0.0))
        return Outcome(metrics={"value": 1.0})

    def cases(self, quick=False):
        return [("fine", {}), ("sleep", {}), ("fine", {})]


@pytest.fixture
def timed_scene():
    if "test-timed" not in _REGISTRY:
        register(_Timed)
    yield
    _REGISTRY.pop("test-timed", None)
    budget.set_limit(None)


def test_jobs_default_to_the_cores_available_to_the_process():
    assert validate.jobs(None) == default_jobs() == len(os.sched_getaffinity(0))
    assert validate.jobs(1) == 1


def test_longest_first_unknown_in_plan_order_then_known_by_time():
    cases = [("bar1d-traction", "none", {}), ("bar1d-traction", "energy", {}),
             ("bar1d-traction", "volume", {}), ("bar1d-traction", "none", {"spacing": 0.025})]
    from pdverify.results import run_key
    from pdverify.scenes import get_scene
    scene = get_scene("bar1d-traction")
    key = [run_key(s, m, scene.resolve(m, o)) for s, m, o in cases]
    assert longest_first(cases) == [0, 1, 2, 3]
    known = {key[0]: 0.5, key[1]: 9.0, key[3]: 2.0}
    assert longest_first(cases, known) == [2, 1, 3, 0]


def test_the_memory_budget_holds_for_the_runs_in_flight_together(timed_scene):
    # 0.6 GiB + 0.6 GiB > the 1 GiB limit: the two big runs never overlap, while a small
    # one (0.1 GiB) runs beside a big one
    budget.set_limit("1G")
    cases = [("test-timed", m, {}) for m in ("small", "big", "small", "big", "small")]
    slots = []
    results = run_cases(cases, jobs=2, schedule=slots)
    assert [r.status for r in results] == ["ok"] * 5
    spans = {k: (s, e) for slot in slots for k, s, e in slot.runs}
    (s1, e1), (s3, e3) = spans[1], spans[3]
    assert e1 <= s3 or e3 <= s1
    # the cases start in the plan's order (no earlier times known)
    assert sorted(spans, key=lambda k: spans[k][0]) == [0, 1, 2, 3, 4]
    smalls = [spans[k] for k in (0, 2, 4)]
    assert any(s < e1 and e > s1 or s < e3 and e > s3 for s, e in smalls)


def test_run_timeout_kills_the_run_and_the_report_goes_on(timed_scene, tmp_path):
    out = tmp_path / "report"
    stream = io.StringIO()
    t0 = time.monotonic()
    code = build_report(out=str(out), only=["test-timed", "bar1d-traction"], jobs=2,
                        run_timeout=1.0, progress=stream)
    assert time.monotonic() - t0 < 120            # not the 300 s of the sleeping run
    assert code == 1
    runs = json.loads((out / "results.json").read_text())["runs"]
    mine = [r for r in runs if r["scene"] == "test-timed"]
    assert [r["status"] for r in mine] == ["ok", "failed", "ok"]
    assert "timed out after 1 s" in mine[1]["message"]
    assert all(r["status"] == "ok" for r in runs if r["scene"] == "bar1d-traction")
    assert "critical path: worker " in stream.getvalue()


def test_run_timeout_on_the_command_line(tmp_path):
    # plate2d-plane-strain's uncorrected run: 3.4 s measured on a quiet machine (8.7 s
    # loaded), 34 times the 0.1 s limit
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    out = subprocess.run([sys.executable, "-m", "pdverify", "run", "plate2d-plane-strain",
                          "--method", "none", "--run-timeout", "0.1"],
                         capture_output=True, text=True, env=env, cwd=tmp_path)
    assert out.returncode == 1, out.stderr
    assert "failed (timed out after 0.1 s" in out.stdout
    bad = subprocess.run([sys.executable, "-m", "pdverify", "report", "--run-timeout", "0"],
                         capture_output=True, text=True, env=env, cwd=tmp_path)
    assert bad.returncode == 2 and "--run-timeout=0" in bad.stderr


def test_critical_path_names_the_last_workers_runs():
    cases = [("bar1d-traction", "none", {}), ("bar1d-traction", "energy", {}),
             ("bar1d-traction", "volume", {})]
    slots = [Slot([(0, 0.0, 4.0)]), Slot([(1, 0.0, 1.0), (2, 1.0, 5.5)])]
    text = critical_path(slots, cases)
    assert text.startswith("critical path: worker 2 of 2 finished last, at 5.5 s (2 runs")
    assert "finished at 4.0, 5.5 s" in text
    assert text.index("volume") < text.index("energy")   # the longest run first


def test_run_timeout_with_a_scheduler_is_bad_input(tmp_path):
    from pdverify.errors import InputError
    with pytest.raises(InputError, match="--run-timeout .* --scheduler"):
        build_report(out=str(tmp_path / "r"), only=["bar1d-traction"], run_timeout=5.0,
                     scheduler="tcp://127.0.0.1:1")
    assert not (tmp_path / "r").exists()          # refused before any work


class _Pid(Scene):
    """Test-only scene: each run reports the process id it ran in, and how many runs
    that process has run (module state a long-lived worker would carry over)."""

    id = "test-pid"
    title = "test only"
    methods = (MethodSpec("light"), MethodSpec("heavy"))
    seen = []

    def estimate(self, method, params):
        return budget.Estimate({"heavy": 0.2 * GIB}.get(method, 0.0), f"test-only {method}")

    def solve(self, method, params, timer):
        _Pid.seen.append(method)
        return Outcome(metrics={"pid": float(os.getpid()), "runs_here": float(len(_Pid.seen))})


@pytest.fixture
def pid_scene():
    if "test-pid" not in _REGISTRY:
        register(_Pid)
    yield
    _REGISTRY.pop("test-pid", None)
    budget.set_limit(None)


def test_workers_are_recycled_after_a_bounded_number_of_runs(pid_scene, monkeypatch):
    """A worker ends after RUNS_PER_WORKER runs and a fresh process takes its place, so no
    process carries its address space through the whole report (the 6 GB ulimit -v
    finding: MemoryErrors from a worker's 179th run on)."""
    import pdverify.runner as runner
    monkeypatch.setattr(runner, "RUNS_PER_WORKER", 2)
    slots = []
    results = run_cases([("test-pid", "light", {})] * 5, jobs=1, schedule=slots)
    pids = [r.metrics["pid"] for r in results]
    assert [r.metrics["runs_here"] for r in results] == [1, 2, 1, 2, 1]
    assert len(set(pids)) == 3 and slots[0].processes == 3
    assert os.getpid() not in pids


def test_a_heavy_run_has_its_worker_to_itself(pid_scene):
    """A run whose estimate is at least HEAVY_FRACTION of the budget (0.2 of 1 GiB) is
    its worker's first and last (its peak memory is its own); light runs share one."""
    budget.set_limit("1G")
    cases = [("test-pid", m, {}) for m in ("light", "light", "heavy", "light", "light")]
    results = run_cases(cases, jobs=1)
    assert [r.metrics["runs_here"] for r in results] == [1, 2, 1, 1, 2]


class _Referenced(Scene):
    """Test-only scene: ``fem`` computes the reference (sleeps 0.6 s), ``pd`` reads it."""

    id = "test-referenced"
    title = "test only"
    methods = (MethodSpec("fem"), MethodSpec("pd"))

    def solve(self, method, params, timer):
        time.sleep(0.6 if method == "fem" else 0.05)
        return Outcome(metrics={"value": 1.0})


class _Other(Scene):
    id = "test-other"
    title = "test only"
    methods = (MethodSpec("work"),)

    def solve(self, method, params, timer):
        time.sleep(0.3)
        return Outcome(metrics={"value": 1.0})


@pytest.fixture
def referenced_scenes():
    for cls in (_Referenced, _Other):
        if cls.id not in _REGISTRY:
            register(cls)
    yield
    for cls in (_Referenced, _Other):
        _REGISTRY.pop(cls.id, None)


def test_reference_runs_start_first_and_no_run_waits_on_one(referenced_scenes):
    """The FEM run starts first even when known to be short (a warm cache), and while it
    runs the other worker takes cases of other scenes, not the runs that read its
    reference (in a cold report they would wait on its cache lock)."""
    cases = [("test-referenced", "pd", {}), ("test-referenced", "pd", {}),
             ("test-other", "work", {}), ("test-referenced", "fem", {}),
             ("test-other", "work", {}), ("test-other", "work", {})]
    from pdverify.results import run_key
    known = {run_key("test-referenced", "fem", {}): 0.01}
    assert longest_first(cases, known) == [3, 0, 1, 2, 4, 5]
    slots = []
    results = run_cases(cases, jobs=2, schedule=slots)
    assert [r.status for r in results] == ["ok"] * 6
    spans = {k: (s, e) for slot in slots for k, s, e in slot.runs}
    fem_end = spans[3][1]
    # the other runs (0.9 s together) outlast the reference (0.6 s): the readers start
    # only when it is done (in plan order a reader would start beside it, at once), the
    # other worker meanwhile on the other scene's runs
    assert all(spans[k][0] >= fem_end for k in (0, 1))
    assert min(spans[k][0] for k in (2, 4, 5)) < spans[3][0] + 0.3
