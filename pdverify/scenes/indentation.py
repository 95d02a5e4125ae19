"""Seed 003 §4.2: a rigid cylinder indenting a block, sticking contact; FEM and
geometrically nonlinear bond-based PD with and without the directional correction."""
from __future__ import annotations

import time

import numpy as np

from .. import budget
from ..errors import InputError, NumericalError
from ..params import Param, at_least, horizon_param, open_interval, spacing_param
from ..pd import get_influence
from ..pd.build import Body, BondMaterial
from ..pd.influence import bond_based_nu
from ..pd.nonlinear import LinearBondBased, NonlinearBondBased
from ..pd.problem import BondProblem, PartCondition, assemble_bonds
from ..solvers.iterative import Lattice
from ..solvers.newton import NEWTON_RTOL, DirichletLinearSolver, newton
from ..solvers.policy import NEWTON_CG_FROM_UNKNOWNS, SPD_LATTICE_SOLVERS, newton_solver
from ..quotes import Quote as Q
from . import Outcome, Published, register
from .base import ExpectedFailure
from .bondfamily import HELD_FACE, PAPER, PD_COMMON, BondStaticScene, check_horizon_grid
from .fem_references import FEM, reference_module

#: Output depths left out of the force comparison: the first one (0.1 mm), where the
#: sticking law catches a whole chord in one increment and the reference itself depends on
#: the stepping by ~25 % (reference_fem.indentation, module docstring).
SKIP_OUTPUT_STEPS = 1
#: A free surface node is caught when it lies this fraction of R inside the indenter (the
#: FEM reference's rule).
CATCH_TOLERANCE = 1e-9
#: the smallest first output depth as a fraction of R: 1000 x CATCH_TOLERANCE
MIN_OUTPUT_DEPTH = 1e-6
KINEMATICS = ("nonlinear", "linear")
#: ``half``: the PD model of the half block x >= 0 with mirrored neighbours (exact for the
#: symmetric solution, :mod:`pdverify.pd.nonlinear`); ``full``: the whole block
SYMMETRY = ("half", "full")
#: The paper's runs: its micromodulus and quadrature (as §4.1), nonlinear kinematics.
NONLINEAR = {**PAPER, "kinematics": "nonlinear", "spacing": 0.00025, "horizon": 0.0015}
#: The like-for-like reference of a nonlinear PD run: the finite-strain FEM (St Venant-
#: Kirchhoff). Two levels (fine element edges 1 and 0.5 mm; the force at 2 mm changed by
#: 0.08 % between them) and 4 increments per output depth (8 changed it by 0.01 %), so the
#: study takes ~100 s once and is cached.
FINITE_REFERENCE = {"kinematics": "finite", "levels": 2, "substeps": 4}
#: where the paper's numbers are shown: the paper's grid and kinematics with our solver
#: choices (the sweep's runs change one of them: not the paper's reading of its solver)
OUR_SOLVER = {"predictor": "tangent", "line_search": "on", "newton_rtol": NEWTON_RTOL,
              "node_volumes": "partial"}
PUBLISHED_AT = {**NONLINEAR, **OUR_SOLVER}
#: the sweep of seed 003 §4.2's unstated solver choices on the uncorrected run (the paper
#: ran Peridigm's quasi-static solver and says nothing of its predictor, line search,
#: stopping rule or surface-node volumes): one change from our defaults each
UNSTATED_CHOICES = ({"predictor": "none"}, {"line_search": "off"}, {"newton_rtol": 1e-4},
                    {"node_volumes": "full"})
#: the same study with the neo-Hookean law (``reference_fem.hyperelastic.NeoHookean``)
NEO_HOOKEAN = {**FINITE_REFERENCE, "law": "neo-hookean"}


#: the paper-grid runs the docstring quotes (pdverify.quotes)
_PAPER_RUN = {"spacing": 0.00025, "substeps": 1, "line_search": "on", "newton_rtol": 1e-8,
              "node_volumes": "partial", "predictor": "tangent"}


