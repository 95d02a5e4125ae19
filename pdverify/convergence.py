"""Convergence studies of every method in 1D, 2D and 3D: a delta-refinement at fixed
m-ratio and an m-refinement at fixed horizon, with the fitted rate.

A study is a list of levels, each a set of parameter overrides of one scene; the report
runs every level with every method the scene offers (its FEM reference excepted) as
ordinary runs, so each level is also an ordinary row of ``results.json``. Afterwards
:func:`collect` finds each level's run, and fits the rate p of ``error ~ C h^p`` by least
squares on ``log error`` against ``log h`` over all levels, where h is the horizon delta
(delta-refinement) or the grid spacing Delta (m-refinement). ``--quick`` keeps the two
coarsest levels (a rate from two points).

What to expect, and how to read a rate:

- delta-refinement at fixed m against a classical or manufactured reference: a method
  whose boundary treatment is consistent converges with the order of its nonlocal
  truncation (e.g. 2 for the Taylor fictitious nodes on the sine-loaded bar); an
  uncorrected model converges at about 1 or less (the surface layer is O(delta) thick).
- m-refinement at fixed delta against a classical reference converges to the nonlocal
  model's own error, so its rate tends to 0 (a plateau, not a defect); a negative rate
  says the error grows as the grid refines at fixed delta (e.g. the uncorrected bar,
  whose Dirichlet node moves towards the boundary).
- A method that is exact for the scene's field (error below :data:`EXACT`, e.g. the
  surface node, mirror node and PDDO methods on the plate's affine field) has no rate:
  the study records ``exact`` and the largest error instead.

The scenes: ``bar1d-sine-load`` (1D, analytic, seed 000 §5.4), ``plate2d-plane-strain``
(2D, analytic, seed 001 §5) and ``body3d-manufactured`` (3D, manufactured cubic field,
seed 001 §4.2): for each, the smallest scene of its dimension that takes every
correction implemented there and has a reference that is not itself refined. Sizes stay
within a few seconds a run.
"""
from __future__ import annotations

import json
from dataclasses import dataclass

import numpy as np

#: errors below this count as exact (round-off of the direct solves, whose residuals are
#: ~1e-13 relative; tests/corrections/test_mirror_pddo.py's SOLVED uses 1e-10 too)
EXACT = 1e-10


@dataclass(frozen=True)
class Study:
    scene: str
    kind: str                  # "delta" (fixed m) or "m" (fixed delta)
    levels: tuple              # overrides per level, coarsest first
    metric: str = "rel_l2_error"

    @property
    def fixed(self) -> str:
        first = self.levels[0]
        if self.kind == "delta":
            return f"m = {first['m_ratio']:g}"
        return f"delta = {first['m_ratio'] * first['spacing']:g}"

    def h(self, level: dict) -> float:
        """The refined length: the horizon (delta-refinement) or the spacing (m)."""
        return level["spacing"] * (level["m_ratio"] if self.kind == "delta" else 1.0)

    def used_levels(self, quick: bool) -> tuple:
        return self.levels[:2] if quick else self.levels


def _lv(spacing, m):
    return {"spacing": spacing, "m_ratio": float(m)}


STUDIES = (
    Study("bar1d-sine-load", "delta", tuple(_lv(h, 3) for h in (0.1, 0.05, 0.025, 0.0125))),
    Study("bar1d-sine-load", "m", tuple(_lv(0.15 / m, m) for m in (3, 6, 12, 24))),
    Study("plate2d-plane-strain", "delta", tuple(_lv(h, 3) for h in (0.1, 0.05, 0.025, 0.0125))),
    Study("plate2d-plane-strain", "m", tuple(_lv(0.2 / m, m) for m in (2, 4, 8))),
    Study("body3d-manufactured", "delta", tuple(_lv(h, 3) for h in (0.1, 0.0625, 0.05))),
    Study("body3d-manufactured", "m", tuple(_lv(1 / (6 * m), m) for m in (2, 3))),
)


def methods(scene) -> list[str]:
    """The methods a study runs: every method of the scene but its FEM reference and
    bond methods that are unavailable (a missing optional extra)."""
    bond = scene.bond_methods()
    return [m.name for m in scene.all_methods
            if m.name != "fem" and not (m.name in bond and bond[m.name].unavailable)]


def cases(scene_ids, quick: bool = False) -> list[tuple[str, str, dict]]:
    """The (scene, method, overrides) runs of every study on ``scene_ids``."""
    from .scenes import get_scene
    out = []
    for st in STUDIES:
        if st.scene not in scene_ids:
            continue
        scene = get_scene(st.scene)
        for method in methods(scene):
            for level in st.used_levels(quick):
                out.append((st.scene, method, dict(level)))
    return out


def fit_rate(h, err) -> float:
    """Least-squares slope p of log(err) = log(C) + p log(h)."""
    x, y = np.log(np.asarray(h, float)), np.log(np.asarray(err, float))
    x0 = x - x.mean()
    return float(x0 @ (y - y.mean()) / (x0 @ x0))


def collect(results, quick: bool = False) -> list[dict]:
    """Each study x method of the scenes present in ``results``: its levels (h, error,
    total time, status) and its fitted rate, or why there is none."""
    from .results import run_key
    from .scenes import get_scene
    present = {r.scene for r in results}
    out = []
    for st in STUDIES:
        if st.scene not in present:
            continue
        scene = get_scene(st.scene)
        for method in methods(scene):
            levels, note = [], ""
            for level in st.used_levels(quick):
                # the run at exactly the level's params (the method's other params at
                # their defaults), not another case of the scene at the same spacing
                want = run_key(st.scene, method, scene.resolve(method, level))
                run = next((r for r in results if r.key == want), None)
                err = None if run is None or run.status != "ok" else run.metrics.get(st.metric)
                levels.append({"h": st.h(level), **level,
                               "error": err, "status": "missing" if run is None else run.status,
                               "total_s": None if run is None else run.timings.get("total_s")})
            errs = [lv["error"] for lv in levels]
            rate = None
            if any(e is None for e in errs):
                note = "a level failed or is missing: no rate"
            elif max(errs) < EXACT:
                note = f"exact at every level (largest error {max(errs):.2g})"
            elif min(errs) <= 0:
                note = "an error of 0 at some level: no rate"
            else:
                rate = fit_rate([lv["h"] for lv in levels], errs)
            out.append({"scene": st.scene, "dim": scene.dim, "study": st.kind,
                        "fixed": st.fixed, "h": "delta" if st.kind == "delta" else "spacing",
                        "metric": st.metric, "method": method, "rate": rate, "note": note,
                        "levels": levels})
    return out


def key(entry: dict) -> tuple:
    """Identity of a study entry across result files."""
    return entry["scene"], entry["study"], entry["method"], json.dumps(
        [{k: v for k, v in lv.items() if k in ("spacing", "m_ratio")} for lv in entry["levels"]],
        sort_keys=True)
