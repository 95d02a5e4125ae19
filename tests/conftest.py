"""Shared pytest configuration: Agg backend, strict float errors, seeded rng."""
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


def pytest_collection_modifyitems(config, items):
    if config.getoption("--bench"):
        return
    skip = pytest.mark.skip(reason="timing benchmark: run with --bench")
    for item in items:
        if "bench" in item.keywords:
            item.add_marker(skip)
