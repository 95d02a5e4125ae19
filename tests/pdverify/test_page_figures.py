"""The report page at a glance (issue 52): one colour and marker per method across the
figures, round-off-exact errors on a marked floor instead of at 1e-15, energy maps on a
logarithmic scale, and a page whose scenes are all there with their secondary parts
folded."""
from __future__ import annotations

import re

import pytest

import numpy as np
from matplotlib.colors import LogNorm, to_hex

from pdverify.convergence import EXACT
from pdverify.report import html
from pdverify.report.figures import convergence, fem_reference, overview, palette
from pdverify.results import RunResult
from pdverify.scenes import get_scene


def _run(scene, method, over=None, status="ok", t=0.5, fields=None, **metrics):
    return RunResult(scene=scene.id, method=method, params=scene.resolve(method, over or {}),
                     reference=scene.reference, status=status, message="",
                     metrics=metrics, fields=fields or {},
                     timings={"setup_s": t / 4, "solve_s": t / 2, "total_s": t})


def _keep(monkeypatch, module, attr="save"):
    """Keep the figures ``module`` saves (open, for inspection) instead of writing them."""
    kept = []

    def save(fig, folder, name):
        kept.append(fig)
        return name
    monkeypatch.setattr(module, attr, save)
    return kept


def _study(method, errors, hs=(0.4, 0.2, 0.1)):
    return {"scene": "s", "study": "delta", "method": method, "metric": "rel_l2_error",
            "fixed": "m = 3", "h": "delta", "rate": None, "note": "",
            "levels": [{"h": h, "error": e} for h, e in zip(hs, errors)]}


def test_one_colour_and_marker_per_method_across_two_figures(monkeypatch, tmp_path):
    """The front page's error-against-cost panels and a convergence study draw ``pddo``,
    ``volume`` and ``none`` in the same colour and marker each (before: tab20 by sorted
    name in the one, the default colour cycle by order in the other)."""
    bar = get_scene("bar1d-traction")
    runs = [_run(bar, "none", rel_l2_error=0.03, t=0.3),
            _run(bar, "pddo", rel_l2_error=0.01, t=0.2),
            _run(bar, "volume", rel_l2_error=0.02, t=0.1)]
    kept = _keep(monkeypatch, overview)
    overview.pareto([bar], runs, str(tmp_path))
    front = {}
    for coll in kept[0].axes[0].collections:
        # each point is one scatter: its face colour is its method's
        xy = coll.get_offsets()[0]
        method = next(r.method for r in runs
                      if np.isclose(xy[1], r.metrics["rel_l2_error"] * 100))
        front[method] = (to_hex(coll.get_facecolor()[0], keep_alpha=False),
                         coll.get_paths()[0])
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots()
    convergence.study_panel(ax, [_study("volume", [0.2, 0.1, 0.05]),
                                 _study("none", [0.3, 0.2, 0.15]),
                                 _study("pddo", [0.1, 0.03, 0.01])])
    study = {line.get_label().split(" (")[0]: (to_hex(line.get_color()), line.get_marker())
             for line in ax.get_lines() if not line.get_label().startswith(("_", "ref", "exact"))}
    plt.close(fig)
    for m in ("none", "pddo", "volume"):
        assert front[m][0] == study[m][0] == palette.colour(m), m
        assert study[m][1] == palette.marker(m)
    assert len({study[m][0] for m in study}) == 3          # three methods, three colours


def test_palette_built_ins_distinct_plugins_deterministic():
    from pdverify.corrections.registry import treatments
    names = [n for n, t in treatments().items() if getattr(t, "origin", "built-in") == "built-in"]
    styles = [palette.style(n) for n in names]
    assert len({s.colour for s in styles}) == len(names)      # no two built-ins alike
    # a plugin (any unknown name): from its name alone, the same in every process
    assert palette.style("my-plugin") == palette._hashed("my-plugin")
    assert palette.style("my-plugin").colour == "#" + "".join(
        f"{round(c * 255):02x}" for c in _hls_of("my-plugin"))
    # shades of one method stay apart
    shades = {palette.variant("taylor-fictitious", k, 3) for k in range(3)}
    assert len(shades) == 3


def _hls_of(name):
    import colorsys
    import zlib
    h = zlib.crc32(name.encode())
    return colorsys.hls_to_rgb((h % 360) / 360, 0.35 + 0.1 * ((h >> 9) % 3), 0.75)


