"""The distance from a point along a direction to where the ray first meets a shape's
boundary: seed 003's a of Eq. (14) (its Fig. 1) on a body that is not a box (issue 55).

:func:`exit_distance` takes a :class:`~pdverify.pd.shapes.Shape` (2D) or a
:class:`~pdverify.pd.shapes3d.Shape3D` and rows of points ``x`` (inside the body: the
real nodes) and unit directions ``e``; it returns, row by row, the smallest t > 0 at which
x + t e meets a boundary part (``inf`` when the ray meets none). Vectorised over the
rows; a loop over the few parts. Each part's crossing is the closed form of a line with
its curve or surface:

- a straight part (:class:`~pdverify.pd.shapes.Segment`): x + t e = a + u (b - a),
  solved by 2D cross products, u in [0, 1] (within :data:`~pdverify.pd.shapes.END`: a
  ray through a vertex meets both parts that end there);
- an arc (:class:`~pdverify.pd.shapes.Arc`): the roots of |x + t e - c|^2 = r^2 whose
  point lies in [theta0, theta1] (within END); a tangent ray does not meet it;
- a crack (:class:`~pdverify.pd.shapes.Crack`, both faces at once): the ray meets the
  slit where it crosses from the point's side to the other, at u in [0, 1) of
  start -> tip, the convention of :meth:`Crack.cuts` (a ray through the tip itself
  passes round it: the ligament ahead of the tip is intact); a point on the crack's
  line (the ``+`` side) heading to the ``-`` side meets it at t = 0;
- in 3D a plane part (:class:`~pdverify.pd.shapes3d.Planar`): the plane's crossing
  t = (o - x).n / (e.n) with its point inside the part's region (within END of the
  region's size); the mantle (:class:`~pdverify.pd.shapes3d.Mantle`): the roots of the
  circle in (x, y) with the point's angle in [0, theta1] and z in [0, L]; the cavity
  (:class:`~pdverify.pd.shapes3d.SphereOctant`): the roots of the sphere with the point
  in the octant.

On a box (a rectangle of four segments, a block of six planes) this is the slab form of
``corrections.energy_directional.ray_distance`` to round-off (the same quotient of a
face's offset by the direction's component, formed in another order: tested).

What the first crossing means for Eq. 14: the direction's material is taken to be the
radial interval [0, a]. Where the ray leaves the body and re-enters it within the
horizon (a chord across a notch, the L seen from its other arm) the model keeps the
bonds beyond the gap, so the direction holds more than [0, a]: :func:`inside_intervals`
gives the parts of the ray's horizon in the body (up to a crack's slit, which ends it),
from which ``corrections.energy_directional.directional_factor`` takes Eq. 14's
denominator there. A bond of the partial-volume quadrature longer than the horizon is
not on the ray's horizon (as on a box, the factor counts [0, delta] only).
"""
from __future__ import annotations

import numpy as np

from .shapes import END, Arc, CrackFace, Segment


def _first(t, hit):
    """t where ``hit``, else inf."""
    return np.where(hit, t, np.inf)


def _cross(p, q):
    return p[..., 0] * q[..., 1] - p[..., 1] * q[..., 0]


def _segment(q: Segment, x, e):
    a, b = np.asarray(q.a, float), np.asarray(q.b, float)
    E = b - a
    den = _cross(e, E)
    ok = den != 0
    den = np.where(ok, den, 1.0)
    w = a - x
    t = _cross(w, E) / den
    u = _cross(w, e) / den
    return _first(t, ok & (t > 0) & (u >= -END) & (u <= 1 + END))[:, None]


def _roots(f, e, radius):
    """The two roots t of |f + t e|^2 = radius^2 (rows) and where they are real and
    distinct."""
    A = np.einsum("ij,ij->i", e, e)
    ok = A > 0
    A = np.where(ok, A, 1.0)
    bq = np.einsum("ij,ij->i", f, e) / A
    cq = (np.einsum("ij,ij->i", f, f) - radius ** 2) / A
    disc = bq * bq - cq
    real = ok & (disc > 0)
    root = np.sqrt(np.where(real, disc, 0.0))
    return (-bq - root, -bq + root), real


def _arc(q: Arc, x, e):
    c = np.asarray(q.centre, float)
    (t0, t1), real = _roots(x - c, e, q.radius)
    out = []
    for t in (t0, t1):
        p = x + t[:, None] * e - c
        th = np.arctan2(p[:, 1], p[:, 0])
        th = q.theta0 - END + np.mod(th - q.theta0 + END, 2 * np.pi)
        on = (th >= q.theta0 - END) & (th <= q.theta1 + END)
        out.append(_first(t, real & (t > 0) & on))
    return np.stack(out, axis=1)


def _crack(c, x, e):
    s = np.asarray(c.start, float)
    E = np.asarray(c.tip, float) - s
    plus = c.side(x)
    turn = _cross(E[None, :], e)       # > 0: e points to the + side (left of start -> tip)
    across = np.where(plus, turn < 0, turn > 0)
    den = np.where(across, _cross(e, E), 1.0)
    w = s - x
    t = np.maximum(_cross(w, E) / den, 0.0)
    u = _cross(w, e) / den
    return _first(t, across & (u >= -END) & (u < 1 - END))


