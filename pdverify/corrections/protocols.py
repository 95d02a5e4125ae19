"""What a treatment hands each problem family: one typed signature per family.

A plugin author reads the signature of the family their treatment serves here, not
``Any``. Every signature takes the treatment's resolved parameters (``Params``: name ->
value, defaults filled in, checked):

========================  ==========================================  =====================
family                    signature                                   built-in examples
========================  ==========================================  =====================
``static-state``          :class:`StaticAssembly`: ``(StaticProblem,  ``plain.assemble_plain``,
                          params) -> LinearSystem`` (``Treatment.     ``taylor_fictitious``,
                          assemble``)                                 ``surface_nodes``, ...
closures (every plain     :class:`BondClosure`: ``(params) ->         ``energy``, ``volume``,
grid, ``BondMethod``)     Closure``                                   ``pals``, ...
``wave-bar`` (role)       :class:`WaveExtension`: ``(None, params) -> ``surface_nodes.
                          (grid -> fictitious-from-real map) | None`` wave_extension``
``flux-bar`` (role)       :class:`FluxClosure`: ``(None, params) ->   Taylor's closure of
                          (grid -> Closure) | None``                  the bar's grid
``clamped-sheet`` (role)  :class:`Clamp`: ``(ClampedBox, params) ->   ``virtual_nodes.clamp``
                          ClampedGrid``
``bond-box`` (role)       :class:`BondBox`: ``(BondProblem, params)   ``bond_fictitious.
                          -> BondSystem``                             assemble_bond_box``
``held-face`` (role)      :class:`HeldFace`: ``(BondProblem, params)  ``virtual_nodes.
                          -> BondProblem``                            held_face``
========================  ==========================================  =====================

Parameter checks share one signature, :class:`ParamCheck` ``(context, params, where)``,
``context`` being what the family's scenes pass (cells per axis for ``static-state`` and
the closures, a node count for the bars); a check raises ``InputError`` (one line) or
returns ``None``.

The classes are :func:`typing.runtime_checkable` protocols of a callable;
``isinstance`` only sees that an object is callable, so :func:`conformance` checks the
signature itself (arity and, where the callable annotates it, the return type): the
built-ins are held to it by ``tests/treatments/test_protocols.py``.
"""
from __future__ import annotations

import inspect
import typing
from typing import Any, Callable, Mapping, NamedTuple, Optional, Protocol, runtime_checkable

import numpy as np
import scipy.sparse as sp

from ..pd.closure import Closure
from ..pd.grid import BoxGrid
from ..pd.problem import BondProblem, BondSystem, ClampedBox, LinearSystem, StaticProblem

#: a treatment's resolved parameters
Params = Mapping[str, Any]
#: ``grid -> (n_ext x n_real map)``: the fictitious nodes' displacements from the real ones
GridMap = Callable[[BoxGrid], sp.csr_matrix]
#: ``grid -> Closure``: a closure made for the grid the scene builds
GridClosure = Callable[[BoxGrid], Closure]


class ClampedGrid(NamedTuple):
    """A ``clamped-sheet`` treatment's own grid: its closure and the nodes that carry the
    clamps below and above."""
    grid: BoxGrid
    closure: Closure
    low: np.ndarray
    high: np.ndarray


@runtime_checkable
class StaticAssembly(Protocol):
    """``static-state``: the problem's linear system under the treatment (it may add
    nodes, unknowns, constraint, flux or boundary rows; the system carries all of it)."""

    def __call__(self, problem: StaticProblem, params: Params) -> LinearSystem: ...


@runtime_checkable
class BondClosure(Protocol):
    """A bond method: the closure of a plain grid's model (bond weights, force factors,
    a constitutive replacement); the conditions stay the uncorrected model's."""

    def __call__(self, params: Params) -> Closure: ...


@runtime_checkable
class WaveExtension(Protocol):
    """``wave-bar``: the bar's fictitious extension as a map of its grid (``None``:
    truncated neighbourhoods). The family has no problem object (``problem`` is None)."""

    def __call__(self, problem: None, params: Params) -> Optional[GridMap]: ...


