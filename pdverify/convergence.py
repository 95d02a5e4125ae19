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

import numpy as np

#: errors below this count as exact (round-off of the direct solves, whose residuals are
#: ~1e-13 relative; tests/corrections/test_mirror_pddo.py's SOLVED uses 1e-10 too)
EXACT = 1e-10


@dataclass(frozen=True)
class Study:
    """One refinement of one scene: ``levels`` are overrides of the scene's own
    parameters, coarsest first. A level's refined length h is the horizon delta (a
    delta-refinement) or the grid spacing Delta (an m-refinement) as the scene states them
    in its one vocabulary, :meth:`~pdverify.scenes.base.Scene.discretisation`; or those
    over the body's size where the scene's size is itself a multiple of delta
    (``Discretisation.relative``). :meth:`fixed_in` says what stays fixed,
    :attr:`h_label` names h."""
    scene: str
    kind: str                  # "delta" (fixed m) or "m" (fixed delta)
    levels: tuple              # overrides per level, coarsest first
    metric: str = "rel_l2_error"
    #: methods the study leaves out, each for a stated cost (the scene's own cases run them)
    skip: tuple = ()
    #: the levels of ``--quick`` where its two coarsest levels cost too much for a quick
    #: report (None: those two; (): the study is left out of ``--quick``); the full
    #: report always runs :attr:`levels`
    quick_levels: tuple | None = None
    #: how the fixed m-ratio is written where the scene's paper writes it otherwise
    m_name: str = "m"
    #: methods that stop before the finest levels, each with the finest level they run
    #: and why: ``((methods, level, why), ...)``. A level finer than theirs (a smaller h)
    #: is not run for them; their rate is fitted over the levels they reach, and the
    #: study says where and why they stop (:meth:`stop`)
    stops: tuple = ()

    def stop(self, method: str):
        """``(finest h, why)`` of a method that stops early (:attr:`stops`), else None."""
        for names, level, why in self.stops:
            if method in names:
                return self.h(level), why
        return None

    def levels_for(self, method: str, quick: bool) -> tuple:
        """The levels of :meth:`used_levels` that ``method`` runs (:attr:`stops`)."""
        stop = self.stop(method)
        levels = self.used_levels(quick)
        if stop is None:
            return levels
        return tuple(lv for lv in levels if self.h(lv) >= stop[0] * (1 - 1e-12))

    def grid(self, level: dict):
        """The level's :class:`~pdverify.scenes.base.Discretisation`: the scene's
        parameters with the level's overrides, those of its uncorrected model where its
        methods differ in them (plate2d-clamped's FEM reference has a spacing of its own)."""
        from .scenes import get_scene
        scene = get_scene(self.scene)
        method = scene.baseline_spec().name or scene.all_methods[0].name
        return scene.discretisation(scene.resolve(method, level))

    @property
    def relative(self) -> bool:
        return self.grid(self.levels[0]).relative is not None

    @property
    def h_label(self) -> str:
        if self.relative:
            return "delta / L (side L)" if self.kind == "delta" else "Delta / L (side L)"
        return "horizon delta [m]" if self.kind == "delta" else "grid spacing Delta [m]"

    def h(self, level: dict) -> float:
        d = self.grid(level)
        if d.relative is not None:
            return float(d.relative[1] if self.kind == "delta" else d.relative[0])
        return float(d.delta if self.kind == "delta" else d.h)

    def used_levels(self, quick: bool) -> tuple:
        if not quick:
            return self.levels
        return self.levels[:2] if self.quick_levels is None else self.quick_levels

    def fixed_in(self, quick: bool) -> str:
        """What stays fixed in the levels of :meth:`used_levels`: the m-ratio of a
        delta-refinement, the horizon (or its ratio to the body's size) of an
        m-refinement; a ValueError where the levels do not keep it fixed."""
        grids = [self.grid(level) for level in self.used_levels(quick) or self.levels]
        if self.kind == "delta":
            held = {round(g.m, 9) for g in grids}
            text = f"{self.m_name} = {grids[0].m:g}"
        elif grids[0].relative is not None:
            held = {round(g.relative[1], 12) for g in grids}
            text = f"delta / L = 1/{1.0 / grids[0].relative[1]:g}"
        else:
            held = {round(g.delta, 12) for g in grids}
            text = f"delta = {grids[0].delta:g}"
        if len(held) > 1:
            raise ValueError(f"{self.scene}: the levels of a {self.kind}-refinement"
                             f"{' (--quick)' if quick else ''} do not keep "
                             f"{'m' if self.kind == 'delta' else 'delta'} fixed")
        return text


def _levels(names, values) -> tuple:
    """Levels as dicts of the scene's own parameters ``names`` (the papers' spelling)."""
    return tuple(dict(zip(names, v)) for v in values)


