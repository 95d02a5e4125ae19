"""Bodies that are not boxes (issue 35): a plate with a circular hole and an L-shaped plate,
2D state-based PD against converged FEM references on meshes of the same shapes.

Both are ``static-state`` descriptions (:class:`~pdverify.pd.problem.StaticProblem` with
a ``shape``): the body is cut from the uniform cell-centred lattice of its bounding box
(``pdverify.pd.grid.ShapeGrid``: a node is real when its cell centre lies inside, its
volume the part of its cell inside, sampled), boundary conditions are keyed by the
shape's named parts, and every treatment of the family that can serve a body that is
not a box runs on it (``list`` says why the others do not).
"""
from __future__ import annotations

import numpy as np

from ..errors import InputError
from ..metrics import region_errors, rel_l2_error
from ..params import Param, at_least, grid_params
from ..pd import QUADRATURES, StateBasedConstants, get_influence, state_based_stencil
from ..pd.problem import FaceCondition, StaticProblem
from ..pd.shapes import l_shape, quarter_hole
from ..quotes import Quote as Q
from ..quotes import used
from . import influence_param, register, whole_cells
from .family import FemStaticStateScene

#: SuperLU ordering of the direct solves: minimum degree on A + A^T (4.5x faster than
#: COLAMD on the hole plate's h = 0.0125 m system, benchmarks/records/
#: plate_solvers-2026-11-26-hole-plate-ordering.json;
#: as the clamped plate's, plate2d.ORDERING)
ORDERING = "MMD_AT_PLUS_A"


def _jitter_params():
    def fraction(v):
        return None if 0.0 <= v < 1.0 else "must be in [0, 1) (a fraction of the spacing)"
    return (Param("jitter", 0.0, "random move of every real node, uniform in a square of "
                  "side jitter * spacing about its lattice point (0: the lattice)", fraction),
            Param("jitter_seed", 0, "seed of the jitter's random moves", at_least(0)))


def shape_errors(x, u, u_ref, shape, horizon, regions=()) -> tuple[dict, np.ndarray]:
    """Errors in % of max |u_ref| (the displacement's magnitude over the PD nodes):
    ``max_error_pct`` (largest component error) over every node, over the ``boundary_``
    layer (within one horizon of the boundary), the ``interior_`` and, per boundary part
    in ``regions``, the nodes within one horizon whose closest boundary point lies on it
    (``<part>_max_error_pct``); ``rel_l2_error`` of the whole field."""
    scale = np.max(np.linalg.norm(u_ref, axis=1))
    err = np.abs(u - u_ref) / scale * 100.0
    _, _, dist, part = shape.closest(x)
    near = dist < horizon
    masks = {"": np.ones(len(x), dtype=bool), "boundary_": near, "interior_": ~near}
    for name in regions:
        masks[f"{name}_"] = near & (part == shape.part_names.index(name))
    out = region_errors(err, masks, {"max_error_pct": None})
    out["rel_l2_error"] = rel_l2_error(u, u_ref)
    return out, err


