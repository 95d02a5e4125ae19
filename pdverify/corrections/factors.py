"""Per-node horizon sums and work densities over a built model's bonds, truncated and
complete: the shared arithmetic of the corrections that scale bonds (``energy``,
``volume``) and of the homogeneous-strain stiffness scenes."""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from ..errors import NumericalError
from ..pd.bonds import homogeneous_extensions

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


def homogeneous_field(model, strain) -> np.ndarray:
    """The unknowns (component-major) of u = strain . x on a plain grid's real nodes."""
    x = model.grid.x[model.grid.interior_ids]
    return (x @ np.asarray(strain, dtype=float).T).T.ravel()


def work_density(model, strain, field=None, offset=None) -> np.ndarray:
    """W_i = 1/2 sum over node i's bonds of f_i,b e_b / V_i under the homogeneous
    ``strain`` (d x d) on every node, f_i,b the part of bond b's force that node i's own
    force state gives (``model.bond_end_forces``). This is node i's strain energy density
    for any model with a quadratic energy (Euler: sum e dW_i/de = 2 W_i): for the
    bond-based model half of each bond's energy (seed 003, Eq. 5); for LPS
    k_theta theta_i^2 / (2 c_theta) + k_e / (2 m_i) sum omega e^2 beta V; for PALS its
    kappa theta^2 / 2 + mu sum sigma (e^d)^2 beta V. For a force scaled after the fact
    (the energy correction) it is the work of the scaled forces, attributed the same way.
    On a plain grid the unknowns are the real nodes (``field=None``); a treatment with
    fictitious or surface nodes gives ``field``, the unknowns it carries (strain . x at
    its unknown nodes), and ``offset``, its grid displacement the unknowns do not carry
    (``LinearSystem.offset``): its fictitious nodes then follow its own closure."""
    if field is None:
        field = homogeneous_field(model, strain)
    f_a, f_b = (model.bond_end_forces(field) if offset is None
                else model.bond_end_forces(field, offset))
    e = homogeneous_extensions(model.bond_x, model.bond_n, strain)
    ne = model.grid.n_ext
    return (np.bincount(model.bond_a, 0.5 * f_a * e, ne)
            + np.bincount(model.bond_b, 0.5 * f_b * e, ne)) / model.node_volume


def uniaxial(dim: int, k: int, eps: float = 1.0) -> np.ndarray:
    """The strain eps e_k (x) e_k."""
    out = np.zeros((dim, dim))
    out[k, k] = eps
    return out


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