@runtime_checkable
class FluxClosure(Protocol):
    """``flux-bar``: the closure of the bar's grid (one horizon of fictitious layers),
    ``None`` for truncated neighbourhoods (``problem`` is None)."""

    def __call__(self, problem: None, params: Params) -> Optional[GridClosure]: ...


@runtime_checkable
class Clamp(Protocol):
    """``clamped-sheet``: the treatment's own grid, closure and clamp nodes."""

    def __call__(self, problem: ClampedBox, params: Params) -> ClampedGrid: ...


@runtime_checkable
class BondBox(Protocol):
    """``bond-box``: a bond-based box's system from its conditions at the surface
    (:class:`~pdverify.pd.problem.SurfaceConditions`), with the treatment's own grid,
    unknowns and rows (``corrections.bond_fictitious``)."""

    def __call__(self, problem: BondProblem, params: Params) -> BondSystem: ...


@runtime_checkable
class HeldFace(Protocol):
    """``held-face``: the description with what the treatment adds beyond its held faces
    (virtual nodes' rigid buffer rows, held as the face is)."""

    def __call__(self, problem: BondProblem, params: Params) -> BondProblem: ...


@runtime_checkable
class ParamCheck(Protocol):
    """Refuses parameters before any work (``InputError``, one line naming ``where``)."""

    def __call__(self, context: Any, params: Params, where: str) -> None: ...


#: the protocol of each family's role (``Role.build``)
ROLE_PROTOCOLS: dict[str, type] = {"wave-bar": WaveExtension, "flux-bar": FluxClosure,
                                   "clamped-sheet": Clamp, "bond-box": BondBox,
                                   "held-face": HeldFace}
#: what ``Role.build`` may be: one of the role protocols
RoleBuild = typing.Union[WaveExtension, FluxClosure, Clamp, BondBox, HeldFace]


def conformance(fn, protocol: type) -> str | None:
    """``None`` when ``fn`` can be called as ``protocol``'s ``__call__`` (as many
    positional parameters, no further required ones) and, if ``fn`` annotates its return,
    returns the protocol's type (or, for ``Optional[X]``, ``X`` or ``None``); else what
    differs, in one phrase."""
    if not isinstance(fn, protocol):
        return f"{fn!r} is not callable"
    want = inspect.signature(protocol.__call__)
    arity = len(want.parameters) - 1                          # without self
    try:
        sig = inspect.signature(fn)
    except (TypeError, ValueError):
        return f"{fn!r} has no signature"
    params = list(sig.parameters.values())
    positional = [p for p in params if p.kind in (p.POSITIONAL_ONLY, p.POSITIONAL_OR_KEYWORD)]
    required = [p for p in params if p.default is p.empty
                and p.kind not in (p.VAR_POSITIONAL, p.VAR_KEYWORD)]
    takes_any = any(p.kind is p.VAR_POSITIONAL for p in params)
    if len(required) > arity or (len(positional) < arity and not takes_any):
        return (f"{getattr(fn, '__qualname__', fn)} takes {len(positional)} positional "
                f"parameters ({len(required)} required); {protocol.__name__} passes {arity}")
    hints = _hints(fn)
    if hints is None:
        return f"{getattr(fn, '__qualname__', fn)}'s annotations do not resolve"
    if "return" in hints:
        expected = typing.get_type_hints(protocol.__call__)["return"]
        # Optional[X] is met by X, and by None (a treatment that adds nothing there)
        if hints["return"] != expected and hints["return"] not in typing.get_args(expected):
            return (f"{getattr(fn, '__qualname__', fn)} returns {hints['return']!r}; "
                    f"{protocol.__name__} returns {expected!r}")
    return None


def _hints(fn) -> dict | None:
    target = fn.func if hasattr(fn, "func") and hasattr(fn, "args") else fn   # partial
    try:
        return typing.get_type_hints(target)
    except Exception:   # an annotation naming what its module does not import
        return None