class ShapeScene(FemStaticStateScene):
    """What the two shape scenes share: the PD parameters, the problem from the shape and
    its conditions, the measurement."""

    dim = 2
    figure = "shape2d"
    has_shape = True
    #: the boundary parts whose own error is reported (``shape_errors``)
    regions: tuple = ()
    pd_params = (
        *grid_params(0.025, 3.0),
        influence_param("hyperbolic", "seed 000, Eq. 23: delta / |xi|"),
        Param("quadrature", "partial-volume", "weights beta: exact cell fractions inside the "
              "horizon, or those adjusted to an isotropic fourth moment",
              choices=QUADRATURES),
    ) + _jitter_params()
    #: delta-refinement at fixed m = 3, coarser than the default grid (0.025 m)
    delta_sweep = (0.05, 1 / 30)
    #: the jitter study (fractions of the spacing; seeds per level), on ``plate-hole``
    jitter_sweep = ()
    jitter_seeds = (0, 1)

    @property
    def quick_spacing(self) -> float:
        """The quick report's grid: the refinement's coarsest (runs of 0.1-0.2 s, against
        0.5-3 s at 0.025 m)."""
        return max(self.delta_sweep)

    def default_cases(self):
        """Every treatment offered here at the default grid (Taylor orders 1 to 3)."""
        out = []
        for name, t in self.offered().items():
            if t.kind == "hand-wired" or t.origin != "built-in" or getattr(t, "peer", False):
                continue         # a peer code names its own runs (pdverify.corrections.peer)
            ordered = any(q.name == "order" for q in t.params_for(self))
            out += [(name, {"order": n}) for n in (1, 2, 3)] if ordered else [(name, {})]
        return out

    @property
    def table_metrics(self):
        """The report's compact table: the largest error, and the largest near each
        reported part, beside the headline rel_l2_error."""
        return ("max_error_pct",) + tuple(
            f"{r}_max_error_pct" for r in self.regions)

    def shape(self, p):
        raise NotImplementedError

    def conditions(self, p) -> dict:
        raise NotImplementedError

    def reference_field(self, p):
        """The FEM displacement at points (the problem's ``exact``): the reference's own
        evaluation; a scene whose reference models part of its body maps it here."""
        return self.reference_of(p).evaluate

    def box(self, p):
        s = self.shape(p)
        return tuple(np.subtract(s.upper, s.lower)), tuple(s.lower)

    def check_pd(self, where, method, p):
        """The grid and the material (2D and 3D shapes; a 3D body has no thickness)."""
        lengths, _ = self.box(p)
        whole_cells(where, p["spacing"], [(f"l_{a}", L) for a, L in zip("xyz", lengths)])
        for name in ("E", "thickness", "traction"):
            if name in p and not (np.isfinite(p[name]) and p[name] > 0):
                raise InputError(f"{where}: {name}={p[name]!r} must be a finite number > 0")
        if not -1.0 < p["nu"] < 0.5:
            raise InputError(f"{where}: nu={p['nu']!r} must be in (-1, 0.5)")

    def problem(self, p, where):
        inf = get_influence(p["influence"])
        lengths, origin = self.box(p)

        def value(x):
            return self.reference_field(p)(x)
        return StaticProblem(
            lengths, origin, float(p["spacing"]),
            state_based_stencil(2, p["m_ratio"], p["spacing"], inf, p["quadrature"]),
            StateBasedConstants("plane-stress", p["E"], p["nu"]), inf,
            self.conditions(p), exact=value, thickness=p["thickness"], solver=self.fixed_solver,
            ordering=ORDERING, where=where, shape=self.shape(p),
            jitter=float(p["jitter"]), jitter_seed=int(p["jitter_seed"]))

    def measure(self, p, problem, system, x, info):
        ref = self.reference_of(p)
        x_int = self.real_nodes(system)
        u, _ = self.solution(system, x)
        u_ref = ref.evaluate(x_int)
        horizon = system.model.horizon
        metrics, err = shape_errors(x_int, u, u_ref, problem.shape, horizon, self.regions)
        return self.fem_outcome(p, system, info, metrics, err, x_int, u, u_ref,
                                self.box(p)[0])

    def cases(self, quick=False):
        runs = self.default_cases()
        out = [("fem", {})] + runs
        if quick:   # every method, on the coarsest level of the refinement
            return [("fem", {})] + [(m, {**q, "spacing": self.quick_spacing}) for m, q in runs]
        for h in self.delta_sweep:
            out += [(m, {**q, "spacing": h}) for m, q in runs]
        # the jitter study: the baseline, a bond method, the fictitious nodes (order 2)
        jittered = (("none", {}), ("energy", {}), ("taylor-fictitious", {"order": 2}))
        for j in self.jitter_sweep:
            for seed in self.jitter_seeds:
                out += [(m, {**q, "jitter": j, "jitter_seed": seed}) for m, q in runs
                        if (m, q) in jittered]
        return out


