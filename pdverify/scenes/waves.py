"""Manufactured PD waves in 2D and 3D: an exact reference in space and time for every treatment's dynamics.

A dynamic mode of the ``static-state`` family, not a family of its own: the scene
describes a :class:`~pdverify.pd.problem.StaticProblem` (a state-based box, every face
prescribed) as the static scenes do, the run's treatment assembles it into its
:class:`~pdverify.pd.problem.LinearSystem` by the same contract, and the scene turns
that system into M u'' + K u = f(t) (:func:`dynamic_system`) and integrates it
(:mod:`pdverify.solvers.dynamics`). Why this and not a new family: the treatments then
carry over with no new role, protocol or parameter (a wave role per treatment, as the
1D bar has, would repeat each treatment's boundary imposition); what does not carry over
is a system whose unknowns are not all masses (constraint rows, algebraic boundary rows,
another code's static solve), and each such treatment says so (``static_only``), which
``list`` shows.
"""
from __future__ import annotations

import math

import numpy as np

from .. import budget
from ..errors import NumericalError
from ..params import Param, at_least, grid_params, material_params, open_interval, positive
from ..pd import StateBasedConstants, get_influence, state_based_stencil
from ..pd.problem import FaceCondition, StaticProblem
from ..solvers.dynamics import SAFETY, DynamicSystem, newmark, stable_step, velocity_verlet
from ..solvers.front import displacement_form
from . import Outcome, register
from .family import StaticStateScene
from .surface_nodes import INFLUENCE, QUADRATURE

#: errors at or below this many machine epsilons of the field's scale count as round-off
#: (the rate fit leaves them out): each step adds a few eps of K u's row sums, and
#: the finest level takes 8 x the base steps
ROUND_OFF = 1e-9

OPERATORS = ("continuum", "discrete")
TIME_FUNCTIONS = ("sine", "quadratic")
INTEGRATORS = ("verlet", "newmark")


def time_function(kind: str, period: float):
    """``(g, g', g'')`` of the field's time factor: ``sine``: g = sin(w t) + cos(w t),
    w = 2 pi / period (u and u' both non-zero at t = 0); ``quadratic``: g = 1 + t/T +
    (t/T)^2, T = period (second-order integrators are exact for it)."""
    if kind == "sine":
        w = 2.0 * math.pi / period
        return (lambda t: math.sin(w * t) + math.cos(w * t),
                lambda t: w * (math.cos(w * t) - math.sin(w * t)),
                lambda t: -w * w * (math.sin(w * t) + math.cos(w * t)))
    s = 1.0 / period
    return (lambda t: 1.0 + s * t + (s * t) ** 2, lambda t: s + 2 * s * s * t,
            lambda t: 2 * s * s)


def dynamic_system(system, density, field_at_unknowns, g, load_shape, where):
    """M u'' + K u = f(t) of a treatment's static ``system`` (a
    :class:`~pdverify.pd.problem.LinearSystem` of the field P):

    K: the system's displacement form (dilatations condensed), over every unknown; M:
    rho V_i on the real nodes' components, 0 on extra unknown nodes (surface nodes); the
    prescribed unknowns move as ``system.values`` g(t); f(t) = g(t) ``load_shape`` + g''(t)
    M P_h, P_h the field at the unknowns (``field_at_unknowns``, component-major), so
    the inertia rho u_tt enters as the body load rho P V_i g'' that every treatment of
    the family applies to a body force. A system that is not of this form (constraint
    rows, an affine offset on its fictitious nodes, a free unknown without mass) is a
    failed run naming what it has."""
    if system.B is not None:
        raise NumericalError(f"{where}: the treatment's system has {system.B.shape[0]} "
                             "constraint rows (Lagrange multipliers): M u'' + K u = f would "
                             "be a differential-algebraic system, not integrated here")
    if system.offset is not None:
        raise NumericalError(f"{where}: the treatment's fictitious nodes carry an affine "
                             "offset of the prescribed values, which a time-dependent "
                             "motion would have to re-derive every step")
    K, _ = displacement_form(system)
    n, d = system.dofs, system.dim
    ni = system.model.grid.n_interior
    volume = system.model.node_volume[system.model.grid.interior_ids]
    per_node = np.zeros(system.n_unknown_nodes)
    per_node[:ni] = density * volume
    mass = np.tile(per_node, d)
    free = np.setdiff1d(np.arange(n), system.fixed)
    massless = free[mass[free] == 0]
    if massless.size:
        raise NumericalError(f"{where}: {massless.size} free unknowns carry no mass (extra "
                             "nodes with equations of their own, e.g. force-flux rows); "
                             "integrating them needs a static condensation per step, not "
                             "done here")
    g0, _, g2 = g
    inertia = mass * field_at_unknowns
    values = np.asarray(system.values, dtype=float)
    g1 = g[1]

    def load(t):
        return g0(t) * load_shape + g2(t) * inertia

    def prescribed(t):
        return g0(t) * values, g1(t) * values, g2(t) * values

    return DynamicSystem(K[:n, :n], np.where(mass > 0, mass, 1.0), free, load, prescribed)