#: seed 000's fictitious nodes in 3D: near-singular on the 10 x 5 x 5 box
#: (body3d-manufactured's docstring) and 35-40 s a run at h = 0.05: five study levels
#: would add minutes to the report (benchmarks/records/taylor3d-2026-11-24-costly-3d.json);
#: the scene's own cases run it at h = 0.05
COSTLY_3D = ("taylor-fictitious",)


#: the methods of body3d-manufactured's delta-refinement that stop before its finest level:
#: their systems are not symmetric, so CG does not apply, and each goes as far as the
#: direct solver allows within the 2 GB a run may take (issue 55). Measured under load
#: (benchmarks/records/refine3d-2026-11-28-direct-reach.json): at spacing 1/24 surface
#: nodes 2.2 GB; energy, mirror nodes and PDDO 0.9-1.1 GB and 6-10 s of CPU; at 1/30 the
#: multifrontal solve of none's system (the size of energy's and the mirror nodes') took
#: 2.0 GB (refine3d-2026-11-28-levels-0.05-to-1-36.json)
STOP_3D = (
    (("surface-nodes",), {"spacing": 0.05, "m_ratio": 3.0},
     "its system is not symmetric (no CG), and the direct solve took 2.2 GB at spacing "
     "1/24, over the 2 GB a run may take"),
    (("energy", "mirror-nodes", "pddo"), {"spacing": 1 / 24, "m_ratio": 3.0},
     "not symmetric (no CG); the direct solve took 0.9-1.1 GB at spacing 1/24, and 2.0 GB "
     "at 1/30 on a system of the same size"),
    (("perifit",), {"spacing": 0.05, "m_ratio": 3.0},
     "an optional extra whose K's symmetry this study has not measured"),
)


#: Taylor's fictitious nodes, the surface nodes and PDDO on the bond-based sheets (issue
#: 55, ``corrections.bond_fictitious``, ``corrections.pddo_bond``): the scenes' own cases run them at the default grid.
#: On the tension sheet they are exact at every level (an affine field: no rate to fit)
#: and at m = 2 near-singular (the flux rows' checkerboard dependency); on the clamped
#: sheet the finest levels took 13-25 s a run under load (side 12, m = 12) and the
#: tension sheet's h = 0.625 mm 81 and 228 s and 2.2 GB (report of 2026-11-28, /tmp):
#: more than the issue's time for all its cells. PDDO's bond-based form
#: (``corrections.pddo_bond``) likewise: exact on the tension sheet, 7.6 and 9.9 s a run
#: under load at the clamped sheet's finest levels (m = 12; side 12)
#: The mirror nodes' bond-box runs the same unsymmetric LU on the same grids (one layer,
#: no surface nodes): skipped alike
BOND_BOX_COST = ("taylor-fictitious", "surface-nodes", "pddo", "mirror-nodes")


def _m(scene, kind, levels, skip=(), quick=None):
    """A study of a scene whose grid is its ``spacing`` and ``m_ratio``; ``levels`` and
    ``quick`` are (spacing, m_ratio) pairs."""
    names = ("spacing", "m_ratio")
    as_float = [(h, float(m)) for h, m in levels]
    return Study(scene, kind, _levels(names, as_float), skip=skip,
                 quick_levels=None if quick is None else _levels(
                     names, [(h, float(m)) for h, m in quick]))


