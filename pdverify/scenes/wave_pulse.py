"""A physical wave in 2D: a pulse in a plate reflecting from a fixed edge, a free edge and a corner, PD against a converged elastodynamic FEM (issue 56, second half).

The dynamic mode of the ``static-state`` family, as the manufactured waves
(:mod:`pdverify.scenes.waves`): the scene describes a static problem (the plate, its
fixed edge, the source's body force as a shape), the run's treatment assembles it into
its :class:`~pdverify.pd.problem.LinearSystem`, and
:func:`~pdverify.scenes.waves.dynamic_system` turns that into M u'' + K u = r(t) f with
r the Ricker wavelet, integrated by velocity Verlet
(:func:`~pdverify.solvers.dynamics.velocity_verlet`).
"""
from __future__ import annotations

import math

import numpy as np

from .. import budget
from ..errors import InputError
from ..params import Param, grid_params, open_interval
from ..pd import StateBasedConstants, get_influence, state_based_stencil
from ..pd.problem import FaceCondition, StaticProblem
from ..quotes import Quote as Q
from ..solvers.dynamics import SAFETY, stable_step, velocity_verlet
from . import register, whole_cells
from .base import ExpectedFailure
from .family import FemStaticStateScene
from .fem_references import FEM, FemReference
from .surface_nodes import INFLUENCE, QUADRATURE

#: the receivers, in the reference's order (``reference_fem.wave_plate.RECEIVERS``)
RECEIVERS = ("fixed", "free", "corner")
#: Butterworth order of the zero-phase low-pass (``scipy.signal.sosfiltfilt``) applied
#: to PD and FEM receiver signals alike
FILTER_ORDER = 4


def ricker(p):
    """(r, r', r'') of the reference's Ricker wavelet (only r is read: nothing is
    prescribed to move)."""
    f, t0 = p.peak_frequency, p.delay

    def r(t):
        a = (math.pi * f * (t - t0)) ** 2
        return (1.0 - 2.0 * a) * math.exp(-a)

    def zero(t):
        return 0.0
    return r, zero, zero


def dispersion(K, x, volume, rho, i, delta, c_p, c_s):
    """PD's phase velocities over the classical ones along x at ``k delta`` = 0.01 ..
    3: ``(kd, p_ratio, s_ratio)`` from node ``i``'s row of K (a node at least two
    horizons from the surface: the translation-invariant operator), its symbol
    sum_j K_ij cos(k (x_j - x_i)) over rho V_i = omega^2 (the longitudinal branch from
    the x-x block with the offsets along x, the transverse from the same block with the
    offsets along y, i.e. u_x varying along y)."""
    n = len(x)
    row = K[i, :n].tocsr()
    cols, row = row.indices, row.data              # the node's neighbours only
    dx, dy = x[cols, 0] - x[i, 0], x[cols, 1] - x[i, 1]
    kd = np.linspace(0.01, 3.0, 300)
    k = kd / delta
    m = rho * volume[i]
    wp = np.sqrt(np.maximum(np.cos(np.outer(k, dx)) @ row, 0.0) / m)
    ws = np.sqrt(np.maximum(np.cos(np.outer(k, dy)) @ row, 0.0) / m)
    return kd, wp / (c_p * k), ws / (c_s * k)


def cutoff(kd, ratio, tol):
    """The first k delta at which |ratio - 1| exceeds ``tol`` (the last one if never)."""
    bad = np.flatnonzero(np.abs(ratio - 1.0) > tol)
    return float(kd[bad[0]]) if bad.size else float(kd[-1])


def spectrum_share_above(p, f_c):
    """The share (%) of the radiated P pulse's energy spectrum above ``f_c``: the Ricker
    force's amplitude spectrum (f / f_p)^2 exp(-(f / f_p)^2) times the curl-free
    Gaussian source's k exp(-(k s)^2 / 2) at k = 2 pi f / c_P, squared, integrated."""
    f = np.linspace(0.0, 10.0 * p.peak_frequency, 20001)
    k = 2 * math.pi * f / p.c_p
    amp = (f / p.peak_frequency) ** 2 * np.exp(-(f / p.peak_frequency) ** 2) * k * np.exp(
        -0.5 * (k * p.source_width) ** 2)
    e = amp ** 2
    total = np.trapezoid(e, f)
    return float(100.0 * np.trapezoid(np.where(f >= f_c, e, 0.0), f) / total)


