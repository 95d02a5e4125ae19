"""Bond families from one stencil of integer offsets, and partial volumes beta."""
from __future__ import annotations

import numpy as np

from .bonds_nd import bond_pairs


def partial_volumes_1d(m_ratio: float) -> tuple[np.ndarray, np.ndarray]:
    """Offsets k >= 1 and cell fractions beta_k inside the horizon, nodes at cell centres.

    The neighbour cell at offset k spans [(k - 1/2), (k + 1/2)] spacings; with
    delta = m_ratio * spacing its fraction inside the horizon is
    beta_k = clip(m_ratio - k + 1/2, 0, 1). At integer m_ratio the node at
    |xi| = delta gets beta = 1/2 (ERRATA, seed 000), which makes the discrete weighted
    volume of a complete neighbourhood equal A delta^3 exactly (Eq. 25).
    Offsets with beta_k = 0 are dropped.
    """
    k_max = int(np.ceil(m_ratio + 0.5)) - 1
    k = np.arange(1, k_max + 1)
    beta = np.clip(m_ratio - k + 0.5, 0.0, 1.0)
    keep = beta > 0
    return k[keep], beta[keep]


def bond_family_1d(n_nodes: int, offsets: np.ndarray, keep=None):
    """All pairs (i, i + k) for the stencil ``offsets`` on a line of ``n_nodes`` nodes.

    Built by array slicing, one block per offset (no per-bond loop), by the same routine
    as the 2D/3D grids (:func:`pdverify.bonds_nd.bond_pairs`). Returns the arrays ``i``,
    ``j`` (i < j) and ``which`` (index into ``offsets``). ``keep(i, j)`` may return a
    boolean mask to drop bonds.
    """
    i, j, which = bond_pairs((n_nodes,), np.asarray(offsets, dtype=int).reshape(-1, 1))
    if keep is not None:
        mask = keep(i, j)
        i, j, which = i[mask], j[mask], which[mask]
    return i, j, which
