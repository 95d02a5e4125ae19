"""Uniform box grids in 1, 2 and 3 dimensions: node placement, node kinds, faces, surface nodes."""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .faces import Face

#: Where the nodes of a box sit. ``cell-centred``: one node at the centre of every cell of
#: side ``spacing`` (seeds 000, 001, 002). ``on-surface``: nodes on the cell vertices, so
#: the outermost nodes lie on the surface (seeds 003, 004).
PLACEMENTS = ("cell-centred", "on-surface")

#: Volume of a node on the surface of an ``on-surface`` grid: ``partial`` = the part of
#: its cell inside the body (1/2 per axis on which it lies on the surface: half on edges,
#: a quarter at 2D corners, seed 003 / ERRATA; half-weight end elements, seed 004),
#: ``full`` = a whole cell (seed 004, Fig. 1).
BOUNDARY_VOLUMES = ("partial", "full")

KIND_INTERIOR, KIND_FICTITIOUS = 0, 1


@dataclass
class BoxGrid:
    """Nodes of the box ``origin + [0, lengths]`` on a uniform grid of side ``spacing``.

    The grid is extended by ``layers`` nodes on every side (the fictitious layer, edge and
    corner regions included). Every node of the extended grid carries its integer index
    (real nodes have 0 <= index < nodes along every axis), its position ``x``, its kind
    (``is_interior`` = a real node of the body, otherwise fictitious) and its volume.
    "Interior" means "inside the body", as opposed to fictitious; it includes the nodes
    on the surface of an ``on-surface`` grid.

    Faces are :class:`~pdverify.pd.faces.Face` (named ``x-``, ``x+``, ...; side 0 at the
    lower end of the axis, 1 at the upper end); the surface arrays store them as
    ``Face.code`` = ``2 * axis + side``. On a cell-centred grid a *surface node* sits at
    the centre of every boundary cell face (seed 001 §3, Fig. 5; seed 002 in 1D); it is
    identified by its face and the index of the boundary cell it belongs to. Surface nodes
    are extra nodes, not part of the extended grid.
    """

    lengths: tuple
    origin: tuple
    spacing: float
    layers: int = 0
    placement: str = "cell-centred"
    boundary_volume: str = "partial"
    arrays: dict = field(init=False, repr=False, default_factory=dict)

    def __post_init__(self):
        if self.placement not in PLACEMENTS:
            raise ValueError(f"placement={self.placement!r}; allowed: {', '.join(PLACEMENTS)}")
        if self.boundary_volume not in BOUNDARY_VOLUMES:
            raise ValueError(f"boundary_volume={self.boundary_volume!r}; allowed: "
                             f"{', '.join(BOUNDARY_VOLUMES)}")
        self.lengths = tuple(float(v) for v in self.lengths)
        self.origin = tuple(float(v) for v in self.origin)
        self.dim = len(self.lengths)
        if not 1 <= self.dim <= 3:
            raise ValueError(f"a box grid has 1, 2 or 3 dimensions, got {self.dim}")
        h = self.spacing
        self.cells = tuple(int(round(L / h)) for L in self.lengths)
        centred = self.placement == "cell-centred"
        self.nodes_per_axis = tuple(n if centred else n + 1 for n in self.cells)
        self.ext_shape = tuple(n + 2 * self.layers for n in self.nodes_per_axis)
        idx = np.indices(self.ext_shape).reshape(self.dim, -1).T - self.layers
        self.index = idx
        self.x = np.asarray(self.origin) + (idx + (0.5 if centred else 0.0)) * h
        n_axis = np.asarray(self.nodes_per_axis)
        self._number_real(np.all((idx >= 0) & (idx < n_axis), axis=1))
        self.kind = np.where(self.is_interior, KIND_INTERIOR, KIND_FICTITIOUS)
        weight = np.ones(idx.shape[0])
        if not centred and self.boundary_volume == "partial":
            on_surface = self.is_interior[:, None] & ((idx == 0) | (idx == n_axis - 1))
            weight = np.prod(np.where(on_surface, 0.5, 1.0), axis=1)
        self.node_volume = weight * self.volume
        if centred:
            self._build_surface()

    # ------------------------------------------------------------------ ids
    def _number_real(self, real) -> None:
        """``is_interior``, the real nodes' ids and each node's number among them (-1)."""
        self.is_interior = real
        self.interior_ids = np.flatnonzero(real)
        self.interior_number = np.full(real.size, -1)
        self.interior_number[self.interior_ids] = np.arange(self.interior_ids.size)

    @property
    def n_ext(self) -> int:
        return self.index.shape[0]

    @property
    def n_interior(self) -> int:
        return self.interior_ids.size

    @property
    def volume(self) -> float:
        """Cell volume h^d (2D: per unit thickness; 1D: per unit cross-section)."""
        return self.spacing ** self.dim

    @property
    def face_area(self) -> float:
        """Cell face area h^(d-1) (2D: a cell edge of unit thickness; 1D: 1)."""
        return self.spacing ** (self.dim - 1)

    def ext_id(self, index) -> np.ndarray:
        """Extended-grid node id of integer node indices (..., dim)."""
        index = np.asarray(index) + self.layers
        return np.ravel_multi_index(tuple(np.moveaxis(index, -1, 0)), self.ext_shape)

    def face_coordinate(self, face: Face) -> float:
        """Coordinate of ``face`` (:class:`~pdverify.pd.faces.Face`) along its axis."""
        return self.origin[face.axis] + (0.0 if face.side == 0 else self.lengths[face.axis])

    def boundary_layer(self, face: Face) -> int:
        """Index, along the face's axis, of the layer of real nodes nearest ``face``."""
        return 0 if face.side == 0 else self.nodes_per_axis[face.axis] - 1

    def surface_on(self, face: Face) -> np.ndarray:
        """Which surface nodes lie on ``face`` (mask over the surface nodes)."""
        return self.surface_face == face.code

    def tangential_axes(self, axis: int) -> tuple:
        return tuple(a for a in range(self.dim) if a != axis)

    # ------------------------------------------------------------------ surface nodes
    def _build_surface(self):
        h = self.spacing
        faces, starts, cell_idx, pos, normal, face_of = [], [], [], [], [], []
        count = 0
        for axis in range(self.dim):
            for side in (0, 1):
                tang = self.tangential_axes(axis)
                shape = tuple(self.cells[t] for t in tang)
                t_idx = np.indices(shape).reshape(len(tang), -1).T if tang else np.zeros((1, 0), int)
                n = t_idx.shape[0]
                cidx = np.zeros((n, self.dim), dtype=int)
                cidx[:, list(tang)] = t_idx
                cidx[:, axis] = 0 if side == 0 else self.cells[axis] - 1
                x = np.asarray(self.origin) + (cidx + 0.5) * h
                x[:, axis] = self.face_coordinate(Face.at(axis, side))
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
        cell_index = np.asarray(cell_index)
        if not shape:  # 1D: one surface node per face
            return np.full(cell_index.shape[:-1], self.face_start[face], dtype=int)
        tang = self.tangential_axes(axis)
        t = tuple(cell_index[..., a] for a in tang)
        return self.face_start[face] + np.ravel_multi_index(t, shape)

    # ------------------------------------------------------------------ geometry
    def distance_to_surface(self, x) -> np.ndarray:
        """Distance of points inside the box to the nearest face."""
        x = np.asarray(x, dtype=float)
        lo = x - np.asarray(self.origin)
        hi = np.asarray(self.origin) + np.asarray(self.lengths) - x
        return np.minimum(lo, hi).min(axis=-1)

    # ------------------------------------------------------------------ bonds
    def bond_vectors(self, a, b) -> np.ndarray:
        """Bond vectors x_b - x_a of node pairs: on the lattice, index differences times
        the spacing (exact multiples of h)."""
        return (self.index[b] - self.index[a]) * self.spacing


