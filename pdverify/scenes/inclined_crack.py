"""The inclined centre crack (issue 54): mixed mode, 2D state-based PD against the converged
FEM reference of ``reference_fem.inclined_crack``.

A subclass of ``plate-crack`` (:class:`~.cracks.CrackPlate`): the same plate outline,
pins, remote tension, PD model and treatments (imported, not reshaped); what differs is
the crack's angle, the reference (the whole plate, no mirror images) and K, which is
read in both modes by the annulus fit (``pdverify.pd.cracks.fit_k_mixed``) because the
lattice has no node pairs mirrored about a crack that is not along its rows.
"""
from __future__ import annotations

import math

import numpy as np

from ..errors import InputError
from ..pd.cracks import fit_k_mixed
from ..pd.shapes import Crack
from . import register, whole_cells
from .cracks import TIP_ZONE, CrackPlate, plate_outline
from .shapes import ShapeScene

#: the K fit's outer radius as a fraction of min(a, the distance from the tip to the
#: plate's edge): inside the series' disk of convergence (the other tip at 2a, the edge)
REACH = 0.8

#: the FEM study's fields that are not parameters of this scene (the reference's stated
#: choice of J domains)
_FEM_FIXED = ("j_radii",)


def inclined_plate(width: float, height: float, crack: float, angle: float, spacing: float):
    """``plate_outline`` with the centre crack of half-length ``crack`` at ``angle``
    degrees to the x axis, as two cracks from the centre (``right`` to a e, ``left`` to
    -a e, e = (cos angle, sin angle)). A crack of zero length is no crack."""
    b = math.radians(angle)
    t = (crack * math.cos(b), crack * math.sin(b))
    return plate_outline(width, height, spacing).with_cracks(
        Crack("right", (0.0, 0.0), t), Crack("left", (0.0, 0.0), (-t[0], -t[1])))


def tip_length(p) -> float:
    """min(a, the distance from the right tip a e to the plate's edge)."""
    b = math.radians(p["angle"])
    tx, ty = p["crack"] * math.cos(b), p["crack"] * math.sin(b)
    return min(p["crack"], p["width"] - tx, p["height"] - abs(ty))


