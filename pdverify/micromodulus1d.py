"""1D bond-based PD with the micromodulus v^2 / (delta xi^2) of seed 002 Eq. (3), as sparse operators."""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import scipy.sparse as sp

from .bonds import partial_volumes_1d
from .corrections.taylor import taylor_extrapolation_weights

BOUNDARIES = ("surface-nodes", "none", "odd-image")


def bond_coefficients(horizon: float, m_ratio: float, wave_speed: float):
    """Offsets k, partial volumes beta_k and c_k = v^2 beta_k Delta / (delta (k Delta)^2) of Eq. (3).

    The acceleration of node i is sum_k c_k (u_{i+k} + u_{i-k} - 2 u_i) on a complete
    neighbourhood; beta = 1/2 for the node at the horizon (ERRATA seed 002, as seed 000).
    """
    spacing = horizon / m_ratio
    offsets, beta = partial_volumes_1d(m_ratio)
    xi = offsets * spacing
    return offsets, beta, wave_speed ** 2 / horizon * beta * spacing / xi ** 2


def lattice_symbol(k, *, horizon: float, m_ratio: float):
    """psi_h(k): the discrete operator of Eq. (3) on an unbounded grid maps sin(kx) to -v^2 psi_h sin(kx).

    psi_h = 2/delta sum_j beta_j Delta (1 - cos(k xi_j)) / xi_j^2, the one-point quadrature of
    psi (Eq. 12). The quadrature omits the node's own cell, where the integrand of Eq. (12)
    is k^2/2, so psi - psi_h = k^2 / (2 m) + O(m^-2) at fixed delta: first-order
    m-convergence.
    """
    offsets, beta, c = bond_coefficients(horizon, m_ratio, 1.0)
    k = np.asarray(k, dtype=float)
    xi = offsets * horizon / m_ratio
    return np.sum(2.0 * c * (1.0 - np.cos(np.multiply.outer(k, xi))), axis=-1)


