"""Plane elasticity with isoparametric 9-node quadrilaterals on mapped meshes (scikit-fem).

The companion of :class:`~reference_fem.elasticity.TensorElasticity` for domains that are
not a box. A mesh is made of structured blocks: each block is a tensor grid in its
logical square [0, 1]^2 and a map F from there to the plane; every Q2 node (vertices,
edge midpoints, centres) is placed at F of its logical position, so the element map is
the biquadratic interpolant of F (isoparametric, ``skfem.MeshQuad2``): a curved boundary
is met at three points per edge and resolved to O(h^3).
"""
from __future__ import annotations

from functools import cached_property
from typing import Callable, Sequence

import numpy as np
import scipy.sparse as sp
from scipy.sparse.csgraph import connected_components
from scipy.spatial import cKDTree
from skfem import Basis, ElementQuad2, ElementVector, MeshQuad, MeshQuad2

from .elasticity import ElasticityBasis, Material
from .field import _lagrange_1d
from .mesh_field import TENSOR_NODES, MeshField

#: the four edges of an element as (start, middle, end) in the tensor order, counter-
#: clockwise: eta = 0, xi = 1, eta = 1, xi = 0
_EDGES = np.array([[0, 3, 6], [6, 7, 8], [8, 5, 2], [2, 1, 0]])


def mapped_mesh(blocks: Sequence[tuple], tol: float,
                slit: Callable[..., np.ndarray] | None = None) -> MeshQuad2:
    """One ``MeshQuad2`` from structured blocks.

    Each block is ``(s, t, F)``: increasing logical coordinates s, t in [0, 1] (the
    element edges along each logical axis) and a vectorised map ``F(s, t) -> (x, y)``.
    Blocks must meet node to node; coincident vertices (closer than ``tol``) are
    merged, and every element's nine nodes are placed at F of their logical positions.
    ``slit(x, y)`` (vectorised, optional) marks the vertices of a slit: two blocks that
    meet there keep their own vertices (a crack's two faces), merged only within a block.
    """
    elem_nodes = []          # (n_el, 9, 2) physical positions in the tensor order
    block_of = []
    for b, (s, t, F) in enumerate(blocks):
        s = np.asarray(s, float)
        t = np.asarray(t, float)
        ns, nt = s.size - 1, t.size - 1
        i, j = np.meshgrid(np.arange(ns), np.arange(nt), indexing="ij")
        i, j = i.ravel(), j.ravel()
        ds = (s[i + 1] - s[i])[:, None]
        dt = (t[j + 1] - t[j])[:, None]
        ls = s[i][:, None] + ds * TENSOR_NODES[None, :, 0]
        lt = t[j][:, None] + dt * TENSOR_NODES[None, :, 1]
        x, y = F(ls, lt)
        elem_nodes.append(np.stack([x, y], axis=2))
        block_of.append(np.full(i.size, b))
    X = np.concatenate(elem_nodes)                                 # (n_el, 9, 2)
    # unique vertices (tensor corners 0, 6, 8, 2 counter-clockwise)
    corners = X[:, [0, 6, 8, 2], :].reshape(-1, 2)
    pairs = cKDTree(corners).query_pairs(tol, output_type="ndarray")
    if slit is not None and len(pairs):
        block = np.repeat(np.concatenate(block_of), 4)
        on = np.asarray(slit(corners[:, 0], corners[:, 1]), dtype=bool)
        pairs = pairs[~(on[pairs[:, 0]] & (block[pairs[:, 0]] != block[pairs[:, 1]]))]
    graph = sp.coo_matrix((np.ones(len(pairs)), (pairs[:, 0], pairs[:, 1])),
                          shape=(len(corners),) * 2)
    _, label = connected_components(graph, directed=False)
    _, first, inverse = np.unique(label, return_index=True, return_inverse=True)
    p = np.ascontiguousarray(corners[first].T)
    t = np.ascontiguousarray(inverse.reshape(-1, 4).T)
    lin = MeshQuad(p, t)
    if not np.array_equal(lin.t, t):
        raise RuntimeError("mapped_mesh: scikit-fem reordered the element vertices")
    m2 = MeshQuad2.from_mesh(lin)
    # place every quadratic node at its block map: the nodes of m2 in skfem's local order
    basis = Basis(m2, ElementQuad2())
    perm = _skfem_to_tensor(ElementQuad2())
    doflocs = m2.doflocs.copy()
    for k_sk, k_t in enumerate(perm):
        doflocs[:, basis.element_dofs[k_sk]] = X[:, k_t, :].T
    return MeshQuad2(np.ascontiguousarray(doflocs), np.ascontiguousarray(m2.t))


def _skfem_to_tensor(element) -> np.ndarray:
    """For each local node of skfem's ``ElementQuad2``, its number in the tensor order."""
    ref = np.asarray(element.doflocs)
    return np.array([3 * int(round(2 * a)) + int(round(2 * b)) for a, b in ref])


