"""Per-node horizon sums over a built model's bonds, truncated and complete, and the
per-node fits: the shared arithmetic of the corrections that scale bonds (``energy``,
``volume``) or fit per node (``pals``, ``pddo``). The work densities under homogeneous
strain, which the stiffness scenes measure as well, are the model's
(:mod:`pdverify.pd.work`)."""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from ..errors import NumericalError

#: a node's scaled system counts as singular above this condition number (1 / 1e-12:
#: machine epsilon times ~1e4, the solution would lose every digit)
MAX_NODE_CONDITION = 1e12


def horizon_sums(model, q) -> np.ndarray:
    """S_i = sum over the bonds b of node i of q_b V_(other end), at every grid node."""
    a, b, V = model.bond_a, model.bond_b, model.node_volume
    q = np.asarray(q, dtype=float)
    n = model.grid.n_ext
    return np.bincount(a, q * V[b], n) + np.bincount(b, q * V[a], n)


def complete_horizon_volume(model) -> float:
    """sum beta V over a complete neighbourhood of the bulk lattice: every stencil offset
    that carries a bond (weight omega beta > 0, as the models keep them), bulk cell volume."""
    st = model.stencil
    r, _ = st.vectors(model.spacing)
    live = model.influence.omega(r, model.horizon) * st.beta > 0
    return float(np.sum(st.beta[live]) * model.grid.volume * model.thickness)


def guarded_ratio(full, part) -> np.ndarray:
    """full / part, 1 where a node has nothing to correct (no bonds: part = 0)."""
    part = np.asarray(part, dtype=float)
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(part > 0, full / np.where(part > 0, part, 1.0), 1.0)


def node_moments(nodes, weights, P, n) -> np.ndarray:
    """M_i = sum over the rows r with nodes[r] = i of weights[r] P_r P_r^T, (n, p, p): the
    per-node moment matrices of a fit over each node's bonds (one row per bond end)."""
    m, p = P.shape
    inc = sp.csr_matrix((weights, (nodes, np.arange(m))), shape=(n, m))
    return (inc @ np.einsum("bk,bl->bkl", P, P).reshape(m, p * p)).reshape(n, p, p)


def node_sums(nodes, weights, P, n) -> np.ndarray:
    """S_i = sum over the rows r with nodes[r] = i of weights[r] P_r, (n, p)."""
    m = P.shape[0]
    inc = sp.csr_matrix((weights, (nodes, np.arange(m))), shape=(n, m))
    return inc @ P


def solve_per_node(K, rhs, what, x) -> np.ndarray:
    """Solve the small systems K_i y_i = rhs_i of every node (K: (n, p, p); rhs: (n, p)
    or (n, p, r)) after scaling each to unit diagonal. A singular one (condition above
    :data:`MAX_NODE_CONDITION`: its bonds do not span what it must fit) is a
    NumericalError naming the first such node, at positions ``x``."""
    diag = np.einsum("npp->np", K)
    s = 1.0 / np.sqrt(np.where(diag > 0, diag, 1.0))
    Ks = K * s[:, :, None] * s[:, None, :]
    cond = np.linalg.cond(Ks)
    bad = ~np.isfinite(cond) | (cond > MAX_NODE_CONDITION)
    if np.any(bad):
        i = int(np.flatnonzero(bad)[0])
        raise NumericalError(f"{what} of the node at {np.array2string(x[i], precision=4)} "
                             f"is singular (condition {cond[i]:.3g}): its bonds do not span "
                             f"the fit ({int(bad.sum())} such nodes)")
    vector = rhs.ndim == 2
    r = (rhs[..., None] if vector else rhs) * s[:, :, None]
    y = np.linalg.solve(Ks, r) * s[:, :, None]
    return y[..., 0] if vector else y
