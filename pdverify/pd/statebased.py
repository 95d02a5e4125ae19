"""Linear ordinary state-based PD on box grids of any dimension, as sparse operator products."""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from .bonds import Stencil, bond_pairs, build_stencil, homogeneous_extensions
from .closure import Closure, real_identity
from .grid import BoxGrid
from .influence import Influence, StateBasedConstants


def state_based_stencil(dim: int, m_ratio: float, spacing: float, influence: Influence,
                        quadrature: str = "partial-volume") -> Stencil:
    """:func:`~pdverify.pd.bonds.build_stencil` for a state-based model: with
    ``moment-corrected`` the fourth moment made isotropic is the one of the state-based
    weight omega |xi|^2 (the discrete bulk then has the continuum moduli)."""
    h, delta = float(spacing), float(m_ratio) * float(spacing)

    def moment_weight(offsets):
        r = np.linalg.norm(offsets, axis=1) * h
        return influence.omega(r, delta) * r ** 2

    return build_stencil(dim, float(m_ratio), quadrature=quadrature, moment_weight=moment_weight)


#: the m of a complete neighbourhood: the stencil's discrete sum, or the continuum integral
COMPLETE_M = ("stencil", "continuum")


class StateBasedModel:
    """Linearised ordinary state-based PD (seed 000 §4.2 and App. D; seed 001 §2-3).

    Built from a grid, a stencil (offsets and weights beta), the constants, an influence
    function and a :class:`~pdverify.pd.closure.Closure` from the boundary treatment.
    Bonds are the stencil pairs (a, a + k), one per half-stencil offset, that the closure
    keeps. ``thickness`` scales every node volume: the cross-section A in 1D, the plate
    thickness in 2D (1 = per unit thickness), unused in 3D.

    Unknowns (component-major, ``d * n_unknown_nodes``): the closure's unknown nodes,
    by default the real nodes. Operators (sparse; names follow seed 000 App. D):
      U = (I_d kron A_U) u~         all node displacements (closure's displacement map)
      e = A_e U                     bond extensions n . (U_b - U_a), Eq. (21) of seed 001
      theta = A_theta e             real-node dilatations, Eq. (23) of seed 001 / (51) of 000
      Theta = A_Theta theta         all node dilatations (closure's dilatation map)
      f = K_e e + K_theta Theta     scalar bond forces times beta V_a V_b, Eq. (24) / (53)
      rows = P f                    equations: minus the internal nodal force of every real
                                    node (:meth:`equilibrium_rows`), plus a correction's
                                    flux rows (:meth:`bond_force_rows`)
    so K = P K_b with K_b = K_e A_e A_U + K_theta A_Theta A_theta A_e A_U.
    Where things are multiplied out: K_b is never formed in 2D/3D (each of its rows would
    couple ~1000 dofs in 3D); :meth:`stiffness` multiplies out the two terms
    (P K_e) B + (P K_theta A_Theta)(A_theta B) with B = A_e A_U, each a product of sparse
    factors (``map_last``: B is not formed, :meth:`unknown_rows`). :meth:`bond_force_matrix`
    does form K_b, for 1D bars, where it is banded and both the stiffness and the
    section-force rows (seed 000, Eq. 60) need it.
    :meth:`rows_of_state` applies the factors to a given state without multiplying
    anything out.
    """

    def __init__(self, grid: BoxGrid, stencil: Stencil, constants: StateBasedConstants,
                 influence: Influence, closure: Closure | None = None, *,
                 thickness: float = 1.0, complete_m: str = "stencil"):
        if grid.dim != stencil.dim or grid.dim != constants.dim:
            raise ValueError(f"dimensions differ: grid {grid.dim}, stencil {stencil.dim}, "
                             f"constants {constants.kind}")
        self.grid, self.stencil, self.constants = grid, stencil, constants
        self.influence = influence
        self.closure = closure = closure or Closure()
        self.spacing = h = grid.spacing
        self.m_ratio = stencil.m_ratio
        self.horizon = delta = stencil.m_ratio * h
        self.thickness = float(thickness)
        self.node_volume = grid.node_volume * self.thickness
        V = grid.volume * self.thickness

        r_k = np.linalg.norm(stencil.offsets, axis=1) * h
        #: m of a complete neighbourhood: ``complete_m="stencil"`` the discrete Eq. (25) of
        #: seed 000 / (22) of seed 001 over the stencil's volumes, ``"continuum"`` its
        #: integral (seed 000: A delta^3 for omega = delta/|xi| in 1D), equal at seed 000's
        #: volumes (beta = 1/2 at |xi| = delta, whole m) and not with whole cells
        if complete_m not in COMPLETE_M:
            raise ValueError(f"complete_m={complete_m!r}; allowed: {', '.join(COMPLETE_M)}")
        self.m_inf = (float(np.sum(influence.omega(r_k, delta) * r_k ** 2 * stencil.beta) * V)
                      if complete_m == "stencil" else
                      influence.weighted_volume(grid.dim, delta) * self.thickness)

        half = stencil.half
        a, b, which = bond_pairs(grid.ext_shape, stencil.offsets[half])
        beta_h = stencil.beta[half]
        keep = closure.bond_mask(grid, a, b)
        self._shadow_bonds(closure, grid, a, b, keep)
        a, b, which = self._ghost_bonds(closure, grid, a, b, which, keep)
        self.bond_a, self.bond_b = a, b
        xi = grid.bond_vectors(a, b)
        x = np.linalg.norm(xi, axis=1)
        self.bond_n = xi / x[:, None]
        self.bond_x = x
        self.bond_omega = influence.omega(x, delta)
        self.bond_beta = beta_h[which]
        if closure.bond_factor is not None:
            self.bond_beta = self.bond_beta * closure.bond_factor(a, b, self.bond_n)
        if closure.geometric_factor is not None:
            self.bond_beta = self.bond_beta * closure.geometric_factor(self)
        if closure.weight_factor is not None:
            self.bond_beta = self.bond_beta * closure.weight_factor(self)
        Va, Vb = self.node_volume[a], self.node_volume[b]
        if closure.weighted_volume == "complete":
            self.m = np.full(grid.n_ext, self.m_inf)
        else:  # Eq. (50) of seed 000 / (22) of seed 001 over the bonds each node has
            w = self.bond_omega * x ** 2 * self.bond_beta
            self.m = np.bincount(a, w * Vb, grid.n_ext) + np.bincount(b, w * Va, grid.n_ext)
        self.n_unknown_nodes = (closure.n_unknown_nodes if closure.n_unknown_nodes is not None
                                else grid.n_interior)
        #: omega(|xi|) beta of every bond (the weight of its end's horizon sums)
        self.bond_weight = self.bond_omega * self.bond_beta
        self._build_operators(Va, Vb)
        if closure.force_factor is not None:  # on each bond's force only
            g = np.asarray(closure.force_factor(self), dtype=float)
            self.K_e = (sp.diags(g) @ self.K_e).tocsr()
            self.K_theta = (sp.diags(g) @ self.K_theta).tocsr()

    def _shadow_bonds(self, closure, grid, a, b, keep):
        """The columns of each kept bond's ends in the operators: its nodes, or for the
        bonds of ``closure.shadow`` a shadow column n_ext + s at the fictitious end
        (``Closure.shadow``). ``col_node``: the grid node of every column."""
        self.col_a, self.col_b = a[keep].copy(), b[keep].copy()
        self.col_node = np.arange(grid.n_ext)
        self.shadow = closure.shadow
        if closure.shadow is None:
            return
        if closure.constitutive is not None:
            raise ValueError("shadow ends need the LPS force state")
        pairs = np.asarray(closure.shadow[0], dtype=int)
        if not keep[pairs].all():
            raise ValueError("shadow: every pair must be a kept bond")
        bond = (np.cumsum(keep) - 1)[pairs]
        real_a = grid.is_interior[a[pairs]]
        if np.any(real_a == grid.is_interior[b[pairs]]):
            raise ValueError("shadow: every pair joins a real and a fictitious node")
        cols = grid.n_ext + np.arange(pairs.size)
        self.col_b[bond[real_a]] = cols[real_a]
        self.col_a[bond[~real_a]] = cols[~real_a]
        self.col_node = np.r_[self.col_node, np.where(real_a, b[pairs], a[pairs])]

    def _ghost_bonds(self, closure, grid, a, b, which, keep):
        """The kept pairs, then the one-sided bonds of ``closure.ghosts`` (from the real
        end to a ghost column n_ext + shadows + g of the other end's node); ``ghost_b``
        marks the bonds whose end b is a ghost (no equation, no dilatation share)."""
        ka, kb, kw = a[keep], b[keep], which[keep]
        self.ghosts = closure.ghosts
        if closure.ghosts is None:
            self.ghost_b = np.zeros(ka.size, dtype=bool)
            return ka, kb, kw
        if closure.constitutive is not None or closure.displacement_map_full is not None:
            raise ValueError("ghost bonds need the LPS force state and one map per component")
        pairs = np.asarray(closure.ghosts[0], dtype=int)
        real_a = np.asarray(closure.ghosts[1], dtype=bool)
        if keep[pairs].any():
            raise ValueError("ghosts: every pair must be a pair a crack cuts, not a bond")
        ra = np.where(real_a, a[pairs], b[pairs])
        gn = np.where(real_a, b[pairs], a[pairs])
        void = getattr(grid, "is_void", None)
        if void is not None and void[ra].any():
            raise ValueError("ghosts: the own end of every pair must be a real or fictitious "
                             "node")
        cols = self.col_node.size + np.arange(pairs.size)
        self.col_a = np.r_[self.col_a, ra]
        self.col_b = np.r_[self.col_b, cols]
        self.col_node = np.r_[self.col_node, gn]
        self.ghost_b = np.r_[np.zeros(ka.size, dtype=bool), np.ones(pairs.size, dtype=bool)]
        return np.r_[ka, ra], np.r_[kb, gn], np.r_[kw, which[pairs]]

    def _real_ends(self):
        """Which bonds' ends a and b carry an equation and a dilatation share: real
        nodes, not ghosts (``Closure.ghosts``)."""
        g = self.grid
        return g.is_interior[self.bond_a], g.is_interior[self.bond_b] & ~self.ghost_b

    # ------------------------------------------------------------------ assembly
    @property
    def dim(self) -> int:
        return self.grid.dim

    def _build_operators(self, Va, Vb):
        g, c, cl = self.grid, self.constants, self.closure
        d = g.dim
        a, b = self.bond_a, self.bond_b
        nb, ne, ni = a.size, g.n_ext, g.n_interior
        nu_ = self.n_unknown_nodes
        rows = np.arange(nb)
        om, x, be, n = self.bond_omega, self.bond_x, self.bond_beta, self.bond_n
        m = self.m

        self.A_U = (cl.displacement_map if cl.displacement_map is not None
                    else real_identity(g, nu_)).tocsr()
        ca, cb, nc = self.col_a, self.col_b, self.col_node.size   # the ends' columns
        if self.shadow is not None and cl.displacement_map_full is None:
            # the shadow ends' rows (Closure.shadow)
            self.A_U = sp.vstack([self.A_U, sp.csr_matrix(self.shadow[1])]).tocsr()
        if self.ghosts is not None:     # the ghost ends' rows (Closure.ghosts)
            self.A_U = sp.vstack([self.A_U, sp.csr_matrix(self.ghosts[2])]).tocsr()
        # bond extension from all-node displacements (component-major columns)
        self.A_e = sp.hstack([sp.csr_matrix((np.r_[-n[:, k], n[:, k]],
                                             (np.r_[rows, rows], np.r_[ca, cb])), shape=(nb, nc))
                              for k in range(d)]).tocsr()
        if cl.displacement_map_full is None:
            self.A_U_full = sp.kron(sp.identity(d, format="csr"), self.A_U, format="csr")
        elif self.shadow is None:
            self.A_U_full = cl.displacement_map_full.tocsr()
        else:   # each component's block: its nodes' rows, then its shadow ends' rows
            full, S, k = (cl.displacement_map_full.tocsr(), sp.csr_matrix(self.shadow[1]),
                          nc - ne)
            self.A_U_full = sp.vstack([blk for c in range(d) for blk in
                                       (full[c * ne:(c + 1) * ne], S[c * k:(c + 1) * k])]
                                      ).tocsr()
        if cl.constitutive is not None:  # another force state on the same bonds (PALS)
            (self.K_e, self.K_theta, self.A_theta, self.A_Theta,
             self.ke_share_a) = cl.constitutive.operators(self)
            return
        self.A_Theta = (cl.dilatation_map if cl.dilatation_map is not None
                        else real_identity(g)).tocsr()
        if self.shadow is not None:
            self.A_Theta = sp.vstack([self.A_Theta, sp.csr_matrix(self.shadow[2])]).tocsr()
        if self.ghosts is not None:
            self.A_Theta = sp.vstack([self.A_Theta, sp.csr_matrix(self.ghosts[3])]).tocsr()
        # real-node dilatations: every bond counts at each real end, with the other end's V
        coef = c.c_theta * om * x * be
        ia, ib = self._real_ends()
        self.A_theta = sp.csr_matrix(
            (np.r_[coef[ia] * Vb[ia] / m[a[ia]], coef[ib] * Va[ib] / m[b[ib]]],
             (np.r_[g.interior_number[a[ia]], g.interior_number[b[ib]]],
              np.r_[rows[ia], rows[ib]])), shape=(ni, nb))
        # bond forces times beta V_a V_b
        VV = Va * Vb
        self.K_e = sp.diags(c.k_e * om * be * VV * (1.0 / m[a] + 1.0 / m[b]))
        self.ke_share_a = (1.0 / m[a]) / (1.0 / m[a] + 1.0 / m[b])
        kt = c.k_theta * om * x * be * VV
        self.K_theta = sp.csr_matrix((np.r_[kt / m[a], kt / m[b]], (np.r_[rows, rows], np.r_[ca, cb])),
                                     shape=(nb, nc))

    def bond_force_rows(self, node_rows, bonds, weights) -> sp.csr_matrix:
        """Rows r (d * n_unknown_nodes x bonds) with r @ f = sum weights f_b n_b per node.

        Equation ``node_rows[i]`` (an unknown-node number, per component) collects
        ``weights[i]`` times bond ``bonds[i]``'s force along its direction a -> b.
        """
        d, nu_ = self.dim, self.n_unknown_nodes
        node_rows, bonds = np.asarray(node_rows), np.asarray(bonds)
        weights = np.broadcast_to(np.asarray(weights, dtype=float), bonds.shape)
        rows = np.concatenate([k * nu_ + node_rows for k in range(d)])
        cols = np.tile(bonds, d)
        vals = np.concatenate([weights * self.bond_n[bonds, k] for k in range(d)])
        return sp.csr_matrix((vals, (rows, cols)), shape=(d * nu_, self.bond_a.size))

    def equilibrium_rows(self) -> sp.csr_matrix:
        """Minus the internal force of every real node (f_b along a -> b pulls a towards b)."""
        g, a, b = self.grid, self.bond_a, self.bond_b
        ia, ib = self._real_ends()
        bonds = np.arange(a.size)
        return self.bond_force_rows(
            np.r_[g.interior_number[a[ia]], g.interior_number[b[ib]]],
            np.r_[bonds[ia], bonds[ib]], np.r_[-np.ones(ia.sum()), np.ones(ib.sum())])

    def unknown_rows(self, rows, map_last: bool = False) -> list:
        """R A_e A_U for each R of ``rows`` (rows over the bonds: the equations times K_e,
        A_theta): the same rows over the unknowns, multiplied out as R B with
        B = A_e A_U formed once, or with ``map_last`` as (R A_e) A_U.

        ``map_last`` is for a closure whose displacement map has wide rows: B holds, in
        the row of each bond with a fictitious end, that node's whole extrapolation
        stencil (the surface nodes' 3D stencil at order 3: 100 sources; B of
        body3d-manufactured at h = 0.05 has 48 M entries, A_e 2 M), while R A_e has one
        entry per node an equation sees: that run's setup then takes 2.4 s of CPU instead
        of 4.4 s, and B's 0.6 GB is never held
        (benchmarks/records/setup3d-2026-11-27-issue32-surface-nodes.json). Mathematically
        the same; the sums round in another order (there the entries 2e-15 of the largest
        apart; tests/surface/test_surface_exactness.py bounds the difference)."""
        if map_last:
            return [(R @ self.A_e) @ self.A_U_full for R in rows]
        B = (self.A_e @ self.A_U_full).tocsr()             # extensions from unknowns
        return [R @ B for R in rows]

    def stiffness(self, P=None, *, map_last: bool = False) -> sp.csr_matrix:
        """K = P K_b, multiplied out as (P K_e) B + (P K_theta A_Theta)(A_theta B).

        ``P`` defaults to :meth:`equilibrium_rows` (K u = external nodal forces);
        ``map_last``: B is not formed (:meth:`unknown_rows`).
        """
        P = self.equilibrium_rows() if P is None else P
        # 'bond-based' part (~stencil-sparse) and real dilatations <- unknowns
        bond_part, theta_of_u = self.unknown_rows([P @ self.K_e, self.A_theta], map_last)
        coupling = (P @ self.K_theta) @ self.A_Theta        # nodes <- real dilatations
        return (bond_part + coupling @ theta_of_u.tocsr()).tocsr()

    def augmented_stiffness(self, P=None, *, map_last: bool = False) -> sp.csr_matrix:
        """The system with the real-node dilatations as unknowns beside the displacements:

            [[P K_e B, P K_theta A_Theta], [A_theta B, -I]] [u; theta] = [f; 0]

        (B = A_e A_U). Eliminating theta gives back :meth:`stiffness`, whose rows couple
        nodes two horizons apart; here every block couples within one horizon (plus the
        closure's extrapolation), so a sparse LU's separators are half as thick: on the
        plane-strain plate at h = 0.01 the augmented matrix has 3.0 M non-zeros against
        6.1 M for K (benchmarks/solvers.py). Unknowns: ``d * n_unknown_nodes``
        displacements (component-major), then ``n_interior`` dilatations. ``map_last``:
        B is not formed (:meth:`unknown_rows`)."""
        P = self.equilibrium_rows() if P is None else P
        bond_part, theta_of_u = self.unknown_rows([P @ self.K_e, self.A_theta], map_last)
        ni = self.A_theta.shape[0]
        return sp.bmat([[bond_part, (P @ self.K_theta) @ self.A_Theta],
                        [theta_of_u, -sp.identity(ni, format="csr")]], format="csr")

    def bond_force_matrix(self, bonds=None) -> sp.csr_matrix:
        """K_b: scalar bond forces (times beta V_a V_b) from the unknowns, multiplied out;
        ``bonds``: only these rows (ascending), each row computed as in the whole K_b
        (a row's products do not depend on the other rows). Memory: a bond's row holds
        every unknown within two horizons of it (the dilatations'), so the whole K_b of
        the plane-strain plate at m = 8 takes ~2.5 GB, the rows of its face-crossing bonds
        a few per cent of that."""
        B = (self.A_e @ self.A_U_full).tocsr()
        K_e, K_theta = self.K_e, self.K_theta
        if bonds is not None:   # row selection in CSR (K_e may be diagonal storage)
            K_e, K_theta = sp.csr_matrix(K_e)[bonds], sp.csr_matrix(K_theta)[bonds]
        return (K_e @ B + K_theta @ (self.A_Theta @ (self.A_theta @ B))).tocsr()

    def bond_forces(self, u) -> np.ndarray:
        """Scalar bond forces f (times beta V_a V_b, along a -> b) of the unknowns ``u``."""
        e = self.A_e @ (self.A_U_full @ np.asarray(u, dtype=float))
        return self.K_e @ e + self.K_theta @ (self.A_Theta @ (self.A_theta @ e))

    def bond_end_forces(self, u, offset=None) -> tuple[np.ndarray, np.ndarray]:
        """The bond forces of :meth:`bond_forces` split by the end whose force state
        gives them: f = f_a + f_b, f_a = beta V_a V_b t_a(xi) (k_e omega e / m_a +
        k_theta omega |xi| theta_a / m_a for LPS). ``ke_share_a`` is end a's part of K_e;
        a K_theta entry belongs to the end whose node its column is (modulo the grid's
        node count: a force state may carry several nodal scalars per node).
        ``offset``: (n_ext, d) displacements of the grid nodes added to the unknowns'
        image (a treatment's affine part, ``LinearSystem.offset``)."""
        U = self.A_U_full @ np.asarray(u, dtype=float)
        if offset is not None:    # a shadow column moves with its node, or has its own
            offset = np.asarray(offset, dtype=float)
            U = U + (offset if len(offset) == self.col_node.size
                     else offset[self.col_node]).T.ravel()
        e = self.A_e @ U
        Theta = self.A_Theta @ (self.A_theta @ e)
        KT = self.K_theta.tocoo()
        at_a = self.col_node[KT.col % self.col_node.size] == self.bond_a[KT.row]
        ke = self.K_e @ e
        f_a = (self.ke_share_a * ke
               + np.bincount(KT.row[at_a], KT.data[at_a] * Theta[KT.col[at_a]],
                             self.bond_a.size))
        return f_a, ke + self.K_theta @ Theta - f_a

    def bulk_work_density(self, strain) -> float:
        """W = 1/2 sum_b f_i,b e_b / V_i (end i's part: half of f_b there) at a node of
        the bulk lattice (a complete neighbourhood) under the homogeneous ``strain``:
        e = |xi| n.strain.n per stencil offset, theta the complete-neighbourhood
        dilatation, f = k_e omega beta V^2 (2/m) e + k_theta omega |xi| beta V^2 (2 theta/m).
        A closure's ``constitutive`` force state gives its own."""
        if self.closure.constitutive is not None:
            return self.closure.constitutive.bulk_work_density(self, strain)
        st, c = self.stencil, self.constants
        r, n = st.vectors(self.spacing)
        e = homogeneous_extensions(r, n, strain)
        V = self.grid.volume * self.thickness
        om, m = self.influence.omega(r, self.horizon), self.m_inf
        theta = c.c_theta * np.sum(om * r * e * st.beta * V) / m
        f = (c.k_e * om * st.beta * V * V * 2.0 / m * e
             + c.k_theta * om * r * st.beta * V * V * 2.0 * theta / m)
        return float(0.25 * np.sum(f * e) / V)

    def crossing_selector(self, planes, axis: int = 0) -> sp.csr_matrix:
        """Rows s (one per plane) with s @ f = the summed force of the bonds crossing it.

        A bond a-b crosses the plane x[axis] = p when its ends lie on opposite sides; the
        force counts with the sign of n_b[axis], so that dividing by the section area gives
        the force flux tau(x_p, +e_axis) of seed 000 Eq. (21) (tension positive).
        """
        planes = np.atleast_1d(np.asarray(planes, dtype=float))
        xa = self.grid.x[self.bond_a, axis]
        xb = self.grid.x[self.bond_b, axis]
        lo, hi = np.minimum(xa, xb), np.maximum(xa, xb)
        hit = (lo[None, :] < planes[:, None]) & (planes[:, None] < hi[None, :])
        return sp.csr_matrix(hit * np.sign(self.bond_n[:, axis])[None, :])

    # ------------------------------------------------------------------ fields
    def dilatation_of_field(self, u_fn, points) -> np.ndarray:
        """Discrete dilatation of a field at ``points`` over complete neighbourhoods.

        ``u_fn(x) -> (n, d)``; used to apply the discrete operator to an exact field.
        """
        h, V, c = self.spacing, self.grid.volume * self.thickness, self.constants
        xi = self.stencil.offsets * h
        r = np.linalg.norm(xi, axis=1)
        n = xi / r[:, None]
        w = c.c_theta * self.influence.omega(r, self.horizon) * r * self.stencil.beta * V / self.m_inf
        points = np.asarray(points, dtype=float)
        u0 = u_fn(points)
        out = np.zeros(points.shape[0])
        for k in range(xi.shape[0]):  # loop over stencil offsets
            du = u_fn(points + xi[k]) - u0
            out += w[k] * (du @ n[k])
        return out

    def rows_of_state(self, U_ext, Theta_ext, P=None) -> np.ndarray:
        """P f for given displacements (n_ext, d) and dilatations (n_ext,) at every node.

        Kept as a product (factor by factor, never forming K): the discrete operator
        applied to an exact field gives discrete manufactured loads.
        """
        P = self.equilibrium_rows() if P is None else P
        U, Theta = np.asarray(U_ext, dtype=float), np.asarray(Theta_ext, dtype=float)
        if self.col_node.size != self.grid.n_ext:   # a shadow or ghost column takes its
            if len(U) != self.col_node.size:          # node's given state, unless given its own
                U = U[self.col_node]
            if len(Theta) != self.col_node.size:
                Theta = Theta[self.col_node]
        f = self.K_e @ (self.A_e @ U.T.ravel()) + self.K_theta @ Theta
        return P @ f
