"""A quadratic displacement field on 9-node isoparametric quadrilaterals (non-box domains).

:class:`MeshField` is the counterpart of :class:`~reference_fem.field.FieldSolution` for
domains that are not a box: a plate with a hole (curved, quadratic element edges) or an
L-shaped plate. It stores the Q2 nodes, the elements (9 nodes each, in the tensor order
below), the nodal displacement and an exact description of the domain (a box minus
disks minus rectangles), so that it is self-contained and round-trips the npz cache.

Evaluation at a point:

1. the point must lie in the exact domain (box minus disks minus rectangles, each test
   with the tolerance ``1e-10 * diameter of the box``, as ``FieldSolution`` uses for its
   box); otherwise ``ValueError`` names how many points are outside and the first;
2. candidate elements come from a uniform bin grid over the padded bounding boxes of the
   elements (padded by 10 % of their size, so a point a little outside an element's
   curved edge still finds it);
3. in every candidate the reference coordinates (xi, eta) of the point are found by
   Newton's method on the element map x(xi, eta) = sum_k N_k(xi, eta) X_k;
4. the element whose reference coordinates lie inside [0, 1]^2, or least outside it,
   is taken, and its polynomial is evaluated at those (xi, eta) as they are.

A point of the exact domain that is not covered by the discrete one (between a circular
arc and the parabola through its three nodes, a distance O(h^3), or 1e-12 outside a
straight edge by round-off) thus gets the nearest element's polynomial extended a
distance O(h^3) beyond its edge: the field stays continuous and as accurate as inside.
A point on an edge between elements takes one of them (the displacement is continuous;
the gradient, hence :meth:`strain_energy_density`, is that element's).
"""
from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property
from pathlib import Path

import numpy as np

from .field import _lagrange_1d

#: reference coordinates of the local nodes: node k = 3 a + b sits at (a / 2, b / 2)
TENSOR_NODES = np.array([[a / 2, b / 2] for a in range(3) for b in range(3)])
#: meshio's ``quad9`` order (4 corners counter-clockwise, 4 edge midpoints, centre) in
#: the tensor order
_QUAD9 = np.array([0, 6, 8, 2, 3, 7, 5, 1, 4])
_CHUNK_PAIRS = 200_000


def _shape(xi: np.ndarray, eta: np.ndarray):
    """Biquadratic shape functions (n, 9) and their derivatives d/dxi, d/deta (n, 9)."""
    pa, da = _lagrange_1d(xi)
    pb, db = _lagrange_1d(eta)
    N = (pa[:, :, None] * pb[:, None, :]).reshape(-1, 9)
    Nx = (da[:, :, None] * pb[:, None, :]).reshape(-1, 9)
    Ny = (pa[:, :, None] * db[:, None, :]).reshape(-1, 9)
    return N, Nx, Ny


