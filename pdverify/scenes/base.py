"""The scene contract: parameters, supported methods, run, and the report's cases."""
from __future__ import annotations

import traceback
from dataclasses import dataclass, field, replace
from typing import Any, Mapping

import numpy as np

from .. import blas, budget
from ..errors import InputError, NumericalError, did_you_mean
from ..params import Param, resolve
from ..pd.closure import Closure
from ..pd.influence import INFLUENCES
from ..results import RunResult, Timer, collecting_notes
from ..solvers.iterative import solver_error_warnings


def what_it_did(exc: BaseException) -> str:
    from ..corrections.registry import what_it_did as phrase
    return phrase(exc)


def conditioning_warnings(diagnostics: Mapping) -> list[str]:
    """One warning for the worst ``*condition_estimate`` in ``diagnostics`` (nested
    included) above :data:`~pdverify.solvers.policy.WARN_CONDITION`."""
    from ..solvers.policy import WARN_CONDITION

    def walk(d, path):
        for k, v in d.items():
            if isinstance(v, Mapping):
                yield from walk(v, path + (k,))
            elif k.endswith("condition_estimate") and isinstance(v, (int, float)):
                yield float(v), ".".join(path + (k,))

    worst = max(walk(diagnostics, ()), default=(0.0, ""))
    if worst[0] <= WARN_CONDITION:
        return []
    eps = float(np.finfo(float).eps)
    return [f"ill-conditioned: {worst[1]} = {worst[0]:.2e}, so the solution is trustworthy "
            f"only to ~{worst[0] * eps:.0e} relative (condition x machine epsilon); errors "
            "below that are round-off, not the method"]


@dataclass(frozen=True)
class Discretisation:
    """A run's grid as every scene states it: the grid spacing ``h`` (Delta) and the
    horizon ``delta``, both in metres (:meth:`Scene.discretisation`), whatever the
    scene's own parameters are called (spacing, horizon, m_ratio, side_factor, nodes,
    horizon_ratio: the papers' and the command line's names).

    ``relative``: (Delta / L, delta / L) for a scene whose size L is itself stated as a
    multiple of delta (sheet2d-clamped: L = side_factor x delta), computed from its
    relative parameters as the scene states them; None for a body of fixed size."""

    h: float
    delta: float
    relative: tuple[float, float] | None = None

    @property
    def m(self) -> float:
        """The m-ratio delta / Delta."""
        return self.delta / self.h


@dataclass(frozen=True)
class MethodSpec:
    """A method as a scene offers it: its name and the parameters it takes there."""

    name: str
    params: tuple[Param, ...] = ()


def influence_param(default: str, source: str) -> Param:
    """The ``influence`` parameter of a state-based scene: any registered influence function
    (``pdverify.pd.influence``), the paper's as the default."""
    return Param("influence", default, f"influence function omega ({source}); any registered: "
                 + ", ".join(f"{k} = {v.description}" for k, v in sorted(INFLUENCES.items())),
                 choices=tuple(sorted(INFLUENCES)))


def require_influence(scene_id: str, method: str, p: dict, allowed: str, why: str) -> None:
    """Refuse (one line, exit 2) an ``influence`` the scene's reference is not derived for."""
    if p["influence"] != allowed:
        raise InputError(f"{scene_id} --method {method}: influence={p['influence']} is not "
                         f"supported here; allowed: {allowed} ({why})")


#: more cells than this along one axis are refused before any other check: beyond 2^53 a
#: double no longer tells whole numbers apart, and no such grid fits any memory
MAX_CELLS_PER_AXIS = 1e15


def cell_count(where: str, spacing: float, name: str, length: float,
               label: str = "spacing") -> float:
    """length / spacing, refused (one line, exit 2) when it is not a finite count of at most
    :data:`MAX_CELLS_PER_AXIS` (a subnormal spacing or a huge length overflows it)."""
    n = length / spacing
    if not n <= MAX_CELLS_PER_AXIS:      # inf, and NaN from 0/0, too
        raise InputError(f"{where}: {label}={spacing:g} and {name}={length:g} give "
                         f"{name}/{label} = {n:g} cells; allowed: at most "
                         f"{MAX_CELLS_PER_AXIS:.0e} cells along an axis")
    return n