class ManufacturedWave(StaticStateScene):
    """Shared description of the manufactured wave boxes; subclasses state the box
    and the field."""

    reference = "manufactured"
    seed = "ours (issue 56; seed 002's extension)"
    figure = "waves"
    kind = "3d"
    #: the field P(x) of u = P(x) g(t), one polynomial per component in x, y, z
    field: tuple = ()

    def box(self, p):
        raise NotImplementedError

    def family_refusal(self, treatment) -> str | None:
        why = super().family_refusal(treatment)
        if why is None and treatment.static_only:
            why = f"static only: {treatment.static_only}"
        return why

    def constants(self, p):
        return StateBasedConstants(self.kind, p["E"], p["nu"])

    def wave_speed(self, p) -> float:
        """The bar speed sqrt(E / rho) [m/s]: the time scale of the field's period."""
        return math.sqrt(p["E"] / p["rho"])

    # ----------------------------------------------------------------- the field
    def manufactured(self, p):
        """The continuum PD fields of P (``manufactured.engine``: the infinite-body body
        force b = -L P of the run's state-based model, influence and horizon). Imported
        here: sympy stays out of the commands that run nothing (``list``)."""
        from manufactured.engine import solution as manufactured_solution
        return manufactured_solution(
            [f"A*({c})" for c in self.field], model="state-based", dim=self.dim,
            horizon=p["m_ratio"] * p["spacing"], E=p["E"], nu=p["nu"],
            influence=p["influence"], plane="strain" if self.dim == 2 else None,
            params={"A": p["amplitude"]})

    def problem(self, p, where):
        lengths, origin = self.box(p)
        inf = get_influence(p["influence"])
        ms = self.manufactured(p)
        body = ms.body_force if p["operator"] == "continuum" else None
        every = tuple(range(self.dim))
        return StaticProblem(
            lengths, origin, float(p["spacing"]),
            state_based_stencil(len(lengths), p["m_ratio"], p["spacing"], inf,
                                p["quadrature"]),
            self.constants(p), inf,
            {face: FaceCondition(prescribed=every) for face in
             ("x-", "x+", "y-", "y+", "z-", "z+")[:2 * self.dim]},
            exact=ms.displacement, body_force=body, solver="direct", where=where)

    # ----------------------------------------------------------------- checks
    def estimate(self, method, p):
        base = super().estimate(method, p)
        cells = p["lx"] / p["spacing"]
        # steps of the base level: the run over the explicit limit, which is 1.3-1.7 h / c
        # on these lattices (measured at m = 3: PDDO's 1.3 the smallest); every level
        # halves the step
        steps = budget.step_count(p["periods"] * p["period"] * cells / (1.3 * p["dt_factor"]))
        # in floats: an extreme time_levels must give inf (refused by the budget), not a
        # Python integer of 2^levels bits (10^18 levels took the whole memory)
        levels = p["time_levels"]
        total = steps * (2.0 ** levels - 1 if levels < 1024 else math.inf)
        return base + budget.Estimate(
            0.0, f"~{total:.3g} time steps: periods={p['periods']:g} x period="
            f"{p['period']:g} transit times at dt_factor={p['dt_factor']:g} of the limit, "
            f"time_levels={p['time_levels']}", total)

    # ----------------------------------------------------------------- solve
    def solve(self, method, p, timer):
        from ..corrections.registry import plugin_call
        where = f"{self.id}/{method}"
        with timer.phase("setup"):
            problem = self.problem(p, where)
            t = self.treatment(method)
            system = plugin_call(t, "assemble", t.assemble, problem, p)
            g = system.model.grid
            x_int = g.x[g.interior_ids]
            x_nodes = x_int if system.extra_x is None else np.r_[x_int, system.extra_x]
            field = problem.exact(x_nodes).T.ravel()
            period = p["period"] * self.box(p)[0][0] / self.wave_speed(p)
            gt = time_function(p["time_function"], period)
            if p["operator"] == "discrete":
                K, _ = displacement_form(system)
                shape = K @ field         # f = g K P_h + g'' M P_h: exact for the model
            else:
                shape = displacement_form(system)[1]   # the treatment's own loads of b
            dyn = dynamic_system(system, p["rho"], field, gt, shape, where)
            limit = stable_step(dyn, where=where)
            T = p["periods"] * period
            base_steps = max(1, math.ceil(T / (p["dt_factor"] * limit.dt_limit)))
            dt0 = T / base_steps
        levels, info = [], {}
        with timer.phase("solve"):
            for k in range(p["time_levels"]):
                scale = 2 ** k
                dt, n_steps = dt0 / scale, base_steps * scale
                sample = np.arange(base_steps + 1) * scale
                if p["integrator"] == "verlet":
                    run = velocity_verlet(dyn, field * gt[0](0.0), field * gt[1](0.0), dt,
                                          n_steps, sample_steps=sample, where=where,
                                          limit=limit)
                else:
                    run = newmark(dyn, field * gt[0](0.0), field * gt[1](0.0), dt, n_steps,
                                  sample_steps=sample, where=where, omega_max=limit.omega_max)
                levels.append(run)
                if k == 0:
                    info = dict(run.info)
        return self.measure_waves(p, system, x_int, field, gt, levels, limit, info,
                                  dyn.asymmetry())

    def measure_waves(self, p, system, x_int, field, gt, levels, limit, info, asymmetry):
        """Metrics (class docstring) of the levels' trajectories."""
        g = system.model.grid
        d, nu_, ni = g.dim, system.n_unknown_nodes, g.n_interior
        base = levels[0]
        times = base.times
        gvals = np.array([gt[0](t) for t in times])
        P = field.reshape(d, nu_)[:, :ni].T                       # (ni, d)
        u_ref = gvals[:, None, None] * P[None]                     # (nt, ni, d)

        def real(run):
            return run.u.reshape(len(times), d, nu_)[:, :, :ni].transpose(0, 2, 1)

        u = real(base)
        scale = float(np.max(np.linalg.norm(u_ref, axis=2)))
        err = np.linalg.norm(u - u_ref, axis=2) / scale * 100.0    # (nt, ni) in %
        near = g.distance_to_surface(x_int) <= system.model.horizon
        l2_ref = float(np.max(np.linalg.norm(u_ref.reshape(len(times), -1), axis=1)))
        metrics = {"max_error_pct": float(err.max())}
        for prefix, mask in (("boundary_", near), ("interior_", ~near)):
            if mask.any():      # a region without nodes is left out (the 3D box's interior)
                metrics[f"{prefix}max_error_pct"] = float(err[:, mask].max())
        metrics.update({
            "rel_l2_error": float(np.max(np.linalg.norm((u - u_ref).reshape(len(times), -1),
                                                        axis=1)) / l2_ref),
            "energy_balance_pct": 100.0 * base.energy_balance(),
            "dt": float(info["dt"]), "dt_limit": float(limit.dt_limit),
            "n_steps": int(info["n_steps"]),
        })
        errors = [float(np.max(np.linalg.norm(real(r) - u_ref, axis=2)) / scale)
                  for r in levels]
        steps = [r.info["dt"] for r in levels]
        diagnostics = dict(info)
        diagnostics.update({"time_levels_dt": steps, "time_levels_max_error": errors,
                            "stiffness_asymmetry": asymmetry,
                            "energy_balance_levels_pct":
                                [100.0 * r.energy_balance() for r in levels],
                            "safety_factor": SAFETY})
        if p["operator"] == "discrete":
            keep = [i for i, e in enumerate(errors) if e > ROUND_OFF]
            if len(keep) >= 2:
                rate = np.polyfit(np.log([steps[i] for i in keep]),
                                  np.log([errors[i] for i in keep]), 1)[0]
                metrics["time_rate"] = float(rate)
            diagnostics["time_rate_levels"] = len(keep)
        else:
            # the finest level's error: the space error (the treatment's boundary error
            # and the lattice's quadrature error) with the least time error in it. No
            # Richardson estimate of the time error: the load's mismatch with the discrete
            # operator excites the lattice's top modes, whose phase error at the base step
            # is not in the asymptotic range (measured: |u_dt - u_dt/2| is half the error
            # while the error's maximum changes by < 1 % across the levels)
            metrics["finest_max_error_pct"] = 100.0 * errors[-1]
        fields = {"x": x_int, "times": times, "u": u, "u_ref": u_ref, "error": err,
                  "energy": base.energy, "spacing": p["spacing"],
                  "horizon": system.model.horizon}
        size = self.size(system)
        size["operator_nnz"] = int(displacement_form(system)[0].nnz)
        return Outcome(metrics=metrics, size=size, fields=fields, diagnostics=diagnostics)

    def cases(self, quick=False):
        over = dict(self.quick_overrides) if quick else {}
        disc = {"operator": "discrete", **over}
        return ([("none", dict(over)), ("none", {**disc}),
                 ("none", {**disc, "integrator": "newmark"}),
                 ("none", {**disc, "time_function": "quadratic"}),
                 ("none", {**disc, "time_function": "quadratic", "integrator": "newmark"})]
                + [(m, dict(over)) for m in ("energy", "volume", "pals", "surface-nodes")]
                + [(m, dict(disc)) for m in ("energy", "volume", "pals", "surface-nodes")])


