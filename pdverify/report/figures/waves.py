"""Figures of the manufactured 2D and 3D waves: error against time per treatment, the energy balance, and the time convergence."""
from __future__ import annotations

import matplotlib.pyplot as plt
import numpy as np

from . import distinct_labels, family, legend_outside, save


def _curves(ax, runs, value, ylabel, log=True):
    labels = distinct_labels(runs)
    for r, name in zip(runs, labels):
        t, y = value(r)
        ax.plot(t * 1e3, y, lw=1.3, label=name)
    ax.set_xlabel("t [ms]")
    ax.set_ylabel(ylabel)
    if log:
        ax.set_yscale("log")
    ax.grid(alpha=0.3)


def _error(r):
    """From the first step on: the initial state is exact (zero error, off a log axis)."""
    f = r.fields
    return f["times"][1:], np.maximum(f["error"][1:].max(axis=1), 1e-16)


def _balance(r):
    f = r.fields
    kin, strain, work = f["energy"]
    total = kin + strain
    scale = np.max(np.abs(total)) or 1.0
    n = total.size
    t = np.linspace(0.0, f["times"][-1], n)
    return t, 100.0 * (total - work - total[0]) / scale


@family("waves")
def wave_figures(scene, results, folder):
    """Per operator (continuum, discrete): the largest nodal error against time and the
    energy balance of every run; and the time study's error against the step."""
    out = []
    for op, what in (("continuum", "continuum PD body force: the treatments' boundary "
                                   "error"),
                     ("discrete", "the run's own discrete operator: the time integration's "
                                  "error alone")):
        runs = [r for r in results if r.params.get("operator") == op
                and r.params.get("time_function") == "sine"]
        if not runs:
            continue
        fig, axes = plt.subplots(1, 2, figsize=(12, 4.2), constrained_layout=True)
        _curves(axes[0], runs, _error, "max over nodes of |u - u_ref| [% of max |u|]")
        _curves(axes[1], runs, _balance, "E_kin + E_strain - W - E(0) [% of max E]",
                log=False)
        axes[0].set_title("error against time", fontsize=10)
        axes[1].set_title("energy balance", fontsize=10)
        legend_outside(axes[1])
        fig.suptitle(f"{scene.id}: {what}", fontsize=11)
        name = f"{scene.id}-{op}-time.png"
        out.append((save(fig, folder, name),
                    f"{what}. Left: the largest nodal error (in % of the largest |u| of the "
                    "run) at each sampled step of the base time step; right: kinetic plus "
                    "strain energy minus the work of the loads and of the prescribed "
                    "unknowns' reactions (trapezoidal in time), in % of the largest energy."))
    study = [r for r in results if r.params.get("operator") == "discrete"
             and r.params.get("time_function") == "sine"
             and r.diagnostics.get("time_levels_dt")]
    if study:
        fig, ax = plt.subplots(figsize=(7, 4.5), constrained_layout=True)
        for r, name in zip(study, distinct_labels(study, base=lambda r: (
                f"{r.method}, {r.params.get('integrator')}"))):
            dt = np.asarray(r.diagnostics["time_levels_dt"])
            err = np.asarray(r.diagnostics["time_levels_max_error"]) * 100.0
            rate = r.metrics.get("time_rate")
            ax.loglog(dt, err, "o-", label=f"{name} (rate {rate:.2f})" if rate else name)
        dt = np.asarray(study[0].diagnostics["time_levels_dt"])
        err0 = np.asarray(study[0].diagnostics["time_levels_max_error"])[0] * 100.0
        ax.loglog(dt, err0 * (dt / dt[0]) ** 2, "k:", lw=1, label="slope 2")
        ax.set_xlabel("dt [s]")
        ax.set_ylabel("max |u - u_ref| [% of max |u|]")
        ax.grid(alpha=0.3, which="both")
        legend_outside(ax)
        name = f"{scene.id}-time-convergence.png"
        out.append((save(fig, folder, name),
                    "Time convergence with the run's own discrete operator (exact in "
                    "space): the largest error against the step, dt = 0.9 of the explicit "
                    "limit and its halvings, with the fitted rate."))
    return out