@register
class HolePlate(ShapeScene):
    """A square plate with a central circular hole under remote uniaxial tension, plane
    stress (issue 35; the classic of Kirsch 1898): the quarter [0, W]^2 without the disk
    r < a, by symmetry.

    The problem, stated once: u_x = 0 on ``x-`` (x = 0, y >= a) and u_y = 0 on ``y-``
    (y = 0, x >= a) (the symmetry planes), the traction (traction, 0) on ``x+``, the top
    ``y+`` and the ``hole`` free. FEM (``fem``): the converged quadratic-element reference
    of ``reference_fem.hole_plate`` on a mapped mesh of the same shape (9-node
    isoparametric quadrilaterals, the arc to O(h^3)): its field changes on the PD grid by
    0.195, 0.055, 0.0117, {{fem_change}} % over its refinements (the report's table),
    u_x(W, 0) = {{fem_ux}} m, stress concentration {{fem_scf}}. Checked against Kirsch (its
    tests): with
    Kirsch's own traction on the outer edges the FEM converges to Kirsch's displacement
    at rate 3.07 (0.070 .. 0.000115 % of max |u|, concentration 2.99988); under uniform
    tension the concentration falls to Kirsch's 3 as the plate grows, {{fem_scf3}}, 3.085,
    3.020, 3.004 at W/a = 5, 10, 20, 40 (3 + ~8.5 (a/W)^2; ours is W/a = 5), and the
    displacement near the hole comes within 0.72 % of Kirsch's at W/a = 20.

    PD: 2D linear state-based, hyperbolic influence, plane-stress constants from energy
    equivalence, m = 3, cell-centred nodes at 0.025 m cut from the lattice of [0, W]^2
    (``ShapeGrid``: real nodes are the cells whose centre lies inside, volume the cell's
    sampled part inside). Treatments: the uncorrected baseline and the bond methods
    impose a part's prescribed component on the real nodes of the cells its boundary
    samples fall in (the layer nearest a straight face, as on the boxes; along the hole
    the cut cells' nodes) and a traction as the integral of t over the part, each
    sample's share on the node of its cell (``assembly.boundary_nodes``). The
    node-adding treatments run along the local normal (our generalisations; each
    module's docstring states it and the exactness it keeps, tested on both shapes):
    Taylor's fictitious nodes (``shape_fictitious``), surface nodes at the boundary
    nodes' points on each part (``surface_nodes.surface_nodes_on_shape``), mirror nodes
    across the tangent at the closest point (``mirror_nodes.MirrorNodesOnShape``) and
    PDDO's boundary rows with the part's normal (``pddo.pddo_shape_system``).

    Metrics: ``max_error_pct`` (largest component error in % of max |u_FEM|),
    the same over the ``boundary_`` layer (within delta of the boundary), the
    ``interior_`` and the nodes within delta whose closest boundary point is on the
    ``hole`` (``hole_max_error_pct``); ``rel_l2_error``; ``reference_change_pct``.
    ``jitter`` moves the real nodes at random (``ShapeGrid``): the error against jitter
    is the report's figure.

    Findings at the default grid (h = 0.025 m, measured): Taylor along the normal beats
    the uncorrected model (max error {{t1_max}} / {{t2_max}} / {{t3_max}} % for orders 1 / 2 / 3
    against {{none_max}} %; rel L2 {{t1_l2}} / {{t2_l2}} / {{t3_l2}} against {{none_l2}}), its
    largest errors at the hole (where the arc's rows are the fit's traction, not a flux);
    PALS has the smallest rel L2 ({{pals_l2}}) with its largest error at the hole's ends
    ({{pals_max}} %); the volume correction is worse than none at the loaded edge's corners
    ({{volume_max}} %). Over the refinement (h = 0.05, 1/30, 0.025, m = 3) the uncorrected
    and bond-method errors fall steadily (rel L2 of none {{none_l2_a}}, {{none_l2_b}},
    {{none_l2}}), Taylor's do not (order 3: {{t3_l2_a}}, {{t3_l2_b}}, {{t3_l2}}; order 1:
    {{t1_l2_a}}, {{t1_l2_b}}, {{t1_l2}}): with a / delta = 1.3 to 2.7 the hole is within a few
    horizons of every node that sees it, and the fitted slopes in the figure are of three
    pre-asymptotic levels, not rates. Jitter up to 0.4 spacings
    raises the Taylor extension's error (rel L2 0.021 -> 0.031, order 2) and lowers the
    uncorrected and energy-corrected ones slightly (0.031 -> 0.026, 0.025 -> 0.020), the
    means of two seeds; why the truncated models gain is not chased (the spread between
    seeds at 0.4 is a fifth of the change).

    Along the normal (issue 55, h = 0.025): surface nodes rel L2 {{s1_l2}} / {{s2_l2}} /
    {{s3_l2}} for orders 1 / 2 / 3 (largest error {{s1_max}} / {{s2_max}} / {{s3_max}} %),
    PDDO {{pddo_l2}} ({{pddo_max}} %), mirror nodes {{mirror_l2}} ({{mirror_max}} %: their
    first-order traction relation across the hole's stress concentration; on the clamped
    box plate they beat none). Over the refinement the surface nodes are erratic (order 2:
    {{s2_l2_a}}, {{s2_l2_b}}, {{s2_l2}} at h = 0.05, 1/30, 0.025; order 3: {{s3_l2_a}},
    {{s3_l2_b}}, {{s3_l2}}) where a / delta is small, PDDO's errors fall ({{pddo_l2_a}},
    {{pddo_l2_b}}, {{pddo_l2}}); not chased further.
    """

    id = "plate-hole"
    #: typed on purpose: the FEM's Kirsch checks (its tests), not report runs
    doc_typed = ("3.07", "2.99988", "3.085", "3.020", "3.004", "0.72")
    #: the numbers the docstring quotes from this report's runs (pdverify.quotes)
    doc_quotes = used(__doc__, {
        "fem_change": Q("field_change_pct", "fem", fmt=".2g"),
        "fem_ux": Q("ux_load_point", "fem", fmt=".6g"),
        "fem_scf": Q("scf", "fem", fmt=".5g"),
        "fem_scf3": Q("scf", "fem", fmt=".3f"),
        **{f"{k}_{m}{tag}": Q(metric, method, {"spacing": h, "m_ratio": 3.0, "jitter": 0.0,
                                                **extra}, fmt)
           for k, method, extra in (("none", "none", {"load_point": "surface"}),
                                    ("pals", "pals", {"load_point": "surface"}),
                                    ("volume", "volume", {"load_point": "surface"}),
                                    ("t1", "taylor-fictitious", {"order": 1}),
                                    ("t2", "taylor-fictitious", {"order": 2}),
                                    ("t3", "taylor-fictitious", {"order": 3}),
                                    ("s1", "surface-nodes", {"order": 1}),
                                    ("s2", "surface-nodes", {"order": 2}),
                                    ("s3", "surface-nodes", {"order": 3}),
                                    ("mirror", "mirror-nodes", {}),
                                    ("pddo", "pddo", {}))
           for m, metric, fmt in (("max", "max_error_pct", ".3g"), ("l2", "rel_l2_error", ".2g"))
           for tag, h in (("", 0.025), ("_a", 0.05), ("_b", 1 / 30))}})
    title = "Plate with a circular hole under remote tension (2D state-based, FEM reference)"
    seed = "ours (issue 35; Kirsch 1898 as the check)"
    params_class, function = "HolePlateParams", "hole_plate"
    shared = ("width", "radius", "thickness", "E", "nu", "traction")
    regions = ("hole",)
    jitter_sweep = (0.1, 0.2, 0.4)

    def shape(self, p):
        return quarter_hole(p["width"], p["radius"])

    def conditions(self, p):
        t = p["traction"]
        return {"x-": FaceCondition(prescribed=(0,)), "y-": FaceCondition(prescribed=(1,)),
                "x+": FaceCondition(traction=lambda x, n: np.c_[np.full(len(x), t),
                                                                np.zeros(len(x))])}


