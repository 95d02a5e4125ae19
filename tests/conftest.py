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
