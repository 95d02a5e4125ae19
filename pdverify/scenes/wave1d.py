"""Seed 002: a Gaussian pulse in a fixed-fixed PD bar, surface nodes against the analytic PD series.

The scene is a description (:func:`wave_problem`: a
:class:`~pdverify.pd.problem.BondProblem` of the bar with both end faces held, family
``wave-bar``) that the wave family's assembly (:func:`~pdverify.pd.problem.assemble_wave`)
turns into an explicit-dynamics system under the treatment's extension; the scene then
steps it and measures. It is not a static bond system (:func:`~pdverify.pd.problem.
assemble_bonds`): the family's unknowns evolve in time, the end values act through the
operator's boundary columns ``A_bc``, and its treatments give a fictitious layer's
extension (their ``wave-bar`` role), not a closure of the bonds.
"""
from __future__ import annotations

import numpy as np

from manufactured import wave1d as analytic

import scipy.sparse as sp

from .. import budget
from ..errors import InputError, NumericalError
from ..metrics import max_error_of_peak_pct, rel_l2_error
from ..params import Param, at_least, horizon_param, m_ratio_param, positive, youngs_modulus
from ..pd import bond_micromodulus, build_stencil, get_influence
from ..pd.build import Body, BondMaterial
from ..pd.problem import BondProblem, PartCondition, WaveSystem, assemble_wave
from ..pd.closure import real_identity, with_rows
from ..solvers.explicit import central_difference
from . import Outcome, Published, Scene, cell_count, register
from .base import truncation_problem

#: The instants of Fig. 5 at which the error is measured [s].
SAMPLE_TIMES = (0.05e-3, 0.10e-3, 0.15e-3, 0.20e-3)


def lattice_symbol(k, *, horizon: float, m_ratio: float):
    """psi_h(k): the discrete operator of Eq. (3) on an unbounded grid maps sin(kx) to -v^2 psi_h sin(kx).

    psi_h = 2/delta sum_j beta_j Delta (1 - cos(k xi_j)) / xi_j^2, the one-point quadrature of
    psi (Eq. 12). The quadrature omits the node's own cell, where the integrand of Eq. (12)
    is k^2/2, so psi - psi_h = k^2 / (2 m) + O(m^-2) at fixed delta: first-order
    m-convergence.
    """
    stencil = build_stencil(1, m_ratio)
    spacing = horizon / m_ratio
    xi = stencil.half_offsets[:, 0] * spacing
    c = stencil.half_beta * spacing / (horizon * xi ** 2)
    k = np.asarray(k, dtype=float)
    return np.sum(2.0 * c * (1.0 - np.cos(np.multiply.outer(k, xi))), axis=-1)


def wave_problem(length, horizon, m_ratio, wave_speed) -> BondProblem:
    """A bar [0, l] of 1D bond-based PD (seed 002 Eq. 3), both ends held (u = 0).

    The engine's bond-based model with the hyperbolic influence delta/|xi| and the
    micromodulus c = v^2 / delta^2 of energy equivalence (rho = 1, unit area), so that
    -(K u)_i / V_i = sum_j v^2 beta_j Delta (u_j - u_i) / (delta xi^2) is Eq. (3). Real
    nodes sit at the cell centres x_i = (i - 1/2) Delta, i = 1..N, Delta = delta / m
    (Fig. 2; N = 100, 250, 1000 for m = 10, 25, 100)."""
    spacing = horizon / m_ratio
    n = length / spacing
    if abs(n - round(n)) > 1e-9 * n:
        raise ValueError(f"spacing {spacing} does not divide length {length}")
    material = BondMaterial(bond_micromodulus("hyperbolic", 1, wave_speed ** 2, horizon),
                            get_influence("hyperbolic"))
    held = PartCondition({0: 0.0})
    return BondProblem(Body((length,), (0.0,), spacing), build_stencil(1, m_ratio), material,
                       horizon, {"x-": held, "x+": held}, wave_speed ** 2, None, "bar",
                       family="wave-bar")


def wave_bar(length, horizon, m_ratio, wave_speed, extension) -> WaveSystem:
    """:func:`wave_problem` assembled with a treatment's ``extension`` (its ``wave-bar``
    role: surface nodes at x = 0 and x = l carry the end values, seed 002 Figs. 3-4;
    :func:`odd_image`) or ``None`` (truncated neighbourhoods, the first and last real
    node held); see :func:`~pdverify.pd.problem.assemble_wave`."""
    return assemble_wave(wave_problem(length, horizon, m_ratio, wave_speed), extension)