@register
class Indentation(BondStaticScene):
    """Seed 003 §4.2 (Figs. 4 and 5): block 40 x 40 mm, rigid cylinder R = 15 mm pressed
    into the middle of the top edge to 2 mm; the parts of the surface it reaches stick to
    it ("move without slip along with the indenter surface").

    FEM (``fem``): Q2 with the same contact law, converged and cached
    (``reference_fem.indentation``: 20 output depths, 8 increments each), small strain by
    default; ``kinematics=finite`` = St Venant-Kirchhoff with the plane-stress Lame
    constants (``reference_fem.hyperelastic``), Newton per increment. Each PD run compares
    with the FEM of its own kinematics: ``linear`` PD with the small-strain FEM,
    ``nonlinear`` PD with the finite-strain FEM (:data:`FINITE_REFERENCE`); a nonlinear run
    also records its errors against the small-strain FEM (``*_vs_small_strain``), the
    reading the paper may have used (it does not say which FEM kinematics it ran).
    Neither does it say which material law: the report also runs the finite-strain FEM with
    a compressible neo-Hookean law of the same Lame constants (``law=neo-hookean``,
    :data:`NEO_HOOKEAN`; drawn beside the others in Fig. 4, not a PD run's reference). At
    2 mm St Venant-Kirchhoff gives 0.894 x the small-strain force and neo-Hookean 1.012 x
    (tests/reference_fem, an independent code agrees): most of the 10.6 % between the
    two references is the law's softening in compression, not the geometry.

    PD (``none``, ``energy-directional``): bond-based, plane stress, E = 1 GPa, nu = 1/3,
    unit thickness (ERRATA: chosen), micromodulus calibrated to the bulk of a complete
    continuous horizon; nodes on the surface (161 x 161 at spacing 0.25 mm, the paper's
    "matching grid of nodes"; boundary nodes carry half a cell, corners a quarter, as in
    §4.1), delta = 1.5 mm (m = 6). ``energy-directional`` applies Eq. (14) with all four
    faces counted, as in §4.1. Bottom row fixed, sides free. ``virtual-nodes`` (our
    extension of §4.1.2, variant 2, the held-face role of
    ``corrections.virtual_nodes.held_face``): m rows of thickness delta below the held
    bottom, held with it, so that the nodes within delta of it keep whole neighbourhoods;
    run at spacing 0.5 mm (no paper value to stand beside).

    Symmetry (``symmetry``): block, indenter and contact law are symmetric about the
    indenter's axis x = 0. ``half`` (default) solves for the nodes with x >= 0 only: a
    bond reaching across the axis joins its node to the mirror image of the other end
    (u_x odd, u_y even; u_x = 0 on the axis), each pair of mirror bonds counted once with
    twice the stiffness (:mod:`pdverify.pd.nonlinear`). That is the whole block's model
    restricted to symmetric displacements, not an approximation: Newton's norms are the
    whole block's, the force sums the half's reactions (the axis nodes counted once), the
    axis nodes' u_x stiffness is still checked as the whole block's free unknown (the quick
    grid's uncorrected run loses definiteness there), and a test shows half and ``full``
    equal to round-off. What the half model cannot show is an asymmetric solution of the
    whole block: at the paper's grid every failing run (``none`` both kinematics,
    ``energy``, ``volume``, ``perifit``) fails at the same depth with the same message in
    both (measured, issue 32), so the report runs the half model.

    Kinematics (``kinematics``): ``nonlinear`` (default; ERRATA: §4.2 is beyond small
    displacements) = the bond force acts along the current bond and depends on the
    current length (:mod:`pdverify.pd.nonlinear`), solved by Newton with a line search
    per increment; ``linear`` = the small-displacement model of §4.1 (one solve per
    contact pass), to compare with the small-strain FEM like for like.

    Contact law (the FEM reference's, node for node): the depth grows in
    ``n_steps * substeps`` equal increments; stuck nodes move down with the indenter by
    each increment, their x frozen; after each equilibrium every free node of the top row
    whose deformed position lies inside the disc is caught: x frozen, y put on the
    indenter surface; equilibrium again, until no free node penetrates. Stuck nodes never
    release. Force = minus the sum of the stuck nodes' y reactions (N per m of thickness).

    Breakdown: after each equilibrium every bond's current vector is compared with its
    reference one; a bond turned by 90 degrees or more (cos <= 0: inverted, e.g. a
    surface node pushed past the next row) ends the run as failed, naming the depth and
    the bond. So does a Newton iteration that stalls or a tangent CG cannot solve. The
    record keeps the curve up to the last equilibrium reached (``failure_depth_mm`` = the
    depth of the increment that failed).

    Metrics (against the FEM curve at the shared output depths, the first
    :data:`SKIP_OUTPUT_STEPS` left out): ``force_error_pct`` = max |F_PD - F_FEM| / F_FEM,
    ``force_bias_pct`` = the mean signed difference (negative: too soft),
    ``force_error_final_pct`` = signed at the last output depth reached, ``max_force``,
    ``failure_depth_mm`` (failed runs only), ``newton_iterations``, ``contact_nodes``;
    CG iterations, preconditioner builds and refreshes and the time per output depth are
    in the diagnostics.

    Findings (not tuned): at the paper's grid the corrected nonlinear run reaches 2 mm
    {{ed_small}} % below the small-strain FEM; the finite-strain FEM itself is 10.4 % below the
    small-strain one at 2 mm (St Venant-Kirchhoff softens in compression); the linear
    corrected run is within {{ed_linear}} % of the small-strain FEM. The uncorrected runs are
    about a
    third too soft (paper: about 30 %) and fail: nonlinear at {{none_nl}} mm, where the surface node
    under the indenter has squeezed its bond to the next row to 18 % of its length and
    Newton's line search finds no descent (the lattice is about to fold); linear at {{none_l}} mm,
    where that node is pushed past the next row. The paper reports about 0.4 mm.
    The peers' corrections (``energy``, ``volume``, ``perifit``: factors calibrated under a
    small homogeneous stretch) delay the collapse but do not prevent it: at the paper's
    grid each fails by a Newton stall ({{energy_d}}, {{volume_d}} and {{perifit_d}} mm), with the
    bond under the indenter at 15 % of its length (force error up to there {{energy_e}},
    {{volume_e}} and {{perifit_e}} %; none {{none_e}} %); on
    the quick report's coarse grid they reach 2 mm about 50 % too soft. Seed 003's
    directional factor, by contrast, keeps that bond at 85 %.

    The paper's unstated solver choices, swept on the uncorrected nonlinear run at the
    paper's grid (:data:`UNSTATED_CHOICES`, report cases, the table beside Fig. 4; the
    failure depth is resolved to the 0.1 mm output step): without the tangent predictor
    (each increment's Newton starts from the old free displacements beside the new
    prescribed ones) it fails at 0.5 mm, the tangent no longer positive definite under
    the indenter; without the line search, with a 1e-4 stopping rule, with 4 substeps,
    with exact partial areas: 0.7 mm (substeps 4: 0.675 mm, their own step); full volumes
    on the surface nodes 1.3 mm, the conical micromodulus 1.1 mm (measured, ``pdverify
    run``). So no single choice gives the paper's 0.4 mm; dropping the predictor comes
    closest (a solver that applies the indenter's increment to the contact nodes alone,
    as a quasi-static code without a predictor does, compresses the bonds under it by the
    whole increment).
    """

    id = "block2d-indentation"
    #: the numbers the docstring quotes from this report's runs (pdverify.quotes)
    doc_quotes = {
        "ed_small": Q("force_error_pct_vs_small_strain", "energy-directional",
                      {"spacing": 0.00025, "substeps": 1, "kinematics": "nonlinear"}, ".2g"),
        "ed_linear": Q("force_error_pct", "energy-directional",
                       {"spacing": 0.00025, "substeps": 1, "kinematics": "linear"}, ".2g"),
        "none_nl": Q("failure_depth_mm", "none", {**_PAPER_RUN, "kinematics": "nonlinear"},
                     ".1f"),
        "none_l": Q("failure_depth_mm", "none", {**_PAPER_RUN, "kinematics": "linear"}, ".1f"),
        "none_e": Q("force_error_pct", "none", {**_PAPER_RUN, "kinematics": "nonlinear"},
                    ".3g"),
        **{f"{m}_{k}": Q(metric, m, {**_PAPER_RUN, "kinematics": "nonlinear"}, fmt)
           for m in ("energy", "volume", "perifit")
           for k, metric, fmt in (("d", "failure_depth_mm", ".1f"),
                                  ("e", "force_error_pct", ".3g"))}}
    #: typed on purpose: the paper's 30 %; bond lengths under the indenter (18, 15, 85 %)
    #: and the quick grid's 50 % are studies of this docstring, not metrics of a run
    #: and the FEM's force ratios 0.894, 1.012 (tests/reference_fem)
    doc_typed = ("30", "18", "15", "85", "50", "0.894", "1.012")
    title = "Rigid cylinder indenting a block, sticking contact: FEM and nonlinear PD (Fig. 4)"
    seed = "003 §4.2"
    figure = "indentation"
    dim = 2
    closure_theory = "bond-based"
    #: virtual nodes hold rigid buffer rows below the held bottom (their held-face role)
    role_families = (HELD_FACE,)
    role_refusals = {"bond-box": "its top face takes the indenter's sticking contact node "
                                 "by node, increment by increment (no static condition at "
                                 "the surface), and the bond-box system's one bordered "
                                 "linear solve has no Newton or contact loop"}
    #: the quick report's coarse grid (m = 6 kept), for every PD method
    quick_overrides = {"spacing": 0.001, "horizon": 0.006}
    headline = "force_error_pct"  # the report overview's error for this scene
    params_class, function = "IndentationParams", "indentation"
    shared = ("width", "height", "radius", "depth", "n_steps", "E", "nu", "thickness")
    pd_params = (
        spacing_param(0.00025, "161 x 161 nodes"),
        horizon_param(0.0015, "m = 6"),
        *(q for q in PD_COMMON if q.name != "solver"),
        Param("solver", "auto", "linear solver of each Newton step: direct (sparse LU), cg "
              "(conjugate gradients, two-level smoothed aggregation one horizon wide, built "
              "once and rebuilt when a solve slows down) or auto (cg from "
              f"{NEWTON_CG_FROM_UNKNOWNS} unknowns)", choices=SPD_LATTICE_SOLVERS),
        Param("substeps", 1, "depth increments per output depth (n_steps * substeps in all)",
              at_least(1)),
        Param("kinematics", "nonlinear", "nonlinear (current bond lengths and directions) "
              "or linear (small displacements)", choices=KINEMATICS),
        Param("symmetry", "half", "half (the block's half x >= 0, mirrored neighbours "
              "across the indenter's axis: the symmetric solution exactly) or full (the "
              "whole block, which could also show an asymmetric one)", choices=SYMMETRY),
        # the paper's unstated solver choices (seed 003 §4.2 ran Peridigm's quasi-static
        # solver): swept by the report's study of the uncorrected failure depth
        Param("predictor", "tangent", "start of each increment's Newton: the tangent "
              "predictor from the last equilibrium, or none (the old free displacements "
              "beside the new prescribed ones)", choices=("tangent", "none")),
        Param("line_search", "on", "Newton's backtracking line search, or off (every full "
              "step taken)", choices=("on", "off")),
        Param("newton_rtol", NEWTON_RTOL, "Newton's stopping rule: free residual over the "
              "force scale", open_interval(0.0, 1.0)),
        Param("node_volumes", "partial", "volume of the nodes on the surface: half on edges, "
              "a quarter at corners, or a full cell", choices=("partial", "full")),
    )
    published = (
        # "about 6 %", "about 30 %": one significant digit, so half a unit in that digit
        # the paper does not say which FEM its 6 % is measured against: against our
        # finite-strain reference ours is 5.3 % at the paper's grid (a known difference,
        # both readings shown), against the small-strain one 5.8 % (checked; the quick
        # grid's 41 x 41 nodes give 4.8 % and 6.3 %: deviations, 003-indentation-reference)
        Published("force_error_pct", 6, "seed 003 §4.2 (about 6 %)", method="energy-directional",
                  where=PUBLISHED_AT, deviation="003-indentation-reference",
                  reproduced=(({}, "5.3", "deviations 003-indentation-reference (the full "
                               "report's record at the paper's grid)"),)),
        Published("force_error_pct_vs_small_strain", 6, "seed 003 §4.2 (about 6 %), against "
                  "the small-strain FEM", method="energy-directional", where=PUBLISHED_AT),
        Published("force_bias_pct", -30, "seed 003 §4.2 (about 30 % too soft)", method="none",
                  where=PUBLISHED_AT, tolerance=5.0,
                  tolerance_source="half a unit in the one printed significant digit "
                                   "('about 30 %')"),
        Published("failure_depth_mm", 0.4, "seed 003 §4.2 (about 0.4 mm)", method="none",
                  where=PUBLISHED_AT, deviation="003-indentation-failure",
                  reproduced=(({}, "0.7", "deviations 003-indentation-failure; "
                               "tests/pdverify/test_indentation_sweep.py"),)),
    )

    #: the documented collapses (deviations: seed 003 findings): failures, as expected
    expected_failures = (
        ExpectedFailure("the uncorrected lattice stalls under the indenter (seed 003 §4.2: "
                        "the paper's fails at about 0.4 mm; ours at 0.7 mm at the paper's "
                        "grid, 1.8 mm at the quick grid)", method="none",
                        where={**PAPER, "kinematics": "nonlinear"}),
        ExpectedFailure("the linear lattice folds under the indenter at 1 mm (a bond "
                        "inverted), as seed 003 §4.2 expects of small-displacement PD",
                        method="none", where={"kinematics": "linear", "spacing": 0.00025}),
        ExpectedFailure("the buffer rows below the held bottom do not stiffen the surface "
                        "under the indenter: at the quick grid the lattice loses definiteness "
                        "at 1.7 mm as the uncorrected one does at 1.8 mm (the quick report of "
                        "2026-11-28; at half the paper's spacing it reaches 2 mm)",
                        method="virtual-nodes", where={**PAPER, "kinematics": "nonlinear",
                                                        "spacing": 0.001, "horizon": 0.006}),
        *(ExpectedFailure("the peers' bond corrections stall at 1.0-1.1 mm at the paper's "
                          "grid, the bond under the indenter at 15 % of its length (our "
                          "finding, deviations)", method=m,
                          where=NONLINEAR)
          for m in ("energy", "volume", "perifit")),
    )

    def reference_params(self, p) -> dict:
        """Like for like: the small-strain FEM for ``kinematics=linear``, the finite-strain
        one (:data:`FINITE_REFERENCE`) for ``nonlinear``."""
        out = super().reference_params(p)
        if "kinematics" in p and p["kinematics"] == "nonlinear":   # a PD run's (fem: none)
            out.update(FINITE_REFERENCE)
        return out

    def extra_fields(self, res, fields):
        fields.update(depths=np.asarray(res.depths), forces=np.asarray(res.forces),
                      contact_widths=np.asarray(res.contact_widths))
        return fields

    def check(self, method, p):
        """The params as the base checks them, the step budget (a huge n_steps is refused
        for its cost, before its depth rule), then the depth: at least n_steps x
        :data:`MIN_OUTPUT_DEPTH` R (FEM and PD)."""
        super().check(method, p)
        budget.check(f"{self.id} --method {method}", self.estimate(method, p))
        smallest = p["n_steps"] * MIN_OUTPUT_DEPTH * p["radius"]
        if not p["depth"] >= smallest:
            raise InputError(f"{self.id} --method {method}: depth={p['depth']:g} is below "
                             f"the smallest allowed, {smallest:.3g} m = n_steps x "
                             f"{MIN_OUTPUT_DEPTH:g} R (the first output depth must be 1000 "
                             f"times the contact rule's penetration tolerance "
                             f"{CATCH_TOLERANCE:g} R, so that it moves no force by more than "
                             "~0.1 %; below it no node is caught and there is no force)")

    def check_pd(self, where, method, p):
        rf = reference_module()
        try:
            rf.IndentationParams(**self.reference_params(p))
        except (TypeError, ValueError) as exc:
            raise InputError(f"{where}: {exc}".replace("\n", " ")) from None
        nu = bond_based_nu(2, "stress")
        if abs(p["nu"] - nu) > 1e-12:
            raise InputError(f"{where}: nu={p['nu']:g} is not allowed; bond-based PD in plane "
                             f"stress represents only nu = 1/3 ({nu:.6g})")
        check_horizon_grid(where, (("width", p["width"]), ("height", p["height"])), p["spacing"],
                    p["horizon"], "spacing")
        if round(p["width"] / p["spacing"]) % 2:
            raise InputError(f"{where}: width={p['width']:g} must be an even number of "
                             "spacings (a node under the indenter's axis)")
        if p["n_steps"] * p["substeps"] > 2000:
            raise InputError(f"{where}: n_steps * substeps = {p['n_steps'] * p['substeps']} "
                             "depth increments; allowed at most 2000")

    def estimate(self, method, p):
        """The memory of :class:`FemAndPD`, and the FEM study's load increments (each at
        least one solve): n_steps x substeps at every level, and twice that again at the
        finest one (its stepping check), held to ``budget.MAX_LOAD_INCREMENTS``; a PD run
        computes the study first unless it is cached."""
        est = super().estimate(method, p)
        ref = p if method == FEM.name else self.reference_params(p)
        increments = ref["n_steps"] * ref["substeps"] * (ref["levels"] + 2)
        return est + budget.Estimate(0.0, f"FEM study: {increments:.3g} load increments "
                                          f"(n_steps x substeps x (levels + 2))",
                                     increments=increments)

    def estimate_pd(self, method, p):
        h = p["spacing"]
        nodes = (p["width"] / h + 1) * (p["height"] / h + 1)
        m = p["horizon"] / h
        bonds = nodes * budget.lattice_neighbours(2, m) / 2
        # the tangent's pattern positions and data, bond vectors, the CG preconditioner
        if newton_solver(p["solver"], 2 * nodes) == "direct":
            return budget.linear_system(nodes, 2, 2, m, extra_bytes=400.0 * bonds)
        # CG never factors: the whole block's tangent (the half model's setup builds the
        # whole block's bonds), once more for the preconditioner's K P and its smoothed
        # prolongator (bounded by a second tangent), and the bond data. At the paper's
        # grid 1.96 GiB, above the measured peaks (benchmarks/records/
        # budget_calibration-2026-11-24-indentation-cg.json); a sparse LU's factor (2.4 GiB
        # more) is not counted
        return budget.iterative_system(nodes, 2, 2, m, extra_bytes=400.0 * bonds)

    def cases(self, quick=False):
        out = [("fem", {}), ("fem", dict(FINITE_REFERENCE)), ("fem", dict(NEO_HOOKEAN))]
        coarse = self.quick_overrides if quick else {}
        for method in ("none", "energy-directional"):
            out.append((method, dict(coarse)))
        if "virtual-nodes" in self.offered():
            # buffer rows below the held bottom (our extension, no paper value): at half
            # the paper's spacing in the full report (4.7 s under load against 13 s of
            # energy-directional's paper-grid run, alone)
            out.append(("virtual-nodes", dict(coarse) if quick else {"spacing": 0.0005}))
        if not quick:
            out += [("energy-directional", {"kinematics": "linear"}),
                    ("none", {"kinematics": "linear"})]
            # the sweep of the paper's unstated solver choices (docstring; Fig. 4's table):
            # the uncorrected run fails early, 6-15 s each at the paper's grid
            out += [("none", dict(v)) for v in UNSTATED_CHOICES]
        return out

    def bond_problem(self, p, where):
        """The block, its material and its held bottom face; the indenter's face ``y+``
        takes its sticking contact step by step (:func:`indent`), which no static
        condition states."""
        W, H, h, delta = p["width"], p["height"], p["spacing"], p["horizon"]
        return BondProblem(
            Body((W, H), (-W / 2, -H), h, placement="on-surface",
                 boundary_volume=p["node_volumes"], thickness=p["thickness"]),
            self.stencil(p, delta / h),
            BondMaterial(self.micromodulus(p, delta), get_influence(p["micromodulus"])),
            delta, {"y-": PartCondition({0: 0.0, 1: 0.0})}, p["E"],
            bond_based_nu(2, "stress"), "plane-stress",
            supports="the bottom face y = -height held (u = 0); the top face y = 0 "
                     "under the rigid indenter, sticking contact")

    def solve_pd(self, method, p, timer):
        h, delta = p["spacing"], p["horizon"]
        where = f"{self.id}/{method}"
        with timer.phase("setup"):
            problem = self.bond_problem(p, where)
            t = self.offered().get(method)
            if t is not None and t.role(HELD_FACE) is not None:
                # virtual nodes: rigid buffer rows below the held bottom, held with it
                problem = t.build_for(HELD_FACE, problem, p)
            model = assemble_bonds(problem, self.bond_closure(method, p)).model
            grid = model.grid
            kin = (NonlinearBondBased if p["kinematics"] == "nonlinear" else LinearBondBased)(
                model, mirror_axis=0 if p["symmetry"] == "half" else None)
            kin.pattern                  # the tangent's pattern, built in the setup phase
            unknowns = 2 * kin.n
            use_cg = newton_solver(p["solver"], unknowns) == "cg"
            ids = kin.node_ids
            lin = DirichletLinearSolver(kin.pattern, "cg" if use_cg else "direct",
                                        Lattice.component_major(grid.index[ids], grid.x[ids], 2),
                                        width=int(round(delta / h)),
                                        describe=lambda k: _describe(grid, kin, k))
        size = {"nodes": int(kin.n), "unknowns": int(unknowns), "bonds": int(kin.a.size),
                "tangent_nnz": int(kin.pattern.nnz)}
        with timer.phase("reference"):
            ref = self.fem_reference(p)
            small = (self.fem_reference({**p, "kinematics": "linear"})
                     if p["kinematics"] == "nonlinear" else ref)
        with timer.phase("solve"):
            curve, failure = indent(kin, grid, p, lin, where)
        metrics = curve_metrics(curve, ref, failure)
        if small is not ref:     # the other reading: against the small-strain FEM
            other = curve_metrics(curve, small, None)
            metrics.update({f"{k}_vs_small_strain": other[k] for k in
                            ("force_error_pct", "force_bias_pct", "force_error_final_pct")
                            if k in other})
        diagnostics = {"solver": ("CG + two-level smoothed aggregation, reused across Newton "
                                  "iterations" if use_cg else "sparse LU per Newton iteration"),
                       "model": ("half block x >= 0, mirrored neighbours" if kin.half is not None
                                 else "whole block"),
                       "linear_solves": lin.stats.solves,
                       "preconditioner_builds": lin.stats.rebuilds,
                       "preconditioner_refreshes": lin.stats.refreshes,
                       "preconditioner_setup_s": lin.stats.setup_s,
                       "linear_solve_s": lin.stats.solve_s,
                       "median_step_s": float(np.median(curve["step_s"])) if curve["step_s"] else 0.0,
                       "max_step_s": float(np.max(curve["step_s"])) if curve["step_s"] else 0.0,
                       "line_search_cuts": int(curve["cuts"])}
        if use_cg:
            diagnostics["cg_iterations"] = lin.stats.iterations
        body = grid.x[:, 1] >= -p["height"] - 1e-9 * h
        fields = {"depths": np.array(curve["depths"]), "forces": np.array(curve["forces"]),
                  "contact_widths": np.array(curve["widths"]),
                  "contact_counts": np.array(curve["counts"]),
                  "step_s": np.array(curve["step_s"]),
                  "min_bond_cosine": np.array(curve["min_cos"]),
                  "min_bond_length_ratio": np.array(curve["min_stretch"]),
                  "newton_residuals": curve["residuals"],
                  "fem_depths": np.asarray(ref.depths), "fem_forces": np.asarray(ref.forces),
                  "fem_kinematics": ref.params["kinematics"],
                  "fem_small_forces": np.asarray(small.forces),
                  # the block's nodes (not a treatment's buffer rows below it)
                  "x": grid.x[body], "u": kin.expand(curve["u"]).reshape(2, -1).T[body],
                  "energy": kin.energy_density(curve["u"])[body], "spacing": h,
                  "horizon": delta, "failure": failure}
        if failure is None:
            fields.update(u_ref=ref.evaluate(grid.x[body]),
                          energy_ref=ref.strain_energy_density(grid.x[body]))
            return Outcome(metrics=metrics, size=size, fields=fields, diagnostics=diagnostics)
        raise NumericalError(failure["message"],
                             partial=Outcome(metrics=metrics, size=size, fields=fields,
                                             diagnostics=diagnostics))