def whole_cells(where: str, spacing: float, lengths, label: str = "spacing") -> list[int]:
    """Cells along each of ``lengths`` ((name, L) pairs); refuse (one line, exit 2) a
    ``spacing`` that does not divide every L into a whole number (>= 2) of cells."""
    counts = []
    for name, L in lengths:
        n = cell_count(where, spacing, name, L, label)
        if abs(n - round(n)) > 1e-9 * max(n, 1.0) or round(n) < 2:
            raise InputError(f"{where}: {label}={spacing:g} must divide {name}={L:g} into a "
                             "whole number (>= 2) of cells")
        counts.append(int(round(n)))
    return counts


#: the strains a linear scene's load may cause: at least 5e-314 = 1e10 x the spacing of the
#: subnormal doubles (4.9e-324), so that the displacements keep 10 significant digits
#: (force=1e-320 gave strains of 1e-327: every displacement 0). Large strains stay
#: allowed: the model is linear and a load scaled by 1e300 gives the default metrics, and
#: what overflows beyond is a failed run naming it (tests/reliability/test_hard_numerics.py:
#: E = 1e-300 under the default force is a near-singular failed run, not bad input).
STRAIN_RANGE = (5e-314, float("inf"))


def check_load_scale(where: str, name: str, value: float, per_unit_strain: float) -> None:
    """Refuse (one line, exit 2) a load ``name`` whose strain ``value / per_unit_strain``
    lies below :data:`STRAIN_RANGE`, naming the smallest load allowed;
    ``per_unit_strain``: the load that causes a unit strain (E A for an end force).
    Zero is left to the scene (it has its own reason to refuse it)."""
    lo, hi = STRAIN_RANGE
    if value == 0 or lo * per_unit_strain <= abs(value) <= hi * per_unit_strain:
        return
    raise InputError(f"{where}: {name}={value:.3g} is below the smallest |{name}| allowed, "
                     f"{lo * per_unit_strain:.3g}: the load of a strain of {lo:.3g} (below, "
                     "the displacements keep fewer than 10 digits in a double)")


#: a series or iterative reference's own truncation error must stay below this share of
#: every error it is used to measure (issue 31): else the "error" is partly the
#: reference's, and the run fails saying so
TRUNCATION_SHARE = 1e-3


def truncation_problem(what: str, estimate: float, errors: Mapping[str, float],
                       hint: str) -> str | None:
    """None when the reference's truncation ``estimate`` is below :data:`TRUNCATION_SHARE`
    of each of ``errors`` (metric name -> the error, in the estimate's unit), else the
    one-line reason for a failed run (``what``: the reference and its setting, ``hint``:
    how to make it finer)."""
    for name, err in errors.items():
        if not estimate < TRUNCATION_SHARE * abs(err):
            return (f"{what}: its truncation error estimate {estimate:.3g} is not below "
                    f"{TRUNCATION_SHARE:g} of the {name} {abs(err):.4g} it measures, so that "
                    f"error is partly the reference's own; {hint}")
    return None


@dataclass
class Outcome:
    """What a scene's ``solve`` returns: numbers for JSON and arrays for figures."""

    metrics: dict
    size: dict = field(default_factory=dict)
    fields: dict = field(default_factory=dict)
    diagnostics: dict = field(default_factory=dict)


def _applies(method_of, where, method: str, params: Mapping[str, Any]) -> bool:
    """A method (None: any) and a subset of the params (None: any) match a run."""
    if method_of is not None and method_of != method:
        return False
    return all(params.get(k) == v for k, v in (where or {}).items())


