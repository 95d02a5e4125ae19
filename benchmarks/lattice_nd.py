"""``solver=auto`` on 2D SPD lattice systems (the bond-based sheets): SuperLU's symmetric
mode (or the dense LU) against nested dissection, over the full report's runs of the
scenes (issue 32).

Plain script (no test runner):

    python benchmarks/lattice_nd.py [SCENE ...] [--repeat N]

For every run the full report makes of each scene (``pdverify.runner.plan``; default
sheet2d-clamped, sheet2d-tension, stiffness2d-sheet), the run with nested dissection off
(``policy.LATTICE_ND_DIMS = ()``, the choice before issue 32) and on, alternating, median
of ``--repeat`` (default 1) per run; prints each scene's summed wall time both ways, the
runs that took nested dissection, any status that differs and the largest relative
change of any metric (the solutions must agree to round-off).
"""
from __future__ import annotations

import argparse

import harness
import pdverify.solvers.policy as policy
from pdverify.runner import plan
from pdverify.scenes import get_scene

OFF, ON = (), (2,)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("scenes", nargs="*",
                    default=["sheet2d-clamped", "sheet2d-tension", "stiffness2d-sheet"])
    ap.add_argument("--repeat", type=int, default=1)
    harness.add_arguments(ap)
    args = ap.parse_args(argv)
    keep = policy.LATTICE_ND_DIMS

    def run(scene, method, over, dims):
        policy.LATTICE_ND_DIMS = dims
        return scene.run(method, over)
    with harness.Record(__file__, args, argv=argv) as rec:
        try:
            for scene_id in args.scenes:
                rec[scene_id] = one_scene(scene_id, args.repeat, run)
        finally:
            policy.LATTICE_ND_DIMS = keep


def one_scene(scene_id, repeat, run):
    scene = get_scene(scene_id)
    cases = [(m, o) for s, m, o in plan(only=[scene_id]) if m != "fem"]
    total = {OFF: 0.0, ON: 0.0}
    worst, nd_runs, differ = 0.0, 0, []
    for method, over in cases:
        t = harness.alternate({dims: (lambda dims=dims: run(scene, method, over, dims))
                               for dims in (OFF, ON)}, repeat)
        for dims in (OFF, ON):
            total[dims] += t[dims].median
        a, b = t[OFF].last, t[ON].last
        nd_runs += "nested" in b.diagnostics.get("solver", "")
        if a.status != b.status:
            differ.append((method, over, a.status, b.status))
        for k, v in a.metrics.items():
            w = b.metrics.get(k)
            if isinstance(v, float) and isinstance(w, float) and v != 0:
                worst = max(worst, abs(w - v) / abs(v))
    print(f"{scene_id:18s} {len(cases):3d} runs: without nested dissection "
          f"{total[OFF]:6.1f} s, with {total[ON]:6.1f} s ({total[OFF] / total[ON]:.2f}x); "
          f"{nd_runs} runs took it; largest relative metric change {worst:.1e}; "
          f"status differs: {differ or 'none'}")
    return {"runs": len(cases), "without_nd_s": total[OFF], "with_nd_s": total[ON],
            "runs_with_nd": nd_runs, "largest_relative_metric_change": worst,
            "status_differs": [[str(x) for x in d] for d in differ]}


if __name__ == "__main__":
    main()
