"""FEM references as scenes with method ``fem`` (issue #5), and the base of the scenes that
run PD methods beside their FEM reference (``FemAndPD``: the seed-003 sheets in
``sheets``; a ``static-state`` description with a FEM reference, such as the seed-000
plate in ``plate2d``, subclasses ``family.FemStaticStateScene``, which builds on it)."""
from __future__ import annotations

import dataclasses

from .. import budget
from ..errors import InputError
from ..params import Param, magnitude
from . import MethodSpec, Outcome, Scene

FEM = MethodSpec("fem")


def _float_check(default):
    """Float fields of a reference's dataclass: no magnitude a double cannot carry through
    the run (:func:`pdverify.params.magnitude`); the dataclass checks the rest."""
    return magnitude if isinstance(default, float) else None


#: the units of the FEM references' dataclass fields (``reference_fem``, SI as their
#: comments state); a field not listed is dimensionless or a count
FEM_UNITS = {"width": "m", "height": "m", "length": "m", "radius": "m", "depth": "m",
             "crack": "m", "horizon": "m", "thickness": "m", "spacing": "m",
             "fine_half_width": "m", "fine_depth": "m", "sample_spacing": "m", "E": "Pa",
             "traction": "Pa", "body_force": "N/m^3", "angle": "deg",
             # the elastodynamic pulse (reference_fem.wave_plate)
             "rho": "kg/m^3", "source_x": "m", "source_y": "m", "source_width": "m",
             "wavelength": "m", "receiver_offset": "m", "duration": "s"}


def _field_param(name, field, cls_name) -> Param:
    """A reference dataclass field as a parameter; its unit from :data:`FEM_UNITS`."""
    unit = FEM_UNITS.get(name) if isinstance(field.default, float) else None
    doc = f"field of the FEM reference's {cls_name}" + (f" [{unit}]" if unit else "")
    return Param(name, field.default, doc, _float_check(field.default))


def reference_module():
    """The FEM reference package (``reference_fem``)."""
    import reference_fem  # heavy (scikit-fem): imported only when a FEM scene runs
    return reference_fem


class FemReference(Scene):
    """Base of the FEM-reference scenes: parameters mirror the reference's dataclass.

    The run calls the converged, cached reference of ``reference_fem`` (a refinement
    study; see its docstring for meshes, elements and every choice) and records its
    metrics, including ``refinement_change_pct`` (change of the compared quantity over
    the last refinement). Timings are this run's wall time (near zero on a cache hit)
    plus ``reference_study_s`` (the whole study as first computed) and the converged
    level's setup and solve; the cost per level is in the refinement table of the report.
    """

    reference = "fem"
    figure = "fem-reference"
    methods = (FEM,)
    params_class: str = ""
    function: str = ""

    def _cls(self):
        return getattr(reference_module(), self.params_class)

    @property
    def params(self):
        # Mirrors the dataclass fields (names, defaults); the dataclass validates values.
        return tuple(_field_param(f.name, f, self.params_class)
                     for f in dataclasses.fields(self._cls()))

    def check(self, method, p):
        try:
            self._cls()(**p)
        except (TypeError, ValueError) as exc:
            raise InputError(f"{self.id} --method {method}: {exc}".replace("\n", " ")) from None

    def estimate(self, method, p):
        return budget.quadratic_elements(self._cls()(**p).finest_cells())

    def solve(self, method, p, timer):
        rf = reference_module()
        with timer.phase("solve"):
            res = getattr(rf, self.function)(**p)
        last = res.refinement[-1]
        metrics = {k: float(v) for k, v in res.metrics().items()}
        size = {"dofs": int(last.dofs), "levels": len(res.refinement)}
        fields = {"refinement": res.refinement_table(), "quantity_name": res.quantity_name,
                  "grid": res.sample_grid((121, 121))}
        # the study's own cost (as first computed, also on a cache hit) sits with the
        # timings, so that everything outside "timings" is reproducible bit for bit
        timer.phases.update(reference_study=float(res.study_s),
                            reference_converged_setup=float(res.setup_s),
                            reference_converged_solve=float(res.solve_s))
        diagnostics = {"from_cache": bool(res.from_cache)}
        return Outcome(metrics=metrics, size=size, fields=self.extra_fields(res, fields),
                       diagnostics=diagnostics)

    def extra_fields(self, res, fields):
        return fields


class FemAndPD(FemReference):
    """A scene whose FEM reference (method ``fem``) and PD methods share one id.

    Scene params are the ones both sides share (``shared``, names of the reference's
    dataclass fields); the FEM study's own params belong to ``fem``, the discretisation's
    (``pd_params``) to the PD methods: the registry's baseline and closures, and the
    treatments with a role in the scene's ``family``.
    Subclasses implement ``check_pd`` and ``solve_pd``.
    """

    shared: tuple = ()
    pd_params: tuple = ()
    #: the uncorrected baseline's parameters beside ``pd_params`` (the closures take
    #: them too)
    baseline_extra: tuple = ()

    @property
    def baseline_params(self):
        return self.pd_params + self.baseline_extra

    @property
    def all_methods(self):
        """``fem``, then the offered treatments; a treatment with a role in the scene's
        family (or its ``role_families``) takes ``pd_params`` beside its role's (the baseline and the closures
        have them through ``baseline_params``)."""
        own = tuple(self.methods)
        offered = self.offered()
        return own + tuple(
            MethodSpec(m.name, (self.pd_params if (offered[m.name].role_on(self)
                                                   or getattr(offered[m.name], "peer", False))
                                else ()) + m.params)
            for m in Scene.all_methods.fget(self)[len(own):])

    def _fields(self):
        return {f.name: f for f in dataclasses.fields(self._cls())}

    @property
    def params(self):
        return tuple(_field_param(n, f, self.params_class)
                     for n, f in self._fields().items() if n in self.shared)

    @property
    def methods(self):
        fem = MethodSpec(FEM.name, tuple(_field_param(n, f, self.params_class)
                                         for n, f in self._fields().items()
                                         if n not in self.shared))
        return (fem,)

    def check(self, method, p):
        if method == FEM.name:
            return super().check(method, p)
        self.check_pd(f"{self.id} --method {method}", method, p)

    def check_pd(self, where, method, p):
        raise NotImplementedError

    def estimate(self, method, p):
        if method == FEM.name:
            return super().estimate(method, p)
        # the FEM reference (at the fem method's defaults) runs first unless cached
        fem = super().estimate(FEM.name, self.reference_params(p))
        return budget.larger(self.estimate_pd(method, p), fem)

    def estimate_pd(self, method, p):
        """The PD run's own needs."""
        raise NotImplementedError

    def solve(self, method, p, timer):
        if method == FEM.name:
            return super().solve(method, p, timer)
        return self.solve_pd(method, p, timer)

    def solve_pd(self, method, p, timer):
        raise NotImplementedError

    def reference_params(self, p) -> dict:
        """The params of the FEM reference a PD run compares with: the ``fem`` method's
        defaults and this run's shared (physical) params."""
        fem_defaults = {q.name: q.default for q in self.method(FEM.name).params}
        return {**fem_defaults, **{k: p[k] for k in self.shared}}

    def fem_reference(self, p):
        """The converged FEM reference at this scene's shared params (cached on disk)."""
        return getattr(reference_module(), self.function)(**self.reference_params(p))
