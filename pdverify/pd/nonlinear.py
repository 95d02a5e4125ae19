"""Geometrically nonlinear bond-based PD on the bonds of a :class:`BondBasedModel`.

Bond a-b with reference vector xi (length L) and current vector y = xi + u_b - u_a
(length l) carries the tension T = s_b (l - L), where s_b = alpha_b c omega beta V_a V_b / L
is the linear model's spring stiffness: the micromodulus acts on the stretch (l - L) / L
of the current length (prototype microelastic brittle material without damage; seed 003,
Eq. 1 with the current bond direction). The force on a is +T y / l, on b -T y / l.

``internal_force(u)`` is the vector f(u) whose equilibrium f(u) = external forces is the
nonlinear version of K u = f; ``tangent(u)`` is its exact Jacobian df/du: per bond the
2x2 (3x3) block

    B = s_b n n^T + (T / l) (I - n n^T),   n = y / l,

placed as [[B, -B], [-B, B]] on (a, b); at u = 0 it is the linear model's K. The tangent
keeps the sparsity of K, whose positions are found once (:class:`_Pattern`), so each
assembly is a few vectorised scatters and no sort.
"""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from .bondbased import BondBasedModel


class _Pattern:
    """CSR pattern of the bond graph's d n x d n stiffness and, for every bond and block
    (p, q), the data positions of its (a, b) and (b, a) entries and of every node's
    diagonal block entries.

    Built from the node graph (one entry per bond and direction, plus the diagonal; no
    duplicates, so its CSR keeps each entry's identity): row (p, i) of the dof pattern is
    the node row i repeated for q = 0 .. d-1, so entry ((p, i), (q, j)) sits at
    p d nnz_n + d start_i + q deg_i + (position of j in node row i).
    """

    def __init__(self, n: int, dim: int, a: np.ndarray, b: np.ndarray):
        nodes = np.arange(n)
        nb = a.size
        rows = np.concatenate([a, b, nodes])
        cols = np.concatenate([b, a, nodes])
        G = sp.csr_matrix((np.arange(1, rows.size + 1, dtype=float), (rows, cols)), shape=(n, n))
        G.sort_indices()
        entry = G.data.astype(np.int64) - 1          # node-graph entry -> input position
        start, deg = G.indptr[:-1].astype(np.int64), np.diff(G.indptr).astype(np.int64)
        nnz_n = G.nnz
        row_n = np.repeat(nodes, deg)
        local = np.arange(nnz_n) - start[row_n]
        where_n = np.empty(nnz_n, dtype=np.int64)   # input position -> (row, local)
        where_n[entry] = np.arange(nnz_n)
        N = dim * n
        self.shape, self.nnz = (N, N), dim * dim * nnz_n
        self.indptr = np.concatenate([p * dim * nnz_n + dim * start for p in range(dim)]
                                     + [[self.nnz]]).astype(np.int64)
        indices = np.empty(self.nnz, dtype=np.int32)

        def pos(p, q, k):          # data position of node-graph entry k in block (p, q)
            i = row_n[k]
            return p * dim * nnz_n + dim * start[i] + q * deg[i] + local[k]

        every = np.arange(nnz_n)
        for p in range(dim):
            for q in range(dim):
                indices[pos(p, q, every)] = q * n + G.indices
        self.indices = indices
        k_ab, k_ba, k_d = where_n[:nb], where_n[nb:2 * nb], where_n[2 * nb:]
        self.ab = [[pos(p, q, k_ab) for q in range(dim)] for p in range(dim)]
        self.ba = [[pos(p, q, k_ba) for q in range(dim)] for p in range(dim)]
        self.diag = [[pos(p, q, k_d) for q in range(dim)] for p in range(dim)]
        self.row_of = np.repeat(np.arange(N, dtype=np.int32), np.diff(self.indptr))
        self.diagonal = np.concatenate([self.diag[p][p] for p in range(dim)])

    def matrix(self, data) -> sp.csr_matrix:
        return sp.csr_matrix((data, self.indices, self.indptr), shape=self.shape)


