"""Convergence studies (:mod:`pdverify.convergence`): per scene, the delta-refinement at
fixed m and the m-refinement at fixed delta, error against h on log axes, the fitted
rate of each method in the legend."""
from __future__ import annotations

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.ticker import NullFormatter

from . import legend_outside, palette, save


def _legend(entry) -> str:
    if entry["rate"] is not None:
        return f"{entry['method']} (rate {entry['rate']:.2f})"
    return f"{entry['method']} ({entry['note'].split(' (')[0]})"


#: the orders :mod:`pdverify.convergence` expects (its docstring): at fixed m a
#: consistent treatment converges with its nonlocal truncation order, 2, an uncorrected
#: model at about 1 (its surface layer is O(delta) thick); at fixed delta the error
#: tends to the nonlocal model's own (rate 0), drawn against the same two guides
EXPECTED_ORDERS = (1, 2)


def reference_slopes(entries):
    """The reference lines of a study panel: ``[(p, (h0, h1), (e0, e1))]`` for each p of
    :data:`EXPECTED_ORDERS`, over the panel's h range, through the geometric mean of the
    errors (that are not round-off) at the coarsest level; [] without such errors."""
    from ...convergence import EXACT
    coarse = {}
    for e in entries:
        for lv in e["levels"]:
            if lv["error"] is not None and lv["error"] > EXACT:
                coarse.setdefault(lv["h"], []).append(lv["error"])
    hs = sorted({lv["h"] for e in entries for lv in e["levels"]})
    if len(hs) < 2 or hs[-1] not in coarse:
        return []
    anchor = float(np.exp(np.mean(np.log(coarse[hs[-1]]))))
    return [(p, (hs[0], hs[-1]), (anchor * (hs[0] / hs[-1]) ** p, anchor))
            for p in EXPECTED_ORDERS]


def _reference_slopes(ax, entries, kind):
    for p, hs, es in reference_slopes(entries):
        ax.loglog(hs, es, ls=(0, (4, 3)) if p == 1 else (0, (1, 2)), color="0.35", lw=1,
                  label=f"reference slope h^{p}")


def exact_floor(entries):
    """The floor of a study panel: a factor :data:`FLOOR_FACTOR` below its smallest error
    that is not round-off (:data:`pdverify.convergence.EXACT`); the round-off errors are
    drawn on it, marked, so that the axis does not stretch down to 1e-15. None when
    every error is round-off (the panel then spans :data:`ALL_EXACT_SPAN`)."""
    from ...convergence import EXACT
    real = [lv["error"] for e in entries for lv in e["levels"]
            if lv["error"] is not None and lv["error"] > EXACT]
    return min(real) / FLOOR_FACTOR if real else None


#: how far below a panel's smallest real error its floor lies (a third of a decade and a
#: half: the floor's markers stay apart from the lowest real point)
FLOOR_FACTOR = 5.0
#: the factor between the floor marks of two methods exact in one panel (a fifth of a
#: decade: the triangles stay apart on the log axis, all below the floor factor)
EXACT_STAGGER = 1.3
#: the y range of a panel whose every error is round-off: just above the EXACT bound
ALL_EXACT_SPAN = (1e-10, 1e-6)


def study_panel(ax, entries):
    """One study panel: a line per method in its colour and marker (:mod:`.palette`), the
    round-off levels (error <= EXACT) as hollow downward triangles on the panel's floor
    (:func:`exact_floor`; a second exact method a step :data:`EXACT_STAGGER` above it,
    still below the smallest real error) and the reference slopes; returns the floor."""
    from ...convergence import EXACT
    floor = exact_floor(entries)
    at = floor if floor is not None else ALL_EXACT_SPAN[0] * 10
    any_exact = 0
    for e in entries:
        st = palette.style(e["method"])
        pts = [(lv["h"], lv["error"]) for lv in e["levels"] if lv["error"] is not None]
        if not pts:
            continue
        real = [(h, v) for h, v in pts if v > EXACT]
        exact = [h for h, v in pts if v <= EXACT]
        # the line runs through the real levels; a round-off level sits on the floor, each
        # method's a step of EXACT_STAGGER above the last one's, so that none hides another
        mark = at * EXACT_STAGGER ** any_exact
        line = [(h, v if v > EXACT else mark) for h, v in pts]
        ax.loglog(*zip(*line), "-", color=st.colour, lw=1.2, alpha=0.6 if exact else 1.0)
        if real:
            ax.loglog(*zip(*real), st.marker, ls="none", ms=4.5, color=st.colour)
        if exact:
            any_exact += 1
            ax.loglog(exact, [mark] * len(exact), "v", ls="none", ms=6, mfc="none",
                      mec=st.colour, mew=1.3)
        ax.plot([], [], "-", marker=st.marker, ms=4.5, color=st.colour, label=_legend(e))
    _reference_slopes(ax, entries, None)
    if any_exact:
        ax.axhline(at, color="0.6", lw=0.8, ls=":")
        ax.plot([], [], "v", ls="none", ms=6, mfc="none", mec="0.3",
                label=f"exact to round-off (error <= {EXACT:g}), drawn at the floor")
    lo = at / 2 if floor is not None else ALL_EXACT_SPAN[0]
    top = max([lv["error"] for e in entries for lv in e["levels"]
               if lv["error"] is not None] + [ALL_EXACT_SPAN[1]] * (floor is None))
    ax.set_ylim(lo, top * 2)
    return floor


def draw(studies, folder) -> dict:
    """``{scene: [(file, caption)]}``, one two-panel figure per scene with studies."""
    out = {}
    for scene in dict.fromkeys(s["scene"] for s in studies):
        mine = [s for s in studies if s["scene"] == scene]
        kinds = [k for k in ("delta", "m") if any(s["study"] == k for s in mine)]
        fig, axes = plt.subplots(1, len(kinds), figsize=(6.2 * len(kinds), 4.4), squeeze=False)
        for ax, kind in zip(axes[0], kinds):
            entries = [s for s in mine if s["study"] == kind]
            study_panel(ax, entries)
            # ticks at the levels only: log axes within a decade otherwise label every
            # minor tick and the labels run into each other
            hs = sorted({lv["h"] for e in entries for lv in e["levels"]})
            ax.xaxis.set_minor_formatter(NullFormatter())
            ax.set_xticks(hs, [f"{h:.3g}" for h in hs])
            fixed = entries[0]["fixed"]
            ax.set_xlabel(entries[0]["h"])
            ax.set_ylabel(entries[0]["metric"])
            ax.set_title(f"{'delta' if kind == 'delta' else 'm'}-refinement at fixed {fixed}",
                         fontsize=10)
            ax.grid(True, which="both", alpha=0.3)
            # below the panel, outside the data
            legend_outside(ax, "below")
        fig.suptitle(f"{scene}: convergence of every method", fontsize=11)
        name = save(fig, folder, f"{scene}-convergence-studies.png")
        out[scene] = [(name, f"{scene}: error against the refined length, one line per "
                             "method, the least-squares rate p of error ~ h^p in the legend "
                             "(grey: reference slopes h^1 and h^2 through the coarsest level, "
                             "the orders expected of an uncorrected and a consistent treatment "
                             "under delta-refinement) "
                             "(or why there is none: exact at every level, a failed level); "
                             "hollow triangles on the dotted floor: levels exact to round-off "
                             "(error <= 1e-10), drawn there instead of at their 1e-15. "
                             "Left: delta -> 0 at fixed m; right: m -> infinity at fixed "
                             "delta, which converges to the nonlocal model's own error "
                             "(rate -> 0) when the reference is classical.")]
    return out
