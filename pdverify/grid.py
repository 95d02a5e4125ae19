"""Uniform 2D/3D cell grids on boxes: interior and fictitious nodes, faces and surface nodes."""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np


@dataclass
class BoxGrid:
    """Cells of side ``spacing`` on the box ``origin + [0, lengths]``, nodes at cell centres.

    The grid is extended by ``layers`` cells on every side (the fictitious layer, edge and
    corner regions included). Every node of the extended grid carries its integer cell
    index (interior cells have 0 <= index < cells along every axis) and its position.

    Faces are numbered ``2 * axis + side`` (side 0 at the lower end of the axis, 1 at the
    upper end). A surface node sits at the centre of every boundary cell face (seed 001
    §3, Fig. 5); it is identified by its face and the index of the boundary cell it
    belongs to.
    """

    lengths: tuple
    origin: tuple
    spacing: float
    layers: int = 0
    arrays: dict = field(init=False, repr=False, default_factory=dict)

    def __post_init__(self):
        self.lengths = tuple(float(v) for v in self.lengths)
        self.origin = tuple(float(v) for v in self.origin)
        self.dim = len(self.lengths)
        h = self.spacing
        self.cells = tuple(int(round(L / h)) for L in self.lengths)
        self.ext_shape = tuple(n + 2 * self.layers for n in self.cells)
        idx = np.indices(self.ext_shape).reshape(self.dim, -1).T - self.layers
        self.index = idx
        self.x = np.asarray(self.origin) + (idx + 0.5) * h
        cells = np.asarray(self.cells)
        self.is_interior = np.all((idx >= 0) & (idx < cells), axis=1)
        self.interior_ids = np.flatnonzero(self.is_interior)
        self.interior_number = np.full(idx.shape[0], -1)
        self.interior_number[self.interior_ids] = np.arange(self.interior_ids.size)
        self._build_surface()

    # ------------------------------------------------------------------ ids
    @property
    def n_ext(self) -> int:
        return self.index.shape[0]

    @property
    def n_interior(self) -> int:
        return self.interior_ids.size

    @property
    def volume(self) -> float:
        """Cell volume h^d (2D: per unit thickness)."""
        return self.spacing ** self.dim

    @property
    def face_area(self) -> float:
        """Cell face area h^(d-1) (2D: a cell edge of unit thickness)."""
        return self.spacing ** (self.dim - 1)

    def ext_id(self, index) -> np.ndarray:
        """Extended-grid node id of integer cell indices (..., dim)."""
        index = np.asarray(index) + self.layers
        return np.ravel_multi_index(tuple(np.moveaxis(index, -1, 0)), self.ext_shape)

    def tangential_axes(self, axis: int) -> tuple:
        return tuple(a for a in range(self.dim) if a != axis)

    # ------------------------------------------------------------------ surface
    def _build_surface(self):
        h = self.spacing
        faces, starts, cell_idx, pos, normal, face_of = [], [], [], [], [], []
        count = 0
        for axis in range(self.dim):
            for side in (0, 1):
                tang = self.tangential_axes(axis)
                shape = tuple(self.cells[t] for t in tang)
                t_idx = np.indices(shape).reshape(len(tang), -1).T
                n = t_idx.shape[0]
                cidx = np.zeros((n, self.dim), dtype=int)
                cidx[:, list(tang)] = t_idx
                cidx[:, axis] = 0 if side == 0 else self.cells[axis] - 1
                x = np.asarray(self.origin) + (cidx + 0.5) * h
                x[:, axis] = self.origin[axis] + (0.0 if side == 0 else self.lengths[axis])
                nrm = np.zeros((n, self.dim))
                nrm[:, axis] = -1.0 if side == 0 else 1.0
                faces.append((axis, side, shape))
                starts.append(count)
                cell_idx.append(cidx)
                pos.append(x)
                normal.append(nrm)
                face_of.append(np.full(n, 2 * axis + side))
                count += n
        self.faces = faces
        self.face_start = np.asarray(starts + [count])
        self.surface_cell = np.concatenate(cell_idx)
        self.surface_x = np.concatenate(pos)
        self.surface_normal = np.concatenate(normal)
        self.surface_face = np.concatenate(face_of)

    @property
    def n_surface(self) -> int:
        return self.surface_x.shape[0]

    def surface_id(self, face: int, cell_index) -> np.ndarray:
        """Surface-node id on ``face`` for boundary-cell indices (..., dim)."""
        axis, _, shape = self.faces[face]
        tang = self.tangential_axes(axis)
        cell_index = np.asarray(cell_index)
        t = tuple(cell_index[..., a] for a in tang)
        return self.face_start[face] + np.ravel_multi_index(t, shape)

    # ------------------------------------------------------------------ geometry
    def distance_to_surface(self, x) -> np.ndarray:
        """Distance of points inside the box to the nearest face."""
        x = np.asarray(x, dtype=float)
        lo = x - np.asarray(self.origin)
        hi = np.asarray(self.origin) + np.asarray(self.lengths) - x
        return np.minimum(lo, hi).min(axis=-1)
