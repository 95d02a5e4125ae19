"""Bodies that are not boxes: 2D shapes cut from a uniform grid, with named boundary parts.

A :class:`Shape` is a region of the plane bounded by named parts (:class:`Segment`,
:class:`Arc`), with a vectorised inside test. What the grid and the treatments need of it,
for every point at once (no loop over nodes; a loop over the few parts):

- :meth:`Shape.closest`: the closest boundary point, its outward unit normal, the
  distance and the part it lies on;
- :meth:`Shape.sdf`: the signed distance (negative inside);
- :meth:`Shape.fractions`: the part of each grid cell inside the shape (cut-cell volume
  fractions), sampled on an ``s x s`` sub-grid of the cells the boundary can cut (1 or 0
  elsewhere). On a polygon whose edges lie on cell faces the fractions are exactly 1 or 0;
  across an arc the sampling error is below the cut length times h / s;
- :meth:`Shape.samples`: Gauss points along every part (3 per sub-segment of length at
  most ``h / SAMPLES_PER_CELL``) with their arc-length weights, normals and part, the
  quadrature of surface loads and the way boundary nodes are found.

Orientation: a :class:`Segment` runs with the body on its left (counter-clockwise around
the body), so its outward normal is the segment direction turned clockwise; an
:class:`Arc` says whether the body lies outside its circle (``hole=True``: the normal
points to the centre) or inside.

Cracks (:class:`Crack`, issue 54): a straight slit of zero width from ``start`` to its
``tip`` inside the body, carried by a shape beside its outer parts (``Shape.cracks``). Its
two traction-free faces are named parts like any other (:class:`CrackFace`, appended to
``Shape.parts``): ``<name>+`` is the face of the material on the left of start -> tip
(the side its left normal nu = the direction turned counter-clockwise points to), outward
normal -nu; ``<name>-`` the face of the material on the right, outward normal +nu. A face
is one-sided: a point sees it only from its own side (:meth:`CrackFace.sees`), so the
closest part of a node beside the crack is the face of its own side. Conventions, in
units of the crack (tolerance :data:`END` of its length):

- side: a point on the crack's line (within END) is on the ``+`` side;
- a bond is cut (:meth:`Crack.cuts`) when its two ends lie on different sides and it
  meets the line at arc-length fraction u in [0, 1) of start -> tip: a bond through the
  start point is cut (a centre crack is two cracks from its centre, and that point is
  cut by both), a bond through the tip point itself is not (the tip is where the faces
  meet: the ligament ahead of it, tip included, is intact), a bond that passes ahead of
  the tip is kept (it goes round the tip through intact material), and a bond with one
  end on the crack at a node is cut exactly when its other end is on the ``-`` side;
- a crack of zero length is no crack: no faces, no cut bond (the shape's arrays are
  those of the shape without it, bit for bit);
- near the tip: a node's neighbourhood loses only the bonds that cross the slit, so a
  node within a horizon of the tip keeps its bonds round the tip; its closest part is the
  face of its side with the tip as closest point when it lies ahead of it;
- every node is on a side by its position (a jittered node by its moved one; a
  fictitious node too: a bond between two fictitious nodes that crosses the crack's line
  outside the body, u < 0 beyond an edge crack's mouth, is not cut);
- the nodes of a face: :meth:`Shape.crack_nodes` (within a reach of the slit on the
  face's side); :meth:`Shape.closest` names the face of the node's side. The samples of
  a face go, like every part's, to the node of the cell that holds them moved inward
  (``corrections.assembly.boundary_nodes``): right for a slit along cell faces, but a
  slit through cells gives each such cell's node both faces' samples (a crack of slope
  1/2 and length 9 h: 108 of each face's 216 samples, on 4 of its 8 nodes, go to a node
  on the other side); a treatment that loads or constrains a crack face needs the
  side's nodes instead.

The model drops the bonds a crack cuts where its bonds are chosen
(``pdverify.pd.closure.Closure.bond_mask``, for every treatment's ``keep``), so the
weighted volumes, dilatations and forces of both theories see only the node's side.

Only 2D: the two shape scenes are plane problems (issue 35 asks for 2D scenes); a 3D
shape would need faces of a polyhedron, which nothing uses yet.
"""
from __future__ import annotations

