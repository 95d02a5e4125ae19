"""Methods that correct the PD model through its bonds alone, built in or from plugins.

A :class:`BondMethod` turns its parameters into a :class:`~pdverify.pd.closure.Closure`
(bond weights, force factors) and says which theories it serves. Every scene that
declares ``closure_theory`` (its models are plain grids with truncated neighbourhoods)
then offers the method in ``run``, ``list`` and ``report`` like its own.

Plugins: another package registers methods through the Python entry point group
``pdverify.methods``; each entry point loads a :class:`BondMethod` or a list of them,
e.g. in the plugin's ``pyproject.toml``::

    [project.entry-points."pdverify.methods"]
    my-method = "my_package.pdverify_plugin:METHOD"

A plugin that fails to load is listed as unavailable with its error; it never stops
pdverify. A method whose optional dependency is missing says so in ``unavailable``
(the install command), and a run of it is refused as bad input.
"""
from __future__ import annotations

from dataclasses import dataclass, replace
from typing import Callable, Mapping

from ..params import Param
from ..pd.closure import Closure

THEORIES = ("bond-based", "state-based")
ENTRY_POINT_GROUP = "pdverify.methods"


@dataclass(frozen=True)
class BondMethod:
    """A correction that acts through the closure of a plain grid's model.

    ``closure(params) -> Closure`` builds it from the method's resolved ``params``;
    ``theories`` the models it applies to, ``dims`` their dimensions; ``scenes``
    restricts it to these scene ids (``None``: every scene of those theories);
    ``unavailable`` is ``None`` when it can run, else why not and how to fix it. ``origin``: ``built-in`` or the plugin's
    entry point.
    """

    name: str
    description: str
    source: str
    closure: Callable[[Mapping], Closure]
    theories: tuple[str, ...] = THEORIES
    params: tuple[Param, ...] = ()
    scenes: tuple[str, ...] | None = None
    unavailable: str | None = None
    origin: str = "built-in"
    dims: tuple[int, ...] = (1, 2, 3)

    def __post_init__(self):
        bad = [t for t in self.theories if t not in THEORIES]
        if bad:
            raise ValueError(f"method {self.name!r}: theories {bad} not in {THEORIES}")

    def serves(self, scene) -> bool:
        theory = getattr(scene, "closure_theory", None)
        return (theory in self.theories and getattr(scene, "dim", None) in self.dims
                and (self.scenes is None or scene.id in self.scenes))


def _builtin() -> list[BondMethod]:
    from .energy import energy_closure
    from .pals import pals_closure
    from .perifit_weights import INSTALL, SCENES, installed_version, perifit_closure
    from .volume import volume_closure
    pv = installed_version()
    return [
        BondMethod("energy", "Le and Bobaru 2018 energy correction: per axis the ratio of a "
                   "complete to the node's uniaxial-stretch energy, bonds by the ellipse of "
                   "their ends' mean factors, applied to the bond force",
                   "Le and Bobaru, Comput. Mech. 61 (2018) 499-518; Peridynamics.jl",
                   energy_closure),
        BondMethod("volume", "volume correction 2 V0 / (V_i + V_j) on the bond force (V the "
                   "discrete horizon volume of each end)",
                   "Le and Bobaru 2018; PeriLab, PeriPy, pypd", volume_closure),
        BondMethod("pals", "position-aware linear solid: per-node dilatation and deviatoric "
                   "influence functions from the matching deformations (Lagrange "
                   "multipliers); constraints as the uncorrected model imposes them",
                   "Mitchell, Silling and Littlewood, J. Mech. Mater. Struct. 10 (2015) "
                   "539-557; seed 001 §5.1; Peridigm pals.cxx", pals_closure,
                   theories=("state-based",), dims=(2, 3)),
        BondMethod("perifit", "operator-matching nodal weights of the perifit package, "
                   "(w_i + w_j) / 2 on each bond's weight", "perifit (PyPI), Shojaei and "
                   "Hermann, Helmholtz-Zentrum Hereon", perifit_closure, scenes=SCENES,
                   params=(Param("perifit_version", pv or "not installed",
                                 "the perifit version that computes the weights (recorded "
                                 "with every run)", choices=(pv or "not installed",)),),
                   unavailable=None if pv else f"needs the optional extra: {INSTALL}"),
    ]


_METHODS: dict[str, BondMethod] | None = None
#: entry points that failed to load: name -> the error, shown by ``list``
BROKEN: dict[str, str] = {}


def _plugins():
    from importlib.metadata import entry_points
    for ep in entry_points(group=ENTRY_POINT_GROUP):
        try:
            obj = ep.load()
            items = obj if isinstance(obj, (list, tuple)) else [obj]
            for item in items:
                if not isinstance(item, BondMethod):
                    raise TypeError(f"{type(item).__name__} is not a pdverify BondMethod")
                yield replace(item, origin=f"plugin {ep.value}")
        except Exception as exc:  # a broken plugin never stops pdverify
            BROKEN[ep.name] = f"{type(exc).__name__}: {exc}"


def bond_methods() -> dict[str, BondMethod]:
    """Every bond method, built-in first, then the plugins (a plugin cannot replace a
    built-in name: it is listed as broken instead)."""
    global _METHODS
    if _METHODS is None:
        methods = {m.name: m for m in _builtin()}
        for m in _plugins():
            if m.name in methods:
                BROKEN[m.name] = f"{m.origin}: the name {m.name!r} is taken"
                continue
            methods[m.name] = m
        _METHODS = methods
    return _METHODS


def reload() -> None:
    """Forget the loaded plugins (tests install one and look again)."""
    global _METHODS
    _METHODS = None
    BROKEN.clear()
