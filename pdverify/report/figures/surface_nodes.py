"""Figures of seed 001: error maps (Figs. 9, 12, 14, 15) and error against cost."""
from __future__ import annotations

import textwrap
import warnings

import matplotlib.pyplot as plt
import numpy as np

from ...results import cost_s
from . import (ROUND_OFF, distinct_labels, family, label, method_colours, number_panel,
               palette, round_off, save as _save, shared_log_norm)
from .fields3d import _grid_values


def _label(r) -> str:
    """Method and order, plus the parameters the seed-001 cases vary."""
    extra = [f"{k}={v}" for k, v in r.params.items()
             if (k == "quadrature" and v != "partial-volume") or (k == "m_ratio" and v != 3.0)
             or k == "load_point" or (k == "neumann" and v != "full-traction")
             or (k == "mirror_point" and v != "nearest")
             or (k == "gradient_at" and v != "mirror")
             or (k == "bulk_model" and v != "lps")
             or (k == "influence" and v != "gaussian")]
    return label(r) + "".join(", " + e for e in extra)


def _paper_settings(r) -> bool:
    """A run at seed 001's quadrature, influence function and m-ratio."""
    return (r.params.get("quadrature") == "partial-volume"
            and r.params.get("influence") == "gaussian" and r.params.get("m_ratio") == 3.0)


def _columns_2d(scene, results):
    """The runs of the 2D plate's shared-scale figure, with their titles: the panels of
    seed 001 §5 (:data:`SECTION5`, at the paper's settings) in the paper's order, then
    every other method's run at its default parameters."""
    cols, seen = [], set()
    for method, want, title in SECTION5:
        hit = [r for r in results if r.method == method and _paper_settings(r)
               and all(r.params.get(k) == v for k, v in want.items())]
        if hit and id(hit[0]) not in seen:
            cols.append((title, hit[0]))
            seen.add(id(hit[0]))
    for r in _defaults(scene, results):
        if id(r) not in seen and not any(r.method == c.method for _, c in cols):
            cols.append((_label(r), r))
            seen.add(id(r))
    return cols


def _defaults(scene, results):
    from .fields3d import default_runs
    return default_runs(scene, results)


#: characters per line of a 2D map's title (its panel is 2.2 in wide, the title 7.5 pt)
TITLE_CHARS = 30


def _maps_2d(scene, results, folder):
    """One small-multiples figure: a column per method (:func:`_columns_2d`), the Eq. (44)
    error in u (top row) and v (bottom row), one logarithmic colour scale per row shared
    by all methods (:func:`~pdverify.report.figures.shared_log_norm`); a map at round-off
    level (:func:`~pdverify.report.figures.round_off`) is replaced by its largest value."""
    cols = _columns_2d(scene, results)
    if not cols:
        return []
    # the panels' titles take up to `lines` lines (7.5 pt: 0.125 in each); the figure grows
    # by them and its top margin holds them under the suptitle
    lines = max(len(textwrap.wrap(title, TITLE_CHARS)) for title, _ in cols) + 1
    height = 4.8 + 2 * 0.125 * (lines - 2)
    fig, axes = plt.subplots(2, len(cols), figsize=(2.2 * len(cols) + 1.2, height),
                             squeeze=False, sharex=True, sharey=True,
                             gridspec_kw={"wspace": 0.08, "hspace": 0.45 + 0.1 * (lines - 2)})
    fig.subplots_adjust(top=1 - (0.125 * lines + 0.3) / height)
    norms = []
    for k, comp in enumerate(("u (Fig. 14)", "v (Fig. 15)")):
        maps = [_grid_values(r.fields, r.fields["error"][:, k]).T for _, r in cols]
        live = [z for z in maps if not round_off(z, 100.0)]
        norm = shared_log_norm(live)
        norms.append(norm)
        im = None
        for col, ((title, r), z) in enumerate(zip(cols, maps)):
            ax = axes[k, col]
            # a long run name wrapped to the panel's width (2.2 in at 7.5 pt: about 30
            # characters), so that neighbouring titles do not run into each other
            head = "\n".join(textwrap.wrap(title, TITLE_CHARS)
                              + [f"{comp}: max {np.nanmax(z):.3g} %"])
            if norm is None or round_off(z, 100.0):
                number_panel(ax, f"round-off:\nmax {np.nanmax(z):.2g} %", head)
                continue
            L = r.fields["lengths"]
            im = ax.imshow(z, origin="lower", extent=(0, L[0], 0, L[1]), cmap="viridis",
                           norm=norm)
            ax.set_title(head, fontsize=7.5)
            ax.tick_params(labelsize=6)
        if im is not None:
            cb = fig.colorbar(im, ax=axes[k, :].tolist(), shrink=0.9, pad=0.01, fraction=0.03)
            cb.set_label(f"eps_{comp[0]} [%] (Eq. 44), log", fontsize=7)
            cb.ax.tick_params(labelsize=6)
    fig.suptitle(f"{scene.id}: Eq. (44) errors of every method "
                 f"(h = {cols[0][1].params['spacing']:g} m; one colour scale per row)",
                 fontsize=9, y=1 - 0.08 / height, va="top")
    name = _save(fig, folder, f"{scene.id}-maps.png")
    _LAST_NORMS[:] = norms
    return [(name, "Seed 001 §5, Figs. 14 (u, top) and 15 (v, bottom) for every method: "
                   "PALS, the mirror node method, the PDDO boundary layer and the surface "
                   "node method at the paper's settings in the paper's order, then our "
                   "second MNM reading, the uncorrected model and the other methods at their "
                   "defaults. All maps of a row share one logarithmic colour scale (down to "
                   "4 decades below the largest error), so the methods compare by eye; a map "
                   f"whose values span at most {ROUND_OFF:g} x 100 % is round-off and shows "
                   "its largest value instead. The paper's ordering: PALS reduces the y "
                   "error but keeps a large x error; MNM is close in x except one corner and "
                   "worst in y; SNM smallest among the ordinary state-based methods; PDDO "
                   "similar to SNM.")]


