"""Figures of the crack scenes (issue 54): the whole body's error maps (as the shape
scenes'), the error near the fitted tip (a window of a few horizons, the tip zone
outlined), the crack-opening profile of every method against the FEM's, and K against
the spacing per method (the refinement at fixed m)."""
from __future__ import annotations

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.patches import Circle

from . import family, fem_then_pd, legend_outside, node_image, palette, save
from .shapes import _default, _error_maps

#: half-width of the window of the tip maps, in horizons (the tip zone is 2 horizons:
#: ``pdverify.scenes.cracks.TIP_ZONE``)
TIP_WINDOW = 5.0


def _at_default(scene, runs):
    """The runs at the default grid, or at the one nearest it (a quick report runs a
    coarser one), ``none`` first."""
    level = [r for r in runs if _default(scene, r, ignore=("spacing",)) and r.status == "ok"
             and r.fields.get("tip") is not None]
    if not level:
        return [], None
    h0 = next(q.default for q in scene.pd_params if q.name == "spacing")
    h = min((r.params.get("spacing", h0) for r in level), key=lambda v: abs(v - h0))
    pick = sorted((r for r in level if r.params.get("spacing", h0) == h),
                  key=lambda r: (r.method != "none", r.method))
    return pick, h


def _tip_maps(scene, runs, folder):
    pick, h = _at_default(scene, runs)
    if not pick:
        return []
    delta = pick[0].fields["horizon"]
    tip = np.asarray(pick[0].fields["tip"])
    half = TIP_WINDOW * delta
    near = []
    for r in pick:
        x, e = r.fields["x"], r.fields["error"].max(axis=1)
        inside = np.all(np.abs(x - tip) <= half + 0.5 * h, axis=1)
        near.append((x[inside], e[inside]))
    vmax = max(e.max() for _, e in near)
    cols = min(4, len(pick))
    rows = -(-len(pick) // cols)
    fig, axes = plt.subplots(rows, cols, figsize=(3.3 * cols + 1, 3.1 * rows),
                             layout="constrained", squeeze=False)
    for ax, r, (x, e) in zip(axes.flat, pick, near):
        img, ext = node_image(x, h, e)
        im = ax.imshow(img, origin="lower", extent=ext, cmap="magma_r", vmin=0, vmax=vmax)
        zone = r.fields["tip_zone"]
        ax.add_patch(Circle(tip, zone, fill=False, ec="#1f77b4", lw=1.2, ls="--"))
        ax.plot([ext[0], tip[0]], [tip[1], tip[1]], color="#1f77b4", lw=1.6)
        ax.set_xlim(ext[0], ext[1])
        ax.set_ylim(ext[2], ext[3])
        ax.set_title(f"{r.method} (max {e.max():.2f} %)", fontsize=8.5)
        ax.set_aspect("equal")
        ax.locator_params(axis="x", nbins=4)
        ax.tick_params(labelsize=7)
    for ax in axes.flat[len(pick):]:
        ax.set_axis_off()
    fig.colorbar(im, ax=axes, shrink=0.85, label="largest component error [% of max |u_FEM|]")
    return [(save(fig, folder, f"{scene.id}-tip-errors.png"),
             f"Error near the fitted tip at h = {h:g} m (m = 3): a window of "
             f"+-{TIP_WINDOW:g} horizons about the tip (the crack the solid line), every "
             "method on one colour scale, the largest component error at each node in % of "
             "max |u_FEM| over the whole body. Dashed: the tip zone of 2 horizons, where a "
             "PD tip and LEFM cannot agree, left out of the field metrics and of the K fit.")]


def _openings(scene, runs, folder):
    pick, h = _at_default(scene, runs)
    if not pick:
        return []
    fig, (a1, a2) = plt.subplots(1, 2, figsize=(11, 4.0), layout="constrained")
    ref = pick[0]
    zone = ref.fields["tip_zone"]
    a1.plot(ref.fields["opening_r"], 1e3 * ref.fields["opening_ref"], color="k", lw=1.8,
            ls="--", label="FEM")
    for r in pick:
        st = palette.style(r.method)
        rr, op, opf = r.fields["opening_r"], r.fields["opening"], r.fields["opening_ref"]
        a1.plot(rr, 1e3 * op, color=st.colour, marker=st.marker, ms=3, lw=1, label=r.method)
        a2.plot(rr, 100 * (op - opf) / np.abs(opf).max(), color=st.colour, marker=st.marker,
                ms=3, lw=1, label=r.method)
    for ax in (a1, a2):
        ax.axvspan(0, zone, color="#1f77b4", alpha=0.12, lw=0)
        ax.set_xlabel("distance r behind the tip [m]")
        ax.grid(True, alpha=0.3)
    a2.axhline(0, color="k", lw=0.8)
    a1.set_ylabel("opening of the nearest rows [mm]")
    a2.set_ylabel("opening - FEM's [% of the largest FEM opening]")
    legend_outside(a2)
    return [(save(fig, folder, f"{scene.id}-opening.png"),
             f"Crack opening behind the fitted tip at h = {h:g} m: u_y of the node row at "
             "h/2 above the crack minus that of its mirror below, every method and the FEM "
             "at the same nodes (left), and the difference in % of the largest FEM opening "
             "(right). Shaded: the tip zone of 2 horizons (opening_error_pct is the largest "
             "difference outside it).")]


def _k_refinement(scene, runs, folder):
    rs = [r for r in runs if _default(scene, r, ignore=("spacing",)) and r.status == "ok"
          and "k_ratio" in r.metrics]
    methods = sorted({r.method for r in rs}, key=lambda m: (m != "none", m))
    series = {}
    for m in methods:
        pts = sorted((r.params.get("spacing"), r.metrics) for r in rs if r.method == m)
        if len({h for h, _ in pts}) >= 3:
            series[m] = pts
    if not series:
        return []
    fig, (a1, a2) = plt.subplots(1, 2, figsize=(11, 4.2), layout="constrained")
    bias = None
    for m, pts in series.items():
        st = palette.style(m)
        hs = np.array([h for h, _ in pts])
        ratio = np.array([q["k_ratio"] for _, q in pts])
        net = np.array([q["k_net_error_pct"] for _, q in pts])
        bias = [(h, 1 + q["k_fit_bias_pct"] / 100) for h, q in pts]
        a1.plot(hs, ratio, color=st.colour, marker=st.marker, ms=4, label=m)
        a2.plot(hs, net, color=st.colour, marker=st.marker, ms=4,
                label=f"{m} ({observed_rates(hs, net)})")
    if bias:
        a1.plot(*zip(*bias), color="k", ls="--", lw=1, label="the fit on the FEM field")
    a1.axhline(1.0, color="k", lw=0.8)
    a2.axhline(0.0, color="k", lw=0.8)
    a1.set_ylabel("K_PD / K_FEM")
    a2.set_ylabel("K_PD / K_fit(FEM) - 1 [%]")
    for ax in (a1, a2):
        ax.set_xscale("log")
        ax.set_xlabel("spacing h [m] (m = 3)")
        ax.grid(True, which="both", alpha=0.3)
        legend_outside(ax)
    return [(save(fig, folder, f"{scene.id}-k-refinement.png"),
             "K_I against the spacing at fixed m = 3 (delta = 3h), per method. Left: "
             "K_PD / K_FEM (K_FEM from J), with the same opening fit applied to the FEM "
             "field at the same nodes (dashed: the fit's own bias on this grid). Right: "
             "the PD model's own error of K net of that bias, K_PD / K_fit(FEM) - 1, "
             "with the observed rates log(e_1 / e_2) / log(h_1 / h_2) between successive "
             "levels in the legend; a sign change or a growing error is pre-asymptotic "
             "(no rate).")]


def observed_rates(h, e) -> str:
    """The observed rates between successive levels of errors ``e`` at spacings ``h``
    (coarse to fine, either order given), or "pre-asymptotic" where the error changes
    sign or grows as h falls."""
    order = np.argsort(h)[::-1]
    h, e = np.asarray(h, float)[order], np.asarray(e, float)[order]
    out = []
    for k in range(len(h) - 1):
        a, b = e[k], e[k + 1]
        if a * b <= 0 or abs(b) >= abs(a):
            return "pre-asymptotic"
        out.append(f"{np.log(a / b) / np.log(h[k] / h[k + 1]):.2f}")
    return "rates " + ", ".join(out)


@family("crack2d")
def crack_figures(scene, results, folder):
    out, _fem, runs = fem_then_pd(scene, results, folder)
    # the tip first (the page shows the first PD figure, folds the others)
    out += _tip_maps(scene, runs, folder)
    out += _k_refinement(scene, runs, folder)
    out += _openings(scene, runs, folder)
    out += _error_maps(scene, [r for r in runs if r.fields.get("x") is not None], folder)
    return out
