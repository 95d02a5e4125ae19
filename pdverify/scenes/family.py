"""The ``static-state`` family: scenes that describe a static state-based problem and let
every treatment of the family assemble it (``pdverify.corrections.assembly``).

A scene of the family states its body, material, boundary conditions (keyed by face and
component), loads and reference once in :meth:`StaticStateScene.problem`, and measures a
solution in :meth:`StaticStateScene.measure`; it never names a method outside its
``cases`` and published numbers. Which treatments run on it, with which parameters, and
why a treatment does not, comes from the registry (``list`` shows it).
"""
from __future__ import annotations

import math

from .. import budget
from ..errors import InputError
from ..solvers.front import solve as solve_system
from .base import MethodSpec, Outcome, Scene, whole_cells
from .fem_references import FEM, FemAndPD, FemReference


class StaticStateScene(Scene):
    """Base of the family. Subclasses set ``id`` etc. and implement :meth:`box`,
    :meth:`problem` and :meth:`measure` (and may refine :meth:`check`/:meth:`estimate`)."""

    family = "static-state"
    theory = "state-based"
    methods = ()
    #: the linear solver of a scene that declares no ``solver`` parameter (its
    #: :meth:`problem` states it); one that declares it reads the run's value
    fixed_solver = "direct"

    # ----------------------------------------------------------------- description
    def box(self, p):
        """``(lengths, origin)`` of the body."""
        raise NotImplementedError

    def problem(self, p, where: str):
        """The :class:`~pdverify.pd.problem.StaticProblem` of the params ``p``."""
        raise NotImplementedError

    def measure(self, p, problem, system, x, info) -> Outcome:
        """Metrics, fields and size of a solved system."""
        raise NotImplementedError

    #: True for a scene whose body is not a box (``problem(...).shape``)
    has_shape = False

    def family_refusal(self, treatment) -> str | None:
        if self.has_shape and not getattr(treatment, "shapes", False):
            return (f"box faces only: {treatment.box_only}" if treatment.box_only else
                    "box faces only (the treatment does not declare shapes)")
        if self.has_shape and self.dim == 3 and not getattr(treatment, "shapes3d", False):
            why = getattr(treatment, "shapes3d_why", "")
            return (f"on a 3D shape: {why}" if why else
                    "2D shapes only (the treatment does not declare 3D shapes)")
        if treatment.whole_faces_only and not self._whole_faces():
            return (f"{treatment.scope or 'whole-face conditions only'}; this scene "
                    "prescribes a component on part of a face")
        return None

    def default_params(self) -> dict:
        """The defaults of every parameter the description reads."""
        return {q.name: q.default for q in self.params}

    def _whole_faces(self) -> bool:
        """Whether the scene's conditions cover whole faces (a property of the scene,
        not of its params: computed once, from the defaults)."""
        cached = self.__dict__.get("_whole_faces_cache")
        if cached is None:
            p = self.default_params()
            cached = self.__dict__["_whole_faces_cache"] = self.problem(p, self.id).whole_faces()
        return cached

    # ----------------------------------------------------------------- checks
    def check(self, method, p):
        from ..corrections.registry import plugin_call
        where = f"{self.id} --method {method}"
        lengths, _ = self.box(p)
        h = p["spacing"]
        cells = whole_cells(where, h, [(f"l_{name}", L) for name, L in zip("xyz", lengths)])
        if p["m_ratio"] > max(cells):
            # a horizon past the whole body (and a stencil of ~m^d offsets to build)
            raise InputError(f"{where}: m_ratio={p['m_ratio']:g} gives a horizon of "
                             f"{p['m_ratio'] * h:g} m, longer than the body "
                             f"({max(lengths):g} m); allowed: m_ratio <= {max(cells)}")
        t = self.treatment(method)
        plugin_call(t, "check", t.check, tuple(cells), p, where)

    def estimate(self, method, p):
        """Unknowns on the cell-centred nodes, and what the treatment adds (a fictitious
        layer m deep folds into the unknowns through its stored extrapolation rows;
        surface nodes are unknowns); the dilatation couples nodes 2m spacings apart (m
        in the augmented system of the nested-dissection solve)."""
        from ..corrections.assembly import footprint
        from ..solvers.policy import static_solver
        lengths, _ = self.box(p)
        m, d = p["m_ratio"], len(lengths)
        cells = [L / p["spacing"] for L in lengths]
        extra, fictitious = footprint(self.treatment(method).footprint, cells, m)
        nodes = math.prod(cells) + extra
        rows = budget.BYTES_PER_NONZERO * fictitious * d * d * budget.lattice_neighbours(d, m)
        solver = static_solver(self.declared(p, "solver") or self.fixed_solver, d, d * nodes)
        t = self.treatment(method)
        if d == 3 and solver == "cg" and (t.baseline or t.kind == "closure"):
            # the uncorrected LPS system and the bond methods' (LPS with bond factors):
            # symmetric, so CG solves it (the augmented matrix and the condensed operator's
            # copy of it, no factor; 0.9 GB measured at h = 1/30 against 1.6 GB estimated).
            # Not a bound for the energy method, whose K is not symmetric: the front door
            # falls back to nested dissection (2.0 GB measured at h = 1/30 on none's system;
            # record refine3d-2026-11-28-levels-0.05-to-1-36)
            return budget.iterative_system(nodes, d, d + 1, m, extra_bytes=rows)
        # cg for the others: the front door falls back to nested dissection where CG does
        # not apply (a system that is not symmetric), so that solve's memory bounds it
        if d == 3 and solver in ("nested-dissection", "cg"):
            return budget.nested_dissection_3d(nodes, d + 1, m, extra_bytes=rows)
        if d == 2 and solver == "nested-dissection":
            return budget.nested_dissection_2d(nodes, d + 1, m, extra_bytes=rows)
        return budget.linear_system(nodes, d, d, 2 * m, dense_allowed=True, extra_bytes=rows)

    # ----------------------------------------------------------------- solve
    def solve(self, method, p, timer):
        return self.solve_problem(method, p, timer, self.problem)

    def solve_problem(self, method, p, timer, describe):
        """Assemble ``describe(p, where)`` by the treatment ``method``, solve and
        measure it."""
        from ..corrections.registry import plugin_call
        where = f"{self.id}/{method}"
        with timer.phase("setup"):
            problem = describe(p, where)
            t = self.treatment(method)
            system = plugin_call(t, "assemble", t.assemble, problem, p)
        peer = getattr(t, "peer_solve", None)
        if peer is not None:     # another code solves it (pdverify.peers): scored as ours
            with timer.phase("solve"):
                x, info, metrics, trouble = peer(self, p, problem, system, where)
            return t.finish(self.measure(p, problem, system, x, info), metrics, trouble, where)
        with timer.phase("solve"):
            x, info = solve_system(system, where=where, ordering=problem.ordering)
            if self.declared(p, "solver") != "auto":     # only the user's auto says what
                info.pop("solver_choice", None)          # it chose
        out = self.measure(p, problem, system, x, info)
        for key in ("matrix_nnz", "static_solver"):      # the front door's, for sizes
            out.diagnostics.pop(key, None)
        return out

    @staticmethod
    def size(system) -> dict:
        """Node, unknown and bond counts of a system, and the treatment's own counts."""
        g = system.model.grid
        out = {"interior_nodes": int(g.n_interior), "bonds": int(system.model.bond_a.size),
               "dofs": int(system.dofs)}
        out.update(system.counts)
        return out

    @staticmethod
    def real_nodes(system):
        g = system.model.grid
        return g.x[g.interior_ids]

    @staticmethod
    def solution(system, x):
        """``(u of the real nodes, u of the extra nodes or None)``."""
        U = system.displacements(x)
        ni = system.model.grid.n_interior
        return U[:ni], (U[ni:] if system.extra_x is not None else None)


