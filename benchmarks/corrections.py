"""What the bond corrections cost: setup beside the solve, at each scene's defaults.

Plain script (no test runner): python benchmarks/corrections.py [--repeat N] [--json F]
Runs ``none`` and every available bond method (``energy``, ``volume``, ``pals``,
``perifit`` with the ``peers`` extra) on the scenes that take them, plus the §5 methods
of the plate (``mirror-nodes``, ``pddo``, ``surface-nodes``), alternating the methods in
each round, and prints the median setup and solve time of each, the correction's extra
setup over ``none``, and that extra as a fraction of ``none``'s solve (the budget of the
corrections issue: at most one solve).

``--indentation`` adds block2d-indentation at the paper's grid (about 35 s a run): there
``none`` fails at 0.7 mm, so the extra setup is compared with the solve of the scene's
own correction ``energy-directional``, which reaches 2 mm.
"""
from __future__ import annotations

import argparse

import harness
from pdverify.corrections.registry import bond_methods
from pdverify.scenes import get_scene

SCENES = ("bar1d-traction", "bar1d-homogenization", "bar1d-vibration", "sheet2d-tension",
          "plate2d-clamped", "plate2d-plane-strain", "body3d-traction", "stiffness3d-box",
          "stiffness3d-box-bond")
#: the run whose solve a correction's extra setup is compared with, where not ``none``
SOLVE_BASE = {"block2d-indentation": "energy-directional"}


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--json", default=None)
    ap.add_argument("--indentation", action="store_true",
                    help="also block2d-indentation at the paper's grid (slow)")
    harness.add_arguments(ap)
    args = ap.parse_args(argv)
    with harness.Record(__file__, args, argv=argv) as rec:
        _measure(args, rec)
        if args.json:
            harness.write_json(args.json, rec.results)


def _measure(args, out):
    for sid in SCENES + (("block2d-indentation",) if args.indentation else ()):
        scene = get_scene(sid)
        methods = ["none"] + [k for k, m in bond_methods().items()
                              if m.origin == "built-in" and m.serves(scene) and not m.unavailable]
        if sid == "plate2d-plane-strain":
            methods += ["mirror-nodes", "pddo", "surface-nodes"]
        solve_base = SOLVE_BASE.get(sid, "none")
        if solve_base not in methods:
            methods.append(solve_base)
        runs = harness.alternate({m: (lambda m=m: scene.run(m)) for m in methods}, args.repeat)
        for m, t in runs.items():
            for r in t.results:
                # the indentation's none fails by design (seed 003: the lattice folds)
                assert r.status == "ok" or (sid in SOLVE_BASE and m == "none"), r.message
        med = {m: {k: harness.median(r.timings.get(k, 0.0) for r in t.results)
                   for k in ("setup_s", "solve_s")} for m, t in runs.items()}
        out[sid] = med
        base, solve = med["none"], med[solve_base]["solve_s"]
        print(f"{sid}: median of {args.repeat}; extra setup against {solve_base}'s solve")
        for m in methods:
            extra = med[m]["setup_s"] - base["setup_s"]
            ratio = extra / solve if solve > 0 else float("nan")
            print(f"  {m:13s} setup {med[m]['setup_s']:8.4f} s  solve {med[m]['solve_s']:8.4f} s"
                  f"  extra setup {extra:+8.4f} s = {ratio:+6.2f} x {solve_base}'s solve")


if __name__ == "__main__":
    main()
