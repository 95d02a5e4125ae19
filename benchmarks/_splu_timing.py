"""Shared by the benchmark scripts: time SuperLU option sets on one matrix, alternating."""
from __future__ import annotations

import time

import numpy as np
import scipy.sparse.linalg as spla


def time_splu(A, alternatives: dict, repeat: int) -> dict:
    """Median seconds of factor + solve for each ``name -> splu options``, over ``repeat``
    rounds that alternate the options (so drift hits every alternative alike); every
    solution's relative residual is checked (< 1e-8)."""
    b = np.random.default_rng(0).normal(size=A.shape[0])
    times = {k: [] for k in alternatives}
    for _ in range(repeat):
        for name, opts in alternatives.items():
            t0 = time.perf_counter()
            x = spla.splu(A, **opts).solve(b)
            times[name].append(time.perf_counter() - t0)
            res = np.linalg.norm(A @ x - b) / np.linalg.norm(b)
            assert res < 1e-8, (name, res)
    return {k: float(np.median(v)) for k, v in times.items()}
