"""Issue 3's speed budget: bar1d-vibration with N = 1000 and 10^4 steps in under 3 s."""
import pytest

from pdverify.scenes import get_scene


@pytest.mark.bench
@pytest.mark.parametrize("method", ["none", "homogenized"])
def test_vibration_1000_points_10k_steps_under_3_s(method):
    # 3.5 periods at dt = 0.8 * 2/omega_max is about 1.1e4 steps for N = 1000, delta = 4 Delta
    r = get_scene("bar1d-vibration").run(method, {"nodes": 1000, "periods": 3.5})
    assert r.status == "ok", r.message
    assert r.size["steps"] >= 10_000
    assert r.timings["total_s"] < 3.0, r.timings
