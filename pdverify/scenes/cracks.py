"""Cracked bodies (issue 54): the centre-cracked plate under mode I, 2D state-based PD
against the converged FEM reference of ``reference_fem.crack_plate``.

The plate is a ``static-state`` shape scene (:mod:`.shapes`): the body is the full plate
cut from its box's lattice, the crack two :class:`~pdverify.pd.shapes.Crack` parts whose
cut bonds every bond method drops (``pdverify.pd.closure.Closure.bond_mask``). The
builder of the plate, its conditions and the FEM field on the whole plate are here once;
``benchmarks/crack_k.py`` (the study before this scene) imports them.
"""
from __future__ import annotations

import numpy as np

from ..errors import InputError
from ..metrics import rel_l2_error
from ..pd.cracks import fit_k, opening_pairs
from ..pd.problem import FaceCondition
from ..pd.shapes import Crack, polygon
from . import register, whole_cells
from .base import MethodSpec
from .fem_references import FemAndPD
from .shapes import ShapeScene, shape_errors

#: the tip zone left out of the field metrics and of the K fit, in horizons: the nonlocal
#: zone where a PD tip and LEFM cannot agree (``pdverify.pd.cracks``, fit_k's tip_zone)
TIP_ZONE = 2.0


def plate_outline(width: float, height: float, spacing: float):
    """The full plate [-W, W] x [-H, H] without a crack: the edges' parts ``y-a``,
    ``pin-b``, ``y-b`` (bottom), ``x+a``, ``pin-r``, ``x+b`` (right), ``y+a``, ``pin-t``,
    ``y+b`` (top), ``x-a``, ``pin-l``, ``x-b`` (left), the ``pin-*`` of length
    spacing / 2 at the middles of the edges."""
    W, H, e = width, height, spacing / 4
    v = [(-W, -H), (-e, -H), (e, -H), (W, -H), (W, -e), (W, e), (W, H), (e, H), (-e, H),
         (-W, H), (-W, e), (-W, -e)]
    names = ("y-a", "pin-b", "y-b", "x+a", "pin-r", "x+b", "y+a", "pin-t", "y+b", "x-a",
             "pin-l", "x-b")
    return polygon(v, names, "cracked plate")


def cracked_plate(width: float, height: float, crack: float, spacing: float):
    """:func:`plate_outline` with the centre crack of half-length ``crack`` along y = 0, as
    two cracks from the centre (``right`` to (a, 0), ``left`` to (-a, 0)). A crack of
    zero length is no crack (``pdverify.pd.shapes``)."""
    return plate_outline(width, height, spacing).with_cracks(
        Crack("right", (0.0, 0.0), (crack, 0.0)), Crack("left", (0.0, 0.0), (-crack, 0.0)))


def crack_conditions(traction: float) -> dict:
    """The remote tension (0, +-traction) on y = +-H (the ``pin-t``, ``pin-b`` parts too),
    u_x prescribed on ``pin-t`` and ``pin-b``, u_y on ``pin-l`` and ``pin-r`` (the rigid
    motions; the values are the problem's ``exact``); the crack faces and x = +-W free."""
    def up(x, n):
        return np.c_[np.zeros(len(x)), np.full(len(x), traction)]

    def down(x, n):
        return np.c_[np.zeros(len(x)), np.full(len(x), -traction)]
    t, b = FaceCondition(traction=up), FaceCondition(traction=down)
    return {"y+a": t, "y+b": t, "y-a": b, "y-b": b,
            "pin-t": FaceCondition(prescribed=(0,), traction=up),
            "pin-b": FaceCondition(prescribed=(0,), traction=down),
            "pin-l": FaceCondition(prescribed=(1,)), "pin-r": FaceCondition(prescribed=(1,))}


def mirrored(field):
    """The quarter model's field on the whole plate: u_x odd in x, u_y odd in y (a point
    on y = 0 maps to the upper face, as the reference evaluates it)."""
    def value(x):
        x = np.asarray(x, float)
        u = field.evaluate(np.abs(x))
        return u * np.sign(np.where(x == 0, 1.0, x))
    return value


#: the FEM study's fields that are not parameters of this scene: the centre crack (the
#: edge crack is another problem) and the extraction's radii and window (tuples, the
#: reference's stated choices)
_FEM_FIXED = ("kind", "j_radii", "fit_window")

#: why the treatments that add nodes do not run here
_NO_CRACK_FACES = (
    "crack faces are not served yet: the node-adding treatments on shapes "
    "(corrections.shape_fictitious and the surface-node, mirror-node and PDDO forms built "
    "on it) would see each crack face as a straight part (fictitious or mirror nodes along "
    "its normal, across the slit into the other face's material, and boundary rows on it); "
    "a slit has no outside to extrapolate into")


