"""Figures of the report: one module per family of scenes, each registering its draw function."""
from __future__ import annotations

import contextlib
import importlib
import os
import pkgutil

import matplotlib
import numpy as np

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

FAMILIES = {}

#: whether the figures being drawn are a ``--quick`` report's (:func:`quick_figures`):
#: lighter (no pyvista renderings, no minor ticks on log axes, a constrained-layout
#: figure saved without the tight-bbox pass, which lays the figure out twice more)
QUICK = False


@contextlib.contextmanager
def quick_figures(quick: bool = True):
    """Draw the figures of a ``--quick`` report (:data:`QUICK`) inside the block; the
    drawing processes forked inside it inherit the setting. Issue 32: the quick report's
    figures took about 30 s of CPU, three quarters of it in ``savefig``'s layout and tick
    passes (record quick_report-2026-11-27-issue32-findings)."""
    global QUICK
    old, QUICK = QUICK, bool(quick)
    try:
        yield
    finally:
        QUICK = old


def family(name, failed: bool = False):
    """Register a figure function ``f(scene, results, folder) -> [(file, caption), ...]``;
    ``failed``: it also draws failed runs that kept a partial result (e.g. a load curve up
    to where the run broke down)."""
    def deco(fn):
        fn.draws_failed = failed
        FAMILIES[name] = fn
        return fn
    return deco


def _load_all():
    for info in pkgutil.iter_modules(__path__):
        importlib.import_module(f"{__name__}.{info.name}")


def draw(scene, results, folder) -> list[tuple[str, str]]:
    """Draw ``scene``'s figure family for its successful runs; returns (file, caption) pairs."""
    _load_all()
    fn = FAMILIES.get(scene.figure)
    ok = [r for r in results if r.fields and (r.status == "ok" or fn is not None
                                              and fn.draws_failed)]
    if fn is None or not ok:
        return []
    return fn(scene, ok, folder)


def fem_then_pd(scene, results, folder):
    """For scenes that run PD beside their FEM reference: the FEM figures, the FEM runs and
    the PD runs, as ``(figures, fem_runs, pd_runs)``."""
    fem = [r for r in results if r.method == "fem"]
    pd_runs = [r for r in results if r.method != "fem"]
    return (FAMILIES["fem-reference"](scene, fem, folder) if fem else []), fem, pd_runs


def label(result) -> str:
    extra = ", ".join(f"{k}={v}" for k, v in result.params.items() if k in ("order",))
    return result.method + (f" ({extra})" if extra else "")


def distinct_labels(results, base=label) -> list[str]:
    """``base(r)`` of each run, plus the params that tell apart runs sharing a label (no
    legend names two lines alike, e.g. two "surface-nodes (order=3)" at two spacings)."""
    names = [base(r) for r in results]
    out = []
    for r, name in zip(results, names):
        twins = [q for q, n in zip(results, names) if n == name]
        if len(twins) > 1:
            differ = [k for k in r.params
                      if any(q.params.get(k) != r.params[k] for q in twins)]
            name += "; " + ", ".join(f"{k}={_short(r.params[k])}" for k in differ)
        out.append(name)
    return out


def method_colours(results) -> list[str]:
    """Each run's colour: its method's (:mod:`.palette`), in shades where a figure draws
    several runs of one method (dark to light in the order given)."""
    from . import palette
    count, seen, out = {}, {}, []
    for r in results:
        count[r.method] = count.get(r.method, 0) + 1
    for r in results:
        k = seen[r.method] = seen.get(r.method, -1) + 1
        out.append(palette.variant(r.method, k, count[r.method]))
    return out


def _short(v):
    return f"{v:.4g}" if isinstance(v, float) else v


#: A map whose values span less than this, relative to their size, shows round-off and
#: is replaced by its value: :data:`pdverify.convergence.EXACT` (1e-10; direct solves'
#: residuals are ~1e-13 relative).
ROUND_OFF = 1e-10


def round_off(values, scale=None) -> bool:
    """Whether a map of ``values`` would only show round-off: their range is at most
    :data:`ROUND_OFF` times ``scale`` (default: their largest magnitude; errors in per
    cent pass 100, so that a map at or below 1e-8 % counts)."""
    v = np.asarray(values, dtype=float)
    v = v[np.isfinite(v)]
    if v.size == 0:
        return True
    ref = np.abs(v).max() if scale is None else scale
    return float(v.max() - v.min()) <= ROUND_OFF * ref


