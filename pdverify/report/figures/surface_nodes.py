"""Figures of seed 001: error maps (Figs. 9, 12, 14, 15) and error against cost."""
from __future__ import annotations

import warnings

import matplotlib.pyplot as plt
import numpy as np

from . import family, label, save as _save
from .fields3d import _grid_values


def _label(r) -> str:
    """Method and order, plus the parameters the seed-001 cases vary."""
    extra = [f"{k}={v}" for k, v in r.params.items()
             if (k == "quadrature" and v != "partial-volume") or (k == "m_ratio" and v != 3.0)
             or k == "load_point" or (k == "neumann" and v != "full-traction")
             or (k == "mirror_point" and v != "nearest")
             or (k == "influence" and v != "gaussian")]
    return label(r) + "".join(", " + e for e in extra)


def _map_name(scene, r, i) -> str:
    return f"{scene.id}-{r.method}-{r.params.get('order', 0)}-{i}.png"




def _maps_2d(scene, results, folder):
    out = []
    for r in results:
        f = r.fields
        L = f["lengths"]
        fig, axes = plt.subplots(1, 2, figsize=(10, 4.2))
        for k, (ax, name) in enumerate(zip(axes, ("u", "v"))):
            z = _grid_values(f, f["error"][:, k]).T
            im = ax.imshow(z, origin="lower", extent=(0, L[0], 0, L[1]), cmap="viridis")
            fig.colorbar(im, ax=ax, label=f"eps_{name} [%] (Eq. 44)")
            ax.set_title(f"{_label(r)}: error in {name}", fontsize=9)
            ax.set_xlabel("x [m]")
            ax.set_ylabel("y [m]")
        name = _save(fig, folder, _map_name(scene, r, len(out)))
        out.append((name, f"{_label(r)}: nodal errors of Eq. (44) in u and v (as Figs. 14-15 "
                          "of seed 001); each map has its own colour scale."))
    return out


