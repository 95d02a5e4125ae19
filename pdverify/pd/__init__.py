"""The PD engine: box grids, stencils, influence functions, and one model per theory.

Data flow (one way): grid -> stencil/bonds -> model (bond-based or state-based), with a
:class:`Closure` from a boundary treatment in ``pdverify.corrections``. The engine never
imports ``corrections`` or ``scenes``.
"""
from .bondbased import BondBasedModel
from .bonds import QUADRATURES, Stencil, bond_pairs, build_stencil, partial_volumes, stencil_offsets
from .closure import Closure
from .grid import BoxGrid
from .influence import (INFLUENCES, StateBasedConstants, bond_micromodulus, get_influence,
                        material_kind)
from .statebased import StateBasedModel, state_based_stencil

__all__ = ["BondBasedModel", "BoxGrid", "Closure", "INFLUENCES", "QUADRATURES", "StateBasedConstants",
           "StateBasedModel", "state_based_stencil", "Stencil", "bond_micromodulus", "bond_pairs", "build_stencil",
           "get_influence", "material_kind", "partial_volumes", "stencil_offsets"]
