"""Stiffness under homogeneous strain: W_i / W_bulk across the body, every method."""
from __future__ import annotations

import matplotlib.pyplot as plt
import numpy as np

from . import family, node_image, palette, save


def _mid_line(r):
    """Node indices on the line along x through the middle of the other axes, by x."""
    x, h = r.fields["x"], r.fields["spacing"]
    mid = r.fields["origin"] + r.fields["lengths"] / 2
    on = np.ones(len(x), dtype=bool)
    for k in range(1, x.shape[1]):
        d = np.abs(x[:, k] - mid[k])
        on &= d <= d.min() + 1e-9 * h
    idx = np.flatnonzero(on)
    return idx[np.argsort(x[idx, 0])]


@family("stiffness")
def stiffness(scene, runs, folder):
    out = []
    spacing = next(q.default for q in scene.params if q.name == "spacing")
    default = [r for r in runs if r.params.get("spacing") == spacing]
    runs = default or runs
    states = [k[len("ratio_"):] for k in runs[0].fields if k.startswith("ratio_")]
    shown = [s for s in ("uniaxial_x", "uniaxial_y", "shear_xy") if s in states]
    fig, axes = plt.subplots(1, len(shown), figsize=(4.6 * len(shown), 3.8),
                             layout="constrained", sharey=True)
    for ax, state in zip(np.atleast_1d(axes), shown):
        for r in runs:
            idx = _mid_line(r)
            st = palette.style(r.method)
            ax.plot(r.fields["x"][idx, 0], r.fields[f"ratio_{state}"][idx], "-",
                    marker=st.marker, ms=3, color=st.colour, label=r.method)
        ax.axhline(1.0, color="k", lw=0.6)
        ax.set_title(f"{state.replace('_', ' ')}", fontsize=9)
        ax.set_xlabel("x [m] (line through the middle)")
    np.atleast_1d(axes)[0].set_ylabel("W_i / W_bulk")
    # one legend for the panels, right of them (inside, it covered the profiles' ends)
    handles, labels = np.atleast_1d(axes)[-1].get_legend_handles_labels()
    fig.legend(handles, labels, loc="outside right upper", fontsize=7, frameon=False)
    out.append((save(fig, folder, f"{scene.id}-profiles.png"),
                "Nodal strain energy density over the bulk lattice's, along the line through "
                "the middle of the body in x, under a unit uniaxial stretch along x (normal "
                "to the faces the line crosses), along y, and a pure shear; 1 = no surface "
                "effect."))
    if runs[0].fields["x"].shape[1] == 2:
        fig, axes = plt.subplots(1, len(runs), figsize=(3.2 * len(runs), 3.6),
                                 layout="constrained", squeeze=False)
        for ax, r in zip(axes[0], runs):
            err = np.max(np.stack([np.abs(r.fields[f"ratio_{s}"] - 1) for s in states]), axis=0)
            img, ext = node_image(r.fields["x"], r.fields["spacing"], err * 100)
            im = ax.imshow(img, origin="lower", extent=ext, vmin=0, vmax=75, cmap="magma_r")
            ax.set_title(r.method, fontsize=9)
            ax.set_xticks([])
            ax.set_yticks([])
        fig.colorbar(im, ax=axes[0].tolist(), shrink=0.8, label="max |W_i / W_bulk - 1| [%]")
        out.append((save(fig, folder, f"{scene.id}-maps.png"),
                    "Largest |W_i / W_bulk - 1| over the strain states at every node, per "
                    "method (colour scale capped at 75 %)."))
    return out
