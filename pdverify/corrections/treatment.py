"""The treatment contract: one interface for every boundary treatment ('method').

A :class:`Treatment` declares its name, parameters, theories and dimensions and says in
one line where it applies (``scope``). It serves a scene in one of three ways:

- **closure** (:class:`~pdverify.corrections.registry.BondMethod`): it only changes the
  model's bonds (weights, force factors, a constitutive replacement), and imposes the
  scene's boundary conditions as the uncorrected model does. It serves every scene whose
  plain-grid model takes a closure (``Scene.closure_theory``) of its theories and
  dimensions.
- **problem family**: it implements ``assemble(problem, params)`` for a family of
  problems that scenes describe without naming a method (``Scene.family``; today
  ``static-state``: :class:`~pdverify.pd.problem.StaticProblem`, the static state-based
  boxes and bars with boundary conditions keyed by face and component). It may add
  nodes, unknowns and rows (surface nodes, fictitious or mirror nodes, flux or boundary
  rows): the returned :class:`~pdverify.pd.problem.LinearSystem` carries all of it.
  A treatment may also have a :class:`Role` in further families (``roles``), each with
  its own parameters, ``build`` and checks: the smaller families of scenes that are not
  static boxes (``wave-bar``: seed 002's wave, whose treatments give the bar's
  fictitious extension; ``flux-bar``: seed 000's force flux, the closure of the bar's grid;
  ``clamped-sheet``: seed 003's clamped sheet, where virtual nodes bring their own grid
  and clamp nodes). A scene asks ``scene.treatment(method)`` for it by role, never by
  name (``tests/treatments/test_contract.py`` greps every scene module).
- the **baseline** (``baseline=True``: ``none``): the uncorrected model; it serves
  every closure scene with the scene's ``baseline_params``, which the closures take too.
- **hand-wired** (``families=()``, no closure, no role): only the ``fem`` reference,
  which the FEM scenes run themselves.

Registration: built-ins here and in ``registry.py``; other packages through the Python
entry point group ``pdverify.methods`` (an entry point loads a :class:`Treatment` or a
list of them), e.g. in the plugin's ``pyproject.toml``::

    [project.entry-points."pdverify.methods"]
    my-method = "my_package.pdverify_plugin:METHOD"

:func:`~pdverify.corrections.registry.from_name` looks a treatment up by name with a
helpful error (close matches);
:meth:`Treatment.info` is its dictionary of facts for ``list --json`` and the report;
:meth:`Treatment.why_not` is the one-line reason an empty cell of the method x scene
matrix is empty.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, Mapping

from ..params import Param

if TYPE_CHECKING:       # the signatures each family takes (imported by the type checker)
    from ..pd.problem import LinearSystem, StaticProblem
    from .protocols import ParamCheck, RoleBuild

THEORIES = ("bond-based", "state-based")
ENTRY_POINT_GROUP = "pdverify.methods"
#: families whose roles serve the scenes of one theory beside the scene's own family
#: (``Scene.role_families``): a scene of that theory that does not list the family
#: says why (``Scene.role_refusals``)
ROLE_FAMILY_THEORY = {"bond-box": "bond-based", "held-face": "bond-based"}
#: the reason a scene of that theory that neither lists the family nor says why gets
ROLE_DEFAULT_REFUSAL = {
    "bond-box": "its bond-box role needs the scene's conditions stated at the body's "
                "surface; this scene states them on nodes only",
    "held-face": "its held-face role needs a face held in every component; this scene "
                 "holds none"}
#: the uncorrected baseline's name (``Treatment.baseline``; a scene that declares its own
#: baseline run names it so)
BASELINE = "none"


@dataclass(frozen=True)
class Role:
    """What a treatment does for one more problem family (``Treatment.roles``): its
    parameters there, ``build(problem, params)`` (what the family's scenes ask of a
    treatment, typed per family in :mod:`~pdverify.corrections.protocols`:
    ``WaveExtension``, ``FluxClosure``, ``Clamp``; ``ROLE_PROTOCOLS`` maps a family to
    its protocol) and ``checker(context, params, where)`` (``ParamCheck``: refuses
    parameters before any work; ``context`` is what the family's scenes pass, e.g. a node
    count). The family fixes the theory and dimension, so a role serves every scene of
    it."""

    build: RoleBuild
    params: tuple[Param, ...] = ()
    checker: ParamCheck | None = None


@dataclass(frozen=True)
class Treatment:
    """A boundary treatment. Subclasses override :meth:`assemble` (problem families) or
    are :class:`~pdverify.corrections.registry.BondMethod` (closures).

    ``theories``/``dims``: the models it applies to; ``families``: the problem families
    it assembles (``Scene.family``); ``scenes``: restricts it to these scene ids
    (``None``: every scene it otherwise serves); ``scope``: one line on where it applies
    and why not elsewhere; ``unavailable``: ``None`` when it can run, else why not and
    how to fix it; ``origin``: ``built-in`` or the plugin's entry point.
    """

    name: str
    description: str
    source: str
    params: tuple[Param, ...] = ()
    theories: tuple[str, ...] = THEORIES
    dims: tuple[int, ...] = (1, 2, 3)
    families: tuple[str, ...] = ()
    scenes: tuple[str, ...] | None = None
    scope: str = ""
    unavailable: str | None = None
    origin: str = "built-in"
    #: what it adds to a box for the memory budget: ``plain`` (nothing), ``fictitious``
    #: (a fictitious layer of the stencil's reach), ``surface`` (that and surface nodes)
    footprint: str = "plain"
    #: True when it can impose a prescribed component only on whole faces
    whole_faces_only: bool = False
    #: True for the uncorrected baseline (``none``): every scene that takes closures
    #: runs it, with the scene's ``baseline_params``; the closures take them too
    baseline: bool = False
    #: ``((family, Role), ...)``: the problem families beyond ``families`` it serves
    roles: tuple[tuple[str, Role], ...] = ()
    #: True when it can assemble a body that is not a box (a ``StaticProblem`` with a
    #: ``shape``: conditions keyed by boundary parts, cut cells, curved parts);
    #: ``box_only``: why not, when it cannot (``list`` shows it on the shape scenes)
    shapes: bool = False
    box_only: str = ""
    #: True when it can also assemble a 3D shape (``pdverify.pd.shapes3d``);
    #: ``shapes3d_why``: why not, when it serves 2D shapes only
    shapes3d: bool = False
    shapes3d_why: str = ""
    #: True when its shape form serves crack faces (``pdverify.pd.shapes.Crack``: one-
    #: sided fictitious nodes on a slit, ``Closure.ghosts``); ``cracks_why``: why not,
    #: when it serves shapes but not the crack scenes (``list`` shows it there)
    cracks: bool = False
    cracks_why: str = ""
    #: why not on a scene of a theory it does not take (one line; empty: "THEORY only")
    theory_refusal: str = ""
    #: why its static system does not carry over into the family's dynamic mode
    #: (M u'' + K u = f(t): every free unknown a mass, the prescribed ones eliminated;
    #: ``pdverify.scenes.waves``), e.g. constraint rows; empty: it carries over
    static_only: str = ""

    def __post_init__(self):
        bad = [t for t in self.theories if t not in THEORIES]
        if bad:
            raise ValueError(f"method {self.name!r}: theories {bad} not in {THEORIES}")

    # ------------------------------------------------------------------ where it applies
    @property
    def kind(self) -> str:
        """``closure``, ``family`` or ``hand-wired`` (module docstring)."""
        return "family" if self.families or self.roles else "hand-wired"

    def role(self, family: str | None) -> Role | None:
        """Its :class:`Role` in ``family``, if it has one."""
        return next((r for f, r in self.roles if f == family), None)

    def role_on(self, scene) -> Role | None:
        """Its :class:`Role` on ``scene``: in the scene's family, else in the first of
        the scene's further ``role_families`` it has one in."""
        for family in (getattr(scene, "family", None), *getattr(scene, "role_families", ())):
            role = self.role(family)
            if role is not None:
                return role
        return None

    def params_for(self, scene) -> tuple[Param, ...]:
        """Its parameters on ``scene``: its role's there (:meth:`role_on`), the scene's
        ``baseline_params`` for the baseline on a closure scene, else ``params``."""
        role = self.role_on(scene)
        if role is not None:
            return role.params
        if self.baseline and self._closure_scene(scene):
            return tuple(getattr(scene, "baseline_params", ()))
        return self.params

    def _closure_scene(self, scene) -> bool:
        """Whether ``scene`` takes closures and is not of a family this treatment
        assembles (there, the family's own form serves)."""
        return (getattr(scene, "closure_theory", None) is not None
                and getattr(scene, "family", None) not in self.families)

    def build_for(self, family: str, problem, params: Mapping[str, Any]):
        """What its role in ``family`` makes of ``problem`` (see :class:`Role`)."""
        return self.role(family).build(problem, params)

    def check_for(self, family: str, context, params: Mapping[str, Any], where: str):
        """Its role's parameter check in ``family`` (nothing when it has none)."""
        role = self.role(family)
        if role is not None and role.checker is not None:
            role.checker(context, params, where)

    def why_not(self, scene) -> str | None:
        """``None`` when this treatment runs on ``scene``, else a one-line reason."""
        if self.name in {m.name for m in scene.methods}:
            return None                                  # the scene implements it itself
        if self.role_on(scene) is not None:  # a role in the scene's problem families,
            refusal = getattr(scene, "role_refusal", None)   # unless the scene says why
            return None if refusal is None else refusal(self)   # not (None: it runs)
        if self.baseline and self._closure_scene(scene):
            return None                      # the uncorrected model of a closure scene
        if getattr(scene, "closed_to_treatments", None):
            return scene.closed_to_treatments
        if self.scenes is not None and scene.id not in self.scenes:
            return self.scope or f"only on {', '.join(self.scenes)}"
        theory = getattr(scene, "model_theory", None)
        if theory is not None and theory not in self.theories:
            return (self.theory_refusal
                    or f"{'/'.join(self.theories)} only; this scene is {theory}")
        if scene.dim is not None and scene.dim not in self.dims:
            return (f"{'/'.join(map(str, self.dims))}D only; this scene is {scene.dim}D"
                    + (f" ({self.scope})" if self.scope else ""))
        return self._why_not_kind(scene)

    def _why_not_kind(self, scene) -> str | None:
        family = getattr(scene, "family", None)
        if self.families and family in self.families:
            return scene.family_refusal(self)
        theory = getattr(scene, "model_theory", None)
        for f, _ in self.roles:
            if ROLE_FAMILY_THEORY.get(f) == theory:
                return (getattr(scene, "role_refusals", {}).get(f)
                        or ROLE_DEFAULT_REFUSAL.get(f, f"the scene offers no {f} role"))
        if self.families:
            return (f"assembles {', '.join(self.families)} problems; this scene is "
                    f"{family or 'not a problem description yet'}"
                    + (f" ({self.scope})" if self.scope else ""))
        return self.scope or "not offered by this scene"

    def serves(self, scene) -> bool:
        return self.why_not(scene) is None

    # ------------------------------------------------------------------ the work
    def check(self, cells: tuple[int, ...], params: Mapping[str, Any], where: str) -> None:
        """Refuse (``InputError``, one line) parameters this treatment cannot run with
        on a box of ``cells`` cells per axis; before any work."""

    def assemble(self, problem: StaticProblem, params: Mapping[str, Any]) -> LinearSystem:
        """The :class:`~pdverify.pd.problem.LinearSystem` of ``problem`` under this
        treatment (problem-family treatments; the signature is
        :class:`~pdverify.corrections.protocols.StaticAssembly`'s)."""
        raise NotImplementedError(f"{self.name} assembles no problem family")

    def info(self) -> dict:
        """What ``list --json`` and the report say about the treatment."""
        return {"name": self.name, "kind": self.kind, "description": self.description,
                "source": self.source, "theories": list(self.theories),
                "dims": list(self.dims), "families": list(self.families),
                "scenes": None if self.scenes is None else list(self.scenes),
                "roles": [f for f, _ in self.roles],
                "scope": self.scope, "params": {p.name: p.default for p in self.params},
                "unavailable": self.unavailable, "origin": self.origin,
                "shapes": self.shapes, "box_only": self.box_only}
