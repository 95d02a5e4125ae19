"""Runs that die in native code become failed runs; the report goes on (issue 18)."""
import ctypes
import faulthandler
import json
import os

import pytest

from pdverify.report import build_report
from pdverify.scenes import MethodSpec, Outcome, Scene, register
from pdverify.scenes import _REGISTRY


class _Dying(Scene):
    """Test-only scene: ``abort`` calls os.abort(), ``segfault`` dereferences NULL,
    ``fine`` returns a number."""

    id = "test-dying"
    title = "test only"
    methods = (MethodSpec("fine"), MethodSpec("abort"), MethodSpec("segfault"))

    def solve(self, method, params, timer):
        if method in ("abort", "segfault"):
            # pytest's fault handler, inherited by the report's forked workers, would print
            # the deliberate crash's "Fatal Python error" traceback on the terminal (under
            # pytest-xdist the workers' stderr is not captured); the runner reads the
            # signal from the exit status, not from that output
            faulthandler.disable()
        if method == "abort":
            os.abort()
        if method == "segfault":
            ctypes.string_at(0)
        return Outcome(metrics={"value": 1.0})

    def cases(self, quick=False):
        return [("fine", {}), ("abort", {}), ("fine", {}), ("segfault", {}), ("fine", {})]


@pytest.fixture
def dying_scene():
    if "test-dying" not in _REGISTRY:
        register(_Dying)
    yield
    _REGISTRY.pop("test-dying", None)


@pytest.mark.parametrize("jobs", [1, 2])
def test_native_deaths_are_failed_runs_and_the_report_goes_on(dying_scene, tmp_path, jobs):
    out = tmp_path / "report"
    code = build_report(out=str(out), only=["test-dying", "bar1d-traction"], jobs=jobs,
                        progress=open(os.devnull, "w"))
    assert code == 1                                    # some runs failed
    doc = json.loads((out / "results.json").read_text())
    runs = [r for r in doc["runs"] if r["scene"] == "test-dying"]
    assert [r["method"] for r in runs] == ["fine", "abort", "fine", "segfault", "fine"]
    assert [r["status"] for r in runs] == ["ok", "failed", "ok", "failed", "ok"]
    assert "SIGABRT" in runs[1]["message"] and "SIGSEGV" in runs[3]["message"]
    bar = [r for r in doc["runs"] if r["scene"] == "bar1d-traction"]
    assert bar and all(r["status"] == "ok" for r in bar)
    assert (out / "index.html").is_file()
    assert not [p for p in tmp_path.iterdir() if "staging" in p.name or ".old-" in p.name]
