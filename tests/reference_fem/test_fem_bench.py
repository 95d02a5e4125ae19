"""Timing budgets of issue 5 (run with --bench): each reference's whole refinement study
under 30 s on 2 cores, a cached reuse under 1 s."""
import time

import pytest

import reference_fem as rf
from reference_fem import cache

# issue 5 "Speed": converged level (whole study) < 30 s, cached reuse < 1 s
FIRST_RUN_BUDGET_S = 30.0
CACHED_BUDGET_S = 1.0
#: issue 56: the elastodynamic pulse's study (a time integration per level) cold at most 60 s
FIRST_RUN_BUDGETS_S = {"plate-pulse": 60.0}


@pytest.mark.bench
@pytest.mark.parametrize("reference", sorted(rf.REFERENCES))
def test_reference_time_budget(reference, tmp_path, monkeypatch):
    monkeypatch.setenv(cache.ENV_VAR, str(tmp_path))
    run = rf.REFERENCES[reference]
    t0 = time.perf_counter()
    first = run()
    first_s = time.perf_counter() - t0
    t0 = time.perf_counter()
    again = run()
    cached_s = time.perf_counter() - t0
    print(f"\n{reference}: first {first_s:.2f} s (study {first.study_s:.2f} s, finest level "
          f"setup {first.setup_s:.2f} s + solve {first.solve_s:.2f} s), cached {cached_s:.3f} s")
    assert not first.from_cache and again.from_cache
    assert first_s < FIRST_RUN_BUDGETS_S.get(reference, FIRST_RUN_BUDGET_S)
    assert cached_s < CACHED_BUDGET_S