@dataclass(frozen=True, eq=False)
class MeshField:
    """Piecewise biquadratic displacement field on isoparametric 9-node quadrilaterals.

    Attributes
    ----------
    node_coords : coordinates of the Q2 nodes, shape (n, 2).
    elements : node numbers of each element, shape (n_el, 9); local node ``3 a + b``
        sits at the reference point (a / 2, b / 2) of [0, 1]^2.
    values : displacement at the nodes, shape (n, 2).
    lam, mu : effective Lame parameters (plane stress uses lambda*), for
        :meth:`strain_energy_density`.
    box : the domain's bounding box [[x0, x1], [y0, y1]].
    disks : removed open disks, rows (cx, cy, r); shape (k, 3), k >= 0.
    rects : removed open rectangles, rows (x0, y0, x1, y1); shape (m, 4), m >= 0. A side
        that lies on the box boundary is given past the box (so that the box's edge
        there is removed too).
    """

    node_coords: np.ndarray
    elements: np.ndarray
    values: np.ndarray
    lam: float
    mu: float
    box: np.ndarray
    disks: np.ndarray
    rects: np.ndarray

    dim = 2

    @property
    def bounds(self) -> np.ndarray:
        """Bounding box of the domain, shape (2, 2)."""
        return np.asarray(self.box, dtype=float)

    def nodes(self) -> np.ndarray:
        """Coordinates of the Q2 nodes, shape (n, 2), in the order of
        :meth:`nodal_displacement`."""
        return self.node_coords

    def nodal_displacement(self) -> np.ndarray:
        """Displacement at :meth:`nodes`, shape (n, 2)."""
        return self.values

    def max_displacement(self) -> float:
        """Largest displacement magnitude over the Q2 nodes."""
        return float(np.max(np.linalg.norm(self.values, axis=1)))

    # --- the domain ---------------------------------------------------------------------
    @property
    def tolerance(self) -> float:
        """Distance (m) by which a point may lie outside the exact domain (round-off)."""
        b = self.bounds
        return 1e-10 * float(np.hypot(*(b[:, 1] - b[:, 0])))

    def contains(self, points: np.ndarray) -> np.ndarray:
        """True where a point lies in the closed domain (up to :attr:`tolerance`)."""
        pts = np.asarray(points, dtype=float)
        tol = self.tolerance
        b = self.bounds
        inside = np.all((pts >= b[:, 0] - tol) & (pts <= b[:, 1] + tol), axis=1)
        for cx, cy, r in np.asarray(self.disks, dtype=float).reshape(-1, 3):
            inside &= np.hypot(pts[:, 0] - cx, pts[:, 1] - cy) >= r - tol
        for x0, y0, x1, y1 in np.asarray(self.rects, dtype=float).reshape(-1, 4):
            inside &= ~((pts[:, 0] > x0 + tol) & (pts[:, 0] < x1 - tol)
                        & (pts[:, 1] > y0 + tol) & (pts[:, 1] < y1 - tol))
        return inside

    # --- point location -----------------------------------------------------------------
    @cached_property
    def _element_nodes(self) -> np.ndarray:
        return self.node_coords[self.elements]                       # (n_el, 9, 2)

    @cached_property
    def _bins(self):
        """Uniform bin grid over the box: (origin, cell size, bins per axis, CSR starts,
        element numbers sorted by bin)."""
        X = self._element_nodes
        lo, hi = X.min(axis=1), X.max(axis=1)
        pad = 0.1 * (hi - lo).max(axis=1, keepdims=True) + self.tolerance
        lo, hi = lo - pad, hi + pad
        n_el = X.shape[0]
        nb = int(min(2048, max(1, np.ceil(np.sqrt(n_el)))))
        b = self.bounds
        origin = b[:, 0]
        cell = (b[:, 1] - b[:, 0]) / nb
        i0 = np.clip(np.floor((lo - origin) / cell).astype(np.int64), 0, nb - 1)
        i1 = np.clip(np.floor((hi - origin) / cell).astype(np.int64), 0, nb - 1)
        cx, cy = i1[:, 0] - i0[:, 0] + 1, i1[:, 1] - i0[:, 1] + 1
        cnt = cx * cy
        el = np.repeat(np.arange(n_el), cnt)
        local = np.arange(cnt.sum()) - np.repeat(np.cumsum(cnt) - cnt, cnt)
        ix = i0[el, 0] + local // cy[el]
        iy = i0[el, 1] + local % cy[el]
        bin_id = ix * nb + iy
        order = np.argsort(bin_id, kind="stable")
        starts = np.searchsorted(bin_id[order], np.arange(nb * nb + 1))
        return origin, cell, nb, starts, el[order], lo, hi

    def _invert(self, pts: np.ndarray, el: np.ndarray):
        """Reference coordinates of pts[i] in element el[i] (Newton), and how far they lie
        outside [0, 1]^2 (inf where Newton did not converge)."""
        X = self._element_nodes[el]                                  # (p, 9, 2)
        xi = np.full(len(el), 0.5)
        eta = np.full(len(el), 0.5)
        size = np.max(X.max(axis=1) - X.min(axis=1), axis=1)
        active = np.arange(len(el))
        for _ in range(25):
            Xa = X[active]
            N, Nx, Ny = _shape(xi[active], eta[active])
            r = pts[active] - np.einsum("pk,pkc->pc", N, Xa)
            J = np.stack([np.einsum("pk,pkc->pc", Nx, Xa), np.einsum("pk,pkc->pc", Ny, Xa)],
                         axis=2)                                     # dx_c / dxi_d
            det = J[:, 0, 0] * J[:, 1, 1] - J[:, 0, 1] * J[:, 1, 0]
            det = np.where(np.abs(det) > 1e-300, det, 1e-300)
            dxi = (J[:, 1, 1] * r[:, 0] - J[:, 0, 1] * r[:, 1]) / det
            deta = (-J[:, 1, 0] * r[:, 0] + J[:, 0, 0] * r[:, 1]) / det
            # the map is only used near [0, 1]^2: keep far-away iterates bounded
            xi[active] = np.clip(xi[active] + dxi, -1.0, 2.0)
            eta[active] = np.clip(eta[active] + deta, -1.0, 2.0)
            active = active[np.abs(dxi) + np.abs(deta) >= 1e-14]
            if active.size == 0:
                break
        N, _, _ = _shape(xi, eta)
        resid = np.linalg.norm(pts - np.einsum("pk,pkc->pc", N, X), axis=1)
        out = np.maximum.reduce([np.zeros_like(xi), -xi, xi - 1.0, -eta, eta - 1.0])
        out = np.where(resid <= 1e-10 * size, out, np.inf)
        return xi, eta, out

    def _locate(self, points: np.ndarray):
        """(element, xi, eta) of each point; ValueError for points outside the domain."""
        pts = np.asarray(points, dtype=float)
        if pts.ndim != 2 or pts.shape[1] != 2:
            raise ValueError(f"points must have shape (n, 2), got {pts.shape}")
        if not np.all(np.isfinite(pts)):
            raise ValueError("points contain NaN or inf")
        outside = ~self.contains(pts)
        if np.any(outside):
            first = pts[np.argmax(outside)]
            raise ValueError(f"{int(outside.sum())} of {len(pts)} points lie outside the "
                             f"domain ({self.describe_domain()}); first: "
                             f"({first[0]:.12g}, {first[1]:.12g})")
        origin, cell, nb, starts, bin_el, lo, hi = self._bins
        ij = np.clip(np.floor((pts - origin) / cell).astype(np.int64), 0, nb - 1)
        b = ij[:, 0] * nb + ij[:, 1]
        cnt = starts[b + 1] - starts[b]
        el_out = np.empty(len(pts), dtype=np.int64)
        xi_out = np.empty(len(pts))
        eta_out = np.empty(len(pts))
        # chunks of points whose candidate pairs number at most _CHUNK_PAIRS
        csum = np.cumsum(cnt)
        begin = 0
        while begin < len(pts):
            base = csum[begin] - cnt[begin]
            end = max(begin + 1, int(np.searchsorted(csum, base + _CHUNK_PAIRS, "right")))
            sel = np.arange(begin, end)
            c = cnt[sel]
            if np.any(c == 0):
                bad = sel[np.argmax(c == 0)]
                raise ValueError(f"no element near the point ({pts[bad, 0]:g}, "
                                 f"{pts[bad, 1]:g}) of the domain")
            who = np.repeat(sel, c)
            local = np.arange(c.sum()) - np.repeat(np.cumsum(c) - c, c)
            el = bin_el[starts[b[who]] + local]
            # only the elements whose padded bounding box holds the point
            keep = np.all((pts[who] >= lo[el]) & (pts[who] <= hi[el]), axis=1)
            missing = np.setdiff1d(sel, who[keep])
            if missing.size:
                raise ValueError(f"no element near the point ({pts[missing[0], 0]:g}, "
                                 f"{pts[missing[0], 1]:g}) of the domain")
            who, el = who[keep], el[keep]
            xi, eta, out = self._invert(pts[who], el)
            # per point the least-outside candidate (ties: the lowest element number)
            order = np.lexsort((el, out, who))
            first = np.ones(len(order), dtype=bool)
            first[1:] = who[order][1:] != who[order][:-1]
            pick = order[first]
            if np.any(~(out[pick] <= 0.5)):
                bad = who[pick][np.argmax(~(out[pick] <= 0.5))]
                raise ValueError(f"no element covers the point ({pts[bad, 0]:g}, "
                                 f"{pts[bad, 1]:g}) of the domain")
            el_out[sel] = el[pick]
            xi_out[sel] = xi[pick]
            eta_out[sel] = eta[pick]
            begin = end
        return el_out, xi_out, eta_out

    def describe_domain(self) -> str:
        b = self.bounds
        text = f"[{b[0, 0]:g}, {b[0, 1]:g}] x [{b[1, 0]:g}, {b[1, 1]:g}]"
        for cx, cy, r in np.asarray(self.disks, dtype=float).reshape(-1, 3):
            text += f" minus the disk r < {r:g} about ({cx:g}, {cy:g})"
        for x0, y0, x1, y1 in np.asarray(self.rects, dtype=float).reshape(-1, 4):
            text += (f" minus ({max(x0, b[0, 0]):g}, {min(x1, b[0, 1]):g}] x "
                     f"({max(y0, b[1, 0]):g}, {min(y1, b[1, 1]):g}]")
        return text

    # --- evaluation ---------------------------------------------------------------------
    def evaluate(self, points: np.ndarray) -> np.ndarray:
        """Displacement at points of the domain, shape (n, 2). ``ValueError`` naming how
        many points lie outside the domain and the first."""
        el, xi, eta = self._locate(points)
        N, _, _ = _shape(xi, eta)
        return np.einsum("pk,pkc->pc", N, self.values[self.elements[el]])

    def gradient(self, points: np.ndarray) -> np.ndarray:
        """Displacement gradient du_i/dx_j at points, shape (n, 2, 2)."""
        el, xi, eta = self._locate(points)
        _, Nx, Ny = _shape(xi, eta)
        X = self._element_nodes[el]
        U = self.values[self.elements[el]]
        J = np.stack([np.einsum("pk,pkc->pc", Nx, X), np.einsum("pk,pkc->pc", Ny, X)], axis=2)
        G_ref = np.stack([np.einsum("pk,pkc->pc", Nx, U), np.einsum("pk,pkc->pc", Ny, U)],
                         axis=2)                                     # du_i / dxi_d
        return G_ref @ np.linalg.inv(J)

    def strain_energy_density(self, points: np.ndarray) -> np.ndarray:
        """Strain energy per unit volume W = lambda/2 tr(eps)^2 + mu eps:eps (J/m^3)."""
        G = self.gradient(points)
        eps = 0.5 * (G + np.swapaxes(G, 1, 2))
        tr = np.trace(eps, axis1=1, axis2=2)
        return 0.5 * self.lam * tr ** 2 + self.mu * np.einsum("nij,nij->n", eps, eps)

    def stress(self, points: np.ndarray) -> np.ndarray:
        """Cauchy stress (Pa) at points, shape (n, 2, 2), with the model's effective Lame
        parameters (plane stress: lambda*)."""
        G = self.gradient(points)
        eps = 0.5 * (G + np.swapaxes(G, 1, 2))
        tr = np.trace(eps, axis1=1, axis2=2)
        return self.lam * tr[:, None, None] * np.eye(2) + 2.0 * self.mu * eps

    # --- export -------------------------------------------------------------------------
    def to_vtu(self, path: str | Path, point_data: dict | None = None) -> Path:
        """Write the field to a VTU file (meshio ``quad9`` cells) with ``displacement``
        (3 components) as point data."""
        import meshio

        n = self.node_coords.shape[0]
        pts3 = np.zeros((n, 3))
        pts3[:, :2] = self.node_coords
        disp = np.zeros((n, 3))
        disp[:, :2] = self.values
        data = {"displacement": disp}
        data.update(point_data or {})
        path = Path(path)
        meshio.write(path, meshio.Mesh(pts3, [("quad9", self.elements[:, _QUAD9])],
                                       point_data=data))
        return path
