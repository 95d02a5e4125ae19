"""The block2d-indentation FEM reference's refinement study: the former method against the
half model with a kept factorisation (issue 32), side by side in one run.

Plain script (no test runner):

    python benchmarks/fem_indentation.py [--kinematics finite|small] [--repeat N] [--all]
                                         [--against SRC]

Runs the whole study (``reference_fem.indentation.compute``, no cache) of the scene's
finite-strain reference (``kinematics="finite", levels=2, substeps=4``, the scene's
FINITE_REFERENCE) or of the small-strain one (the defaults), ``--repeat`` times (default
3) per case, alternating, each in a fresh process (the study only is timed, not the
imports). Cases:

- ``full, plain``: the whole block, Newton factorising the tangent at every iterate (the
  former method, on today's assembly);
- ``half, kept``: the right half with u_x = 0 on the axis, Newton keeping its
  factorisation (the default);
- ``--all`` adds ``half, plain`` and ``full, kept``;
- ``--against SRC``: the study as the ``reference_fem`` of another source tree computes
  it (e.g. ``git archive`` of an earlier commit unpacked), with its own defaults.

Small strain has no Newton: its cases are ``full`` and ``half``. Prints per case the
median and spread of the study time, the median of the converged level's setup + solve,
the ratio to the first case, the linear solves and factorisations of each level, and the
largest relative change of the force-depth curve against the first case and against
``--against`` (every output depth, relative to that depth's force).
"""
from __future__ import annotations

import argparse
import json
import os
import sys
from pathlib import Path

import harness

ROOT = Path(__file__).resolve().parents[1]
STUDIES = {"finite": {"kinematics": "finite", "levels": 2, "substeps": 4}, "small": {}}

CHILD = r"""
import importlib, json, sys, time
import numpy as np
ind = importlib.import_module("reference_fem.indentation")   # the package exports a function
study, options = json.loads(sys.argv[1]), json.loads(sys.argv[2])
p = ind.IndentationParams(**study, **options.get("params", {}))
kw = {"newton": options["newton"]} if "newton" in options else {}
t = time.perf_counter()
r = ind.compute(p, **kw)
study_s = time.perf_counter() - t
print(json.dumps({"study_s": study_s, "forces": np.asarray(r.forces).tolist(),
                  "converged_s": r.setup_s + r.solve_s,
                  "levels": [{k: v for k, v in row.extra.items()
                              if k in ("solves", "factorisations")} | {"dofs": row.dofs}
                             for row in r.refinement]}))
"""


def run_case(study: dict, options: dict, path: Path) -> dict:
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(
        [str(path)] + [p for p in os.environ.get("PYTHONPATH", "").split(os.pathsep) if p]))
    return harness.fresh([sys.executable, "-c", CHILD, json.dumps(study), json.dumps(options)],
                         env=env, cwd=path)


def max_rel_change(a, b) -> float:
    """Largest |a - b| / |b| over the output depths (depth 0, force 0, left out)."""
    return max(abs(x - y) / abs(y) for x, y in zip(a[1:], b[1:]))


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--kinematics", choices=sorted(STUDIES), default="finite")
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--all", action="store_true")
    ap.add_argument("--against", type=Path, default=None)
    harness.add_arguments(ap)
    args = ap.parse_args(argv)
    if args.repeat < 1:
        raise SystemExit(f"--repeat must be >= 1, got {args.repeat}")
    if args.against is not None and not (args.against / "reference_fem").is_dir():
        raise SystemExit(f"--against {args.against}: no reference_fem folder there")
    study = STUDIES[args.kinematics]
    finite = args.kinematics == "finite"

    def case(sym, newton):
        opts = {"params": {"symmetry": sym}}
        if finite:
            opts["newton"] = newton
        return (f"{sym}, {newton}" if finite else sym), opts, ROOT

    cases = [case("full", "plain"), case("half", "reuse")]
    if args.all and finite:
        cases += [case("half", "plain"), case("full", "reuse")]
    if args.against is not None:
        cases.append((f"{args.against.name} (against)", {}, args.against.resolve()))
    with harness.Record(__file__, args, argv=argv) as rec:
        _measure(args, study, cases, rec)


def _measure(args, study, cases, rec):
    def one(name, opts, path):
        r = run_case(study, opts, path)
        print(f"  {name}: study {r['study_s']:.1f} s", flush=True)
        return r
    timed = harness.alternate({name: (lambda name=name, opts=opts, path=path: one(name, opts, path))
                               for name, opts, path in cases}, args.repeat, rotate=False)
    runs = {name: t.results for name, t in timed.items()}
    print(f"\n{args.kinematics}-strain study {study or '(defaults)'}, median of {args.repeat}")
    first = runs[cases[0][0]]
    base = harness.median(r["study_s"] for r in first)
    against = runs[cases[-1][0]] if args.against is not None else None
    print(f"{'case':22s} {'study s':>8s} {'min-max s':>13s} {'conv. s':>8s} {'ratio':>6s} "
          f"{'dF vs 1st':>10s} {'dF vs against':>13s}  levels (dofs, solves, factorisations)")
    for name, rs in runs.items():
        med = harness.median(r["study_s"] for r in rs)
        conv = harness.median(r["converged_s"] for r in rs)
        spread = f"{min(r['study_s'] for r in rs):.1f}-{max(r['study_s'] for r in rs):.1f}"
        d1 = max_rel_change(rs[0]["forces"], first[0]["forces"])
        da = max_rel_change(rs[0]["forces"], against[0]["forces"]) if against else float("nan")
        levels = "; ".join(f"{lv['dofs']}, {lv.get('solves', '-')}, "
                           f"{lv.get('factorisations', '-')}" for lv in rs[0]["levels"])
        print(f"{name:22s} {med:8.1f} {spread:>13s} {conv:8.1f} {med / base:6.3f} "
              f"{d1:10.2e} {da:13.2e}  {levels}")
        rec[name] = {"study_median_s": med, "study_s": [r["study_s"] for r in rs],
                     "converged_median_s": conv, "ratio_to_first": med / base,
                     "force_change_vs_first": d1, "force_change_vs_against": da,
                     "levels": rs[0]["levels"]}


if __name__ == "__main__":
    main()
