"""Shared by the benchmark scripts: time SuperLU option sets on one matrix, alternating."""
from __future__ import annotations

import numpy as np
import scipy.sparse.linalg as spla

import harness


def time_splu(A, alternatives: dict, repeat: int) -> dict:
    """Median seconds of factor + solve for each ``name -> splu options``, over ``repeat``
    rounds that alternate the options (``harness.alternate``: drift hits every
    alternative alike); every solution's relative residual is checked (< 1e-8)."""
    b = np.random.default_rng(0).normal(size=A.shape[0])

    def solve(name, opts):
        x = spla.splu(A, **opts).solve(b)
        res = np.linalg.norm(A @ x - b) / np.linalg.norm(b)
        assert res < 1e-8, (name, res)
    runs = harness.alternate({name: (lambda name=name, opts=opts: solve(name, opts))
                              for name, opts in alternatives.items()}, repeat)
    return {k: t.median for k, t in runs.items()}
