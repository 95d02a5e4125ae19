"""Figures of seed 003 §4.1: Fig. 2 error maps, Fig. 3 energy density maps (the sheets'
convergence is drawn with every other study, :mod:`.convergence`)."""
from __future__ import annotations

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.colors import LogNorm

from . import family, fem_then_pd, node_image, save

PAPER = {"micromodulus": "constant", "quadrature": "full-cells"}


def _is_default(r, **extra):
    p = r.params
    want = {**PAPER, **extra}
    return all(p.get(k, v) == v for k, v in want.items()) and \
        p.get("load_sharing", "tributary") == "tributary" and \
        p.get("node_volumes", "partial") == "partial"


def _grid(r, values):
    """Values at the run's nodes as an image (rows: y), extent in mm."""
    return node_image(r.fields["x"], r.fields["spacing"], values, unit=1e3)


def _tension(scene, runs, folder):
    out = []
    pick = {r.method: r for r in runs if _is_default(r) and r.params["spacing"] == 0.001}
    if {"none", "energy-directional"} <= pick.keys():
        fig, axes = plt.subplots(1, 4, figsize=(15, 5.2), layout="constrained")
        cmap = plt.get_cmap("viridis").with_extremes(bad="black")
        panels = [("none", 1, "(a)"), ("energy-directional", 1, "(b)"), ("none", 0, "(c)"),
                  ("energy-directional", 0, "(d)")]
        for ax, (method, k, tag) in zip(axes, panels):
            err = pick[method].fields["error"][:, k]
            img, ext = _grid(pick[method], err)
            pos = img[np.isfinite(img) & (img > 0)]
            im = ax.imshow(img, origin="lower", extent=ext, cmap=cmap,
                           norm=LogNorm(vmin=max(pos.min(), 1e-3), vmax=pos.max()))
            comp = "u_y" if k else "u_x"
            ax.set_title(f"{tag} {method}: |Delta {comp} / {comp}| [%]", fontsize=9)
            ax.set_xlabel("x [mm]")
            fig.colorbar(im, ax=ax, shrink=0.7)
        axes[0].set_ylabel("y [mm]")
        out.append((save(fig, folder, f"{scene.id}-fig2.png"),
                    "Fig. 2 of seed 003: relative nodal errors against the closed form with the "
                    "lattice's bulk moduli, uncorrected and corrected, u_y (a, b) and u_x (c, d); "
                    "black: symmetry lines, where both displacements vanish (undefined). Log scale."))
    return out


def _clamped(scene, runs, folder):
    pick = {}
    for r in runs:
        if _is_default(r) and not r.params.get("correct_sides", False):
            pick.setdefault(r.method, r)
    order = [("energy-directional", "(b) corrected PD"),
             ("virtual-nodes", "(c) virtual nodes, sides uncorrected"), ("none", "(d) uncorrected PD")]
    if not all(m in pick for m, _ in order):
        return []
    ref = pick["energy-directional"]
    values = [(r"(a) FEM reference", ref, ref.fields["energy_ref"])] + \
        [(title, pick[m], pick[m].fields["energy"]) for m, title in order]
    data = np.concatenate([v for *_, v in values])
    # the FEM corner values are singular (clamped meets free): cap the scale there
    lo, hi = np.percentile(data[data > 0], [1, 99.5])
    fig, axes = plt.subplots(1, 4, figsize=(16, 4.4), layout="constrained")
    for ax, (title, r, v) in zip(axes, values):
        img, ext = _grid(r, v)
        im = ax.imshow(img, origin="lower", extent=ext, cmap="inferno", norm=LogNorm(lo, hi))
        ax.set_title(title, fontsize=9)
        ax.set_xlabel("x [mm]")
    axes[0].set_ylabel("y [mm]")
    fig.colorbar(im, ax=axes, shrink=0.8, label="strain energy density [J/m^3]")
    return [(save(fig, folder, f"{scene.id}-fig3.png"),
             "Fig. 3 of seed 003: strain energy density at the sample nodes, one logarithmic "
             "colour scale for all four (capped at the 99.5th percentile: the FEM is singular at "
             "the clamped corners); FEM evaluated at the PD nodes of the corrected run.")]


@family("sheets")
def sheet_figures(scene, results, folder):
    out, _, pd_runs = fem_then_pd(scene, results, folder)
    if scene.id == "sheet2d-tension":
        out += _tension(scene, pd_runs, folder)
    else:
        out += _clamped(scene, pd_runs, folder)
    return out
