"""``peer:lammps`` as a treatment of the ``static-state`` family (the cracked shapes
too: atom types keep LAMMPS from bonding across a crack,
:func:`pdverify.peers.lammps.crack_types`) and of the scenes that state their problem
(the sheets, :data:`BOND_SCENES`; the stiffness scenes of both theories,
:data:`ENERGY_SCENES`, whose atoms LAMMPS evaluates at u = eps . x; seed 004's static
bars, :data:`BAR_SCENES`, and its vibrating bar, :data:`DYNAMIC_BAR_SCENES`, run by
``fix nve``): the scene's uncorrected problem solved by LAMMPS
(:mod:`pdverify.peers.lammps`) instead of pdverify's own solve, and measured by the
scene's own ``measure``; the bond-based scenes it cannot run say why (:data:`REFUSED`).

Beside the scene's metrics a run records, as metrics (all relative L2 norms over the
real nodes, divided by the norm of pdverify's ``none`` field at the same params):
- ``peer_diff_to_none``: LAMMPS's field against pdverify's ``none``;
- ``peer_gap_volumes``: (``as-used`` only) the linear model with LAMMPS's volume ramp and
  uniform volumes against ``none``: what LAMMPS's weights near the horizon change;
- ``peer_gap_nonlinear``: LAMMPS's field against the linear model of its own setting
  (``none`` for ``same-model``): its geometric nonlinearity and the stopping tolerance;
- ``equilibrium_residual``: the relative residual of LAMMPS's field in the linear model of
  its setting; the run fails, naming it, when the field is farther from that model's
  solution than :func:`pdverify.nodeset.equilibrium` allows, and when bonds were lost.
Both linear models are assembled and solved by pdverify in the same run, in its solve
phase beside LAMMPS, which takes nearly all of it (record peers-2026-11-28-twin-solves).
On the stiffness scenes the same metrics compare the nodal energy densities (relative L2
over nodes and strain states) and ``equilibrium_residual`` has no meaning (nothing is
solved): LAMMPS's energies must lie within the equilibrium check's rule of its setting's
linear model (:func:`peer_energies_of`).
"""
from __future__ import annotations

import dataclasses
import tempfile
from dataclasses import dataclass

import numpy as np

from .treatment import Treatment
from ..errors import InputError, NumericalError
from ..params import Param
from ..peers import lammps

SETTING = Param("setting", "as-used", "how LAMMPS runs: as its examples run it (volume "
                "ramp near the horizon, horizon (m + 2e-4) h, one volume per atom) or driven "
                "to solve pdverify's discrete model (its volumes and bonds, no ramp)",
                choices=lammps.SETTINGS)


def ramp(bond_x, spacing, horizon):
    """LAMMPS's volume factor of a bond of length ``bond_x`` (pair_peri_*.cpp: bonds
    within half a lattice constant h of the horizon get (delta + h/2 - r0) / h)."""
    half = 0.5 * spacing
    return np.where(np.abs(bond_x - horizon) <= half,
                    (-1.0 / (2 * half)) * bond_x + (1.0 + (horizon - half) / (2 * half)), 1.0)


def as_used_closure(model):
    """The closure that gives pdverify's linear model LAMMPS's as-used bond weights on a
    lattice of uniform volumes (``model``: :class:`pdverify.peers.lammps.Model`): its ramp
    within h/2 of its horizon (m + 2e-4) h, whole cells inside, no bond beyond, in place of
    the scene's quadrature's beta (``weight_factor`` multiplies beta, or the bond-based
    spring stiffness, which holds beta)."""
    from ..pd.closure import Closure
    horizon = (model.m_ratio + lammps.EXAMPLES_MARGIN) * model.spacing

    def lammps_weights(m):
        keep = m.bond_x <= horizon
        return np.where(keep, ramp(m.bond_x, model.spacing, horizon)
                        / np.where(keep, m.bond_beta, 1.0), 0.0)
    return Closure(weight_factor=lammps_weights)


def _rel(a, b, scale) -> float:
    return float(np.linalg.norm(a - b) / scale) if scale > 0 else float(np.linalg.norm(a - b))


