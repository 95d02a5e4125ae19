"""Convergence studies of every method in 1D, 2D and 3D: a delta-refinement at fixed
m-ratio and an m-refinement at fixed horizon, with the fitted rate.

A study is a list of levels, each a set of parameter overrides of one scene; the report
runs every level with every method the scene offers (its FEM reference excepted) as
ordinary runs, so each level is also an ordinary row of ``results.json``. Afterwards
:func:`collect` finds each level's run, and fits the rate p of ``error ~ C h^p`` by least
squares on ``log error`` against ``log h`` over all levels, where h is the horizon delta
(delta-refinement) or the grid spacing Delta (m-refinement). ``--quick`` keeps the two
coarsest levels (a rate from two points), or a study's own cheaper quick levels
(:attr:`Study.quick_levels`, e.g. the 3D delta-refinement), or leaves a study out where
no pair of levels is cheap (the 3D m-refinement).

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
from typing import Callable

import numpy as np

#: errors below this count as exact (round-off of the direct solves, whose residuals are
#: ~1e-13 relative; tests/corrections/test_mirror_pddo.py's SOLVED uses 1e-10 too)
EXACT = 1e-10


@dataclass(frozen=True)
class Study:
    """One refinement of one scene: ``levels`` are parameter overrides, coarsest first;
    ``h_of`` maps a level to the refined length h (the horizon for a delta-refinement,
    the spacing for an m-refinement, or those over the body's size where the scene is
    given in relative terms); ``fixed`` says what stays fixed, ``h_label`` names h."""
    scene: str
    kind: str                  # "delta" (fixed m) or "m" (fixed delta)
    levels: tuple              # overrides per level, coarsest first
    h_of: Callable[[dict], float]
    fixed: str
    h_label: str
    metric: str = "rel_l2_error"
    #: methods the study leaves out, each for a stated cost (the scene's own cases run them)
    skip: tuple = ()
    #: the levels of ``--quick`` where its two coarsest levels cost too much for a quick
    #: report (None: those two; (): the study is left out of ``--quick``); the full
    #: report always runs :attr:`levels`
    quick_levels: tuple | None = None
    #: what stays fixed in :attr:`quick_levels` where it differs from :attr:`fixed`
    quick_fixed: str | None = None

    def h(self, level: dict) -> float:
        return float(self.h_of(level))

    def used_levels(self, quick: bool) -> tuple:
        if not quick:
            return self.levels
        return self.levels[:2] if self.quick_levels is None else self.quick_levels

    def fixed_in(self, quick: bool) -> str:
        """What stays fixed in the levels of :meth:`used_levels`."""
        return self.quick_fixed if quick and self.quick_fixed is not None else self.fixed


def _mratio(scene, kind, levels, skip=(), quick=None):
    """Levels given as spacing and m_ratio (delta = m_ratio x spacing); ``quick``: the
    levels of ``--quick`` likewise (:attr:`Study.quick_levels`)."""
    lv = tuple({"spacing": h, "m_ratio": float(m)} for h, m in levels)
    ql = None if quick is None else tuple({"spacing": h, "m_ratio": float(m)}
                                          for h, m in quick)
    if kind == "delta":
        if ql is not None and len({q["m_ratio"] for q in ql}) > 1:
            raise ValueError(f"{scene}: a delta-refinement's quick levels share one m_ratio")
        return Study(scene, kind, lv, lambda p: p["spacing"] * p["m_ratio"],
                     f"m = {lv[0]['m_ratio']:g}", "horizon delta [m]", skip=skip,
                     quick_levels=ql,
                     quick_fixed=f"m = {ql[0]['m_ratio']:g}" if ql else None)
    if ql is not None and len({round(q["spacing"] * q["m_ratio"], 12) for q in ql}) > 1:
        raise ValueError(f"{scene}: an m-refinement's quick levels share one delta")
    return Study(scene, kind, lv, lambda p: p["spacing"],
                 f"delta = {lv[0]['spacing'] * lv[0]['m_ratio']:g}", "grid spacing Delta [m]",
                 skip=skip, quick_levels=ql,
                 quick_fixed=f"delta = {ql[0]['spacing'] * ql[0]['m_ratio']:g}" if ql else None)


#: seed 000's fictitious nodes in 3D: 35-40 s and 2 GB a run at h = 0.05, near-singular on
#: the 10 x 5 x 5 box (body3d-manufactured's docstring): five study levels would add about
#: three minutes of run time to the report; the scene's own cases run it at h = 0.05
COSTLY_3D = ("taylor-fictitious",)


def _sheet(kind, levels):
    """sheet2d-tension: the spacing and the horizon are parameters, the sheet is fixed."""
    lv = tuple({"spacing": h, "horizon": d} for h, d in levels)
    if kind == "delta":
        return Study("sheet2d-tension", kind, lv, lambda p: p["horizon"],
                     f"m = {lv[0]['horizon'] / lv[0]['spacing']:g}", "horizon delta [m]")
    return Study("sheet2d-tension", kind, lv, lambda p: p["spacing"],
                 f"delta = {lv[0]['horizon']:g}", "grid spacing Delta [m]")


def _clamped(kind, levels, quick=None):
    """sheet2d-clamped: the side is side_factor x delta and the load a strain, so the
    relative errors depend only on delta / L = 1 / side_factor and m; a delta-refinement
    at a fixed sheet is a growing side_factor. ``quick``: the levels of ``--quick``
    (:attr:`Study.quick_levels`), a delta-refinement at the same m."""
    lv = tuple({"side_factor": float(s), "m_ratio": float(m)} for s, m in levels)
    if kind == "delta":
        ql = None if quick is None else tuple({"side_factor": float(s), "m_ratio": float(m)}
                                              for s, m in quick)
        if ql is not None and len({q["m_ratio"] for q in ql}) > 1:
            raise ValueError("sheet2d-clamped: a delta-refinement's quick levels share one "
                             "m_ratio")
        return Study("sheet2d-clamped", kind, lv, lambda p: 1.0 / p["side_factor"],
                     f"m = {lv[0]['m_ratio']:g}", "delta / L (side L)", quick_levels=ql,
                     quick_fixed=None if ql is None else f"m = {ql[0]['m_ratio']:g}")
    return Study("sheet2d-clamped", kind, lv,
                 lambda p: 1.0 / (p["side_factor"] * p["m_ratio"]),
                 f"delta / L = 1/{lv[0]['side_factor']:g}", "Delta / L (side L)")


def _vibration(kind, levels):
    """bar1d-vibration: N points on L = 1 (spacing 1 / (N - 1)), delta = ratio x spacing."""
    lv = tuple({"nodes": int(n), "horizon_ratio": float(r)} for n, r in levels)
    if kind == "delta":
        return Study("bar1d-vibration", kind, lv,
                     lambda p: p["horizon_ratio"] / (p["nodes"] - 1),
                     f"delta / Delta = {lv[0]['horizon_ratio']:g}", "horizon delta [m]")
    return Study("bar1d-vibration", kind, lv, lambda p: 1.0 / (p["nodes"] - 1),
                 f"delta = {lv[0]['horizon_ratio'] / (lv[0]['nodes'] - 1):g}",
                 "grid spacing Delta [m]")


STUDIES = (
    _mratio("bar1d-sine-load", "delta", [(h, 3) for h in (0.1, 0.05, 0.025, 0.0125)]),
    _mratio("bar1d-sine-load", "m", [(0.15 / m, m) for m in (3, 6, 12, 24)]),
    # seed 004: the homogenised bond bar; free-end history against Rao's series
    _vibration("delta", [(n, 4) for n in (26, 51, 101, 201)]),
    _vibration("m", [(int(12.5 * r) + 1, r) for r in (2, 4, 8, 16)]),   # delta = 0.08
    # seed 003: bond-based sheets (the directional, energy, volume, perifit corrections)
    _sheet("delta", [(d / 4, d) for d in (0.01, 0.005, 0.0025)]),   # even spacings a side
    _sheet("m", [(0.005 / m, 0.005) for m in (2, 4, 8)]),
    # 16: 10 s a run; --quick at m = 3 (side 8: 0.5 s for its six methods, 6.9 s at m = 6;
    # issue 32), its side 4 the m-refinement's first level
    _clamped("delta", [(s, 6) for s in (4, 8, 12)], quick=[(4, 3), (8, 3)]),
    _clamped("m", [(4, m) for m in (3, 6, 12)]),
    # seed 000 §6: the scene's own sweeps (same levels, so no extra runs in a full report)
    _mratio("plate2d-clamped", "delta", [(h, 3) for h in (0.2, 0.1, 0.05)]),
    # --quick at delta = 0.4 (h = 0.2 at m = 2, 0.1 at m = 4: 1.5 s for the eight methods;
    # 3.5 s at delta = 0.2, whose h = 1/15 level took 3.1 s; issue 32)
    _mratio("plate2d-clamped", "m", [(0.2 / m, m) for m in (2, 3, 4)],
            quick=[(0.2, 2), (0.1, 4)]),
    _mratio("plate2d-plane-strain", "delta", [(h, 3) for h in (0.1, 0.05, 0.025, 0.0125)]),
    _mratio("plate2d-plane-strain", "m", [(0.2 / m, m) for m in (2, 4, 8)]),
    # --quick (issue 32: the quick report in 30 s on 2 cores): the delta-refinement at
    # h = 0.1 (the scene's own quick runs) and 1/12 (6 cells a side, 0.5-4 s a run),
    # not 0.0625 (1-6.5 s a run, 16 s in all); the m-refinement is left out: its finer
    # level, h = 1/18 at m = 3, took 30 s of the quick report's 111 s of runs (surface
    # nodes alone 12 s), and no cheaper pair of whole m-ratios at one delta exists on the
    # 1 x 0.5 x 0.5 box (order-3 surface nodes need 5 cells a side, whole m-ratios)
    _mratio("body3d-manufactured", "delta", [(h, 3) for h in (0.1, 0.0625, 0.05)],
            skip=COSTLY_3D, quick=[(0.1, 3), (1 / 12, 3)]),
    _mratio("body3d-manufactured", "m", [(1 / (6 * m), m) for m in (2, 3)], skip=COSTLY_3D,
            quick=[]),
)


def methods(scene) -> list[str]:
    """The methods a study runs: every method of the scene but its FEM reference, bond
    methods that are unavailable (a missing optional extra) and peer codes (they run on
    the parameters their own report runs name, :mod:`pdverify.peers`)."""
    bond = scene.bond_methods()
    offered = scene.offered()
    return [m.name for m in scene.all_methods
            if m.name != "fem" and not (m.name in bond and bond[m.name].unavailable)
            and not getattr(offered.get(m.name), "peer", False)]


def cases(scene_ids, quick: bool = False) -> list[tuple[str, str, dict]]:
    """The (scene, method, overrides) runs of every study on ``scene_ids``."""
    from .scenes import get_scene
    out = []
    for st in STUDIES:
        if st.scene not in scene_ids:
            continue
        scene = get_scene(st.scene)
        for method in methods(scene):
            if method in st.skip:
                continue
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
    first = {}                  # each key's first run, as a scan of ``results`` finds it
    for r in results:
        first.setdefault(r.key, r)
    out = []
    for st in STUDIES:
        if st.scene not in present or not st.used_levels(quick):
            continue
        scene = get_scene(st.scene)
        for method in methods(scene):
            if method in st.skip:
                continue
            levels, note = [], ""
            for level in st.used_levels(quick):
                # the run at exactly the level's params (the method's other params at
                # their defaults), not another case of the scene at the same spacing
                want = run_key(st.scene, method, scene.resolve(method, level))
                run = first.get(want)
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
                        "fixed": st.fixed_in(quick), "h": st.h_label,
                        "metric": st.metric, "method": method, "rate": rate, "note": note,
                        "levels": levels})
    return out


#: the keys of a collected level that are results, not the level's parameters
LEVEL_RESULTS = ("h", "error", "status", "total_s")


def key(entry: dict) -> tuple:
    """Identity of a study entry across result files."""
    return entry["scene"], entry["study"], entry["method"], json.dumps(
        [{k: v for k, v in lv.items() if k not in LEVEL_RESULTS} for lv in entry["levels"]],
        sort_keys=True)