from dataclasses import dataclass, replace
from typing import Callable

import numpy as np

#: sub-segments per grid spacing along a boundary part (3 Gauss points each)
SAMPLES_PER_CELL = 8
#: sub-grid per axis of the sampled cut-cell fractions
FRACTION_SAMPLES = 16
#: a crossing this close to a part's end (fraction of the part, or radians) is on the
#: end: it counts half for each of the two parts that meet there
END = 1e-12


@dataclass(frozen=True)
class Segment:
    """The straight boundary part ``name`` from ``a`` to ``b`` (body on its left)."""

    name: str
    a: tuple
    b: tuple
    straight = True

    def closest(self, x):
        a, b = np.asarray(self.a, float), np.asarray(self.b, float)
        t = b - a
        L2 = float(t @ t)
        s = np.clip(((x - a) @ t) / L2, 0.0, 1.0)
        p = a + s[:, None] * t
        n = np.array([t[1], -t[0]]) / np.sqrt(L2)
        return p, np.broadcast_to(n, p.shape).copy()

    @property
    def length(self) -> float:
        return float(np.linalg.norm(np.subtract(self.b, self.a)))

    def crossings(self, xa, xb):
        """Segments xa -> xb that cross this part: ``(segment, arc length of the
        crossing, sign, alpha)``: sign +1 when xa lies on the body's side of the part's
        line, alpha 1/2 at either end of the part (within :data:`END`; seed 001's rule on
        a cell face's edge), else 1."""
        a, b = np.asarray(self.a, float), np.asarray(self.b, float)
        e = b - a
        d = xb - xa
        den = d[:, 0] * e[1] - d[:, 1] * e[0]
        ok = den != 0
        den = np.where(ok, den, 1.0)
        w = a - xa
        t = (w[:, 0] * e[1] - w[:, 1] * e[0]) / den           # along the bond
        u = (w[:, 0] * d[:, 1] - w[:, 1] * d[:, 0]) / den     # along the part
        hit = np.flatnonzero(ok & (t > 0) & (t < 1) & (u >= -END) & (u <= 1 + END))
        n = np.array([e[1], -e[0]])
        sign = np.where((xa[hit] - a) @ n < 0, 1.0, -1.0)
        u = np.clip(u[hit], 0.0, 1.0)
        alpha = np.where((u <= END) | (u >= 1 - END), 0.5, 1.0)
        return hit, u * self.length, sign, alpha

    def param(self, x):
        """Arc length from ``a`` of the closest point of each row of ``x``."""
        a, b = np.asarray(self.a, float), np.asarray(self.b, float)
        t = (b - a) / self.length
        return np.clip((np.asarray(x, float) - a) @ t, 0.0, self.length)

    def point(self, s):
        """Points at arc-length fractions ``s`` in [0, 1] and their outward normals."""
        a, b = np.asarray(self.a, float), np.asarray(self.b, float)
        t = b - a
        n = np.array([t[1], -t[0]]) / np.linalg.norm(t)
        return a + s[:, None] * t, np.broadcast_to(n, (s.size, 2)).copy()


@dataclass(frozen=True)
class CrackFace(Segment):
    """One face of a :class:`Crack`: the segment ``a`` -> ``b`` with the body of this face
    on its left (outward normal the direction turned clockwise), seen only from that
    side (module docstring: a point on the crack's line is on the ``+`` side, i.e. it
    sees the ``+`` face)."""

    plus: bool = True

    def sees(self, x) -> np.ndarray:
        """Which rows of ``x`` lie on this face's side of the crack's line."""
        a, b = np.asarray(self.a, float), np.asarray(self.b, float)
        e = b - a if self.plus else a - b        # start -> tip
        start = a if self.plus else b
        on_plus = _side(x, start, e)
        return on_plus if self.plus else ~on_plus

    def crossings(self, xa, xb):
        """As :meth:`Segment.crossings`, the crossings of the segments that leave this
        face's side (sign +1): a bond through the slit crosses the face of the side it
        starts on, once. A segment through the tip point itself (not cut: the tip's
        bonds stay) crosses both faces there, at the face's end (alpha 1/2), with its
        sign on each: its force is half each face's force flux, as a bond through the
        edge between two cell faces is half each's (seed 001)."""
        hit, s, sign, alpha = super().crossings(xa, xb)
        tip = self.length if self.plus else 0.0
        own = (sign > 0) | (np.abs(s - tip) <= END * self.length)
        return hit[own], s[own], sign[own], alpha[own]