def legend_outside(ax, where="right", **kw):
    """``ax``'s legend outside its data: right of the panel (``where="right"``) or below
    it (``"below"``, two columns); constrained layout makes room for it. Inside, a legend
    covers lines or markers wherever they happen to run (issue 52)."""
    style = {"fontsize": 7, "frameon": False, **kw}
    if where == "below":
        return ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.16),
                         ncol=style.pop("ncol", 2), **style)
    return ax.legend(loc="upper left", bbox_to_anchor=(1.02, 1.0), borderaxespad=0.0,
                     **style)


def number_panel(ax, text, title=None):
    """An axes showing ``text`` instead of a map (round-off, a single value)."""
    ax.set_axis_off()
    ax.text(0.5, 0.5, text, ha="center", va="center", fontsize=8, wrap=True,
            transform=ax.transAxes, bbox={"fc": "#eef4ff", "ec": "#99b", "lw": 0.5})
    if title:
        ax.set_title(title, fontsize=8.5)


def shared_log_norm(arrays, decades=4.0):
    """One logarithmic colour scale for several maps: up to the largest value, down to
    the smallest positive one but at most ``decades`` below the top (lower values take
    the lowest colour). None when no value is positive."""
    from matplotlib.colors import LogNorm
    pos = [np.asarray(a, dtype=float) for a in arrays]
    pos = np.concatenate([a[np.isfinite(a) & (a > 0)].ravel() for a in pos]) if pos else []
    if len(pos) == 0:
        return None
    hi = float(pos.max())
    lo = max(float(pos.min()), hi * 10.0 ** -decades)
    if lo >= hi:
        lo = hi / 10
    return LogNorm(vmin=lo, vmax=hi, clip=True)


#: the percentiles of the positive values between which an energy-density map's
#: logarithmic colour scale runs (:func:`energy_norm`; the Fig. 3 maps of seed 003 use the
#: same): the densities are singular at re-entrant and clamped corners and under a
#: contact's edge, so the top is capped below the singular nodes' values; with a linear
#: scale, or one up to the singular value, all but the corner was one colour (plate-l)
ENERGY_PERCENTILES = (1.0, 99.5)


def energy_norm(arrays):
    """One logarithmic colour scale for energy-density maps, from the
    :data:`ENERGY_PERCENTILES` of their positive values (values beyond take the end
    colours); None when no value is positive."""
    from matplotlib.colors import LogNorm
    pos = np.concatenate([np.asarray(a, dtype=float).ravel() for a in arrays])
    pos = pos[np.isfinite(pos) & (pos > 0)]
    if pos.size == 0:
        return None
    lo, hi = (float(v) for v in np.percentile(pos, ENERGY_PERCENTILES))
    if not lo < hi:
        lo, hi = float(pos.min()), float(pos.max())
    if not lo < hi:
        lo = hi / 10
    return LogNorm(vmin=lo, vmax=hi, clip=True)


def _tidy_axes(fig):
    """Before saving: log axes label only non-overlapping ticks (decades when two or more
    are in view, else :func:`nice_log_ticks`; minor ticks unlabelled), and colour bars
    print their values in full (no offset or multiplier text above the bar, where it
    ran into panel titles)."""
    from matplotlib.ticker import (FixedLocator, FormatStrFormatter, FuncFormatter,
                                   LogLocator, NullFormatter, ScalarFormatter)
    for ax in fig.axes:
        if hasattr(ax, "_colorbar"):
            for axis in (ax.xaxis, ax.yaxis):
                if isinstance(axis.get_major_formatter(), ScalarFormatter):
                    axis.set_major_formatter(FormatStrFormatter("%.3g"))
        for axis, scale in ((ax.xaxis, ax.get_xscale()), (ax.yaxis, ax.get_yscale())):
            if scale != "log":
                continue
            lo, hi = sorted(axis.get_view_interval())
            if not (lo > 0 and np.isfinite(hi)):
                continue
            axis.set_minor_formatter(NullFormatter())
            if not isinstance(axis.get_major_locator(), LogLocator):
                continue       # ticks set by hand (e.g. at a study's levels)
            ticks = nice_log_ticks(lo, hi)
            if ticks is not None:   # < 2 decades in view: LogLocator's own fallback
                axis.set_major_locator(FixedLocator(ticks))
                axis.set_major_formatter(FuncFormatter(lambda v, _: f"{v:.3g}"))


