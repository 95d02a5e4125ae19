"""The built-in treatments: those that assemble problem families (``static-state``) and
the descriptions of those that their scenes still wire by hand.

Each treatment's assembly is in its own module (``plain``, ``taylor_fictitious``,
``surface_nodes``, ``mirror_nodes``, ``pddo``); here it is only declared: its parameters,
checks and the function of each family it serves, typed by the family's protocol
(:mod:`.protocols`)."""
from __future__ import annotations

import functools
from dataclasses import dataclass

from ..errors import InputError
from ..params import Param, at_least
from ..pd.problem import LOAD_POINTS, BondProblem, BondSystem, LinearSystem, StaticProblem
from .bond_fictitious import assemble_bond_box, check_bond_box
from .mirror_nodes import (GRADIENT_AT, MIRROR_POINTS, NEUMANN_READINGS, assemble_mirror,
                           assemble_mirror_bond_box)
from .pddo import BULK_MODELS, assemble_pddo
from .pddo_bond import assemble_bond_pddo
from .plain import assemble_plain
from .protocols import GridClosure, ParamCheck, Params, StaticAssembly
from .surface_nodes import MAX_ORDER, assemble_surface_nodes, check_wave_order, wave_extension
from .taylor_fictitious import CORNER_RULES, assemble_taylor, fictitious_closure
from .treatment import BASELINE, Role, Treatment
from .virtual_nodes import check_layers, clamp, held_face

FAMILY = ("static-state",)


@dataclass(frozen=True)
class FamilyTreatment(Treatment):
    """A treatment whose ``assemble`` is a function ``build(problem, params)`` and whose
    parameter checks are ``checker(cells, params, where)``."""

    build: StaticAssembly | None = None
    checker: ParamCheck | None = None

    def assemble(self, problem: StaticProblem, params: Params) -> LinearSystem:
        return self.build(problem, params)

    def check(self, cells, params, where):
        if self.checker is not None:
            self.checker(cells, params, where)


def _order_check(value):
    return (None if 1 <= value <= MAX_ORDER
            else f"must be 1, 2 or 3 (Taylor orders above {MAX_ORDER} are not supported)")


def _check_taylor(cells, p, where) -> None:
    """Seed 000 App. D: the extrapolation of order n needs more than 2 n nodes along
    every axis."""
    n = min(cells)
    if n <= 2 * p["order"]:
        raise InputError(f"{where}: order={p['order']} is too large for {n} nodes; "
                         f"seed 000 App. D needs nodes > 2 * order (order <= {(n - 1) // 2})")


def _whole_layer(p, where, method):
    """A fictitious layer of thickness delta must be a whole number of cells."""
    m = p["m_ratio"]
    if abs(m - round(m)) > 1e-12:
        raise InputError(f"{where}: m_ratio={m:g} must be a whole number for {method} "
                         "(the fictitious layer of thickness delta must be a whole number "
                         "of cells)")