def _maps_3d(scene, results, folder):
    out = []
    for r in results:
        f = r.fields
        err = _grid_values(f, f["error"])
        nx, ny, nz = err.shape
        L, o = f["lengths"], f["origin"]
        ext_xy = (o[0], o[0] + L[0], o[1], o[1] + L[1])
        ext_xz = (o[0], o[0] + L[0], o[2], o[2] + L[2])
        ext_yz = (o[1], o[1] + L[1], o[2], o[2] + L[2])
        panels = [("top layer z = l_z/2 - h/2", err[:, :, -1].T, ext_xy, ("x", "y")),
                  ("mid-plane z ~ 0", err[:, :, nz // 2].T, ext_xy, ("x", "y")),
                  ("side layer y = l_y/2 - h/2", err[:, -1, :].T, ext_xz, ("x", "z")),
                  ("end layer x = l_x - h/2", err[-1, :, :].T, ext_yz, ("y", "z"))]
        vmax = np.nanmax(err)
        fig, axes = plt.subplots(1, 4, figsize=(17, 3.6),
                                 gridspec_kw={"width_ratios": [2, 2, 2, 1], "wspace": 0.35})
        for ax, (title, z, ext, (a, b)) in zip(axes, panels):
            im = ax.imshow(z, origin="lower", extent=ext, cmap="viridis", vmin=0, vmax=vmax)
            ax.set_title(title, fontsize=9)
            ax.set_xlabel(f"{a} [m]")
            ax.set_ylabel(f"{b} [m]")
        fig.colorbar(im, ax=axes, label="|eps| [%] (Eq. 38)", shrink=0.9)
        fig.suptitle(f"{scene.id}: {_label(r)} (max {vmax:.3g} %)")
        name = _save(fig, folder, _map_name(scene, r, len(out)))
        out.append((name, f"{_label(r)}: magnitude of the nodal error of Eq. (38) on four node "
                          "layers (as Figs. 9 and 12 of seed 001); one colour scale per run."))
    return out


def _cost(scene, results, folder):
    fig, ax = plt.subplots(figsize=(6.5, 4))
    for r in results:
        ax.loglog(r.timings["total_s"], r.metrics["max_error_pct"], "o", ms=8, label=_label(r))
    ax.set_xlabel("total time [s] (setup + solve)")
    ax.set_ylabel("max_error_pct")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=7)
    ax.set_title(f"{scene.id}: error against cost")
    return [(_save(fig, folder, f"{scene.id}-cost.png"),
             "Largest nodal error against the run's wall time, one point per method and order "
             "(the table above lists setup and solve time separately).")]


#: the panels of seed 001 Figs. 14 and 15 (§5), in the paper's order, then ours
SECTION5 = (("pals", {}, "(a) PALS"), ("mirror-nodes", {"neumann": "full-traction"}, "(b) MNM"),
            ("pddo", {}, "(c) PDDO"), ("surface-nodes", {"order": 1}, "(d) SNM"),
            ("mirror-nodes", {"neumann": "normal-only"}, "MNM, normal-only Neumann"),
            ("none", {}, "none (uncorrected)"))


def _section5(scene, results, folder):
    """Figs. 14 and 15 side by side: one column per method at the paper's settings
    (partial volumes, Gaussian influence, m = 3, the default spacing of the runs)."""
    def paper(r):
        return (r.params.get("quadrature") == "partial-volume"
                and r.params.get("influence") == "gaussian" and r.params.get("m_ratio") == 3.0)
    panels = []
    for method, want, title in SECTION5:
        hit = [r for r in results if r.method == method and paper(r)
               and all(r.params.get(k) == v for k, v in want.items())]
        if hit:
            panels.append((title, hit[0]))
    if len(panels) < 2:
        return []
    fig, axes = plt.subplots(2, len(panels), figsize=(3.1 * len(panels), 5.8), squeeze=False)
    for col, (title, r) in enumerate(panels):
        f = r.fields
        L = f["lengths"]
        for k, name in enumerate(("u (Fig. 14)", "v (Fig. 15)")):
            ax = axes[k, col]
            z = _grid_values(f, f["error"][:, k]).T
            im = ax.imshow(z, origin="lower", extent=(0, L[0], 0, L[1]), cmap="viridis")
            cb = fig.colorbar(im, ax=ax, shrink=0.8)
            cb.ax.tick_params(labelsize=6)
            ax.set_title(f"{title}\n{name}: max {np.nanmax(z):.3g} %", fontsize=8)
            ax.tick_params(labelsize=6)
    fig.suptitle(f"{scene.id}: Eq. (44) errors [%] of the §5 methods "
                 f"(h = {panels[0][1].params['spacing']:g} m; one colour scale per panel)",
                 fontsize=9)
    fig.tight_layout()
    name = _save(fig, folder, f"{scene.id}-section5.png")
    return [(name, "Seed 001 §5, Figs. 14 (u) and 15 (v): PALS, the mirror node method, the "
                   "PDDO boundary layer and the surface node method on the same plate, then "
                   "our second MNM reading and the uncorrected model; each panel its own "
                   "colour scale, its maximum in the title. The paper's ordering: PALS "
                   "reduces the y error but keeps a large x error; MNM is close in x except "
                   "one corner and worst in y; SNM smallest among the ordinary state-based "
                   "methods; PDDO similar to SNM.")]


def _renderings_3d(scene, results, folder):
    """pyvista renderings of |u| and the error (:mod:`.fields3d`); a renderer that fails
    (no OpenGL, ...) costs these images only, with a warning naming the cause."""
    try:
        from .fields3d import render_box_fields
        return render_box_fields(scene, results, folder)
    except Exception as exc:  # noqa: BLE001  (any VTK/OpenGL failure: keep the report)
        warnings.warn(f"{scene.id}: no 3D renderings ({type(exc).__name__}: {exc})",
                      RuntimeWarning, stacklevel=2)
        return []


@family("seed001-boxes")
def surface_node_figures(scene, results, folder):
    dim = results[0].fields["x"].shape[1]
    maps = (_maps_3d(scene, results, folder) + _renderings_3d(scene, results, folder)
            if dim == 3 else _maps_2d(scene, results, folder))
    front = _section5(scene, results, folder) if dim == 2 else []
    return front + maps + _cost(scene, results, folder)