@register
class InclinedCrackPlate(CrackPlate):
    """A plate with an inclined centre crack under remote tension, mixed mode, plane
    stress (issue 54): the full plate [-W, W] x [-H, H] (W = H = 1 m) with the crack of
    length 2a (a = 0.5 m) through the centre at beta = 30 degrees to the x axis.

    The problem: as ``plate-crack`` (the traction (0, +-traction) on y = +-H; the crack
    faces and x = +-W free; the rigid motions by the four pins of length h/2 at the
    middles of the edges at the FEM's values, which here do not vanish: O(h) small),
    the crack two ``Crack`` parts from the centre.

    The lattice is not aligned with the crack: the slit crosses cells, so the nodes
    beside it lie at every distance from 0 to h from the line (at 30 degrees none on it:
    tan 30 is irrational), a bond is cut when its ends lie on different sides and it
    crosses the slit (``pdverify.pd.shapes``; the cut pattern changes from node to node
    along the crack, the faces' nodes are a staircase), and the faces' boundary samples
    go to the cell's node, which may sit on the other side (``pd.shapes``: a treatment
    that loads or constrains a face would need the side's nodes; the bond methods here
    do neither, their closures only drop the cut bonds).

    FEM (``fem``): ``reference_fem.inclined_crack``, the whole plate on Q2 elements graded
    toward both tips, K_I and K_II by the interaction integral (its docstring: converged,
    the large plate within 0.05 % of Tada's K_0), cached; its ``j_radii`` fixed.

    PD: as ``plate-crack`` (LPS, hyperbolic influence, ``partial-volume``, m = 3, h = 1/40
    m; ``spacing`` must divide W and H). Treatments: as ``plate-crack`` (the uncorrected
    model, the bond methods and Taylor's one-sided fictitious nodes at order 1; the
    faces at an angle to the lattice take the one-sided fit's traction, not the force
    flux: ``shape_fictitious.lattice_flux``) and LAMMPS (as on ``plate-crack``); the
    other node-adding ones refused (``list``: what each would need).

    Metrics: ``k1_ratio``, ``k2_ratio`` = K_PD / K_FEM, K_PD by ``fit_k_mixed`` at the
    right tip (Williams orders 1..5 of both modes and a translation fitted to both
    displacement components of every node in the annulus r in [2 horizons, 0.8 min(a,
    the tip's distance to the edge)]; K_FEM the reference's interaction integral);
    ``k_error_pct`` = 100 |K_PD - K_FEM| / |K_FEM| of the vector (K_I, K_II), the headline;
    ``k1_fit_bias_pct``, ``k2_fit_bias_pct``: the same fit on the FEM field at the PD
    nodes against K_FEM (the fit's own error on this grid); ``max_error_pct`` (also
    ``boundary_`` within a horizon of any boundary, crack faces included, and
    ``interior_``) and ``rel_l2_error`` over the nodes outside the tip zone (2 horizons
    of either tip); ``tip_zone_nodes``; ``reference_change_pct``.

    Cases: ``fem`` and every method at the defaults, no refinement (as ``plate-crack``);
    the quick report at h = 1/30. The refinement at m = 3 (h = 1/30, 1/40, 1/60) is
    ``benchmarks/inclined_crack_k.py``'s (its docstring: the levels are pre-asymptotic,
    K within 1 % for none; ``energy`` closest in K_I and halving the field error;
    ``volume`` worse than none in the field; ``pals`` the best field, the worst K_II).
    """

    id = "plate-inclined-crack"
    title = ("Plate with an inclined centre crack under remote tension, mixed mode "
             "(2D state-based, FEM)")
    seed = "ours (issue 54; Tada's handbook K_I, K_II as the check)"
    params_class, function = "InclinedCrackParams", "inclined_crack"
    shared = ("width", "height", "crack", "angle", "thickness", "E", "nu", "traction")
    headline = "k_error_pct"
    delta_sweep = ()
    quick_spacing = 1 / 30
    fem_fixed = _FEM_FIXED

    @property
    def table_metrics(self):
        return ("k1_ratio", "k2_ratio", "max_error_pct", "rel_l2_error")

    def shape(self, p):
        return inclined_plate(p["width"], p["height"], p["crack"], p["angle"], p["spacing"])

    def box(self, p):
        W, H = p["width"], p["height"]
        return (2 * W, 2 * H), (-W, -H)

    def reference_field(self, p):
        return self.reference_of(p).evaluate

    def check_pd(self, where, method, p):
        ShapeScene.check_pd(self, where, method, p)     # the shape scenes' checks only
        h = p["spacing"]
        whole_cells(where, h, [("width", p["width"]), ("height", p["height"])])
        try:
            self._cls()(**{k: p[k] for k in self.shared})
        except (TypeError, ValueError) as exc:
            raise InputError(f"{where}: {exc}") from None
        if not p["angle"] >= 5:
            raise InputError(f"{where}: angle={p['angle']!r}: allowed 5 to 60 degrees here "
                             "(K_II vanishes at 0, so its ratio has no meaning; the crack "
                             "along the rows is plate-crack)")
        reach = REACH * tip_length(p)
        if not TIP_ZONE * p["m_ratio"] * h + 2 * h <= reach:
            raise InputError(f"{where}: the K fit's annulus r in [{TIP_ZONE:g} horizons, "
                             f"{REACH:g} x {tip_length(p):g}] = [{TIP_ZONE * p['m_ratio'] * h:g}, "
                             f"{reach:g}] m is thinner than two spacings; allowed: a "
                             "smaller spacing or m_ratio, or a shorter crack")

    def measure(self, p, problem, system, x, info):
        ref = self.reference_of(p)
        b = math.radians(p["angle"])
        e = np.array([math.cos(b), math.sin(b)])
        tip = p["crack"] * e
        x_int, u, u_ref, err, metrics = self.field_away_from_tips(
            p, problem, system, x, [tip, -tip])
        delta = system.model.horizon
        kw = dict(E=p["E"], nu=p["nu"], plane="plane-stress", horizon=delta,
                  reach=REACH * tip_length(p), tip_zone=TIP_ZONE)
        fit = fit_k_mixed(x_int, u, tip, e, **kw)
        fem = fit_k_mixed(x_int, u_ref, tip, e, **kw)
        d1, d2 = fit.k1 - ref.k1, fit.k2 - ref.k2
        metrics.update(
            k1_ratio=float(fit.k1 / ref.k1), k2_ratio=float(fit.k2 / ref.k2),
            k_error_pct=float(100 * math.hypot(d1, d2) / math.hypot(ref.k1, ref.k2)),
            k1_fit_bias_pct=float(100 * (fem.k1 / ref.k1 - 1)),
            k2_fit_bias_pct=float(100 * (fem.k2 / ref.k2 - 1)))
        return self.fem_outcome(p, system, info, metrics, err, x_int, u, u_ref,
                                self.box(p)[0])
