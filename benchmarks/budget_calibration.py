"""Memory estimate (pdverify.budget) against the measured peak of each run.

Runs every case below in its own process (``python -m pdverify run``, FEM references
recomputed in an empty cache folder for each) and prints the peak resident memory above that of a
trivial run, the estimate, and their ratio. The estimate is meant as an upper bound within
a factor of about 3; the budget's two constants were chosen from this table.

    python benchmarks/budget_calibration.py [--quick] [--timing-only]

It first times the validation and budget of every report case (issue 18: under 50 ms).
"""
from __future__ import annotations

import argparse
import os
import sys
import tempfile

import harness
from pdverify.budget import measured_peak
from pdverify.params import parse_assignments
from pdverify.scenes import get_scene

CASES = [
    ("bar1d-traction", "taylor-fictitious", ["spacing=0.00001"]),
    ("bar1d-vibration", "homogenized", ["nodes=2000"]),
    ("wave1d-surface-nodes", "surface-nodes", ["m_ratio=100"]),
    ("sheet2d-tension", "none", []),
    ("sheet2d-tension", "none", ["spacing=0.0005"]),
    ("sheet2d-clamped", "virtual-nodes", ["m_ratio=12"]),
    ("plate2d-clamped", "taylor-fictitious", ["spacing=0.05"]),
    ("plate2d-clamped", "taylor-fictitious", ["spacing=0.025"]),
    ("plate2d-plane-strain", "surface-nodes", []),
    ("plate2d-plane-strain", "none", ["spacing=0.01"]),
    ("body3d-traction", "none", ["spacing=0.0625"]),
    ("body3d-traction", "none", []),
    ("body3d-traction", "surface-nodes", ["spacing=0.1"]),
    ("body3d-traction", "surface-nodes", []),
    ("plate2d-clamped", "fem", ["levels=3"]),
    ("plate2d-clamped", "fem", []),
    ("sheet2d-clamped", "fem", []),
    ("sheet2d-tension", "fem", ["levels=3"]),
    ("block2d-indentation", "fem", []),
]
QUICK = [c for c in CASES if c[0] in ("bar1d-traction", "plate2d-clamped", "sheet2d-clamped")]


def resolve_times():
    """Validation and budget (Scene.resolve) of every report case, after the imports a run
    needs anyway: (median, max) in seconds over 5 repeats of each case."""
    from pdverify.scenes import all_scenes
    times = []
    for scene in all_scenes():
        for method, over in scene.cases(quick=False):
            scene.resolve(method, over)  # warm: imports (scikit-fem for the FEM scenes)
            times.append(harness.alternate({"x": lambda: scene.resolve(method, over)}, 5,
                                           collect=False)["x"].median)
    return harness.median(times), max(times), len(times)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--timing-only", action="store_true")
    harness.add_arguments(ap)
    args = ap.parse_args(argv)
    with harness.Record(__file__, args, argv=argv) as rec:
        _measure(args, rec)


def _measure(args, rec):
    med, worst, n = resolve_times()
    rec["resolve_s"] = {"median": med, "max": worst, "cases": n}
    print(f"validation + budget per run (Scene.resolve, {n} report cases): median "
          f"{med * 1e3:.2f} ms, max {worst * 1e3:.2f} ms")
    if args.timing_only:
        return
    cases = QUICK if args.quick else CASES
    with tempfile.TemporaryDirectory() as tmp:
        env = dict(os.environ, PDVERIFY_CACHE_DIR=tmp)
        run = [sys.executable, "-m", "pdverify", "run"]
        base = measured_peak(run + ["bar1d-traction"], env)
        rec["baseline_bytes"] = base
        rows = rec["cases"] = []
        print(f"interpreter and imports: {base / 1e6:.0f} MB (subtracted)")
        print(f"{'scene':22s} {'method':18s} {'set':16s} {'measured':>9s} {'estimate':>9s} "
              f"{'ratio':>6s}")
        for scene_id, method, sets in cases:
            scene = get_scene(scene_id)
            est = scene.estimate(method, scene.resolve(method, parse_assignments(sets)))
            args = run + [scene_id, "--method", method] + [a for s in sets for a in ("--set", s)]
            # an empty cache for each run: FEM references are computed, as on a first run
            env["PDVERIFY_CACHE_DIR"] = tempfile.mkdtemp(dir=tmp)
            used = max(measured_peak(args, env) - base, 1e6)
            print(f"{scene_id:22s} {method:18s} {' '.join(sets):16s} {used / 1e6:7.0f} MB "
                  f"{est.memory / 1e6:7.0f} MB {est.memory / used:6.2f}", flush=True)
            rows.append({"scene": scene_id, "method": method, "set": sets,
                         "measured_bytes": used, "estimate_bytes": est.memory,
                         "ratio": est.memory / used})
            rec.save()


if __name__ == "__main__":
    main()
