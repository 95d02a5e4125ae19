"""What issue 55's new cells on the 2D shapes cost a full report: the surface-node,
mirror-node and PDDO runs of ``plate-hole`` and ``plate-l`` (every case the report plans
for them: the default grid and the delta-refinement, surface nodes at orders 1 to 3).

Plain script (no test runner):

    python benchmarks/curved_cells.py [--repeat N] [--no-record] [--tag TAG]

Runs, in this process, every report case of the two scenes (``Scene.cases``, the FEM
reference read from its cache after the first), each ``--repeat`` times (default 1),
alternating the cases, and sums each run's wall time (its ``Timer`` phases) over the
new cells and over the cells the report had before (``none``, the bond methods,
Taylor's fictitious nodes, the jitter study). The ratio of the two sums is what the new
cells add to the two scenes' run time whatever the machine's load; the sum itself is
the added time at this load (the issue's budget: 90 s on 2 cores for all of issue 55's
new cells and scenes). Also the peak resident size of the process (each run's own peak
is in the report's results.json: ``resources.peak_rss_gb``).
"""
from __future__ import annotations

import argparse
import resource
import time

import harness

from pdverify.results import Timer
from pdverify.scenes import get_scene

NEW = ("surface-nodes", "mirror-nodes", "pddo")
SCENES = ("plate-hole", "plate-l")


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=1, help="runs of every case")
    harness.add_arguments(ap)
    args = ap.parse_args()
    with harness.Record(__file__, args) as rec:
        rows = []
        for sid in SCENES:            # the FEM references first (cached), not timed
            scene = get_scene(sid)
            scene.reference_of(scene.resolve("none", {}))
        for rep in range(args.repeat):
            for sid in SCENES:
                scene = get_scene(sid)
                for method, over in scene.cases():
                    if method == "fem":
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
        print(f"new cells: {rec['summary']['new_cells']} runs, {new:.1f} s; the cells "
              f"before: {old:.1f} s; added {100 * new / old:.0f} % of the two scenes' run "
              f"time; peak RSS {peak:.2f} GB (under this machine's load)")


if __name__ == "__main__":
    main()
