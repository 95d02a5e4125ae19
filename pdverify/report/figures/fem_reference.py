"""Figures of the FEM references: fields, refinement convergence, force-depth (issue #5)."""
from __future__ import annotations

import matplotlib.pyplot as plt
import numpy as np

from . import ENERGY_PERCENTILES, energy_norm, family, number_panel, round_off, save


@family("fem-reference")
def fem_figures(scene, results, folder):
    out = []
    for k, r in enumerate(results):
        f = r.fields
        g = f["grid"]
        mag = np.hypot(g["ux"], g["uy"])
        rows = f["refinement"]
        dofs = np.array([row["dofs"] for row in rows], dtype=float)
        change = np.array([row["change_pct"] for row in rows], dtype=float)
        ok = np.isfinite(change) & (change > 0)
        fig, axes = plt.subplots(1, 3 if ok.sum() >= 2 else 2,
                                 figsize=(16 if ok.sum() >= 2 else 11, 4.2),
                                 layout="constrained")
        for ax, (title, data) in zip(axes[:2], (("|u| [m]", mag),
                                                 ("strain energy density [J/m^3]",
                                                  g["strain_energy_density"]))):
            if round_off(data):   # a uniform field: its value, not a map of round-off
                number_panel(ax, f"uniform: {np.nanmean(data):.6g}\n(range "
                                 f"{np.nanmax(data) - np.nanmin(data):.2g}, round-off)", title)
                continue
            if title.startswith("strain energy"):
                title += ", log"
            # the energy density on a log scale (:func:`energy_norm`): it is singular at
            # re-entrant corners, where a linear scale leaves the rest one colour
            norm = energy_norm([data]) if title.startswith("strain energy") else None
            pc = ax.pcolormesh(g["x"], g["y"], data, shading="auto", cmap="viridis", norm=norm)
            ax.set_aspect("equal")
            ax.set_title(title)
            fig.colorbar(pc, ax=ax, shrink=0.8)
        if ok.sum() >= 2:    # one point is no study: the table above gives its value
            axes[2].loglog(dofs[ok], change[ok], "o-")
            axes[2].set_xlabel("dofs")
            axes[2].set_ylabel(f"change of {f['quantity_name']} [%]")
            axes[2].set_title("refinement study")
            axes[2].grid(True, which="both", alpha=0.3)
        name = save(fig, folder, f"{scene.id}-{k}.png")
        lo, hi = ENERGY_PERCENTILES
        out.append((name, "Converged FEM field (displacement magnitude, strain energy density on a "
                          f"log scale from the {lo:g}th to the {hi:g}th percentile of its values, "
                          "so that a singular corner does not take the whole scale) "
                          "and the change of the compared quantity per refinement level (drawn from two "
                          "changes on; a uniform field shows its value: its range is "
                          "round-off)."))
        if "forces" in f:
            fig, (a1, a2) = plt.subplots(1, 2, figsize=(10, 4))
            a1.plot(np.r_[0, f["depths"]] * 1e3, np.r_[0, f["forces"]] / 1e3, "o-", ms=3)
            a1.set_xlabel("depth [mm]")
            a1.set_ylabel("force [kN per m thickness]")
            a1.set_title("force-depth")
            a2.plot(f["depths"] * 1e3, f["contact_widths"] * 1e3, "o-", ms=3)
            a2.set_xlabel("depth [mm]")
            a2.set_ylabel("contact width [mm]")
            a2.set_title("contact width")
            for a in (a1, a2):
                a.grid(alpha=0.3)
            out.append((save(fig, folder, f"{scene.id}-{k}-force.png"),
                        "Force-depth curve and contact width per step (sticking contact)."))
    return out
