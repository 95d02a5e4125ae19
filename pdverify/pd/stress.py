"""Nodal quantities from bond forces: the virial (peridynamic) stress of a node."""
from __future__ import annotations

import numpy as np


def virial_stress(model, bond_forces, nodes) -> np.ndarray:
    """Stress sigma_a = 1 / (2 V_a) sum_(bonds at a) f_b |xi_b| n_b (x) n_b at grid ``nodes``.

    ``bond_forces`` are a model's scalar bond forces (``model.bond_forces(u)``: the force
    on the bond's ends along a -> b, quadrature weights included). For a homogeneous
    deformation of a node with a complete neighbourhood this is the force flux through a
    plane per unit area (Lehoucq and Silling 2008), so it reads off the discrete material's
    moduli; near a surface it is the usual nodal estimate. Returns (n_nodes, d, d).
    """
    nodes = np.atleast_1d(np.asarray(nodes))
    d = model.dim
    f = np.asarray(bond_forces, dtype=float) * model.bond_x
    nn = model.bond_n[:, :, None] * model.bond_n[:, None, :]
    out = np.zeros((nodes.size, d, d))
    lookup = np.full(model.grid.n_ext, -1)
    lookup[nodes] = np.arange(nodes.size)
    for end in (model.bond_a, model.bond_b):  # each bond counts at both of its ends
        hit = lookup[end] >= 0
        np.add.at(out, lookup[end[hit]], f[hit, None, None] * nn[hit])
    return out / (2.0 * model.node_volume[nodes])[:, None, None]
