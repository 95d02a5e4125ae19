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

A plugin never stops or stalls pdverify (issue 31, issue 50; the mechanics are in
:mod:`~pdverify.corrections.containment`). Every call into plugin code is contained and
under the plugin time limit (``$PDVERIFY_PLUGIN_TIMEOUT``, default 60 s):

- the entry points are loaded first in a child process (import, conversion, the answers
  of a plugin class's ``why_not``/``params_for``/``kind`` for every scene, its parameters'
  defaults checked); one that raises, exits, signals itself or does not return there is
  listed as broken (``list``: ``plugin NAME: failed to load (ENTRY POINT: ...)``), never
  imported here, and left out of reports; so is one whose entry point is not a
  well-formed :class:`~pdverify.corrections.treatment.Treatment` or whose parameter
  shares a name with a parameter of a scene it serves (it would replace that scene's
  default). ``run --method NAME`` of it gives that error;
- a plugin's own class is held as a :class:`PluginTreatment` (its answers from the
  load), so pdverify calls no plugin code but its checks, closure and assembly;
- its checks (treatment, role, parameters) run in a child process
  (:func:`contained_check`): a refusal is bad input; anything else is a
  :class:`PluginCheckError` naming the plugin (``run``: exit 2; a report fails that case);
- its closure, the functions that closure hands the model, its ``assemble`` and roles run
  in a run's worker process (``run`` of a plugin method goes to one too): a raise or
  ``SystemExit`` is a failed run naming the plugin and what it did; an exit, a signal or
  a call past the limit ends the worker, and the supervisor records a failed run naming
  the plugin call (:mod:`pdverify.runner`).