def _planar(q, x, e):
    o, e1, e2 = (np.asarray(v, float) for v in (q.origin, q.e1, q.e2))
    n = np.asarray(q.normal, float)
    den = e @ n
    ok = den != 0
    t = ((o - x) @ n) / np.where(ok, den, 1.0)
    r = x + t[:, None] * e - o
    s, v = r @ e1, r @ e2
    if q.region == "rect":
        A, B = q.size
        tol = END * max(A, B)
        inside = (s >= -tol) & (s <= A + tol) & (v >= -tol) & (v <= B + tol)
    elif q.region == "quarter-disk":
        (R,) = q.size
        tol = END * R
        inside = (s >= -tol) & (v >= -tol) & (s * s + v * v <= R * R * (1 + END))
    else:
        W, a = q.size
        tol = END * W
        inside = ((s >= -tol) & (s <= W + tol) & (v >= -tol) & (v <= W + tol)
                  & (s * s + v * v >= a * a * (1 - END)))
    return _first(t, ok & (t > 0) & inside)[:, None]


def _mantle(q, x, e):
    (t0, t1), real = _roots(x[:, :2], e[:, :2], q.radius)
    out = []
    for t in (t0, t1):
        p = x + t[:, None] * e
        th = np.arctan2(p[:, 1], p[:, 0])
        th = -END + np.mod(th + END, 2 * np.pi)
        on = ((th >= -END) & (th <= q.theta1 + END) & (p[:, 2] >= -END * q.length)
              & (p[:, 2] <= q.length * (1 + END)))
        out.append(_first(t, real & (t > 0) & on))
    return np.stack(out, axis=1)


def _sphere_octant(q, x, e):
    (t0, t1), real = _roots(x, e, q.radius)
    out = []
    for t in (t0, t1):
        p = x + t[:, None] * e
        on = np.all(p >= -END * q.radius, axis=1)
        out.append(_first(t, real & (t > 0) & on))
    return np.stack(out, axis=1)


def _part_roots(q, x, e):
    """(n, k): every crossing t > 0 of the ray with the part (k = 1 or 2), inf where
    none."""
    from .shapes3d import Mantle, Planar, SphereOctant
    if isinstance(q, Segment):
        return _segment(q, x, e)
    if isinstance(q, Arc):
        return _arc(q, x, e)
    if isinstance(q, Planar):
        return _planar(q, x, e)
    if isinstance(q, Mantle):
        return _mantle(q, x, e)
    if isinstance(q, SphereOctant):
        return _sphere_octant(q, x, e)
    raise TypeError(f"no ray crossing for the boundary part {getattr(q, 'name', q)!r} "
                    f"({type(q).__name__})")


def _rows(x, e):
    x = np.atleast_2d(np.asarray(x, dtype=float))
    e = np.atleast_2d(np.asarray(e, dtype=float))
    return x, np.broadcast_to(e, x.shape)


def _crack_stop(shape, x, e) -> np.ndarray:
    """The first crossing of a crack's slit along each ray (inf where none)."""
    stop = np.full(len(x), np.inf)
    for c in getattr(shape, "cracks", ()):
        if c.length:
            stop = np.minimum(stop, _crack(c, x, e))
    return stop


def _outline_roots(shape, x, e) -> np.ndarray:
    """(n, K): the crossings of every part but the crack faces."""
    roots = [_part_roots(q, x, e) for q in shape.parts if not isinstance(q, CrackFace)]
    return np.concatenate(roots, axis=1) if roots else np.full((len(x), 1), np.inf)


def exit_distance(shape, x, e) -> np.ndarray:
    """The smallest t > 0 with x + t e on a part of ``shape`` (module docstring), row by
    row; ``inf`` where the ray meets no part. ``x`` (n, D): points inside the body;
    ``e`` (n, D): directions (unit, for t to be a distance)."""
    x, e = _rows(x, e)
    return np.minimum(_outline_roots(shape, x, e).min(axis=1), _crack_stop(shape, x, e))


def inside_intervals(shape, x, e, reach: float):
    """The parts of each ray's [0, ``reach``] (a horizon) inside the body and reachable
    from its point: ``(edges, inside)``, ``edges`` (n, K + 2) the sorted crossings with
    the parts, 0 first and the ray's end last, ``inside`` (n, K + 1) whether the
    interval between two edges lies in the body (its midpoint inside, the interval not
    empty). A crack's slit ends the ray there (the model cuts every bond across it, so
    nothing beyond it is the point's); a hole or a notch does not (the model keeps the
    bonds across a gap in the body, so the material beyond it is the point's again).
    Vectorised; a loop over the parts."""
    x, e = _rows(x, e)
    stop = np.minimum(_crack_stop(shape, x, e), float(reach))
    roots = np.sort(np.minimum(_outline_roots(shape, x, e), stop[:, None]), axis=1)
    edges = np.concatenate([np.zeros((len(x), 1)), roots, stop[:, None]], axis=1)
    lo, hi = edges[:, :-1], edges[:, 1:]
    full = hi > lo
    mid = x[:, None, :] + (0.5 * (lo + hi))[:, :, None] * e[:, None, :]
    inside = np.zeros(lo.shape, dtype=bool)
    inside[full] = shape.inside(mid[full])
    return edges, inside
