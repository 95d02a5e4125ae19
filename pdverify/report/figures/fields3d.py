"""Off-screen pyvista renderings of the 3D boxes' displacement and error fields.

Each image shows one run as two panels side by side: the displacement magnitude |u| and
the nodal error of Eq. (38) of seed 001, both as cell data of the box's grid (every node
is a cell centre) with one octant cut away so the interior shows. Only reshaping and the
magnitude here: the values are the run's own fields. pyvista is imported only when
something is rendered (the figure package imports every module of its own).
"""
from __future__ import annotations

import contextlib
import os

import numpy as np

from ...errors import InputError
from . import label

#: pixels of one image (two panels); a render takes about 0.3 s here (EGL, no GPU)
WINDOW = (1400, 600)
MM = 1e3  # displacements are in m, shown in mm


def _grid_values(f, values):
    """Nodal values of a box's cell-centred nodes on its cell grid (NaN where none)."""
    idx = np.rint((f["x"] - f["origin"]) / f["spacing"] - 0.5).astype(int)
    out = np.full(tuple(int(n) for n in f["cells"]), np.nan)
    out[tuple(idx.T)] = values
    return out


def _cell_values(f, values):
    """Nodal values as cell data of the box's ImageData (x fastest, VTK's order)."""
    return _grid_values(f, values).ravel(order="F")


def default_runs(scene, results):
    """Per method, the first run at the method's default parameters (besides the spacing,
    which ``--quick`` changes); the method's first run when none has them."""
    out = {}
    for r in results:
        if r.method in out:
            continue
        try:
            want = scene.resolve(r.method, {"spacing": r.params["spacing"]})
        except InputError:  # a method the scene no longer offers
            want = None
        if want is not None and all(r.params.get(k) == v for k, v in want.items()):
            out[r.method] = r
    for r in results:
        out.setdefault(r.method, r)
    return [r for r in results if out.get(r.method) is r]


