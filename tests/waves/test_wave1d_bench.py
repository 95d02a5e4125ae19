"""Speed budget of issue 4: m = 100 (1000 nodes, 1000 steps) in under 1 s."""
import pytest

from pdverify.scenes import get_scene


@pytest.mark.bench
@pytest.mark.parametrize("method", ["surface-nodes", "none"])
def test_m100_run_within_one_second(method, record_property):
    scene = get_scene("wave1d-surface-nodes")
    scene.run(method, {"m_ratio": 10})  # warm imports and caches
    best = min((scene.run(method, {"m_ratio": 100}) for _ in range(3)),
               key=lambda r: r.timings["total_s"])
    assert best.status == "ok", best.message
    t = best.timings
    record_property("timings", t)
    print(f"\n{method} m=100: setup {t['setup_s']:.3f} s, solve {t['solve_s']:.3f} s, "
          f"total {t['total_s']:.3f} s")
    assert best.size["real_nodes"] == 1000 and best.diagnostics["n_steps"] == 1000
    assert t["total_s"] < 1.0  # issue 4, Speed