class MeshElasticity(ElasticityBasis):
    """Small-strain plane elasticity with vector Q2 elements on a ``MeshQuad2``.

    Parameters
    ----------
    mesh : the isoparametric mesh (see :func:`mapped_mesh`).
    material : a 2D :class:`Material`.
    domain : the exact domain for :class:`MeshField`: ``box`` [[x0, x1], [y0, y1]],
        ``disks`` rows (cx, cy, r), ``rects`` rows (x0, y0, x1, y1) (removed).
    intorder : quadrature degree of the stiffness; the default 5 is 3 x 3 Gauss points,
        exact for Q2 on parallelograms and the usual full integration of isoparametric
        Q2 (Zienkiewicz & Taylor, The Finite Element Method, vol. 1, ch. on numerical
        integration).
    """

    def __init__(self, mesh: MeshQuad2, material: Material, domain: dict, intorder: int = 5):
        if material.dim != 2:
            raise ValueError("MeshElasticity is two-dimensional")
        self.mesh = mesh
        self.material = material
        self.domain = domain
        self.element = ElementVector(ElementQuad2())
        self.basis = Basis(mesh, self.element, intorder=intorder)
        self.scalar = Basis(mesh, ElementQuad2(), intorder=intorder)
        self.split = self.basis.split_indices()
        self.dof_component = np.empty(self.basis.N, dtype=np.int64)
        for c, idx in enumerate(self.split):
            self.dof_component[idx] = c
        self.dof_coords = self.basis.doflocs
        self.dof_coords_scalar = self.scalar.doflocs
        for idx in self.split:        # component c of scalar node k is DOF split[c][k]
            if not np.array_equal(self.basis.doflocs[:, idx], self.scalar.doflocs):
                raise RuntimeError("vector and scalar Q2 DOFs do not correspond")

    @cached_property
    def elements(self) -> np.ndarray:
        """Node numbers (scalar Q2 DOFs) of each element in the tensor order, (n_el, 9)."""
        perm = _skfem_to_tensor(ElementQuad2())
        el = np.empty((self.mesh.t.shape[1], 9), dtype=np.int64)
        el[:, perm] = self.scalar.element_dofs.T
        return el

    @cached_property
    def boundary_edges(self) -> np.ndarray:
        """The boundary edges as node triples (start, middle, end), each running
        counter-clockwise about its element (the domain lies to the left), (n_edges, 3)."""
        e = self.elements[:, _EDGES].reshape(-1, 3)
        key = np.sort(e[:, [0, 2]], axis=1)
        _, inverse, counts = np.unique(key, axis=0, return_inverse=True, return_counts=True)
        return e[counts[inverse.ravel()] == 1]

    def traction_load(self, on: Callable[..., np.ndarray], t) -> np.ndarray:
        """Load vector of a traction on the boundary edges whose middle node satisfies
        ``on(x, y)``: ``t`` is a constant vector (Pa) or a function
        ``t(x, y, nx, ny) -> (tx, ty)`` of points and outward unit normals.

        Integrated edge by edge with 6-point Gauss-Legendre on the quadratic edge
        x(s) = sum_i N_i(s) X_i (exact for a constant traction on a curved Q2 edge);
        assembled here rather than with ``skfem.FacetBasis``, whose inverse element map
        (absolute Newton tolerance 1e-12 in reference coordinates) does not converge
        on the tiny elements of a strongly graded mesh."""
        edges = self.boundary_edges
        xy = self.dof_coords_scalar
        mid = xy[:, edges[:, 1]]
        edges = edges[np.asarray(on(mid[0], mid[1]), dtype=bool)]
        if edges.size == 0:
            raise ValueError("traction_load: no boundary edge satisfies the selector")
        gp, gw = np.polynomial.legendre.leggauss(6)
        s, w = 0.5 * (gp + 1.0), 0.5 * gw
        N, dN = _lagrange_1d(s)                                      # (q, 3)
        X = xy[:, edges]                                             # (2, e, 3)
        x = np.einsum("qi,cei->ceq", N, X)
        dx = np.einsum("qi,cei->ceq", dN, X)
        length = np.hypot(dx[0], dx[1])                              # |x'(s)|, (e, q)
        nx, ny = dx[1] / length, -dx[0] / length                     # right of the tangent
        if callable(t):
            tx, ty = t(x[0], x[1], nx, ny)
            tx = np.broadcast_to(np.asarray(tx, dtype=float), length.shape)
            ty = np.broadcast_to(np.asarray(ty, dtype=float), length.shape)
        else:
            tc = np.asarray(t, dtype=float)
            tx = np.full(length.shape, tc[0])
            ty = np.full(length.shape, tc[1])
        f = np.zeros(self.basis.N)
        for c, tc in enumerate((tx, ty)):
            local = np.einsum("qi,eq,q->ei", N, tc * length, w)     # (e, 3)
            np.add.at(f, self.split[c][edges], local)
        return self.material.scale * f

    def field(self, u: np.ndarray) -> MeshField:
        """The displacement as a self-contained :class:`MeshField`."""
        elements = self.elements
        values = np.stack([u[idx] for idx in self.split], axis=1)
        lam, mu = self.material.lame()
        d = self.domain
        return MeshField(node_coords=np.ascontiguousarray(self.scalar.doflocs.T),
                         elements=elements, values=values, lam=lam, mu=mu,
                         box=np.asarray(d["box"], float),
                         disks=np.asarray(d.get("disks", np.zeros((0, 3))), float).reshape(-1, 3),
                         rects=np.asarray(d.get("rects", np.zeros((0, 4))), float).reshape(-1, 4))

    def min_edge(self) -> float:
        """Shortest distance between adjacent vertices of an element (m)."""
        p = self.mesh.p[:, self.mesh.t]                              # (2, 4, n_el)
        d = np.linalg.norm(p - np.roll(p, 1, axis=1), axis=0)
        return float(d.min())
