"""Figures of the seed-004 bond-based bars: f(N) beside Table 12, Fig. 3 and Figs. 4-5."""
from __future__ import annotations

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.lines import Line2D

from . import family, palette, save as _save

def _case(r) -> str:
    return f"{r.params['horizon_ratio']:g}, {r.params['end_weight']}"


def _unique_sweeps(results):
    """One run per (method, horizon, end weight, shape, calibration): the sweep is the same."""
    seen, out = set(), []
    for r in sorted(results, key=lambda r: r.params["nodes"]):
        key = (r.method, r.params["horizon_ratio"], r.params["end_weight"],
               r.params["micromodulus"], r.params["calibration"])
        if key not in seen:
            seen.add(key)
            out.append(r)
    return out


@family("bondbar1d-homogenization")
def homogenization_figures(scene, results, folder):
    """f(N) of the non-homogenised bars against Table 12, and |f(N) - 1| homogenised."""
    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(13, 4.8), layout="constrained")
    sweeps = _unique_sweeps(results)
    for r in sweeps:  # the other stiffness corrections (energy, volume, plugins) on the left
        if r.method in ("none", "homogenized"):
            continue
        if "sweep_nodes" not in r.fields:     # a peer code's run: its one bar
            ax1.semilogx([r.params["nodes"]], [r.metrics["strain_factor"]], "D", ms=7,
                         mfc="none", mew=1.3, label=f"{r.method} (one bar), delta/Delta = "
                         f"{_case(r)}")
            continue
        ax1.semilogx(r.fields["sweep_nodes"], r.fields["sweep_f"], "^:", ms=3, lw=1,
                     label=f"{r.method}, delta/Delta = {_case(r)}")
    for r in sweeps:
        if r.method != "none":
            continue
        f = r.fields
        line, = ax1.semilogx(f["sweep_nodes"], f["sweep_f"], "o-", ms=2.5, lw=1,
                             label=f"delta/Delta = {_case(r)}")
        cell = scene.table12.get((r.params["horizon_ratio"], r.params["end_weight"]))
        if cell is None or r.params["micromodulus"] != "triangular":
            continue
        if cell.formula is not None:
            n = f["sweep_nodes"].astype(float)
            ax1.semilogx(n, cell.formula(n), "--", color=line.get_color(), lw=1.2)
        ax1.plot([cell.nodes], [cell.printed], "x" if cell.erratum else "s",
                 ms=10 if cell.erratum else 7, mfc="none", color=line.get_color(), mew=1.5)
        if cell.erratum:
            ax1.annotate(f"Table 12 prints {cell.text} here;\n{cell.erratum}",
                         (cell.nodes, cell.printed), textcoords="axes fraction",
                         xytext=(0.32, 0.42), fontsize=8, color=line.get_color(),
                         arrowprops={"arrowstyle": "->", "color": line.get_color(), "lw": 0.8})
    handles, _ = ax1.get_legend_handles_labels()
    handles += [Line2D([], [], color="k", ls="--", label="Table 12 closed / fitted f(N)"),
                Line2D([], [], color="k", marker="s", mfc="none", ls="none",
                       label="Table 12 printed f(2m+1)"),
                Line2D([], [], color="k", marker="x", ls="none", label="printed, erratum")]
    ax1.legend(handles=handles, fontsize=7, ncol=2)
    ax1.axhline(1.0, color="k", lw=0.8)
    ax1.set_xlabel("points N")
    ax1.set_ylabel("strain factor f(N)")
    ax1.set_title("non-homogenised (ours: solid; other corrections: dotted)")
    ax1.grid(True, which="both", alpha=0.3)
    floor = 1e-17
    homogenized = [r for r in sweeps if r.method == "homogenized"]
    colors = plt.cm.tab20(np.linspace(0.0, 1.0, max(len(homogenized), 2)))
    for r, color in zip(homogenized, colors):
        f = r.fields
        ax2.loglog(f["sweep_nodes"], np.maximum(np.abs(f["sweep_f"] - 1.0), floor), "o-", ms=2.5,
                   lw=0.9, color=color, label=f"delta/Delta = {_case(r)}")
    ax2.axhline(1e-12, color="r", lw=0.8, ls="--", label="1e-12 (issue's bound)")
    ax2.set_xlabel("points N")
    ax2.set_ylabel(f"|f(N) - 1| (exact zeros drawn at {floor:g})")
    ax2.set_title("homogenised")
    ax2.grid(True, which="both", alpha=0.3)
    ax2.legend(fontsize=6.5, ncol=2)
    name = _save(fig, folder, f"{scene.id}-strain-factor.png")
    caption = ("Left: strain factor f(N) of the non-homogenised bars (ours, solid) against Table "
               "12's closed or fitted forms (dashed) and its printed values at N = 2m + 1 "
               "(squares; the cross is the erratum 1.043, exactly 5/3); the energy and volume "
               "corrections dotted, at the scene's defaults. Right: |f(N) - 1| of the "
               "homogenised bars, at round-off for every N.")
    return [(name, caption)]