@dataclass(frozen=True)
class Published:
    """A number a paper prints (or that is read off a figure), for the report's 'paper'
    column and the ``published`` entries of a results file (:mod:`pdverify.published`).

    ``value`` as printed (a number, a fraction "3/2", a bound "< 1", or words); ``kind``
    ``printed`` or ``read off a figure``. The check: a decimal is equal within half a unit
    in its last printed digit unless ``tolerance`` (with ``tolerance_source``) says
    otherwise; ``exact`` values (fractions, closed forms) to round-off; ``bound`` turns
    words ("machine precision", "non-zero") into a bound (``check``: ``below`` or
    ``above``), named in ``tolerance_source``. ``deviation``: the key of the
    :mod:`pdverify.deviations` entry that explains why ours differs; the check then uses
    ``expected`` (the value that deviation predicts) or, without it, is a known
    difference (shown, not failed)."""

    metric: str
    value: Any
    source: str
    method: str | None = None
    where: Mapping[str, Any] | None = None
    kind: str = "printed"
    tolerance: float | None = None
    tolerance_source: str = ""
    exact: bool = False
    bound: float | None = None
    check: str | None = None
    deviation: str = ""
    expected: float | None = None
    note: str = ""
    #: what the entry is (:data:`pdverify.published.ROLES`): ``value`` (a number the paper
    #: computes: reproduced or not), ``setup`` (a number the paper states about its setup,
    #: which the scene sets itself: checked, never counted as a reproduced number) or
    #: ``claim`` (a statement in words or a bound); empty: ``claim`` for words and bounds,
    #: else ``value``
    role: str = ""
    #: a known difference (``deviation`` without ``expected``): the value WE reproduce, as
    #: ``(where, text, source)`` triples (the first whose ``where`` matches the run's
    #: params; ``{}`` matches any), each checked within half a unit in its last digit
    #: (:func:`pdverify.published.parse`): ours must stay there, or the entry fails.
    #: ``source`` names where the number comes from (a deviation's text, a test, or "ours,
    #: recorded from the full report of commit C" where nothing else states it)
    reproduced: tuple = ()

    def applies(self, method: str, params: Mapping[str, Any]) -> bool:
        return _applies(self.method, self.where, method, params)

    @property
    def entry_role(self) -> str:
        from .. import published as pub
        if self.role:
            if self.role not in pub.ROLES:
                raise ValueError(f"{self.source}: role={self.role!r}; allowed: "
                                 f"{', '.join(pub.ROLES)}")
            return self.role
        check, _, _ = pub.parse(self.value)
        return "claim" if (self.bound is not None or check != "equal") else "value"

    def reproduced_for(self, params: Mapping[str, Any] | None):
        """(value, tolerance, source) of :attr:`reproduced` for a run's ``params``, or None."""
        from .. import published as pub
        for where, text, source in self.reproduced:
            if params is None or all(params.get(k) == v for k, v in where.items()):
                check, number, tol = pub.parse(text)
                if check != "equal" or tol is None:
                    raise ValueError(f"{self.source}: reproduced {text!r} is not a decimal")
                return number, tol, source
        return None

    def entry(self, params: Mapping[str, Any] | None = None) -> dict:
        """The run record's ``published`` entry (:mod:`pdverify.published`) for a run of
        ``params`` (None: the first :attr:`reproduced` value)."""
        from .. import published as pub
        check, number, tol = pub.parse(self.value)
        source = pub.DIGITS_SOURCE if check == "equal" else pub.BOUND_SOURCE
        if self.bound is not None:
            check, number, tol = self.check or "below", float(self.bound), 0.0
            source = self.tolerance_source or pub.BOUND_SOURCE
        if self.expected is not None:
            number = float(self.expected)
        if self.exact:
            tol, source = pub.exact_tolerance(number), pub.EXACT_SOURCE
        if self.tolerance is not None:
            tol, source = float(self.tolerance), self.tolerance_source
        if check == pub.NO_CHECK:
            number, tol, source = None, None, "a statement without a number: shown, not checked"
        elif tol is None:
            raise ValueError(f"{self.source}: {self.value!r} is exact; say exact=True")
        value = self.value if isinstance(self.value, (str, int, float)) else str(self.value)
        out = {"metric": self.metric, "value": value, "source": self.source,
               "kind": self.kind, "check": check, "target": number, "tolerance": tol,
               "tolerance_source": source}
        if self.deviation:
            out["deviation"] = self.deviation
            out["known_difference"] = self.expected is None
            mine = self.reproduced_for(params) if self.expected is None else None
            if mine is not None:
                out["reproduced"], out["reproduced_tolerance"], out["reproduced_source"] = mine
        if self.note:
            out["note"] = self.note
        out["role"] = self.entry_role
        return out