#: nodes of a shape's bounding lattice that are neither real nor fictitious
KIND_VOID = 2


@dataclass
class ShapeGrid(BoxGrid):
    """The nodes of a 2D :class:`~pdverify.pd.shapes.Shape` or a 3D
    :class:`~pdverify.pd.shapes3d.Shape3D` cut from the uniform lattice of its bounding box
    ``origin + [0, lengths]`` (cell-centred).

    A node is real when its cell centre lies inside the shape; its volume is the part of
    its cell inside the shape (:meth:`Shape.fractions`; the slivers of cut cells whose
    centre lies outside are left out, so the body's volume is short by at most half a cell
    per boundary cell). The lattice nodes outside the shape within ``layers`` spacings of
    a real node along every axis (the stencil's reach) are the fictitious layer: every
    stencil bond of a real node ends on a real or fictitious node. The others are void
    (no bonds, ``KIND_VOID``).

    ``jitter``: every real node moves by a seeded random vector, uniform in the square
    (cube) of side ``jitter * spacing`` about its lattice point (``jitter_seed``); a node the move
    would take out of the shape stays at its lattice point (``jitter_kept`` counts them).
    The bond family stays the lattice's (the stencil's offsets, weights and cell volumes);
    the bonds' lengths and directions come from the moved positions
    (:meth:`bond_vectors`).
    """

    shape: object = None
    jitter: float = 0.0
    jitter_seed: int = 0

    def __post_init__(self):
        if self.placement != "cell-centred":
            raise ValueError("a shape is cut from a cell-centred lattice")
        super().__post_init__()
        if self.dim not in (2, 3) or getattr(self.shape, "dim", None) != self.dim:
            raise ValueError(f"a {self.dim}D box cuts a shape of its own dimension (2D or "
                             f"3D), got a {getattr(self.shape, 'dim', None)}D shape")
        s = self.shape
        lattice = self.x.copy()
        inside = s.inside(lattice)
        self._number_real(inside)
        fictitious = np.zeros_like(inside)
        if self.layers:
            from scipy.spatial import cKDTree
            out = np.flatnonzero(~inside)
            reach = self.layers * self.spacing * (1 + 1e-12)
            dist = cKDTree(lattice[inside]).query(lattice[out], p=np.inf,
                                                  distance_upper_bound=reach)[0]
            fictitious[out[np.isfinite(dist)]] = True
        self.is_void = ~inside & ~fictitious
        self.kind = np.where(inside, KIND_INTERIOR,
                             np.where(fictitious, KIND_FICTITIOUS, KIND_VOID))
        self.node_volume = np.full(self.index.shape[0], self.volume)
        self.node_volume[self.interior_ids] = self.volume * s.fractions(
            lattice[self.interior_ids], self.spacing)
        self.lattice_x = lattice
        self.jitter_kept = 0
        if self.jitter:
            rng = np.random.default_rng(self.jitter_seed)
            ids = self.interior_ids
            move = rng.uniform(-0.5, 0.5, size=(ids.size, self.dim)) * self.jitter * self.spacing
            moved = lattice[ids] + move
            stays = ~s.inside(moved)
            moved[stays] = lattice[ids][stays]
            self.x = lattice.copy()
            self.x[ids] = moved
            self.jitter_kept = int(stays.sum())

    def _build_surface(self):
        """No box surface nodes: a shape's boundary is its parts (``Shape.samples``)."""
        self.faces = ()
        self.face_start = np.zeros(1, dtype=int)
        self.surface_cell = np.zeros((0, self.dim), dtype=int)
        self.surface_x = np.zeros((0, self.dim))
        self.surface_normal = np.zeros((0, self.dim))
        self.surface_face = np.zeros(0, dtype=int)

    def bond_vectors(self, a, b) -> np.ndarray:
        if not self.jitter:
            return super().bond_vectors(a, b)
        return self.x[b] - self.x[a]

    def distance_to_surface(self, x) -> np.ndarray:
        return self.shape.closest(np.asarray(x, dtype=float))[2]
