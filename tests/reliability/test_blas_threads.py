"""Every run computes with one BLAS thread (pdverify.blas), in-process and in a report's
workers, so that its numbers do not depend on the machine's core count or on --jobs."""
import numpy as np
import pytest

from pdverify import blas
from pdverify.runner import run_cases
from pdverify.scenes import MethodSpec, Outcome, Scene, register
from pdverify.scenes import _REGISTRY

#: these tests need the caller's own BLAS threads (conftest runs the others with one)
pytestmark = pytest.mark.blas_default_threads


class _Threads(Scene):
    """Test-only scene: reports the BLAS threads its solve ran with, and a dot product
    long enough for OpenBLAS to split it among threads."""

    id = "test-blas-threads"
    title = "test only"
    methods = (MethodSpec("probe"),)

    def solve(self, method, params, timer):
        v = np.sin(np.arange(200_000) * 0.37)
        return Outcome(metrics={"blas_threads": float(blas.threads()), "dot": float(v @ v)})


@pytest.fixture
def threads_scene():
    if _Threads.id not in _REGISTRY:
        register(_Threads)
    yield
    _REGISTRY.pop(_Threads.id, None)


def test_a_run_uses_one_blas_thread_and_restores_the_setting(threads_scene):
    before = blas.threads()
    res = _REGISTRY[_Threads.id].run("probe")
    assert res.status == "ok" and res.metrics["blas_threads"] == 1
    assert blas.threads() == before          # the caller's setting is back


@pytest.mark.parametrize("jobs", [1, 2])
def test_report_workers_run_with_one_blas_thread(threads_scene, jobs):
    results = run_cases([(_Threads.id, "probe", {})] * 2, jobs=jobs)
    assert [r.metrics["blas_threads"] for r in results] == [1, 1]


def test_a_long_dot_product_is_the_same_whatever_the_callers_threads(threads_scene):
    """The run's dot product equals the one-thread one bit for bit, also when the caller
    allows more threads (where the machine has them, two threads add it in another order:
    the reason for pdverify.blas)."""
    v = np.sin(np.arange(200_000) * 0.37)
    with blas.one_thread():
        single = float(v @ v)
    assert _REGISTRY[_Threads.id].run("probe").metrics["dot"] == single
