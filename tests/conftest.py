"""Shared pytest configuration: Agg backend, strict float errors, seeded rng, and the two
test tiers: tests marked ``slow`` are skipped unless ``--runslow`` (the README's test
command runs the fast tier; ``.ci/run`` then runs the slow one with
``--runslow -m slow``)."""
import os

os.environ.setdefault("MPLBACKEND", "Agg")

import numpy as np
import pytest


@pytest.fixture(autouse=True)
def _strict_float_errors():
    old = np.seterr(all="raise", under="ignore")
    yield
    np.seterr(**old)


@pytest.fixture(autouse=True)
def _one_blas_thread(request):
    """Every test computes with one BLAS thread, as every run does (pdverify.blas): the
    numbers a test computes beside a run's are made the same way, and the suite does not
    depend on OpenBLAS's threads, which on a busy 2-core machine turned the dense rank
    checks of tests/treatments/test_taylor_3d.py (a 712 x 864 SVD: 0.17 s with one thread)
    into 4.4 s each (issue 32). Tests of the thread setting itself opt out with
    ``@pytest.mark.blas_default_threads`` and see the process's own setting."""
    if request.node.get_closest_marker("blas_default_threads"):
        yield
        return
    from pdverify import blas
    with blas.one_thread():
        yield


@pytest.fixture
def rng():
    return np.random.default_rng(20211121)


def pytest_addoption(parser):
    parser.addoption("--bench", action="store_true", default=False,
                     help="run the timing benchmarks (marked 'bench') against the issues' budgets")
    parser.addoption("--runslow", action="store_true", default=False,
                     help="also run the tests marked 'slow' (CI's second tier)")


def pytest_collection_modifyitems(config, items):
    bench = config.getoption("--bench")
    slow = config.getoption("--runslow")
    skip_bench = pytest.mark.skip(reason="timing benchmark: run with --bench")
    skip_slow = pytest.mark.skip(reason="slow tier: run with --runslow")
    for item in items:
        if "bench" in item.keywords and not bench:
            item.add_marker(skip_bench)
        if "slow" in item.keywords and not slow:
            item.add_marker(skip_slow)


_SHARED_RUNS = {}


@pytest.fixture(scope="session")
def run_once():
    """``run_once(scene, method, **over)``: the scene's run, made once per test session and
    shared by every test that asks for the same scene, method and parameters (issue 32:
    several files re-ran the same default case). The runs are deterministic (the report is
    bitwise reproducible), so a shared result is the one each test would have made; tests
    read it and must not change it. A test that patches pdverify must call the scene
    itself."""
    from pdverify.scenes import get_scene

    def run(scene, method=None, **over):
        key = (scene, method, repr(sorted(over.items())))
        if key not in _SHARED_RUNS:
            _SHARED_RUNS[key] = get_scene(scene).run(method, dict(over))
        return _SHARED_RUNS[key]
    return run


@pytest.fixture(scope="session")
def cli_concurrently():
    """``cli_concurrently(argvs, env=None, cwd=None)``: each argv run as its own
    ``python -m pdverify ARGV`` (a fresh interpreter: its real exit code and stderr), as
    many at a time as the process has cores; returns ``{tuple(argv): CompletedProcess}``.
    For the tables of bad-input cases, whose cost is the interpreter's start (issue 32)."""
    import subprocess
    import sys
    from concurrent.futures import ThreadPoolExecutor

    def run_all(argvs, env=None, cwd=None, timeout=120):
        def one(argv):
            return subprocess.run([sys.executable, "-m", "pdverify", *argv],
                                  capture_output=True, text=True, env=env, cwd=cwd,
                                  timeout=timeout)
        argvs = [tuple(a) for a in argvs]
        with ThreadPoolExecutor(max_workers=len(os.sched_getaffinity(0))) as pool:
            return dict(zip(argvs, pool.map(one, argvs)))
    return run_all
