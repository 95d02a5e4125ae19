"""The bond-based static scenes: a description each (:class:`~pdverify.pd.problem.BondProblem`:
body, stencil, material, conditions keyed by named parts) that the generic assembly
(:func:`~pdverify.pd.problem.assemble_bonds`) turns into a system under the run's
treatment, the twin of the ``static-state`` family (:mod:`pdverify.scenes.family`).

A bond method (a closure of the registry) assembles here exactly as it does on the
state-based boxes: the same ``make_closure`` on the description's grid; a treatment with
a role in the description's ``family`` brings its own grid and clamp nodes
(``clamped-sheet``). The seed-003 sheets (:mod:`pdverify.scenes.sheets`) and the
indentation's model (:mod:`pdverify.scenes.indentation`) are built on it; the bond-based
stiffness boxes describe their body the same way (:mod:`pdverify.scenes.stiffness`).
"""
from __future__ import annotations

import numpy as np

from ..errors import InputError
from ..params import Param
from ..pd import bond_micromodulus, build_stencil
from ..pd.problem import BondProblem, BondSystem, Face, assemble_bonds
from ..solvers.front import solve_with_dirichlet
from ..solvers.iterative import Lattice
from ..solvers.policy import AUTO_ITERATIVE_UNKNOWNS, SPD_LATTICE_SOLVERS
from .base import Outcome, whole_cells
from .fem_references import FemAndPD

#: the family of the treatments that impose a bond-based box's conditions at its surface
BOND_BOX = "bond-box"
#: the family of the treatments that add a rigid buffer beyond a held face (virtual nodes)
HELD_FACE = "held-face"

MICROMODULI = ("constant", "conical")
#: seed 003's node volumes (ERRATA) and the horizon quadrature that reproduces Tables 1-2
PD_COMMON = (
    Param("micromodulus", "constant", "c(xi): constant (the paper's) or conical (Le and Bobaru)",
          choices=MICROMODULI),
    Param("quadrature", "full-cells", "horizon quadrature: whole cells of the nodes with "
          "|xi| <= delta (reproduces Tables 1 and 2; Peridigm's default) or the exact cell "
          "fractions inside the horizon", choices=("full-cells", "partial-volume")),
    Param("solver", "auto", "linear solver: direct (sparse LU), cg (conjugate gradients, "
          "two-level smoothed aggregation one horizon wide) or auto (cg from "
          f"{AUTO_ITERATIVE_UNKNOWNS} free unknowns)", choices=SPD_LATTICE_SOLVERS),
)
PAPER = {"micromodulus": "constant", "quadrature": "full-cells"}


def check_horizon_grid(where, lengths, spacing, horizon, label):
    """Whole cells along every named length, and m = horizon / spacing >= 2."""
    whole_cells(where, spacing, lengths, label)
    m = horizon / spacing
    if m < 2 - 1e-12:
        raise InputError(f"{where}: horizon / spacing = {m:g} must be >= 2 (m = delta / Delta; "
                         "the paper uses 5 and 6)")


class BondStaticScene(FemAndPD):
    """A bond-based 2D scene with a FEM reference (method ``fem``) whose PD runs are a
    description (:meth:`bond_problem`, naming no method), the generic assembly under the
    run's treatment (:meth:`bond_system`), a linear solve and :meth:`measure`; ``pdverify
    score`` measures another code's field on the ``none`` system the same way
    (:mod:`pdverify.exchange`)."""

    closure_theory = "bond-based"
    dim = 2

    def bond_problem(self, p, where) -> BondProblem:
        """The PD problem at ``p``: body, stencil, material, conditions by named part."""
        raise NotImplementedError

    def bond_system(self, method, p, where) -> tuple[BondProblem, BondSystem]:
        """The description at ``p`` and its linear system under the treatment
        ``method``: a treatment with a role in the description's family brings its grid,
        closure and the nodes of the faces it clamps (``clamped-sheet``: ``(grid,
        closure, low, high)`` of the description's
        :class:`~pdverify.pd.problem.ClampedBox`); any other its bond closure (the
        uncorrected one for the baseline and a peer)."""
        problem = self.bond_problem(p, where)
        t = self.offered().get(method)
        if (problem.surface is not None and t is not None
                and t.role(problem.family) is None and t.role(BOND_BOX) is not None):
            # conditions at the surface: the treatment's own grid, unknowns and rows
            return problem, t.build_for(BOND_BOX, problem, p)
        if problem.family is not None and t is not None and t.role(problem.family):
            box = problem.clamped_box()
            grid, closure, low, high = t.build_for(problem.family, box, p)
            own = (grid, closure, {Face.at(box.axis, 0).name: low, Face.at(box.axis, 1).name: high})
            return problem, assemble_bonds(problem, own=own)
        return problem, assemble_bonds(problem, self.bond_closure(method, p))

    def solve_pd(self, method, p, timer):
        where = f"{self.id}/{method}"
        with timer.phase("setup"):
            problem, system = self.bond_system(method, p, where)

        def solve_none():
            return self.solve_fixed(system.model, system.fixed, system.values, where,
                                    system.rhs, solver=p["solver"])
        t = self.offered().get(method)
        peer = getattr(t, "peer_solve_bonds", None)
        with timer.phase("solve"):
            if hasattr(system, "solve"):   # a bond-box system: its own bordered solve
                u, info = system.solve(where)
            elif peer is not None:       # another code solves it (pdverify.peers)
                u, info, peer_metrics, trouble = peer(self, p, problem, system, where,
                                                      solve_none)
            else:
                u, _, info = solve_none()
        outcome = self.measure_run(p, problem, system, u, info, timer)
        return outcome if peer is None else t.finish(outcome, peer_metrics, trouble, where)

    def measure_run(self, p, problem, system, x, info, timer) -> Outcome:
        """:meth:`measure` in a run (a scene times its reference's load here)."""
        return self.measure(p, problem, system, x, info)

    def measure(self, p, problem, system, x, info) -> Outcome:
        """Metrics, fields and size of the displacements ``x`` (the system's unknowns,
        component-major over the model's grid) with the solver's ``info``."""
        raise NotImplementedError

    # ----------------------------------------------------------------- PD helpers
    @staticmethod
    def stencil(p, m_ratio):
        return build_stencil(2, m_ratio, quadrature=p["quadrature"])

    @staticmethod
    def micromodulus(p, horizon):
        """c of a complete continuous horizon, plane stress (ERRATA seed 003)."""
        return bond_micromodulus(p["micromodulus"], 2, p["E"], horizon, plane="stress")

    @staticmethod
    def solve_fixed(model, fixed, values, where, f=None, solver="direct"):
        """K u = f with the given DOFs prescribed; returns (u, reactions K u - f, info).

        ``solver``: see :func:`~pdverify.solvers.front.solve_with_dirichlet`; CG's
        aggregates are one horizon (m nodes) wide."""
        K = model.K
        rhs = np.zeros(K.shape[0]) if f is None else f
        order = np.argsort(fixed)
        g = model.grid
        u, info = solve_with_dirichlet(  # bond-based K with Dirichlet rows removed: SPD
            K, rhs, fixed[order], values[order], where=where, spd=True, solver=solver,
            lattice=Lattice.component_major(g.index, g.x, g.dim),
            aggregate_width=int(round(model.m_ratio)))
        return u, K @ u - rhs, info
