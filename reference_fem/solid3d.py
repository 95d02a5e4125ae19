"""3D linear elasticity on mapped tetrahedral meshes (scikit-fem, quadratic tetrahedra).

The 3D companion of :mod:`reference_fem.mesh_elasticity` for the bodies of issue 55 that
are not boxes. A mesh is made of structured blocks: each block is a tensor grid of its
logical cube [0, 1]^3 and a vectorised map F from there to space; the hexahedral cells'
corners are placed at F of their logical positions, blocks meet vertex to vertex (merged
within a tolerance), and every hexahedron is split into 24 tetrahedra about its centre
and its faces' centres (each face into 4 triangles about its centre, each joined to the
cell's centre). That split is conforming whatever the blocks' relative orientation (a
face is split the same way from both sides), which a 5- or 6-tetrahedra split is not.
Every cell corner is F of its logical position (a face's or cell's centre the mean of its
mapped corners), so the vertices on a curved surface lie on it and the tetrahedra are
straight-sided: the geometry is
resolved to O(h^2) (facets inside a convex surface), the displacement of quadratic
elements (``ElementTetP2``) to O(h^2) near a curved part (O(h^3) elsewhere).

:class:`TetField` is the converged field: the P2 nodes, each tetrahedron's ten nodes
(vertices, then the edges 01, 12, 02, 03, 13, 23: scikit-fem's order, checked when
built) and the displacement at every node. It evaluates the displacement and the stress
at any point: in the tetrahedron that holds it, or (a point of the exact body that the
faceted mesh misses, between a convex curved surface and its facets, O(h^2) thin) by
the nearest tetrahedron's polynomial, extended (the map is affine, so its polynomial is
defined everywhere).
"""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from scipy.spatial import cKDTree

#: local edges of a P2 tetrahedron in scikit-fem's order
EDGES = np.array([[0, 1], [1, 2], [0, 2], [0, 3], [1, 3], [2, 3]])


#: the four corners (bit numbers) of each face -s, +s, -t, +t, -u, +u, in cyclic order
_FACE_CORNERS = np.array([[0, 1, 3, 2], [4, 5, 7, 6], [0, 1, 5, 4], [2, 3, 7, 6],
                          [0, 2, 6, 4], [1, 3, 7, 5]])


def block_points(F, n: tuple):
    """The vertices, face centres and cell centre of each cell of an n0 x n1 x n2 tensor
    grid of the logical cube mapped by F: (corners (nc, 8, 3), face centres (nc, 6, 3),
    centres (nc, 3)); corners in the order (i, j, k) bits, faces -s, +s, -t, +t, -u, +u.
    The corners are F of their logical positions, the face and cell centres the means of
    their mapped corners (so a face whose corners are coplanar is split in its plane: a
    prism's faceted mantle stays vertical)."""
    axes = [np.arange(m) / m for m in n]
    I, J, K = np.meshgrid(*[np.arange(m) for m in n], indexing="ij")
    I, J, K = I.ravel(), J.ravel(), K.ravel()
    d = [1.0 / m for m in n]
    lo = np.stack([axes[0][I], axes[1][J], axes[2][K]], axis=1)
    bits = np.array([[i, j, k] for i in (0, 1) for j in (0, 1) for k in (0, 1)], float)

    L = lo[:, None, :] + bits[None] * np.asarray(d)
    x, y, z = F(L[..., 0], L[..., 1], L[..., 2])
    corners = np.stack([x, y, z], axis=-1)
    faces = corners[:, _FACE_CORNERS].mean(axis=2)
    return corners, faces, corners.mean(axis=1)


