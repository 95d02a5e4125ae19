"""The papers' claims without a printed number, each as a metric of ours that can fail."""
import numpy as np

from pdverify.scenes import get_scene
from pdverify.scenes.bar1d import error_fluctuation_pct


def test_seed000_5_4_fluctuations_fall_as_the_order_grows():
    """seed 000 §5.4 (Fig. 25 right): increasing n reduces the fluctuations near the
    ends, while the largest error rises slightly (the paper: 0.87 -> 0.93 %)."""
    scene = get_scene("bar1d-sine-load")
    runs = [scene.run("taylor-fictitious", {"order": n}) for n in (1, 3, 5)]
    fluct = [r.metrics["error_fluctuation_pct"] for r in runs]
    peak = [r.metrics["max_error_pct"] for r in runs]
    assert fluct[0] > fluct[1] > fluct[2]
    assert peak[0] < peak[1] < peak[2]
    # the uncorrected bar fluctuates far more than any corrected one
    assert scene.run("none").metrics["error_fluctuation_pct"] > 100 * fluct[0]


def test_fluctuation_metric_sees_an_oscillation_and_not_a_smooth_error():
    """A node-to-node oscillation of amplitude a near an end gives 4 a; a smooth error
    (a parabola on a grid of spacing h) gives 2 c h^2, its exact second difference."""
    x = np.linspace(0.0, 1.0, 101)
    h = x[1] - x[0]
    smooth = 3.0 * x ** 2
    assert np.isclose(error_fluctuation_pct(x, smooth, 0.05, 1.0), 6.0 * h ** 2)
    wobble = smooth + np.where(x < 0.05, 0.01 * (-1.0) ** np.arange(x.size), 0.0)
    assert error_fluctuation_pct(x, wobble, 0.05, 1.0) > 0.039