@register
class CrackPlate(ShapeScene):
    """A plate with a centre crack under remote tension, mode I, plane stress (issue 54):
    the full plate [-W, W] x [-H, H] (W = 1 m, H = 3 m) with the crack of length 2a
    (a = 0.5 m) along y = 0.

    The problem, stated once: the traction (0, +-traction) on y = +-H; the crack faces and
    x = +-W free; the rigid motions by four parts of length h/2 at the middles of the
    edges (``pin-l``, ``pin-r`` on x = -+W prescribe u_y; ``pin-b``, ``pin-t`` on y = -+H
    prescribe u_x and carry the traction too), each at the FEM's value (components that
    vanish on the symmetry lines: O(h) small). The full plate, not a quarter: this family
    imposes a symmetry plane's component on the nearest node layer, which ahead of a tip
    would keep bonds that the crack cuts in the mirror half. The crack is two ``Crack``
    parts from the centre (``right``, ``left``; ``pdverify.pd.shapes``: the bonds that cross
    the slit are cut, those round a tip kept), so both tips follow the same conventions.

    FEM (``fem``): ``reference_fem.crack_plate``, the quarter model on Q2 elements graded
    toward the tip, K from J (its docstring: converged, within Tada's stated accuracy),
    cached like the other references; evaluated at the PD nodes by the quarter's
    symmetry (u_x odd in x, u_y odd in y). Its fields ``kind`` (the centre crack),
    ``j_radii`` and ``fit_window`` are fixed at the reference's defaults.

    PD: 2D linear state-based (LPS), hyperbolic influence, plane-stress constants,
    ``partial-volume`` quadrature, m = 3, cell-centred nodes at h = 1/40 m (the crack line
    and the tips on cell faces: ``spacing`` must divide W, H and a), as
    ``benchmarks/crack_k.py`` (the study this scene repeats). Treatments: the uncorrected
    model and every bond method of the family that serves shapes (their closures drop
    the cut bonds); the treatments that add nodes are refused (``list`` gives the reason:
    crack faces are not served yet).

    Metrics: ``k_ratio`` = K_PD / K_FEM (``pdverify.pd.cracks.fit_k`` at the right tip:
    the Williams fit of the opening of the two node rows nearest the crack on each side,
    window r in [2 horizons, 0.8 min(a, W - a)]; K_FEM the reference's K from J) and
    ``k_error_pct`` = 100 (k_ratio - 1), the headline; ``k_fit_bias_pct``: the same fit
    on the FEM field at the PD nodes against K_FEM (the fit's own error on this grid,
    which the PD number carries too); ``opening_error_pct``: the largest |opening_PD -
    opening_FEM| of the mirrored pairs of the rows nearest the crack behind the right tip
    at r >= 2 horizons, in % of the largest FEM opening there; ``max_error_pct`` (largest
    component error in % of max |u_FEM|; also over the ``boundary_`` layer within one
    horizon of the boundary, crack faces included, and the ``interior_``) and
    ``rel_l2_error``, both over the nodes outside the tip zone (within 2 horizons of
    either tip: the nonlocal zone, as the fit's window; ``tip_zone_nodes`` counts them);
    ``reference_change_pct``. The error maps show every node, the tip zone included.

    Cases: ``fem`` and every method at the defaults; no refinement (its time and the
    budget's estimate at h = 1/60 are past the report's limits: the comment at
    ``delta_sweep``); the study's three levels are ``benchmarks/crack_k.py``'s. The quick
    report runs every method at h = 1/30 (``quick_spacing``). What the study found (its
    docstring, not retyped here): the uncorrected model reads K low by a few per cent,
    falling with h; ``volume`` is worse than none; ``energy`` comes closer in K than in
    the opening. The solves are nested dissection (``fixed_solver``).
    """

    id = "plate-crack"
    title = "Plate with a centre crack under remote tension, mode I (2D state-based, FEM)"
    seed = "ours (issue 54; Tada's handbook K as the check)"
    params_class, function = "CrackPlateParams", "crack_plate"
    shared = ("width", "height", "crack", "thickness", "E", "nu", "traction")
    headline = "k_error_pct"
    #: ``export`` and ``score`` refuse it (``pdverify.exchange``)
    export_refusal = ("a node set does not carry the crack: the code that reads it builds "
                      "its own bonds from the positions and would bond across the slit")
    #: nested dissection (``solvers.policy``): the direct solve under plate-hole's
    #: ordering took 4-7x longer on this 80 x 240 lattice (report --only plate-crack: 20 s
    #: at h = 1/40, 119 s at 1/80, under load), the study's auto choice 3 and 18 s
    fixed_solver = "auto"
    #: no refinement in the report: the study's levels 1/60 and 1/80 (m = 3) are past the
    #: report's budgets. Three levels took ``report --only plate-crack`` to 84 s (load ~4)
    #: and 62 s (load ~1.3), past the 60 s the scene may add; two levels (23 s) are
    #: estimated at 5.6 GB at 1/60 (``budget.linear_system``'s sparse LU; measured peak
    #: 1.96 GB under nested dissection), past the 4 GB every report case must stay under
    #: (tests/reliability/test_budget.py). The refinement is ``benchmarks/crack_k.py``'s.
    delta_sweep = ()

    @property
    def methods(self):
        (fem,) = FemAndPD.methods.fget(self)
        return (MethodSpec(fem.name, tuple(q for q in fem.params
                                           if q.name not in _FEM_FIXED)),)

    #: the quick report's grid (m = 3): 60 x 180 nodes, about half the default's time;
    #: the fit's window [2 delta, 0.4 m] = [0.2, 0.4] m still holds 6 pairs a row (at 1/20
    #: it would hold 2, as many as the fit's orders)
    quick_spacing = 1 / 30

    @property
    def table_metrics(self):
        return ("k_ratio", "opening_error_pct", "max_error_pct", "rel_l2_error")

    def family_refusal(self, treatment):
        out = super().family_refusal(treatment)
        if out is not None:
            return out
        if getattr(treatment, "peer", False):
            return ("its code builds its own bonds from the node positions, so it would "
                    "bond across the crack; crack faces are not served yet")
        if not (treatment.kind == "closure" or getattr(treatment, "baseline", False)):
            return _NO_CRACK_FACES
        return None

    def shape(self, p):
        return cracked_plate(p["width"], p["height"], p["crack"], p["spacing"])

    def conditions(self, p):
        return crack_conditions(p["traction"])

    def box(self, p):
        W, H = p["width"], p["height"]
        return (2 * W, 2 * H), (-W, -H)

    def reference_field(self, p):
        return mirrored(self.reference_of(p).field)

    def check_pd(self, where, method, p):
        super().check_pd(where, method, p)
        h, W, H, a = p["spacing"], p["width"], p["height"], p["crack"]
        # the crack line, the tips and the pins' middles on cell faces
        whole_cells(where, h, [("width", W), ("height", H), ("crack", a)])
        if p["jitter"] != 0:
            raise InputError(f"{where}: jitter={p['jitter']!r}: allowed 0 only (the K fit "
                             "pairs the nodes mirrored about the crack on the lattice)")
        reach = 0.8 * min(a, W - a)
        if not TIP_ZONE * p["m_ratio"] * h + 2 * h <= reach:
            raise InputError(f"{where}: the K fit's window r in [{TIP_ZONE:g} horizons, "
                             f"0.8 min(a, W - a)] = [{TIP_ZONE * p['m_ratio'] * h:g}, "
                             f"{reach:g}] m holds fewer than two spacings; allowed: "
                             "a smaller spacing or m_ratio, or a crack nearer W / 2")

    def measure(self, p, problem, system, x, info):
        ref = self.reference_of(p)
        x_int = self.real_nodes(system)
        u, _ = self.solution(system, x)
        u_ref = self.reference_field(p)(x_int)
        h, delta, a = p["spacing"], system.model.horizon, p["crack"]
        _, err = shape_errors(x_int, u, u_ref, problem.shape, delta)
        tip = np.minimum(np.hypot(x_int[:, 0] - a, x_int[:, 1]),
                         np.hypot(x_int[:, 0] + a, x_int[:, 1]))
        away = tip >= TIP_ZONE * delta
        metrics, _ = shape_errors(x_int[away], u[away], u_ref[away], problem.shape, delta)
        metrics["rel_l2_error"] = rel_l2_error(u[away], u_ref[away])
        kw = dict(E=p["E"], nu=p["nu"], plane="plane-stress", horizon=delta, spacing=h,
                  crack_length=a, ligament=p["width"] - a, tip_zone=TIP_ZONE)
        fit = fit_k(x_int, u, (a, 0.0), (1.0, 0.0), **kw)
        fit_fem = fit_k(x_int, u_ref, (a, 0.0), (1.0, 0.0), **kw)
        r, _, op, t = opening_pairs(x_int, u, (a, 0.0), (1.0, 0.0), h)
        _, _, opf, _ = opening_pairs(x_int, u_ref, (a, 0.0), (1.0, 0.0), h)
        far = (t <= t.min() + 1e-6 * h) & (r >= TIP_ZONE * delta)
        metrics.update(
            k_ratio=float(fit.k / ref.k_j), k_error_pct=float(100 * (fit.k / ref.k_j - 1)),
            k_fit_bias_pct=float(100 * (fit_fem.k / ref.k_j - 1)),
            opening_error_pct=float(100 * np.abs(op[far] - opf[far]).max()
                                    / np.abs(opf[far]).max()),
            tip_zone_nodes=int(np.count_nonzero(~away)))
        return self.fem_outcome(p, system, info, metrics, err, x_int, u, u_ref,
                                self.box(p)[0])

    def cases(self, quick=False):
        runs = self.default_cases()
        out = [("fem", {})] + runs
        if quick:    # every method, on the quick grid
            return [("fem", {})] + [(m, {**q, "spacing": self.quick_spacing}) for m, q in runs]
        return out
