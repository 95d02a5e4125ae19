"""Linearised ordinary state-based PD on 2D/3D box grids as sparse operator products (seed 001)."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from .bonds_nd import (bond_pairs, half_stencil, moment_corrected_volumes, partial_volumes,
                       stencil_offsets)
from .corrections.surface_nodes import (dilatation_extrapolation, displacement_extrapolation,
                                        face_crossings)
from .grid import BoxGrid

KINDS = ("3d", "plane-strain", "plane-stress")
QUADRATURES = ("partial-volume", "moment-corrected")


@dataclass(frozen=True)
class StateBasedConstants:
    """c_theta, k_theta, k_e of the force state of seed 001 Eq. (11).

    From energy equivalence under homogeneous strain with the moments
    int omega x^2 n_a n_b = m delta_ab / d and the fourth moment m / (d (d + 2)):
    sigma = (k_theta c_theta / d^2 + k_e / (d (d + 2))) tr(eps) I + 2 k_e / (d (d + 2)) eps.
      3d:           c_theta = 3, k_theta = -3 (1 - 4 nu) E / (2 (1 + nu)(1 - 2 nu)),
                    k_e = 15 E / (2 (1 + nu))                               (§2.1)
      plane-strain: c_theta = 2, k_theta = -(1 - 4 nu) E / ((1 + nu)(1 - 2 nu)),
                    k_e = 4 E / (1 + nu)                                     (§5)
      plane-stress: c_theta = 2, k_theta = -(1 - 3 nu) E / (1 - nu^2), k_e = 4 E / (1 + nu)
                    (same derivation with lambda* = nu E / (1 - nu^2); our choice of
                    c_theta = 2 keeps theta the in-plane trace)
    so that k_theta / 3 + k_e / 15 = lambda and k_theta / 3 + k_e / 5 = lambda + 2 mu in 3D
    (ERRATA seed 001).
    """

    kind: str
    E: float
    nu: float

    @property
    def dim(self) -> int:
        return 3 if self.kind == "3d" else 2

    @property
    def c_theta(self) -> float:
        return 3.0 if self.kind == "3d" else 2.0

    @property
    def k_theta(self) -> float:
        E, nu = self.E, self.nu
        if self.kind == "3d":
            return -3.0 * (1 - 4 * nu) * E / (2 * (1 + nu) * (1 - 2 * nu))
        if self.kind == "plane-strain":
            return -(1 - 4 * nu) * E / ((1 + nu) * (1 - 2 * nu))
        return -(1 - 3 * nu) * E / (1 - nu ** 2)

    @property
    def k_e(self) -> float:
        return (15.0 / 2.0 if self.kind == "3d" else 4.0) * self.E / (1 + self.nu)


def gaussian_influence(r, horizon):
    """omega = exp(-|xi|^2 / delta^2), seed 001 Eq. (7)."""
    return np.exp(-(np.asarray(r) / horizon) ** 2)


def gaussian_weighted_volume(dim: int, horizon: float) -> float:
    """Continuum m = int_H omega |xi|^2 dV: 4 pi Delta_1 in 3D (Eq. 41), 2 pi delta^4 (1/2 - 1/e) in 2D."""
    from math import erf, exp, pi, sqrt
    if dim == 3:
        return 4 * pi * (3 / 8 * sqrt(pi) * erf(1.0) - 5 / 4 * exp(-1.0)) * horizon ** 5
    return 2 * pi * (0.5 - exp(-1.0)) * horizon ** 4


class StateBasedBox:
    """A box of linear state-based PD material, uncorrected or with surface nodes.

    ``order=None``: the uncorrected model (seed 001 §4, 'without the fictitious and
    surface nodes'): bonds only between interior nodes, m_i and theta_i over the
    truncated neighbourhoods (Eqs. 22-23). ``order=N``: the surface node method: a
    fictitious layer of thickness delta (edge and corner regions included), one surface
    node per boundary cell face, fictitious displacements by order-N Taylor
    extrapolation about the nearest surface node (steps 7-12) and dilatations by order
    N - 1 about the nearest interior node (steps 1-6), m = m of a complete neighbourhood
    everywhere (§3.2), one force-flux equation per surface node (Eq. 36).

    ``quadrature``: the weights beta of Eqs. (22)-(24): ``partial-volume`` = the exact
    fraction of each cell inside the horizon (§3.1, ref. [6]); ``moment-corrected`` (our
    addition) = those fractions minimally adjusted so the stencil's fourth moment is
    isotropic, which makes the discrete bulk moduli equal the continuum ones
    (``bonds_nd.moment_corrected_volumes``).

    Unknowns ``u~`` (component-major): the interior nodes, then the surface nodes.
    Operators (sparse; names follow seed 000 App. D):
      U = (I_d kron A_U) u~        all node displacements (extrapolation on fictitious)
      e = A_e U                    bond extensions n . (U_b - U_a), Eq. (21)
      theta = A_theta e            interior dilatations, Eq. (23)
      Theta = A_Theta theta        all node dilatations
      f = K_e e + K_theta Theta    scalar bond forces times beta V^2, Eq. (24)
      rows = P f                   P = [-S; F]: minus the internal nodal force of every
                                   interior node (Eq. 33) and the force flux times A of
                                   every surface node (Eq. 36)
    so K = P K_b with K_b = K_e A_e A_U + K_theta A_Theta A_theta A_e A_U.
    K_b itself is never multiplied out (in 3D each of its rows would couple ~1000 dofs);
    ``stiffness`` multiplies out the two terms of K = (P K_e) B + (P K_theta A_Theta)
    (A_theta B) with B = A_e A_U, each a product of sparse factors (3D default: 35 M
    non-zeros, ~40 % full, then solved by dense LU). ``rows_of_state`` keeps the product
    form: it applies the factors to a given state without multiplying anything out.
    """

    def __init__(self, lengths, origin, spacing, m_ratio, constants: StateBasedConstants,
                 order: int | None = None, quadrature: str = "partial-volume"):
        if quadrature not in QUADRATURES:
            raise ValueError(f"quadrature={quadrature!r}; allowed: {', '.join(QUADRATURES)}")
        self.constants = constants
        self.quadrature = quadrature
        self.order = order
        self.spacing = h = float(spacing)
        self.m_ratio = float(m_ratio)
        self.horizon = delta = self.m_ratio * h
        dim = len(lengths)
        offsets = stencil_offsets(dim, self.m_ratio)
        beta = partial_volumes(offsets, self.m_ratio)
        r_k = np.linalg.norm(offsets, axis=1) * h
        w_k = gaussian_influence(r_k, delta) * r_k ** 2  # weight of m per unit beta V
        if quadrature == "moment-corrected":
            beta = moment_corrected_volumes(offsets, beta, w_k)
        self.offsets, self.beta_k = offsets, beta
        layers = int(np.abs(offsets).max()) if order is not None else 0
        self.grid = g = BoxGrid(lengths, origin, h, layers)
        V = g.volume
        self.m_inf = float(np.sum(w_k * beta) * V)

        half = half_stencil(offsets)
        a, b, which = bond_pairs(g.ext_shape, offsets[half])
        beta_h = beta[half]
        ia, ib = g.is_interior[a], g.is_interior[b]
        keep = ia | ib
        if order is not None:
            cand = np.flatnonzero(~(ia & ib))
            s, bond, alpha, sign = face_crossings(g, a[cand], b[cand])
            keep[cand[bond]] = True
            new_index = np.cumsum(keep) - 1
            self.flux = (s, new_index[cand[bond]], alpha, sign)
        a, b, which = a[keep], b[keep], which[keep]
        self.bond_a, self.bond_b = a, b
        xi = (g.index[b] - g.index[a]) * h
        x = np.linalg.norm(xi, axis=1)
        self.bond_n = xi / x[:, None]
        self.bond_x = x
        self.bond_omega = gaussian_influence(x, delta)
        self.bond_beta = beta_h[which]
        if order is None:
            contrib = self.bond_omega * x ** 2 * self.bond_beta * V
            self.m = np.bincount(a, contrib, g.n_ext) + np.bincount(b, contrib, g.n_ext)
        else:
            self.m = np.full(g.n_ext, self.m_inf)
        self._build_operators()

    # ------------------------------------------------------------------ assembly
    @property
    def dim(self) -> int:
        return self.grid.dim

    @property
    def n_unknown_nodes(self) -> int:
        g = self.grid
        return g.n_interior + (g.n_surface if self.order is not None else 0)

    def _build_operators(self):
        g, c = self.grid, self.constants
        d, V = g.dim, g.volume
        a, b = self.bond_a, self.bond_b
        nb, ne, ni = a.size, g.n_ext, g.n_interior
        nu_ = self.n_unknown_nodes
        rows = np.arange(nb)
        om, x, be, n = self.bond_omega, self.bond_x, self.bond_beta, self.bond_n
        m = self.m

        # all-node displacements (scalar map, applied per component)
        fict = np.flatnonzero(~g.is_interior)
        parts = [sp.csr_matrix((np.ones(ni), (g.interior_ids, np.arange(ni))), shape=(ne, nu_))]
        theta_parts = [sp.csr_matrix((np.ones(ni), (g.interior_ids, np.arange(ni))),
                                     shape=(ne, ni))]
        if self.order is not None and fict.size:
            Wu = displacement_extrapolation(g, self.order, fict).tocoo()
            parts.append(sp.csr_matrix((Wu.data, (fict[Wu.row], Wu.col)), shape=(ne, nu_)))
            Wt = dilatation_extrapolation(g, self.order, fict).tocoo()
            theta_parts.append(sp.csr_matrix((Wt.data, (fict[Wt.row], Wt.col)), shape=(ne, ni)))
        self.A_U = sum(parts[1:], parts[0]).tocsr()
        self.A_Theta = sum(theta_parts[1:], theta_parts[0]).tocsr()
        # bond extension from all-node displacements (component-major columns)
        self.A_e = sp.hstack([sp.csr_matrix((np.r_[-n[:, k], n[:, k]],
                                             (np.r_[rows, rows], np.r_[a, b])), shape=(nb, ne))
                              for k in range(d)]).tocsr()
        # interior dilatations, Eq. (23): every bond counts at each interior end
        coef = c.c_theta * om * x * be * V
        ia, ib = g.is_interior[a], g.is_interior[b]
        self.A_theta = sp.csr_matrix(
            (np.r_[coef[ia] / m[a[ia]], coef[ib] / m[b[ib]]],
             (np.r_[g.interior_number[a[ia]], g.interior_number[b[ib]]],
              np.r_[rows[ia], rows[ib]])), shape=(ni, nb))
        # bond forces times beta V^2, Eq. (24)
        V2 = V * V
        self.K_e = sp.diags(c.k_e * om * be * V2 * (1.0 / m[a] + 1.0 / m[b]))
        kt = c.k_theta * om * x * be * V2
        self.K_theta = sp.csr_matrix((np.r_[kt / m[a], kt / m[b]], (np.r_[rows, rows], np.r_[a, b])),
                                     shape=(nb, ne))
        # P: minus internal force on interior nodes (f_b along a->b pulls a towards b),
        # then the force flux of surface nodes; rows component-major like the unknowns
        prow, pcol, pval = [], [], []
        for k in range(d):
            prow += [k * nu_ + g.interior_number[a[ia]], k * nu_ + g.interior_number[b[ib]]]
            pcol += [rows[ia], rows[ib]]
            pval += [-n[ia, k], n[ib, k]]
            if self.order is not None:
                s, bond, alpha, sign = self.flux
                prow.append(k * nu_ + ni + s)
                pcol.append(bond)
                pval.append(alpha * sign * n[bond, k])
        self.P = sp.csr_matrix((np.concatenate(pval), (np.concatenate(prow), np.concatenate(pcol))),
                               shape=(d * nu_, nb))
        self.A_U_full = sp.kron(sp.identity(d, format="csr"), self.A_U, format="csr")

    def stiffness(self) -> sp.csr_matrix:
        """K = P K_b, multiplied out here as (P K_e) B + (P K_theta A_Theta)(A_theta B)."""
        B = (self.A_e @ self.A_U_full).tocsr()             # extensions from unknowns
        bond_part = (self.P @ self.K_e) @ B                 # 'bond-based' part, ~stencil-sparse
        coupling = (self.P @ self.K_theta) @ self.A_Theta   # nodes <- interior dilatations
        theta_of_u = (self.A_theta @ B).tocsr()             # interior dilatations <- unknowns
        return (bond_part + coupling @ theta_of_u).tocsr()

    # ------------------------------------------------------------------ fields
    def dilatation_of_field(self, u_fn, points) -> np.ndarray:
        """Discrete dilatation (Eq. 23) of a field at ``points`` over complete neighbourhoods.

        ``u_fn(x) -> (n, d)``; used to apply the discrete operator to an exact field.
        """
        h, V, c = self.spacing, self.grid.volume, self.constants
        xi = self.offsets * h
        r = np.linalg.norm(xi, axis=1)
        n = xi / r[:, None]
        w = c.c_theta * gaussian_influence(r, self.horizon) * r * self.beta_k * V / self.m_inf
        points = np.asarray(points, dtype=float)
        u0 = u_fn(points)
        out = np.zeros(points.shape[0])
        for k in range(xi.shape[0]):  # loop over stencil offsets
            du = u_fn(points + xi[k]) - u0
            out += w[k] * (du @ n[k])
        return out

    def rows_of_state(self, U_ext, Theta_ext) -> np.ndarray:
        """P f for given displacements (n_ext, d) and dilatations (n_ext,) at every node.

        Kept as a product (factor by factor, never forming K): the discrete operator
        applied to an exact field gives discrete manufactured loads.
        """
        U = np.asarray(U_ext, dtype=float).T.ravel()
        f = self.K_e @ (self.A_e @ U) + self.K_theta @ np.asarray(Theta_ext, dtype=float)
        return self.P @ f

    def size(self) -> dict:
        g = self.grid
        out = {"interior_nodes": int(g.n_interior), "bonds": int(self.bond_a.size),
               "dofs": int(self.dim * self.n_unknown_nodes)}
        if self.order is not None:
            out["surface_nodes"] = int(g.n_surface)
            out["fictitious_nodes"] = int(g.n_ext - g.n_interior)
        return out