def test_exact_levels_sit_on_a_floor_not_at_round_off():
    """A method exact to round-off (errors 1e-15) is drawn on the panel's floor, a factor
    FLOOR_FACTOR below the smallest real error, and the axis stops just below it (before:
    the axis ran down to 1e-16)."""
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots()
    entries = [_study("none", [0.3, 0.2, 0.15]), _study("mirror-nodes", [1e-15, 3e-15, 2e-16]),
               _study("pals", [0.1, 0.03, 0.01])]
    floor = convergence.study_panel(ax, entries)
    assert floor == 0.01 / convergence.FLOOR_FACTOR
    ys = np.concatenate([np.asarray(line.get_ydata(), float) for line in ax.get_lines()])
    assert ys.size and ys.min() >= floor * (1 - 1e-12)       # nothing below the floor
    assert ax.get_ylim()[0] >= floor / 2                      # the axis stops near it
    assert any("exact to round-off" in line.get_label() for line in ax.get_lines())
    plt.close(fig)
    # every level exact: the panel spans just above the EXACT bound, not 1e-15
    fig, ax = plt.subplots()
    assert convergence.study_panel(ax, [_study("pddo", [1e-15, 1e-14, 1e-16])]) is None
    assert ax.get_ylim()[0] >= EXACT
    plt.close(fig)


def test_energy_map_is_logarithmic(monkeypatch):
    """The FEM reference's energy density (singular at a re-entrant corner) is drawn on a
    logarithmic colour scale; the displacement stays linear."""
    plate = get_scene("plate-l")
    x, y = np.meshgrid(np.linspace(0, 1, 21), np.linspace(0, 1, 21))
    r = np.hypot(x - 0.5, y - 0.5) + 1e-3
    fields = {"grid": {"x": x, "y": y, "ux": x * 1e-3, "uy": y * 1e-3,
                       "strain_energy_density": 1e3 / r},   # ~1/r at the corner
              "refinement": [{"dofs": 100, "change_pct": 1.0}], "quantity_name": "u"}
    kept = _keep(monkeypatch, fem_reference)
    fem_reference.fem_figures(plate, [_run(plate, "fem", fields=fields)], "unused")
    meshes = [a.collections[0] for a in kept[0].axes if a.collections]
    assert not isinstance(meshes[0].norm, LogNorm)            # |u|
    norm = meshes[1].norm
    assert isinstance(norm, LogNorm) and norm.vmin > 0        # energy density
    # the values away from the singular corner span most of the colours (with a linear
    # scale, or a log one up to the corner's value, they sat in its bottom fifth)
    far = fields["grid"]["strain_energy_density"][r > 0.1]
    assert np.ptp(norm(far)) > 0.6


def _page(figures, runs, scene):
    section = html.scene_section(scene, runs, figures, deviations=[])
    doc = {"runs": [{"status": "ok", "method": r.method, "warnings": []} for r in runs],
           "pdverify_version": "x", "created": "now", "machine": {"python": "3", "cpus": 1},
           "schema": "pdverify.results/1"}
    return section, doc


def _outside_details(text):
    """``text`` with every <details>...</details> (and what it holds) removed."""
    while "<details" in text:
        new = re.sub(r"<details(?:(?!<details).)*?</details>", "", text, flags=re.S)
        if new == text:
            break
        text = new
    return text


def test_every_scene_is_on_the_page_with_its_secondary_parts_folded():
    """Each scene's section is there (its heading and runs table unfolded); its lead
    figure is shown, the others folded under their short titles; the FEM reference's
    figure never leads; the published values' table is folded with its counts in the
    summary."""
    bar = get_scene("bar1d-homogenization")
    plate = get_scene("plate-l")
    bar_runs = [_run(bar, "none", rel_l2_error=0.03, strain_factor=1.0)]
    plate_runs = [_run(plate, "none", max_error_pct=9.4)]
    figs = [("plate-l-0.png", "Converged FEM field: |u|"), ("plate-l-errors.png",
                                                           "Error maps at h = 0.025 m: maps"),
            ("plate-l-convergence.png", "Refinement toward the FEM reference: lines")]
    s1, doc = _page([("bar1d-homogenization-strain-factor.png", "Fig. 4 of seed 004: f")],
                    bar_runs, bar)
    s2, _ = _page(figs, plate_runs, plate)
    page = html.page(doc, [(bar, s1), (plate, s2)], 1.0, bar_runs + plate_runs, ())
    visible = _outside_details(page)
    for scene in (bar, plate):
        assert f'<h2 id="{scene.id}">' in visible
    assert "plate-l-errors.png" in visible                    # the lead figure, shown
    assert "plate-l-0.png" not in visible                     # the FEM's, folded
    assert "plate-l-convergence.png" not in visible
    assert "plate-l-0.png" in page and "plate-l-convergence.png" in page
    assert re.search(r"<summary>More figures \(2\): Refinement toward the FEM reference; "
                     r"Converged FEM field</summary>", page)
    # the paper's values beside the run (Table 13 of seed 004): folded, counted in the
    # summary
    assert html.published_rows(bar, bar_runs)
    assert 'class="pub"' in page and 'class="pub"' not in visible
    assert '<details class="fold"><summary>Published values beside ours: ' in page


