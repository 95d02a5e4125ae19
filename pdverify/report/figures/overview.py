"""The front page's error-against-cost plots: one small panel per scene (small multiples),
every run of the scene at its headline error (per cent) against its setup + solve time,
the scene's Pareto front (the runs no other run of that scene beats in both error and
time) drawn as a line with the methods on it named."""
from __future__ import annotations

import math

import matplotlib.pyplot as plt
import numpy as np

from . import palette, save
from ..html import cost_s, headline_pct, is_exact
from ..summary import headline

#: panels per row of the small multiples
COLUMNS = 4
#: a run faster than this is drawn at it, so that it stays on the log time axis (the
#: timer's resolution is far finer; 0.1 ms is below every run's setup)
MIN_TIME_S = 1e-4


def pareto_front(points):
    """Indices of the non-dominated (time, error) pairs, by increasing time."""
    order = sorted(range(len(points)), key=lambda k: (points[k][0], points[k][1]))
    front, best = [], np.inf
    for k in order:
        if points[k][1] < best:
            front.append(k)
            best = points[k][1]
    return front


def panels(scenes, results) -> list[dict]:
    """One panel per scene with at least one headline error: its points ``(time_s,
    |error| in %, method, exact)``, the y range (clipped to the non-exact errors, a
    factor 2 of margin; exact runs sit on its floor) and the front's indices."""
    out = []
    for scene in scenes:
        pts, external = [], []
        for r in results:
            if r.scene != scene.id:
                continue
            v = headline_pct(scene, r)
            if v is None:
                continue
            if r.method.startswith("external:"):  # no cost measured: a level, not a point
                external.append((abs(v), r.method, is_exact(v)))
            else:
                pts.append((max(cost_s(r), MIN_TIME_S), abs(v), r.method, is_exact(v)))
        if not pts:
            continue
        real = [e for _, e, _, x in pts if not x] + [e for e, _, x in external if not x]
        if real:
            lo, hi = min(real) / 2, max(real) * 2
        else:   # every run exact: a band just above the round-off bound
            lo, hi = 1e-12, 1e-6
        floor = lo if real else lo * 2
        ranked = [(t, floor if x else e) for t, e, _, x in pts]
        out.append({"scene": scene.id, "metric": headline(scene), "points": pts,
                    "ylim": (lo, hi), "floor": floor, "front": pareto_front(ranked),
                    "external": external})
    return out


def pareto(scenes, results, folder) -> list[tuple[str, str]]:
    """The small multiples of :func:`panels`, :data:`COLUMNS` per row, as one figure."""
    data = panels(scenes, results)
    if not data:
        return []
    methods = sorted({p[2] for d in data for p in d["points"]}, key=lambda m: (m != "none", m))
    # the report's one colour and marker per method (:mod:`.palette`)
    colours = {m: palette.colour(m) for m in methods}
    markers = {m: palette.marker(m) for m in methods}
    rows = math.ceil(len(data) / COLUMNS)
    fig, axes = plt.subplots(rows, COLUMNS, figsize=(3.3 * COLUMNS, 2.6 * rows),
                             squeeze=False, gridspec_kw={"wspace": 0.38, "hspace": 0.5})
    for ax, d in zip(axes.flat, data):
        lo, hi = d["ylim"]
        for t, e, m, exact in d["points"]:
            ax.scatter(t, d["floor"] if exact else e, marker="v" if exact else markers[m],
                       color=colours[m], s=22, alpha=0.85, edgecolor="k", linewidth=0.3,
                       clip_on=False, zorder=3)
        front = d["front"]
        pts = d["points"]
        ys = [d["floor"] if pts[k][3] else pts[k][1] for k in front]
        ax.plot([pts[k][0] for k in front], ys, "-", color="k", lw=1.0, zorder=2)
        for e, m, exact in d.get("external", ()):
            # an external code's run has no cost pdverify measured: its error is drawn as
            # a level across the panel, named at the right, never on the front
            y = d["floor"] if exact else e
            ax.axhline(y, color="tab:red", lw=0.9, ls="--", zorder=2)
            ax.annotate(m, (1.0, y), xycoords=("axes fraction", "data"), xytext=(-2, 2),
                        textcoords="offset points", ha="right", fontsize=6.5,
                        color="tab:red", zorder=4)
        named = []
        for k, y in zip(front, ys):
            m = pts[k][2]
            if m in named:
                continue
            # alternate above / below the front, so neighbours' names do not overprint
            ax.annotate(m, (pts[k][0], y), xytext=(4, 3 if len(named) % 2 == 0 else -9),
                        textcoords="offset points", fontsize=6.5, color="k", zorder=4)
            named.append(m)
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_ylim(lo, hi)
        ax.set_title(d["scene"], fontsize=8.5)
        ax.set_ylabel(f"{d['metric']} [%]", fontsize=7)
        ax.tick_params(labelsize=6.5)
        ax.xaxis.set_minor_formatter(plt.NullFormatter())
        ax.yaxis.set_minor_formatter(plt.NullFormatter())
        ax.grid(True, which="major", alpha=0.3)
    for ax in list(axes.flat)[len(data):]:
        ax.set_axis_off()
    for ax in axes[-1]:
        if ax.has_data():
            ax.set_xlabel("setup + solve time [s]", fontsize=7)
    handles = [plt.Line2D([], [], ls="none", marker=markers[m], color=colours[m],
                          markeredgecolor="k", markeredgewidth=0.3, label=m) for m in methods]
    handles.append(plt.Line2D([], [], ls="none", marker="v", color="0.6",
                              label="exact (round-off), on the floor"))
    handles.append(plt.Line2D([], [], color="k", lw=1.0, label="Pareto front"))
    if any(d.get("external") for d in data):
        handles.append(plt.Line2D([], [], color="tab:red", lw=0.9, ls="--",
                                  label="external code (error; cost not measured)"))
    # above the panels (below them it ran into the bottom row's axis labels)
    fig.legend(handles=handles, loc="lower center", bbox_to_anchor=(0.5, 0.9 + 0.02 / rows),
               ncol=min(len(handles), 7), fontsize=7, frameon=False)
    name = save(fig, folder, "overview-pareto.png")
    return [(name, f"Error against cost, one panel per scene ({len(data)} scenes): the "
                   "headline error in per cent of every run of the scene (colour and marker: "
                   "method; the metric on each y axis) against its setup + solve time (the "
                   "metrics computed afterwards not counted). The black line is the scene's "
                   "Pareto front, the runs no other run of the scene beats in both error and "
                   "time, the methods on it named. Each y range is clipped to the scene's "
                   "errors that are not round-off; exact runs (|error| at most 1e-8 %) are "
                   "drawn as triangles on the panel's floor. A run of another code scored by "
                   "pdverify (external:NAME) has no cost pdverify measured: its error is a "
                   "dashed red level across its panel, named at the right, off the front.")]