@family("bondbar1d-constraints")
def constraint_figures(scene, results, folder):
    """Fig. 3: the full bar (a), the half bar with its end point held (b) and with m held (c)."""
    fig, axes = plt.subplots(1, 4, figsize=(17, 4), layout="constrained")
    titles = {"a": "(a) full bar, midpoint held", "b": "(b) half bar, end point held",
              "c": "(c) half bar, m end points held"}
    markers = {r.method: palette.marker(r.method) for r in results}
    for r in results:
        f = r.fields
        for ax, k in zip(axes[:3], "abc"):
            if f"x_{k}" in f:   # the fictitious-node methods run (a) and (b) only
                ax.plot(f[f"x_{k}"], f[f"u_{k}"], markers.get(r.method, "d") + "-", ms=4,
                        lw=0.8, mfc="none", color=palette.colour(r.method), label=r.method)
        # bar (a)'s nodes that bar (b) shares: x >= 0 (its midpoint on), x > 0 (cell-centred)
        gap = np.abs(f["x_a"][:, None] - f["x_b"][None, :]).min(axis=1)
        shared = gap <= 1e-9 * np.max(np.abs(f["x_a"]))
        half = f["u_a"][shared]
        scale = np.max(np.abs(f["u_a"]))
        mk = markers.get(r.method, "d")
        axes[3].plot(f["x_b"], (f["u_b"] - half) / scale, mk + "-", ms=4, lw=0.8,
                     mfc="none", color=palette.colour(r.method), label=f"{r.method}: (b) - (a)")
        if "x_c" in f:
            m = f["x_c"].size - f["x_b"].size + 1
            axes[3].plot(f["x_b"], (f["u_c"][m - 1:] - half) / scale, mk + "--", ms=4,
                         lw=0.8, color=palette.colour(r.method), label=f"{r.method}: (c) - (a)")
    first = next((r for r in results if "x_c" in r.fields), results[0])
    s = first.fields["stress_over_E"]
    for ax, k in zip(axes[:3], "abc"):
        if f"x_{k}" not in first.fields:
            continue
        x = first.fields[f"x_{k}"]
        held_at_zero = x < 0 if k == "c" else np.zeros(x.size, dtype=bool)  # (c): x < 0 held
        ax.plot(x, s * np.where(held_at_zero, 0.0, x), "k:", lw=1.2, label="classical")
        ax.set_title(titles[k])
        ax.set_xlabel("x [m]")
        ax.grid(alpha=0.3)
    axes[0].set_ylabel("u [m]")
    axes[0].legend(fontsize=8)
    axes[3].axhline(0.0, color="k", lw=0.6)
    axes[3].set_title("difference from the full bar's half")
    axes[3].set_xlabel("x [m]")
    axes[3].set_ylabel("(u_half - u_full) / max |u_full|")
    axes[3].legend(fontsize=7)
    axes[3].grid(alpha=0.3)
    name = _save(fig, folder, f"{scene.id}.png")
    caption = ("Fig. 3 of seed 004: displacements of the full bar (a), the half bar with its end "
               "point held (b) and with m end points held (c), non-homogenised and homogenised, "
               "with the classical solution; right: the halves minus the full bar's half. "
               "Homogenised, (b) coincides with (a); (c) does not. Taylor's fictitious nodes "
               "and the surface nodes (bond-based form) run (a) and (b) with the conditions "
               "at the surface, on the cell centres between the end points; (c) is seed "
               "004's discrete variant of (b)'s u(0) = 0 and is not theirs.")
    return [(name, caption)]


#: Table 13's columns: the constraint, its panel letter in Figs. 4-5 and its words
CONSTRAINTS = (("end", "b", "end point held"), ("mid", "a", "midpoint held"),
               ("end-points", "c", "end points 1-4 held"))


@family("bondbar1d-vibration")
def vibration_figures(scene, results, folder):
    """Figs. 4-5 (a)-(c): the point next to the held region and the free end against Rao's
    series, one figure per constraint of Table 13."""
    out = []
    for constraint, letter, words in CONSTRAINTS:
        runs = [r for r in results if r.params.get("constraint", "end") == constraint]
        if not runs:
            continue
        ratios = sorted({r.params["horizon_ratio"] for r in runs})
        fig, axes = plt.subplots(2, len(ratios), figsize=(6.5 * len(ratios), 7), squeeze=False,
                                 layout="constrained")
        for col, ratio in enumerate(ratios):
            mine = [r for r in runs if r.params["horizon_ratio"] == ratio]
            first = mine[0]
            T = first.fields["period"]
            for row, (key, metric, fig_no) in enumerate((("next", "next_point", 4),
                                                         ("free", "free_point", 5))):
                ax = axes[row, col]
                point = first.metrics.get(metric)
                ax.plot(first.fields["t"] / T, first.fields[f"u_{key}_ref"], "k-", lw=1.4,
                        label="Rao, Eq. (105)")
                for r in mine:
                    ax.plot(r.fields["t"] / T, r.fields[f"u_{key}"], lw=0.9,
                            color=palette.colour(r.method), label=r.method)
                ax.set_title(f"Fig. {fig_no}{letter}: u_{point:g}, delta = {ratio:g} Delta"
                             if point is not None else f"Fig. {fig_no}{letter}, delta = "
                             f"{ratio:g} Delta")
                ax.set_xlabel("t / (4 L_f / c)")
                ax.set_ylabel("u [m]")
                ax.grid(alpha=0.3)
                ax.legend(fontsize=8, loc="lower left")
        suffix = "" if constraint == "end" else f"-{constraint}"
        name = _save(fig, folder, f"{scene.id}{suffix}.png")
        p = runs[0].params
        out.append((name, f"Figs. 4{letter}-5{letter} of seed 004 ({words}; Table 13: L = "
                          f"{p['length']:g} m, N = {p['nodes']}): displacement of the point "
                          "next to the held region (top) and of the free end (bottom) against "
                          "Rao's series, for each horizon. Time in periods 4 L_f/c of Rao's "
                          "first mode, L_f the free length (L/2 in a). The paper's curves were "
                          "lost in the text conversion; its words: the vibrating and static "
                          "bars' stiffness are similar (Figs. 3, 4a-c), and only the "
                          "non-homogenised bar's frequency deviates in Fig. 5b."))
    return out