def _side(x, start, e) -> np.ndarray:
    """True where the rows of ``x`` lie on the left of the line start + u e or on it
    (within :data:`END` of |e|: the ``+`` side)."""
    r = np.asarray(x, dtype=float) - start
    cross = e[0] * r[:, 1] - e[1] * r[:, 0]
    return cross >= -END * float(e @ e)


@dataclass(frozen=True)
class Crack:
    """A straight slit of zero width named ``name`` from ``start`` to ``tip`` (module
    docstring: faces, sides, which bonds it cuts)."""

    name: str
    start: tuple
    tip: tuple

    @property
    def length(self) -> float:
        return float(np.linalg.norm(np.subtract(self.tip, self.start)))

    @property
    def faces(self) -> tuple:
        """``(<name>+, <name>-)``; none for a crack of zero length."""
        if self.length == 0:
            return ()
        s, t = tuple(map(float, self.start)), tuple(map(float, self.tip))
        return (CrackFace(f"{self.name}+", s, t, plus=True),
                CrackFace(f"{self.name}-", t, s, plus=False))

    def side(self, x) -> np.ndarray:
        """True where the rows of ``x`` are on the ``+`` side (left of start -> tip, or on
        the crack's line)."""
        start = np.asarray(self.start, float)
        return _side(x, start, np.asarray(self.tip, float) - start)

    def cuts(self, xa, xb) -> np.ndarray:
        """Which segments xa -> xb (bonds; rows of (n, 2) arrays) the crack cuts: ends
        on different sides and the crossing at u in [0, 1) along start -> tip, u within
        :data:`END` of 1 counting as the tip (module docstring). Vectorised."""
        xa, xb = np.asarray(xa, dtype=float), np.asarray(xb, dtype=float)
        if self.length == 0:
            return np.zeros(len(xa), dtype=bool)
        s = np.asarray(self.start, float)
        e = np.asarray(self.tip, float) - s
        apart = self.side(xa) != self.side(xb)
        d = xb - xa
        den = e[0] * d[:, 1] - e[1] * d[:, 0]
        den = np.where(apart & (den != 0), den, 1.0)
        r = xa - s
        u = (r[:, 0] * d[:, 1] - r[:, 1] * d[:, 0]) / den
        return apart & (u >= -END) & (u < 1 - END)

    def near(self, x, reach: float) -> tuple:
        """``(plus, minus)``: the rows of ``x`` within ``reach`` of the slit (closed) on
        each side, the nodes the faces ``<name>+`` and ``<name>-`` belong to."""
        x = np.asarray(x, dtype=float)
        if self.length == 0:
            none = np.zeros(len(x), dtype=bool)
            return none, none.copy()
        p, _ = self.faces[0].closest(x)
        close = np.linalg.norm(x - p, axis=1) <= reach
        plus = self.side(x)
        return close & plus, close & ~plus


