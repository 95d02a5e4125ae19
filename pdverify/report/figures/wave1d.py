"""Figures of the 1D wave of seed 002: snapshots (Fig. 5), error profiles and m-convergence."""
from __future__ import annotations

import matplotlib.pyplot as plt
import numpy as np

from manufactured import wave1d as analytic

from . import family, method_colours, save


def _group(r) -> str:
    if r.method == "surface-nodes":
        return f"surface-nodes (order {r.params.get('order', 1)})"
    return r.method


def _groups(results) -> dict:
    out: dict[str, list] = {}
    for r in sorted(results, key=lambda r: r.params["m_ratio"]):
        out.setdefault(_group(r), []).append(r)
    return out


def _snapshots(scene, runs, title, folder, name):
    f0 = runs[0].fields
    xf = np.linspace(0.0, f0["length"], 801)
    kw = dict(horizon=f0["horizon"], wave_speed=f0["wave_speed"], length=f0["length"],
              n_terms=f0["n_terms"])
    times = f0["times"]
    pd = analytic.pd_wave_displacement(xf, times, **kw)
    cl = analytic.classical_wave_displacement(xf, times, wave_speed=f0["wave_speed"],
                                              length=f0["length"], n_terms=f0["n_terms"])
    fig, axes = plt.subplots(2, 2, figsize=(11, 7), sharex=True, sharey=True)
    colors = plt.rcParams["axes.prop_cycle"].by_key()["color"]
    for j, ax in enumerate(axes.ravel()[:len(times)]):
        ax.plot(xf, cl[j], "--", color="0.55", lw=1.2, label="CCM analytic")
        ax.plot(xf, pd[j], "k-", lw=1.4, label=f"PD analytic (delta = {f0['horizon']:g} m)")
        for c, r in zip(colors, runs):
            f = r.fields
            stride = max(1, f["x"].size // 100)  # about 100 markers per curve
            ax.plot(f["x"][::stride], f["u"][j, ::stride], "o", ms=3, color=c,
                    label=f"PD numerical, m = {r.params['m_ratio']}")
        ax.set_title(f"t = {times[j] * 1e3:.3g} ms", fontsize=10)
        ax.grid(alpha=0.3)
    for ax in axes[-1]:
        ax.set_xlabel("x [m]")
    for ax in axes[:, 0]:
        ax.set_ylabel("u [m]")
    axes[0, 1].legend(fontsize=7, loc="lower center")  # u is ~0 mid-bar at 0.1 ms
    fig.suptitle(f"{scene.id}: {title}", fontsize=11)
    return save(fig, folder, name)


@family("wave1d")
def wave_figures(scene, results, folder):
    """Fig. 5 of seed 002 per method, nodal error profiles, and the m-convergence plot."""
    out = []
    groups = _groups(results)
    for gname, runs in groups.items():
        slug = gname.split(" ")[0] + (f"-order{runs[0].params['order']}" if "order" in runs[0].params else "")
        out.append((_snapshots(scene, runs, gname, folder, f"{scene.id}-{slug}-snapshots.png"),
                    f"{gname}: displacement at the four instants of Fig. 5; PD analytic series "
                    "(corrected Eq. 11, solid), classical series (dashed), nodal values per "
                    "m-ratio (dots; at most about 100 drawn per curve)."))

    # nodal error profiles at the reflection (0.1 ms) and at the end (0.2 ms)
    fig, axes = plt.subplots(1, 2, figsize=(12, 4), sharey=True)
    colors = plt.rcParams["axes.prop_cycle"].by_key()["color"]
    m_all = sorted({r.params["m_ratio"] for r in results})
    styles = ["-", "--", ":", "-."]
    for g, (gname, runs) in enumerate(groups.items()):
        for r in runs:
            f = r.fields
            c = colors[m_all.index(r.params["m_ratio"]) % len(colors)]
            for ax, j in zip(axes, (1, len(f["times"]) - 1)):
                err = np.abs(f["u"][j] - f["u_ref"][j]) / f["peak"] * 100.0
                ax.semilogy(f["x"], np.where(err > 0, err, np.nan), styles[g % 4], color=c,
                            lw=1, label=f"{gname}, m = {r.params['m_ratio']}")
    d, L = results[0].fields["horizon"], results[0].fields["length"]
    for ax, j in zip(axes, (1, len(results[0].fields["times"]) - 1)):
        ax.axvspan(0, 2 * d, color="0.9")
        ax.axvspan(L - 2 * d, L, color="0.9")
        ax.set_title(f"t = {results[0].fields['times'][j] * 1e3:.3g} ms")
        ax.set_xlabel("x [m]")
        ax.grid(True, which="both", alpha=0.3)
    axes[0].set_ylabel("|u - u_PD| [% of 0.02 m]")
    axes[1].legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.02, 1.0))
    out.append((save(fig, folder, f"{scene.id}-error-profiles.png"),
                "Nodal error |u - u_PD| in % of the pulse peak at t = 0.1 ms (pulse halves at "
                "the ends) and t = 0.2 ms; shaded: within 2 delta of an end, where "
                "boundary_error_pct is measured."))

    # m-convergence with fitted slopes
    fig, ax = plt.subplots(figsize=(6.5, 4.5))
    # each group in its method's colour (:mod:`.palette`; orders of one method in shades)
    group_colours = method_colours([runs[0] for runs in groups.values()])
    for g, (gname, runs) in enumerate(groups.items()):
        m = np.array([r.params["m_ratio"] for r in runs], dtype=float)
        for key, mk in (("max_error_pct", "o-"), ("boundary_error_pct", "s--")):
            e = np.array([r.metrics[key] for r in runs])
            lab = f"{gname}: {key}"
            if m.size >= 2:
                slope = -np.polyfit(np.log(m), np.log(e), 1)[0]
                lab += f" (order {slope:.2f})"
            ax.loglog(m, e, mk, ms=5, color=group_colours[g], label=lab)
    ax.set_xlabel("m-ratio (delta fixed)")
    ax.set_ylabel("error [% of 0.02 m]")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.02, 1.0))
    out.append((save(fig, folder, f"{scene.id}-convergence.png"),
                "m-convergence against the analytic PD series: max_error_pct (all nodes) and "
                "boundary_error_pct (within 2 delta of an end) with the fitted log-log order "
                "-d log(error) / d log(m)."))
    return out
