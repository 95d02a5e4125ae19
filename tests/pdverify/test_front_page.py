"""The report's front page and shared-scale figures (issue 34): the matrix's best
configuration beside the default one, its fitted colour scale, exact runs marked apart,
unavailable methods named, the failure links, alt text, per-scene Pareto panels and the
colour scale the methods' error maps share."""
from __future__ import annotations

import dataclasses
import re

import numpy as np
import pytest

from pdverify.report import html
from pdverify.results import RunResult
from pdverify.scenes import get_scene


def _run(scene, method, over=None, status="ok", message="", t=0.5, **metrics):
    return RunResult(scene=scene.id, method=method, params=scene.resolve(method, over or {}),
                     reference=scene.reference, status=status, message=message,
                     metrics=metrics,
                     timings={"setup_s": t / 4, "solve_s": t / 2, "total_s": t})


def _cells(text, scene_id):
    """The <td> cells of ``scene_id``'s row of the matrix, by column header."""
    heads = re.findall(r"<th>(.*?)</th>", text.split("</tr>")[0])
    heads = [h.replace("-<wbr>", "-") for h in heads]
    row = next(r for r in text.split("<tr>") if f'href="#{scene_id}"' in r)
    cells = re.findall(r"<td[^>]*>.*?</td>", row, re.S)[1:]
    return dict(zip(heads, cells))


def test_best_configuration_beside_the_default_in_per_cent():
    """Taylor order 1 is the default (0.452 %), order 2 is more accurate (0.0121 %) at a
    higher cost: the cell shows both, the best one's params and setup + solve time."""
    bar = get_scene("bar1d-uniform-load")
    runs = [_run(bar, "none", rel_l2_error=0.03),
            _run(bar, "taylor-fictitious", rel_l2_error=0.00452),
            _run(bar, "taylor-fictitious", {"order": 2}, t=2.0, rel_l2_error=1.21e-4),
            _run(bar, "taylor-fictitious", {"order": 3}, rel_l2_error=0.2)]
    cell = _cells(html.overview([bar], runs), bar.id)["taylor-fictitious"]
    default, best = cell.split('class="best"')
    assert "0.452 %" in default and "&#9733;" in default      # default run, starred
    assert "0.0121 %" in best and "order=2" in best
    assert "1.5 s" in best                                     # setup 0.5 + solve 1.0
    assert "20 %" not in cell                                  # the worse sweep run stays below
    # no better run: no best line
    assert 'class="best"' not in _cells(html.overview([bar], runs), bar.id)["none"]


def test_best_configuration_is_a_setting_on_the_same_problem():
    """A finer grid, a jittered lattice or another geometry is more accurate, but it is
    another problem or grid, not a configuration of the method (issue 52): the best line
    shows the more accurate setting on the default run's problem, and the page says the
    rule."""
    sheet = get_scene("plate-hole")
    runs = [_run(sheet, "taylor-fictitious", rel_l2_error=0.05),
            _run(sheet, "taylor-fictitious", {"order": 3}, rel_l2_error=0.02),
            _run(sheet, "energy", rel_l2_error=0.1),
            _run(sheet, "energy", {"jitter": 0.4, "jitter_seed": 1}, rel_l2_error=0.001),
            _run(sheet, "taylor-fictitious", {"spacing": sheet.resolve(
                "taylor-fictitious", {})["spacing"] / 2}, rel_l2_error=1e-4)]
    text = html.overview([sheet], runs)
    cells = _cells(text, sheet.id)
    best = cells["taylor-fictitious"].split('class="best"')[1]
    assert "2 %" in best and "order=<wbr>3" in best and "spacing" not in best
    assert 'class="best"' not in cells["energy"]            # the jittered lattice is not
    assert "never a best configuration" in text and "lattice jitter" in text


def test_colour_scale_is_fitted_to_the_errors_present():
    """The scale runs from the smallest error that is not round-off to the largest (per
    cent); the ends get the scale's two extreme colours."""
    assert html.colour_scale([0.452, 75.0, 1e-13, None, -3.0]) == (0.452, 75.0)
    assert html.colour_scale([1e-12, 0.0]) is None
    bar = get_scene("bar1d-uniform-load")
    runs = [_run(bar, "none", rel_l2_error=0.0452),
            _run(bar, "taylor-fictitious", rel_l2_error=0.00452)]
    assert html.overview_scale([bar], runs) == pytest.approx((0.452, 4.52))
    text = html.overview([bar], runs)
    cells = _cells(text, bar.id)
    lo, hi = html._colour(0.452, (0.452, 4.52)), html._colour(4.52, (0.452, 4.52))
    assert lo != hi
    assert f"background:{lo}" in cells["taylor-fictitious"]
    assert f"background:{hi}" in cells["none"]


