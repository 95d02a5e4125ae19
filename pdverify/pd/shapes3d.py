"""Bodies that are not boxes, in 3D: a quarter cylinder and a block with a spherical cavity
(octants of the bodies by symmetry), cut from a uniform grid, with named boundary parts.

The 3D companion of :mod:`pdverify.pd.shapes` (issue 55), with the same interface, so the
grid (``ShapeGrid``), the uncorrected model's boundary nodes
(``corrections.assembly.boundary_nodes``) and the scenes' error regions take either:

- :meth:`Shape3D.closest`: ``(points, outward unit normals, distance, part index)`` of
  the closest boundary point of every row of ``x`` (n, 3), ties to the first part;
- :meth:`Shape3D.sdf`: the signed distance (negative inside);
- :meth:`Shape3D.fractions`: the part of each cubic cell inside the shape, sampled on an
  ``s x s x s`` sub-grid of the cells the boundary can cut (distance below
  sqrt(3)/2 h; 1 or 0 elsewhere). Stated accuracy: a sub-cell is miscounted only when
  its centre lies within sqrt(3)/2 h/s of the boundary, so the summed volume errs by
  at most sqrt(3) A h / s for curved parts of area A (a plane part on cell faces is
  exact); tested on both shapes at h = 1/16, s = 8: measured 3.7e-4 and 1.2e-5 of
  volumes 0.196 and 0.986 (bounds 1.1e-2, 5.3e-3: the midpoint errors cancel);
- :meth:`Shape3D.samples`: Gauss points over every part (3 x 3 per patch of side at
  most ``h / SAMPLES_PER_CELL`` in its parameters) with their area weights, outward
  normals and part: the quadrature of surface loads, and how the uncorrected model
  finds its boundary nodes.

Every part is convex or (``square-minus-disk``) handled exactly, so the closest points
are exact projections (to round-off), not searches. Parts:

- :class:`Planar`: a plane region ``origin + s e1 + t e2`` (e1, e2 orthonormal) with the
  constant outward ``normal``; the region in (s, t) is ``rect`` (``[0, A] x [0, B]``),
  ``quarter-disk`` (``s, t >= 0``, ``s^2 + t^2 <= R^2``) or ``square-minus-disk``
  (``[0, W]^2`` without the quarter disk of radius a about the origin: a symmetry face of
  the block with a cavity);
- :class:`Mantle`: the lateral surface r = R, 0 <= theta <= theta1, 0 <= z <= L of a
  cylinder of axis z through the origin (outward normal radial);
- :class:`SphereOctant`: r = a with x, y, z >= 0 (the cavity; outward normal of the
  body points into the cavity, to the centre).

No cracks (zero-width slits are 2D only, ``pdverify.pd.shapes``); ``cracks = ()`` so the
model's bond choice (``closure.uncut``) treats a 3D shape as uncracked.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np

#: patches per grid spacing along each parameter of a part (3 x 3 Gauss points each)
SAMPLES_PER_CELL = 4
#: sub-grid per axis of the sampled cut-cell fractions
FRACTION_SAMPLES = 8

_G, _W = np.polynomial.legendre.leggauss(3)
_G, _W = 0.5 * (_G + 1), 0.5 * _W


def _tensor_gauss(lo0, hi0, lo1, hi1, n0, n1):
    """Gauss points (3 x 3 per patch) of the rectangle [lo0, hi0] x [lo1, hi1] of
    parameters split into n0 x n1 patches: (u, v, weight)."""
    u = lo0 + (hi0 - lo0) * ((np.arange(n0)[:, None] + _G) / n0).ravel()
    v = lo1 + (hi1 - lo1) * ((np.arange(n1)[:, None] + _G) / n1).ravel()
    wu = np.tile(_W, n0) * (hi0 - lo0) / n0
    wv = np.tile(_W, n1) * (hi1 - lo1) / n1
    U, V = np.meshgrid(u, v, indexing="ij")
    return U.ravel(), V.ravel(), np.outer(wu, wv).ravel()


def _pieces(length, h):
    return max(1, int(np.ceil(length / h * SAMPLES_PER_CELL)))


REGIONS = ("rect", "quarter-disk", "square-minus-disk")


def _roots_on(x, p, c, d, radius, on_part):
    """(n, 2) roots t in (0, 1) of |c + t d| = radius whose points x + t (p - x) lie on
    the part (``on_part``), NaN elsewhere."""
    A = np.einsum("ij,ij->i", d, d)
    B = 2 * np.einsum("ij,ij->i", c, d)
    C = np.einsum("ij,ij->i", c, c) - radius * radius
    disc = B * B - 4 * A * C
    ok = (A > 0) & (disc > 0)
    root = np.sqrt(np.where(ok, disc, 0.0))
    A = np.where(ok, A, 1.0)
    out = np.full((len(x), 2), np.nan)
    for k, t in enumerate(((-B - root) / (2 * A), (-B + root) / (2 * A))):
        q = x + t[:, None] * (p - x)
        good = ok & (t > 0) & (t < 1) & on_part(q)
        out[good, k] = t[good]
    return out


@dataclass(frozen=True)
class Planar:
    """A plane part (module docstring): ``region`` with its sizes ``size`` (rect: (A, B);
    quarter-disk: (R,); square-minus-disk: (W, a))."""

    name: str
    origin: tuple
    e1: tuple
    e2: tuple
    normal: tuple
    region: str
    size: tuple
    straight = True

    def _frame(self):
        return (np.asarray(self.origin, float), np.asarray(self.e1, float),
                np.asarray(self.e2, float))

    def local(self, st) -> np.ndarray:
        """The closest point of the region to each (s, t) of the plane."""
        s, t = st[:, 0], st[:, 1]
        if self.region == "rect":
            A, B = self.size
            return np.c_[np.clip(s, 0, A), np.clip(t, 0, B)]
        if self.region == "quarter-disk":
            (R,) = self.size
            q = np.maximum(st, 0.0)          # projection onto the quadrant, then the disk
            r = np.linalg.norm(q, axis=1)
            scale = np.where(r > R, R / np.where(r > 0, r, 1.0), 1.0)
            return q * scale[:, None]
        W, a = self.size
        q = np.clip(st, 0.0, W)             # the square, then out of the disk radially
        r = np.linalg.norm(q, axis=1)
        inside = r < a
        zero = r == 0                       # the disk's centre: the nearer axis end
        safe = np.where(zero, 1.0, r)
        out = np.where(inside[:, None], q * (a / safe)[:, None], q)
        if np.any(zero):
            along_s = st[zero, 0] >= st[zero, 1]
            out[zero] = np.where(along_s[:, None], [a, 0.0], [0.0, a])
        return out

    def closest(self, x):
        o, e1, e2 = self._frame()
        r = np.asarray(x, float) - o
        st = self.local(np.c_[r @ e1, r @ e2])
        p = o + st[:, :1] * e1 + st[:, 1:] * e2
        return p, np.broadcast_to(np.asarray(self.normal, float), p.shape).copy()

    def crosses(self, x, p) -> np.ndarray:
        """Parameters t in (0, 1) where the segments x -> p cross the region (NaN where
        they do not; a segment in the plane does not cross it)."""
        o, e1, e2 = self._frame()
        nrm = np.asarray(self.normal, float)
        d = p - x
        den = d @ nrm
        ok = np.abs(den) > 0
        t = np.where(ok, ((o - x) @ nrm) / np.where(ok, den, 1.0), np.nan)
        at = x + np.nan_to_num(t)[:, None] * d - o
        st = np.c_[at @ e1, at @ e2]
        inside = np.linalg.norm(self.local(st) - st, axis=1) <= 1e-12 * max(self.size)
        return np.where(ok & inside & (t > 0) & (t < 1), t, np.nan)

    @property
    def area(self) -> float:
        if self.region == "rect":
            return float(self.size[0] * self.size[1])
        if self.region == "quarter-disk":
            return float(0.25 * np.pi * self.size[0] ** 2)
        W, a = self.size
        return float(W * W - 0.25 * np.pi * a * a)

    def samples(self, h):
        """Gauss points, area weights and normals over the region (module docstring;
        the disk regions in polar coordinates, exact in area up to the quadrature)."""
        if self.region == "rect":
            A, B = self.size
            s, t, w = _tensor_gauss(0, A, 0, B, _pieces(A, h), _pieces(B, h))
        elif self.region == "quarter-disk":
            (R,) = self.size
            r, th, w = _tensor_gauss(0, R, 0, 0.5 * np.pi, _pieces(R, h),
                                     _pieces(0.5 * np.pi * R, h))
            s, t, w = r * np.cos(th), r * np.sin(th), w * r
        else:
            W, a = self.size
            parts = []
            for lo, hi, far in ((0.0, 0.25 * np.pi, np.cos), (0.25 * np.pi, 0.5 * np.pi, np.sin)):
                v, th, w = _tensor_gauss(0, 1, lo, hi, _pieces(W - a, h),
                                         _pieces(0.25 * np.pi * W, h))
                top = W / far(th)
                r = a + v * (top - a)
                parts.append((r * np.cos(th), r * np.sin(th), w * r * (top - a)))
            s, t, w = (np.concatenate(c) for c in zip(*parts))
        o, e1, e2 = self._frame()
        p = o + s[:, None] * e1 + t[:, None] * e2
        return p, w, np.broadcast_to(np.asarray(self.normal, float), p.shape).copy()


@dataclass(frozen=True)
class Mantle:
    """r = radius, 0 <= theta <= theta1, 0 <= z <= length about the z axis (outward: radial)."""

    name: str
    radius: float
    length: float
    theta1: float = 0.5 * np.pi
    straight = False

    def closest(self, x):
        x = np.asarray(x, float)
        th = np.arctan2(x[:, 1], x[:, 0])
        gap = 2 * np.pi - self.theta1          # past the end: the nearer end's angle
        th = np.mod(th, 2 * np.pi)
        past = th > self.theta1
        th = np.where(past & (th - self.theta1 < 0.5 * gap), self.theta1,
                      np.where(past, 0.0, th))
        e = np.c_[np.cos(th), np.sin(th), np.zeros(len(x))]
        p = self.radius * e
        p[:, 2] = np.clip(x[:, 2], 0.0, self.length)
        return p, e

    def crosses(self, x, p) -> np.ndarray:
        """(n, 2) parameters t in (0, 1) where the segments x -> p cross the mantle
        (NaN where not; two roots of |x_xy + t d_xy| = R)."""
        return _roots_on(x, p, x[:, :2], (p - x)[:, :2], self.radius, lambda q: (
            (np.mod(np.arctan2(q[:, 1], q[:, 0]), 2 * np.pi) <= self.theta1 + 1e-12)
            & (q[:, 2] >= 0) & (q[:, 2] <= self.length)))

    @property
    def area(self) -> float:
        return float(self.radius * self.theta1 * self.length)

    def samples(self, h):
        th, z, w = _tensor_gauss(0, self.theta1, 0, self.length,
                                 _pieces(self.radius * self.theta1, h), _pieces(self.length, h))
        e = np.c_[np.cos(th), np.sin(th), np.zeros(th.size)]
        p = self.radius * e
        p[:, 2] = z
        return p, w * self.radius, e


@dataclass(frozen=True)
class SphereOctant:
    """r = radius with x, y, z >= 0, the body outside (outward normal: to the centre)."""

    name: str
    radius: float
    straight = False

    def closest(self, x):
        q = np.maximum(np.asarray(x, float), 0.0)   # max n.x over unit n >= 0
        r = np.linalg.norm(q, axis=1)
        e = np.where((r > 0)[:, None], q / np.where(r > 0, r, 1.0)[:, None],
                     np.array([1.0, 0.0, 0.0]))
        return self.radius * e, -e

    def crosses(self, x, p) -> np.ndarray:
        """(n, 2) parameters t in (0, 1) where the segments x -> p cross the sphere's
        octant (NaN where not)."""
        return _roots_on(x, p, x, p - x, self.radius,
                         lambda q: np.all(q >= -1e-12 * self.radius, axis=1))

    @property
    def area(self) -> float:
        return float(0.5 * np.pi * self.radius ** 2)

    def samples(self, h):
        a = self.radius
        phi, lam, w = _tensor_gauss(0, 0.5 * np.pi, 0, 0.5 * np.pi,
                                    _pieces(0.5 * np.pi * a, h), _pieces(0.5 * np.pi * a, h))
        e = np.c_[np.sin(phi) * np.cos(lam), np.sin(phi) * np.sin(lam), np.cos(phi)]
        return a * e, w * a * a * np.sin(phi), -e


@dataclass(frozen=True)
class Shape3D:
    """A 3D body: its named ``parts``, the vectorised ``inside(x) -> bool`` and its
    bounding box ``lower``, ``upper`` (module docstring)."""

    parts: tuple
    inside: Callable[[np.ndarray], np.ndarray]
    lower: tuple
    upper: tuple
    name: str = "shape3d"
    cracks: tuple = ()

    dim = 3

    def __post_init__(self):
        names = [q.name for q in self.parts]
        if len(set(names)) != len(names):
            raise ValueError(f"shape {self.name!r}: part names must differ, got {names}")

    @property
    def part_names(self) -> tuple:
        return tuple(q.name for q in self.parts)

    @property
    def area(self) -> float:
        return float(sum(q.area for q in self.parts))

    def closest(self, x):
        """``(points, normals, distance, part index)`` (module docstring)."""
        x = np.asarray(x, dtype=float)
        best = np.full(len(x), np.inf)
        P, N = np.zeros_like(x), np.zeros_like(x)
        part = np.zeros(len(x), dtype=int)
        for k, q in enumerate(self.parts):
            p, n = q.closest(x)
            dist = np.linalg.norm(x - p, axis=1)
            better = dist < best
            best = np.where(better, dist, best)
            P[better], N[better], part[better] = p[better], n[better], k
        return P, N, best, part

    def hides(self, x, p, part) -> np.ndarray:
        """Which boundary points ``p`` (rows, on the parts ``part``) the points ``x`` do
        not see through the body: the segment x -> p crosses a part other than p's own
        farther than 1e-9 |x - p| from p (it passes through the body's exterior, as a
        segment through the cavity does), as ``pdverify.pd.shapes.Shape.hides`` in 2D.
        Exact crossings (planes, the mantle's and the sphere's quadratics)."""
        x, p = np.asarray(x, dtype=float), np.asarray(p, dtype=float)
        part = np.asarray(part)
        out = np.zeros(len(x), dtype=bool)
        gap = 1e-9
        for k, q in enumerate(self.parts):
            other = np.flatnonzero(part != k)
            if other.size == 0:
                continue
            t = np.asarray(q.crosses(x[other], p[other])).reshape(other.size, -1)
            out[other[np.any(t < 1 - gap, axis=1)]] = True
        return out

    def sdf(self, x) -> np.ndarray:
        """Signed distance to the boundary, negative inside."""
        x = np.asarray(x, dtype=float)
        dist = self.closest(x)[2]
        return np.where(self.inside(x), -dist, dist)

    def fractions(self, centres, h: float, samples: int = FRACTION_SAMPLES) -> np.ndarray:
        """The part of each cube of side ``h`` about ``centres`` inside the shape (module
        docstring: sampled on the cut cells, in chunks of at most ~2 M points)."""
        centres = np.asarray(centres, dtype=float)
        out = self.inside(centres).astype(float)
        cut = np.flatnonzero(self.closest(centres)[2] < h * np.sqrt(0.75) * (1 + 1e-12))
        if cut.size:
            t = (np.arange(samples) + 0.5) / samples - 0.5
            sub = np.stack(np.meshgrid(t, t, t, indexing="ij"), -1).reshape(-1, 3) * h
            step = max(1, 2_000_000 // sub.shape[0])
            for lo in range(0, cut.size, step):
                c = cut[lo:lo + step]
                pts = (centres[c][:, None, :] + sub[None]).reshape(-1, 3)
                out[c] = self.inside(pts).reshape(c.size, -1).mean(axis=1)
        return out

    def samples(self, h: float):
        """Gauss points over every part: ``(points, weights, normals, part index)``."""
        P, W, N, K = [], [], [], []
        for k, q in enumerate(self.parts):
            p, w, n = q.samples(h)
            P.append(p)
            W.append(w)
            N.append(n)
            K.append(np.full(w.size, k))
        return np.concatenate(P), np.concatenate(W), np.concatenate(N), np.concatenate(K)


def quarter_cylinder(radius: float, length: float) -> Shape3D:
    """The quarter x, y >= 0 of the cylinder r < R, 0 < z < L (axis z). Parts: ``mantle``
    (r = R), ``top`` (z = L), ``bottom`` (z = 0), ``x-`` (x = 0), ``y-`` (y = 0)."""
    R, L = float(radius), float(length)
    if not (R > 0 and L > 0):
        raise ValueError(f"radius {R} and length {L} must be > 0")
    ex, ey, ez = (1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0)
    parts = (Mantle("mantle", R, L),
             Planar("top", (0.0, 0.0, L), ex, ey, ez, "quarter-disk", (R,)),
             Planar("bottom", (0.0, 0.0, 0.0), ex, ey, (0.0, 0.0, -1.0), "quarter-disk", (R,)),
             Planar("x-", (0.0, 0.0, 0.0), ey, ez, (-1.0, 0.0, 0.0), "rect", (R, L)),
             Planar("y-", (0.0, 0.0, 0.0), ex, ez, (0.0, -1.0, 0.0), "rect", (R, L)))

    def inside(x):
        x = np.asarray(x, dtype=float)
        return ((x[:, 0] > 0) & (x[:, 1] > 0) & (x[:, 2] > 0) & (x[:, 2] < L)
                & (x[:, 0] ** 2 + x[:, 1] ** 2 < R * R))

    return Shape3D(parts, inside, (0.0, 0.0, 0.0), (R, R, L), "quarter-cylinder")


def cavity_octant(width: float, radius: float) -> Shape3D:
    """The octant [0, W]^3 of a block without the ball r < a about the origin. Parts:
    ``cavity`` (r = a), ``x-``, ``y-``, ``z-`` (the symmetry planes, squares without the
    quarter disk), ``x+``, ``y+``, ``z+`` (the outer faces)."""
    W, a = float(width), float(radius)
    if not 0 < a < W:
        raise ValueError(f"radius {a} must lie in (0, width {W})")
    e = np.eye(3)
    parts = [SphereOctant("cavity", a)]
    for k, ax in enumerate("xyz"):
        i, j = [m for m in range(3) if m != k]
        parts.append(Planar(f"{ax}-", (0.0, 0.0, 0.0), tuple(e[i]), tuple(e[j]),
                            tuple(-e[k]), "square-minus-disk", (W, a)))
    for k, ax in enumerate("xyz"):
        i, j = [m for m in range(3) if m != k]
        parts.append(Planar(f"{ax}+", tuple(W * e[k]), tuple(e[i]), tuple(e[j]),
                            tuple(e[k]), "rect", (W, W)))

    def inside(x):
        x = np.asarray(x, dtype=float)
        return (np.all((x > 0) & (x < W), axis=1)
                & (np.einsum("ij,ij->i", x, x) > a * a))

    return Shape3D(tuple(parts), inside, (0.0, 0.0, 0.0), (W, W, W), "cavity-octant")
