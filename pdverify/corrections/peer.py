"""``peer:lammps`` as a treatment of the ``static-state`` family and of the bond-based
sheets: the scene's uncorrected problem solved by LAMMPS (:mod:`pdverify.peers.lammps`)
instead of pdverify's linear solve, and measured by the scene's own ``measure``.

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
"""
from __future__ import annotations

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


def _rel(a, b, scale) -> float:
    return float(np.linalg.norm(a - b) / scale) if scale > 0 else float(np.linalg.norm(a - b))


#: the report's peer runs: scene -> overrides (each run in both settings, with LAMMPS's
#: influence and whole-cell volumes where the scene has those parameters); sizes kept
#: small so that the runs add seconds to a full report (~1 s for the 3D box at h = 0.1:
#: record peers-2026-11-28-report-runs)
REPORT_RUNS = {"body3d-traction": {"spacing": 0.1}, "plate2d-clamped": {},
               "plate2d-plane-strain": {}, "bar1d-traction": {}, "sheet2d-tension": {"spacing": 0.0025}}
#: the bond-based scenes that solve through a peer (their own assembly; the static-state
#: family's scenes are served through the family)
BOND_SCENES = ("sheet2d-tension",)


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
        return [{**lammps_overrides(scene), **over, "setting": s} for s in lammps.SETTINGS]

    def why_not(self, scene):
        if scene.id in BOND_SCENES:
            return None
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
        from ..pd.closure import Closure
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
                horizon = (model.m_ratio + lammps.EXAMPLES_MARGIN) * model.spacing

                def lammps_weights(m):
                    """LAMMPS's weight of each bond (its ramp, whole cells within its
                    horizon, none beyond) in place of the scene's quadrature's beta."""
                    keep = m.bond_x <= horizon
                    return np.where(keep, ramp(m.bond_x, model.spacing, horizon)
                                    / np.where(keep, m.bond_beta, 1.0), 0.0)
                ramped = assemble_plain(problem, Closure(weight_factor=lammps_weights))
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

    def peer_solve_bonds(self, scene, p, problem, system, where, solve_none):
        """The bond-based sheets (their own assembly: ``scene.bond_problem``):
        ``(x, info, metrics, trouble)`` of LAMMPS's peri/pmb on the node set of the
        sheet's linear ``problem`` and ``system`` (:class:`~pdverify.pd.problem.BondSystem`,
        every grid node real; the deck of :func:`pdverify.peers.lammps.bond_based_model`,
        as ``export --format lammps`` writes it), with ``solve_none()`` pdverify's own
        solve ``(u, reactions, info)``; ``x`` holds LAMMPS's field as the system's
        unknowns. ``same-model`` is checked for equilibrium in the system's model
        (:func:`pdverify.nodeset.equilibrium`, as ``score`` checks it); ``as-used`` has no
        linear twin here (the sheet's edge nodes carry half cells, LAMMPS's atoms one
        volume each) and is judged by LAMMPS's own stopping and bond count."""
        from ..nodeset import equilibrium, node_set_of, not_in_equilibrium, solution_vector
        ns = node_set_of(scene, p, problem, system)
        d, n = ns.dim, len(ns.x)
        setting = p["setting"]
        with tempfile.TemporaryDirectory(prefix="pdverify-lammps-") as folder:
            result = lammps.run(lammps.bond_based_model(ns), setting, folder, where=where)
        u_none = solve_none()[0].reshape(d, n).T
        scale = float(np.linalg.norm(u_none))
        metrics = {"peer_diff_to_none": _rel(result.u, u_none, scale)}
        info = {"solver": self.name, "peer": result.info}
        if setting == "same-model":
            metrics["peer_gap_nonlinear"] = metrics["peer_diff_to_none"]
            info["equilibrium"] = equilibrium(ns, result.u, u_none)
            metrics["equilibrium_residual"] = info["equilibrium"]["residual"]
        return (solution_vector(system, result.u), info, metrics,
                _trouble(result.info, info.get("equilibrium"), not_in_equilibrium))


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
        families=("static-state",), shapes=True, unavailable=lammps.unavailable(),
        scope="the static state-based scenes' uncorrected node sets (influence=hyperbolic) "
              f"and the bond-based {', '.join(BOND_SCENES)} (micromodulus=constant)")]
