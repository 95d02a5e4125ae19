"""K_I and K_II of the uncorrected PD model and the bond methods on the plate with the
inclined centre crack (``plate-inclined-crack``, issue 54, mixed mode): the refinement
at fixed m = 3 (h = 1/30, 1/40, 1/60 m) and the run times.

Each case is the scene's own run (``Scene.run``: the problem, the treatment, the K fit
``pdverify.pd.cracks.fit_k_mixed`` at the right tip and the metrics as the report has
them), in this process, one after another; the FEM reference is read from the cache
(computed first if missing, outside the timings). Printed per case: K_I / K_FEM, K_II /
K_FEM, the fit's own bias on the FEM field at the PD nodes (``fit1%``, ``fit2%``), the
field errors outside the tip zone (``max%``, ``l2``) and the run's total time (its
``timings.total_s``: setup and solve, under the machine's load at the time).

Run: ``python benchmarks/inclined_crack_k.py`` (``--spacings``, ``--methods``). Measured
(under load: load average 12-18 on the 2 cores; record
``benchmarks/records/inclined_crack_k-<date>-default.json``): see the record and the
report of the branch that added the scene.
"""
from __future__ import annotations

import argparse
import os
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

import harness  # noqa: E402

SPACINGS = (1 / 30, 1 / 40, 1 / 60)
METHODS = ("none", "energy", "volume", "pals")


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--spacings", type=float, nargs="+", default=list(SPACINGS),
                    help="grid spacings h (m), m = 3")
    ap.add_argument("--methods", nargs="+", default=list(METHODS), choices=METHODS)
    harness.add_arguments(ap)
    args = ap.parse_args()
    from pdverify.scenes import get_scene
    scene = get_scene("plate-inclined-crack")
    ref = scene.run("fem", {})                   # the cache, before any timing
    k1, k2 = ref.metrics["k1"], ref.metrics["k2"]
    print(f"K_FEM: K_I = {k1:.7g}, K_II = {k2:.7g} Pa m^0.5; load {os.getloadavg()}")
    print(f"{'method':8s} {'h':>7s} {'K1/FEM':>8s} {'K2/FEM':>8s} {'fit1%':>7s} "
          f"{'fit2%':>7s} {'max%':>6s} {'l2':>7s} {'total s':>8s}")
    with harness.Record(__file__, args) as rec:
        rows = []
        for h in args.spacings:
            for m in args.methods:
                t0 = time.perf_counter()
                res = scene.run(m, {"spacing": h})
                wall = time.perf_counter() - t0
                q = res.metrics
                row = {"method": m, "spacing": h, "status": res.status,
                       "k1_ratio": q.get("k1_ratio"), "k2_ratio": q.get("k2_ratio"),
                       "k1_fit_bias_pct": q.get("k1_fit_bias_pct"),
                       "k2_fit_bias_pct": q.get("k2_fit_bias_pct"),
                       "max_error_pct": q.get("max_error_pct"),
                       "rel_l2_error": q.get("rel_l2_error"),
                       "total_s": res.timings.get("total_s"), "wall_s": wall,
                       "load": os.getloadavg()[0]}
                rows.append(row)
                rec["rows"] = rows
                rec.save()
                print(f"{m:8s} 1/{1 / h:<5.0f} {row['k1_ratio']:8.5f} {row['k2_ratio']:8.5f} "
                      f"{row['k1_fit_bias_pct']:+7.3f} {row['k2_fit_bias_pct']:+7.3f} "
                      f"{row['max_error_pct']:6.3f} {row['rel_l2_error']:7.4f} "
                      f"{row['total_s']:8.2f}", flush=True)


if __name__ == "__main__":
    main()