def test_bar_errors_exact_to_round_off_sit_on_a_floor(monkeypatch):
    """The bars' nodal error panel: a run exact to round-off (1e-13 %) is drawn on a floor
    below the smallest real error, not at 1e-13 % (before: the axis ran down to 1e-13)."""
    from pdverify.report.figures import bar1d
    bar = get_scene("bar1d-uniform-load")
    x = np.linspace(0.025, 0.975, 20)

    def fields(err):
        return {"x": x, "u": x * 1e-4, "error_pct": err, "length": 1.0}
    runs = [_run(bar, "none", fields=fields(np.linspace(1.0, 10.0, 20))),
            _run(bar, "pddo", fields=fields(np.full(20, 3e-13))),
            _run(bar, "taylor-fictitious", {"order": 2}, fields=fields(np.full(20, 1e-13)))]
    kept = _keep(monkeypatch, bar1d, "_save")
    bar1d.bar_figures(bar, runs, "unused")
    ax2 = kept[0].axes[1]
    ys = np.concatenate([np.asarray(line.get_ydata(), float) for line in ax2.get_lines()])
    ys = ys[np.isfinite(ys)]
    floor = 1.0 / 5
    assert ys.min() >= floor * (1 - 1e-12)                    # nothing at round-off level
    assert ax2.get_ylim()[0] > 1e-2
    labels = [line.get_label() for line in kept[0].axes[0].get_lines()]
    assert sum("exact to round-off" in lab for lab in labels) == 2


def _full_records(scene_id):
    """The full report's records of ``scene_id`` (params, metrics, status): what the
    convergence figures draw (tests/data/full_report_records.json.gz)."""
    import gzip
    import json
    import os
    path = os.path.join(os.path.dirname(__file__), "..", "data",
                        "full_report_records.json.gz")
    scene = get_scene(scene_id)
    with gzip.open(path, "rt") as fh:
        return [RunResult(scene=scene_id, method=r["method"], params=r["params"],
                          reference=scene.reference, status=r["status"], message="",
                          metrics=r["metrics"], fields={}, timings={"total_s": 1.0})
                for r in json.load(fh)["runs"]
                if r["scene"] == scene_id and r["method"] != "fem"]


def _legends_off_the_data(fig):
    """(legend, axes) pairs where a legend of ``fig`` (an axes' or the figure's) overlaps
    an axes' data area, after drawing."""
    fig.canvas.draw()
    legends = [a.get_legend() for a in fig.axes if a.get_legend()] + list(fig.legends)
    assert legends, "no legend drawn"
    return [(i, j) for i, leg in enumerate(legends) for j, ax in enumerate(fig.axes)
            if leg.get_window_extent().overlaps(ax.get_window_extent())]


@pytest.mark.parametrize("scene_id", ["plate-hole", "plate-l",
                                      "plate2d-clamped", "plate2d-plane-strain"])
def test_convergence_legends_sit_outside_the_data(monkeypatch, scene_id):
    """The shape scenes' and the plates' refinement figures, and their convergence
    studies' figure, put each legend beside or below its panel, not over its lines
    (before: the refinement figures' legends sat inside, over the coarse levels)."""
    import matplotlib.pyplot as plt
    from pdverify.convergence import collect
    from pdverify.report.figures import plate2d, shapes
    records = _full_records(scene_id)
    figs = []
    if scene_id != "plate2d-plane-strain":      # its refinement is the studies' figure
        module = plate2d if scene_id.startswith("plate2d") else shapes
        kept = _keep(monkeypatch, module)
        assert module._convergence(get_scene(scene_id), records, "unused")
        figs += kept
    studies = collect(records)
    if scene_id.startswith("plate2d"):          # the shape scenes have none
        kept = _keep(monkeypatch, convergence)
        assert studies and convergence.draw(studies, "unused")
        figs += kept
    try:
        for fig in figs:
            assert _legends_off_the_data(fig) == [], fig.axes[0].get_title()
    finally:
        for fig in figs:
            plt.close(fig)