def lowpass(signal, dt, f_c):
    """Zero-phase Butterworth low-pass along axis 1 (time)."""
    from scipy.signal import butter, sosfiltfilt
    nyq = 0.5 / dt
    if f_c >= 0.95 * nyq:
        return signal
    sos = butter(FILTER_ORDER, f_c, fs=1.0 / dt, output="sos")
    return sosfiltfilt(sos, signal, axis=1)


class CondensedSystem:
    """M u'' + K u = r(t) f of a system some of whose free unknowns carry no mass (the
    surface nodes' force-flux rows on free faces: algebraic equations K_ss u_s + K_sk
    u_k = f_s), integrated on the others: u_s = K_ss^-1 (f_s - K_sk u_k) at every step,
    so K_eff = K_kk - K_ks K_ss^-1 K_sk applied as two sparse products and a solve with
    one sparse LU of K_ss (a Schur complement formed once would be dense over every
    face's boundary layer), and f_eff = f_k - K_ks K_ss^-1 f_s. The same attributes as
    :class:`~pdverify.solvers.dynamics.DynamicSystem` for
    :func:`~pdverify.solvers.dynamics.velocity_verlet` (``K`` a
    ``scipy.sparse.linalg.LinearOperator``); ``keep``: the integrated unknowns among the
    system's, ``condensed``: the others."""

    def __init__(self, K, mass, fixed, massless, shape, r):
        import scipy.sparse as sp
        from scipy.sparse.linalg import LinearOperator, splu
        n = K.shape[0]
        K = sp.csr_matrix(K)
        keep = np.setdiff1d(np.arange(n), massless)
        self.keep, self.condensed = keep, np.asarray(massless)
        rows_k, rows_s = K[keep], K[massless]
        Kkk, Kks = rows_k[:, keep], rows_k[:, massless]
        Ksk, Kss = rows_s[:, keep], rows_s[:, massless]
        lu = splu(Kss.tocsc())

        def matvec(u):
            u = np.ravel(u)
            return Kkk @ u - Kks @ lu.solve(Ksk @ u)
        self.K = LinearOperator((keep.size, keep.size), matvec=matvec, dtype=float)
        self.load_shape = shape[keep] - Kks @ lu.solve(shape[massless])
        self.mass = np.where(mass[keep] > 0, mass[keep], 1.0)
        prescribed = np.isin(keep, fixed)
        self.free_mask = ~prescribed
        self.free, self.fixed = np.flatnonzero(~prescribed), np.flatnonzero(prescribed)
        self._r = r
        self._zero = np.zeros(self.fixed.size)

    def load(self, t):
        return self._r(t) * self.load_shape

    def prescribed(self, t):
        return self._zero, self._zero, self._zero

    def stable_step(self, where):
        """2 / omega_max, omega_max^2 the largest-magnitude eigenvalue of M_f^-1 K_eff on
        the free unknowns (ARPACK ``eigs``, tolerance 1e-8; K_eff is not symmetric); a
        complex one refuses the explicit scheme, a negative one the model itself (its
        motion grows exponentially under any integrator). A negative eigenvalue that is
        not the largest in magnitude is not looked for: the integration then overflows,
        which the integrator reports as a failed run."""
        from scipy.sparse.linalg import LinearOperator, eigs

        from ..errors import NumericalError
        from ..solvers.dynamics import StableStep
        nk, free, m = self.K.shape[0], self.free, self.mass[self.free]

        def mv(x):
            full = np.zeros(nk)
            full[free] = np.ravel(x)
            return (self.K @ full)[free] / m
        op = LinearOperator((free.size, free.size), matvec=mv, dtype=float)
        lam = eigs(op, k=1, which="LM", tol=1e-8, return_eigenvectors=False)[0]
        if abs(lam.imag) > 1e-6 * abs(lam):
            raise NumericalError(f"{where}: M^-1 K_eff has the extreme eigenvalue {lam:.6g}"
                                 " (complex); no explicit step is stable")
        if lam.real < 0:
            raise NumericalError(
                f"{where}: with the massless unknowns condensed, M^-1 K_eff has the "
                f"eigenvalue {lam.real:.3g} s^-2 (negative, its largest in magnitude): "
                "the semi-discrete motion grows as exp(t / "
                f"{1e6 / math.sqrt(-lam.real):.2g} us) under any integrator")
        w = float(np.sqrt(lam.real))
        return StableStep(2.0 / w, w, "ARPACK eigs on M^-1 K_eff (massless unknowns "
                          "condensed per step)", 0.0)