STUDIES = (
    _m("bar1d-sine-load", "delta", [(h, 3) for h in (0.1, 0.05, 0.025, 0.0125)]),
    _m("bar1d-sine-load", "m", [(0.15 / m, m) for m in (3, 6, 12, 24)]),
    # seed 004: the homogenised bond bar (N points on L = 1, delta = horizon_ratio x
    # Delta); free-end history against Rao's series
    Study("bar1d-vibration", "delta", _levels(("nodes", "horizon_ratio"),
                                              [(n, 4.0) for n in (26, 51, 101, 201)]),
          m_name="delta / Delta"),
    Study("bar1d-vibration", "m", _levels(("nodes", "horizon_ratio"),   # delta = 0.08
                                          [(int(12.5 * r) + 1, float(r))
                                           for r in (2, 4, 8, 16)])),
    # seed 003: bond-based sheets (the directional, energy, volume, perifit corrections)
    Study("sheet2d-tension", "delta", _levels(("spacing", "horizon"),   # even spacings a side
                                              [(d / 4, d) for d in (0.01, 0.005, 0.0025)]),
          skip=BOND_BOX_COST),
    Study("sheet2d-tension", "m", _levels(("spacing", "horizon"),
                                          [(0.005 / m, 0.005) for m in (2, 4, 8)]),
          skip=BOND_BOX_COST),
    # sheet2d-clamped: the side is side_factor x delta and the load a strain, so the
    # relative errors depend only on delta / L = 1 / side_factor and m; a delta-refinement
    # at a fixed sheet is a growing side_factor.
    # 16 is too slow for the report; --quick at m = 3, its side 4 the m-refinement's first
    # level (benchmarks/records/quick_report-2026-11-26-quick-sheet2d-clamped.json)
    Study("sheet2d-clamped", "delta", _levels(("side_factor", "m_ratio"),
                                              [(float(s), 6.0) for s in (4, 8, 12)]),
          quick_levels=_levels(("side_factor", "m_ratio"), [(4.0, 3.0), (8.0, 3.0)]),
          skip=BOND_BOX_COST),
    Study("sheet2d-clamped", "m", _levels(("side_factor", "m_ratio"),
                                          [(4.0, float(m)) for m in (3, 6, 12)]),
          skip=BOND_BOX_COST),
    # seed 000 §6: the scene's own sweeps (same levels, so no extra runs in a full report)
    _m("plate2d-clamped", "delta", [(h, 3) for h in (0.2, 0.1, 0.05)]),
    # --quick at delta = 0.4 (h = 0.2 at m = 2, 0.1 at m = 4), less than half the time
    # of delta = 0.2 (benchmarks/records/quick_report-2026-11-26-quick-plate2d-clamped.json)
    _m("plate2d-clamped", "m", [(0.2 / m, m) for m in (2, 3, 4)],
       quick=[(0.2, 2), (0.1, 4)]),
    _m("plate2d-plane-strain", "delta", [(h, 3) for h in (0.1, 0.05, 0.025, 0.0125)]),
    _m("plate2d-plane-strain", "m", [(0.2 / m, m) for m in (2, 4, 8)]),
    # --quick (issue 32: the quick report in 30 s on 2 cores): the delta-refinement at
    # h = 0.1 (the scene's own quick runs) and 1/12 (6 cells a side), not 0.0625; the
    # m-refinement is left out: its finer level, h = 1/18 at m = 3, was over a quarter
    # of the quick report's runs
    # (benchmarks/records/quick_report-2026-11-26-quick-body3d-manufactured.json), and no
    # cheaper pair of whole m-ratios at one delta exists on the 1 x 0.5 x 0.5 box
    # (order-3 surface nodes need 5 cells a side, whole m-ratios)
    # issue 55: on to h = 1/24 and 1/30 (delta = 0.125, 0.1), where ``auto`` solves the
    # symmetric systems (none, volume, pals) by CG (policy.CG3D_FROM_UNKNOWNS); the others
    # stop where the direct solver does (STOP_3D)
    Study("body3d-manufactured", "delta",
          _levels(("spacing", "m_ratio"),
                  [(h, 3.0) for h in (0.1, 0.0625, 0.05, 1 / 24, 1 / 30)]),
          skip=COSTLY_3D, quick_levels=_levels(("spacing", "m_ratio"),
                                               [(0.1, 3.0), (1 / 12, 3.0)]),
          stops=STOP_3D),
    _m("body3d-manufactured", "m", [(1 / (6 * m), m) for m in (2, 3)], skip=COSTLY_3D,
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
            for level in st.levels_for(method, quick):
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
            reached = st.levels_for(method, quick)
            for level in reached:
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
            elif len(levels) < 2:
                note = "fewer than two levels: no rate"
            else:
                rate = fit_rate([lv["h"] for lv in levels], errs)
            # the rate between each pair of successive levels: a rate still drifting at
            # the finest pair says the levels are pre-asymptotic (three levels or more)
            pairs = ([fit_rate([a["h"], b["h"]], [a["error"], b["error"]])
                      for a, b in zip(levels, levels[1:])]
                     if rate is not None and len(levels) >= 3 else [])
            if len(reached) < len(st.used_levels(quick)):
                h_stop, why = st.stop(method)
                note = "; ".join(x for x in (note, f"stops at h = {h_stop:.4g}: {why}") if x)
            out.append({"scene": st.scene, "dim": scene.dim, "study": st.kind,
                        "fixed": st.fixed_in(quick), "h": st.h_label,
                        "metric": st.metric, "method": method, "rate": rate, "note": note,
                        "pair_rates": pairs, "levels": levels})
    return out


#: the keys of a collected level that are results, not the level's parameters
LEVEL_RESULTS = ("h", "error", "status", "total_s")


def key(entry: dict) -> tuple:
    """Identity of a study entry across result files."""
    return entry["scene"], entry["study"], entry["method"], json.dumps(
        [{k: v for k, v in lv.items() if k not in LEVEL_RESULTS} for lv in entry["levels"]],
        sort_keys=True)