def indent(kin, grid, p, lin, where):
    """Depth stepping with the sticking contact law of :class:`Indentation`; returns the
    curve (dict of per-output-depth lists, the last equilibrium ``u`` of ``kin``'s unknowns)
    and ``None``, or the curve up to the last equilibrium and a failure dict (depth,
    message, node) when the lattice folds or Newton fails. With a half model (``kin.half``)
    the nodes on the axis keep u_x = 0, and the contact width and count are the whole
    top's (the mirror images of the stuck nodes are stuck); the force, a sum of the half
    model's reactions, is the whole body's already."""
    n = kin.n
    x0 = grid.x[kin.node_ids]
    index = grid.index[kin.node_ids]
    R = p["radius"]
    top = np.flatnonzero(index[:, 1] == grid.index[:, 1].max())
    top = top[np.argsort(x0[top, 0])]
    # the held bottom row, and any buffer rows a treatment adds below it (virtual nodes)
    bottom = np.flatnonzero(x0[:, 1] <= -p["height"] + 1e-9 * p["spacing"])
    fixed = np.zeros(2 * n, dtype=bool)              # the body's prescribed unknowns
    fixed[bottom] = fixed[n + bottom] = True
    plane = np.zeros(2 * n, dtype=bool)              # and those of the symmetry
    if kin.half is not None:
        plane[kin.plane_unknowns] = True
        image_x = grid.x[kin.half["image"][top], 0]     # the top nodes' mirror images
        copies = np.where(kin.half["image"][top] == kin.node_ids[top], 1, 2)
    stuck = np.zeros(top.size, dtype=bool)
    u = np.zeros(2 * n)
    n_inc = p["n_steps"] * p["substeps"]
    dd = p["depth"] / n_inc
    curve = {"depths": [0.0], "forces": [0.0], "widths": [0.0], "counts": [0], "step_s": [],
             "newton": [0], "residuals": [], "cuts": 0, "u": u.copy(), "min_cos": [1.0],
             "min_stretch": [1.0]}
    lin.set_fixed(fixed | plane, watched=plane & ~fixed)
    t_step = time.perf_counter()
    iterations = 0
    for inc in range(1, n_inc + 1):
        d = p["depth"] * inc / n_inc
        yc = R - d
        at = f"{where}: depth {d * 1e3:.4g} mm"
        previous = u.copy()
        u[n + top[stuck]] -= dd
        while True:
            try:
                rep = newton(kin, u, lin, where=at, rtol=p["newton_rtol"],
                             previous=previous if p["predictor"] == "tangent" else None,
                             line_search=p["line_search"] == "on")
            except NumericalError as exc:
                return curve, _stalled(kin, grid, u, previous, d, str(exc))
            iterations += rep.iterations
            curve["cuts"] += rep.line_search_cuts
            if len(curve["residuals"]) < 3 and rep.iterations >= 2:
                curve["residuals"].append([r / rep.scale for r in rep.residuals])
            state = kin.bond_extremes(u)
            folded = _folding(kin, grid, u, at, state)
            if folded is not None:
                folded["depth"] = d
                return curve, folded
            X = x0[top, 0] + u[top]
            Y = x0[top, 1] + u[n + top]
            new = ~stuck & (np.hypot(X, Y - yc) - R < -CATCH_TOLERANCE * R)
            if not new.any():
                break
            idx = top[new]
            previous = u.copy()
            u[n + idx] = yc - np.sqrt(R ** 2 - X[new] ** 2) - x0[idx, 1]
            stuck |= new
            fixed[idx] = fixed[n + idx] = True
            lin.set_fixed(fixed | plane, watched=plane & ~fixed)
        if inc % p["substeps"]:
            continue
        f = kin.internal_force(u)
        xs = x0[top[stuck], 0] + u[top[stuck]]
        count = int(stuck.sum())
        if kin.half is not None:
            xs = np.concatenate([xs, image_x[stuck] - u[top[stuck]]])
            count = int(copies[stuck].sum())
        curve["depths"].append(d)
        curve["forces"].append(-float(f[n + top[stuck]].sum()))
        curve["widths"].append(float(xs.max() - xs.min()) if xs.size else 0.0)
        curve["counts"].append(count)
        curve["newton"].append(iterations)
        curve["min_cos"].append(state["cos"])           # of the final u of this increment
        curve["min_stretch"].append(state["ratio"])
        curve["u"] = u.copy()
        now = time.perf_counter()
        curve["step_s"].append(now - t_step)
        t_step = now
    return curve, None