A method whose optional dependency is missing says so in ``unavailable`` (the install
command), and a run of it is refused as bad input.
"""
from __future__ import annotations

import difflib
import functools
from dataclasses import dataclass, field, fields, replace
from typing import Any, Callable, Mapping

from ..errors import InputError, NumericalError
from . import containment
from .containment import what_it_did  # noqa: F401  (re-exported)
from ..params import Param
from ..pd.closure import Closure
from .protocols import BondClosure, ParamCheck
from .treatment import ENTRY_POINT_GROUP, Treatment


@dataclass(frozen=True)
class BondMethod(Treatment):
    """A correction that acts through the closure of a plain grid's model.

    ``closure(params) -> Closure`` builds it from the method's resolved ``params``; the
    boundary conditions are imposed as the uncorrected model imposes them (``none``).
    """

    closure: BondClosure | None = None
    families: tuple[str, ...] = ("static-state",)
    #: a closure changes bonds only; the uncorrected model's conditions serve any shape,
    #: 2D or 3D (``assemble_plain`` is the same in both)
    shapes: bool = True
    shapes3d: bool = True
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
                   "to its truncated part along the bond direction, the ray run to the "
                   "scene's box or, on a shape, to the first of its parts it meets, crack "
                   "faces included (bond-based; the seed-003 scenes wire it to their own "
                   "boxes)",
                   "Ritter, Wohlmuth et al. (seed 003), Eqs. 2, 12-14",
                   closure=energy_directional_closure,
                   scope="box and shape scenes (Eq. 14's ratio with xi^D: the paper's 2D, "
                         "our 1D and 3D; on a shape the ray distance to the first part the "
                         "ray meets, pdverify/pd/rays.py; state-based, our reading: the "
                         "factor on each bond's influence, so in m, the dilatation and the "
                         "force state, with xi^(D+1))"),
        BondMethod("volume", "volume correction 2 V0 / (V_i + V_j) on the bond force (V the "
                   "discrete horizon volume of each end)",
                   "Le and Bobaru 2018; PeriLab, PeriPy, pypd", closure=volume_closure),
        BondMethod("pals", "position-aware linear solid: per-node dilatation and deviatoric "
                   "influence functions from the matching deformations (Lagrange "
                   "multipliers); constraints as the uncorrected model imposes them",
                   "Mitchell, Silling and Littlewood, J. Mech. Mater. Struct. 10 (2015) "
                   "539-557; seed 001 §5.1; Peridigm pals.cxx", closure=pals_closure,
                   theories=("state-based",), dims=(2, 3),
                   theory_refusal="a state-based constitutive model (its influence "
                                  "functions weigh the dilatation and the deviatoric "
                                  "extension); a bond-based model has neither term, so "
                                  "there is nothing for them to weigh",
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


def _guard(fn, who: str, what: str, error=PluginError):
    """``fn`` wrapped so that anything it raises except ``KeyboardInterrupt`` (and the
    engine's own :class:`NumericalError` raised through it) becomes ``error`` naming
    ``who`` (the plugin) and ``what`` (which of its functions)."""
    @functools.wraps(fn)
    def guarded(*args, **kwargs):
        mark = containment.watching(f"{who}: {what}")
        try:
            return fn(*args, **kwargs)
        except KeyboardInterrupt:
            raise
        except NumericalError:
            raise
        except BaseException as exc:  # SystemExit included: a plugin never ends pdverify
            raise error(f"{who}: {what} raised {what_it_did(exc)}") from None
        finally:
            containment.unwatch(mark)
    return guarded


class PluginCheckError(InputError):
    """A plugin's check (of its treatment or of a parameter) raised something other than
    a refusal, ended its process or did not return: the plugin's failure, not the user's
    input. ``run`` records it as a failed run naming the plugin; a report's case of that
    plugin fails, the other cases go on."""


#: outcomes of contained checks by (who, what, arguments): a check is a function of its
#: arguments, and one that hung is not waited for twice
_CHECKED: dict[tuple, tuple] = {}


def contained_check(fn, who: str, what: str, *args):
    """``fn(*args)``, a plugin's check, run in a child process under the plugin time limit
    (:mod:`~pdverify.corrections.containment`): its refusal (``InputError``) is bad input
    as it wrote it; anything else it does is a :class:`PluginCheckError` naming ``who``."""
    try:
        key = (who, what, repr(args))
    except Exception:  # an argument whose repr fails: not cached
        key = None
    outcome = _CHECKED.get(key) if key is not None else None
    if outcome is None:
        outcome = containment.in_child(fn, args)
        if key is not None:
            _CHECKED[key] = outcome
    if outcome[0] == "ok":
        return outcome[1]
    if outcome[0] == "raised":
        if outcome[1]:
            raise InputError(outcome[3])
        raise PluginCheckError(f"{who}: {what} raised {outcome[2]}")
    if outcome[0] == "ended":
        raise PluginCheckError(f"{who}: {what} ended its process ({outcome[1]})")
    raise PluginCheckError(f"{who}: {what} did not return within {outcome[1]:g} s (the "
                           f"plugin time limit, ${containment.ENV}); its process was killed")


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


def _checked_param(p: Param, who: str, check_default: bool = True) -> Param:
    """A plugin's parameter whose check is contained (:func:`contained_check`); its
    default must pass it (else the plugin is broken; checked in the load's child process,
    ``check_default`` False in pdverify's own)."""
    if not isinstance(p, Param):
        raise TypeError(f"params holds {type(p).__name__}, not a pdverify Param")
    if not isinstance(p.name, str) or not p.name.isidentifier():
        raise TypeError(f"parameter name {p.name!r} is not an identifier")
    if p.check is None or isinstance(p.check, functools.partial) and \
            p.check.func is contained_check:
        return p
    problem = (_guard(p.check, who, f"the check of its parameter {p.name}")(p.default)
               if check_default else None)
    guarded = functools.partial(contained_check, p.check, who,
                                f"the check of its parameter {p.name}")
    if problem:
        raise ValueError(f"the default {p.name}={p.default!r} fails its own check ({problem})")
    return replace(p, check=guarded)


def _as_builtin_type(item, origin: str, probed=None) -> Treatment:
    """The plugin's treatment with its origin set and its fields checked, rebuilt as one
    of pdverify's own classes so that only pdverify's methods run on it: a
    :class:`BondMethod` as a plain one with the plugin's data (its closure guarded); any
    other :class:`~pdverify.corrections.treatment.Treatment` as a :class:`PluginTreatment`
    that holds what the plugin's own methods answered once, at load, for every scene
    (``params_for``, ``why_not``, ``kind``), and calls the plugin only for ``check`` and
    ``assemble`` (through :func:`plugin_call`).

    ``probed``: None in the load's child process (the plugin's methods are asked and its
    parameters' defaults checked there); in pdverify's own process, what the child
    answered (:func:`_answers`), so that no plugin method is called here."""
    if not isinstance(item, Treatment):
        raise TypeError(f"{type(item).__name__} is not a pdverify Treatment")
    bond = isinstance(item, BondMethod)
    base = BondMethod if bond else Treatment
    data = {f.name: getattr(item, f.name) for f in fields(base)}
    if not (isinstance(data["name"], str) and data["name"] and data["name"].isprintable()
            and " " not in data["name"]):
        raise TypeError(f"method name {data['name']!r} must be a non-empty word")
    for key in ("description", "source", "scope", "box_only"):
        if not isinstance(data[key], str):
            raise TypeError(f"{key} must be a string")
    if bond and not callable(data["closure"]):
        raise TypeError("closure is not callable")
    who = f"plugin method {data['name']} ({origin})"
    fresh = probed is None
    roles = tuple((str(f), r) for f, r in data["roles"])
    data.update(origin=f"plugin {origin}",
                params=tuple(_checked_param(p, who, fresh) for p in tuple(data["params"])),
                theories=tuple(data["theories"]), dims=tuple(int(d) for d in data["dims"]),
                families=tuple(map(str, data["families"])),
                scenes=None if data["scenes"] is None else tuple(map(str, data["scenes"])),
                unavailable=None if data["unavailable"] is None else str(data["unavailable"]),
                roles=roles)
    if bond:
        return BondMethod(**data)
    if not fresh:
        kind, coded = probed
        role_params = {f: tuple(_checked_param(p, who, False) for p in tuple(r.params))
                       for f, r in roles}
        answers = {sid: (why, data["params"] if code == "own" else
                         role_params[code[1]] if isinstance(code, tuple) and code
                         and code[0] == "role" else code)
                   for sid, (why, code) in coded.items()}
        return PluginTreatment(**data, plugin=item, plugin_kind=kind, answers=answers,
                               coded=coded)
    kind = item.kind
    if kind not in ("family", "hand-wired"):
        raise TypeError(f"kind {kind!r} is not family or hand-wired")
    own = tuple(item.params)
    answers, coded = {}, {}
    for scene in (SCENES() if SCENES is not None else ()):
        why = item.why_not(scene)
        if why is not None and not isinstance(why, str):
            raise TypeError(f"why_not({scene.id}) returned {type(why).__name__}, not a "
                            "string or None")
        raw = tuple(item.params_for(scene))
        params = tuple(_checked_param(p, who) for p in raw)
        answers[scene.id] = (why, params)
        # how the parent finds the same parameters without calling the plugin
        code = ("own" if raw == own else
                next((("role", f) for f, r in roles if raw == tuple(r.params)), params))
        coded[scene.id] = (why, code)
    return PluginTreatment(**data, plugin=item, plugin_kind=kind, answers=answers,
                           coded=coded)


def _answers(methods) -> list:
    """What the load's child hands back of an entry point's treatments: for each, None
    (a bond method: nothing to ask) or its kind and coded answers."""
    return [None if isinstance(m, BondMethod) else (m.plugin_kind, m.coded) for m in methods]


@dataclass(frozen=True)
class PluginTreatment(Treatment):
    """A plugin's treatment of its own class, as pdverify holds it (:func:`_as_builtin_type`):
    where it applies and its parameters as the plugin answered at load; its ``check``,
    ``assemble`` and roles call the plugin's object, guarded."""

    plugin: Any = field(default=None, compare=False)
    plugin_kind: str = "hand-wired"
    #: scene id -> (why_not, params_for) as the plugin answered at load
    answers: Mapping[str, tuple] = field(default=None, compare=False)
    #: the same, as the load's child process hands it back (params_for: ``"own"``,
    #: ``("role", family)`` or the parameters)
    coded: Mapping[str, tuple] = field(default=None, compare=False, repr=False)

    @property
    def kind(self) -> str:
        return self.plugin_kind

    def why_not(self, scene) -> str | None:
        answer = self.answers.get(scene.id)
        return ("not offered (the plugin was loaded before this scene)" if answer is None
                else answer[0])

    def params_for(self, scene) -> tuple[Param, ...]:
        answer = self.answers.get(scene.id)
        return self.params if answer is None else answer[1]

    def check(self, cells, params, where):
        return self.plugin.check(cells, params, where)

    def assemble(self, problem, params):
        return self.plugin.assemble(problem, params)

    def build_for(self, family, problem, params):
        return plugin_call(self, f"role in {family}",
                           lambda *a: self.plugin.build_for(*a), family, problem, params)

    def check_for(self, family, context, params, where):
        role = self.role(family)
        if role is None or role.checker is None:
            return None
        who = f"plugin method {self.name} ({self.origin.removeprefix('plugin ')})"
        return contained_check(lambda *a: self.plugin.check_for(*a), who, "its check",
                               family, context, params, where)


def plugin_call(treatment: Treatment, what: str, fn, *args):
    """``fn(*args)`` of ``treatment``; guarded when the treatment is a plugin's: its
    ``check`` runs in a child process under the plugin time limit (a refusal stays bad
    input; anything else is a :class:`PluginCheckError` naming it); its other calls run
    guarded in the run's worker process, whose supervisor enforces the limit and names
    the plugin if the process ends inside it (:mod:`pdverify.runner`)."""
    if treatment.origin == "built-in":
        return fn(*args)
    who = f"plugin method {treatment.name} ({treatment.origin.removeprefix('plugin ')})"
    if what == "check":
        if not _has_check(treatment):   # pdverify's own no-op: no child process
            return None
        return contained_check(fn, who, f"its {what}", *args)
    return _guard(fn, who, f"its {what}")(*args)


def _has_check(t: Treatment) -> bool:
    """Whether the ``check`` of the plugin treatment ``t`` runs plugin code."""
    if isinstance(t, BondMethod):
        return t.checker is not None
    if isinstance(t, PluginTreatment):
        return type(t.plugin).check is not Treatment.check
    return True


def _load(ep, probed=None) -> tuple[list, str | None]:
    """The treatments of entry point ``ep`` and, when it is broken, why (one phrase).
    ``probed``: what the load's child answered for its treatments (:func:`_answers`);
    None in that child."""
    try:
        obj = ep.load()
    except KeyboardInterrupt:
        raise
    except BaseException as exc:  # a broken plugin never stops pdverify
        return [], f"{ep.value}: {what_it_did(exc)} at import"
    try:
        items = obj if isinstance(obj, (list, tuple)) else [obj]
        if probed is not None and len(probed) != len(items):
            return [], f"{ep.value}: loads differently in another process"
        methods = [_as_builtin_type(item, ep.value, None if probed is None else probed[i])
                   for i, item in enumerate(items)]
        for m in methods:
            clash = _scene_param_clash(m)
            if clash:
                return [], f"{m.origin}: {clash}"
    except KeyboardInterrupt:
        raise
    except BaseException as exc:
        return [], f"{ep.value}: {what_it_did(exc)}"
    return methods, None


def _probe_one(ep):
    """In the load's child process: ``("problem", phrase)`` or ``("ok", answers)``."""
    methods, problem = _load(ep)
    return ("problem", problem) if problem is not None else ("ok", _answers(methods))


def _plugins():
    """Every plugin's treatments. The entry points are first loaded in a child process
    (:func:`~pdverify.corrections.containment.probe`: import, conversion, the answers of
    its methods, under the plugin time limit); one that raises, ends that process or
    does not return is listed in :data:`BROKEN` with its entry point and never imported
    here; the others are then imported here and take the child's answers."""
    from importlib.metadata import entry_points
    try:
        eps = list(entry_points(group=ENTRY_POINT_GROUP))
    except KeyboardInterrupt:
        raise
    except BaseException as exc:  # broken metadata of some installed distribution
        BROKEN["(entry points)"] = f"{what_it_did(exc)} while listing the entry points"
        return
    if not eps:
        return
    if SCENES is None:
        # the plugins' answers are asked of every scene: a first call that comes before
        # anything imported the scenes would otherwise load them with no scene to answer
        # for (and every scene would say the plugin was loaded before it)
        import importlib
        importlib.import_module(__name__.rsplit(".", 2)[0] + ".scenes")
    # what the child's answers read of every scene, its own methods (the FEM-referenced
    # scenes import their reference modules), loaded here first: the child inherits it
    # and this process keeps it (else both would import them)
    for scene in (SCENES() if SCENES is not None else ()):
        scene.methods
    answers, failures = containment.probe(len(eps), lambda k: _probe_one(eps[k]))
    for k, ep in enumerate(eps):
        if k in failures:
            BROKEN[ep.name] = f"{ep.value}: {failures[k]} while loading"
            continue
        status, payload = answers.get(k, ("problem", f"{ep.value}: no answer"))
        if status != "ok":
            BROKEN[ep.name] = payload if ep.value in payload else f"{ep.value}: {payload}"
            continue
        methods, problem = _load(ep, payload)
        if problem is not None:
            BROKEN[ep.name] = problem
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
    _CHECKED.clear()


def from_name(name: str) -> Treatment:
    """The registered treatment ``name``; unknown names are bad input with the close
    matches and the full list."""
    known = treatments()
    if name in known:
        return known[name]
    close = difflib.get_close_matches(name, list(known), n=3)
    hint = f"; did you mean {' or '.join(close)}?" if close else ""
    raise InputError(f"unknown method {name!r}{hint} (allowed: {', '.join(known)})")
