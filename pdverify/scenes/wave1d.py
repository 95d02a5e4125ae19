"""Seed 002: a Gaussian pulse in a fixed-fixed PD bar, surface nodes against the analytic PD series."""
from __future__ import annotations

import numpy as np

from manufactured import wave1d as analytic

from ..errors import InputError
from ..metrics import max_error_of_peak_pct, rel_l2_error
from ..micromodulus1d import WaveBar1D
from ..params import Param, at_least, positive
from ..solvers.explicit import central_difference
from . import MethodSpec, Outcome, Published, Scene, register

#: The instants of Fig. 5 at which the error is measured [s].
SAMPLE_TIMES = (0.05e-3, 0.10e-3, 0.15e-3, 0.20e-3)

SURFACE_NODES = MethodSpec("surface-nodes", (
    Param("order", 1, "Taylor order of the fictitious-node extrapolation (1 = Eqs. 8-9)",
          at_least(1)),))
NONE = MethodSpec("none")


@register
class Wave1DSurfaceNodes(Scene):
    """Seed 002: elastic wave in a 1D bond-based PD bar, Eqs. (3)-(12), l = 1 m, delta = 0.1 l.

    Problem (Eq. 10): u(x, 0) = 0.02 exp(-100 (x - l/2)^2), zero initial velocity,
    u(0, t) = u(l, t) = 0; v = sqrt(E / rho) = 5000 m/s; dt = 2e-7 s up to T = 0.2 ms.
    Discretisation: Eq. (3) with partial volumes (beta = 1/2 at the horizon, ERRATA), real
    nodes at cell centres (N = l m / delta), explicit central differences, Eqs. (4)-(7).
    Reference: the separation-of-variables series of Eqs. (11)-(12) with the corrected time
    factor cos(v sqrt(psi) t) and coefficients by projection (``manufactured.wave1d``,
    ERRATA seed 002); ``n_terms`` counts the modes m = 1..n_terms.

    Methods. ``surface-nodes``: Dirichlet on surface nodes at x = 0 and l, fictitious layer
    of depth delta extrapolated about the nearest surface node (order 1 = Eqs. 8-9).
    ``none``: truncated neighbourhoods, the first and last real node (Delta/2 from the
    ends) held at u = 0.

    Metrics: ``max_error_pct`` = max |u - u_PD| over the real nodes and the instants
    0.05, 0.10, 0.15, 0.20 ms, in % of the pulse peak 0.02 m; ``boundary_error_pct`` the
    same over nodes within 2 delta of an end; ``rel_l2_error`` over all nodes and instants;
    ``classical_gap_pct`` = max |u_PD - u_classical| at the same points (the dispersion that
    makes the classical series unfit as a reference, Fig. 5).

    Choices where the paper is silent: the pulse is centred at l/2 for any l; the errors
    are sampled at the time steps nearest the four instants and compared with the series at
    those step times (exact for the default dt); T = 0.2 ms is fixed; ``none`` fixes the
    nodes nearest the ends at zero (the paper shows no uncorrected run); a dt above the
    central-difference limit 2 / sqrt(lambda_max) of the discrete operator fails the run
    with that limit named (lambda_max by ARPACK; for the symmetric ``none`` operator a
    Gershgorin bound first, sharpened only when the step exceeds it).

    Findings: the error falls at first order in 1/m because the one-point quadrature of
    Eq. (3) leaves out the node's own cell (psi - psi_h = k^2 / (2m), see
    ``micromodulus1d.lattice_symbol``). Order-1 extrapolation is not the odd extension the
    analytic series implies (``WaveBar1D(boundary="odd-image")``): the two discrete solutions
    differ by about 0.27-0.28 % of the peak at m = 25 and 100 alike (order 2: 0.11-0.09 %).
    That gap is below the quadrature error for m <= 100, so the paper's convergence shows,
    but it bounds it beyond a few hundred (at m = 400 the order-1 error, 0.33 %, already
    exceeds the odd image's, 0.26 %). Higher orders stiffen the fictitious layer: at
    m = 100 order 3 needs dt < 7.4e-8 s and the default dt fails the run.
    """

    id = "wave1d-surface-nodes"
    title = "1D elastic wave, fixed ends: surface nodes vs analytic PD series"
    seed = "002"
    reference = "analytic"
    figure = "wave1d"
    params = (
        Param("length", 1.0, "bar length l [m]", positive),
        Param("horizon", 0.1, "horizon delta [m] (0.1 l)", positive),
        Param("E", 200e9, "Young's modulus [Pa]", positive),
        Param("rho", 8000.0, "density [kg/m^3]", positive),
        Param("m_ratio", 10, "m-ratio delta / Delta (the paper uses 10, 25, 100)", at_least(1)),
        Param("dt", 2e-7, "time step [s]", positive),
        Param("n_terms", 40, "modes m = 1..n_terms of the analytic series", at_least(1)),
    )
    methods = (SURFACE_NODES, NONE)
    published = (
        Published("max_error_pct", "decreases with m, no number printed", "seed 002 Fig. 5",
                  method="surface-nodes"),
    )

    def check(self, method, p):
        where = f"{self.id} --method {method}"
        if p["horizon"] > p["length"] / 2:
            raise InputError(f"{where}: horizon={p['horizon']} must be <= length/2 = "
                             f"{p['length'] / 2:g}")
        n = p["length"] * p["m_ratio"] / p["horizon"]
        if abs(n - round(n)) > 1e-9 * n:
            raise InputError(f"{where}: m_ratio={p['m_ratio']} gives spacing "
                             f"{p['horizon'] / p['m_ratio']:g} m, which must divide "
                             f"length={p['length']} into whole cells")
        if p["dt"] > SAMPLE_TIMES[0]:
            raise InputError(f"{where}: dt={p['dt']} must be <= {SAMPLE_TIMES[0]:g} s "
                             "(the first sampled instant)")
        if method == SURFACE_NODES.name and 2 * (p["order"] + 1) > round(n):
            raise InputError(f"{where}: order={p['order']} needs 2 (order + 1) <= "
                             f"{round(n)} real nodes (order <= {round(n) // 2 - 1})")

    def cases(self, quick=False):
        if quick:
            return ([("surface-nodes", {"m_ratio": m}) for m in (10, 25)]
                    + [("none", {"m_ratio": 25})])
        ms = (10, 25, 100)
        return ([("surface-nodes", {"m_ratio": m}) for m in ms]
                + [("none", {"m_ratio": m}) for m in ms]
                + [("surface-nodes", {"m_ratio": m, "order": 2}) for m in ms])

    def solve(self, method, p, timer):
        length, horizon = p["length"], p["horizon"]
        wave_speed = float(np.sqrt(p["E"] / p["rho"]))
        with timer.phase("setup"):
            bar = WaveBar1D(length, horizon, float(p["m_ratio"]), wave_speed,
                            boundary=method, taylor_order=p.get("order", 1))
            u0 = analytic.gaussian_pulse(bar.x_free, length=length)
            steps = [int(round(t / p["dt"])) for t in SAMPLE_TIMES]
        with timer.phase("solve"):
            run = central_difference(-bar.A, u0, 0.0, p["dt"], steps[-1], sample_steps=steps,
                                     where=f"{self.id}/{method} (m_ratio={p['m_ratio']})")
        x = bar.x_real
        u = bar.real_displacements(run.u)
        pd = analytic.wave_series(horizon=horizon, wave_speed=wave_speed, length=length,
                                  n_terms=p["n_terms"])
        cl = analytic.wave_series(horizon=0.0, wave_speed=wave_speed, length=length,
                                  n_terms=p["n_terms"])
        u_ref = pd.displacement(x, run.times)
        u_cl = cl.displacement(x, run.times)
        peak = analytic.PULSE_PEAK
        near = (x <= 2 * horizon) | (x >= length - 2 * horizon)
        metrics = {
            "max_error_pct": max_error_of_peak_pct(u, u_ref, peak),
            "boundary_error_pct": max_error_of_peak_pct(u[:, near], u_ref[:, near], peak),
            "rel_l2_error": rel_l2_error(u, u_ref),
            "classical_gap_pct": max_error_of_peak_pct(u_cl, u_ref, peak),
        }
        diagnostics = dict(run.info)
        diagnostics.update({"sample_times": run.times, "wave_speed": wave_speed,
                            "spacing": bar.spacing, "series_tail": pd.tail,
                            "boundary_nodes": int(near.sum())})
        fields = {"x": x, "times": run.times, "u": u, "u_ref": u_ref, "u_classical": u_cl,
                  "horizon": horizon, "length": length, "peak": peak,
                  "wave_speed": wave_speed, "n_terms": p["n_terms"]}
        return Outcome(metrics=metrics, size=bar.size(), fields=fields, diagnostics=diagnostics)