def nice_log_ticks(lo, hi):
    """Major ticks for a log axis from ``lo`` to ``hi`` when fewer than two decades are in
    view (else None: the decades serve): 1, 2, 5 times a power of ten, or 1, 1.5, 2, 3,
    5, 7 when that gives fewer than two, or the two ends rounded."""
    k0, k1 = int(np.floor(np.log10(lo))), int(np.ceil(np.log10(hi)))
    if sum(1 for k in range(k0, k1 + 1) if lo <= 10.0 ** k <= hi) >= 2:
        return None
    for subs in ((1, 2, 5), (1, 1.5, 2, 3, 5, 7)):
        ticks = [c * 10.0 ** k for k in range(k0, k1 + 1) for c in subs
                 if lo <= c * 10.0 ** k <= hi]
        if len(ticks) >= 2:
            return ticks
    return [float(f"{lo:.2g}"), float(f"{hi:.2g}")]


def node_image(x, spacing, values, unit=1.0):
    """Values at the nodes of a uniform 2D grid as an image (rows: y) and its extent
    (node positions times ``unit``, e.g. 1e3 for mm), for ``imshow(origin="lower")``."""
    i = np.rint((x[:, 0] - x[:, 0].min()) / spacing).astype(int)
    j = np.rint((x[:, 1] - x[:, 1].min()) / spacing).astype(int)
    img = np.full((j.max() + 1, i.max() + 1), np.nan)
    img[j, i] = values
    ext = tuple(unit * v for v in (x[:, 0].min(), x[:, 0].max(), x[:, 1].min(), x[:, 1].max()))
    return img, ext


#: the figures' resolution (dots per inch)
DPI = 110
#: zlib level of the PNG files: 3 writes them in about half the time of the default 6, the
#: files 6 % larger, lossless either way (record quick_report-2026-11-27-png-level)
PNG_LEVEL = 3


def save(fig, folder, name) -> str:
    """Write ``fig`` as ``folder/name`` (PNG, :data:`DPI`, cropped to its content) and
    close it. Under :data:`QUICK`: log axes without minor ticks, and a figure with a
    constrained layout (which already fits its content into the canvas) is saved
    without the tight bounding box, whose extra draw and layout passes cost about a third
    of a save (``benchmarks/quick_report.py``).

    The figure is laid out here, once, and then drawn once: ``savefig`` with a layout
    engine or a tight bounding box first draws the whole figure without output (ticks,
    text, images resampled) only to lay it out. Laying out needs no draw: the layout
    engine and the tight bounding box measure the artists with a renderer of the
    figure's size and dpi, as in that draw, so the file is the same, pixel for pixel
    (``tests/pdverify/test_quick_report.py``); the quick report's figures take about a
    sixth less CPU time (``benchmarks/quick_report.py --mode figures``)."""
    _tidy_axes(fig)
    tight = True
    engine = fig.get_layout_engine()
    if QUICK:
        _no_minor_log_ticks(fig)
        from matplotlib.layout_engine import ConstrainedLayoutEngine
        if isinstance(engine, ConstrainedLayoutEngine):
            tight = False
    path = os.path.join(folder, name)
    fig.set_dpi(DPI)
    renderer = fig.canvas.get_renderer()
    if engine is not None and fig.axes:
        try:
            engine.execute(fig)
        except ValueError:    # as Figure.draw: a layout that cannot be made is skipped
            pass
    fig.set_layout_engine(None)  # laid out: savefig neither lays out nor pre-draws
    box = (fig.get_tightbbox(renderer).padded(matplotlib.rcParams["savefig.pad_inches"])
           if tight else None)
    fig.savefig(path, dpi=DPI, bbox_inches=box, pil_kwargs={"compress_level": PNG_LEVEL})
    plt.close(fig)
    return name


def _no_minor_log_ticks(fig):
    """No minor ticks on the log axes of ``fig`` (their labels are off anyway,
    :func:`_tidy_axes`; each tick is laid out on every draw)."""
    from matplotlib.ticker import NullLocator
    for ax in fig.axes:
        for axis, scale in ((ax.xaxis, ax.get_xscale()), (ax.yaxis, ax.get_yscale())):
            if scale == "log":
                axis.set_minor_locator(NullLocator())