@dataclass
class WaveBar1D:
    """A bar [0, l] of 1D bond-based PD (seed 002 Eq. 3) with one of two boundary treatments.

    Real nodes sit at the cell centres x_i = (i - 1/2) Delta, i = 1..N, Delta = delta / m
    (Fig. 2; N = 100, 250, 1000 for m = 10, 25, 100).

    ``boundary="surface-nodes"`` (seed 002 Figs. 3-4): surface nodes at x = 0 and x = l carry
    the Dirichlet values and have no bonds; a fictitious layer of m cells beyond each end
    completes the neighbourhoods, its displacements extrapolated about the nearest surface
    node by a Taylor series of order ``taylor_order`` through the surface node and the
    ``taylor_order`` nearest real nodes (order 1 = Eqs. 8-9). All N real nodes are unknowns.

    ``boundary="none"``: no fictitious nodes, neighbourhoods truncated at the ends, and the
    end nodes (the first and last real node, Delta/2 inside the bar) held at the Dirichlet
    value; the N - 2 others are unknowns.

    ``boundary="odd-image"`` (a reference model, not a method of the paper): like
    surface nodes, but the fictitious layer is the odd image about the surface value,
    u(x_s - xi) = 2 u_s - u(x_s + xi). This is the extension the sine series of Eq. (11)
    implies, so it isolates the quadrature error from the extrapolation's model error.

    In every case the free accelerations are ``a = A u_free + A_bc u_bc`` with
    ``A = lattice @ extension`` multiplied out once (N x N, a banded matrix plus the few
    columns the extrapolation adds): one sparse product per time step.
    """

    length: float
    horizon: float
    m_ratio: float
    wave_speed: float
    boundary: str = "surface-nodes"
    taylor_order: int = 1
    arrays: dict = field(init=False, repr=False, default_factory=dict)

    def __post_init__(self):
        if self.boundary not in BOUNDARIES:
            raise ValueError(f"boundary={self.boundary!r}; allowed: {', '.join(BOUNDARIES)}")
        self.spacing = self.horizon / self.m_ratio
        n = self.length / self.spacing
        if abs(n - round(n)) > 1e-9 * n:
            raise ValueError(f"spacing {self.spacing} does not divide length {self.length}")
        self.n_real = int(round(n))
        self.offsets, self.beta_k, self.c_k = bond_coefficients(self.horizon, self.m_ratio,
                                                                self.wave_speed)
        surface = self.boundary != "none"
        if surface and self.n_real < self.taylor_order + 1:
            raise ValueError(f"order {self.taylor_order} needs at least {self.taylor_order + 1} "
                             f"real nodes, got {self.n_real}")
        self.n_fict = int(self.offsets.max()) if surface else 0
        self.x_lattice = (np.arange(-self.n_fict, self.n_real + self.n_fict) + 0.5) * self.spacing
        self._build()

    # ----------------------------------------------------------------- assembly
    def _lattice_rows(self):
        """Rows of Eq. (3) for the real nodes over all lattice nodes (real + fictitious).

        One block per offset, vectorised over nodes; bonds leaving the lattice are dropped
        (that is the truncation of ``none``; with fictitious layers none leave).
        """
        nf, nr = self.n_fict, self.n_real
        n_lat = nr + 2 * nf
        i = np.arange(nf, nf + nr)
        rows, cols, vals = [], [], []
        n_bonds = 0
        for k, c in zip(self.offsets, self.c_k):
            for j in (i - k, i + k):
                ok = (j >= 0) & (j < n_lat)
                rows += [i[ok] - nf, i[ok] - nf]
                cols += [j[ok], i[ok]]
                vals += [np.full(ok.sum(), c), np.full(ok.sum(), -c)]
            # bonds (a, a + k) of the lattice with at least one real end, counted once
            a = np.arange(0, n_lat - k)
            n_bonds += int(np.count_nonzero(((a >= nf) & (a < nf + nr))
                                            | ((a + k >= nf) & (a + k < nf + nr))))
        self.n_bonds = n_bonds
        return sp.csr_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))),
                             shape=(nr, n_lat))

    def _extension(self):
        """Lattice displacements from [real u (N), surface values (2)]: identity + Eqs. (8)-(9)."""
        nf, nr, n = self.n_fict, self.n_real, self.taylor_order
        xr = self.x_lattice[nf:nf + nr]
        rows, cols, vals = [np.arange(nr) + nf], [np.arange(nr)], [np.ones(nr)]
        if self.boundary == "odd-image":
            j = np.arange(nf)  # fictitious node at -(j + 1/2) Delta mirrors real node j
            rows += [nf - 1 - j, nf - 1 - j, nf + nr + j, nf + nr + j]
            cols += [j, np.full(nf, nr), nr - 1 - j, np.full(nf, nr + 1)]
            vals += [-np.ones(nf), np.full(nf, 2.0), -np.ones(nf), np.full(nf, 2.0)]
            return sp.csr_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))),
                                 shape=(nr + 2 * nf, nr + 2))
        for side in ("left", "right"):
            if side == "left":
                anchor, near, tgt, s_col = 0.0, np.arange(n), np.arange(nf), nr
            else:
                anchor, near, tgt, s_col = self.length, nr - 1 - np.arange(n), nf + nr + np.arange(nf), nr + 1
            src_x = np.r_[anchor, xr[near]]
            W = taylor_extrapolation_weights(src_x, self.x_lattice[tgt], n, anchor, self.spacing)
            src_col = np.r_[s_col, near]
            rows.append(np.repeat(tgt, n + 1))
            cols.append(np.tile(src_col, tgt.size))
            vals.append(W.ravel())
        return sp.csr_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))),
                             shape=(nr + 2 * nf, nr + 2))

    def _build(self):
        lattice = self._lattice_rows()
        nr = self.n_real
        if self.boundary != "none":
            full = (lattice @ self._extension()).tocsc()
            self.free = np.arange(nr)
            self.x_bc = np.array([0.0, self.length])
            self.A = full[:, :nr].tocsr()
            self.A_bc = full[:, nr:].tocsr()
        else:
            self.free = np.arange(1, nr - 1)
            fixed = np.array([0, nr - 1])
            self.x_bc = self.x_real[fixed]
            rows = lattice.tocsr()[self.free].tocsc()
            self.A = rows[:, self.free].tocsr()
            self.A_bc = rows[:, fixed].tocsr()
        self.A.sort_indices()

    # ----------------------------------------------------------------- queries
    @property
    def x_real(self) -> np.ndarray:
        return self.x_lattice[self.n_fict:self.n_fict + self.n_real]

    @property
    def x_free(self) -> np.ndarray:
        return self.x_real[self.free]

    def real_displacements(self, u_free, u_bc=(0.0, 0.0)) -> np.ndarray:
        """All real nodes' displacements from the free ones (``none``: the end nodes get ``u_bc``)."""
        u_free = np.asarray(u_free, dtype=float)
        if self.boundary != "none":
            return u_free
        out = np.empty(u_free.shape[:-1] + (self.n_real,))
        out[..., self.free] = u_free
        out[..., 0], out[..., -1] = u_bc[0], u_bc[1]
        return out

    def size(self) -> dict:
        surface = 2 if self.boundary != "none" else 0
        return {"nodes": int(self.n_real + 2 * self.n_fict + surface), "real_nodes": int(self.n_real),
                "fictitious_nodes": int(2 * self.n_fict), "dofs": int(self.free.size),
                "bonds": int(self.n_bonds), "operator_nnz": int(self.A.nnz)}
