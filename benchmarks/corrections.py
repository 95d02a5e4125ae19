"""What the bond corrections cost: setup beside the solve, at each scene's defaults.

Plain script (no test runner): python benchmarks/corrections.py [--repeat N] [--json F]
Runs ``none`` and every available bond method (``energy``, ``volume``, ``pals``,
``perifit`` with the ``peers`` extra) on the scenes that take them, plus the §5 methods
of the plate (``mirror-nodes``, ``pddo``, ``surface-nodes``), alternating the methods in
each round, and prints the median setup and solve time of each, the correction's extra
setup over ``none``, and that extra as a fraction of ``none``'s solve (the budget of the
corrections issue: at most one solve).
"""
from __future__ import annotations

import argparse
import json
import statistics

from pdverify.corrections.registry import bond_methods
from pdverify.scenes import get_scene

SCENES = ("bar1d-traction", "sheet2d-tension", "plate2d-plane-strain", "body3d-traction",
          "stiffness3d-box")


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--json", default=None)
    args = ap.parse_args(argv)
    out = {}
    for sid in SCENES:
        scene = get_scene(sid)
        methods = ["none"] + [k for k, m in bond_methods().items()
                              if m.origin == "built-in" and m.serves(scene) and not m.unavailable]
        if sid == "plate2d-plane-strain":
            methods += ["mirror-nodes", "pddo", "surface-nodes"]
        times = {m: {"setup_s": [], "solve_s": []} for m in methods}
        for _ in range(args.repeat):
            for m in methods:
                r = scene.run(m)
                assert r.status == "ok", r.message
                for k in times[m]:
                    times[m][k].append(r.timings.get(k, 0.0))
        med = {m: {k: statistics.median(v) for k, v in t.items()} for m, t in times.items()}
        out[sid] = med
        base = med["none"]
        print(f"{sid}: median of {args.repeat}")
        for m in methods:
            extra = med[m]["setup_s"] - base["setup_s"]
            ratio = extra / base["solve_s"] if base["solve_s"] > 0 else float("nan")
            print(f"  {m:13s} setup {med[m]['setup_s']:8.4f} s  solve {med[m]['solve_s']:8.4f} s"
                  f"  extra setup {extra:+8.4f} s = {ratio:+6.2f} x none's solve")
    if args.json:
        with open(args.json, "w") as fh:
            json.dump(out, fh, indent=1)


if __name__ == "__main__":
    main()
