"""Plugins that misbehave in each place pdverify calls plugin code; each must become a
broken listing or a failed run naming the plugin, never the end of pdverify."""
import sys

import numpy as np

from pdverify.corrections.registry import BondMethod
from pdverify.params import Param
from pdverify.pd.closure import Closure


def _exit_in_closure(params):
    sys.exit(0)


def _exit_in_force_factor(params):
    def force_factor(model):
        raise SystemExit(4)
    return Closure(force_factor=force_factor)


def _uniform(params):
    return Closure(force_factor=lambda model: np.ones(model.bond_a.size))


def _exit_in_check(value):
    if value > 1:
        sys.exit(5)
    return None


def _not_a_closure(params):
    return "a string"


COMMON = dict(description="misbehaving test plugin", source="tests/plugins/broken_plugins")
CLOSURE_EXIT = BondMethod(name="closure-exit", closure=_exit_in_closure, **COMMON)
FACTOR_EXIT = BondMethod(name="factor-exit", closure=_exit_in_force_factor, **COMMON)
NOT_A_CLOSURE = BondMethod(name="not-a-closure", closure=_not_a_closure, **COMMON)
#: a parameter named like the scenes' spacing: would replace every scene's default
SPACING_CLASH = BondMethod(name="spacing-clash", closure=_uniform,
                           params=(Param("spacing", 0.5, "clashes with the scenes'"),), **COMMON)
CHECK_EXIT = BondMethod(name="check-exit", closure=_uniform,
                        params=(Param("gain", 1.0, "exits when above 1", _exit_in_check),),
                        **COMMON)
NOT_A_METHOD = object()
