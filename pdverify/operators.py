"""Sparse operators of 1D linear state-based PD (seed 000 §4.2 and App. D)."""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import scipy.sparse as sp

from .bonds import bond_family_1d, partial_volumes_1d
from .corrections.taylor import taylor_extrapolation_weights
from .materials import StateBased1D, hyperbolic_influence


@dataclass
class Bar1D:
    """A uniform 1D state-based PD bar, optionally with Taylor-extrapolated fictitious layers.

    Real nodes sit at cell centres x_i = (i - 1/2) spacing, i = 1..N (Fig. 10); with
    ``taylor_order`` n >= 1 a fictitious layer of the stencil's reach is added at both
    ends and its displacements (order n, Eq. 45) and dilatations (order n - 1, Eq. 47)
    are extrapolated from the nearest real nodes. Without it (``taylor_order=None``) the
    bar is the uncorrected model: neighbourhoods are truncated and the weighted volume
    m_i comes from Eq. (50) over real neighbours. With fictitious layers every node gets
    m_inf, the discrete weighted volume of a complete neighbourhood (= A delta^3 exactly
    at integer m-ratio, Eq. 25; ERRATA seed 000).

    Operators (App. D), all sparse; ``u`` holds the N real displacements:
      U = A_U u (all nodes, D1), e = A_e U (bond extensions, D2),
      theta = A_theta e (real dilatations, D3), Theta = A_Theta theta (all nodes, D4),
      f_b = K_e e + K_theta Theta (bond forces, D5), so f_b = K_b u (D6),
      internal nodal force S f_b (D7) and K = -S K_b (Eq. 55).
    K_b is multiplied out once (a product of banded sparse matrices, O(bonds) work and
    storage) because both K and the force-flux rows need it; the factors are kept too.
    """

    length: float
    area: float
    E: float
    nu: float
    spacing: float
    m_ratio: float
    taylor_order: int | None = None
    arrays: dict = field(init=False, repr=False)

    def __post_init__(self):
        self.n_real = int(round(self.length / self.spacing))
        self.horizon = self.m_ratio * self.spacing
        self.material = StateBased1D(self.E, self.nu)
        offsets, beta = partial_volumes_1d(self.m_ratio)
        self.offsets, self.beta_k = offsets, beta
        n_fict = int(offsets.max()) if (self.taylor_order and offsets.size) else 0
        self.n_fict = n_fict
        self.n_nodes = self.n_real + 2 * n_fict
        self.x = (np.arange(-n_fict, self.n_real + n_fict) + 0.5) * self.spacing
        self.real = slice(n_fict, n_fict + self.n_real)
        self._build()

    # ------------------------------------------------------------------ assembly
    def _is_real(self, idx):
        return (idx >= self.n_fict) & (idx < self.n_fict + self.n_real)

    def _build(self):
        V = self.area * self.spacing
        mat = self.material
        i, j, w = bond_family_1d(self.n_nodes, self.offsets,
                                 keep=lambda i, j: self._is_real(i) | self._is_real(j))
        xi = self.offsets[w] * self.spacing
        beta = self.beta_k[w]
        omega = hyperbolic_influence(xi, self.horizon)
        self.bond_i, self.bond_j, self.bond_xi, self.bond_beta = i, j, xi, beta
        nb, nn, nr = i.size, self.n_nodes, self.n_real
        rows = np.arange(nb)

        # weighted volume, Eq. (50) or m_inf for the corrected model
        m_inf = float(np.sum(2.0 * hyperbolic_influence(self.offsets * self.spacing, self.horizon)
                             * (self.offsets * self.spacing) ** 2 * self.beta_k) * V)
        self.m_inf = m_inf
        if self.taylor_order:
            m = np.full(nn, m_inf)
        else:
            contrib = omega * xi ** 2 * beta * V
            m = np.bincount(i, contrib, nn) + np.bincount(j, contrib, nn)
        self.m = m

        # D1: all-node displacements from the real ones
        self.A_U = self._extension_matrix(self.taylor_order)
        # D2: e_b = U_j - U_i (bonds point from i to j, xi > 0)
        self.A_e = sp.csr_matrix((np.r_[-np.ones(nb), np.ones(nb)],
                                  (np.r_[rows, rows], np.r_[i, j])), shape=(nb, nn))
        # D3: dilatation of real nodes from every bond at that node, Eq. (51)
        coef = mat.c_theta * omega * xi * beta * V
        ri, rj = self._is_real(i), self._is_real(j)
        th_rows = np.r_[i[ri], j[rj]] - self.n_fict
        th_cols = np.r_[rows[ri], rows[rj]]
        th_vals = np.r_[coef[ri] / m[i[ri]], coef[rj] / m[j[rj]]]
        self.A_theta = sp.csr_matrix((th_vals, (th_rows, th_cols)), shape=(nr, nb))
        # D4: all-node dilatations (order n - 1 extrapolation)
        self.A_Theta = self._extension_matrix(self.taylor_order - 1 if self.taylor_order else None)
        # D5: bond forces, Eq. (53)
        V2 = V * V
        self.K_e = sp.diags(mat.k_e * omega * beta * V2 * (1.0 / m[i] + 1.0 / m[j]))
        kt = mat.k_theta * omega * xi * beta * V2
        self.K_theta = sp.csr_matrix((np.r_[kt / m[i], kt / m[j]],
                                      (np.r_[rows, rows], np.r_[i, j])), shape=(nb, nn))
        # D6: f_b = K_b u, multiplied out once
        e_of_u = (self.A_e @ self.A_U).tocsr()
        self.K_b = (self.K_e @ e_of_u + self.K_theta @ (self.A_Theta @ (self.A_theta @ e_of_u))).tocsr()
        # D7: force of bond b on its real end nodes: +f on i (pulled toward j), -f on j
        s_rows = np.r_[i[ri], j[rj]] - self.n_fict
        s_cols = np.r_[rows[ri], rows[rj]]
        s_vals = np.r_[np.ones(ri.sum()), -np.ones(rj.sum())]
        self.S = sp.csr_matrix((s_vals, (s_rows, s_cols)), shape=(nr, nb))
        self.K = (-(self.S @ self.K_b)).tocsr()

    def _extension_matrix(self, order):
        """Identity on real nodes plus Taylor extrapolation blocks on the fictitious ones."""
        nr, nf = self.n_real, self.n_fict
        rows = [np.arange(nr) + nf]
        cols = [np.arange(nr)]
        vals = [np.ones(nr)]
        if nf:
            x = self.x
            xr = x[self.real]
            for side in ("left", "right"):
                src = np.arange(order + 1) if side == "left" else nr - 1 - np.arange(order + 1)
                anchor = xr[0] if side == "left" else xr[-1]
                tgt = np.arange(nf) if side == "left" else np.arange(nf) + nf + nr
                W = taylor_extrapolation_weights(xr[src], x[tgt], order, anchor, self.spacing)
                rows.append(np.repeat(tgt, src.size))
                cols.append(np.tile(src, tgt.size))
                vals.append(W.ravel())
        return sp.csr_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))),
                             shape=(self.n_nodes, nr))

    # ------------------------------------------------------------------ queries
    @property
    def x_real(self) -> np.ndarray:
        return self.x[self.real]

    def boundary_value_row(self, side: str) -> np.ndarray:
        """Row r with r @ u = u at the boundary point, by Taylor extrapolation (Eq. 58)."""
        order = self.taylor_order
        nr = self.n_real
        xr = self.x_real
        src = np.arange(order + 1) if side == "left" else nr - 1 - np.arange(order + 1)
        anchor = xr[0] if side == "left" else xr[-1]
        point = 0.0 if side == "left" else self.length
        row = np.zeros(nr)
        row[src] = taylor_extrapolation_weights(xr[src], [point], order, anchor, self.spacing)[0]
        return row

    def crossing_selector(self, planes) -> sp.csr_matrix:
        """Rows s with s @ f_b = the summed force of the bonds crossing each plane (Eq. 60).

        A bond i-j crosses the plane x_p when x_i < x_p < x_j; dividing by the area gives
        the discrete force flux tau(x_p, +1) of Eq. (21), tension positive.
        """
        planes = np.atleast_1d(np.asarray(planes, dtype=float))
        xi_, xj_ = self.x[self.bond_i], self.x[self.bond_j]
        hit = (xi_[None, :] < planes[:, None]) & (planes[:, None] < xj_[None, :])
        return sp.csr_matrix(hit.astype(float))

    def flux_rows(self, planes) -> sp.csr_matrix:
        """Rows r with r @ u = A * tau(x_p, +1) at each plane (force through the section)."""
        return (self.crossing_selector(planes) @ self.K_b).tocsr()

    def size(self) -> dict:
        return {"nodes": int(self.n_nodes), "real_nodes": int(self.n_real),
                "dofs": int(self.n_real), "bonds": int(self.bond_i.size)}
