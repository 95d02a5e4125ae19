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

Mirror symmetry (``mirror_axis``): for a body, bonds and loads symmetric about the lattice's
middle plane across axis k, the solution has u_k odd and the other components even. The
half model keeps the nodes on one side and on the plane (index_k >= the middle) as unknowns;
u = S u_h expands them to every node (a mirrored node takes its image's displacement with
u_k reversed). Its energy is the whole body's, E_h(u_h) = E(S u_h), written as a sum over
one bond of each mirror pair {bond, its image} (weight 2; 1 for a bond that is its own
image; this holds for u_k = 0 on the plane): a bond with both ends kept is kept as it
is, a bond that crosses the plane keeps its kept end and reaches the other through its
image (the "mirrored neighbour": y = xi + R u_b - u_a, R reversing component k).
So f_h = S^T f(S u_h) and the tangent S^T T S, symmetric; at a symmetric state
f_h = D f on the kept nodes (D = 2 off the plane, 1 on it), so Newton on the half model
takes, in exact arithmetic, the full model's steps (norms weighted by
``residual_weight`` = 1 / D are the body's), and a sum of reactions over kept nodes is the
whole body's. Nothing in it forbids an asymmetric solution in the full model, which the half
model cannot show (a bifurcation).
"""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from .bondbased import BondBasedModel
from .bonds import unique_ids


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

    #: None for the whole body, else see :meth:`_mirror` (the half model's arrays)
    half = None

    def __init__(self, model: BondBasedModel, mirror_axis: int | None = None):
        if model.closure.displacement_map is not None:
            raise ValueError("the nonlinear bond-based model needs the grid nodes themselves "
                             "as unknowns (no fictitious-node displacement map)")
        g = model.grid
        self.model, self.n, self.dim = model, g.n_ext, g.dim
        self.a, self.b = model.bond_a, model.bond_b
        self.L = model.bond_x
        self.xi = model.bond_n * self.L[:, None]
        self.s = model.bond_stiffness
        #: the grid nodes of the unknowns (all of them, or the kept half's)
        self.node_ids = np.arange(self.n)
        #: per unknown, the weight w of its equation in ||f||^2 = sum w f^2: None (all 1),
        #: or 1 / D of the half model, so that norms are the whole body's
        self.residual_weight = None
        if mirror_axis is not None:
            self._mirror(int(mirror_axis))
        self.xi_t = np.ascontiguousarray(self.xi.T)
        self._pattern = None
        self._data = None
        #: the last state's bond vectors and forces (:meth:`bond_vectors`)
        self._last = None

    def _mirror(self, k: int) -> None:
        """The half model about the middle plane across axis ``k`` (module docstring).
        Bonds are kept in two groups, those with no mirrored end first (``half["plain"]``
        of them), then those reaching across the plane; per bond ``rep``: the bond of the
        whole body it stands for (the lower index of the pair, so that ties are broken as
        the whole body's argmin breaks them)."""
        g = self.model.grid
        if g.layers:
            raise ValueError("the half model needs a grid without extra layers")
        idx = g.index
        top = int(idx[:, k].max())
        if top % 2 or top != int(np.ptp(idx[:, k])):
            raise ValueError(f"mirror_axis={k}: the grid needs an odd number of nodes along "
                             "it (a node row on the middle plane)")
        image_idx = idx.copy()
        image_idx[:, k] = top - idx[:, k]
        image = g.ext_id(image_idx)                       # each node's mirror image
        kept = 2 * idx[:, k] >= top
        nodes = np.flatnonzero(kept)
        to_half = np.full(self.n, -1, dtype=np.int64)
        to_half[nodes] = np.arange(nodes.size)
        where = np.where(kept, to_half, to_half[image])   # the kept node standing for each
        flip = np.where(kept, 1.0, -1.0)                  # its u_k sign
        a, b = self.a.astype(np.int64), self.b.astype(np.int64)
        n = self.n
        key = np.minimum(a, b) * n + np.maximum(a, b)
        order = np.argsort(key)
        ia, ib = image[a], image[b]
        partner = order[np.searchsorted(key[order], np.minimum(ia, ib) * n + np.maximum(ia, ib))]
        if not np.array_equal(key[partner], np.minimum(ia, ib) * n + np.maximum(ia, ib)):
            raise ValueError("the bonds are not mirror symmetric")
        side = idx[a, k] + idx[b, k]                      # > top: on the kept side
        keep = (side > top) | ((side == top) & (np.arange(a.size) <= partner))
        weight = np.where(partner == np.arange(a.size), 1.0, 2.0)
        sel = np.flatnonzero(keep)
        crossing = (flip[a[sel]] < 0) | (flip[b[sel]] < 0)
        sel = np.concatenate([sel[~crossing], sel[crossing]])
        A, B = where[a[sel]], where[b[sel]]
        self.half = {"axis": k, "plain": int((~crossing).sum()),
                     "ra": flip[a[sel]], "rb": flip[b[sel]],
                     "rep": np.minimum(sel, partner[sel]),
                     "image": image[nodes], "full_n": n}
        self.a, self.b = A, B
        self.L, self.xi = self.L[sel], self.xi[sel]
        self.s = self.s[sel] * weight[sel]
        self.node_ids = nodes
        self.n = int(nodes.size)
        on_plane = 2 * idx[nodes, k] == top
        #: the unknowns u_k of the nodes on the plane (zero by symmetry: to prescribe; the
        #: half model's energy is the body's only at u_k = 0 there, so their equations are
        #: not the body's and weigh nothing in its norms: the body's are 0 by symmetry)
        self.plane_unknowns = k * self.n + np.flatnonzero(on_plane)
        self.residual_weight = np.tile(np.where(on_plane, 1.0, 0.5), self.dim)
        self.residual_weight[self.plane_unknowns] = 0.0

    def expand(self, u) -> np.ndarray:
        """u of every grid node (component-major) from the model's unknowns."""
        if self.half is None:
            return np.asarray(u, dtype=float).copy()
        h = self.half
        U = np.asarray(u, dtype=float).reshape(self.dim, self.n)
        out = np.empty((self.dim, h["full_n"]))
        mirrored = U.copy()
        mirrored[h["axis"]] *= -1.0
        out[:, h["image"]] = mirrored
        out[:, self.node_ids] = U           # the plane's nodes are their own images
        return out.ravel()

    def bond_nodes(self, bond: int) -> tuple[int, int]:
        """The grid nodes (a, b) of the whole body's bond that ``bond`` stands for."""
        if self.half is not None:
            bond = int(self.half["rep"][bond])
        return int(self.model.bond_a[bond]), int(self.model.bond_b[bond])

    @property
    def pattern(self) -> _Pattern:
        if self._pattern is None:
            if self.half is None:
                self._pattern = _Pattern(self.n, self.dim, self.a, self.b)
            else:
                self._pattern = self._half_pattern()
        return self._pattern

    def _half_pattern(self) -> _Pattern:
        """The pattern of the half model's node pairs (a pair may carry a plain and a
        crossing bond, and a crossing bond may join a node to itself), with per bond the
        data positions of its (a, b) and (b, a) entries (``ab``, ``ba``; the diagonal for a
        bond from a node to itself)."""
        A, B, n = self.a.astype(np.int64), self.b.astype(np.int64), self.n
        lo, hi = np.minimum(A, B), np.maximum(A, B)
        pairs = unique_ids((lo * n + hi)[lo != hi])
        P = _Pattern(n, self.dim, pairs // n, pairs % n)
        k = np.searchsorted(pairs, lo * n + hi)
        k[lo == hi] = 0
        fwd, self_ = A < B, A == B
        ab = [[np.where(fwd, P.ab[p][q][k], P.ba[p][q][k]) for q in range(self.dim)]
              for p in range(self.dim)]
        ba = [[np.where(fwd, P.ba[p][q][k], P.ab[p][q][k]) for q in range(self.dim)]
              for p in range(self.dim)]
        for p in range(self.dim):
            for q in range(self.dim):
                ab[p][q][self_] = ba[p][q][self_] = P.diag[p][q][A[self_]]
        P.ab, P.ba = ab, ba
        return P

    def bond_vectors(self, u) -> tuple[np.ndarray, np.ndarray]:
        """Current bond vectors y (D x bonds, component rows; the caller's to change) and
        lengths l (read-only).

        The last state's are kept and handed out again (y copied) while ``u`` is the same
        bit for bit: Newton evaluates the forces at an iterate, then the tangent at the same
        iterate, the breakdown check and the next increment's predictor at the equilibrium
        it ended on; each evaluation of a state after its first was 8-13 ms of recomputation
        on the paper grid's 0.7 million bonds (half model). The same numbers, as a function of
        ``u``; the kept state costs 3 floats a bond."""
        last = self._state(u)
        return last["y"].copy(), last["l"]

    def _state(self, u) -> dict:
        """The kept state of ``u`` (its bits ``u``, ``y``, ``l`` and, once computed, the
        forces ``f``), computed unless it is the last one."""
        U = np.ascontiguousarray(u, dtype=float).reshape(self.dim, self.n)
        last = self._last
        if last is None or not np.array_equal(U.view(np.int64), last["u"]):
            y, l = self._bond_vectors(U)
            l.flags.writeable = False
            self._last = last = {"u": U.view(np.int64).copy(), "y": y, "l": l, "f": None}
        return last

    def _bond_vectors(self, U) -> tuple[np.ndarray, np.ndarray]:
        y = self.xi_t + np.take(U, self.b, axis=1)
        y -= np.take(U, self.a, axis=1)
        if self.half is not None:          # the crossing bonds' mirrored component
            h, c = self.half, self.half["plain"]
            Uk, k = U[self.half["axis"]], self.half["axis"]
            y[k, c:] = (self.xi_t[k, c:] + h["rb"][c:] * Uk[self.b[c:]]
                        - h["ra"][c:] * Uk[self.a[c:]])
        return y, np.sqrt(np.einsum("kb,kb->b", y, y))

    def internal_force(self, u) -> np.ndarray:
        last = self._state(u)
        if last["f"] is None:
            last["f"] = self._internal_force(last["y"].copy(), last["l"])
        return last["f"].copy()

    def _internal_force(self, y, l) -> np.ndarray:
        y *= self.s * (1.0 - self.L / l)          # the bond force vectors T y / l
        out = np.empty(self.dim * self.n)
        for k in range(self.dim):
            if self.half is not None and k == self.half["axis"]:   # R_b F on b, -R_a F on a
                h, c = self.half, self.half["plain"]
                yb, ya = y[k].copy(), y[k]
                yb[c:] *= h["rb"][c:]
                ya[c:] *= h["ra"][c:]
                out[k * self.n:(k + 1) * self.n] = (np.bincount(self.b, yb, self.n)
                                                    - np.bincount(self.a, ya, self.n))
                continue
            out[k * self.n:(k + 1) * self.n] = (np.bincount(self.b, y[k], self.n)
                                                - np.bincount(self.a, y[k], self.n))
        return out

    def energy(self, u) -> float:
        _, l = self.bond_vectors(u)
        return float(0.5 * np.sum(self.s * (l - self.L) ** 2))

    def energy_density(self, u) -> np.ndarray:
        """Per node: half of each of its bonds' energy s (l - L)^2 / 2, over the node
        volume (the nonlinear counterpart of ``BondBasedModel.strain_energy_density``); of
        every grid node, also for the half model."""
        if self.half is not None:
            return NonlinearBondBased(self.model).energy_density(self.expand(u))
        _, l = self.bond_vectors(u)
        half = 0.25 * self.s * (l - self.L) ** 2
        return ((np.bincount(self.a, half, self.n) + np.bincount(self.b, half, self.n))
                / self.model.node_volume)

    def _gather(self) -> np.ndarray:
        """Per data position of :attr:`pattern`, its slot in the stacked values that
        :meth:`tangent_data` computes: per block p <= q the bonds' -B_pq, then the nodes'
        diagonal sums, then a zero (positions only a crossing bond of a half model reaches).
        A gather into the CSR data reads those values in data order instead of scattering
        them bond by bond, faster and the same numbers bit for bit
        (benchmarks/records/indentation-2026-11-24-tangent-gather.json). Frees the pattern's
        per-bond positions, except the crossing bonds' (added on top)."""
        P, n, dim = self.pattern, self.n, self.dim
        nb = self.a.size
        c = nb if self.half is None else self.half["plain"]
        blocks = [(p, q) for p in range(dim) for q in range(p, dim)]
        g = np.full(P.nnz, len(blocks) * (nb + n), dtype=np.intp)
        for t, (p, q) in enumerate(blocks):
            for i, j in {(p, q), (q, p)}:
                g[P.ab[i][j][:c]] = t * nb + np.arange(c)
                g[P.ba[i][j][:c]] = t * nb + np.arange(c)
                g[P.diag[i][j]] = len(blocks) * nb + t * n + np.arange(n)
        P.ab = [[x[c:] for x in row] for row in P.ab]
        P.ba = [[x[c:] for x in row] for row in P.ba]
        return g

    def tangent_data(self, u) -> np.ndarray:
        """CSR data of the tangent on :attr:`pattern` (blocks (p, q) and (q, p) share B),
        in a buffer that the next call overwrites. A half model's crossing bonds add
        -R_a B R_b at (a, b), -R_b B R_a at (b, a) and R B R on the diagonals (module
        docstring); the plain ones are the whole body's."""
        y, l = self.bond_vectors(u)
        geo = self.s * (1.0 - self.L / l)         # T / l
        y *= np.sqrt(self.s * self.L / l) / l     # sqrt(s - T/l) n  (T/l < s: l > 0)
        P = self.pattern
        if self._data is None:
            self._gather_index = self._gather()
            self._data = np.empty(P.nnz)
        n, nb, h = self.n, self.a.size, self.half
        blocks = [(p, q) for p in range(self.dim) for q in range(p, self.dim)]
        src = np.empty(len(blocks) * (nb + n) + 1)
        src[-1] = 0.0
        k = None if h is None else h["axis"]
        for t, (p, q) in enumerate(blocks):
            B = src[t * nb:(t + 1) * nb]
            np.multiply(y[p], y[q], out=B)        # (s - T/l) n_p n_q
            if p == q:
                B += geo
            if h is not None and (p == k) != (q == k):   # R_a B R_a, R_b B R_b off-diagonal
                diag = np.bincount(self.a, h["ra"] * B, n) + np.bincount(self.b, h["rb"] * B, n)
            else:
                diag = np.bincount(self.a, B, n) + np.bincount(self.b, B, n)
            src[len(blocks) * nb + t * n:len(blocks) * nb + (t + 1) * n] = diag
            np.negative(B, out=B)
        # mode="clip": the indices are in range by construction, so the same values; with
        # ``out`` numpy's default ("raise") always gathers into a buffer first (numpy.take's
        # documentation), twice the time here
        # (benchmarks/records/indentation-2026-11-26-take-clip.json)
        data = np.take(src, self._gather_index, out=self._data, mode="clip")
        if h is not None:
            c, ra, rb = h["plain"], h["ra"][h["plain"]:], h["rb"][h["plain"]:]
            for t, (p, q) in enumerate(blocks):
                B = src[t * nb + c:(t + 1) * nb]      # -B of the crossing bonds
                for i, j in {(p, q), (q, p)}:     # r_a,i r_b,j (-B) at (a, b) and its mirror
                    np.add.at(data, P.ab[i][j], (ra if i == k else 1.0) * (rb if j == k else 1.0) * B)
                    np.add.at(data, P.ba[i][j], (rb if i == k else 1.0) * (ra if j == k else 1.0) * B)
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
        if self.half is not None:      # among ties, the bond the whole body's argmin names
            rep = self.half["rep"]
            k, j = (int(t[np.argmin(rep[t])]) for t in (np.flatnonzero(cos == cos[k]),
                                                         np.flatnonzero(ratio == ratio[j])))
        return {"cos": float(cos[k]), "cos_bond": k, "ratio": float(ratio[j]), "ratio_bond": j}


class LinearBondBased(NonlinearBondBased):
    """The small-displacement model behind the same interface: f(u) = K u and the constant
    tangent K (the nonlinear tangent at u = 0, on the same pattern); its energy density is
    the linear model's. The geometric checks (:meth:`bond_extremes`) still read the
    current bond vectors, so a linear run that folds the lattice is caught all the same."""

    def __init__(self, model: BondBasedModel, mirror_axis: int | None = None):
        super().__init__(model, mirror_axis)
        self._data = super().tangent_data(np.zeros(self.dim * self.n))
        self.K = self.pattern.matrix(self._data)

    def internal_force(self, u) -> np.ndarray:
        return self.K @ u

    def energy(self, u) -> float:
        return float(0.5 * u @ (self.K @ u))

    def energy_density(self, u) -> np.ndarray:
        return self.model.strain_energy_density(self.expand(u))

    def tangent_data(self, u) -> np.ndarray:
        return self._data.copy()