def test_exact_runs_are_marked_apart_from_the_scale():
    bar = get_scene("bar1d-traction")
    runs = [_run(bar, "none", rel_l2_error=0.03297),
            _run(bar, "surface-nodes", rel_l2_error=9.0e-15),   # round-off
            _run(bar, "mirror-nodes", rel_l2_error=2.0e-9)]     # small, but not round-off
    cells = _cells(html.overview([bar], runs), bar.id)
    assert ">exact<" in cells["surface-nodes"] and "background" not in cells["surface-nodes"]
    assert "exact" not in cells["mirror-nodes"] and "2e-07 %" in cells["mirror-nodes"]
    assert html.overview_scale([bar], runs) == pytest.approx((2e-7, 3.297))
    # the threshold: the convergence studies' EXACT (a fraction), in per cent
    assert html.is_exact(100 * html.EXACT_FRACTION) and not html.is_exact(
        1.01 * 100 * html.EXACT_FRACTION)


def test_unavailable_method_says_so(monkeypatch):
    sheet = get_scene("sheet2d-tension")
    offered = sheet.offered()
    assert "perifit" in offered
    why = "needs the optional extra: pip install 'pdverify[perifit]'"
    fake = {**offered, "perifit": dataclasses.replace(offered["perifit"], unavailable=why)}
    monkeypatch.setattr(sheet, "offered", lambda: fake)
    runs = [_run(sheet, "none", rel_l2_error=0.5), _run(sheet, "energy", rel_l2_error=0.1)]
    cell = _cells(html.overview([sheet], runs), sheet.id)["perifit"]
    assert "unavailable: needs the optional extra" in cell


def test_failure_count_links_to_the_failed_runs_rows():
    bar = get_scene("bar1d-traction")
    ok = _run(bar, "none", rel_l2_error=0.03)
    bad = _run(bar, "surface-nodes", status="failed", message="bar1d-traction/surface-nodes: "
               "singular")
    level = _run(bar, "pddo", {"spacing": 0.05}, status="failed", message="level broke")
    expected = dataclasses.replace(_run(bar, "mirror-nodes", status="failed", message="m"),
                                   expected_failure="documented")
    results = [ok, bad, level, expected]
    section = html.scene_section(bar, [ok, bad, expected], [], deviations=[])
    doc = {"runs": [r.to_json() if hasattr(r, "to_json") else
                    {"status": r.status, "method": r.method,
                     "expected_failure": r.expected_failure, "warnings": []}
                    for r in results],
           "pdverify_version": "x", "created": "now", "machine": {"python": "3", "cpus": 1},
           "schema": "pdverify.results/1"}
    page = html.page(doc, [(bar, section)], 1.0, results, (),
                     tabled={ok.key, bad.key, expected.key})
    assert '<a href="#failed-runs" class="bad">2 failed</a>' in page
    assert 'id="failed-runs"' in page
    anchor = html.run_anchor(bad)
    assert f'href="#{anchor}"' in page and f'<tr id="{anchor}"' in page
    # a convergence level without a row links to the scene's convergence section
    assert 'href="#bar1d-traction-convergence"' in page
    assert html.run_anchor(expected) not in page.split('id="failed-runs"')[1].split("</ul>")[0]


def test_no_failure_no_link():
    bar = get_scene("bar1d-traction")
    ok = _run(bar, "none", rel_l2_error=0.03)
    doc = {"runs": [{"status": "ok", "method": "none", "warnings": []}],
           "pdverify_version": "x", "created": "now", "machine": {"python": "3", "cpus": 1},
           "schema": "pdverify.results/1"}
    page = html.page(doc, [(bar, html.scene_section(bar, [ok], [], deviations=[]))], 1.0,
                     [ok], ())
    assert "failed-runs" not in page
    assert 'href="#top"' in page and 'id="top"' in page  # back-to-top links


