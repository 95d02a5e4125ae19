"""The crack scenes' figures (issue 54): the map near the tip (a window of a few horizons,
the tip zone outlined), the opening profiles against the FEM's, K against the spacing with
the observed rates or "pre-asymptotic"; drawn from synthetic runs, no solve."""
from __future__ import annotations

import matplotlib.pyplot as plt
import numpy as np
import pytest
from matplotlib.patches import Circle

from pdverify.report.figures import cracks
from pdverify.results import RunResult
from pdverify.scenes import get_scene


def _fields(h, tip=(0.5, 0.0)):
    xs = (np.arange(int(round(1 / h))) + 0.5) * h
    ys = (np.arange(-int(round(1 / h)), int(round(1 / h))) + 0.5) * h
    X, Y = np.meshgrid(xs, ys, indexing="ij")
    x = np.c_[X.ravel(), Y.ravel()]
    err = np.c_[np.hypot(*(x - tip).T), np.zeros(len(x))]
    r = np.arange(1, 20) * h
    return {"x": x, "u": 0 * x, "u_ref": 0 * x, "error": err, "spacing": h,
            "horizon": 3 * h, "lengths": (1.0, 2.0), "tip": list(tip), "tip_zone": 6 * h,
            "opening_r": r, "opening": np.sqrt(r) * 1.01, "opening_ref": np.sqrt(r)}


def _run(scene, method, h, net):
    over = {} if h == 0.025 else {"spacing": h}
    return RunResult(scene=scene.id, method=method, params=scene.resolve(method, over),
                     reference=scene.reference, status="ok", message="",
                     metrics={"k_ratio": 1 + net / 100, "k_net_error_pct": net,
                              "k_fit_bias_pct": 0.5},
                     fields=_fields(h), timings={"total_s": 1.0})


def test_observed_rates_or_pre_asymptotic():
    assert cracks.observed_rates([0.04, 0.02, 0.01], [4.0, 1.0, 0.25]) == "rates 2.00, 2.00"
    assert cracks.observed_rates([0.01, 0.02], [0.5, 1.0]) == "rates 1.00"   # any order
    assert cracks.observed_rates([0.04, 0.02, 0.01], [0.1, -0.1, -0.2]) == "pre-asymptotic"
    assert cracks.observed_rates([0.04, 0.02], [0.1, 0.2]) == "pre-asymptotic"   # grows


def test_the_crack_figures_zoom_on_the_tip_and_give_k_against_spacing(monkeypatch):
    scene = get_scene("plate-edge-crack")
    kept = []
    monkeypatch.setattr(cracks, "save", lambda fig, folder, name: kept.append((name, fig))
                        or name)
    runs = [_run(scene, m, h, net) for m, nets in (("none", (0.5, -0.1, -0.2)),
                                                   ("energy", (0.8, 0.4, 0.2)))
            for h, net in zip((1 / 30, 0.025, 1 / 60), nets)]
    cracks._tip_maps(scene, runs, "x")
    cracks._k_refinement(scene, runs, "x")
    cracks._openings(scene, runs, "x")
    names = [n for n, _ in kept]
    assert names == ["plate-edge-crack-tip-errors.png", "plate-edge-crack-k-refinement.png",
                     "plate-edge-crack-opening.png"]
    tip_fig = kept[0][1]
    ax = tip_fig.axes[0]
    delta = 3 * 0.025
    x0, x1 = ax.get_xlim()
    # the window: +-TIP_WINDOW horizons about the tip (the image's cell edges)
    assert x1 - x0 == pytest.approx(2 * cracks.TIP_WINDOW * delta + 0.025, abs=0.026)
    circles = [p for p in ax.patches if isinstance(p, Circle)]
    assert len(circles) == 1 and circles[0].radius == pytest.approx(2 * delta)
    legends = [t.get_text() for a in kept[1][1].axes if a.get_legend()
               for t in a.get_legend().get_texts()]
    assert "none (pre-asymptotic)" in legends and "energy (rates 2.41, 1.71)" in legends
    for _, fig in kept:
        plt.close(fig)
