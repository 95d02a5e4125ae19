"""Figures of the 3D shape scenes (issue 55): the FEM reference's slice and refinement,
and each treatment's errors by region at the default grid."""
from __future__ import annotations

import matplotlib.pyplot as plt
import numpy as np

from . import family, fem_then_pd, palette, save


@family("shape3d")
def shape3d_figures(scene, results, folder):
    out, _, runs = fem_then_pd(scene, results, folder)
    runs = [r for r in runs if r.status == "ok" and r.metrics]
    if not runs:
        return out
    keys = (["max_error_pct", "boundary_max_error_pct", "interior_max_error_pct"]
            + [f"{name}_max_error_pct" for name in scene.regions])
    fig, ax = plt.subplots(figsize=(9, 4), layout="constrained")
    width = 0.8 / len(runs)
    for k, r in enumerate(runs):
        vals = [r.metrics.get(key, np.nan) for key in keys]
        ax.bar(np.arange(len(keys)) + (k - (len(runs) - 1) / 2) * width, vals, width,
               label=r.method, color=palette.style(r.method).colour)
    ax.set_xticks(np.arange(len(keys)))
    ax.set_xticklabels([key.replace("_max_error_pct", "") .replace("max_error_pct", "all")
                        for key in keys])
    ax.set_ylabel("max error [% of max |u_FEM|]")
    ax.legend()
    ax.grid(True, axis="y", alpha=0.3)
    out.append((save(fig, folder, f"{scene.id}-errors.png"),
                "Largest displacement error of each treatment at the default grid, over every "
                "node, the boundary layer (within a horizon), the interior, and the nodes "
                "nearest each named curved or loaded part."))
    return out