@register
class LPlate(ShapeScene):
    """An L-shaped plate with a re-entrant corner under mixed conditions, plane stress
    (issue 35): [0, L]^2 without (L/2, L] x (L/2, L], clamped on ``x-`` (x = 0), the
    shear traction (0, -traction) on the arm's end ``x+`` (x = L, y <= L/2), every other
    part free (``y-``, ``y+``, and the re-entrant ``notch-x``, ``notch-y``; the stress is
    singular at their corner, r^-0.4555, the displacement bounded, r^0.5445).

    FEM (``fem``): ``reference_fem.l_plate``, Q2 on a mesh graded toward the re-entrant
    corner, converged (its docstring and the report's refinement table). PD: as
    ``plate-hole`` (its docstring); every edge lies on cell faces, so the cut-cell volumes
    are whole cells and the lattice is a box's with a quarter removed; the re-entrant
    corner is where the neighbourhoods are cut from two sides at once. Metrics: as
    ``plate-hole``, with the nodes nearest the re-entrant edges (``notch-x_``,
    ``notch-y_max_error_pct``).

    Finding (what breaks at a re-entrant corner; measured, not tuned): Taylor's
    fictitious nodes along the normal, one value per fictitious node, did worse here than
    the uncorrected model (h = 0.025, rel L2 about 1.5 to 1.9 times none's for orders 1
    to 3, the report of 674b0c4; the error grew linearly along the lower arm from the
    re-entrant corner, a rotation of the arm: the corner too stiff), though they
    reproduce a smooth cubic field with its body force on the same L-shape (x-
    prescribed, every other part loaded by the field's traction) to 1.7e-3 at order 2
    (moment-corrected stencil) against 6.0e-2 uncorrected. The cause was the notch: its
    fictitious nodes were extrapolated from one arm and bonded to the other, so bonds
    bridged the notch the singular field opens (u ~ r^0.5445; finding
    035-l-plate-bridging). Now (issue 55) a bond whose real end does not see the
    fictitious node's closest point through the body reads a value of its own,
    extrapolated from the real end's side (``corrections.shape_fictitious``, the
    ``bridging_bonds`` count: 53 at h = 0.025): rel L2 {{t1}} / {{t2}} / {{t3}} against
    {{none}}, largest errors {{t1_max}} / {{t2_max}} / {{t3_max}} % against {{none_max}} %. The
    rest (the clamped-free corners' singularities; the uncorrected model's ring takes
    the FEM values, its advantage here) is not chased further.

    The other node-adding methods along the normal (issue 55, h = 0.025): surface nodes
    rel L2 {{s1}} / {{s2}} / {{s3}} for orders 1 / 2 / 3 (largest errors {{s1_max}} /
    {{s2_max}} / {{s3_max}} %), the smallest here, with the same shadow values across the
    notch; PDDO {{pddo}} (largest {{pddo_max}} %, beside notch-x) and mirror nodes {{mirror}}
    ({{mirror_max}} %) are worse than none. The mirror nodes take the same shadow
    relations across the notch (exact for affine fields still); with them their rel L2
    is about a tenth higher than without (measured at h = 0.025, not a report run). Why
    the surface nodes do so much better than Taylor's rows on the same fits is not
    chased."""

    id = "plate-l"
    #: the numbers the docstring quotes from this report's runs (pdverify.quotes)
    doc_quotes = {
        **{f"none{tag}": Q(metric, "none", {"spacing": 0.025, "m_ratio": 3.0, "jitter": 0.0,
                                            "load_point": "surface"}, fmt)
           for tag, metric, fmt in (("", "rel_l2_error", ".2g"),
                                    ("_max", "max_error_pct", ".3g"))},
        **{f"t{k}{tag}": Q(metric, "taylor-fictitious", {"spacing": 0.025, "m_ratio": 3.0,
                                                         "jitter": 0.0, "order": k}, fmt)
           for k in (1, 2, 3)
           for tag, metric, fmt in (("", "rel_l2_error", ".3g"),
                                    ("_max", "max_error_pct", ".3g"))},
        **{f"{k}{tag}": Q(metric, method, {"spacing": 0.025, "m_ratio": 3.0, "jitter": 0.0,
                                           **extra}, fmt)
           for k, method, extra in (("s1", "surface-nodes", {"order": 1}),
                                    ("s2", "surface-nodes", {"order": 2}),
                                    ("s3", "surface-nodes", {"order": 3}),
                                    ("mirror", "mirror-nodes", {}), ("pddo", "pddo", {}))
           for tag, metric, fmt in (("", "rel_l2_error", ".3g"),
                                    ("_max", "max_error_pct", ".3g"))}}
    title = "L-shaped plate with a re-entrant corner (2D state-based, FEM reference)"
    seed = "ours (issue 35)"
    params_class, function = "LPlateParams", "l_plate"
    shared = ("length", "thickness", "E", "nu", "traction")
    regions = ("notch-x", "notch-y")

    def shape(self, p):
        return l_shape(p["length"])

    def conditions(self, p):
        t = p["traction"]
        return {"x-": FaceCondition(prescribed=(0, 1)),
                "x+": FaceCondition(traction=lambda x, n: np.c_[np.zeros(len(x)),
                                                                np.full(len(x), -t)])}