def _node_at(grid, node) -> str:
    x = grid.x[node] * 1e3
    return f"node {node} at ({x[0]:.4g}, {x[1]:.4g}) mm"


def _describe(grid, kin, k) -> str:
    """Unknown k of ``kin`` (component-major) as 'u_y of node i at (x, y) mm' (of a half
    model: of the node or its mirror image, the one the whole body's lower index names)."""
    node = int(kin.node_ids[k % kin.n])
    if kin.half is not None:
        node = min(node, int(kin.half["image"][k % kin.n]))
    return f"u_{'xy'[k // kin.n]} of {_node_at(grid, node)}"


def _ends(kin, grid, bond):
    """(lower, upper) node of a bond in lattice order (row, then column), and its offset."""
    a, b = kin.bond_nodes(bond)
    off = grid.index[b] - grid.index[a]
    return ((a, b) if off[1] > 0 or (off[1] == 0 and off[0] > 0) else (b, a)), off


def _folding(kin, grid, u, at, state=None):
    """None, or a failure dict when a bond has turned by >= 90 degrees (``state``: the
    :meth:`bond_extremes` of ``u`` if already computed)."""
    state = state or kin.bond_extremes(u)
    cos = state["cos"]
    if cos > 0:
        return None
    (lower, upper), off = _ends(kin, grid, state["cos_bond"])
    what = ("pushed past the next row (its vertical nearest-neighbour bond inverted)"
            if abs(off[0]) == 0 and abs(off[1]) == 1 else
            f"bond to node {lower} (offset {tuple(int(v) for v in off)}) inverted")
    return {"message": f"{at}: the lattice folds: {_node_at(grid, upper)} {what}, "
                       f"cos = {cos:.3f}; the configuration is no longer a deformation "
                       "(seed 003 §4.2)",
            "node": upper, "bond": (lower, upper), "cos": cos}