def _check_surface(cells, p, where) -> None:
    _whole_layer(p, where, "surface-nodes")
    N = p["order"]
    need = max(N + 1, 2 * ((N + 1) // 2) + 1)
    for name, n in zip("xyz", cells):
        if n < need:
            raise InputError(f"{where}: l_{name} has {n} cells; order {N} needs at least "
                             f"{need} for the Taylor stencils")


def _check_mirror(cells, p, where) -> None:
    _whole_layer(p, where, "mirror-nodes")


def _none(problem: StaticProblem, p: Params) -> LinearSystem:
    return assemble_plain(problem)


def _taylor(problem: StaticProblem, p: Params) -> LinearSystem:
    return assemble_taylor(problem, p["order"], p.get("corners", CORNERS.default))


def _surface(problem: StaticProblem, p: Params) -> LinearSystem:
    return assemble_surface_nodes(problem, p["order"])


def _mirror(problem: StaticProblem, p: Params) -> LinearSystem:
    return assemble_mirror(problem, p["neumann"], p["mirror_point"],
                           p.get("gradient_at", "mirror"))


def _pddo(problem: StaticProblem, p: Params) -> LinearSystem:
    return assemble_pddo(problem, p.get("bulk_model", "lps"))


LOAD_POINT = Param("load_point", "surface", "where the uncorrected model evaluates a "
                   "surface load: at the node it is applied to (like its constraints) or "
                   "at the face centre on the surface", choices=LOAD_POINTS,
                   scene_default=True)
ORDER = Param("order", 1, "Taylor truncation order n", at_least(1), scene_default=True)
CORNERS = Param("corners", "normal-only", "constrained components on the lines through a "
                "corner node where two faces prescribe the same component (seed 000 "
                "Remark 4): the normal one only, or both (over-constrained: singular)",
                choices=CORNER_RULES)
SURFACE_ORDER = Param("order", 1, "Taylor truncation order N (displacements N, "
                      "dilatations N - 1)", _order_check, scene_default=True)
MIRROR_PARAMS = (
    Param("neumann", "full-traction", "how a face's traction sets the gradient in the "
          "mirror relation: the full traction condition with the tangential derivatives "
          "at the mirror node (central differences), or the normal derivatives alone "
          "(tangential terms dropped)", choices=NEUMANN_READINGS),
    Param("mirror_point", "nearest", "mirror node: the real node nearest the mirror point "
          "(the method), that node with the mismatch corrected by its gradient "
          "(our variant; exact for linear fields), or that node taken as sitting at the "
          "mirror point in the Neumann relation (step x_f - x*: a reading of seed 001 "
          "§5.2's 'same distance from the boundary'; not exact near corners)",
          choices=MIRROR_POINTS),
    Param("gradient_at", "mirror", "where the full traction relation's tangential "
          "derivatives are differenced: at the mirror node or at the boundary point "
          "(same for affine fields)", choices=GRADIENT_AT))

PDDO_PARAMS = (
    Param("bulk_model", "lps", "equations of the nodes beyond 2 delta: the LPS model (ours) "
          "or the PDDO equilibrium of the layer (a stand-in for the paper's non-ordinary "
          "bulk; both exact for affine fields)", choices=BULK_MODELS),)

STATE = ("state-based",)
WAVE_ORDER = Param("order", 1, "Taylor order of the fictitious-node extrapolation (1 = Eqs. 8-9)",
                   at_least(1))


def _truncated(_problem: None, _params: Params) -> None:
    """The baseline's role in the ``wave-bar`` and ``flux-bar`` families: no extension
    (truncated neighbourhoods)."""
    return None


def _flux_order(_problem: None, params: Params) -> GridClosure:
    """Taylor's role in the ``flux-bar`` family: its closure of the bar's grid (one
    horizon of fictitious layers, extrapolated to ``order``)."""
    return functools.partial(fictitious_closure, order=params["order"])


def _check_flux_order(nodes, params, where) -> None:
    _check_taylor((nodes,), params, where)


def _bond_taylor(problem: BondProblem, params: Params) -> BondSystem:
    """Taylor's role in the ``bond-box`` family (seed 000 §7: the bond-based form)."""
    return assemble_bond_box(problem, params["order"], "real")


def _bond_surface(problem: BondProblem, params: Params) -> BondSystem:
    """The surface nodes' role in the ``bond-box`` family (seed 001 read for bond-based
    PD: ``corrections.bond_fictitious``)."""
    return assemble_bond_box(problem, params["order"], "surface")


def _check_bond_surface(cells, p, where) -> None:
    N = p["order"]
    need = max(N + 1, 2 * ((N + 1) // 2) + 1)
    for name, n in zip("xyz", cells):
        if n < need:
            raise InputError(f"{where}: {n} cells along {name}; order {N} needs at least "
                             f"{need} for the Taylor stencils")


def _bond_pddo(problem: BondProblem, params: Params) -> BondSystem:
    """PDDO's role in the ``bond-box`` family (seed 001 §5.3 read for bond-based PD:
    ``corrections.pddo_bond``)."""
    return assemble_bond_pddo(problem)


def _bond_mirror(problem: BondProblem, params: Params) -> BondSystem:
    """The mirror nodes' role in the ``bond-box`` family (seed 001 §5.2 read for
    bond-based PD, the traction relation with the lattice's C11, C12, C66:
    ``corrections.mirror_nodes.assemble_mirror_bond_box``)."""
    return assemble_mirror_bond_box(problem, params["neumann"], params["mirror_point"],
                                    params.get("gradient_at", "mirror"))


def _check_bond_mirror(cells, p, where) -> None:
    """The mirror point of the layer's outermost fictitious node lies ceil(m) cells
    inside the face; a body thinner than that along an axis has no node there."""
    import math
    m = next((p[k] for k in ("m_ratio", "horizon_ratio") if k in p), None)
    if m is None:
        m = p["horizon"] / p["spacing"]
    reach = math.ceil(m - 1e-9)     # the layer's cells (a rounding of m's product: 1e-9)
    for name, n in zip("xyz", cells):
        if n < reach:
            raise InputError(f"{where}: {n} cells along {name}; the mirror nodes of a layer "
                             f"{reach} cells thick need at least {reach}")


BOTH = ("state-based", "bond-based")


def family_treatments() -> list[Treatment]:
    return [
        FamilyTreatment(
            BASELINE, "uncorrected PD: truncated neighbourhoods, BCs on the nodes nearest "
            "the boundary", "the papers' baseline (seed 000 §5, seed 001 §4)",
            params=(LOAD_POINT,), families=FAMILY, build=_none, baseline=True, shapes=True,
            shapes3d=True,
            roles=(("wave-bar", Role(_truncated)), ("flux-bar", Role(_truncated)))),
        FamilyTreatment(
            "taylor-fictitious", "seed 000: fictitious layer by nearest-node Taylor "
            "extrapolation (1D series along the normal; corners by Eq. 69), Dirichlet and "
            "Neumann conditions via Lagrange multipliers (Eqs. 58, 60, 63)",
            "Scabbia, Zaccariotto, Galvanetto 2021 (seed 000)", params=(ORDER, CORNERS),
            theories=BOTH, dims=(1, 2, 3), families=FAMILY, footprint="fictitious",
            scope="state-based 1D, 2D and 3D (3D is our extension). 3D at the seed-001 "
                  "boxes' h = 0.05: 35-40 s and 2.1-2.2 GB (bordered system under nested "
                  "dissection, 6.1-6.5 M non-zeros); one flux row of each edge cell's "
                  "complementary shear pair is dropped (else near-singular: "
                  "taylor_fictitious.assemble_taylor). body3d-manufactured's quick grid "
                  "(10 x 5 x 5 cells) keeps 2 dependent constraint rows and fails as "
                  "near-singular. On a shape (not a box) the series runs along the local "
                  "normal with derivatives from a least-squares fit, the conditions at "
                  "boundary points (corrections.shape_fictitious; corners unused; on a 3D "
                  "shape every part not prescribing a component takes the fit's "
                  "traction row, and grids whose condition rows outnumber the unknowns "
                  "fail as singular, named). "
                  "Bond-based (seed 000 §7): the 2D boxes and seed 004's static bars that "
                  "state their conditions at the surface (corrections.bond_fictitious)",
            build=_taylor, checker=_check_taylor, shapes=True, shapes3d=True, cracks=True,
            static_only="its conditions are Lagrange constraint rows, so the dynamics "
                        "would be a differential-algebraic system",
            roles=(("flux-bar", Role(_flux_order, (ORDER,), _check_flux_order)),
                   ("bond-box", Role(_bond_taylor, (ORDER,), check_bond_box)))),
        FamilyTreatment(
            "surface-nodes", "seeds 001/002: surface nodes carry the boundary conditions, "
            "fictitious layer by Taylor extrapolation about the nearest surface node",
            "Scabbia, Zaccariotto, Galvanetto 2023 (seed 001); seed 002",
            params=(SURFACE_ORDER,), theories=BOTH, families=FAMILY, footprint="surface",
            build=_surface, checker=_check_surface, shapes=True, shapes3d=True,
            cracks=True,
            scope="state-based boxes, shapes and 1D waves; on a shape the surface nodes sit "
                  "at the boundary nodes' points on each part, the series about the nearest "
                  "one runs along the local normal with derivatives from a least-squares "
                  "fit, arcs take the series' traction, on a 3D shape every part does "
                  "(surface_nodes.surface_nodes_on_shape: our generalisation); bond-based: "
                  "the 2D boxes and seed 004's static bars that state their conditions at "
                  "the surface (corrections.bond_fictitious: what seed 001 leaves open for "
                  "bond-based PD)",
            roles=(("wave-bar", Role(wave_extension, (WAVE_ORDER,), check_wave_order)),
                   ("bond-box", Role(_bond_surface, (SURFACE_ORDER,), _check_bond_surface)))),
        FamilyTreatment(
            "mirror-nodes", "seed 001 §5: a delta-thick fictitious layer whose nodes copy "
            "mirror nodes inside the body (odd reflection for Dirichlet components, the "
            "traction through the Neumann relation)",
            "Zhao, Jafarzadeh, Chen, Bobaru 2020; seed 001 §5.2", params=MIRROR_PARAMS,
            theories=BOTH, families=FAMILY, footprint="fictitious",
            scope="state-based; the mirror relation (Dirichlet or traction) is chosen "
                  "per boundary cell face, on a shape (2D or 3D) per fictitious node at "
                  "its closest point, the reflection across the local tangent line or "
                  "plane and the traction relation with the local normal "
                  "(mirror_nodes.MirrorNodesOnShape: our generalisation); bond-based: the "
                  "boxes and seed 004's static bars that state their conditions at the "
                  "surface, the traction relation with the lattice's C11, C12, C66 "
                  "(mirror_nodes.assemble_mirror_bond_box: our reading)",
            build=_mirror, checker=_check_mirror, shapes=True, shapes3d=True,
            cracks_why="crack faces are not served yet: its shape form puts a face's mirror "
                       "nodes across the face, where on a slit they land among the other "
                       "face's real nodes; it needs one-sided bonds to ghosts carrying the "
                       "reflected field of the end's own side (Closure.ghosts, which the "
                       "engine does not yet take with a per-component map, "
                       "displacement_map_full)",
            static_only="its fictitious nodes carry an affine offset of the prescribed "
                        "values, fixed at assembly",
            roles=(("bond-box", Role(_bond_mirror, MIRROR_PARAMS, _check_bond_mirror)),)),
        FamilyTreatment(
            "pddo", "seed 001 §5: peridynamic differential operator (moment matrices exact "
            "for quadratics) for the boundary rows and the equilibrium within 2 delta, LPS "
            "beyond", "Behera, Roy, Anicode, Madenci, Spencer 2022; seed 001 §5.3",
            params=PDDO_PARAMS, theories=BOTH, families=FAMILY,
            scope="state-based; the boundary row (Dirichlet or traction) is chosen per "
                  "boundary node; on a shape (2D or 3D) at each boundary node's points "
                  "with the part's local normal (pddo.pddo_shape_system: our "
                  "generalisation). Bond-based: the 2D and 3D boxes and seed 004's static "
                  "bars that state their conditions at the surface, the rows with the "
                  "lattice's own elasticity tensor and the bond-based equations beyond 2 "
                  "delta (corrections.pddo_bond)",
            build=_pddo, shapes=True, shapes3d=True,
            cracks_why="crack faces are not served yet: its shape form's boundary rows fit "
                       "their PDDO functions over the nodes near a face, on a slit both "
                       "faces' nodes; it needs one-sided families for the faces' rows and "
                       "one-sided bonds across the slit (Closure.ghosts)",
            static_only="its boundary rows on the outer node layer are algebraic "
                        "equations, not a mass's equation of motion",
            roles=(("bond-box", Role(_bond_pddo)),)),
    ]


CORRECT_SIDES = Param("correct_sides", False, "apply the directional correction on the free "
                      "sides (variant 4)")


def hand_wired() -> list[Treatment]:
    """Treatments only their own scenes implement; ``scope`` says where and why."""
    return [
        Treatment("virtual-nodes", "seed 003 §4.1.2: buffer layers of thickness delta "
                  "outside the clamped edges, displaced rigidly (bond-based)",
                  "seed 003 §4.1.2", theories=("bond-based",), footprint="fictitious",
                  roles=(("clamped-sheet", Role(clamp, (CORRECT_SIDES,), check_layers)),
                         ("held-face", Role(held_face))),
                  scope="bond-based bodies with a face held in every component: the "
                        "clamped sheet (its own grid, variants 2 and 4) and the held-face "
                        "scenes (buffer rows beyond the held face, variant 2)",
                  theory_refusal="bond-based (seed 003 §4.1.2: a rigid buffer beyond a "
                                 "clamp, its nodes carrying no state of their own); an LPS "
                                 "buffer node needs a dilatation and enters its neighbours' "
                                 "m, which the paper does not give, and most state-based "
                                 "scenes prescribe a varying field on a face (the plates) "
                                 "or its normal component only (body3d), where no buffer "
                                 "is rigid"),
        Treatment("fem", "classical-elasticity FEM reference (reference_fem)",
                  "scikit-fem", scope="the reference of the scenes whose reference is FEM"),
    ]
