"""Figures of seed 000 §6.2: Fig. 28 (FEM u, v), Figs. 29-30 (Eq. 70 error maps), refinement."""
from __future__ import annotations

import matplotlib.pyplot as plt
import numpy as np

from ...scenes.plate2d import TABLE4 as PAPER
from . import family, fem_then_pd, legend_outside, node_image, palette, save
from .shapes import taylor_style

#: the params of Table 4's runs (the maps); the sweeps vary spacing, m_ratio, quadrature
TABLE4 = {**PAPER, "ring_value": "reference"}


def _matches(r, ignore=()):
    """Whether run ``r`` has Table 4's params, apart from those in ``ignore``."""
    return all(abs(r.params.get(k, v) - v) < 1e-12 if isinstance(v, float)
               else r.params.get(k, v) == v for k, v in TABLE4.items() if k not in ignore)


def _label(r):
    return "none" if r.method == "none" else f"n = {r.params['order']}"


def _fig28(scene, fem, folder):
    g = fem.fields["grid"]
    fig, axes = plt.subplots(1, 2, figsize=(12, 3.9), layout="constrained")
    for ax, key, title in zip(axes, ("ux", "uy"), ("(A) u [m]", "(B) v [m]")):
        pc = ax.pcolormesh(g["x"], g["y"], g[key], shading="auto", cmap="viridis")
        ax.set_aspect("equal")
        ax.set_title(title)
        ax.set_xlabel("x [m]")
        fig.colorbar(pc, ax=ax, shrink=0.85)
    axes[0].set_ylabel("y [m]")
    return (save(fig, folder, f"{scene.id}-fig28.png"),
            "Fig. 28 of seed 000: the converged FEM reference, u and v (Q2, finest edge 0.025 m; "
            "separate colour scales, as in the paper).")


def _error_maps(scene, runs, folder):
    pick = [r for r in runs if r.method == "none" and _matches(r)]
    pick = pick[:1] + sorted((r for r in runs if r.method == "taylor-fictitious"
                              and _matches(r) and r.params["order"] in (1, 2, 3)),
                             key=lambda r: r.params["order"])
    if len(pick) < 2:
        return []
    fig, axes = plt.subplots(2, len(pick), figsize=(3.6 * len(pick) + 1, 5.6),
                             layout="constrained", squeeze=False)
    for k, (comp, fig_no) in enumerate((("u", 29), ("v", 30))):
        vmax = max(r.fields["error"][:, k].max() for r in pick)
        for j, r in enumerate(pick):
            img, ext = node_image(r.fields["x"], r.fields["spacing"], r.fields["error"][:, k])
            ax = axes[k, j]
            im = ax.imshow(img, origin="lower", extent=ext, cmap="magma_r", vmin=0, vmax=vmax)
            ax.set_title(f"Fig. {fig_no}: e_{comp}, {_label(r)} (max "
                         f"{r.fields['error'][:, k].max():.2f} %)", fontsize=8.5)
            ax.set_aspect("equal")
            if j == 0:
                ax.set_ylabel("y [m]")
            if k == 1:
                ax.set_xlabel("x [m]")
        fig.colorbar(im, ax=axes[k, :], shrink=0.85, label=f"e_{comp} [%] (Eq. 70)")
    return [(save(fig, folder, f"{scene.id}-fig29-30.png"),
             "Figs. 29 and 30 of seed 000: Eq. (70) errors of u (top) and v (bottom) at the PD "
             "nodes, uncorrected and with Taylor fictitious nodes of order 1, 2, 3 (Table 4); "
             "one colour scale per component. The uncorrected ring of nodes is fixed at the "
             "FEM value (zero error there by construction).")]


def _sweep(ax, runs, x_of, xlabel, title):
    styles = {("none", None): (palette.colour("none"), palette.marker("none")),
              **{n: taylor_style(n) for n in (1, 2, 3)}}
    slopes = {}
    for quad, ls in (("partial-volume", "-"), ("moment-corrected", "--")):
        for key, (colour, marker) in styles.items():
            method = "none" if key == ("none", None) else "taylor-fictitious"
            rs = [r for r in runs if r.method == method
                  and r.params.get("quadrature") == quad
                  and (method == "none" or r.params.get("order") == key)]
            rs = sorted(rs, key=x_of)
            if len(rs) < 2:
                continue
            xs = np.array([x_of(r) for r in rs])
            e = np.array([r.metrics["rel_l2_error"] for r in rs])
            slope = np.polyfit(np.log(xs), np.log(e), 1)[0]
            name = "none" if method == "none" else f"n = {key}"
            q = "" if quad == "partial-volume" else ", moment-corr."
            ax.loglog(xs, e * 100, ls, color=colour, marker=marker, ms=4,
                      label=f"{name}{q} (slope {slope:.2f})")
            slopes[(method, key if method != "none" else None, quad)] = slope
    ax.set_xlabel(xlabel)
    ax.set_ylabel("rel. L2 error vs FEM [%]")
    ax.set_title(title, fontsize=10)
    ax.grid(True, which="both", alpha=0.3)
    if slopes:
        legend_outside(ax)
    return slopes


def _convergence(scene, runs, folder):
    delta = scene.m_sweep_horizon
    fixed_m = [r for r in runs if _matches(r, ignore=("spacing", "quadrature"))]
    fixed_d = [r for r in runs if _matches(r, ignore=("spacing", "m_ratio"))
               and abs(r.params["spacing"] * r.params["m_ratio"] - delta) < 1e-9]
    m = TABLE4["m_ratio"]
    fig, (a1, a2) = plt.subplots(1, 2, figsize=(12, 4.4), layout="constrained")
    s1 = _sweep(a1, fixed_m, lambda r: r.params["spacing"] * r.params["m_ratio"],
                f"horizon delta [m] (m = {m:g} fixed)", f"delta-refinement at fixed m = {m:g}")
    s2 = _sweep(a2, fixed_d, lambda r: r.params["m_ratio"],
                f"m = delta / Delta (delta = {delta:g} m fixed)", "m-refinement at fixed delta")
    if not (s1 or s2):
        plt.close(fig)
        return []
    # the rates the caption quotes: the fitted slopes of the corrected, moment-corrected
    # lines of the left panel (those in its legend), never a typed number
    mc = [v for (method, _, quad), v in s1.items()
          if method != "none" and quad == "moment-corrected"]
    rates = ("converge at the rates in the legend" if not mc else
             f"converge at rate {mc[0]:.2f}" if len(mc) == 1 else
             f"converge at rates {min(mc):.2f} to {max(mc):.2f}")
    return [(save(fig, folder, f"{scene.id}-convergence.png"),
             "Refinement toward the FEM reference, fitted log-log slopes in the legends. Left: "
             f"delta -> 0 at m = {m:g}; with exact partial volumes (solid) the corrected errors "
             f"stop at the fixed-m quadrature error, with moment-corrected weights (dashed) they "
             f"{rates}. Right: m -> infinity at delta = {delta:g} m; the corrected errors "
             "fall, the uncorrected ones grow (one ring of fixed nodes clamps an ever thinner "
             "layer).")]


@family("plate2d")
def plate_figures(scene, results, folder):
    out, fem, runs = fem_then_pd(scene, results, folder)
    if fem and "grid" in fem[0].fields:
        out.append(_fig28(scene, fem[0], folder))
    out += _error_maps(scene, runs, folder)
    out += _convergence(scene, runs, folder)
    return out