class NonlinearBondBased:
    """Internal forces, tangent and energy of large-displacement bond-based PD (see the
    module docstring). ``u`` is component-major over all grid nodes, like ``model.K``."""

    def __init__(self, model: BondBasedModel):
        if model.closure.displacement_map is not None:
            raise ValueError("the nonlinear bond-based model needs the grid nodes themselves "
                             "as unknowns (no fictitious-node displacement map)")
        g = model.grid
        self.model, self.n, self.dim = model, g.n_ext, g.dim
        self.a, self.b = model.bond_a, model.bond_b
        self.L = model.bond_x
        self.xi = model.bond_n * self.L[:, None]
        self.xi_t = np.ascontiguousarray(self.xi.T)
        self.s = model.bond_stiffness
        self._pattern = None
        self._data = None

    @property
    def pattern(self) -> _Pattern:
        if self._pattern is None:
            self._pattern = _Pattern(self.n, self.dim, self.a, self.b)
        return self._pattern

    def bond_vectors(self, u) -> tuple[np.ndarray, np.ndarray]:
        """Current bond vectors y (D x bonds, component rows) and lengths l."""
        U = np.asarray(u, dtype=float).reshape(self.dim, self.n)
        y = self.xi_t + np.take(U, self.b, axis=1)
        y -= np.take(U, self.a, axis=1)
        return y, np.sqrt(np.einsum("kb,kb->b", y, y))

    def internal_force(self, u) -> np.ndarray:
        y, l = self.bond_vectors(u)
        y *= self.s * (1.0 - self.L / l)          # the bond force vectors T y / l
        out = np.empty(self.dim * self.n)
        for k in range(self.dim):
            out[k * self.n:(k + 1) * self.n] = (np.bincount(self.b, y[k], self.n)
                                                - np.bincount(self.a, y[k], self.n))
        return out

    def energy(self, u) -> float:
        _, l = self.bond_vectors(u)
        return float(0.5 * np.sum(self.s * (l - self.L) ** 2))

    def energy_density(self, u) -> np.ndarray:
        """Per node: half of each of its bonds' energy s (l - L)^2 / 2, over the node
        volume (the nonlinear counterpart of ``BondBasedModel.strain_energy_density``)."""
        _, l = self.bond_vectors(u)
        half = 0.25 * self.s * (l - self.L) ** 2
        return ((np.bincount(self.a, half, self.n) + np.bincount(self.b, half, self.n))
                / self.model.node_volume)

    def tangent_data(self, u) -> np.ndarray:
        """CSR data of the tangent on :attr:`pattern` (blocks (p, q) and (q, p) share B),
        in a buffer that the next call overwrites."""
        y, l = self.bond_vectors(u)
        geo = self.s * (1.0 - self.L / l)         # T / l
        y *= np.sqrt(self.s * self.L / l) / l     # sqrt(s - T/l) n  (T/l < s: l > 0)
        P = self.pattern
        if self._data is None:        # reused: every position is written below
            self._data = np.empty(P.nnz)
        data = self._data
        for p in range(self.dim):
            for q in range(p, self.dim):
                B = y[p] * y[q]                   # (s - T/l) n_p n_q
                if p == q:
                    B += geo
                diag = np.bincount(self.a, B, self.n) + np.bincount(self.b, B, self.n)
                np.negative(B, out=B)
                for i, j in {(p, q), (q, p)}:
                    data[P.ab[i][j]] = B
                    data[P.ba[i][j]] = B
                    data[P.diag[i][j]] = diag
        return data

    def tangent(self, u) -> sp.csr_matrix:
        return self.pattern.matrix(self.tangent_data(u))

    def bond_extremes(self, u) -> dict:
        """The most turned and the most shortened bond: ``cos`` = the smallest
        cos(angle between current and reference bond) and its bond ``cos_bond`` (<= 0: the
        bond has turned against its reference direction, inverted); ``ratio`` = the smallest
        current / reference length and its bond ``ratio_bond``."""
        y, l = self.bond_vectors(u)
        ratio = l / self.L
        with np.errstate(divide="ignore", invalid="ignore"):
            cos = np.einsum("kb,kb->b", y, self.xi_t) / (l * self.L)
        cos = np.where(np.isfinite(cos), cos, -np.inf)
        k, j = int(np.argmin(cos)), int(np.argmin(ratio))
        return {"cos": float(cos[k]), "cos_bond": k, "ratio": float(ratio[j]), "ratio_bond": j}


class LinearBondBased(NonlinearBondBased):
    """The small-displacement model behind the same interface: f(u) = K u and the constant
    tangent K (the nonlinear tangent at u = 0, on the same pattern); its energy density is
    the linear model's. The geometric checks (:meth:`bond_extremes`) still read the
    current bond vectors, so a linear run that folds the lattice is caught all the same."""

    def __init__(self, model: BondBasedModel):
        super().__init__(model)
        self._data = super().tangent_data(np.zeros(self.dim * self.n))
        self.K = self.pattern.matrix(self._data)

    def internal_force(self, u) -> np.ndarray:
        return self.K @ u

    def energy(self, u) -> float:
        return float(0.5 * u @ (self.K @ u))

    def energy_density(self, u) -> np.ndarray:
        return self.model.strain_energy_density(u)

    def tangent_data(self, u) -> np.ndarray:
        return self._data.copy()
