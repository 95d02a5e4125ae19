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

A plugin never stops pdverify. Every call into plugin code (its import, its closure, the
functions that closure hands the model, its parameters' checks) catches any exception,
``SystemExit`` included (only ``KeyboardInterrupt``, the user's own stop, passes):

- a plugin that fails to load, whose entry point is not a well-formed
  :class:`BondMethod`, whose parameter's default fails its own check, or whose parameter
  shares a name with a parameter of a scene it serves (it would replace that scene's
  default), is listed as broken with its error (``list``: ``plugin NAME: failed to load
  (SystemExit(3) at import)``) and left out of reports; the built-in methods run as
  before, and ``run --method NAME`` on a scene that takes bond methods is a failed run
  giving that error;
- a plugin whose code raises during a run (``SystemExit(0)`` in its closure included)
  makes that run a failed run whose message names the plugin and what it did.

A method whose optional dependency is missing says so in ``unavailable`` (the install
command), and a run of it is refused as bad input.
"""
from __future__ import annotations

import functools
from dataclasses import dataclass, fields, replace
from typing import Callable, Mapping

from ..errors import InputError, NumericalError
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

    def make_closure(self, params: Mapping) -> Closure:
        """The closure for ``params``; a plugin's is guarded (see the module docstring)."""
        if self.origin == "built-in":
            return self.closure(params)
        return _plugin_closure(self, params)

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


class PluginError(NumericalError):
    """A plugin's code raised (or exited) during a run: the run fails, naming the plugin."""


def what_it_did(exc: BaseException) -> str:
    """``SystemExit(3)``, ``ValueError: bad factor``: the exception in one short phrase."""
    if isinstance(exc, SystemExit):
        return f"SystemExit({exc.code!r})"
    text = " ".join(str(exc).split())
    return f"{type(exc).__name__}: {text}" if text else type(exc).__name__


def _guard(fn, who: str, what: str, error=PluginError):
    """``fn`` wrapped so that anything it raises except ``KeyboardInterrupt`` (and the
    engine's own :class:`NumericalError` raised through it) becomes ``error`` naming
    ``who`` (the plugin) and ``what`` (which of its functions)."""
    @functools.wraps(fn)
    def guarded(*args, **kwargs):
        try:
            return fn(*args, **kwargs)
        except KeyboardInterrupt:
            raise
        except NumericalError:
            raise
        except BaseException as exc:  # SystemExit included: a plugin never ends pdverify
            raise error(f"{who}: {what} raised {what_it_did(exc)}") from None
    return guarded


class _GuardedConstitutive:
    """A plugin's ``constitutive`` object whose methods are guarded like its closure's."""

    def __init__(self, inner, who):
        self._inner, self._who = inner, who

    def __getattr__(self, name):
        try:
            value = getattr(self._inner, name)
        except KeyboardInterrupt:
            raise
        except BaseException as exc:
            raise PluginError(f"{self._who}: constitutive.{name} raised "
                              f"{what_it_did(exc)}") from None
        return _guard(value, self._who, f"constitutive.{name}") if callable(value) else value


_CALLABLE_FIELDS = ("keep", "bond_factor", "weight_factor", "force_factor")


def _plugin_closure(method: "BondMethod", params: Mapping) -> Closure:
    """The closure of a plugin's method, every function in it guarded (see the module
    docstring); a closure that is not a :class:`Closure` fails the run."""
    who = f"plugin method {method.name} ({method.origin.removeprefix('plugin ')})"
    closure = _guard(method.closure, who, "its closure")(dict(params))
    if not isinstance(closure, Closure):
        raise PluginError(f"{who}: its closure returned {type(closure).__name__}, not a "
                          "pdverify Closure")
    changes = {k: _guard(getattr(closure, k), who, k) for k in _CALLABLE_FIELDS
               if callable(getattr(closure, k))}
    if closure.constitutive is not None:
        changes["constitutive"] = _GuardedConstitutive(closure.constitutive, who)
    return replace(closure, **changes)


def _checked_param(p: Param, who: str) -> Param:
    """A plugin's parameter whose check is guarded: raising in it is refused as bad input
    naming the plugin; its default must pass it (else the plugin is broken)."""
    if not isinstance(p, Param):
        raise TypeError(f"params holds {type(p).__name__}, not a pdverify Param")
    if not isinstance(p.name, str) or not p.name.isidentifier():
        raise TypeError(f"parameter name {p.name!r} is not an identifier")
    if p.check is None:
        return p
    guarded = _guard(p.check, who, f"the check of its parameter {p.name}", error=InputError)
    problem = guarded(p.default)
    if problem:
        raise ValueError(f"the default {p.name}={p.default!r} fails its own check ({problem})")
    return replace(p, check=guarded)


def _as_builtin_type(item, origin: str) -> "BondMethod":
    """A plain :class:`BondMethod` with the plugin's data, so that only pdverify's own
    methods (``serves``, ``__post_init__``) run on it; fields of the wrong type refused."""
    if not isinstance(item, BondMethod):
        raise TypeError(f"{type(item).__name__} is not a pdverify BondMethod")
    data = {f.name: getattr(item, f.name) for f in fields(BondMethod)}
    if not (isinstance(data["name"], str) and data["name"] and data["name"].isprintable()
            and " " not in data["name"]):
        raise TypeError(f"method name {data['name']!r} must be a non-empty word")
    for key in ("description", "source"):
        if not isinstance(data[key], str):
            raise TypeError(f"{key} must be a string")
    if not callable(data["closure"]):
        raise TypeError("closure is not callable")
    who = f"plugin method {data['name']} ({origin})"
    data.update(origin=f"plugin {origin}", params=tuple(_checked_param(p, who)
                                                        for p in tuple(data["params"])),
                theories=tuple(data["theories"]), dims=tuple(int(d) for d in data["dims"]),
                scenes=None if data["scenes"] is None else tuple(map(str, data["scenes"])),
                unavailable=None if data["unavailable"] is None else str(data["unavailable"]))
    return BondMethod(**data)


def _plugins():
    """(name, BondMethod or the error) of every entry point: a load that raises anything
    but KeyboardInterrupt, ``SystemExit`` at import included, is an error."""
    from importlib.metadata import entry_points
    try:
        eps = list(entry_points(group=ENTRY_POINT_GROUP))
    except KeyboardInterrupt:
        raise
    except BaseException as exc:  # broken metadata of some installed distribution
        BROKEN["(entry points)"] = f"{what_it_did(exc)} while listing the entry points"
        return
    for ep in eps:
        try:
            obj = ep.load()
        except KeyboardInterrupt:
            raise
        except BaseException as exc:  # a broken plugin never stops pdverify
            BROKEN[ep.name] = f"{ep.value}: {what_it_did(exc)} at import"
            continue
        try:
            items = obj if isinstance(obj, (list, tuple)) else [obj]
            methods = [_as_builtin_type(item, ep.value) for item in items]
        except KeyboardInterrupt:
            raise
        except BaseException as exc:
            BROKEN[ep.name] = f"{ep.value}: {what_it_did(exc)}"
            continue
        yield from methods


def _scene_param_clash(method: BondMethod) -> str | None:
    """The first parameter of ``method`` named like a parameter of a scene it serves (its
    own or those of that scene's ``none``, which a bond method takes), as a phrase."""
    from ..scenes import all_scenes
    mine = {p.name for p in method.params}
    for scene in all_scenes():
        if not method.serves(scene):
            continue
        base = next((m.params for m in scene.methods if m.name == "none"), ())
        taken = mine & {p.name for p in tuple(scene.params) + tuple(base)}
        if taken:
            return (f"its parameter {sorted(taken)[0]!r} is a parameter of scene {scene.id} "
                    "(it would replace the scene's value); rename it")
    return None


def bond_methods() -> dict[str, BondMethod]:
    """Every bond method, built-in first, then the plugins (a plugin cannot replace a
    built-in name, nor a scene's parameter: it is listed as broken instead)."""
    global _METHODS
    if _METHODS is None:
        methods = {m.name: m for m in _builtin()}
        _METHODS = dict(methods)  # the scenes, loaded to check the plugins, see these
        for m in _plugins():
            if m.name in methods:
                BROKEN[m.name] = f"{m.origin}: the name {m.name!r} is taken"
                continue
            clash = _scene_param_clash(m)
            if clash:
                BROKEN[m.name] = f"{m.origin}: {clash}"
                continue
            methods[m.name] = m
        _METHODS = methods
    return _METHODS


def broken_method(name: str) -> str | None:
    """Why the plugin method ``name`` is not available, if it is a broken plugin."""
    bond_methods()
    return BROKEN.get(name)


def reload() -> None:
    """Forget the loaded plugins (tests install one and look again)."""
    global _METHODS
    _METHODS = None
    BROKEN.clear()