def odd_image(grid):
    """The extension the sine series of Eq. (11) implies, u(x_s - xi) = 2 u_s - u(x_s +
    xi), which isolates the quadrature error from the extrapolation's model error:
    fictitious node at -(j + 1/2) Delta (and its mirror at the right end) from 2 u_s -
    u_j, unknowns [real u (N), surface values (2)]."""
    nr, nf = grid.n_interior, grid.layers
    j = np.arange(nf)
    left = np.flatnonzero(grid.index[:, 0] < 0)[::-1]      # -(j + 1/2) Delta, j = 0..
    right = np.flatnonzero(grid.index[:, 0] >= nr)          # l + (j + 1/2) Delta
    rows = np.r_[left, left, right, right]
    cols = np.r_[j, np.full(nf, nr), nr - 1 - j, np.full(nf, nr + 1)]
    vals = np.r_[-np.ones(nf), np.full(nf, 2.0), -np.ones(nf), np.full(nf, 2.0)]
    block = sp.csr_matrix((vals, (np.arange(rows.size), cols)), shape=(rows.size, nr + 2))
    return with_rows(real_identity(grid, nr + 2), rows, block)


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
    ``lattice_symbol``). Order-1 extrapolation is not the odd extension the
    analytic series implies (``wave_bar(..., extension=odd_image)``): the two discrete solutions
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
    closed_to_treatments = ("bond-based 1D waves whose reference is the PD series of the "
                            "same model at the same delta: only the seed-002 treatments "
                            "are wired to its explicit time stepping")
    dim = 1
    params = (
        Param("length", 1.0, "bar length l [m]", positive),
        horizon_param(0.1, "0.1 l"),
        youngs_modulus(200e9),
        Param("rho", 8000.0, "density [kg/m^3]", positive),
        m_ratio_param(10, least=1, note="the paper uses 10, 25, 100"),
        Param("dt", 2e-7, "time step [s]", positive),
        Param("n_terms", 40, "modes m = 1..n_terms of the analytic series", at_least(1)),
    )
    #: the treatments with a role here (the baseline and surface nodes) give the bar's
    #: fictitious extension
    family = "wave-bar"
    published = (
        Published("max_error_pct", "decreases with m, no number printed", "seed 002 Fig. 5",
                  method="surface-nodes", kind="read off a figure"),
    )

    def estimate(self, method, p):
        m = p["m_ratio"]
        nodes = p["length"] * m / p["horizon"] + 1 + 2 * m
        steps = budget.step_count(SAMPLE_TIMES[-1] / p["dt"])
        series = 8.0 * p["n_terms"] * nodes * (len(SAMPLE_TIMES) + 1)
        return budget.linear_system(nodes, 1, 1, m, extra_bytes=series) + budget.Estimate(
            0.0, f"{steps:.3g} time steps, {p['n_terms']} series terms", steps)

    def check(self, method, p):
        where = f"{self.id} --method {method}"
        if p["horizon"] > p["length"] / 2:
            raise InputError(f"{where}: horizon={p['horizon']} must be <= length/2 = "
                             f"{p['length'] / 2:g}")
        n = cell_count(where, p["horizon"] / p["m_ratio"], "length", p["length"],
                       "horizon/m_ratio")
        if abs(n - round(n)) > 1e-9 * n:
            raise InputError(f"{where}: m_ratio={p['m_ratio']} gives spacing "
                             f"{p['horizon'] / p['m_ratio']:g} m, which must divide "
                             f"length={p['length']} into whole cells")
        if p["dt"] > SAMPLE_TIMES[0]:
            raise InputError(f"{where}: dt={p['dt']} must be <= {SAMPLE_TIMES[0]:g} s "
                             "(the first sampled instant)")
        self.treatment(method).check_for(self.family, round(n), p, where)

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
            extension = self.treatment(method).build_for(self.family, None, p)
            bar = wave_bar(length, horizon, float(p["m_ratio"]), wave_speed, extension)
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
        # the series' own truncation (manufactured.wave1d.truncation_estimate), in % of the
        # peak like the errors; the classical gap subtracts two series, so twice it
        tail_pct = 100.0 * pd.tail / peak
        diagnostics = dict(run.info)
        diagnostics.update({"sample_times": run.times, "wave_speed": wave_speed,
                            "spacing": bar.spacing, "series_tail": pd.tail,
                            "series_truncation_pct": tail_pct,
                            "boundary_nodes": int(near.sum())})
        fields = {"x": x, "times": run.times, "u": u, "u_ref": u_ref, "u_classical": u_cl,
                  "horizon": horizon, "length": length, "peak": peak,
                  "wave_speed": wave_speed, "n_terms": p["n_terms"]}
        out = Outcome(metrics=metrics, size=bar.size(), fields=fields, diagnostics=diagnostics)
        problem = truncation_problem(
            f"the reference series (n_terms={p['n_terms']}; omitted modes ~{tail_pct:.3g} % "
            "of the peak)", tail_pct,
            {"max_error_pct": metrics["max_error_pct"],
             "boundary_error_pct": metrics["boundary_error_pct"],
             "classical_gap_pct / 2": metrics["classical_gap_pct"] / 2},
            "raise n_terms (40 is below 1e-8 %)")
        if problem:
            raise NumericalError(problem, partial=out)
        return out