def test_every_image_has_alt_text():
    bar = get_scene("bar1d-traction")
    ok = _run(bar, "none", rel_l2_error=0.03)
    figs = [("a.png", 'Displacement "u" <b>against</b> x'), ("b.png", "x" * 400)]
    doc = {"runs": [{"status": "ok", "method": "none", "warnings": []}],
           "pdverify_version": "x", "created": "now", "machine": {"python": "3", "cpus": 1},
           "schema": "pdverify.results/1"}
    page = html.page(doc, [(bar, html.scene_section(bar, [ok], figs, deviations=[]))], 1.0,
                     [ok], [("c.png", "front")])
    imgs = re.findall(r"<img [^>]*>", page)
    assert len(imgs) == 3
    for img in imgs:
        alt = re.search(r'alt="([^"]*)"', img)
        assert alt and alt.group(1).strip(), img
    assert "Displacement &#34;u&#34; against x" in page or \
        "Displacement &quot;u&quot; against x" in page


def test_pareto_one_panel_per_scene(tmp_path):
    from pdverify.report.figures import overview
    bar, plate = get_scene("bar1d-traction"), get_scene("plate2d-clamped")
    sheet = get_scene("sheet2d-tension")
    runs = [_run(bar, "none", rel_l2_error=0.03, t=0.3),
            _run(bar, "surface-nodes", rel_l2_error=1e-15, t=0.2),
            _run(bar, "pddo", rel_l2_error=0.05, t=0.05),
            _run(plate, "none", rel_l2_error=0.2), _run(plate, "energy", rel_l2_error=0.01),
            _run(sheet, "none", status="failed", message="x")]          # no error: no panel
    panels = overview.panels([bar, plate, sheet], runs)
    assert [p["scene"] for p in panels] == ["bar1d-traction", "plate2d-clamped"]
    front = panels[0]
    # the front: the fast pddo, then the exact surface nodes; the uncorrected run is beaten
    assert [front["points"][k][2] for k in front["front"]] == ["pddo", "surface-nodes"]
    lo, hi = front["ylim"]
    assert lo == pytest.approx(3.0 / 2) and hi == pytest.approx(5.0 * 2)  # clipped, in %
    out = overview.pareto([bar, plate, sheet], runs, str(tmp_path))
    assert len(out) == 1 and "2 scenes" in out[0][1]
    assert (tmp_path / out[0][0]).exists()


def test_shared_colour_scale_of_the_error_maps():
    from pdverify.report.figures import round_off, shared_log_norm
    a, b = np.array([[0.5, 2.0]]), np.array([[30.0, np.nan]])
    norm = shared_log_norm([a, b])
    assert (norm.vmin, norm.vmax) == (0.5, 30.0)          # one scale over both maps
    norm = shared_log_norm([np.array([1e-6, 10.0])], decades=4)
    assert (norm.vmin, norm.vmax) == (1e-3, 10.0)          # at most 4 decades deep
    assert shared_log_norm([np.zeros(3)]) is None
    assert round_off(np.array([500.0, 500.0 + 1e-10]))       # the tension sheet's energy
    assert not round_off(np.array([1.0, 1.5]))
    assert round_off(np.array([1e-12, 3e-9]), 100.0)         # an error map at round-off (%)


def test_plate_maps_share_one_scale_per_row(tmp_path):
    """The 2D plate's error maps: one figure, every method in it, one scale per component
    spanning the methods' errors (the largest error is the top of its row's scale)."""
    from pdverify.report.figures import surface_nodes
    scene = get_scene("plate2d-plane-strain")
    n = 6
    x = np.stack(np.meshgrid(np.arange(n) + 0.5, np.arange(n) + 0.5), -1).reshape(-1, 2)
    fields = lambda scale: {"x": x * 0.1, "origin": np.zeros(2), "spacing": 0.1,
                            "cells": (n, n), "lengths": (n * 0.1, n * 0.1),
                            "error": scale * np.column_stack([1 + x[:, 0], 1 + x[:, 1]])}
    runs = []
    for method, scale in (("none", 10.0), ("surface-nodes", 1.0), ("pddo", 1e-13)):
        r = _run(scene, method, rel_l2_error=0.1)
        r.fields = fields(scale)
        runs.append(r)
    out = surface_nodes._maps_2d(scene, runs, str(tmp_path))
    assert len(out) == 1
    u, v = surface_nodes._LAST_NORMS
    assert u.vmax == pytest.approx(10.0 * (1 + x[:, 0].max()))
    assert u.vmin == pytest.approx(1.0 * (1 + x[:, 0].min()))   # the other method's low end
    assert v.vmax == pytest.approx(10.0 * (1 + x[:, 1].max()))