def pulse_system(system, density, wavelet, shape, where):
    """``(dynamic system, integrated unknowns)`` of a treatment's ``system``: as
    :func:`~pdverify.scenes.waves.dynamic_system` builds it (nothing prescribed moves,
    the load r(t) ``shape``), or, when free unknowns carry no mass and the system is
    otherwise of masses, a :class:`CondensedSystem`."""
    from ..solvers.front import displacement_form
    from .waves import dynamic_system
    n = system.dofs
    g = system.model.grid
    per_node = np.zeros(system.n_unknown_nodes)
    per_node[:g.n_interior] = density * system.model.node_volume[g.interior_ids]
    mass = np.tile(per_node, system.dim)
    free = np.setdiff1d(np.arange(n), system.fixed)
    massless = free[mass[free] == 0]
    if not massless.size or system.B is not None or system.offset is not None:
        return dynamic_system(system, density, np.zeros(n), wavelet, shape, where), \
            np.arange(n)
    K, _ = displacement_form(system)
    dyn = CondensedSystem(K[:n, :n], mass, system.fixed, massless, shape, wavelet[0])
    return dyn, dyn.keep


@register
class Wave2DPulse(FemStaticStateScene):
    """A pulse in a plane-strain plate reflecting from a fixed edge, a free edge and a
    corner (ours; issue 56): PD treatments in dynamics against a converged FEM.

    The body and load (``reference_fem.wave_plate``, stated once there): plate [0, 2] x
    [0, 1.6] m, plane strain, E = 200 GPa, nu = 0.25, rho = 7850 kg/m^3; the edge x = 0
    fixed (``x-`` prescribes both components at 0), the others free; a curl-free
    Gaussian body force (s = 0.08 m) at (1, 0.8) m times a Ricker wavelet of peak
    wavelength c_P / f_p = 0.4 m; receivers 0.25 m from the fixed edge, the free edge and
    the free-free corner. FEM (``fem``): Q2 elements with lumped mass and the central
    difference, three levels (edges 0.1, 0.05, 0.025 m, the step with the edge) and the
    finest at half its step; the docstring of ``reference_fem.wave_plate`` quotes the
    changes.

    PD: the state-based plane-strain model (seed 001 §5's constants), Gaussian
    influence, h = 0.01 m, m = 3 (delta = 0.03 m: the peak wavelength is 13 delta), the
    body force applied by each treatment as it applies a body force (its own load
    vector of b at the nodes), the mass rho V_i lumped on the real nodes; velocity Verlet
    at the largest step T / (n0 j) within ``dt_factor`` of the explicit limit 2 /
    omega_max (n0 the FEM's base step count, so that the FEM's stored fields fall on PD
    steps).

    Where PD and classical agree (the metric's band): PD's phase velocity from the run's
    own operator (the symbol of a central node's row, :func:`dispersion`) against c_P
    and c_S along x; ``cutoff_kdelta`` is the first k delta where the longitudinal
    branch departs from c_P by more than ``dispersion_tol`` (1 %), and the receiver
    signals (PD's and FEM's alike) are low-passed at f_c = c_P k_c / 2 pi (a
    zero-phase Butterworth of order 4). The source is curl-free, so the direct and the
    reflected P-P pulses are longitudinal; the S waves converted at the edges reach the
    transverse branch's 1 % departure at a lower frequency (``cutoff_kdelta_s``, stated,
    not filtered). ``spectrum_above_cutoff_pct``: the share of the radiated pulse's
    energy spectrum above f_c (the Ricker force's times the source's).

    Metrics: per receiver (``fixed``, ``free``, ``corner``) in the window of its
    feature's reflected P rays (``reference_fem``: from half a period before the first
    to a period after the last): ``<r>_arrival_error_pct`` = (t_PD - t_FEM) over the
    FEM's travel time t_FEM - t_0 (t the time of the largest filtered |u| in the window,
    refined by a parabola; t_0 the wavelet's centre), ``<r>_amplitude_error_pct`` = the
    largest filtered |u| in the window, PD over FEM - 1 (in %);
    ``receiver_max_error_pct`` = max over receivers and time of the filtered |u_PD -
    u_FEM| over max |u_FEM|; ``field_max_error_pct`` / ``field_rel_l2_error``: the whole
    field at the FEM's stored times (unfiltered; nodes within 3 s of the source left
    out, the load zone) over the largest |u_FEM| there, max over time, with
    ``boundary_max_error_pct`` within one horizon of the surface and
    ``interior_max_error_pct`` beyond it; ``energy_balance_pct``
    = max over the steps of |E_kin + E_strain - W| over max (E_kin + E_strain) (W: the
    load's work, trapezoidal: second order in dt); ``dt``, ``dt_limit``, ``n_steps``.

    Findings at h = 0.01 m (measured, not tuned; PALS too, run once there): the
    reflections of ``none``, ``energy``, ``volume`` and ``pals`` arrive within 0.5 % of
    the FEM's travel time (fixed edge -0.46 to {{none_fixed}} %, free edge 0.11 to
    {{volume_free}} %, corner 0.26 to {{volume_corner}} %), well inside the 1 % the
    dispersion band allows, their amplitudes within 0.6-2.3 %; ``energy-directional``
    (seed 003's bond-based factor on this state-based lattice) is the outlier,
    {{edir_fixed}} % at the fixed edge and {{edir_interior}} % field error in the
    interior. The largest field error of ``none``, ``energy`` and ``volume`` (11 %
    alike) sits on the node layer next to the fixed edge, which each holds at zero half
    a spacing inside the edge (``interior_max_error_pct`` leaves that layer out); the
    energy balance (0.94 %) is Verlet's, the same for those three, and falls by 4 per
    step halving. Cost (benchmarks/wave_pulse_cost.py, under load 4x): the scene's full
    runs 20 s of CPU warm, 25 s cold (the FEM study), --quick 6 s; 0.82 GB at most.

    Treatments: the uncorrected model and the bond methods (``energy``,
    ``energy-directional``, ``volume``, ``pals``; PALS at twice the spacing, :meth:`cases`), and surface nodes (seed 002's
    form): on the free edges their unknowns are the force-flux equations' and carry no
    mass, so they are condensed at every step (:class:`CondensedSystem`; the condensed
    static system reproduces the full one's solution to 2e-11). Finding: the condensed
    operator is not stable in time. At h = 0.02 (order 1) M^-1 K_eff has real
    eigenvalues down to -3.9e11 s^-2 (order 2: -8.4e10), beside the largest positive
    1.9e11: modes that grow as exp(t / 1.6 us), under any integrator; the run fails
    naming that eigenvalue. (With every face prescribed, as in the manufactured boxes,
    no unknown is condensed and the surface nodes carry over.)
    """

    id = "wave2d-pulse"
    #: the report's error for this scene: the receivers' low-passed signals against the
    #: FEM's, the wavelengths where PD and classical agree (class docstring)
    headline = "receiver_max_error_pct"
    #: the compact table beside it (report.html): the reflections' arrival errors and
    #: Verlet's energy balance
    table_metrics = ("fixed_arrival_error_pct", "corner_arrival_error_pct",
                     "energy_balance_pct")
    #: the numbers the docstring quotes from this report's runs (pdverify.quotes)
    doc_quotes = {k: Q(metric, method, {"spacing": 0.01}, ".2g") for k, metric, method in (
        ("none_fixed", "fixed_arrival_error_pct", "none"),
        ("volume_free", "free_arrival_error_pct", "volume"),
        ("volume_corner", "corner_arrival_error_pct", "volume"),
        ("edir_fixed", "fixed_arrival_error_pct", "energy-directional"),
        ("edir_interior", "interior_max_error_pct", "energy-directional"))}
    title = "A pulse in a plate: reflections from a fixed edge, a free edge and a corner (2D, FEM reference)"
    seed = "ours (issue 56; seed 002's extension)"
    figure = "wave-pulse"
    dim = 2
    kind = "plane-strain"
    params_class, function = "PulseParams", "plate_pulse"
    shared = ("length", "width", "E", "nu", "rho", "source_x", "source_y", "source_width",
              "wavelength", "body_force", "receiver_offset", "duration")
    pd_params = (
        *grid_params(0.01, 3.0),
        QUADRATURE,
        INFLUENCE,
        Param("dt_factor", SAFETY, "largest step over the explicit limit 2/omega_max",
              open_interval(0.0, 1.0)),
        Param("dispersion_tol", 0.01, "PD's departure from the classical P velocity that "
              "sets the receivers' low-pass cut-off", open_interval(0.0, 1.0)),
    )
    baseline_params = ()
    #: the surface nodes' condensed operator grows exponentially (class docstring)
    expected_failures = (
        ExpectedFailure("with their force-flux rows on the free edges condensed, the "
                        "surface nodes' operator has negative eigenvalues (down to "
                        "-3.9e11 s^-2 at h = 0.02): its motion grows exponentially under "
                        "any integrator (our finding, issue 56)", method="surface-nodes"),)
    quick_spacing = 0.02

    def box(self, p):
        return (p["length"], p["width"]), (0.0, 0.0)

    def family_refusal(self, treatment) -> str | None:
        why = super().family_refusal(treatment)
        if why is None and treatment.static_only:
            why = f"static only: {treatment.static_only}"
        return why

    def pulse(self, p):
        """The reference's parameter record (its source, wavelet, receivers, windows)."""
        from .fem_references import reference_module
        return reference_module().PulseParams(**self.reference_params(p))

    def check_pd(self, where, method, p):
        whole_cells(where, p["spacing"], [(k, p[k]) for k in ("length", "width")])
        for name in ("E", "rho", "duration", "source_width", "wavelength"):
            if not (np.isfinite(p[name]) and p[name] > 0):
                raise InputError(f"{where}: {name}={p[name]!r} must be a finite number > 0")
        if not -1.0 < p["nu"] < 0.5:
            raise InputError(f"{where}: nu={p['nu']!r} must be in (-1, 0.5)")

    def problem(self, p, where):
        inf = get_influence(p["influence"])
        q = self.pulse(p)

        def body(x):
            bx, by = q.body_force_shape(x[:, 0], x[:, 1])
            return np.c_[bx, by]
        return StaticProblem(
            (p["length"], p["width"]), (0.0, 0.0), float(p["spacing"]),
            state_based_stencil(2, p["m_ratio"], p["spacing"], inf, p["quadrature"]),
            StateBasedConstants("plane-strain", p["E"], p["nu"]), inf,
            {"x-": FaceCondition(prescribed=(0, 1))}, exact=np.zeros_like,
            body_force=body, solver="direct", where=where)

    def estimate(self, method, p):
        """The FEM study's (``fem``, and before a PD run unless cached) or the PD run's:
        an explicit integration factors nothing, so K's non-zeros (twice: the assembly's
        intermediate and the operator; measured 0.75 GB at h = 0.01 for ``none`` against
        1.9 GB estimated) and the displacement at every step."""
        if method == FEM.name:
            return FemReference.estimate(self, method, p)
        fem = FemReference.estimate(self, FEM.name, self.reference_params(p))
        cells = [p[k] / p["spacing"] for k in ("length", "width")]
        nodes = math.prod(cells)
        # the explicit limit is 1.8 h / c_P on this lattice (measured at m = 3, h = 0.02:
        # 6.6 us); 1.5 for a margin, c_P of the run's moduli
        lam = p["E"] * p["nu"] / ((1 + p["nu"]) * (1 - 2 * p["nu"]))
        c_p = math.sqrt((lam + p["E"] / (1 + p["nu"])) / p["rho"])
        steps = budget.step_count(p["duration"] * c_p / (1.5 * p["dt_factor"] * p["spacing"]))
        samples = 8.0 * (steps + 1) * 2 * nodes
        pd = budget.iterative_system(nodes, 2, 2, 2 * p["m_ratio"], extra_bytes=samples)
        return budget.larger(pd, fem) + budget.Estimate(
            0.0, f"explicit: ~{steps:.3g} time steps over {max(cells):.0f} cells", steps)

    def extra_fields(self, res, fields):
        fields.update({"times": res.times, "receivers": res.receivers,
                       "receiver_points": res.receiver_points, "windows": res.windows,
                       "energy": res.energy})
        return fields

    def solve(self, method, p, timer):
        if method == FEM.name:
            return FemReference.solve(self, method, p, timer)
        from ..corrections.registry import plugin_call
        where = f"{self.id}/{method}"
        with timer.phase("reference"):
            ref = self.reference_of(p)
        q = self.pulse(p)
        with timer.phase("setup"):
            problem = self.problem(p, where)
            t = self.treatment(method)
            system = plugin_call(t, "assemble", t.assemble, problem, p)
            from ..solvers.front import displacement_form
            K, rhs = displacement_form(system)
            n = system.dofs
            dyn, keep = pulse_system(system, p["rho"], ricker(q), rhs[:n], where)
            limit = (dyn.stable_step(where) if isinstance(dyn, CondensedSystem)
                     else stable_step(dyn, where=where))
            n0 = q.base_steps()
            T = p["duration"]
            j = max(1, math.ceil(T / (n0 * p["dt_factor"] * limit.dt_limit)))
            steps = n0 * j
            dt = T / steps
            snap = np.rint(ref.snapshot_times / dt).astype(int)
        with timer.phase("solve"):
            nk = keep.size
            run = velocity_verlet(dyn, np.zeros(nk), np.zeros(nk), dt, steps,
                                  sample_steps=np.arange(steps + 1), where=where,
                                  limit=limit)
            if nk < n:       # the condensed unknowns (surface nodes) are not measured
                full = np.zeros((run.u.shape[0], n))
                full[:, keep] = run.u
                run.u = full
        return self.measure_pulse(p, q, ref, system, K, run, snap, limit)

    def measure_pulse(self, p, q, ref, system, K, run, snap, limit):
        """Metrics (class docstring) of one trajectory."""
        from scipy.interpolate import CubicSpline

        from reference_fem.wave_plate import window_peaks
        g = system.model.grid
        d, nu_, ni = g.dim, system.n_unknown_nodes, g.n_interior
        x = g.x[g.interior_ids]
        times = run.times
        U = run.u.reshape(len(times), d, nu_)[:, :, :ni]          # (nt, d, ni)
        # receivers: the lattice's displacement interpolated bilinearly to the points
        h = p["spacing"]
        nx, ny = round(p["length"] / h), round(p["width"] / h)
        order = np.lexsort((x[:, 1], x[:, 0]))                     # x-major, as 'ij'
        grid = U[:, :, order].reshape(len(times), d, nx, ny)
        pd_rec = np.empty((len(RECEIVERS), len(times), d))
        for k, (px, py) in enumerate(ref.receiver_points):
            fx, fy = px / h - 0.5, py / h - 0.5
            i0, j0 = int(math.floor(fx)), int(math.floor(fy))
            ax, ay = fx - i0, fy - j0
            pd_rec[k] = ((1 - ax) * (1 - ay) * grid[:, :, i0, j0]
                         + ax * (1 - ay) * grid[:, :, i0 + 1, j0]
                         + (1 - ax) * ay * grid[:, :, i0, j0 + 1]
                         + ax * ay * grid[:, :, i0 + 1, j0 + 1])
        fem_rec = CubicSpline(ref.times, ref.receivers, axis=1)(times)
        # the band where PD and classical agree
        vol = system.model.node_volume[g.interior_ids]
        centre = int(np.argmax(g.distance_to_surface(x)))
        kd, rp, rs = dispersion(K, x, vol, p["rho"], centre, system.model.horizon,
                                q.c_p, q.c_s)
        kc, kc_s = cutoff(kd, rp, p["dispersion_tol"]), cutoff(kd, rs, p["dispersion_tol"])
        f_c = q.c_p * kc / system.model.horizon / (2 * math.pi)
        dt = times[1] - times[0]
        pd_f, fem_f = lowpass(pd_rec, dt, f_c), lowpass(fem_rec, dt, f_c)
        pd_peaks = window_peaks(times, pd_f, ref.windows)
        fem_peaks = window_peaks(times, fem_f, ref.windows)
        scale = np.max(np.linalg.norm(fem_f, axis=2))
        metrics = {"receiver_max_error_pct": float(
            100 * np.max(np.linalg.norm(pd_f - fem_f, axis=2)) / scale)}
        for k, name in enumerate(RECEIVERS):
            travel = fem_peaks[k, 0] - q.delay
            metrics[f"{name}_arrival_error_pct"] = float(
                100 * (pd_peaks[k, 0] - fem_peaks[k, 0]) / travel)
            metrics[f"{name}_amplitude_error_pct"] = float(
                100 * (pd_peaks[k, 1] / fem_peaks[k, 1] - 1.0))
        # the field at the FEM's stored times, away from the load
        away = np.linalg.norm(x - q.source_point(), axis=1) > 3 * q.source_width
        near = g.distance_to_surface(x) <= system.model.horizon
        u_pd = U[snap].transpose(0, 2, 1)[:, away]                   # (ns, n_away, d)
        u_fem = np.array([ref.snapshot(k).evaluate(x[away])
                          for k in range(len(ref.snapshot_times))])
        fscale = float(np.max(np.linalg.norm(u_fem, axis=2)))
        err = np.linalg.norm(u_pd - u_fem, axis=2) / fscale * 100.0  # (ns, n_away)
        metrics.update({
            "field_max_error_pct": float(err.max()),
            "boundary_max_error_pct": float(err[:, near[away]].max()),
            "interior_max_error_pct": float(err[:, ~near[away]].max()),
            "field_rel_l2_error": float(np.max(
                np.linalg.norm((u_pd - u_fem).reshape(len(snap), -1), axis=1))
                / np.max(np.linalg.norm(u_fem.reshape(len(snap), -1), axis=1))),
            "energy_balance_pct": 100.0 * run.energy_balance(),
            "cutoff_kdelta": kc, "cutoff_kdelta_s": kc_s, "cutoff_frequency": f_c,
            "spectrum_above_cutoff_pct": spectrum_share_above(q, f_c),
            "reference_change_pct": float(ref.receiver_change_pct),
            "dt": float(run.info["dt"]), "dt_limit": float(limit.dt_limit),
            "n_steps": int(run.info["n_steps"]),
        })
        diagnostics = dict(run.info)
        diagnostics.update({"fem_arrivals_s": fem_peaks[:, 0].tolist(),
                            "pd_arrivals_s": pd_peaks[:, 0].tolist(),
                            "fem_amplitudes_m": fem_peaks[:, 1].tolist(),
                            "pd_amplitudes_m": pd_peaks[:, 1].tolist()})
        err_full = np.full((len(snap), len(x)), np.nan)
        err_full[:, away] = err
        fields = {"x": x, "times": times, "receivers": pd_f, "fem_receivers": fem_f,
                  "windows": ref.windows, "energy": run.energy,
                  "snapshot_times": ref.snapshot_times, "error": err_full,
                  "spacing": p["spacing"], "horizon": system.model.horizon,
                  "lengths": (p["length"], p["width"]),
                  "dispersion": {"kdelta": kd, "p_ratio": rp, "s_ratio": rs}}
        size = self.size(system)
        size["operator_nnz"] = int(K.nnz)
        from . import Outcome
        return Outcome(metrics=metrics, size=size, fields=fields, diagnostics=diagnostics)

    def cases(self, quick=False):
        """Every treatment offered at the default grid (quick: twice the spacing); PALS at twice
        the spacing of the others, beside ``none`` there (PALS's operator has 4x the
        non-zeros and its assembly solves the influence functions' constraint rows: at
        h = 0.01 it took 77 s of setup and 2.05 GB under load, past the scene's budget;
        in --quick at 0.04 m a smoke run only, its horizon 0.12 m a third of the peak
        wavelength: its errors there are not PALS's at a usable grid)."""
        h = self.quick_spacing if quick else self.default_params()["spacing"]
        runs = [(m, {"spacing": h} if quick else {})
                for m in ("none", "energy", "energy-directional", "volume", "surface-nodes")]
        coarse = {"spacing": 2 * h}
        extra = [("pals", coarse)] + ([] if quick else [("none", coarse)])
        return [("fem", {})] + runs + extra
