"""The volume surface correction 2 V_0 / (V_i + V_j) (Le and Bobaru 2018; PeriLab, PeriPy
and pypd ship it): a bond's force is scaled by the complete horizon volume over the mean
of its ends' truncated horizon volumes.

V_i = sum_j beta_ij V_j over node i's bonds (the discrete horizon volume, partial cells
counted by their weights beta), V_0 the same over a complete neighbourhood of the bulk
lattice, so the bulk is untouched. Our choices: the volumes carry no influence weight
(the method is about the missing volume, and Le and Bobaru define it so); the factor
scales the bond's volume wherever it enters (``Closure.weight_factor``), as PeriLab
scales the neighbour volume: in a state-based model m and the dilatation included.
"""
from __future__ import annotations

import numpy as np

from ..pd.closure import Closure
from .factors import complete_horizon_volume, horizon_sums


def horizon_volumes(model) -> np.ndarray:
    """V_i at every grid node: the volume its bonds reach (weights beta, no omega)."""
    return horizon_sums(model, model.bond_beta)


def volume_factors(model) -> np.ndarray:
    Vi = horizon_volumes(model)
    return 2.0 * complete_horizon_volume(model) / (Vi[model.bond_a] + Vi[model.bond_b])


def volume_closure(params=None) -> Closure:
    return Closure(weight_factor=volume_factors)