@dataclass(frozen=True)
class Arc:
    """The circular boundary part ``name``: centre, radius, from angle ``theta0`` to
    ``theta1`` (radians, counter-clockwise); ``hole``: the body lies outside the circle."""

    name: str
    centre: tuple
    radius: float
    theta0: float
    theta1: float
    hole: bool = True
    straight = False

    def _angle(self, x):
        """The angle of each point's closest point on the arc: its own angle, taken into
        [theta0, theta0 + 2 pi), or outside [theta0, theta1] the nearer end's."""
        r = np.asarray(x, float) - np.asarray(self.centre, float)
        lo, hi = self.theta0, self.theta1
        th = lo + np.mod(np.arctan2(r[:, 1], r[:, 0]) - lo, 2 * np.pi)
        past = th > hi
        gap = 2 * np.pi - (hi - lo)
        return np.where(past & (th - hi < 0.5 * gap), hi, np.where(past, lo, th))

    def closest(self, x):
        e = self._angle(x)
        e = np.c_[np.cos(e), np.sin(e)]
        p = np.asarray(self.centre, float) + self.radius * e
        return p, (-e if self.hole else e)

    @property
    def length(self) -> float:
        return float(self.radius * (self.theta1 - self.theta0))

    def crossings(self, xa, xb):
        """As :meth:`Segment.crossings`, for the circle's arc (up to two per segment);
        alpha 1/2 at either end angle (within :data:`END`)."""
        c = np.asarray(self.centre, float)
        d = xb - xa
        f = xa - c
        A = np.einsum("ij,ij->i", d, d)
        Bq = 2 * np.einsum("ij,ij->i", f, d)
        Cq = np.einsum("ij,ij->i", f, f) - self.radius ** 2
        disc = Bq * Bq - 4 * A * Cq
        real = disc > 0
        root = np.sqrt(np.where(real, disc, 0.0))
        out = []
        for t in ((-Bq - root) / (2 * A), (-Bq + root) / (2 * A)):
            idx = np.flatnonzero(real & (t > 0) & (t < 1))
            p = xa[idx] + t[idx, None] * d[idx] - c
            th = np.arctan2(p[:, 1], p[:, 0])
            th = self.theta0 - END + np.mod(th - self.theta0 + END, 2 * np.pi)
            on = (th >= self.theta0 - END) & (th <= self.theta1 + END)
            idx, th = idx[on], np.clip(th[on], self.theta0, self.theta1)
            outside_a = np.einsum("ij,ij->i", f[idx], f[idx]) > self.radius ** 2
            sign = np.where(outside_a == self.hole, 1.0, -1.0)
            alpha = np.where((th <= self.theta0 + END) | (th >= self.theta1 - END), 0.5, 1.0)
            out.append((idx, self.radius * (th - self.theta0), sign, alpha))
        return tuple(np.concatenate(v) for v in zip(*out))

    def param(self, x):
        """Arc length from ``theta0`` of the closest point of each row of ``x``."""
        return self.radius * (self._angle(x) - self.theta0)

    def point(self, s):
        th = self.theta0 + s * (self.theta1 - self.theta0)
        e = np.c_[np.cos(th), np.sin(th)]
        return np.asarray(self.centre, float) + self.radius * e, (-e if self.hole else e)


