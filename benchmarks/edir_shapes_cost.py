"""What seed 003's ``energy-directional`` on the shape scenes (issue 55) adds to a full
report: its runs there (the scenes' own cases), each timed beside the same case's
``none`` (alternating), and the ray distances alone (``pdverify.pd.rays``, both ends of
every bond of the case's model).

Plain script (no test runner):

    python benchmarks/edir_shapes_cost.py [--repeat N] [--baseline RESULTS] [--no-record]

The times are wall seconds in this process, under whatever load the machine has. The
estimate "alone" scales each case's ``energy-directional`` median by the ratio of the
same case's ``none`` in ``--baseline`` (a full report's ``results.json`` measured on a
quiet machine; default ``/work/runs/s60c/results.json`` when it exists) to its median
here: the load scales both runs alike (same model, same solver; the closure adds the
rays).

Measured 2026-11-28 under load (load average 11-15 on the 2 cores shared with seven other
sessions; record ``edir_shapes_cost-2026-11-28-repeat-3.json``): the 13 runs took 69.7 s
here, each within -9 .. +33 % of its ``none`` beside it (the rays of plate-crack's 409 504
bonds 1.5 s of its 28 s); scaled to the baseline's quiet ``none`` times ~10.6 s summed
over the workers (plate-crack 4.2 s, plate-edge-crack 2.6 s, plate-inclined-crack 1.1 s,
block3d-cavity 1.0 s, cylinder3d-tension 0.6 s, plate-l 0.6 s, plate-hole 0.5 s), about
5 s of a 2-worker report's wall time; peak memory as ``none``'s (0.92 GB, plate-crack,
in the partial report).
"""
from __future__ import annotations

import argparse
import json
import os
import time

import numpy as np

import harness

SCENES = ("plate-hole", "plate-l", "plate-crack", "plate-edge-crack",
          "plate-inclined-crack", "cylinder3d-tension", "block3d-cavity")
METHOD = "energy-directional"


def _key(scene, params) -> tuple:
    return (scene, json.dumps(params, sort_keys=True, default=str))


def _baseline(path):
    if not path or not os.path.exists(path):
        return {}
    with open(path) as fh:
        runs = json.load(fh)["runs"]
    return {_key(r["scene"], r["params"]): r["timings"].get("total_s")
            for r in runs if r["method"] == "none" and r["status"] == "ok"}


def _ray_seconds(scene, params) -> tuple[float, int]:
    """The exit distances of both ends of every bond of ``none``'s model of the case."""
    from pdverify.corrections.assembly import model_of
    from pdverify.pd.rays import exit_distance
    problem = scene.problem(params, scene.id)
    model = model_of(problem, problem.body.grid(0), None)
    x = model.grid.x
    t0 = time.perf_counter()
    exit_distance(problem.shape, x[model.bond_a], model.bond_n)
    exit_distance(problem.shape, x[model.bond_b], -model.bond_n)
    return time.perf_counter() - t0, int(model.bond_a.size)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=2, help="rounds per case (default 2)")
    ap.add_argument("--baseline", default="/work/runs/s60c/results.json",
                    help="a full report's results.json measured on a quiet machine")
    ap.add_argument("--only", nargs="*", default=SCENES, help="scenes (default: all 7)")
    harness.add_arguments(ap)
    args = ap.parse_args()
    from pdverify.scenes import get_scene
    base = _baseline(args.baseline)
    with harness.Record(__file__, args) as rec:
        total, alone = 0.0, 0.0
        for sid in args.only:
            scene = get_scene(sid)
            for method, over in scene.cases():
                if method != METHOD:
                    continue
                runs = {m: (lambda m=m: scene.run(m, over)) for m in ("none", METHOD)}
                t = harness.alternate(runs, args.repeat)
                for m, timing in t.items():
                    bad = [r for r in timing.results if r.status != "ok"]
                    assert not bad, (sid, m, bad[0].message)
                params = scene.resolve("none", over)
                rays, bonds = _ray_seconds(scene, params)
                quiet = base.get(_key(sid, t["none"].last.params))
                med = {m: timing.median for m, timing in t.items()}
                est = med[METHOD] * quiet / med["none"] if quiet else float("nan")
                name = f"{sid} {json.dumps(over, sort_keys=True)}"
                rec[name] = {**harness.summary(t, base="none"), "rays_s": rays,
                             "bonds": bonds, "none_quiet_s": quiet, "alone_estimate_s": est}
                total += med[METHOD]
                alone += est
                print(f"{name:48s} none {med['none']:6.2f} s  {METHOD} {med[METHOD]:6.2f} s  "
                      f"rays {rays:5.2f} s ({bonds} bonds)  alone ~{est:5.2f} s", flush=True)
        rec["all"] = {"energy_directional_s": total, "alone_estimate_s": alone}
        print(f"all: {METHOD} {total:.1f} s here (load: see the record), ~{alone:.1f} s alone")


if __name__ == "__main__":
    main()
