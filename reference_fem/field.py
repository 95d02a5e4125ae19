"""A quadratic displacement field on a tensor-product mesh: evaluation, energy density, VTU."""
from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np


def midpoint_refined(c: np.ndarray) -> np.ndarray:
    """Vertex coordinates with every element midpoint inserted (the Q2 node line)."""
    c = np.asarray(c, dtype=float)
    out = np.empty(2 * c.size - 1)
    out[0::2] = c
    out[1::2] = 0.5 * (c[:-1] + c[1:])
    return out


def _lagrange_1d(s: np.ndarray):
    """Quadratic Lagrange basis on [0, 1] with nodes 0, 1/2, 1, and d/ds; shape (n, 3)."""
    phi = np.stack([2.0 * (s - 0.5) * (s - 1.0), -4.0 * s * (s - 1.0), 2.0 * s * (s - 0.5)], axis=1)
    dphi = np.stack([4.0 * s - 3.0, 4.0 - 8.0 * s, 4.0 * s - 1.0], axis=1)
    return phi, dphi


@dataclass(frozen=True, eq=False)
class FieldSolution:
    """Piecewise tensor-product quadratic displacement field (the FEM solution).

    Attributes
    ----------
    coords : vertex coordinates per axis (the tensor-product mesh), each increasing.
    values : displacement at the nodes of the midpoint-refined grid, shape
        ``(n_x', n_y'[, n_z'], dim)`` with ``n' = 2 n - 1`` and ``'ij'`` indexing.
    lam, mu : effective Lame parameters of the model (plane stress uses lambda*), used by
        :meth:`strain_energy_density`.
    """

    coords: tuple
    values: np.ndarray
    lam: float
    mu: float

    @property
    def dim(self) -> int:
        return len(self.coords)

    @property
    def bounds(self) -> np.ndarray:
        """Domain box, shape (dim, 2)."""
        return np.array([[c[0], c[-1]] for c in self.coords])

    def nodes(self) -> np.ndarray:
        """Coordinates of the Q2 nodes, shape (n, dim), in the order of
        ``values.reshape(-1, dim)``."""
        grids = np.meshgrid(*[midpoint_refined(c) for c in self.coords], indexing="ij")
        return np.stack([g.ravel() for g in grids], axis=1)

    def nodal_displacement(self) -> np.ndarray:
        """Displacement at :meth:`nodes`, shape (n, dim)."""
        return self.values.reshape(-1, self.dim)

    def max_displacement(self) -> float:
        """Largest displacement magnitude over the Q2 nodes."""
        return float(np.max(np.linalg.norm(self.nodal_displacement(), axis=1)))

    # --- evaluation ---------------------------------------------------------------------
    def _locate(self, points: np.ndarray):
        pts = np.asarray(points, dtype=float)
        if pts.ndim != 2 or pts.shape[1] != self.dim:
            raise ValueError(f"points must have shape (n, {self.dim}), got {pts.shape}")
        if not np.all(np.isfinite(pts)):
            raise ValueError("points contain NaN or inf")
        lo, hi = self.bounds[:, 0], self.bounds[:, 1]
        # Points on the boundary (PD surface nodes) belong to the domain; the tolerance
        # absorbs the round-off of a node grid built from a different origin.
        tol = 1e-10 * np.max(hi - lo)
        outside = np.any((pts < lo - tol) | (pts > hi + tol), axis=1)
        if np.any(outside):
            first = pts[np.argmax(outside)]
            box = " x ".join(f"[{a:g}, {b:g}]" for a, b in zip(lo, hi))
            raise ValueError(f"{int(outside.sum())} of {len(pts)} points lie outside the domain "
                             f"{box}; first: ({', '.join(f'{v:g}' for v in first)})")
        idx, phi, dphi = [], [], []
        for k, c in enumerate(self.coords):
            e = np.clip(np.searchsorted(c, pts[:, k], side="right") - 1, 0, c.size - 2)
            h = c[e + 1] - c[e]
            s = np.clip((pts[:, k] - c[e]) / h, 0.0, 1.0)
            p, dp = _lagrange_1d(s)
            idx.append(2 * e[:, None] + np.arange(3)[None, :])
            phi.append(p)
            dphi.append(dp / h[:, None])
        return idx, phi, dphi

    def _gather(self, idx):
        """Nodal values of each point's element, shape (n, 3, 3[, 3], dim)."""
        if self.dim == 2:
            return self.values[idx[0][:, :, None], idx[1][:, None, :]]
        return self.values[idx[0][:, :, None, None], idx[1][:, None, :, None],
                           idx[2][:, None, None, :]]

    def evaluate(self, points: np.ndarray) -> np.ndarray:
        """Displacement at arbitrary points, shape (n, dim).

        Raises ``ValueError`` naming how many points lie outside the domain and the first.
        """
        idx, phi, _ = self._locate(points)
        U = self._gather(idx)
        if self.dim == 2:
            return np.einsum("na,nb,nabc->nc", phi[0], phi[1], U)
        return np.einsum("na,nb,nd,nabdc->nc", phi[0], phi[1], phi[2], U)

    def gradient(self, points: np.ndarray) -> np.ndarray:
        """Displacement gradient du_i/dx_j at points, shape (n, dim, dim)."""
        idx, phi, dphi = self._locate(points)
        U = self._gather(idx)
        if self.dim == 2:
            gx = np.einsum("na,nb,nabc->nc", dphi[0], phi[1], U)
            gy = np.einsum("na,nb,nabc->nc", phi[0], dphi[1], U)
            return np.stack([gx, gy], axis=2)
        gx = np.einsum("na,nb,nd,nabdc->nc", dphi[0], phi[1], phi[2], U)
        gy = np.einsum("na,nb,nd,nabdc->nc", phi[0], dphi[1], phi[2], U)
        gz = np.einsum("na,nb,nd,nabdc->nc", phi[0], phi[1], dphi[2], U)
        return np.stack([gx, gy, gz], axis=2)

    def strain_energy_density(self, points: np.ndarray) -> np.ndarray:
        """Strain energy per unit volume W = lambda/2 tr(eps)^2 + mu eps:eps (J/m^3) at
        points. The gradient jumps across element interfaces; a point on an interface takes
        the element on its upper side along each axis (the last element at the upper bound)."""
        G = self.gradient(points)
        eps = 0.5 * (G + np.swapaxes(G, 1, 2))
        tr = np.trace(eps, axis1=1, axis2=2)
        return 0.5 * self.lam * tr ** 2 + self.mu * np.einsum("nij,nij->n", eps, eps)

    # --- export -------------------------------------------------------------------------
    def to_vtu(self, path: str | Path, point_data: dict | None = None) -> Path:
        """Write the field to a VTU file (meshio): every Q2 element split into 2^dim linear
        cells on the refined grid, with ``displacement`` (3 components) and
        ``strain_energy_density`` (element-interior evaluation) as point data."""
        import meshio

        pts = self.nodes()
        shape = tuple(2 * c.size - 1 for c in self.coords)
        ids = np.arange(int(np.prod(shape))).reshape(shape)
        if self.dim == 2:
            cells = np.stack([ids[:-1, :-1], ids[1:, :-1], ids[1:, 1:], ids[:-1, 1:]],
                             axis=-1).reshape(-1, 4)
            cell_type = "quad"
        else:
            c = [ids[:-1, :-1, :-1], ids[1:, :-1, :-1], ids[1:, 1:, :-1], ids[:-1, 1:, :-1],
                 ids[:-1, :-1, 1:], ids[1:, :-1, 1:], ids[1:, 1:, 1:], ids[:-1, 1:, 1:]]
            cells = np.stack(c, axis=-1).reshape(-1, 8)
            cell_type = "hexahedron"
        disp = np.zeros((pts.shape[0], 3))
        disp[:, :self.dim] = self.nodal_displacement()
        data = {"displacement": disp, "strain_energy_density": self.strain_energy_density(pts)}
        data.update(point_data or {})
        pts3 = np.zeros((pts.shape[0], 3))
        pts3[:, :self.dim] = pts
        path = Path(path)
        meshio.write(path, meshio.Mesh(pts3, [(cell_type, cells)], point_data=data))
        return path
