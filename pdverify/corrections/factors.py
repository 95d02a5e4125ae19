"""Per-node horizon sums and work densities over a built model's bonds, truncated and
complete: the shared arithmetic of the corrections that scale bonds (``energy``,
``volume``) and of the homogeneous-strain stiffness scenes."""
from __future__ import annotations

import numpy as np


def horizon_sums(model, q) -> np.ndarray:
    """S_i = sum over the bonds b of node i of q_b V_(other end), at every grid node.

    ``q`` (n_bonds,) or (n_bonds, k): per-bond integrands (weights included)."""
    a, b, V = model.bond_a, model.bond_b, model.node_volume
    q = np.asarray(q, dtype=float)
    n = model.grid.n_ext
    if q.ndim == 1:
        return np.bincount(a, q * V[b], n) + np.bincount(b, q * V[a], n)
    return np.stack([horizon_sums(model, q[:, k]) for k in range(q.shape[1])], axis=1)


def complete_sums(model, integrand) -> np.ndarray:
    """The same sums over a complete neighbourhood of the bulk lattice: every stencil
    offset xi with its weight omega(|xi|) beta and the bulk cell volume.

    ``integrand(omega, beta, length, unit)`` per offset, like the per-bond ``q`` of
    :func:`horizon_sums` (offsets of zero weight omega beta carry no bond and are left
    out, as the models leave them out)."""
    st, h = model.stencil, model.spacing
    xi = st.offsets * h
    r = np.linalg.norm(xi, axis=1)
    om = model.influence.omega(r, model.horizon)
    live = om * st.beta > 0
    V = model.grid.volume * model.thickness
    q = np.asarray(integrand(om[live], st.beta[live], r[live], xi[live] / r[live, None]),
                   dtype=float)
    return np.sum(q * V, axis=0)


def guarded_ratio(full, part) -> np.ndarray:
    """full / part, 1 where a node has nothing to correct (no bonds: part = 0)."""
    part = np.asarray(part, dtype=float)
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(part > 0, full / np.where(part > 0, part, 1.0), 1.0)


def homogeneous_field(model, strain) -> np.ndarray:
    """The unknowns (component-major) of u = strain . x on a plain grid's real nodes."""
    x = model.grid.x[model.grid.interior_ids]
    return (x @ np.asarray(strain, dtype=float).T).T.ravel()


def work_density(model, strain) -> np.ndarray:
    """W_i = 1/4 sum over node i's bonds of f_b e_b / V_i under the homogeneous ``strain``
    (d x d) on every node: half of each bond's work f e / 2 to each end. For the
    bond-based model this is its strain energy density (seed 003, Eq. 5); for the
    state-based model the work of its pair forces, the same attribution. Plain grids only
    (the unknowns are the real nodes)."""
    f = model.bond_forces(homogeneous_field(model, strain))
    n = model.bond_n
    e = model.bond_x * np.einsum("bi,ij,bj->b", n, np.asarray(strain, dtype=float), n)
    w = 0.25 * f * e
    ne = model.grid.n_ext
    return (np.bincount(model.bond_a, w, ne) + np.bincount(model.bond_b, w, ne)) / model.node_volume


def uniaxial(dim: int, k: int, eps: float = 1.0) -> np.ndarray:
    """The strain eps e_k (x) e_k."""
    out = np.zeros((dim, dim))
    out[k, k] = eps
    return out