def _octant(f):
    """Cell ids kept (all but the octant of the cells at or beyond the grid's middle
    cell on every axis) and the cut position on each axis."""
    n = np.asarray(f["cells"], dtype=int)
    i, j, k = np.meshgrid(*(np.arange(m) for m in n), indexing="ij")
    cut = (i >= n[0] // 2) & (j >= n[1] // 2) & (k >= n[2] // 2)
    keep = np.flatnonzero(~cut.ravel(order="F"))
    # rounded for the labels (no -2.8e-17 for a cut at y = 0); + 0.0 turns -0.0 into 0.0
    return keep, np.round(np.asarray(f["origin"]) + (n // 2) * f["spacing"], 12) + 0.0


def _lift(camera, d):
    """Move the view down by ``d`` (the body up in the image, clear of the colour bar)."""
    up = np.asarray(camera.up, dtype=float)
    shift = -d * up / np.linalg.norm(up)
    camera.focal_point = tuple(np.asarray(camera.focal_point) + shift)
    camera.position = tuple(np.asarray(camera.position) + shift)


def _caption(r, cut):
    return (f"{label(r)}: 3D rendering of the run's nodal fields on the grid cells (each "
            f"node is a cell centre, h = {r.fields['spacing']:g} m), the octant x > "
            f"{cut[0]:.3g} m, y > {cut[1]:.3g} m, z > {cut[2]:.3g} m cut away so the "
            "interior mid-planes show; the box's outline in black. Left: displacement "
            "magnitude |u| [mm]; right: the nodal error of Eq. (38) of seed 001 [%]. "
            "Isometric view; each panel's colour scale is shared by the scene's renderings "
            "(the largest value over its methods).")


#: the two panels: cell-data name, scalar bar title (VTK renders a title with $...$ by
#: matplotlib's mathtext; without it the default font draws "[" like "(" and "|" breaks
#: the text), the nodal values (the metre displacements in mm)
PANELS = (("u_mm", r"displacement $\Vert u\Vert$ [mm]",
           lambda f: MM * np.linalg.norm(f["u"], axis=1)),
          ("error_pct", r"error $\varepsilon$ [%], Eq. (38)", lambda f: f["error"]))


def _grid(pv, f):
    """The box's grid with the panels' nodal values as cell data."""
    grid = pv.ImageData(dimensions=tuple(int(n) + 1 for n in f["cells"]),
                        spacing=(float(f["spacing"]),) * 3,
                        origin=tuple(float(v) for v in f["origin"]))
    for name, _, values in PANELS:
        grid.cell_data[name] = _cell_values(f, values(f))
    return grid


def render_box_fields(scene, results, folder) -> list[tuple[str, str]]:
    """One png of the runs of :func:`default_runs` of ``results`` (3D box runs with
    fields), octant cut away: the displacement magnitude |u| of the first, then the
    Eq. (38) error of each on one colour scale shared by all (:func:`shared_tops`), three
    panels a row; returns one (file, caption) pair."""
    import pyvista as pv

    pv.OFF_SCREEN = True
    runs = default_runs(scene, results)
    if not runs:
        return []
    tops = shared_tops(runs)
    keep, cut = _octant(runs[0].fields)
    panels = [(runs[0], 0, f"displacement magnitude [mm]: {label(runs[0])}")] + [
        (r, 1, f"error [%]: {label(r)} (max {float(np.nanmax(r.fields['error'])):.3g})")
        for r in runs]
    file = f"{scene.id}-3d.png"
    with _quiet(pv):
        _render_grid(pv, panels, tops, os.path.join(folder, file))
    f = runs[0].fields
    return [(file, f"{scene.id}: 3D rendering of the runs' nodal fields on the grid cells "
                   f"(each node is a cell centre, h = {f['spacing']:g} m), the octant x > "
                   f"{cut[0]:.3g} m, y > {cut[1]:.3g} m, z > {cut[2]:.3g} m cut away so the "
                   "interior mid-planes show; the box's outline in black. First panel: "
                   f"displacement magnitude |u| [mm] of {label(runs[0])}; then the nodal "
                   "error of Eq. (38) of seed 001 [%] of each method at its defaults, all "
                   "on one colour scale (0 to the largest error over the methods), so the "
                   "methods compare by eye. Isometric view.")]


#: panels a row of :func:`render_box_fields`, and pixels of one panel
RENDER_COLUMNS, PANEL_PX = 3, (460, 380)


def _render_grid(pv, panels, tops, path):
    rows = -(-len(panels) // RENDER_COLUMNS)
    pl = pv.Plotter(shape=(rows, RENDER_COLUMNS), off_screen=True, border=False,
                    window_size=(PANEL_PX[0] * RENDER_COLUMNS, PANEL_PX[1] * rows))
    try:
        bars = set()
        for k, (r, which, head) in enumerate(panels):
            pl.subplot(k // RENDER_COLUMNS, k % RENDER_COLUMNS)
            f = r.fields
            grid = _grid(pv, f)
            keep, _ = _octant(f)
            name, title, _ = PANELS[which]
            pl.add_mesh(grid.extract_cells(keep), scalars=name, cmap="viridis",
                        show_edges=True, edge_color="#444444", line_width=0.5,
                        ambient=0.65, diffuse=0.35, specular=0.0,
                        clim=(0.0, tops[which]), show_scalar_bar=which not in bars,
                        scalar_bar_args={"title": title, "fmt": "%.3g", "vertical": False,
                                         "title_font_size": 14, "label_font_size": 12,
                                         "n_labels": 4, "position_x": 0.15,
                                         "position_y": 0.03, "width": 0.7, "height": 0.12})
            bars.add(which)
            pl.add_mesh(grid.outline(), color="black", line_width=1.5)
            pl.add_text(head, position=(0.01, 0.92), viewport=True, font_size=8)
            pl.view_isometric()
            pl.camera.zoom(0.85)
            _lift(pl.camera, 0.09 * float(np.linalg.norm(f["lengths"])))
        pl.screenshot(path)
    finally:
        pl.close()


def _quiet(pv):
    """VTK's log at errors only: a headless VTK first tries an X display and logs a
    warning ("bad X server connection") before it falls back to EGL or OSMesa."""
    verbosity = getattr(pv, "vtk_verbosity", None)  # pyvista >= 0.45
    return verbosity("error") if verbosity is not None else contextlib.nullcontext()


def shared_tops(runs) -> list[float]:
    """The top of each panel's colour scale, shared by ``runs`` (one scene's renderings
    compare by eye): the largest value of the panel over every run (1 where none is
    positive)."""
    tops = []
    for _, _, values in PANELS:
        top = max((float(np.nanmax(values(r.fields))) for r in runs), default=0.0)
        tops.append(top if top > 0 else 1.0)
    return tops


def _render(pv, grid, part, heads, lengths, path, tops=None):
    """The two panels of :data:`PANELS`: ``part`` of ``grid`` coloured on the scale of
    the whole grid, the grid's outline, one colour bar each, isometric view."""
    # a fresh plotter per image: one already shown renders again on every added actor
    pl = pv.Plotter(shape=(1, 2), off_screen=True, window_size=WINDOW, border=False)
    try:
        for col, (name, title, _) in enumerate(PANELS):
            pl.subplot(0, col)
            top = (float(np.nanmax(grid.cell_data[name])) if tops is None else tops[col])
            pl.add_mesh(part, scalars=name, cmap="viridis", show_edges=True,
                        edge_color="#444444", line_width=0.5,
                        ambient=0.65, diffuse=0.35, specular=0.0,  # faces darken little
                        clim=(0.0, top if top > 0 else 1.0),
                        scalar_bar_args={"title": title, "fmt": "%.3g", "vertical": False,
                                         "title_font_size": 16, "label_font_size": 14,
                                         "n_labels": 5, "position_x": 0.2,
                                         "position_y": 0.03, "width": 0.6, "height": 0.1})
            pl.add_mesh(grid.outline(), color="black", line_width=1.5)
            # at a fixed size: a corner annotation ("upper_left") shrinks long text
            pl.add_text(heads[col], position=(0.01, 0.93), viewport=True, font_size=10)
            pl.add_axes(line_width=2)
            pl.view_isometric()
            pl.camera.zoom(0.9)
            _lift(pl.camera, 0.09 * float(np.linalg.norm(lengths)))
        pl.screenshot(path)
    finally:
        pl.close()


def _deformed(pv, f, u):
    """The box's node lattice (the cell centres) moved by ``u``, as a structured grid
    with |u| [m] as point data."""
    coords = [_grid_values(f, f["x"][:, k] + u[:, k]) for k in range(3)]
    grid = pv.StructuredGrid(*coords)
    grid.point_data["u_m"] = _grid_values(f, np.linalg.norm(u, axis=1)).ravel(order="F")
    return grid


def render_deformed(scene, results, folder) -> list[tuple[str, str]]:
    """Seed 001 Fig. 11's view: the deformed body at true scale, coloured by |u| [m],
    for the exact field and the default run with the smallest error (of the runs that
    record ``max_displacement``, the largest |u| of the exact field; the undeformed box
    in black); the caption names the paper's colour-bar top beside ours."""
    import pyvista as pv

    pv.OFF_SCREEN = True
    runs = [r for r in default_runs(scene, results)
            if "max_displacement" in r.metrics and "u_ref" in r.fields]
    if not runs:
        return []
    best = min(runs, key=lambda r: r.metrics.get("max_error_pct", np.inf))
    f = best.fields
    panels = [("exact field", f["u_ref"]),
              (f"{label(best)} (max error {best.metrics['max_error_pct']:.3g} %)", f["u"])]
    top = max(float(np.linalg.norm(u, axis=1).max()) for _, u in panels)
    file = f"{scene.id}-deformed.png"
    pl = pv.Plotter(shape=(1, 2), off_screen=True, window_size=WINDOW, border=False)
    try:
        with _quiet(pv):
            for col, (head, u) in enumerate(panels):
                pl.subplot(0, col)
                pl.add_mesh(_deformed(pv, f, u).extract_surface(), scalars="u_m",
                            cmap="viridis", clim=(0.0, top), show_edges=True,
                            edge_color="#444444", line_width=0.5,
                            ambient=0.65, diffuse=0.35, specular=0.0,
                            scalar_bar_args={"title": r"displacement $\Vert u\Vert$ [m]",
                                             "fmt": "%.3g", "vertical": False,
                                             "title_font_size": 16, "label_font_size": 14,
                                             "n_labels": 5, "position_x": 0.2,
                                             "position_y": 0.03, "width": 0.6,
                                             "height": 0.1})
                lo = np.asarray(f["origin"], dtype=float)
                hi = lo + np.asarray(f["lengths"], dtype=float)
                pl.add_mesh(pv.Box(bounds=(lo[0], hi[0], lo[1], hi[1], lo[2], hi[2])).outline(),
                            color="black", line_width=1.5)
                pl.add_text(head, position=(0.01, 0.93), viewport=True, font_size=10)
                pl.add_axes(line_width=2)
                pl.view_isometric()
                pl.camera.zoom(0.9)
                _lift(pl.camera, 0.09 * float(np.linalg.norm(f["lengths"])))
            pl.screenshot(os.path.join(folder, file))
    finally:
        pl.close()
    paper = next((e for r in results for e in r.published
                  if e.get("metric") == "max_displacement"), None)
    beside = ("" if paper is None else
              f" The paper's colour bar tops at {paper['value']} m ({paper['source']}); the "
              f"exact field here peaks at {best.metrics['max_displacement']:.3g} m"
              + (f" (deviation {paper['deviation']})" if paper.get("deviation") else "")
              + ".")
    return [(file, f"{scene.id}: the deformed body at true scale (seed 001 Fig. 11's view): "
                   "the node lattice (cell centres) moved by the exact displacement and by "
                   f"{label(best)}, the default run with the smallest error, coloured by "
                   "|u| [m] on one scale; the undeformed box in black; isometric view."
                   + beside)]
