"""Linear bond-based PD on box grids of any dimension: bond stiffnesses and the sparse stiffness."""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from .bonds import Stencil, bond_pairs, homogeneous_extensions
from .closure import Closure, real_identity
from .grid import BoxGrid
from .influence import Influence


class BondBasedModel:
    """Linearised bond-based PD: pairwise forces along the reference bond direction.

    Bond a-b (a -> a + k for every half-stencil offset k the closure keeps) has the
    micromodulus c omega(|xi|); linearised, its force on a is s_b (n . (u_b - u_a)) n with
    the spring stiffness

        s_b = alpha_b c omega(|xi|) beta_k V_a V_b / |xi|,

    so that the force density on a is c omega (e / |xi|) V_b (seed 004, Eq. 33, times V_a;
    seed 002, Eq. 3 with c omega / |xi| = v^2 rho / (delta xi^2); seed 003, Eq. 1).
    ``alpha_b`` is the closure's bond factor (1 by default), ``beta_k`` the stencil's
    partial volume and V the node volumes (grid volumes times ``thickness``: the
    cross-section A in 1D, the thickness in 2D). Offsets whose weight omega beta is zero
    (the tip of a conical micromodulus at integer m) carry no bond.

    ``K`` (d * n_ext square, component-major) is the symmetric stiffness of all grid nodes,
    K u = external nodal forces, assembled from the bond arrays in one sparse call:
    K = sum_b s_b (n n^T) kron (e_a - e_b)(e_a - e_b)^T. :meth:`reduced` restricts it to
    the closure's unknowns (displacement map) and to the real nodes' equations.
    """

    def __init__(self, grid: BoxGrid, stencil: Stencil, micromodulus: float,
                 influence: Influence, closure: Closure | None = None, *,
                 thickness: float = 1.0):
        if grid.dim != stencil.dim:
            raise ValueError(f"dimensions differ: grid {grid.dim}, stencil {stencil.dim}")
        self.grid, self.stencil, self.influence = grid, stencil, influence
        self.closure = closure = closure or Closure()
        self.c = float(micromodulus)
        self.spacing = h = grid.spacing
        self.m_ratio = stencil.m_ratio
        self.horizon = delta = stencil.m_ratio * h
        self.thickness = float(thickness)
        self.node_volume = grid.node_volume * self.thickness

        offsets, beta = stencil.half_offsets, stencil.half_beta
        r = np.linalg.norm(offsets, axis=1) * h
        live = influence.omega(r, delta) * beta > 0
        self.offsets, self.beta_k = offsets[live], beta[live]
        a, b, which = bond_pairs(grid.ext_shape, offsets)
        keep = closure.bond_mask(grid, a, b) & live[which]
        a, b, which = a[keep], b[keep], which[keep]
        xi = grid.bond_vectors(a, b)
        x = np.linalg.norm(xi, axis=1)
        self.bond_a, self.bond_b, self.bond_which = a, b, which
        self.bond_x, self.bond_n = x, xi / x[:, None]
        self.bond_factor = (closure.bond_factor(a, b, self.bond_n)
                            if closure.bond_factor is not None else np.ones(a.size))
        if closure.geometric_factor is not None:
            self.bond_factor = self.bond_factor * closure.geometric_factor(self)
        self.bond_beta = beta[which]
        #: omega(|xi|) beta of every bond (the weight of its end's horizon sum)
        self.bond_weight = influence.omega(x, delta) * self.bond_beta
        self.bond_stiffness = (self.bond_factor * self.c * self.bond_weight
                               * self.node_volume[a] * self.node_volume[b] / x)
        for hook in (closure.weight_factor, closure.force_factor):
            if hook is not None:
                factor = hook(self)
                self.bond_factor = self.bond_factor * factor
                self.bond_stiffness = self.bond_stiffness * factor
        self.n_unknown_nodes = (closure.n_unknown_nodes if closure.n_unknown_nodes is not None
                                else grid.n_interior)
        self._K = None

    @property
    def K(self) -> sp.csr_matrix:
        """The stiffness, assembled on first use (energy and force queries do not need it)."""
        if self._K is None:
            self._K = self._assemble()
        return self._K

    @property
    def dim(self) -> int:
        return self.grid.dim

    def _assemble(self) -> sp.csr_matrix:
        d, ne = self.dim, self.grid.n_ext
        a, b, s, n = self.bond_a, self.bond_b, self.bond_stiffness, self.bond_n
        rows, cols, vals = [], [], []
        for p in range(d):          # d^2 blocks, each vectorised over bonds
            for q in range(d):
                w = s * n[:, p] * n[:, q]
                ra, rb, ca, cb = p * ne + a, p * ne + b, q * ne + a, q * ne + b
                rows += [ra, rb, ra, rb]
                cols += [ca, cb, cb, ca]
                vals += [w, w, -w, -w]
        # duplicates (a node's many bonds) are summed by the COO -> CSR step
        return sp.csr_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))),
                             shape=(d * ne, d * ne))

    def displacement_map(self) -> sp.csr_matrix:
        """The closure's all-node map (I_d kron A_U), identity on real nodes by default."""
        cl, g = self.closure, self.grid
        A_U = cl.displacement_map if cl.displacement_map is not None else real_identity(g)
        return sp.kron(sp.identity(self.dim, format="csr"), A_U, format="csr")

    def real_rows(self) -> np.ndarray:
        """Row indices of K that are the real nodes' equations (component-major)."""
        ne = self.grid.n_ext
        return np.concatenate([k * ne + self.grid.interior_ids for k in range(self.dim)])

    def reduced(self) -> sp.csr_matrix:
        """The real nodes' equations in terms of the unknowns: K[real rows] @ (I kron A_U)."""
        return (self.K[self.real_rows()] @ self.displacement_map()).tocsr()

    def bond_extensions(self, u) -> np.ndarray:
        """Linearised bond extensions e_b = n_b . (u_b - u_a) of the unknowns ``u``."""
        U = (self.displacement_map() @ np.asarray(u, dtype=float)).reshape(self.dim, -1)
        return np.einsum("kb,bk->b", U[:, self.bond_b] - U[:, self.bond_a], self.bond_n)

    def bond_forces(self, u) -> np.ndarray:
        """Scalar bond forces s_b e_b (tension positive) of the unknowns ``u``."""
        return self.bond_stiffness * self.bond_extensions(u)

    def bond_end_forces(self, u) -> tuple[np.ndarray, np.ndarray]:
        """The bond force split between its ends: half each (one pairwise spring)."""
        half = 0.5 * self.bond_forces(u)
        return half, half

    def strain_energy_density(self, u) -> np.ndarray:
        """W_i = 1 / (2 V_i) sum_(bonds at i) s_b e_b^2 / 2 at every grid node: half of each
        bond's energy s e^2 / 2 goes to each end (seed 003, Eq. 5 discretised)."""
        e = self.bond_extensions(u)
        half = 0.25 * self.bond_stiffness * e * e
        n = self.grid.n_ext
        return (np.bincount(self.bond_a, half, n) + np.bincount(self.bond_b, half, n)) / self.node_volume

    def bulk_work_density(self, strain) -> float:
        """W = 1/4 sum_b f_b e_b / V_i at a node with a complete neighbourhood of the bulk
        lattice under the homogeneous strain ``strain`` (d x d): every stencil offset a
        bond, e = |xi| n.strain.n, f = s e (the energy density, seed 003 Eq. 5)."""
        st = self.stencil
        r, n = st.vectors(self.spacing)
        e = homogeneous_extensions(r, n, strain)
        V = self.grid.volume * self.thickness
        s = self.c * self.influence.omega(r, self.horizon) * st.beta * V * V / r
        return float(0.25 * np.sum(s * e * e) / V)

    def lumped_mass(self, density: float) -> np.ndarray:
        """Nodal masses rho V_i of the real nodes (component-major, repeated per component)."""
        return np.tile(density * self.node_volume[self.grid.interior_ids], self.dim)

    def n_bonds(self) -> int:
        return int(self.bond_a.size)