@dataclass(frozen=True)
class Shape:
    """A 2D body: its boundary ``parts`` (named, see the module docstring), the vectorised
    ``inside(x) -> bool`` and its bounding box ``lower``, ``upper``; ``cracks``: its
    :class:`Crack` slits, whose faces are appended to ``parts`` (each crack of non-zero
    length adds ``<name>+``, ``<name>-``); ``inside`` does not see them (zero width)."""

    parts: tuple
    inside: Callable[[np.ndarray], np.ndarray]
    lower: tuple
    upper: tuple
    name: str = "shape"
    cracks: tuple = ()

    dim = 2

    def __post_init__(self):
        if not self.cracks:
            return
        cracks = tuple(self.cracks)
        for c in cracks:
            if not isinstance(c, Crack):
                raise ValueError(f"cracks: {c!r} is not a Crack")
            if c.length == 0:
                continue
            u = np.linspace(0.0, 1.0, 65)[1:]
            pts = np.asarray(c.start, float) + u[:, None] * np.subtract(c.tip, c.start)
            if not np.all(self.inside(pts)):
                raise ValueError(f"crack {c.name!r}: every point past its start up to "
                                 f"its tip must lie inside the shape {self.name!r}")
        crack_names = [c.name for c in cracks]
        if len(set(crack_names)) != len(crack_names):
            raise ValueError(f"shape {self.name!r}: crack names must differ, got {crack_names}")
        have = set(self.parts)       # the faces already appended (dataclasses.replace)
        new = tuple(f for c in cracks for f in c.faces if f not in have)
        names = [q.name for q in self.parts] + [f.name for f in new]
        if len(set(names)) != len(names):
            raise ValueError(f"shape {self.name!r}: part names must differ, got {names}")
        object.__setattr__(self, "cracks", cracks)
        object.__setattr__(self, "parts", tuple(self.parts) + new)

    def with_cracks(self, *cracks) -> "Shape":
        """This shape with ``cracks`` added to its own (their faces become parts)."""
        return replace(self, cracks=tuple(self.cracks) + tuple(cracks))

    def crack_nodes(self, x, reach: float) -> dict:
        """``{face name: mask}``: the rows of ``x`` within ``reach`` (a horizon) of each
        crack on the face's side (:meth:`Crack.near`), whichever part is closest."""
        out = {}
        for c in self.cracks:
            if c.length:
                plus, minus = c.near(x, reach)
                out[f"{c.name}+"], out[f"{c.name}-"] = plus, minus
        return out

    def severs(self, xa, xb) -> np.ndarray:
        """Which segments xa -> xb any crack cuts (:meth:`Crack.cuts`)."""
        out = np.zeros(len(xa), dtype=bool)
        for c in self.cracks:
            out |= c.cuts(xa, xb)
        return out

    def hides(self, x, p, part) -> np.ndarray:
        """Which boundary points ``p`` (rows, on the parts ``part``) the points ``x`` do not
        see through the body: the segment x -> p crosses a part other than p's own
        farther than 1e-9 |x - p| from p (it passes through the body's exterior, as a
        segment across a re-entrant corner's notch does), or a crack cuts it
        (:meth:`severs`). A segment that dips outside across p's own part (a chord of
        a hole's arc) is not hidden: the exterior it crosses is the one p's part bounds.
        At a convex corner p's segment never leaves the body. Vectorised; a loop over
        the few parts."""
        x, p = np.asarray(x, dtype=float), np.asarray(p, dtype=float)
        part = np.asarray(part)
        out = self.severs(x, p)
        gap = 1e-9 * np.linalg.norm(x - p, axis=1)
        for k, q in enumerate(self.parts):
            other = np.flatnonzero(part != k)
            if other.size == 0 or isinstance(q, CrackFace):
                continue
            hit, s, _, _ = q.crossings(x[other], p[other])
            at, _ = q.point(s / q.length)
            far = np.linalg.norm(at - p[other[hit]], axis=1) > gap[other[hit]]
            out[other[hit[far]]] = True
        return out

    @property
    def part_names(self) -> tuple:
        return tuple(p.name for p in self.parts)

    def closest(self, x):
        """``(points, normals, distance, part index)`` of the closest boundary point of
        every row of ``x`` (n, 2); ties go to the first part. A crack's face counts only
        for the points on its side (:meth:`CrackFace.sees`)."""
        x = np.asarray(x, dtype=float)
        best = np.full(len(x), np.inf)
        P, N = np.zeros_like(x), np.zeros_like(x)
        part = np.zeros(len(x), dtype=int)
        for k, q in enumerate(self.parts):
            p, n = q.closest(x)
            dist = np.linalg.norm(x - p, axis=1)
            if isinstance(q, CrackFace):
                dist = np.where(q.sees(x), dist, np.inf)
            better = dist < best
            best = np.where(better, dist, best)
            P[better], N[better], part[better] = p[better], n[better], k
        return P, N, best, part

    def sdf(self, x) -> np.ndarray:
        """Signed distance to the boundary, negative inside."""
        x = np.asarray(x, dtype=float)
        dist = self.closest(x)[2]
        return np.where(self.inside(x), -dist, dist)

    def fractions(self, centres, h: float, samples: int = FRACTION_SAMPLES) -> np.ndarray:
        """The part of each square cell of side ``h`` about ``centres`` inside the shape
        (module docstring)."""
        centres = np.asarray(centres, dtype=float)
        out = self.inside(centres).astype(float)
        cut = np.flatnonzero(self.closest(centres)[2] < h * np.sqrt(0.5) * (1 + 1e-12))
        if cut.size:
            t = (np.arange(samples) + 0.5) / samples - 0.5
            sub = np.stack(np.meshgrid(t, t, indexing="ij"), -1).reshape(-1, 2) * h
            pts = (centres[cut][:, None, :] + sub[None]).reshape(-1, 2)
            out[cut] = self.inside(pts).reshape(cut.size, -1).mean(axis=1)
        return out

    def crossings(self, xa, xb):
        """Every crossing of a part by the segments xa -> xb: ``(segment, part, arc
        length on the part, sign, alpha)`` (the parts' ``crossings``)."""
        out = []
        for k, q in enumerate(self.parts):
            idx, s, sign, alpha = q.crossings(xa, xb)
            out.append((idx, np.full(idx.size, k), s, sign, alpha))
        return tuple(np.concatenate(v) for v in zip(*out))

    def samples(self, h: float):
        """Gauss points along every part: ``(points, weights, normals, part index)``."""
        g, w = np.polynomial.legendre.leggauss(3)
        g, w = 0.5 * (g + 1), 0.5 * w
        P, W, N, K = [], [], [], []
        for k, q in enumerate(self.parts):
            pieces = max(1, int(np.ceil(q.length / h * SAMPLES_PER_CELL)))
            s = ((np.arange(pieces)[:, None] + g[None]) / pieces).ravel()
            p, n = q.point(s)
            P.append(p)
            N.append(n)
            W.append(np.tile(w, pieces) * q.length / pieces)
            K.append(np.full(s.size, k))
        return np.concatenate(P), np.concatenate(W), np.concatenate(N), np.concatenate(K)


