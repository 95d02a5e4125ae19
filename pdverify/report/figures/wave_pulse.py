"""Figures of the 2D pulse scene: the receivers' signals PD against FEM per treatment, the energy balance against time, and an error snapshot."""
from __future__ import annotations

import matplotlib.pyplot as plt
import numpy as np

from . import distinct_labels, family, fem_then_pd, legend_outside, save

#: the receivers in the reference's order (``reference_fem.wave_plate.RECEIVERS``)
RECEIVERS = ("fixed", "free", "corner")


@family("wave-pulse")
def pulse_figures(scene, results, folder):
    """The FEM reference's own figures, then per receiver the low-passed |u| of every PD
    run against the FEM's with the reflection's window shaded; the energy balance of
    every PD run against time; the error field of the uncorrected run at the stored
    time of largest error."""
    out, _, pd_runs = fem_then_pd(scene, results, folder)
    pd_runs = [r for r in pd_runs if "receivers" in r.fields]
    if not pd_runs:
        return out
    labels = distinct_labels(pd_runs)
    fig, axes = plt.subplots(1, 3, figsize=(15, 4.2), constrained_layout=True)
    first = pd_runs[0].fields
    for k, (ax, name) in enumerate(zip(axes, RECEIVERS)):
        t = first["times"] * 1e6
        ax.plot(t, np.linalg.norm(first["fem_receivers"][k], axis=1), "k-", lw=2.2,
                label="FEM (converged)")
        for r, lab in zip(pd_runs, labels):
            f = r.fields
            ax.plot(f["times"] * 1e6, np.linalg.norm(f["receivers"][k], axis=1), lw=1.1,
                    label=lab)
        a, b = np.asarray(first["windows"])[k] * 1e6
        ax.axvspan(a, b, color="0.85", zorder=0)
        ax.set_title(f"receiver facing the {name}"
                     f"{'' if name == 'corner' else ' edge'}", fontsize=10)
        ax.set_xlabel("t [us]")
        ax.set_ylabel("|u| low-passed [m]")
        ax.grid(alpha=0.3)
    legend_outside(axes[-1])
    fig.suptitle(f"{scene.id}: receiver signals (shaded: the reflection's window)",
                 fontsize=11)
    out.append((save(fig, folder, f"{scene.id}-receivers.png"),
                "The displacement magnitude at the three receivers, PD (each treatment) "
                "against the converged FEM, both low-passed at the frequency where PD's "
                "longitudinal phase velocity departs from c_P by the run's "
                "dispersion_tol; the shaded window holds the feature's reflected P rays, "
                "where the arrival time and amplitude errors are measured."))
    fig, ax = plt.subplots(figsize=(8, 4.2), constrained_layout=True)
    for r, lab in zip(pd_runs, labels):
        kin, strain, work = r.fields["energy"]
        total = kin + strain
        scale = np.max(np.abs(total)) or 1.0
        t = np.linspace(0.0, r.fields["times"][-1], total.size) * 1e6
        ax.plot(t, 100.0 * (total - work) / scale, lw=1.2, label=lab)
    ax.set_xlabel("t [us]")
    ax.set_ylabel("E_kin + E_strain - W [% of max E]")
    ax.grid(alpha=0.3)
    legend_outside(ax)
    ax.set_title(f"{scene.id}: energy balance", fontsize=10)
    out.append((save(fig, folder, f"{scene.id}-energy.png"),
                "Kinetic plus strain energy minus the work of the source (trapezoidal in "
                "time), in % of the largest energy, per treatment: velocity Verlet "
                "conserves it to second order in the step."))
    base = next((r for r in pd_runs if r.method == "none"), pd_runs[0])
    f = base.fields
    err = np.asarray(f["error"])
    k = int(np.nanargmax(np.nanmax(err, axis=1)))
    x = np.asarray(f["x"])
    fig, ax = plt.subplots(figsize=(7.5, 5.2), constrained_layout=True)
    sc = ax.scatter(x[:, 0], x[:, 1], c=err[k], s=2, cmap="viridis", marker="s")
    fig.colorbar(sc, ax=ax, label="|u_PD - u_FEM| [% of max |u_FEM|]")
    ax.set_aspect("equal")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.set_title(f"{scene.id}, {base.method}: error at t = "
                 f"{f['snapshot_times'][k] * 1e6:.0f} us (blank: the load zone)", fontsize=10)
    out.append((save(fig, folder, f"{scene.id}-error-snapshot.png"),
                "The error field of one run at the stored time of its largest error "
                "(unfiltered: PD's dispersion of the pulse's share above the cut-off is "
                "in it); the nodes within 3 source widths of the source are left out."))
    return out