#: the report's peer runs: scene -> overrides (each run in both settings, with LAMMPS's
#: influence and whole-cell volumes where the scene has those parameters); sizes kept
#: small so that the runs add seconds to a full report (~1 s for the 3D box at h = 0.1:
#: record peers-2026-11-28-report-runs); the clamped sheet at m = 4 (17 x 17 atoms, ~850
#: FIRE steps; Table 2's m = 6 takes ~4x as long)
REPORT_RUNS = {"body3d-traction": {"spacing": 0.1}, "plate2d-clamped": {},
               "plate2d-plane-strain": {}, "bar1d-traction": {}, "sheet2d-tension": {"spacing": 0.0025},
               "sheet2d-clamped": {"m_ratio": 4.0},
               # no solve: one LAMMPS process evaluates every strain state (~0.4 s each)
               "stiffness2d-sheet": {"spacing": 0.002}, "stiffness3d-box-bond": {"spacing": 0.1},
               # peri/lps, its energy read as lammps.lps_energy_density (~0.1 s each)
               "stiffness3d-box": {"spacing": 0.1}, "stiffness2d-plate": {"spacing": 0.05},
               # seed 004's bars at the paper's sizes (9 and 17 + 9 + 12 atoms), same model
               "bar1d-homogenization": {}, "bar1d-constraints": {},
               # seed 004's vibrating bar (b) at Table 13's size (100 atoms, ~1,500 steps)
               "bar1d-vibration": {},
               # the crack scenes at the coarsest grids whose K fit has its 8 node pairs
               # (m = 2: the fit's window starts at 2 horizons; 1,600-4,800 atoms, the
               # crack kept by atom types: pdverify.peers.lammps.crack_types)
               "plate-crack": {"spacing": 0.05, "m_ratio": 2.0},
               "plate-edge-crack": {"spacing": 1 / 30, "m_ratio": 2.0},
               "plate-inclined-crack": {"spacing": 0.05, "m_ratio": 2.0},
               # the 3D shapes at their report grids (832 and 983 atoms, 5-8 s of FIRE)
               "cylinder3d-tension": {}, "block3d-cavity": {}}
#: the report's settings where not both: the crack scenes and the 3D shapes same-model
#: only (the
#: difference to none's K is the number; 1,600-4,800 atoms, 700-1,800 FIRE steps, the
#: largest peer runs: 2.8-10 s each under a load of ~14 on 2 cores, all ten runs issue
#: 55 added 31 s of wall and 16 s of CPU there with both settings on the cracks:
#: benchmarks/records/peers-2026-11-28-issue55-lammps-cracks-dynamics-lps.json); as-used
#: runs with ``--set setting=as-used`` (tests/peers/test_lammps.py checks it on a crack)
REPORT_SETTINGS = {scene: ("same-model",) for scene in
                   ("plate-crack", "plate-edge-crack", "plate-inclined-crack",
                    "cylinder3d-tension", "block3d-cavity")}
#: the scenes whose quick report runs the peer at the scene's own quick grid (every other
#: method runs there too): the 3D shapes (their default grids cost LAMMPS 5-8 s)
QUICK_AT_SCENE_GRID = ("cylinder3d-tension", "block3d-cavity")
#: the bond-based scenes that solve through a peer (their own assembly; the static-state
#: family's scenes are served through the family): the clamped sheet's clamps are held
#: atoms (``fix setforce`` on the group of each prescribed component, the atoms set to
#: their prescribed positions first), as LAMMPS users hold a grip
BOND_SCENES = ("sheet2d-tension", "sheet2d-clamped")
#: the stiffness scenes: every atom placed at u = eps . x and LAMMPS's ``compute pe/atom``
#: read as the node's energy density (:meth:`PeerTreatment.peer_energies`): peri/pmb's as
#: it is, peri/lps's corrected with ``compute dilatation/atom``
#: (:func:`pdverify.peers.lammps.lps_energy_density`: it tallies half of the deviatoric
#: energy)
ENERGY_SCENES = ("stiffness2d-sheet", "stiffness3d-box-bond", "stiffness3d-box",
                 "stiffness2d-plate")
#: seed 004's static bars: a line of atoms on the x axis (y and z held at zero) with
#: peri/pmb's c matched to the bar's c1 (pdverify.peers.lammps.bar_types: the triangular
#: micromodulus by type pair), same-model only (:data:`BAR_AS_USED`)
BAR_SCENES = ("bar1d-homogenization", "bar1d-constraints")
#: seed 004's vibrating bar: LAMMPS's fix nve against the scene's central differences
#: (same model only, as the static bars; :meth:`PeerTreatment.peer_dynamic_bar`)
DYNAMIC_BAR_SCENES = ("bar1d-vibration",)
#: why a bar has no as-used run
BAR_AS_USED = ("LAMMPS is a 3D code and its users give peri/pmb the 3D c = 18 K / (pi "
               "delta^4); a line of atoms with it is not seed 004's 1D bar (nothing of the "
               "bar's c1 or cross-section enters), so only the same model runs, c matched "
               "to c1: --set setting=same-model")
#: the bars' setting: the same model only
BAR_SETTING = Param("setting", "same-model", "how LAMMPS runs: driven to solve the bar's "
                    "discrete model (peri/pmb on a line of atoms, c matched to c1 by type "
                    "pair, each point's volume); no as-used run: " + BAR_AS_USED.split(
                        ": --set")[0], choices=("same-model",))
