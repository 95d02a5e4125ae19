"""The front page's error-against-cost plots: every run of every scene, one plot per
spatial dimension, each scene's Pareto front (the runs no other run of that scene beats
in both error and time) joined by a line."""
from __future__ import annotations

import matplotlib.pyplot as plt
import numpy as np

from . import save
from ..summary import headline, headline_value

#: An exact run (error 0) is drawn at this error so that it stays on a log axis.
FLOOR = 1e-16
_MARKERS = "osD^v<>phX*P8"


def pareto_front(points):
    """Indices of the non-dominated (time, error) pairs, by increasing time."""
    order = sorted(range(len(points)), key=lambda k: (points[k][0], points[k][1]))
    front, best = [], np.inf
    for k in order:
        if points[k][1] < best:
            front.append(k)
            best = points[k][1]
    return front


def pareto(scenes, results, folder) -> list[tuple[str, str]]:
    """One error-against-total-time plot per dimension of ``scenes``."""
    by_dim = {}
    for scene in scenes:
        pts = []
        for r in results:
            if r.scene != scene.id:
                continue
            v = headline_value(scene, r)
            if v is not None:
                pts.append((max(r.timings.get("total_s", 0.0), 1e-4), max(v, FLOOR), r.method))
        if pts:
            by_dim.setdefault(scene.dim or 0, []).append((scene, pts))
    methods = sorted({p[2] for groups in by_dim.values() for _, pts in groups for p in pts},
                     key=lambda m: (m != "none", m))
    # tab20's dark shades first, then its light ones: neighbours in the list differ
    colours = {m: plt.get_cmap("tab20")((2 * k) % 20 + (2 * k) // 20 % 2)
               for k, m in enumerate(methods)}
    out = []
    for dim in sorted(by_dim):
        groups = by_dim[dim]
        fig, ax = plt.subplots(figsize=(11, 5.2))
        for j, (scene, pts) in enumerate(groups):
            marker = _MARKERS[j % len(_MARKERS)]
            for t, e, m in pts:
                ax.scatter(t, e, marker=marker, color=colours[m], s=28, alpha=0.85,
                           edgecolor="k", linewidth=0.3)
            front = pareto_front([(t, e) for t, e, _ in pts])
            ax.plot([pts[k][0] for k in front], [pts[k][1] for k in front], "-",
                    color="0.55", lw=0.8, zorder=0)
            ax.scatter([], [], marker=marker, color="0.6", edgecolor="k", linewidth=0.3,
                       label=f"{scene.id} ({headline(scene)})")
        used = {m for _, pts in groups for _, _, m in pts}
        for m in methods:
            if m in used:
                ax.scatter([], [], marker="s", color=colours[m], label=m)
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel("total time of the run [s]")
        ax.set_ylabel("headline error (fraction; % metrics / 100)")
        ax.set_title(f"{dim}D scenes: error against cost, every run" if dim else
                     "scenes without a dimension: error against cost")
        ax.grid(True, which="major", alpha=0.3)
        ax.legend(fontsize=7, ncol=2, loc="upper left", bbox_to_anchor=(1.01, 1.0),
                  frameon=False)
        name = save(fig, folder, f"overview-pareto-{dim}d.png")
        out.append((name, f"{dim}D scenes: the headline error of every run (colour: method; "
                          "marker: scene) against its total time (setup + solve). The grey "
                          "line joins each scene's Pareto front, the runs that no other run of "
                          f"the scene beats in both error and time. Exact runs (error 0) sit "
                          f"at {FLOOR:g}."))
    return out
