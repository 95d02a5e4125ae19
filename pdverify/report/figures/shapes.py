"""Figures of the shape scenes (issue 35): error maps at the default grid, refinement, and
the error against jitter."""
from __future__ import annotations

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.ticker import FormatStrFormatter

from . import family, fem_then_pd, legend_outside, node_image, palette, save

def taylor_style(order: int) -> tuple[str, str]:
    """The Taylor method's colour in a shade per order 1, 2, 3 (dark to light) and its
    marker (:mod:`.palette`)."""
    return (palette.variant("taylor-fictitious", int(order) - 1, 3),
            palette.marker("taylor-fictitious"))


def _style(key) -> tuple[str, str]:
    if isinstance(key, int):
        return taylor_style(key)
    st = palette.style(key)
    return st.colour, st.marker


def _key(r):
    return r.params.get("order", r.method) if r.method == "taylor-fictitious" else r.method


def _name(r):
    return f"taylor n = {r.params['order']}" if r.method == "taylor-fictitious" else r.method


def _default(scene, r, ignore=()):
    d = {q.name: q.default for q in scene.pd_params}
    return all(r.params.get(k, v) == v for k, v in d.items() if k not in ignore)


def _error_maps(scene, runs, folder):
    level = [r for r in runs if _default(scene, r, ignore=("spacing",)) and r.status == "ok"]
    if not level:
        return []
    # the default grid, or the one nearest it (a quick report runs a coarser one)
    h0 = next(q.default for q in scene.pd_params if q.name == "spacing")
    h = min((r.params.get("spacing", h0) for r in level), key=lambda v: abs(v - h0))
    pick = sorted((r for r in level if r.params.get("spacing", h0) == h),
                  key=lambda r: (r.method != "none", r.method, r.params.get("order", 0)))
    cols = min(4, len(pick))
    rows = -(-len(pick) // cols)
    fig, axes = plt.subplots(rows, cols, figsize=(3.4 * cols + 1, 3.2 * rows),
                             layout="constrained", squeeze=False)
    err = [r.fields["error"].max(axis=1) for r in pick]
    vmax = max(e.max() for e in err)
    for ax, r, e in zip(axes.flat, pick, err):
        img, ext = node_image(r.fields["x"], r.fields["spacing"], e)
        half = 0.5 * r.fields["spacing"]     # each node's cell: the image spans the body
        ext = (ext[0] - half, ext[1] + half, ext[2] - half, ext[3] + half)
        im = ax.imshow(img, origin="lower", extent=ext, cmap="magma_r", vmin=0, vmax=vmax)
        ax.set_title(f"{_name(r)} (max {e.max():.2f} %)", fontsize=8.5)
        ax.set_aspect("equal")
        # three x ticks, the body's ends and middle: on a narrow body (the 2 x 6 m
        # cracked plate) the default ticks ran into each other ("-0.50.00.5")
        ax.set_xticks(np.linspace(ext[0], ext[1], 3))
        ax.xaxis.set_major_formatter(FormatStrFormatter("%.2g"))
        ax.tick_params(labelsize=8)
    for ax in axes.flat[len(pick):]:
        ax.set_axis_off()
    fig.colorbar(im, ax=axes, shrink=0.85, label="largest component error [% of max |u_FEM|]")
    return [(save(fig, folder, f"{scene.id}-errors.png"),
             f"Error maps at h = {h:g} m (m = 3), every method on one colour "
             "scale: the largest component error at each PD node in % of max |u_FEM|. The "
             "uncorrected model and the bond methods fix the nodes nearest a prescribed part "
             "at the FEM value (zero error there by construction).")]


def _lines(ax, runs, x_of, metric, xlabel, spread=False):
    drawn = False
    for key in sorted({_key(r) for r in runs}, key=str):
        rs = [r for r in runs if _key(r) == key and r.status == "ok"]
        xs = sorted({x_of(r) for r in rs})
        if len(xs) < 2:
            continue
        colour, marker = _style(key)
        by = [np.array([r.metrics[metric] for r in rs if x_of(r) == x]) for x in xs]
        mean = np.array([b.mean() for b in by])
        name = _name(next(r for r in rs))
        if spread:
            lo = mean - np.array([b.min() for b in by])
            hi = np.array([b.max() for b in by]) - mean
            ax.errorbar(xs, mean, yerr=[lo, hi], color=colour, marker=marker, ms=4,
                        capsize=3, label=name)
        else:
            slope = np.polyfit(np.log(xs), np.log(mean), 1)[0]
            ax.loglog(xs, mean, color=colour, marker=marker, ms=4,
                      label=f"{name} (slope {slope:.2f})")
        drawn = True
    ax.set_xlabel(xlabel)
    ax.grid(True, which="both", alpha=0.3)
    if drawn:
        legend_outside(ax)
    return drawn


def _convergence(scene, runs, folder):
    rs = [r for r in runs if _default(scene, r, ignore=("spacing",))]
    fig, (a1, a2) = plt.subplots(1, 2, figsize=(11, 4.2), layout="constrained")
    ok = _lines(a1, rs, lambda r: r.params["spacing"], "rel_l2_error", "spacing [m] (m = 3)")
    _lines(a2, rs, lambda r: r.params["spacing"], "boundary_max_error_pct",
           "spacing [m] (m = 3)")
    a1.set_ylabel("rel. L2 error vs FEM")
    a2.set_ylabel("max error within delta of the boundary [%]")
    if not ok:
        plt.close(fig)
        return []
    return [(save(fig, folder, f"{scene.id}-convergence.png"),
             "Refinement toward the FEM reference at m = 3 (delta = 3 spacings), fitted "
             "log-log slopes in the legends: the whole field (left) and the largest error "
             "in the layer within one horizon of the boundary (right).")]


def _jitter(scene, runs, folder):
    jittered = {(r.method, r.params.get("order")) for r in runs
                if r.params.get("jitter", 0.0) > 0}
    rs = [r for r in runs if _default(scene, r, ignore=("jitter", "jitter_seed"))
          and (r.method, r.params.get("order")) in jittered]
    if len({r.params.get("jitter", 0.0) for r in rs}) < 2:
        return []
    fig, (a1, a2) = plt.subplots(1, 2, figsize=(11, 4.2), layout="constrained")
    x_of = lambda r: r.params.get("jitter", 0.0)   # noqa: E731
    _lines(a1, rs, x_of, "rel_l2_error", "jitter [fraction of the spacing]", spread=True)
    _lines(a2, rs, x_of, "max_error_pct", "jitter [fraction of the spacing]", spread=True)
    a1.set_ylabel("rel. L2 error vs FEM")
    a2.set_ylabel("max error [% of max |u_FEM|]")
    a1.set_yscale("log")
    a2.set_yscale("log")
    seeds = len(scene.jitter_seeds)
    return [(save(fig, folder, f"{scene.id}-jitter.png"),
             f"Error against jitter (every real node moved at random, uniform in a square of "
             f"side jitter x spacing; the bond family stays the lattice's), at the default "
             f"grid: the mean over {seeds} seeds, bars from the smallest to the largest. "
             f"Jitter 0 is the lattice.")]


@family("shape2d")
def shape_figures(scene, results, folder):
    out, fem, runs = fem_then_pd(scene, results, folder)
    out += _error_maps(scene, [r for r in runs if r.fields.get("x") is not None], folder)
    out += _convergence(scene, runs, folder)
    out += _jitter(scene, runs, folder)
    return out