#: the scenes of the bond-based models that LAMMPS cannot run as they are stated, and
#: what it would take
REFUSED = {
    "block2d-indentation": (
        "its sticking contact is not a prescribed-displacement set: the top atoms the "
        "indenter reaches are caught after each equilibrium (the set grows with the depth) "
        "and then move with it, which one LAMMPS deck cannot state (fix indent is a "
        "frictionless penalty wall, another contact law); it would take driving LAMMPS "
        "increment by increment (its Python module: minimize, read the top atoms, hold "
        "the caught ones on the indenter, repeat) with the scene's Newton stopping rule"),
}


def lammps_overrides(scene) -> dict:
    """LAMMPS's influence (1/|xi|) and whole-cell volumes, where the scene has them."""
    names = {q.name for m in scene.all_methods for q in m.params} | {
        q.name for q in scene.params}
    return {k: v for k, v in (("influence", "hyperbolic"), ("quadrature", "full-cells"))
            if k in names}


@dataclass(frozen=True)
class PeerTreatment(Treatment):
    """A peer code as a method: assembles the uncorrected system (for its node set and the
    checks) and solves it with the peer (``peer_solve``)."""

    peer: bool = True
    static_only: str = "the peer code solves the static system in one call"

    def report_runs(self, scene, quick) -> list[dict]:
        over = REPORT_RUNS.get(scene.id)
        if over is None:
            return []
        settings = (("same-model",) if scene.id in BAR_SCENES + DYNAMIC_BAR_SCENES
                    else REPORT_SETTINGS.get(scene.id, lammps.SETTINGS))
        if quick and scene.id in QUICK_AT_SCENE_GRID:
            over = {**over, "spacing": scene.quick_spacing}
        return [{**lammps_overrides(scene), **over, "setting": s} for s in settings]

    def params_for(self, scene):
        """:data:`BAR_SETTING` on seed 004's bars, else its own."""
        return (BAR_SETTING,) if scene.id in BAR_SCENES + DYNAMIC_BAR_SCENES else self.params

    def check_bar(self, params, where):
        """A seed-004 bar: same-model only (:data:`BAR_SETTING`'s one choice); any
        micromodulus (by type pair, :func:`pdverify.peers.lammps.bar_types`)."""
        if params["setting"] != "same-model":     # the Param's choices refuse it first
            raise InputError(f"{where}: setting={params['setting']!r} on a 1D bar: "
                             f"{BAR_AS_USED}")

    def why_not(self, scene):
        if scene.id in BOND_SCENES + ENERGY_SCENES + BAR_SCENES + DYNAMIC_BAR_SCENES:
            return None
        if scene.id in REFUSED:
            return REFUSED[scene.id]
        return super().why_not(scene)

    def check(self, cells, params, where):
        micromodulus = params.get("micromodulus")
        if micromodulus is not None and micromodulus != "constant":
            raise InputError(f"{where}: micromodulus={micromodulus!r}; LAMMPS's peri/pmb "
                             "has a constant micromodulus: run it with "
                             "--set micromodulus=constant")
        influence = params.get("influence")
        if influence is not None and influence != "hyperbolic":
            raise InputError(f"{where}: influence={influence!r}; LAMMPS's peri/lps fixes the "
                             "influence at 1/|xi|: run it with --set influence=hyperbolic")
        if params["setting"] == "same-model" and params.get("quadrature") != "full-cells":
            raise InputError(f"{where}: setting=same-model needs quadrature=full-cells "
                             f"(got {params.get('quadrature')!r}): LAMMPS cannot state "
                             "per-bond volume fractions")

    def assemble(self, problem, params):
        from .plain import assemble_plain
        return assemble_plain(problem)

    # ------------------------------------------------------------------ the run
    @staticmethod
    def finish(outcome, metrics, trouble, where):
        """The run's outcome: the scene's measure of the peer's field (``outcome``) with
        the peer's ``metrics``; a field that is no solution (``trouble``) is a failed run
        that keeps them (NumericalError with the outcome)."""
        outcome.metrics.update(metrics)
        if trouble:
            raise NumericalError(f"{where}: {trouble}", partial=outcome)
        return outcome

    def peer_solve(self, scene, p, problem, system, where):
        """``(x, info, metrics, trouble)``: LAMMPS's field as the system's unknowns, the
        diagnostics, the peer's metrics (module docstring) and why the field is not a
        solution (None when it is)."""
        from .plain import assemble_plain
        from ..nodeset import equilibrium, node_set_of, not_in_equilibrium, solution_vector
        from ..solvers.front import solve as solve_system
        ns = node_set_of(scene, p, problem, system)
        model = lammps.state_based_model(ns)
        setting = p["setting"]
        with tempfile.TemporaryDirectory(prefix="pdverify-lammps-") as folder:
            result = lammps.run(model, setting, folder, where=where)
        x_none, _ = solve_system(system, where=where, ordering=problem.ordering)
        u_none = system.displacements(x_none)
        scale = float(np.linalg.norm(u_none))
        metrics = {"peer_diff_to_none": _rel(result.u, u_none, scale)}
        # the linear model of LAMMPS's setting (its node set and solution), if there is one
        own, u_own = ns, u_none
        if setting == "as-used":
            if not np.allclose(ns.volume, model.uniform_volume, rtol=1e-12, atol=0):
                own = None      # cut cells or half cells: no linear model of LAMMPS's here
            else:
                ramped = assemble_plain(problem, as_used_closure(model))
                x_ramp, _ = solve_system(ramped, where=where, ordering=problem.ordering)
                own, u_own = node_set_of(scene, p, problem, ramped), ramped.displacements(x_ramp)
                metrics["peer_gap_volumes"] = _rel(u_own, u_none, scale)
        info = {"solver": self.name, "peer": result.info}
        if own is not None:
            metrics["peer_gap_nonlinear"] = _rel(result.u, u_own, scale)
            info["equilibrium"] = equilibrium(own, result.u, u_own)
            metrics["equilibrium_residual"] = info["equilibrium"]["residual"]
        return (solution_vector(system, result.u), info, metrics,
                _trouble(result.info, info.get("equilibrium"), not_in_equilibrium))

    def peer_energies(self, scene, p, problem, model, states, where):
        """The stiffness scenes: ``(ratios, info, metrics, trouble)``, W_i / W_bulk per
        strain state (``states``: ``(name, eps)`` each) of LAMMPS's peri/pmb (bond-based
        scenes) or peri/lps (state-based, ``problem`` None; its pe/atom corrected by
        :func:`pdverify.peers.lammps.lps_energy_density`) with every atom at
        u = eps . x (:func:`pdverify.peers.lammps.energies`) on the uncorrected
        ``model``'s atoms. W_bulk is the bulk of the setting's own lattice: pdverify's for
        ``same-model``, LAMMPS's ramped one for ``as-used`` (:func:`lammps_bulk_work_density`;
        ``peer_bulk_ratio`` is it over pdverify's, the ramp's toll on the bulk). The
        metrics compare the energy densities themselves (relative L2 over nodes and
        states): ``peer_diff_to_none`` against pdverify's ``none``, ``peer_gap_volumes``
        (as-used) its linear twin (whole cells, LAMMPS's ramp) against ``none``,
        ``peer_gap_nonlinear`` LAMMPS against its setting's linear model, which must stay
        within :data:`pdverify.nodeset.DISTANCE_PER_GRADIENT` times the field's largest
        relative bond displacement (the equilibrium check's rule; here the strain scale),
        else the run fails naming it."""
        return peer_energies_of(scene, p, problem, model, states, where)

    def peer_solve_bar(self, scene, p, problem, system, where, u_none, centred=False):
        """A seed-004 bar (:class:`~pdverify.pd.problem.BondSystem` of ``problem``) run by
        LAMMPS in the same model (peri/pmb on a line of atoms, c1 by type pair, each
        point's volume; held points as held atoms): ``(u, info, metrics, trouble)`` with
        ``u`` (n,) its displacements, shifted like ``u_none`` (pdverify's, (n,)) to rest
        at the bar's centre when ``centred`` (the free bar under end forces: its rigid
        translation is no part of the answer), and its equilibrium checked in the bar's
        linear model (:func:`pdverify.nodeset.equilibrium`, against ``u_none``)."""
        from ..nodeset import DISTANCE_FLOOR, equilibrium, node_set_of, not_in_equilibrium
        ns = node_set_of(scene, p, problem, system)
        with tempfile.TemporaryDirectory(prefix="pdverify-lammps-") as folder:
            result = lammps.run(lammps.bond_based_model(ns), p["setting"], folder,
                                where=where)
        u = np.asarray(result.u[:, 0], dtype=float)
        if centred:
            n = u.size
            u = u - 0.5 * (u[(n - 1) // 2] + u[n // 2])
        diff = _rel(u, u_none, float(np.linalg.norm(u_none)))
        metrics = {"peer_diff_to_none": diff, "peer_gap_nonlinear": diff}
        balance = equilibrium(ns, u[:, None], np.asarray(u_none)[:, None])
        # a line of atoms is geometrically linear (a collinear bond's stretch is
        # (u_j - u_i) / |xi| exactly while no bond inverts; the bar strains by sigma / E,
        # 1 here, which would make the gradient rule's limit ~10): LAMMPS's equilibrium
        # is the linear one, so the distance is the stopping rule's alone, held to the
        # floor of nodeset.equilibrium (1e-6, FTOL_REL = 1e-9 times the cut systems'
        # condition numbers, below 10 at the report's sizes)
        balance["limit"] = DISTANCE_FLOOR
        balance["in_equilibrium"] = bool(balance["distance"] <= DISTANCE_FLOOR)
        info = {"solver": self.name, "peer": result.info, "equilibrium": balance}
        metrics["equilibrium_residual"] = balance["residual"]
        trouble = _trouble(result.info, None, not_in_equilibrium)
        if trouble is None and not balance["in_equilibrium"]:
            trouble = (f"not in equilibrium: {balance['distance']:.3g} (relative L2) from "
                       f"the bar's linear solution, above {DISTANCE_FLOOR:g} (a collinear "
                       "bar is geometrically linear: only the stopping rule may move it); "
                       f"relative residual {balance['residual']:.3g}")
        return u, info, metrics, trouble

    def peer_dynamic_bar(self, scene, p, problem, system, u0, dt, steps, record,
                         history_none, where):
        """Seed 004's vibrating bar (:class:`~pdverify.pd.problem.BondSystem` of
        ``problem``, its held points held) released from ``u0`` ((n,), at rest) and run
        by LAMMPS in the same model (peri/pmb on a line of atoms, c1 by type pair, each
        point's volume, the scene's density as the atoms' mass density) with ``fix nve``
        for ``steps`` steps of the scene's ``dt``: ``(history, info, metrics, trouble)``,
        ``history`` (steps + 1, len(record)) the displacements of the atoms ``record``,
        compared with pdverify's own run ``history_none`` (relative L2 over the whole
        history). Velocity Verlet's positions are the scene's central differences, and a
        collinear bar is geometrically linear (see :meth:`peer_solve_bar`), so the two
        histories differ by rounding only: LAMMPS carries absolute positions, so each step
        may round a displacement by eps max|x| (machine epsilon of the largest
        coordinate), eps max|x| / max|u0| relative to the motion's amplitude; the run
        fails, naming it, when the distance exceeds that summed over the steps (the
        worst case, every rounding in one direction; 3.2e-10 at Table 13's bar (b),
        1.4e-12 measured)."""
        from ..nodeset import node_set_of
        ns = node_set_of(scene, p, problem, system)
        model = dataclasses.replace(lammps.bond_based_model(ns), density=float(p["density"]))
        n = len(ns.x)
        with tempfile.TemporaryDirectory(prefix="pdverify-lammps-") as folder:
            history, peer = lammps.dynamics(model, np.asarray(u0, float).reshape(n, 1), dt,
                                            steps, record, folder, where=where)
        u = history[:, :, 0]
        diff = _rel(u, history_none, float(np.linalg.norm(history_none)))
        metrics = {"peer_diff_to_none": diff, "peer_gap_nonlinear": diff}
        per_step = float(np.finfo(float).eps * np.max(np.abs(ns.x)) / np.max(np.abs(u0)))
        limit = per_step * steps
        info = {"peer": peer, "peer_check": {"distance": diff, "limit": limit,
                                             "in_agreement": bool(diff <= limit)}}
        trouble = None
        if peer.get("damage_sum"):
            trouble = f"LAMMPS lost bonds (damage summed over the atoms {peer['damage_sum']:.3g})"
        elif not diff <= limit:
            trouble = (f"LAMMPS's history is {diff:.3g} (relative L2) from the bar's own run, "
                       f"above {limit:.3g} (rounding: {per_step:.3g} a step over "
                       f"{steps} steps; a collinear bar is geometrically linear and velocity "
                       "Verlet's positions are central differences)")
        return u, info, metrics, trouble

    def finish_bars(self, outcome, runs, where):
        """The outcome of a scene of several bars (``runs``: name -> the
        :meth:`peer_solve_bar` tuple): the largest of each peer metric over the bars, each
        bar's in the diagnostics, the first bar's trouble."""
        metrics = {}
        for name in ("peer_diff_to_none", "peer_gap_nonlinear", "equilibrium_residual"):
            metrics[name] = max(r[2][name] for r in runs.values())
        for k, (_u, info, m, _t) in runs.items():
            outcome.diagnostics[f"bar_{k}_peer"] = {**info["peer"], **m,
                                                    "equilibrium": info["equilibrium"]}
        trouble = next((f"bar ({k}): {r[3]}" for k, r in runs.items() if r[3]), None)
        return self.finish(outcome, metrics, trouble, where)

    def peer_solve_bonds(self, scene, p, problem, system, where, solve_none):
        """The bond-based sheets (their own assembly: ``scene.bond_problem``):
        ``(x, info, metrics, trouble)`` of LAMMPS's peri/pmb on the node set of the
        sheet's linear ``problem`` and ``system`` (:class:`~pdverify.pd.problem.BondSystem`,
        every grid node real; the deck of :func:`pdverify.peers.lammps.bond_based_model`,
        as ``export --format lammps`` writes it), with ``solve_none()`` pdverify's own
        solve ``(u, reactions, info)``; ``x`` holds LAMMPS's field as the system's
        unknowns. ``same-model`` is checked for equilibrium in the system's model
        (:func:`pdverify.nodeset.equilibrium`, as ``score`` checks it); ``as-used`` in
        the linear model with LAMMPS's weights (:func:`as_used_closure`) where every
        node carries a whole cell (``node_volumes=full`` on the clamped sheet), like the
        state-based scenes; where edge nodes carry half cells (the sheets' default) it
        has no linear twin (LAMMPS's atoms carry one volume each) and is judged by
        LAMMPS's own stopping and bond count."""
        from ..nodeset import equilibrium, node_set_of, not_in_equilibrium, solution_vector
        ns = node_set_of(scene, p, problem, system)
        d, n = ns.dim, len(ns.x)
        setting = p["setting"]
        model = lammps.bond_based_model(ns)
        with tempfile.TemporaryDirectory(prefix="pdverify-lammps-") as folder:
            result = lammps.run(model, setting, folder, where=where)
        u_none = solve_none()[0].reshape(d, n).T
        scale = float(np.linalg.norm(u_none))
        metrics = {"peer_diff_to_none": _rel(result.u, u_none, scale)}
        info = {"solver": self.name, "peer": result.info}
        own, u_own = (ns, u_none) if setting == "same-model" else (None, None)
        twin = _as_used_twin(problem, model) if setting == "as-used" else None
        if twin is not None:
            u_twin = scene.solve_fixed(twin.model, twin.fixed, twin.values, where, twin.rhs,
                                       solver=p["solver"])[0]
            own, u_own = node_set_of(scene, p, problem, twin), u_twin.reshape(d, n).T
            metrics["peer_gap_volumes"] = _rel(u_own, u_none, scale)
        if own is not None:
            metrics["peer_gap_nonlinear"] = _rel(result.u, u_own, scale)
            info["equilibrium"] = equilibrium(own, result.u, u_own)
            metrics["equilibrium_residual"] = info["equilibrium"]["residual"]
        return (solution_vector(system, result.u), info, metrics,
                _trouble(result.info, info.get("equilibrium"), not_in_equilibrium))


def peer_energies_of(scene, p, problem, model_none, states, where):
    """The stiffness scenes through LAMMPS (:meth:`PeerTreatment.peer_energies`): the
    bond-based ones through peri/pmb, the state-based ones (``problem`` None,
    ``model_none`` a :class:`~pdverify.pd.statebased.StateBasedModel`) through peri/lps,
    whose energy is read as :func:`pdverify.peers.lammps.lps_energy_density`."""
    from ..nodeset import DISTANCE_FLOOR, DISTANCE_PER_GRADIENT
    from ..pd.work import work_density
    g, d = model_none.grid, model_none.dim
    ids = g.interior_ids
    h, m = model_none.spacing, model_none.m_ratio
    state = problem is None
    lm = energy_model(model_none)
    strains = [eps for _, eps in states]
    setting = p["setting"]
    with tempfile.TemporaryDirectory(prefix="pdverify-lammps-") as folder:
        W, peer = lammps.energies(lm, setting, strains, folder, where=where)
    W_none = np.stack([work_density(model_none, eps)[ids] for eps in strains])
    scale = float(np.linalg.norm(W_none))
    metrics = {"peer_diff_to_none": _rel(W, W_none, scale)}
    if setting == "same-model":
        bulk = [model_none.bulk_work_density(eps) for eps in strains]
        W_own = W_none
    else:
        if state:
            bulk = [lammps_lps_bulk_work_density(model_none, lm.uniform_volume, eps)
                    for eps in strains]
            twin = _as_used_state_twin(scene, p, lm)
        else:
            bulk = [lammps_bulk_work_density(model_none.c, h, m, d, lm.uniform_volume, eps)
                    for eps in strains]
            twin = _as_used_twin(problem, lm)
            twin = None if twin is None else twin.model
        W_own = (None if twin is None else
                 np.stack([work_density(twin, eps)[twin.grid.interior_ids]
                           for eps in strains]))
        if W_own is not None:
            metrics["peer_gap_volumes"] = _rel(W_own, W_none, scale)
        metrics["peer_bulk_ratio"] = float(np.mean(
            [b / model_none.bulk_work_density(eps) for b, eps in zip(bulk, strains)]))
    ratios = {name: W[s] / bulk[s] for s, (name, _) in enumerate(states)}
    info = {"solver": lammps.NAME, "peer": peer}
    trouble = None
    if peer["damage_sum"]:
        trouble = f"LAMMPS lost bonds (damage summed over the atoms {peer['damage_sum']:.3g})"
    if W_own is not None:
        # the homogeneous field's largest relative bond displacement |u_b - u_a| / |xi|
        # is STRAIN_SCALE times the largest |eps n|, the largest singular value of a state
        gradient = lammps.STRAIN_SCALE * max(np.linalg.norm(e, 2) for e in strains)
        limit = max(DISTANCE_PER_GRADIENT * gradient, DISTANCE_FLOOR)
        gap = _rel(W, W_own, float(np.linalg.norm(W_own)))
        metrics["peer_gap_nonlinear"] = gap
        info["energy_check"] = {"distance": gap, "max_gradient": gradient, "limit": limit,
                                "in_agreement": bool(gap <= limit)}
        if trouble is None and not gap <= limit:
            trouble = (f"LAMMPS's energy densities are {gap:.3g} (relative L2) from its "
                       f"setting's linear model, above {limit:.3g} ({DISTANCE_PER_GRADIENT:g}"
                       " x the largest relative bond displacement)")
    return ratios, info, metrics, trouble


def energy_model(model_none) -> lammps.Model:
    """The atoms of a stiffness scene's uncorrected model (its real nodes, their volumes,
    its bonds by the horizon between two lattice shells): peri/lps with
    :func:`pdverify.peers.lammps.lps_moduli` for a state-based model, peri/pmb with its c
    for a bond-based one; no loads, nothing held."""
    from ..nodeset import between_shells
    g, d = model_none.grid, model_none.dim
    ids = g.interior_ids
    h = model_none.spacing
    state = hasattr(model_none, "constants")
    off = np.asarray(model_none.stencil.offsets if state else model_none.offsets)
    if state:
        K, G = lammps.lps_moduli(model_none.constants)
        pair, coefficients, stiffness = "peri/lps", (K, G), K + 4 * G / 3
    else:
        pair, coefficients = "peri/pmb", (model_none.c,)
        stiffness = model_none.c * model_none.horizon ** (d + 1)
    return lammps.Model(g.x[ids], np.asarray(model_none.node_volume)[ids],
                        np.zeros((len(ids), d)), {}, h, model_none.m_ratio,
                        between_shells(h, np.r_[off, -off], d),
                        h ** d * model_none.thickness, pair, coefficients, stiffness)


def _as_used_state_twin(scene, p, model):
    """The state-based linear model of LAMMPS's as-used run (None where there is none):
    the stiffness box built by the scene under :func:`as_used_closure` (LAMMPS's ramp,
    whole cells), when every node's volume is LAMMPS's one volume per atom (the
    cell-centred boxes: always)."""
    twin = scene.build("none", p, as_used_closure(model))
    volume = np.asarray(twin.node_volume)[twin.grid.interior_ids]
    if len(volume) != len(model.x) or not np.allclose(volume, model.uniform_volume,
                                                      rtol=1e-12, atol=0):
        return None
    return twin


def lammps_lps_bulk_work_density(model, volume, strain) -> float:
    """W of an atom with a complete neighbourhood in LAMMPS's as-used lattice under the
    homogeneous ``strain`` for the linear LPS ``model``'s constants and influence: its
    bulk form (:meth:`pdverify.pd.statebased.StateBasedModel.bulk_work_density`) with
    LAMMPS's weights, ramp(|xi|) V on the lattice offsets within (m + 2e-4) h, in m,
    theta and the forces alike."""
    from ..pd.bonds import homogeneous_extensions
    h, d = model.spacing, model.dim
    k, r = _lattice_within(h, model.m_ratio, d)
    n = k * h / r[:, None]
    e = homogeneous_extensions(r, n, np.asarray(strain, dtype=float))
    horizon = (model.m_ratio + lammps.EXAMPLES_MARGIN) * h
    c = model.constants
    w = model.influence.omega(r, model.horizon) * ramp(r, h, horizon) * volume
    m = float(np.sum(w * r * r))
    theta = c.c_theta * np.sum(w * r * e) / m
    return float(0.5 * (c.k_theta * theta ** 2 / c.c_theta + c.k_e * np.sum(w * e * e) / m))


def _lattice_within(spacing, m_ratio, dim):
    """The lattice offsets k (in spacings) within LAMMPS's as-used horizon and their
    lengths |k| h."""
    horizon = (m_ratio + lammps.EXAMPLES_MARGIN) * spacing
    reach = int(np.floor(m_ratio + lammps.EXAMPLES_MARGIN))
    axes = np.arange(-reach, reach + 1)
    k = np.stack(np.meshgrid(*([axes] * dim), indexing="ij"), axis=-1).reshape(-1, dim)
    r = np.linalg.norm(k, axis=1) * spacing
    keep = (r > 0) & (r <= horizon)
    return k[keep], r[keep]


def _as_used_twin(problem, model):
    """The bond-based linear model of LAMMPS's as-used run (None where there is none):
    ``problem``'s body with a whole cell on every node (LAMMPS's one volume per atom; the
    loads are nodal forces, which do not depend on the volumes) under
    :func:`as_used_closure`; its system, when every node's volume is then LAMMPS's."""
    import dataclasses
    from ..pd.problem import assemble_bonds
    body = problem.body
    if getattr(body, "shape", None) is not None:
        return None
    whole = dataclasses.replace(problem, body=dataclasses.replace(body, boundary_volume="full"))
    twin = assemble_bonds(whole, as_used_closure(model))
    g = twin.model.grid
    volume = np.asarray(twin.model.node_volume)[g.interior_ids]
    if len(volume) != len(model.x) or not np.allclose(volume, model.uniform_volume,
                                                      rtol=1e-12, atol=0):
        return None
    return twin


def lammps_bulk_work_density(c, spacing, m_ratio, dim, volume, strain) -> float:
    """W of an atom with a complete neighbourhood in LAMMPS's as-used lattice under the
    homogeneous ``strain``: 1/4 sum_k c ramp(|xi|) V (n.strain.n)^2 |xi| over the lattice
    offsets k within its horizon (m + 2e-4) h, every atom's volume ``volume``
    (pdverify.pd.bondbased.BondBasedModel.bulk_work_density's form, LAMMPS's weights)."""
    horizon = (m_ratio + lammps.EXAMPLES_MARGIN) * spacing
    reach = int(np.floor(m_ratio + lammps.EXAMPLES_MARGIN))
    axes = np.arange(-reach, reach + 1)
    k = np.stack(np.meshgrid(*([axes] * dim), indexing="ij"), axis=-1).reshape(-1, dim)
    r = np.linalg.norm(k, axis=1) * spacing
    k, r = k[(r > 0) & (r <= horizon)], r[(r > 0) & (r <= horizon)]
    n = k * spacing / r[:, None]
    e_over_r = np.einsum("bi,ij,bj->b", n, np.asarray(strain, dtype=float), n)
    return float(0.25 * np.sum(c * ramp(r, spacing, horizon) * volume * e_over_r ** 2 * r))


def _trouble(peer: dict, balance: dict | None, not_in_equilibrium) -> str | None:
    """Why a peer's field is not a solution (None: it is); the residual is named where
    one was computed."""
    residual = ("" if balance is None else
                f"; {balance['distance']:.3g} (relative L2) from the linear solution, "
                f"relative residual {balance['residual']:.3g}")
    lost = peer.get("damage_sum", 0.0)
    if lost:
        return f"LAMMPS lost bonds (damage summed over the atoms {lost:.3g}){residual}"
    if peer.get("stopping") != "force tolerance":
        return (f"LAMMPS's minimiser stopped on {peer.get('stopping')!r}, force norm "
                f"{peer.get('fnorm_final', float('nan')):.3g} of "
                f"{peer.get('fnorm_initial', float('nan')):.3g}{residual}")
    if balance is not None and not balance["in_equilibrium"]:
        return not_in_equilibrium(balance)
    return None


def peer_treatments() -> list[Treatment]:
    return [PeerTreatment(
        lammps.NAME, "LAMMPS's PERI package (peri/lps, peri/pmb) run on the scene's "
        "uncorrected node set and scored like pdverify's own runs: as its users run it, "
        "or driven to solve pdverify's discrete model", "LAMMPS (Thompson et al., CPC 271 "
        "(2022) 108171), PERI package (Parks, Lehoucq, Plimpton, Silling 2008)",
        params=(SETTING,), theories=("state-based", "bond-based"), dims=(1, 2, 3),
        families=("static-state",), shapes=True, shapes3d=True, unavailable=lammps.unavailable(),
        scope="the static state-based scenes' uncorrected node sets (influence=hyperbolic) "
              f"and {', '.join(BOND_SCENES + ENERGY_SCENES + BAR_SCENES + DYNAMIC_BAR_SCENES)} "
              "(bond-based: micromodulus=constant)")]
