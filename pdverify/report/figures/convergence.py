"""Convergence studies (:mod:`pdverify.convergence`): per scene, the delta-refinement at
fixed m and the m-refinement at fixed delta, error against h on log axes, the fitted
rate of each method in the legend."""
from __future__ import annotations

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.ticker import NullFormatter

from . import save


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


def draw(studies, folder) -> dict:
    """``{scene: [(file, caption)]}``, one two-panel figure per scene with studies."""
    out = {}
    for scene in dict.fromkeys(s["scene"] for s in studies):
        mine = [s for s in studies if s["scene"] == scene]
        kinds = [k for k in ("delta", "m") if any(s["study"] == k for s in mine)]
        fig, axes = plt.subplots(1, len(kinds), figsize=(6.2 * len(kinds), 4.4), squeeze=False)
        for ax, kind in zip(axes[0], kinds):
            entries = [s for s in mine if s["study"] == kind]
            for e in entries:
                pts = [(lv["h"], max(lv["error"], 1e-16)) for lv in e["levels"]
                       if lv["error"] is not None]
                if pts:
                    ax.loglog(*zip(*pts), "o-", ms=4, label=_legend(e))
            _reference_slopes(ax, entries, kind)
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
            ax.legend(fontsize=7)
        fig.suptitle(f"{scene}: convergence of every method", fontsize=11)
        name = save(fig, folder, f"{scene}-convergence-studies.png")
        out[scene] = [(name, f"{scene}: error against the refined length, one line per "
                             "method, the least-squares rate p of error ~ h^p in the legend "
                             "(grey: reference slopes h^1 and h^2 through the coarsest level, "
                             "the orders expected of an uncorrected and a consistent treatment "
                             "under delta-refinement) "
                             "(or why there is none: exact at every level, a failed level). "
                             "Left: delta -> 0 at fixed m; right: m -> infinity at fixed "
                             "delta, which converges to the nonlocal model's own error "
                             "(rate -> 0) when the reference is classical.")]
    return out
