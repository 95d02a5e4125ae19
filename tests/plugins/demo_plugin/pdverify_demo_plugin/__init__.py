"""A third-party correction as a researcher would ship one: every bond's force times a
constant ``factor`` (1 = the uncorrected model). It exists to test pdverify's entry
point ``pdverify.methods``; it corrects nothing."""
import numpy as np

from pdverify.corrections.registry import BondMethod
from pdverify.params import Param, positive
from pdverify.pd.closure import Closure


def _closure(params):
    factor = float(params["factor"])
    return Closure(force_factor=lambda model: np.full(model.bond_a.size, factor))


METHOD = BondMethod(
    name="demo-uniform",
    description="demo plugin: every bond force times a constant factor",
    source="tests/plugins/demo_plugin",
    closure=_closure,
    params=(Param("factor", 1.0, "the constant factor", positive),),
)