class FemStaticStateScene(StaticStateScene, FemAndPD):
    """A scene of the ``static-state`` family whose reference is a converged FEM solution
    (``reference_fem``), run as the scene's own method ``fem``.

    What a subclass states: the reference (``params_class``, ``function``; the FEM
    dataclass's fields named in ``shared`` are the scene's physical parameters, its
    other fields the ``fem`` method's), the PD discretisation's parameters
    (``pd_params``: every treatment takes them; a FEM study has its own ``spacing``),
    ``baseline_params`` (parameters of how the uncorrected baseline and the closure
    treatments impose the conditions, which they take beside ``pd_params``), and as
    every family scene :meth:`box`, :meth:`problem` (its ``exact``: the FEM field, from
    :meth:`reference_of`) and :meth:`measure`. The treatments, their parameters and why
    one does not run come from the registry, as for the other family scenes.
    """

    reference = "fem"
    methods = property(FemAndPD.methods.fget)
    pd_params: tuple = ()
    baseline_params: tuple = ()

    def default_params(self) -> dict:
        return {q.name: q.default
                for q in self.params + self.pd_params + self.baseline_params}

    @property
    def all_methods(self) -> tuple[MethodSpec, ...]:
        own = tuple(self.methods)
        offered = self.offered()
        out = []
        for m in Scene.all_methods.fget(self)[len(own):]:
            t = offered[m.name]
            extra = self.baseline_params if (t.kind == "closure" or t.baseline) else ()
            out.append(MethodSpec(m.name, self.pd_params + extra + m.params))
        return own + tuple(out)

    def check(self, method, p):
        if method == FEM.name:
            return FemReference.check(self, method, p)
        self.check_pd(f"{self.id} --method {method}", method, p)
        StaticStateScene.check(self, method, p)

    def check_pd(self, where, method, p):
        """Checks of the physical parameters a PD run reads (the FEM study checks its
        own through its dataclass)."""

    def estimate(self, method, p):
        if method == FEM.name:
            return FemReference.estimate(self, method, p)
        # the FEM reference (at the fem method's defaults) runs first unless cached
        fem = FemReference.estimate(self, FEM.name, self.reference_params(p))
        return budget.larger(StaticStateScene.estimate(self, method, p), fem)

    def reference_of(self, p):
        """The converged FEM reference of the params ``p`` (from the disk cache after its
        first computation; the last one is kept in memory, as a run reads it twice)."""
        key = tuple(sorted(self.reference_params(p).items()))
        memo = self.__dict__.get("_reference_memo")
        if memo is None or memo[0] != key:
            memo = self.__dict__["_reference_memo"] = (key, self.fem_reference(p))
        return memo[1]

    def fem_outcome(self, p, system, info, metrics, err, x_int, u, u_ref, lengths) -> Outcome:
        """A PD run's :class:`Outcome` against the FEM reference: the reference's last
        field change beside ``metrics``, the fields of the error maps, the size with K's
        non-zeros, and the constraint rows (if any) in the diagnostics."""
        ref = self.reference_of(p)
        metrics["reference_change_pct"] = float(ref.refinement[-1].extra["field_change_pct"])
        fields = {"x": x_int, "u": u, "u_ref": u_ref, "error": err, "spacing": p["spacing"],
                  "horizon": system.model.horizon, "lengths": lengths}
        size = self.size(system)
        size["stiffness_nnz"] = info.pop("matrix_nnz", int(system.K.nnz))
        info.pop("static_solver", None)
        if system.B is not None:
            info["constraints"] = int(system.B.shape[0])
        return Outcome(metrics=metrics, size=size, fields=fields, diagnostics=info)

    def solve(self, method, p, timer):
        if method == FEM.name:
            return FemReference.solve(self, method, p, timer)
        with timer.phase("reference"):
            self.reference_of(p)
        return self.solve_problem(method, p, timer, self.problem)
