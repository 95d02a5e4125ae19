"""What issue 55's mirror-node cells on the bond-based boxes cost a full report: the
``mirror-nodes`` runs of ``sheet2d-tension``, ``sheet2d-clamped``, ``stiffness2d-sheet``
and ``stiffness3d-box-bond`` (the report plans one each, at the scene's defaults; the
sheets' studies skip them, ``convergence.BOND_BOX_COST``).

Plain script (no test runner):

    python benchmarks/mirror_bond_cells.py [--repeat N] [--no-record] [--tag TAG]

Runs, in this process, every full-report case of the four scenes
(``Scene.report_cases``; the clamped sheet's FEM reference read from its cache after
the first, not timed), each ``--repeat`` times (default 1), and sums each run's wall
time over the new cells and over the cells the report had before. The ratio of the two
sums is what the new cells add to the four scenes' run time whatever the machine's
load; the sum itself is the added time at this load (the issue's budget: 90 s on 2 cores
for all of issue 55's new cells and scenes; this part's share ~10 s). Also the peak
resident size of the process (each run's own peak is in the report's results.json).
"""
from __future__ import annotations

import argparse
import resource
import time

import harness

from pdverify.results import Timer
from pdverify.scenes import get_scene

NEW = ("mirror-nodes",)
SCENES = ("sheet2d-tension", "sheet2d-clamped", "stiffness2d-sheet", "stiffness3d-box-bond")


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=1, help="runs of every case")
    harness.add_arguments(ap)
    args = ap.parse_args()
    with harness.Record(__file__, args) as rec:
        rows = []
        clamped = get_scene("sheet2d-clamped")    # the FEM reference first (cached)
        clamped.fem_reference(clamped.resolve("none", {}))
        for rep in range(args.repeat):
            for sid in SCENES:
                scene = get_scene(sid)
                for method, over in scene.report_cases(quick=False):
                    if method == "fem" or method.startswith("peer:"):
                        continue
                    p = scene.resolve(method, over)
                    t0 = time.perf_counter()
                    scene.solve(method, p, Timer())
                    wall = time.perf_counter() - t0
                    rows.append(dict(scene=sid, method=method, params=over, wall_s=wall,
                                     new=method in NEW, repeat=rep))
            rec["rows"] = rows
            rec.save()
        new = sum(r["wall_s"] for r in rows if r["new"]) / args.repeat
        old = sum(r["wall_s"] for r in rows if not r["new"]) / args.repeat
        peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1e6
        rec["summary"] = dict(new_cells=sum(r["new"] for r in rows) // args.repeat,
                              new_s=new, before_s=old, added_fraction=new / old,
                              peak_rss_gb=peak)
        print(f"new cells: {rec['summary']['new_cells']} runs, {new:.2f} s; the cells "
              f"before (peers left out): {old:.1f} s; added {100 * new / old:.1f} % of the "
              f"four scenes' run time; peak RSS {peak:.2f} GB (under this machine's load)")


if __name__ == "__main__":
    main()