#: the colour scales of the last shared-scale figure (for the tests)
_LAST_NORMS: list = []


def _maps_3d(scene, results, folder):
    """One small-multiples figure: a row per method (its run at default parameters), the
    error magnitude of Eq. (38) on four node layers, one logarithmic colour scale shared
    by every panel; a run at round-off level shows its largest value instead."""
    runs = _defaults(scene, results)
    if not runs:
        return []
    errs = [_grid_values(r.fields, r.fields["error"]) for r in runs]
    live = [e for e in errs if not round_off(e, 100.0)]
    norm = shared_log_norm(live)
    _LAST_NORMS[:] = [norm]
    # shared axes, labels on the outer panels only, no layout engine: a 4 x 8 grid of maps
    # with every tick labelled took ~4x the time of the runs it shows (record
    # quick_report-2026-11-24-error-map-ticks)
    fig, axes = plt.subplots(len(runs), 4, figsize=(12, 1.75 * len(runs) + 0.7),
                             gridspec_kw={"width_ratios": [2, 2, 2, 1], "wspace": 0.3,
                                          "hspace": 0.5}, squeeze=False, sharex="col",
                             sharey="col")
    height = 1.75 * len(runs) + 0.7
    # room above the first row for the suptitle, its run's name and the layer titles
    fig.subplots_adjust(top=1 - 0.75 / height)
    im = None
    for row, (r, err) in enumerate(zip(runs, errs)):
        f = r.fields
        nz = err.shape[2]
        L, o = f["lengths"], f["origin"]
        ext_xy = (o[0], o[0] + L[0], o[1], o[1] + L[1])
        ext_xz = (o[0], o[0] + L[0], o[2], o[2] + L[2])
        ext_yz = (o[1], o[1] + L[1], o[2], o[2] + L[2])
        panels = [("top layer", err[:, :, -1].T, ext_xy, ("x", "y")),
                  ("mid-plane z ~ 0", err[:, :, nz // 2].T, ext_xy, ("x", "y")),
                  ("side layer y = l_y/2 - h/2", err[:, -1, :].T, ext_xz, ("x", "z")),
                  ("end layer x = l_x - h/2", err[-1, :, :].T, ext_yz, ("y", "z"))]
        vmax = np.nanmax(err)
        if norm is None or round_off(err, 100.0):
            for ax in axes[row, 1:]:
                ax.set_axis_off()
            number_panel(axes[row, 0], f"{_label(r)}: round-off, max {vmax:.2g} %")
            continue
        for col, (ax, (title, z, ext, (a, b))) in enumerate(zip(axes[row], panels)):
            im = ax.imshow(z, origin="lower", extent=ext, cmap="viridis", norm=norm)
            if row == 0:   # the layers once, as column heads
                ax.set_title(title, fontsize=7)
            if col == 0:   # the run's name above its row, left, clear of the heads
                ax.annotate(f"{_label(r)} (max {vmax:.3g} %)", (0, 1), xycoords="axes fraction",
                            xytext=(0, 15 if row == 0 else 4), textcoords="offset points",
                            fontsize=8, fontweight="bold", va="bottom")
            ax.tick_params(labelsize=6)
            if row == len(runs) - 1:
                ax.set_xlabel(f"{a} [m]", fontsize=6.5)
            ax.set_ylabel(f"{b} [m]", fontsize=6.5, labelpad=1)
    if im is not None:
        cb = fig.colorbar(im, ax=axes.ravel().tolist(), shrink=0.6, pad=0.02)
        cb.set_label("|eps| [%] (Eq. 38), log", fontsize=7)
    fig.suptitle(f"{scene.id}: nodal error of every method at its defaults, one colour scale",
                 fontsize=9, y=1 - 0.12 / height, va="top")
    name = _save(fig, folder, f"{scene.id}-maps.png")
    return [(name, "Magnitude of the nodal error of Eq. (38) on four node layers (as Figs. 9 "
                   "and 12 of seed 001), one row per method at its default parameters, all "
                   "panels on one logarithmic colour scale (down to 4 decades below the "
                   f"largest error); a run whose errors span at most {ROUND_OFF:g} x 100 % "
                   "is round-off and shows its largest value instead.")]


def _cost(scene, results, folder):
    """Error against cost, one point per run in its method's colour and marker
    (:mod:`.palette`; a method's several runs in its shades); errors at round-off are
    drawn on a floor below the others, marked, not at 1e-15."""
    from ...convergence import EXACT
    fig, ax = plt.subplots(figsize=(6.5, 4))
    errs = [r.metrics["max_error_pct"] for r in results]
    real = [e for e in errs if e > EXACT * 100]
    floor = min(real) / 5 if real else EXACT * 100
    for r, name, e, colour in zip(results, distinct_labels(results, _label), errs,
                                  method_colours(results)):
        t = max(cost_s(r.timings), 1e-4)
        exact = e <= EXACT * 100
        ax.loglog(t, floor if exact else e, "v" if exact else palette.marker(r.method),
                  ms=7 if exact else 6, color=colour, mfc="none" if exact else colour,
                  mew=1.4, ls="none", label=name + (" (exact to round-off)" if exact else ""))
    if len(real) < len(errs):
        ax.axhline(floor, color="0.6", lw=0.8, ls=":")
    ax.set_xlabel("setup + solve time [s] (cached setup at the time it took)")
    ax.set_ylabel("max_error_pct")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=6, loc="upper left", bbox_to_anchor=(1.01, 1.0), frameon=False)
    ax.set_title(f"{scene.id}: error against cost")
    return [(_save(fig, folder, f"{scene.id}-cost.png"),
             "Largest nodal error against the run's setup + solve time (the metrics computed "
             "afterwards not counted), one point per run, colour and marker per method as in "
             "every figure of the report (a method's several runs in its shades); hollow "
             f"triangles on the dotted floor: runs exact to round-off (error <= {EXACT * 100:g} "
             "%), drawn there instead of at round-off level.")]


def where_max(fields, k, reach) -> str:
    """Where component k's largest error sits: ``corner x+, y-`` within ``reach`` of two
    faces, ``edge x+`` within reach of one, else ``inside``; ``round-off`` for errors
    at round-off level (:func:`~pdverify.report.figures.round_off`)."""
    if round_off(fields["error"][:, k], 100.0):
        return "round-off"
    x, L = fields["x"], np.asarray(fields["lengths"])
    o = np.asarray(fields.get("origin", np.zeros_like(L)))
    p = x[np.argmax(fields["error"][:, k])] - o
    near = [f"{'xyz'[a]}{'-' if p[a] <= L[a] / 2 else '+'}"
            for a in range(p.size) if min(p[a], L[a] - p[a]) <= reach]
    if not near:
        return "inside"
    return ("edge " if len(near) == 1 else "corner ") + ", ".join(near)


def mnm_pattern(run, pals, others) -> bool:
    """Seed 001 §5.4's MNM pattern in a run's metrics: 'close in x' (u error below
    PALS's, which §5.4 calls significant in x) and 'worst in y' (v error above every run
    of ``others``: the other methods of Figs. 14-15 and the uncorrected model)."""
    m = run.metrics if hasattr(run, "metrics") else run
    close_x = m["max_error_u_pct"] < pals["max_error_u_pct"]
    worst_y = m["max_error_v_pct"] > max(o["max_error_v_pct"] for o in others)
    return bool(close_x and worst_y)


#: the readings of seed 001 §5's MNM and PDDO (report cases of the plate), as
#: (method, params that differ from the defaults, what the reading is)
SECTION5_READINGS = (
    ("mirror-nodes", {}, "MNM: full traction, nearest mirror node (default)"),
    ("mirror-nodes", {"neumann": "normal-only"}, "MNM: normal derivatives only"),
    ("mirror-nodes", {"mirror_point": "corrected"}, "MNM: mirror mismatch corrected"),
    ("mirror-nodes", {"mirror_point": "at-mirror-point"},
     "MNM: Neumann step from the mirror point"),
    ("mirror-nodes", {"gradient_at": "boundary"}, "MNM: gradient at the boundary point"),
    ("pddo", {}, "PDDO: LPS bulk (default)"),
    ("pddo", {"bulk_model": "pddo"}, "PDDO: PDDO bulk (non-ordinary stand-in)"),
)


def _reading_run(results, method, want, spacing):
    """The run of ``method`` at the paper's settings and ``spacing`` whose reading params
    are ``want`` (the others at their defaults)."""
    defaults = {"neumann": "full-traction", "mirror_point": "nearest",
                "gradient_at": "mirror", "bulk_model": "lps", "order": 1}
    for r in results:
        if r.method == method and _paper_settings(r) and r.params["spacing"] == spacing and all(
                r.params.get(k, defaults[k]) == want.get(k, defaults[k])
                for k in defaults if k in r.params or k in want):
            return r
    return None


def section5_readings(results):
    """Rows of the §5 study: (name, run, where u max, where v max, matches the paper's MNM
    pattern) for every reading run, then PALS, SNM and none as the yardstick, all at the
    spacing of the first run at the paper's settings (the scene's cases come first; the
    spacing sweeps after them)."""
    first = next((r for r in results if _paper_settings(r)), None)
    if first is None:
        return []
    h = first.params["spacing"]
    pals = _reading_run(results, "pals", {}, h)
    others = [r for r in (pals, _reading_run(results, "surface-nodes", {"order": 1}, h),
                          _reading_run(results, "none", {}, h)) if r is not None]
    rows = []
    for method, want, name in SECTION5_READINGS + (
            ("pals", {}, "PALS"), ("surface-nodes", {"order": 1}, "SNM (order 1)"),
            ("none", {}, "none (uncorrected)")):
        r = _reading_run(results, method, want, h)
        if r is None:
            continue
        reach = r.params["m_ratio"] * r.params["spacing"]
        match = (pals is not None and method in ("mirror-nodes", "pddo")
                 and mnm_pattern(r, pals.metrics, [o.metrics for o in others]))
        rows.append((name, r, where_max(r.fields, 0, reach), where_max(r.fields, 1, reach),
                     match))
    return rows


def _readings_table(scene, results, folder):
    """Seed 001 §5's readings of MNM and PDDO as a table figure: the largest Eq. (44)
    errors, where they sit, and whether the reading shows the paper's MNM pattern."""
    rows = section5_readings(results)
    if not any(r.method in ("mirror-nodes", "pddo") for _, r, *_ in rows):
        return []
    cells = [[name, f"{r.metrics['max_error_u_pct']:.3g}", wu,
              f"{r.metrics['max_error_v_pct']:.3g}", wv,
              ("yes" if match else "no") if r.method in ("mirror-nodes", "pddo") else "-"]
             for name, r, wu, wv, match in rows]
    fig, ax = plt.subplots(figsize=(10.5, 0.22 * len(cells) + 0.6))
    ax.set_axis_off()
    tab = ax.table(cellText=cells, colLabels=["reading", "max eps_u [%]", "where",
                                              "max eps_v [%]", "where",
                                              "paper's MNM pattern"],
                   loc="center", cellLoc="left", colLoc="left")
    tab.auto_set_font_size(False)
    tab.set_fontsize(7.5)
    tab.auto_set_column_width(list(range(6)))
    matched = [name for name, r, *_, match in rows if match]
    h = rows[0][1].params["spacing"]
    ax.set_title(f"{scene.id}: seed 001 §5 readings of MNM and PDDO (h = {h:g} m, m = 3); "
                 f"matching the paper: {', '.join(matched) if matched else 'none'}",
                 fontsize=9)
    name = _save(fig, folder, f"{scene.id}-s5-readings.png")
    verdict = (f"The reading that matches the paper: {', '.join(matched)}." if matched else
               "No reading matches the paper. The plate's exact field (Eq. 43) is affine and "
               "every real node has a complete neighbourhood, where an affine field carries "
               "no force whatever the lattice: a reading whose boundary relations are exact "
               "for affine fields gives round-off (full traction with the nearest or "
               "corrected mirror node or the gradient at the boundary point; PDDO with "
               "either bulk). A reading that is not either moves the whole plate to another "
               "homogeneous state (normal-only: the free face x = l_x imposes the relation "
               "that ties u to v, so both err, u more) or errs at the corners, where the "
               "mirror node is only the nearest one (the step from the mirror point: in "
               "both components, v below PALS). In a homogeneous state whose free-face "
               "relation is exact the relative errors of u and v are equal, so 'close in "
               "x except one corner, worst in y' can only come from errors local to the "
               "boundary, and the readings' local errors are small in both components.")
    return [(name, "Seed 001 §5.2-5.4, the readings of the mirror node method and the PDDO "
                   "layer that the text allows, run on the plate at the paper's settings: "
                   "the largest Eq. (44) error of each component, where it sits (within one "
                   "horizon of one face: edge; of two: corner), and whether the run shows "
                   "§5.4's MNM pattern, 'close in x' (u error below PALS's) and 'worst in y' "
                   "(v error above PALS's, SNM's and the uncorrected model's). Not run: the "
                   "2 delta layer with the fictitious nodes' dilatations from their own "
                   "neighbourhoods, which is exact for affine fields whenever its "
                   "displacement relations are (deviations: 001-s5-mnm-readings). "
                   + verdict)]


#: the panels of seed 001 Figs. 14 and 15 (§5), in the paper's order, then ours
SECTION5 = (("pals", {}, "(a) PALS"), ("mirror-nodes", {"neumann": "full-traction"}, "(b) MNM"),
            ("pddo", {}, "(c) PDDO"), ("surface-nodes", {"order": 1}, "(d) SNM"),
            ("mirror-nodes", {"neumann": "normal-only"}, "MNM, normal-only Neumann"),
            ("none", {}, "none (uncorrected)"))


def _renderings_3d(scene, results, folder):
    """pyvista renderings of |u| and the error (:mod:`.fields3d`); a renderer that fails
    (no OpenGL, ...) costs these images only, with a warning naming the cause. None in a
    ``--quick`` report (:data:`QUICK`): pyvista's import and the renders took seconds of
    its figures' time (record quick_report-2026-11-26-pyvista-quick); the maps show the
    same fields."""
    from . import QUICK
    if QUICK:
        return []
    try:
        from .fields3d import render_box_fields, render_deformed
        return render_box_fields(scene, results, folder) + render_deformed(scene, results,
                                                                           folder)
    except Exception as exc:  # noqa: BLE001  (any VTK/OpenGL failure: keep the report)
        warnings.warn(f"{scene.id}: no 3D renderings ({type(exc).__name__}: {exc})",
                      RuntimeWarning, stacklevel=2)
        return []


@family("seed001-boxes")
def surface_node_figures(scene, results, folder):
    dim = results[0].fields["x"].shape[1]
    maps = (_maps_3d(scene, results, folder) + _renderings_3d(scene, results, folder)
            if dim == 3 else _maps_2d(scene, results, folder)
            + _readings_table(scene, results, folder))
    return maps + _cost(scene, results, folder)
