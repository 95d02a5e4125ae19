"""cylinder3d-tension's PD error under h-refinement at fixed m = 3 (issue 55): a study
outside the report (its budget holds one grid), for ``none`` and the bond methods.

Plain script (no test runner):

    python benchmarks/shape3d_refinement.py [--spacing H ...] [--method M ...]
                                            [--no-record] [--tag TAG]

Each (method, h) is solved in this process by the scene itself (``scene.solve``) and
its ``rel_l2_error`` and ``max_error_pct`` recorded with the run time; the least-squares
slope of log(rel_l2_error) against log(h) is the fitted rate. The reference is the FEM
field, equal to the closed form to round-off, so the error is the PD model's alone.
"""
from __future__ import annotations

import argparse
import time

import numpy as np

import harness

SPACINGS = (0.125, 1 / 12, 0.0625, 1 / 24)
METHODS = ("none", "energy", "volume", "pals")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--spacing", type=float, nargs="+", default=list(SPACINGS))
    ap.add_argument("--method", nargs="+", default=list(METHODS))
    harness.add_arguments(ap)
    args = ap.parse_args()
    from pdverify.results import Timer
    from pdverify.scenes import get_scene
    scene = get_scene("cylinder3d-tension")
    with harness.Record(__file__, args) as rec:
        for m in args.method:
            rows = []
            for h in args.spacing:
                p = {**scene.default_params(), "load_point": "surface", "spacing": h}
                t0 = time.perf_counter()
                out = scene.solve(m, p, Timer())
                rows.append({"spacing": h, "rel_l2_error": out.metrics["rel_l2_error"],
                             "max_error_pct": out.metrics["max_error_pct"],
                             "nodes": out.size["interior_nodes"],
                             "s": time.perf_counter() - t0})
                print(f"{m:8s} h={h:.5f} nodes={rows[-1]['nodes']:5d} "
                      f"rel_l2={rows[-1]['rel_l2_error']:.4f} "
                      f"max={rows[-1]['max_error_pct']:.2f} % {rows[-1]['s']:.1f} s", flush=True)
            hs = np.array([r["spacing"] for r in rows])
            e = np.array([r["rel_l2_error"] for r in rows])
            rate = float(np.polyfit(np.log(hs), np.log(e), 1)[0]) if len(rows) > 1 else None
            rec[m] = {"levels": rows, "rate_rel_l2": rate}
            rec.save()
            print(f"{m}: fitted rate of rel_l2_error in h: {rate}", flush=True)


if __name__ == "__main__":
    main()