def tet_mesh(blocks, tol: float):
    """``(points (3, np), tets (4, nt))`` of the 24-tetrahedra split of the mapped blocks
    ``[(F, (n0, n1, n2)), ...]`` (module docstring), every tetrahedron positively
    oriented; coincident points (closer than ``tol``) merged."""
    corners, faces, centres = [], [], []
    for F, n in blocks:
        c, f, m = block_points(F, n)
        corners.append(c)
        faces.append(f)
        centres.append(m)
    C, Fc, M = np.concatenate(corners), np.concatenate(faces), np.concatenate(centres)
    nc = len(C)
    allp = np.concatenate([C.reshape(-1, 3), Fc.reshape(-1, 3), M])
    pairs = cKDTree(allp).query_pairs(tol, output_type="ndarray")
    from scipy.sparse.csgraph import connected_components
    g = sp.coo_matrix((np.ones(len(pairs)), (pairs[:, 0], pairs[:, 1])), shape=(len(allp),) * 2)
    _, label = connected_components(g, directed=False)
    _, first, inv = np.unique(label, return_index=True, return_inverse=True)
    pts = allp[first]
    cid = inv[:nc * 8].reshape(nc, 8)
    fid = inv[nc * 8:nc * 14].reshape(nc, 6)
    mid = inv[nc * 14:]
    tets = []
    for f in range(6):
        q = _FACE_CORNERS[f]
        for e in range(4):
            a, b = cid[:, q[e]], cid[:, q[(e + 1) % 4]]
            tets.append(np.stack([a, b, fid[:, f], mid], axis=0))
    t = np.concatenate(tets, axis=1)
    P = pts[t]                                    # (4, nt, 3)
    vol = np.einsum("ij,ij->i", np.cross(P[1] - P[0], P[2] - P[0]), P[3] - P[0])
    if np.any(np.abs(vol) < 1e-14 * np.max(np.abs(vol))):
        raise RuntimeError("tet_mesh: a degenerate tetrahedron (a block map folds)")
    neg = vol < 0
    t[0, neg], t[1, neg] = t[1, neg].copy(), t[0, neg].copy()
    return np.ascontiguousarray(pts.T), np.ascontiguousarray(t)


class TetField:
    """A P2 displacement field on straight tetrahedra (module docstring).

    ``node_coords`` (n, 3), ``elements`` (nt, 10), ``values`` (n, 3); ``lam``, ``mu``
    the Lame parameters (the stress)."""

    def __init__(self, node_coords, elements, values, lam: float, mu: float):
        self.node_coords = np.asarray(node_coords, float)
        self.elements = np.asarray(elements, dtype=np.int64)
        self.values = np.asarray(values, float)
        self.lam, self.mu = float(lam), float(mu)
        V = self.node_coords[self.elements[:, :4]]              # (nt, 4, 3)
        self._x0 = V[:, 0]
        A = np.transpose(V[:, 1:] - V[:, :1], (0, 2, 1))        # columns: edges from v0
        self._Ainv = np.linalg.inv(A)
        self._tree = cKDTree(V.mean(axis=1))
        self._reach = float(np.max(np.linalg.norm(V - V.mean(axis=1, keepdims=True), axis=2)))
        self.bounds = list(zip(self.node_coords.min(axis=0), self.node_coords.max(axis=0)))

    def _bary(self, x, tet):
        r = np.einsum("nij,nj->ni", self._Ainv[tet], x - self._x0[tet])
        return np.c_[1.0 - r.sum(axis=1), r]

    def locate(self, x, k: int = 24):
        """The tetrahedron of each point: the one that holds it among the ``k`` nearest
        by centroid (barycentrics >= -1e-10), else the one it lies least outside of."""
        x = np.asarray(x, float)
        _, cand = self._tree.query(x, k=min(k, len(self.elements)))
        best = np.full(len(x), -1)
        worst = np.full(len(x), -np.inf)
        for j in range(cand.shape[1]):
            lam = self._bary(x, cand[:, j])
            m = lam.min(axis=1)
            better = m > worst
            worst = np.where(better, m, worst)
            best = np.where(better, cand[:, j], best)
        return best, worst

    def _shape(self, lam):
        """P2 shape functions (n, 10) at barycentrics ``lam`` (n, 4)."""
        v = lam * (2 * lam - 1)
        e = 4 * lam[:, EDGES[:, 0]] * lam[:, EDGES[:, 1]]
        return np.c_[v, e]

    def evaluate(self, x) -> np.ndarray:
        x = np.asarray(x, float)
        tet, _ = self.locate(x)
        N = self._shape(self._bary(x, tet))
        return np.einsum("nk,nkc->nc", N, self.values[self.elements[tet]])

    def gradient(self, x) -> np.ndarray:
        """du_i/dx_j (n, 3, 3) at points."""
        x = np.asarray(x, float)
        tet, _ = self.locate(x)
        lam = self._bary(x, tet)
        Ai = self._Ainv[tet]                                     # rows: d lam_1..3 / dx
        dl = np.concatenate([-Ai.sum(axis=1, keepdims=True), Ai], axis=1)   # (n, 4, 3)
        dv = (4 * lam - 1)[:, :, None] * dl
        a, b = EDGES[:, 0], EDGES[:, 1]
        de = 4 * (lam[:, a, None] * dl[:, b] + lam[:, b, None] * dl[:, a])
        dN = np.concatenate([dv, de], axis=1)                    # (n, 10, 3)
        return np.einsum("nkj,nki->nij", dN, self.values[self.elements[tet]])

    def stress(self, x) -> np.ndarray:
        g = self.gradient(x)
        eps = 0.5 * (g + np.transpose(g, (0, 2, 1)))
        tr = np.trace(eps, axis1=1, axis2=2)
        return 2 * self.mu * eps + self.lam * tr[:, None, None] * np.eye(3)

    def strain_energy_density(self, x) -> np.ndarray:
        g = self.gradient(x)
        eps = 0.5 * (g + np.transpose(g, (0, 2, 1)))
        tr = np.trace(eps, axis1=1, axis2=2)
        return self.mu * np.einsum("nij,nij->n", eps, eps) + 0.5 * self.lam * tr ** 2

    def to_vtu(self, path):
        import meshio
        mesh = meshio.Mesh(self.node_coords, [("tetra10", self.elements[:, [0, 1, 2, 3, 4, 5, 6, 7, 8, 9]])],
                           point_data={"u": self.values})
        mesh.write(str(path))
        return path