def _wave_params(lengths, spacing):
    names = ("lx", "ly", "lz")[:len(lengths)]
    return (
        *(Param(n, L, f"box size {n[1]} [m]", positive) for n, L in zip(names, lengths)),
        *material_params(200e9, 0.25),
        Param("rho", 7850.0, "density [kg/m^3]", positive),
        *grid_params(spacing, 3.0),
        QUADRATURE,
        INFLUENCE,
        Param("amplitude", 1e-4, "field scale A [m] (u = A P(x) g(t))", positive),
        Param("operator", "continuum", "the operator whose body force the field satisfies: "
              "the run's own discrete PD operator (b = rho u_tt - L_h u: exact for the "
              "discrete model, so only the time integration errs) or the continuum PD "
              "operator (manufactured.engine: the treatment's boundary error shows)",
              choices=OPERATORS),
        Param("time_function", "sine", "g(t): sin + cos of one period, or quadratic "
              "(exact for both integrators)", choices=TIME_FUNCTIONS),
        Param("integrator", "verlet", "velocity Verlet (explicit) or Newmark average "
              "acceleration (implicit, one factorisation)", choices=INTEGRATORS),
        Param("dt_factor", SAFETY, "base step over the explicit limit 2/omega_max of the "
              "run's operator (Newmark runs at the same step, for comparison)",
              open_interval(0.0, 1.0)),
        Param("period", 4.0, "period of g in transit times l_x / sqrt(E/rho)", positive),
        Param("periods", 1.0, "run length in periods of g", positive),
        Param("time_levels", 4, "steps of the time study: dt, dt/2, ... (a rate needs "
              "two)", at_least(2)),
    )


