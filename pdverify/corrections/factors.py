"""Per-node horizon sums and work densities over a built model's bonds, truncated and
complete: the shared arithmetic of the corrections that scale bonds (``energy``,
``volume``) and of the homogeneous-strain stiffness scenes."""
from __future__ import annotations

import numpy as np

from ..pd.bonds import homogeneous_extensions


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


def work_density(model, strain) -> np.ndarray:
    """W_i = 1/4 sum over node i's bonds of f_b e_b / V_i under the homogeneous ``strain``
    (d x d) on every node: half of each bond's work f e / 2 to each end. For the
    bond-based model this is its strain energy density (seed 003, Eq. 5); for the
    state-based model the work of its pair forces, the same attribution. Plain grids only
    (the unknowns are the real nodes)."""
    f = model.bond_forces(homogeneous_field(model, strain))
    w = 0.25 * f * homogeneous_extensions(model.bond_x, model.bond_n, strain)
    ne = model.grid.n_ext
    return (np.bincount(model.bond_a, w, ne) + np.bincount(model.bond_b, w, ne)) / model.node_volume


def uniaxial(dim: int, k: int, eps: float = 1.0) -> np.ndarray:
    """The strain eps e_k (x) e_k."""
    out = np.zeros((dim, dim))
    out[k, k] = eps
    return out
