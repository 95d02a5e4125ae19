"""The registry of boundary treatments: built in, and from plugins.

Every method is a :class:`~pdverify.corrections.treatment.Treatment` (the contract and
its three ways of serving a scene are in that module). A :class:`BondMethod` is the
simplest: ``closure(params) -> Closure`` (bond weights, force factors, a constitutive
replacement) on the uncorrected model, whose boundary conditions it keeps; it serves
every scene that declares ``closure_theory`` (its models are plain grids with truncated
neighbourhoods) and every ``static-state`` problem.

Plugins: another package registers treatments of any kind through the Python entry point
group ``pdverify.methods``; each entry point loads a :class:`Treatment` or a list of
them, e.g. in the plugin's ``pyproject.toml``::

    [project.entry-points."pdverify.methods"]
    my-method = "my_package.pdverify_plugin:METHOD"

A plugin that fails to load is listed as unavailable with its error; it never stops
pdverify. A method whose optional dependency is missing says so in ``unavailable``
(the install command), and a run of it is refused as bad input.
"""
from __future__ import annotations

import difflib
from dataclasses import dataclass, replace
from typing import Any, Callable, Mapping

from ..errors import InputError
from ..params import Param
from ..pd.closure import Closure
from .treatment import ENTRY_POINT_GROUP, THEORIES, Treatment  # noqa: F401  (re-exported)


@dataclass(frozen=True)
class BondMethod(Treatment):
    """A correction that acts through the closure of a plain grid's model.

    ``closure(params) -> Closure`` builds it from the method's resolved ``params``; the
    boundary conditions are imposed as the uncorrected model imposes them (``none``).
    """

    closure: Callable[[Mapping], Closure] | None = None
    families: tuple[str, ...] = ("static-state",)

    @property
    def kind(self) -> str:
        return "closure"

    def _why_not_kind(self, scene) -> str | None:
        if getattr(scene, "closure_theory", None) is not None:
            return None
        return super()._why_not_kind(scene)

    def assemble(self, problem, params: Mapping[str, Any]):
        from .static_state import assemble_plain
        return assemble_plain(problem, self.closure(params))


def _builtin() -> list[Treatment]:
    from .builtin import family_treatments, hand_wired
    from .energy import energy_closure
    from .pals import pals_closure
    from .perifit_weights import INSTALL, SCENES, installed_version, perifit_closure
    from .volume import volume_closure
    pv = installed_version()
    return family_treatments() + hand_wired() + [
        BondMethod("energy", "Le and Bobaru 2018 energy correction: per axis the ratio of a "
                   "complete to the node's uniaxial-stretch energy, bonds by the ellipse of "
                   "their ends' mean factors, applied to the bond force",
                   "Le and Bobaru, Comput. Mech. 61 (2018) 499-518; Peridynamics.jl",
                   closure=energy_closure),
        BondMethod("volume", "volume correction 2 V0 / (V_i + V_j) on the bond force (V the "
                   "discrete horizon volume of each end)",
                   "Le and Bobaru 2018; PeriLab, PeriPy, pypd", closure=volume_closure),
        BondMethod("pals", "position-aware linear solid: per-node dilatation and deviatoric "
                   "influence functions from the matching deformations (Lagrange "
                   "multipliers); constraints as the uncorrected model imposes them",
                   "Mitchell, Silling and Littlewood, J. Mech. Mater. Struct. 10 (2015) "
                   "539-557; seed 001 §5.1; Peridigm pals.cxx", closure=pals_closure,
                   theories=("state-based",), dims=(2, 3),
                   scope="2D/3D state-based (the matching deformations of a 1D bar leave "
                         "its influence functions undetermined)"),
        BondMethod("perifit", "operator-matching nodal weights of the perifit package, "
                   "(w_i + w_j) / 2 on each bond's weight", "perifit (PyPI), Shojaei and "
                   "Hermann, Helmholtz-Zentrum Hereon", closure=perifit_closure,
                   scenes=SCENES,
                   scope="scenes whose families perifit's API can weigh (bond-based, or "
                         "the 3D LPS boxes): " + ", ".join(SCENES),
                   params=(Param("perifit_version", pv or "not installed",
                                 "the perifit version that computes the weights (recorded "
                                 "with every run)", choices=(pv or "not installed",)),),
                   unavailable=None if pv else f"needs the optional extra: {INSTALL}"),
    ]


_METHODS: dict[str, Treatment] | None = None
#: entry points that failed to load: name -> the error, shown by ``list``
BROKEN: dict[str, str] = {}


def _plugins():
    from importlib.metadata import entry_points
    for ep in entry_points(group=ENTRY_POINT_GROUP):
        try:
            obj = ep.load()
            items = obj if isinstance(obj, (list, tuple)) else [obj]
            for item in items:
                if not isinstance(item, Treatment):
                    raise TypeError(f"{type(item).__name__} is not a pdverify Treatment")
                yield replace(item, origin=f"plugin {ep.value}")
        except Exception as exc:  # a broken plugin never stops pdverify
            BROKEN[ep.name] = f"{type(exc).__name__}: {exc}"


def treatments() -> dict[str, Treatment]:
    """Every treatment, built-in first, then the plugins (a plugin cannot replace a
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


def bond_methods() -> dict[str, BondMethod]:
    """The closure treatments (:class:`BondMethod`) among :func:`treatments`."""
    return {k: m for k, m in treatments().items() if isinstance(m, BondMethod)}


def reload() -> None:
    """Forget the loaded plugins (tests install one and look again)."""
    global _METHODS
    _METHODS = None
    BROKEN.clear()


def from_name(name: str) -> Treatment:
    """The registered treatment ``name``; unknown names are bad input with the close
    matches and the full list."""
    known = treatments()
    if name in known:
        return known[name]
    close = difflib.get_close_matches(name, list(known), n=3)
    hint = f"; did you mean {' or '.join(close)}?" if close else ""
    raise InputError(f"unknown method {name!r}{hint} (allowed: {', '.join(known)})")