@register
class Wave2DManufactured(ManufacturedWave):
    """Manufactured 2D waves (plane strain, ours): u(x, t) = A P(x) g(t) on a clamped
    plate, every treatment's dynamics against an exact reference.

    Field: P = (x^2 y + x y, x^3 - y^2), A = 1e-4 m, on [0, 1] x [0, 1] m; g(t) = sin(w t)
    + cos(w t) with the period 2 pi / w = four transit times l_x / sqrt(E/rho) (param
    ``period``; w dt <= 0.25 at the base step), one period long; or g quadratic (``time_function=quadratic``).
    Material: state-based plane strain (seed 001 §5's constants), E = 200 GPa, nu = 0.25,
    rho = 7850 kg/m^3, Gaussian influence, h = 0.1 m, m = 3. Every face prescribes both
    components at the field's value (boundary data from the same field).

    Body force (``operator``): ``discrete`` (b = rho u_tt - L_h u with L_h the discrete
    operator of the run's own treatment: f(t) = g K P_h + g'' M P_h, so P_h g(t) is the
    exact solution of the semi-discrete system and the only error is the time
    integration's) or ``continuum`` (default: b = rho u_tt + b_eq g with b_eq = -L P the
    infinite-body PD body force of ``manufactured.engine``, applied by each treatment as
    it applies a body force; the error is then the treatment's boundary error and the
    lattice's quadrature error, plus a time error).

    Integrators (``pdverify.solvers.dynamics``): velocity Verlet at ``dt_factor`` = 0.9 of
    the explicit limit 2 / omega_max, omega_max^2 the largest eigenvalue of the
    mass-scaled stiffness M^-1/2 K M^-1/2 (LAPACK or Lanczos ``eigsh`` to machine
    precision; ARPACK on M^-1 K for a non-symmetric K), the step then shortened to divide
    the run into whole steps; Newmark average acceleration at the same step (one sparse
    LU of K_ff + 4/dt^2 M_ff). Every run repeats its integration at dt/2, dt/4, dt/8
    (``time_levels``).

    Metrics (base step): ``max_error_pct`` = max over the sampled steps and real nodes of
    |u - u_ref| over max |u_ref| (in %), ``boundary_max_error_pct`` /
    ``interior_max_error_pct`` its split at one horizon from the surface,
    ``rel_l2_error`` = max over time of ||u - u_ref||_2 over max over time of
    ||u_ref||_2, ``energy_balance_pct`` = max over time of |E_kin + E_strain - W - E(0)|
    over max (E_kin + E_strain) (W: the work of the loads and of the prescribed
    unknowns' reactions, trapezoidal in time), ``dt``, ``dt_limit``, ``n_steps``;
    ``time_rate`` (discrete) the fitted slope of log max error against log dt over the
    levels above round-off (1e-9 of the scale), ``finest_max_error_pct`` (continuum) the
    error at the finest step: the space error with the least time error in it (no
    Richardson estimate: the load's mismatch with the lattice excites its top modes,
    whose phase error at the base step is not asymptotic).

    Findings at the defaults (not tuned): with the discrete operator every carried
    treatment is exact to round-off for the quadratic motion, and the
    fitted rates of both integrators are 2 within a few hundredths in 2D (the 3D base
    pair is steeper, the finer pairs at the asymptotic rate); with the continuum operator the uncorrected
    model's error is several times the surface nodes', most of it within a horizon of the
    surface, and ``energy``, ``volume`` and ``pals`` do not lower it (their factors
    correct the stiffness of a homogeneous strain, not this field's boundary data).

    Choices where the issue is silent: the mass is lumped, rho V_i on the real nodes
    (surface nodes are prescribed here and carry none); the inertia enters as the body
    load rho P V_i g''; the error scale is the largest |u| over the run; a treatment
    whose system has constraint rows or algebraic unknowns is not carried over (its
    ``static_only`` reason, shown by ``list``).
    """

    id = "wave2d-manufactured"
    title = "2D manufactured waves: time integrators and treatments against an exact reference"
    kind = "plane-strain"
    dim = 2
    field = ("x**2*y + x*y", "x**3 - y**2")
    params = _wave_params((1.0, 1.0), 0.1)
    quick_overrides = {"time_levels": 3}

    def box(self, p):
        return (p["lx"], p["ly"]), (0.0, 0.0)


@register
class Wave3DManufactured(ManufacturedWave):
    """Manufactured 3D waves (ours): the 2D scene's construction on a clamped box
    [0, 1] x [0, 0.5] x [0, 0.5] m, h = 0.1 m, m = 3, with the 3D state-based constants and
    P = (x y + x^2 z, x^3 - y z, x z + y^2); everything else (body force, integrators,
    metrics, choices) as ``wave2d-manufactured`` states it."""

    id = "wave3d-manufactured"
    title = "3D manufactured waves: time integrators and treatments against an exact reference"
    kind = "3d"
    dim = 3
    field = ("x*y + x**2*z", "x**3 - y*z", "x*z + y**2")
    params = _wave_params((1.0, 0.5, 0.5), 0.1)
    quick_overrides = {"time_levels": 3}

    def box(self, p):
        return (p["lx"], p["ly"], p["lz"]), (0.0, 0.0, 0.0)
