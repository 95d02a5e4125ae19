"""A bond method in one module: the mean of the two ends' horizon-volume ratios.

Node i's truncated horizon volume is V_i = sum_j beta_ij V_j over its bonds, V_0 the same
over a complete neighbourhood of the bulk lattice. Each node's own correction is the ratio
r_i = V_0 / V_i (1 in the bulk, above 1 near a surface); a bond's factor is the arithmetic
mean of its ends' ratios,

    f_ij = (r_i + r_j) / 2 = V_0 (V_i + V_j) / (2 V_i V_j),

where the built-in ``volume`` method takes their harmonic mean 2 V_0 / (V_i + V_j). By the
inequality of the means f_ij >= volume's factor, with equality where V_i = V_j, and
f_ij * volume's factor = r_i r_j on every bond (an identity the tests check). Like
``volume`` it scales the bond's volume wherever it enters (``Closure.weight_factor``), so
one closure serves the bond-based and the state-based models alike.

It exists to show that a bond method is one module: pdverify's entry point group
``pdverify.methods`` registers it, and it runs on every scene that takes bond methods.
"""
import numpy as np

from pdverify.corrections.factors import complete_horizon_volume, horizon_sums
from pdverify.corrections.registry import BondMethod
from pdverify.pd.closure import Closure


def node_ratios(model) -> np.ndarray:
    """r_i = V_0 / V_i at every grid node (V_i with the weights beta, no influence)."""
    Vi = horizon_sums(model, model.bond_beta)
    with np.errstate(divide="ignore"):
        return np.where(Vi > 0, complete_horizon_volume(model) / np.where(Vi > 0, Vi, 1.0),
                        1.0)


def mean_ratio_factors(model) -> np.ndarray:
    """f_ij = (r_i + r_j) / 2 on every bond."""
    r = node_ratios(model)
    return 0.5 * (r[model.bond_a] + r[model.bond_b])


def _closure(params):
    return Closure(weight_factor=mean_ratio_factors)


METHOD = BondMethod(
    name="mean-ratio",
    description="test plugin: a bond's volume times the mean of its ends' horizon-volume "
                "ratios V_0/V_i (volume takes their harmonic mean)",
    source="tests/plugins/mean_ratio_plugin",
    closure=_closure,
)