class Solid3D:
    """P2 elasticity on a mapped tetrahedral mesh (``tet_mesh``): the vector basis, its
    node positions and components, assembly, Dirichlet rows by position, traction by
    facets, the direct solve and the :class:`TetField`."""

    def __init__(self, points, tets, E: float, nu: float):
        from skfem import Basis, ElementTetP2, ElementVector, MeshTet
        from skfem.models.elasticity import lame_parameters
        self.mesh = MeshTet(points, tets)
        self.scalar = Basis(self.mesh, ElementTetP2())
        self.basis = Basis(self.mesh, ElementVector(ElementTetP2()))
        self.lam, self.mu = lame_parameters(E, nu)
        nv = self.mesh.p.shape[1]
        # per-scalar-node component dofs: vertices, then edges (scikit-fem numbering)
        self.node_dofs = np.concatenate([self.basis.nodal_dofs, self.basis.edge_dofs], axis=1)
        self.node_coords = np.concatenate(
            [self.mesh.p, 0.5 * (self.mesh.p[:, self.mesh.edges[0]]
                                 + self.mesh.p[:, self.mesh.edges[1]])], axis=1).T
        ed = self.scalar.element_dofs.T
        loc = self.node_coords[ed]
        mids = 0.5 * (loc[:, EDGES[:, 0]] + loc[:, EDGES[:, 1]])
        if not (np.all(ed[:, :4] < nv) and np.allclose(loc[:, 4:], mids, atol=1e-12)):
            raise RuntimeError("Solid3D: scikit-fem's P2 dof order is not the one assumed")
        self.elements = ed

    @property
    def N(self) -> int:
        return int(self.basis.N)

    def min_edge(self) -> float:
        p = self.mesh.p
        e = self.mesh.edges
        return float(np.min(np.linalg.norm(p[:, e[0]] - p[:, e[1]], axis=0)))

    def stiffness(self):
        from skfem import asm
        from skfem.models.elasticity import linear_elasticity
        return asm(linear_elasticity(self.lam, self.mu), self.basis).tocsr()

    def dofs(self, where, component: int) -> np.ndarray:
        """Unknowns of ``component`` at the P2 nodes where ``where(x) -> bool``."""
        return self.node_dofs[component, where(self.node_coords)]

    def traction_load(self, on, t) -> np.ndarray:
        """The load vector of the traction ``t(x) -> (3, ...)`` on the boundary facets
        whose centres satisfy ``on(x)`` (x: (3, ...))."""
        from skfem import FacetBasis, LinearForm
        from skfem.helpers import dot
        facets = self.mesh.facets_satisfying(lambda x: on(x), boundaries_only=True)
        fb = FacetBasis(self.mesh, self.basis.elem, facets=facets)

        @LinearForm
        def form(v, w):
            return dot(t(w.x), v)
        return form.assemble(fb)

    def solve(self, K, f, fixed, values=0.0) -> np.ndarray:
        """K u = f with the unknowns ``fixed`` set to ``values`` (SuperLU)."""
        u = np.zeros(self.N)
        fixed = np.unique(fixed)
        u[fixed] = values
        free = np.setdiff1d(np.arange(self.N), fixed)
        rhs = f[free] - K[free][:, fixed] @ u[fixed]
        u[free] = spla.splu(K[free][:, free].tocsc(), permc_spec="MMD_AT_PLUS_A").solve(rhs)
        if not np.all(np.isfinite(u)):
            raise RuntimeError("Solid3D: the solve returned non-finite values")
        return u

    def field(self, u) -> TetField:
        vals = u[self.node_dofs].T
        return TetField(self.node_coords, self.elements, vals, self.lam, self.mu)
