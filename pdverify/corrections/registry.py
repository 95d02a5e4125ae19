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

A plugin never stops pdverify. Every call into plugin code (its import, its closure, the
functions that closure hands the model, its ``assemble`` and ``check``, its parameters'
checks) catches any exception, ``SystemExit`` included (only ``KeyboardInterrupt``, the
user's own stop, passes):

- a plugin that fails to load, whose entry point is not a well-formed
  :class:`~pdverify.corrections.treatment.Treatment`, whose parameter's default fails its
  own check, or whose parameter shares a name with a parameter of a scene it serves (it
  would replace that scene's default), is listed as broken with its error (``list``:
  ``plugin NAME: failed to load (SystemExit(3) at import)``) and left out of reports;
  the built-in methods run as before, and ``run --method NAME`` on a scene that takes
  bond methods is a failed run giving that error;
- a plugin whose code raises during a run (``SystemExit(0)`` in its closure included)
  makes that run a failed run whose message names the plugin and what it did.

A method whose optional dependency is missing says so in ``unavailable`` (the install
command), and a run of it is refused as bad input.
"""
from __future__ import annotations

import difflib
import functools
from dataclasses import dataclass, fields, replace
from typing import Any, Callable, Mapping

from ..errors import InputError, NumericalError
from ..params import Param
from ..pd.closure import Closure
from .protocols import BondClosure, ParamCheck
from .treatment import ENTRY_POINT_GROUP, THEORIES, Treatment  # noqa: F401  (re-exported)


@dataclass(frozen=True)
class BondMethod(Treatment):
    """A correction that acts through the closure of a plain grid's model.

    ``closure(params) -> Closure`` builds it from the method's resolved ``params``; the
    boundary conditions are imposed as the uncorrected model imposes them (``none``).
    """

    closure: BondClosure | None = None
    families: tuple[str, ...] = ("static-state",)
    #: a closure changes bonds only; the uncorrected model's conditions serve any shape
    shapes: bool = True
    #: ``checker(cells, params, where)``: refuses parameters before any work
    checker: ParamCheck | None = None

    def check(self, cells, params, where):
        if self.checker is not None:
            self.checker(cells, params, where)

    @property
    def kind(self) -> str:
        return "closure"

    def _why_not_kind(self, scene) -> str | None:
        if getattr(scene, "closure_theory", None) is not None:
            return None
        return super()._why_not_kind(scene)

    def make_closure(self, params: Mapping) -> Closure:
        """The closure for ``params``; a plugin's is guarded (see the module docstring)."""
        if self.origin == "built-in":
            return self.closure(params)
        return _plugin_closure(self, params)

    def assemble(self, problem, params: Mapping[str, Any]):
        from .plain import assemble_plain
        return assemble_plain(problem, self.make_closure(params))


#: the seed-004 bars, where the end-bond factors are derived
SEED004_BARS = ("bar1d-homogenization", "bar1d-constraints", "bar1d-vibration")


def _builtin() -> list[Treatment]:
    from .builtin import family_treatments, hand_wired
    from .energy import energy_closure
    from .energy_directional import energy_directional_closure
    from .pals import pals_closure
    from .perifit_weights import INSTALL, SCENES, installed_version, perifit_closure
    from .volume import volume_closure
    pv = installed_version()
    from .homogenized import check_homogenized, homogenized_closure
    from .peer import peer_treatments
    return family_treatments() + [
        BondMethod("homogenized", "seed 004: stiffness factors on the end bonds (1, 1+k), "
                   "(N, N-k) so that a linear field satisfies every equilibrium equation "
                   "(1D bond-based)", "Eriksson, Stenström 2020 (seed 004)",
                   closure=homogenized_closure, checker=check_homogenized,
                   theories=("bond-based",), dims=(1,), scenes=SEED004_BARS,
                   scope="1D bond-based bars only (seed 004 derives its factors for the "
                         "triangular micromodulus in 1D)")] + hand_wired() + [
        BondMethod("energy", "Le and Bobaru 2018 energy correction: per axis the ratio of a "
                   "complete to the node's uniaxial-stretch energy, bonds by the ellipse of "
                   "their ends' mean factors, applied to the bond force",
                   "Le and Bobaru, Comput. Mech. 61 (2018) 499-518; Peridynamics.jl",
                   closure=energy_closure),
        BondMethod("energy-directional", "seed 003: bond stiffness times (phi(x, e) + "
                   "phi(x', -e))/2, phi the Eq. (14) ratio of the horizon's radial integral "
                   "to its truncated part along the bond direction, on the scene's box "
                   "(bond-based; the seed-003 scenes wire it to their own boxes)",
                   "Ritter, Wohlmuth et al. (seed 003), Eqs. 2, 12-14",
                   closure=energy_directional_closure, theories=("bond-based",),
                   scope="bond-based box scenes (Eq. 14's ratio with xi^D: the paper's 2D, "
                         "our 1D and 3D)"),
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
    ] + peer_treatments()


_METHODS: dict[str, Treatment] | None = None
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


_CALLABLE_FIELDS = ("keep", "bond_factor", "geometric_factor", "weight_factor", "force_factor")


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


def _as_builtin_type(item, origin: str) -> Treatment:
    """The plugin's treatment with its origin set and its fields checked: a
    :class:`BondMethod` is rebuilt as a plain one with the plugin's data (so that only
    pdverify's own methods run on it, its closure guarded); any other
    :class:`~pdverify.corrections.treatment.Treatment` keeps its class (its ``assemble``
    and ``check`` are the plugin's, called through :func:`plugin_call`)."""
    if not isinstance(item, Treatment):
        raise TypeError(f"{type(item).__name__} is not a pdverify Treatment")
    base = BondMethod if isinstance(item, BondMethod) else type(item)
    data = {f.name: getattr(item, f.name) for f in fields(base)}
    if not (isinstance(data["name"], str) and data["name"] and data["name"].isprintable()
            and " " not in data["name"]):
        raise TypeError(f"method name {data['name']!r} must be a non-empty word")
    for key in ("description", "source"):
        if not isinstance(data[key], str):
            raise TypeError(f"{key} must be a string")
    if base is BondMethod and not callable(data["closure"]):
        raise TypeError("closure is not callable")
    who = f"plugin method {data['name']} ({origin})"
    data.update(origin=f"plugin {origin}", params=tuple(_checked_param(p, who)
                                                        for p in tuple(data["params"])),
                theories=tuple(data["theories"]), dims=tuple(int(d) for d in data["dims"]),
                families=tuple(map(str, data["families"])),
                scenes=None if data["scenes"] is None else tuple(map(str, data["scenes"])),
                unavailable=None if data["unavailable"] is None else str(data["unavailable"]))
    return base(**data)


def plugin_call(treatment: Treatment, what: str, fn, *args):
    """``fn(*args)`` of ``treatment``; guarded when the treatment is a plugin's (a raise
    or exit becomes a failed run naming it; bad input stays bad input)."""
    if treatment.origin == "built-in":
        return fn(*args)
    who = f"plugin method {treatment.name} ({treatment.origin.removeprefix('plugin ')})"
    error = InputError if what == "check" else PluginError
    return _guard(fn, who, f"its {what}", error=error)(*args)


def _plugins():
    """Every plugin's treatments; a load that raises anything but KeyboardInterrupt,
    ``SystemExit`` at import included, is listed in :data:`BROKEN`."""
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


#: the registered scenes, set by ``pdverify.scenes`` when it loads (the registry sits
#: below the scenes and does not import them): the plugins' parameters are checked
#: against those of the scenes they serve
SCENES: Callable[[], list] | None = None


def _scene_param_clash(method: Treatment) -> str | None:
    """The first parameter of ``method`` named like a parameter of a scene it serves (its
    own or those of that scene's ``none``, which a bond method takes), as a phrase."""
    mine = {p.name for p in method.params}
    for scene in (SCENES() if SCENES is not None else ()):
        try:
            served = method.serves(scene)
        except KeyboardInterrupt:
            raise
        except BaseException as exc:
            return f"deciding whether it serves {scene.id} raised {what_it_did(exc)}"
        if not served:
            continue
        taken = mine & {p.name for p in tuple(scene.params) + scene.baseline_spec().params}
        if taken:
            return (f"its parameter {sorted(taken)[0]!r} is a parameter of scene {scene.id} "
                    "(it would replace the scene's value); rename it")
        for q in method.params:    # a scene default it takes must be one it allows
            if q.scene_default and q.name in getattr(scene, "treatment_defaults", {}):
                try:
                    q.convert(scene.treatment_defaults[q.name], f"scene {scene.id}'s default")
                except InputError as exc:
                    return str(exc)
    return None


def treatments() -> dict[str, Treatment]:
    """Every treatment, built-in first, then the plugins (a plugin cannot replace a
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


def bond_methods() -> dict[str, BondMethod]:
    """The closure treatments (:class:`BondMethod`) among :func:`treatments`."""
    return {k: m for k, m in treatments().items() if isinstance(m, BondMethod)}


def broken_method(name: str) -> str | None:
    """Why the plugin method ``name`` is not available, if it is a broken plugin."""
    treatments()
    return BROKEN.get(name)


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