def polygon(vertices, names, name="polygon") -> Shape:
    """The polygon of ``vertices`` (counter-clockwise), edge k from vertex k to k + 1
    named ``names[k]``; inside by the even-odd rule."""
    v = np.asarray(vertices, dtype=float)
    edges = tuple(Segment(nm, tuple(v[k]), tuple(v[(k + 1) % len(v)]))
                  for k, nm in enumerate(names))
    if len(names) != len(v):
        raise ValueError(f"{len(v)} vertices need {len(v)} edge names, got {len(names)}")
    if np.sum(v[:, 0] * np.roll(v[:, 1], -1) - np.roll(v[:, 0], -1) * v[:, 1]) <= 0:
        raise ValueError("polygon vertices must run counter-clockwise")

    def inside(x):
        x = np.asarray(x, dtype=float)
        a, b = v, np.roll(v, -1, axis=0)
        xs, ys = x[:, :1], x[:, 1:2]
        crosses = (a[None, :, 1] > ys) != (b[None, :, 1] > ys)
        with np.errstate(divide="ignore", invalid="ignore"):
            at = a[None, :, 0] + (ys - a[None, :, 1]) * (b[None, :, 0] - a[None, :, 0]) / (
                b[None, :, 1] - a[None, :, 1])
        return (np.sum(crosses & (xs < at), axis=1) % 2) == 1

    return Shape(edges, inside, tuple(v.min(axis=0)), tuple(v.max(axis=0)), name)


def l_shape(length: float) -> Shape:
    """[0, L]^2 without (L/2, L] x (L/2, L]: the re-entrant corner at (L/2, L/2). Parts:
    ``y-`` (y = 0), ``x+`` (x = L, y <= L/2), ``notch-y`` (y = L/2, x >= L/2), ``notch-x``
    (x = L/2, y >= L/2), ``y+`` (y = L, x <= L/2), ``x-`` (x = 0)."""
    L, H = float(length), 0.5 * float(length)
    return polygon([(0, 0), (L, 0), (L, H), (H, H), (H, L), (0, L)],
                   ("y-", "x+", "notch-y", "notch-x", "y+", "x-"), "l-plate")


def quarter_hole(width: float, radius: float) -> Shape:
    """[0, W]^2 without the disk r < a about the origin (a quarter plate with a hole).
    Parts: ``y-`` (y = 0, x >= a), ``x+``, ``y+``, ``x-`` (x = 0, y >= a), ``hole``."""
    W, a = float(width), float(radius)
    if not 0 < a < W:
        raise ValueError(f"radius {a} must lie in (0, width {W})")
    parts = (Segment("y-", (a, 0.0), (W, 0.0)), Segment("x+", (W, 0.0), (W, W)),
             Segment("y+", (W, W), (0.0, W)), Segment("x-", (0.0, W), (0.0, a)),
             Arc("hole", (0.0, 0.0), a, 0.0, 0.5 * np.pi, hole=True))

    def inside(x):
        x = np.asarray(x, dtype=float)
        return (np.all((x > 0) & (x < W), axis=1)
                & (np.einsum("ij,ij->i", x, x) > a * a))

    return Shape(parts, inside, (0.0, 0.0), (W, W), "quarter-hole")