@dataclass(frozen=True)
class ExpectedFailure:
    """A documented finding that makes a run fail (the paper's own failure, a collapse
    the paper predicts): the run's failure is expected, shown as such and not counted in
    the exit code; if the run stops failing, that is reported (strict)."""

    reason: str
    method: str | None = None
    where: Mapping[str, Any] | None = None

    def applies(self, method: str, params: Mapping[str, Any]) -> bool:
        return _applies(self.method, self.where, method, params)


class Scene:
    """Base class of a verification case; subclasses set the class attributes.

    ``params`` are the scene's own parameters (defaults = the paper's values),
    ``methods`` the boundary treatments it supports (the first is the default),
    ``solve(method, params, timer)`` does the work and returns an :class:`Outcome`,
    ``cases(quick)`` lists the (method, overrides) pairs the report runs.
    """

    id: str = ""
    title: str = ""
    seed: str = ""
    reference: str = "analytic"
    params: tuple[Param, ...] = ()
    methods: tuple[MethodSpec, ...] = ()
    published: tuple[Published, ...] = ()
    #: documented findings that make runs fail (:class:`ExpectedFailure`)
    expected_failures: tuple = ()
    figure: str = ""  # name of the report figure family that draws this scene's runs
    #: the theory of the scene's plain-grid model ("bond-based" or "state-based") when
    #: it takes the closure treatments (bond methods) of ``pdverify.corrections.registry``
    #: (built-in and plugins) through :meth:`bond_closure`; None: only its own ``methods``
    closure_theory: str | None = None
    #: the problem family the scene describes (``static-state``:
    #: :class:`~pdverify.pd.problem.StaticProblem`), whose treatments assemble its system;
    #: None: the scene implements its own ``methods``
    family: str | None = None
    #: the theory of a family scene's model (closure scenes: ``closure_theory``)
    theory: str | None = None
    #: the spatial dimension of the scene's model (1, 2 or 3): a bond method may serve
    #: some dimensions only, and the report groups its error-against-cost plots by it
    dim: int | None = None
    #: overrides of the offered treatments' report cases under ``--quick``
    quick_overrides: Mapping[str, Any] = {}
    #: the scene's defaults of treatment parameters (e.g. a Taylor order), by name; they
    #: apply to the parameters that declare ``scene_default`` only, each checked as a
    #: given value is (its type, choices and check)
    treatment_defaults: Mapping[str, Any] = {}
    #: why no treatment beyond the scene's own ``methods`` applies (one line), e.g. a
    #: reference that is the uncorrected model's own; None: the registry decides
    closed_to_treatments: str | None = None
    #: further problem families whose treatments' roles serve the scene beside its
    #: ``family`` (``bond-box``: a bond-based box whose description states its
    #: conditions at the surface too, :class:`~pdverify.pd.problem.SurfaceConditions`)
    role_families: tuple[str, ...] = ()
    #: why a family of :data:`~pdverify.corrections.treatment.ROLE_FAMILY_THEORY` of the
    #: scene's theory is not among its ``role_families`` (family -> one line)
    role_refusals: Mapping[str, str] = {}

    # -- methods ----------------------------------------------------------------------
    @property
    def model_theory(self) -> str | None:
        return self.theory or self.closure_theory

    def offered(self) -> dict:
        """The registry's treatments this scene offers beside its own ``methods``: the
        closure treatments of its theory, and the treatments of its problem family."""
        if self.closure_theory is None and self.family is None:
            return {}
        from ..corrections.registry import treatments
        known = treatments()
        cached = self.__dict__.get("_offered_cache")
        if cached is not None and cached[0] is known:    # the same registry: same answer
            return cached[1]
        own = {m.name for m in self.methods}
        out = {k: t for k, t in known.items()
               if k not in own and t.kind != "hand-wired" and t.serves(self)}
        self.__dict__["_offered_cache"] = (known, out)
        return out

    def treatment(self, method: str):
        """The registry's treatment ``method`` as this scene offers it."""
        return self.offered()[method]

    def bond_methods(self) -> dict:
        """The registry's closure treatments (bond methods) this scene offers."""
        return {k: t for k, t in self.offered().items() if t.kind == "closure"}

    def family_refusal(self, treatment) -> str | None:
        """Why a treatment of this scene's family cannot serve it (None: it can)."""
        return None

    def role_refusal(self, treatment) -> str | None:
        """Why a treatment with a role in one of this scene's families cannot serve it
        nonetheless (None: it can), e.g. a stiffness box's treatments that add no node."""
        return None

    def _with_defaults(self, params, method: str) -> tuple[Param, ...]:
        """``params`` with this scene's :attr:`treatment_defaults` applied to those that
        declare ``scene_default``; a default a parameter does not allow is bad input."""
        if not self.treatment_defaults:
            return tuple(params)
        return tuple(
            replace(q, default=q.convert(self.treatment_defaults[q.name],
                                         f"{self.id} --method {method} (the scene's default)"))
            if q.scene_default and q.name in self.treatment_defaults else q for q in params)

    @property
    def all_methods(self) -> tuple[MethodSpec, ...]:
        """The scene's own methods, then the offered treatments (closure treatments take
        the params of the uncorrected method ``none``, which they correct, and their
        own)."""
        own = tuple(self.methods)
        offered = self.offered()
        base = next((t.params_for(self) for t in offered.values() if t.baseline), ())
        return own + tuple(
            MethodSpec(k, self._with_defaults((base if t.kind == "closure" else ())
                                              + t.params_for(self), k))
            for k, t in offered.items())

    def method(self, name: str) -> MethodSpec:
        for m in self.all_methods:
            if m.name == name:
                t = self.offered().get(name)
                if t is not None and t.unavailable:
                    raise InputError(f"{self.id}: method {name} is unavailable here: "
                                     f"{t.unavailable}")
                return m
        if self._broken_plugin(name):
            # accepted as a bond method (the params of ``none``): its run is a failed run
            # naming the plugin and what it did (see :meth:`run`)
            return MethodSpec(name, self.baseline_spec().params)
        from ..corrections.registry import broken_method
        why = broken_method(name)
        if why:
            raise InputError(f"{self.id}: method {name!r} is a plugin that failed to load: "
                             f"{why}")
        allowed = [m.name for m in self.all_methods]
        raise InputError(f"{self.id}: method {name!r}{did_you_mean(name, allowed)} is not "
                         f"supported by this scene; allowed: {', '.join(allowed)}")

    def baseline_spec(self) -> MethodSpec:
        """The uncorrected baseline among the offered treatments (the registry's
        ``baseline``), with its parameters here; an empty spec when none is offered."""
        offered = self.offered()
        name = next((k for k, t in offered.items() if t.baseline), None)
        return next((m for m in self.all_methods if m.name == name), MethodSpec(""))

    def _broken_plugin(self, name: str) -> str | None:
        """Why the plugin method ``name`` failed to load, for a scene that takes bond
        methods; None otherwise."""
        if self.closure_theory is None:
            return None
        from ..corrections.registry import broken_method
        return broken_method(name)

    def declared(self, params: Mapping[str, Any], name: str):
        """``params[name]`` where the run's method takes the parameter ``name``; else its
        default as this scene declares it (its own parameters, then its methods' in
        order), ``None`` where the scene declares no parameter of that name. A
        description reads a treatment's parameter this way (the baseline's
        ``load_point``, which the other treatments do not read): the default stays the
        declaration's, stated once."""
        if name in params:
            return params[name]
        for q in (*self.params, *(q for m in self.all_methods for q in m.params)):
            if q.name == name:
                return q.default
        return None

    def bond_closure(self, method: str, params: Mapping[str, Any]) -> Closure:
        """The :class:`~pdverify.pd.closure.Closure` of a bond method; the uncorrected
        ``Closure()`` for the scene's own methods."""
        bm = self.bond_methods().get(method)
        return Closure() if bm is None else bm.make_closure(params)

    @property
    def default_method(self) -> str:
        """The method of the scene's first (quick) report case: the run its papers
        show first; the first offered method when it lists none."""
        first = self.cases(quick=True)
        return first[0][0] if first else self.all_methods[0].name

    def resolve(self, method: str, overrides: Mapping[str, Any] | None = None) -> dict:
        """Effective parameters (scene + method) with ``overrides`` applied and checked."""
        spec = self.method(method)
        where = f"{self.id} --method {method}"
        values = resolve(self.params + spec.params, dict(overrides or {}), where)
        try:
            self.check(method, values)
            estimate = self.estimate(method, values)
        except InputError:
            raise
        except (ArithmeticError, ValueError, TypeError) as exc:
            # the last guard of the class of bug "an extreme value overflows a size": a
            # one-line refusal naming the values given, never a traceback
            given = ", ".join(f"{k}={v}" for k, v in (overrides or {}).items()) or "defaults"
            raise InputError(f"{where}: {given} is outside what this scene can size "
                             f"({type(exc).__name__}: {exc})") from None
        if estimate is not None and not estimate.memory < float("inf"):
            given = ", ".join(f"{k}={v}" for k, v in (overrides or {}).items()) or "defaults"
            raise InputError(f"{where}: {given} makes the run's size overflow "
                             f"({estimate.detail}); no run of this size fits any memory")
        budget.check(where, estimate)
        return values

    def discretisation(self, p: Mapping[str, Any]) -> Discretisation:
        """The grid spacing and the horizon of the run of resolved params ``p``, in metres.

        The default reads the spellings most scenes use: ``spacing`` with ``m_ratio``
        (delta = m_ratio x spacing) or with ``horizon``, or ``horizon`` with ``m_ratio``
        (Delta = horizon / m_ratio); a scene that states its grid otherwise overrides it."""
        if "spacing" in p and "m_ratio" in p:
            return Discretisation(p["spacing"], p["spacing"] * p["m_ratio"])
        if "spacing" in p and "horizon" in p:
            return Discretisation(p["spacing"], p["horizon"])
        if "horizon" in p and "m_ratio" in p:
            return Discretisation(p["horizon"] / p["m_ratio"], p["horizon"])
        raise NotImplementedError(f"{self.id}: no grid spacing and horizon among its params "
                                  f"({', '.join(p)}); the scene states its discretisation")

    def check(self, method: str, params: dict) -> None:
        """Cross-parameter checks; raise :class:`InputError` with a one-line message."""

    def estimate(self, method: str, params: dict) -> budget.Estimate | None:
        """What the run will need, from its checked params alone (:mod:`pdverify.budget`);
        cheap: no assembly, no import of a heavy library."""
        return None

    # -- running ----------------------------------------------------------------------
    def solve(self, method: str, params: dict, timer: Timer) -> Outcome:
        raise NotImplementedError

    def cases(self, quick: bool = False) -> list[tuple[str, dict]]:
        return [(m.name, {}) for m in self.methods]

    def report_cases(self, quick: bool = False) -> list[tuple[str, dict]]:
        """:meth:`cases` and one run of every available offered treatment it does not
        list (at :attr:`quick_overrides` under ``--quick``)."""
        out = list(self.cases(quick=quick))
        listed = {m for m, _ in out}
        for name, t in self.offered().items():
            if name not in listed and not t.unavailable:
                runs = getattr(t, "report_runs", None)   # a peer code names its own runs
                if runs is not None:
                    out += [(name, o) for o in runs(self, quick)]
                else:
                    out.append((name, dict(self.quick_overrides) if quick else {}))
        return out

    def run(self, method: str, overrides: Mapping[str, Any] | None = None) -> RunResult:
        """Resolve, solve and record one run; numerical trouble becomes a failed result.

        Bad input raises :class:`InputError` before any work starts.
        """
        from ..corrections.registry import PluginCheckError
        try:
            params = self.resolve(method, overrides)
        except PluginCheckError as exc:   # the plugin's check failed, not the user's input
            return RunResult(scene=self.id, method=method, params=dict(overrides or {}),
                             reference=self.reference, status="failed",
                             message=f"{self.id}/{method}: {exc}",
                             timings={"setup_s": 0.0, "solve_s": 0.0, "total_s": 0.0})
        result = RunResult(scene=self.id, method=method, params=params, reference=self.reference,
                           expected_failure=next((e.reason for e in self.expected_failures
                                                  if e.applies(method, params)), ""),
                           published=[p.entry(params) for p in
                                      self.published_for(method, params).values()])
        timer = Timer()
        budget.release_freed_memory()        # what earlier runs left is not this run's
        measured = budget.reset_peak_rss()   # the run's own peak memory, beside its time
        load_start = budget.load_average()   # the machine's load, beside its time
        broken = self._broken_plugin(method)
        if broken:
            result.status = "failed"
            result.message = f"{self.id}/{method}: the plugin failed to load: {broken}"
            result.timings = timer.as_dict()
            return result
        notes = {"diagnostics": {}, "timings": {}}
        try:
            # the same numbers on any machine (pdverify.blas); what the code inside
            # reports beside its metrics is collected (pdverify.results.note)
            with blas.one_thread(), collecting_notes() as notes:
                out = self.solve(method, params, timer)
            bad = [k for k, v in out.metrics.items()
                   if isinstance(v, float) and not np.isfinite(v)]
            if bad:
                raise NumericalError(f"metric {bad[0]} is not finite ({out.metrics[bad[0]]})")
            result.metrics, result.size = out.metrics, out.size
            result.fields, result.diagnostics = out.fields, out.diagnostics
            result.warnings = (conditioning_warnings(out.diagnostics)
                               + solver_error_warnings(out.diagnostics, out.metrics))
        except NumericalError as exc:
            where = f"{self.id}/{method}"
            msg = str(exc)
            result.status = "failed"
            result.message = msg if msg.startswith(where) else f"{where}: {msg}"
            if exc.partial is not None:     # what was computed up to the trouble
                result.metrics, result.size = exc.partial.metrics, exc.partial.size
                result.fields, result.diagnostics = exc.partial.fields, exc.partial.diagnostics
        except (FloatingPointError, ArithmeticError, np.linalg.LinAlgError) as exc:
            result.status = "failed"
            result.message = f"numerical error: {type(exc).__name__}: {exc}"
        except SystemExit as exc:  # code outside the plugin guards that exits: a failed
            # run, never the end of the process (nor of a report's worker)
            result.status = "failed"
            result.message = (f"{self.id}/{method}: the run tried to end the process "
                              f"({what_it_did(exc)})" + (
                                  f" in {self.bond_methods()[method].origin}"
                                  if method in self.bond_methods() else ""))
        except Exception as exc:  # never crash a whole report on one run
            frame = traceback.extract_tb(exc.__traceback__)[-1]
            result.status = "failed"
            result.message = (f"internal error: {type(exc).__name__}: {exc} "
                              f"({frame.filename.rsplit('/', 1)[-1]}:{frame.lineno})")
        result.timings = {**timer.as_dict(), **notes["timings"]}
        if notes["diagnostics"]:
            result.diagnostics = {**result.diagnostics, **notes["diagnostics"]}
        peak = budget.peak_rss() if measured else None
        if peak is not None:
            result.resources = {"peak_rss_gb": peak / 1e9}
        load_end = budget.load_average()
        if load_start is not None and load_end is not None:
            result.resources.update(load_start=load_start, load_end=load_end)
        return result

    def published_for(self, method: str, params: dict) -> dict:
        return {p.metric: p for p in self.published if p.applies(method, params)}
