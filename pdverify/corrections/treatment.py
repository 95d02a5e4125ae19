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
- **hand-wired** (``families=()``, no closure): the scenes that list it in their own
  ``methods`` implement it (the seed-003 and seed-004 corrections, whose scenes are not
  yet problem descriptions). Its ``scope`` names them.

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
from typing import Any, Mapping

from ..params import Param

THEORIES = ("bond-based", "state-based")
ENTRY_POINT_GROUP = "pdverify.methods"


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

    def __post_init__(self):
        bad = [t for t in self.theories if t not in THEORIES]
        if bad:
            raise ValueError(f"method {self.name!r}: theories {bad} not in {THEORIES}")

    # ------------------------------------------------------------------ where it applies
    @property
    def kind(self) -> str:
        """``closure``, ``family`` or ``hand-wired`` (module docstring)."""
        return "family" if self.families else "hand-wired"

    def why_not(self, scene) -> str | None:
        """``None`` when this treatment runs on ``scene``, else a one-line reason."""
        if self.name in {m.name for m in scene.methods}:
            return None                                  # the scene implements it itself
        if getattr(scene, "closed_to_treatments", None):
            return scene.closed_to_treatments
        if self.scenes is not None and scene.id not in self.scenes:
            return self.scope or f"only on {', '.join(self.scenes)}"
        theory = getattr(scene, "model_theory", None)
        if theory is not None and theory not in self.theories:
            return f"{'/'.join(self.theories)} only; this scene is {theory}"
        if scene.dim is not None and scene.dim not in self.dims:
            return (f"{'/'.join(map(str, self.dims))}D only; this scene is {scene.dim}D"
                    + (f" ({self.scope})" if self.scope else ""))
        return self._why_not_kind(scene)

    def _why_not_kind(self, scene) -> str | None:
        family = getattr(scene, "family", None)
        if self.families and family in self.families:
            return scene.family_refusal(self)
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

    def assemble(self, problem, params: Mapping[str, Any]):
        """The :class:`~pdverify.pd.problem.LinearSystem` of ``problem`` under this
        treatment (problem-family treatments)."""
        raise NotImplementedError(f"{self.name} assembles no problem family")

    def info(self) -> dict:
        """What ``list --json`` and the report say about the treatment."""
        return {"name": self.name, "kind": self.kind, "description": self.description,
                "source": self.source, "theories": list(self.theories),
                "dims": list(self.dims), "families": list(self.families),
                "scenes": None if self.scenes is None else list(self.scenes),
                "scope": self.scope, "params": {p.name: p.default for p in self.params},
                "unavailable": self.unavailable, "origin": self.origin}
