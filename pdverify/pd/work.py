"""Work densities of a built model under homogeneous strain: what the stiffness scenes
measure (W_i / W_bulk) and the ``energy`` correction inverts."""
from __future__ import annotations

import numpy as np

from .bonds import homogeneous_extensions


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