def _stalled(kin, grid, u, previous, depth, message):
    """The failure dict of a Newton that gave up: what the lattice looked like at the last
    equilibrium (``previous``) and at the last iterate (``u``)."""
    state = kin.bond_extremes(previous)
    where = _node_at(grid, _ends(kin, grid, state["ratio_bond"])[0][1])
    note = (f"; at the last equilibrium the shortest bond was {state['ratio']:.2f} of its "
            f"reference length ({where})")
    folded = _folding(kin, grid, u, "the last iterate")
    if folded is not None:
        note += "; " + folded["message"]
    return {"depth": depth, "message": message + note, "node": where}


def curve_metrics(curve, ref, failure) -> dict:
    """The force comparison of :class:`Indentation` at the output depths reached."""
    F = np.array(curve["forces"])
    k = np.arange(SKIP_OUTPUT_STEPS + 1, F.size)
    F_ref = np.asarray(ref.forces)[k]
    rel = (F[k] - F_ref) / F_ref * 100.0
    metrics = {"max_force": float(F.max()), "contact_nodes": int(curve["counts"][-1]),
               "newton_iterations": int(curve["newton"][-1]),
               "depth_reached_mm": float(curve["depths"][-1] * 1e3)}
    if rel.size:
        metrics.update(force_error_pct=float(np.max(np.abs(rel))),
                       force_bias_pct=float(np.mean(rel)),
                       force_error_final_pct=float(rel[-1]))
    if failure is not None:
        metrics["failure_depth_mm"] = float(failure["depth"] * 1e3)
    return metrics
