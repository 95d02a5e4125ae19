"""The indentation scene's PD speed (issues 14 and 32): before and after, side by side in one run.

Plain script (no test runner):

    python benchmarks/indentation.py [--repeat N] [--before REV] [--scene] [--quick]
    python benchmarks/indentation.py --phases [--repeat N] [--before REV] [--method M]

Each timed run is a fresh ``python`` process (so no run inherits another's caches or
grown memory) running ``get_scene('block2d-indentation').run(METHOD, OVERRIDES)``; the
variants alternate within each repeat, and the table shows medians of ``--repeat``
(default 3) runs: the run's total and solve phase (its own timings), the process's CPU
time, linear solves, CG iterations, preconditioner builds (+ refreshes), Newton iterations and the
status. The FEM references come from the cache (the first variant's run fills it).

Variants (paper grid: 161 x 161 nodes, m = 6, 20 depth steps):

- ``half``: this tree's default, the half block with mirrored neighbours;
- ``full``: this tree with ``symmetry=full`` (the whole block);
- ``before``: ``--before REV`` (a git revision, e.g. ``main`` or a commit): the package as
  it is at REV, extracted with ``git archive`` into a temporary folder, at its defaults;
  or an existing folder holding another checkout (e.g. ``/path/to/main``).

Cases: the corrected nonlinear curve (``energy-directional``; budget, issue 32: <= 15 s on
a quiet 2-core machine); with ``--scene`` every PD run the full report makes of the scene
(budget: <= 60 s together), each variant's sum printed at the end; ``--quick`` adds the
quick grid (41 x 41 nodes) of the corrected curve.

``--phases``: where the time of one curve goes (default the corrected one; ``--method``
and ``--set name=value`` choose another), this tree and ``--before REV`` alternating in
fresh processes, medians of ``--repeat``: the wall time of the run, the process's CPU time
(the steadier on a busy machine), the wall time of its solve phase,
and within it the summed wall time of each phase of Newton, timed by wrapping the
functions that do them (the same names in both trees): residual evaluation
(``internal_force``), tangent assembly (``tangent_data``), CG iterations (``cg_solve``),
preconditioner setup (``TwoLevelPreconditioner`` and its ``refresh``), the prescribed set (``set_fixed``) and the
breakdown check (``bond_extremes``); "rest" is the solve phase's remainder (the line
search's trial points are residual evaluations). The metrics of the variants are compared
bit for bit.
"""
from __future__ import annotations

import argparse
import json
import os
import sys
import tempfile
from pathlib import Path

import harness
from _trees import extract

ROOT = Path(__file__).resolve().parents[1]
QUICK = {"spacing": 0.001, "horizon": 0.006}
#: one run in a fresh process: prints its timings and diagnostics as JSON
RUNNER = """
import json, resource, sys
from pdverify.scenes import get_scene
method, over = sys.argv[1], json.loads(sys.argv[2])
r = get_scene("block2d-indentation").run(method, over)
cpu = resource.getrusage(resource.RUSAGE_SELF)
print(json.dumps({"status": r.status, "message": r.message, "timings": r.timings,
                  "diagnostics": {k: v for k, v in r.diagnostics.items()
                                  if isinstance(v, (int, float, str))},
                  "metrics": r.metrics, "cpu_s": cpu.ru_utime + cpu.ru_stime}))
"""


#: one run in a fresh process with its Newton phases timed: prints them as JSON
PHASE_RUNNER = """
import json, resource, sys, time
from pdverify.pd import nonlinear
from pdverify.scenes import get_scene
from pdverify.solvers import newton
spent = {}

def timed(name, f):
    def wrapper(*args, **kw):
        t0 = time.perf_counter()
        try:
            return f(*args, **kw)
        finally:
            spent[name] = spent.get(name, 0.0) + time.perf_counter() - t0
    return wrapper

NB, DL = nonlinear.NonlinearBondBased, newton.DirichletLinearSolver
NB.internal_force = timed("residual", NB.internal_force)
NB.tangent_data = timed("tangent", NB.tangent_data)
NB.bond_extremes = timed("breakdown check", NB.bond_extremes)
DL.set_fixed = timed("prescribed set", DL.set_fixed)
newton.cg_solve = timed("CG", newton.cg_solve)
PC = newton.TwoLevelPreconditioner
if hasattr(PC, "refresh"):           # a refresh is preconditioner setup too
    PC.refresh = timed("preconditioner setup", PC.refresh)
newton.TwoLevelPreconditioner = timed("preconditioner setup", PC)
method, over = sys.argv[1], json.loads(sys.argv[2])
t0 = time.perf_counter()
r = get_scene("block2d-indentation").run(method, over)
wall = time.perf_counter() - t0
cpu = resource.getrusage(resource.RUSAGE_SELF)
print(json.dumps({"status": r.status, "wall_s": wall, "solve_s": r.timings["solve_s"],
                  "cpu_s": cpu.ru_utime + cpu.ru_stime,
                  "phases": spent, "metrics": {k: float(v).hex() if isinstance(v, float)
                                               else v for k, v in r.metrics.items()},
                  "cg_iterations": r.diagnostics.get("cg_iterations")}))
"""
PHASES = ("residual", "tangent", "CG", "preconditioner setup", "prescribed set",
          "breakdown check")


def phases(args):
    """The ``--phases`` table (module docstring)."""
    over = {"spacing": 0.00025}
    for kv in args.set:
        k, v = kv.split("=", 1)
        try:
            over[k] = json.loads(v)
        except json.JSONDecodeError:
            over[k] = v
    with tempfile.TemporaryDirectory() as tmp:
        variants = [("this tree", ROOT)]
        if args.before:
            variants.append((f"before ({args.before})", Path(args.before) if Path(
                args.before).is_dir() else extract(args.before, Path(tmp))))
        def one(name, path):
            r = harness.fresh([sys.executable, "-c", PHASE_RUNNER, args.method,
                               json.dumps(over)], env={**os.environ, "PYTHONPATH": str(path)},
                              cwd=path)
            print(f"  {name}: {r['wall_s']:.1f} s", file=sys.stderr, flush=True)
            return r
        timed = harness.alternate({name: (lambda name=name, path=path: one(name, path))
                                   for name, path in variants}, args.repeat, rotate=False)
        runs = {name: t.results for name, t in timed.items()}
    print(f"{args.method} {over}, medians of {args.repeat} (wall s)")
    cols = ("wall", "cpu", "solve", *PHASES, "rest")
    print(f"{'variant':20s} " + " ".join(f"{c[:12]:>12s}" for c in cols))
    table = {}
    for name, rs in runs.items():
        med = {"wall": harness.median(r["wall_s"] for r in rs),
               "cpu": harness.median(r["cpu_s"] for r in rs),
               "solve": harness.median(r["solve_s"] for r in rs)}
        med.update({c: harness.median(r["phases"].get(c, 0.0) for r in rs) for c in PHASES})
        med["rest"] = harness.median(r["solve_s"] - sum(r["phases"].values()) for r in rs)
        print(f"{name:20s} " + " ".join(f"{med[c]:12.2f}" for c in cols))
        table[name] = med
    first = next(iter(runs.values()))[0]
    same = all(r["metrics"] == first["metrics"] and r["status"] == first["status"]
               and r["cg_iterations"] == first["cg_iterations"]
               for rs in runs.values() for r in rs)
    print(f"status {first['status']}, CG iterations {first['cg_iterations']}; metrics "
          f"{'bitwise identical' if same else 'DIFFER'} across all runs")
    return {"phases": {"method": args.method, "overrides": over, "median_s": table,
                       "metrics_identical": same}}


def run_once(path: Path, method: str, over: dict) -> dict:
    return harness.fresh([sys.executable, "-c", RUNNER, method, json.dumps(over)],
                         env={**os.environ, "PYTHONPATH": str(path)}, cwd=path)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--before", metavar="REV", help="git revision to time as 'before'")
    ap.add_argument("--scene", action="store_true",
                    help="every PD run of the scene in the full report, not only the "
                         "corrected curve")
    ap.add_argument("--quick", action="store_true", help="also the quick grid")
    ap.add_argument("--phases", action="store_true",
                    help="time the phases of one curve at the paper grid instead")
    ap.add_argument("--method", default="energy-directional", help="the --phases curve")
    ap.add_argument("--set", action="append", default=[], metavar="NAME=VALUE",
                    help="a parameter of the --phases curve (repeatable)")
    harness.add_arguments(ap)
    args = ap.parse_args(argv)
    with harness.Record(__file__, args, argv=argv) as rec:
        rec.update(phases(args) if args.phases else _measure(args))


def _measure(args):
    cases = [("energy-directional", {})]
    if args.scene:
        sys.path.insert(0, str(ROOT))
        from pdverify.scenes import get_scene
        cases = [(m, o) for m, o in get_scene("block2d-indentation").cases() if m != "fem"]
    if args.quick:
        cases.append(("energy-directional", dict(QUICK)))
    with tempfile.TemporaryDirectory() as tmp:
        variants = [("half", ROOT, {}), ("full", ROOT, {"symmetry": "full"})]
        if args.before:
            path = (Path(args.before) if Path(args.before).is_dir()
                    else extract(args.before, Path(tmp)))
            variants.append((f"before ({args.before})", path, {}))
        def one(method, over, name, path, extra):
            r = run_once(path, method, {**over, **extra})
            print(f"  {name:18s} {method} {over}: {r['status']} "
                  f"{r['timings']['total_s']:.1f} s", file=sys.stderr, flush=True)
            return r
        timed = harness.alternate(
            {(method, json.dumps(over), name): (lambda a=(method, over, name, path, extra): one(*a))
             for method, over in cases for name, path, extra in variants}, args.repeat,
            rotate=False)
        results = {k: t.results for k, t in timed.items()}
    print(f"{'case':44s} {'variant':18s} {'total s':>8s} {'solve s':>8s} {'cpu s':>7s} "
          f"{'solves':>6s} {'CG it':>6s} {'builds':>9s} {'newton':>6s}  status")
    sums, table = {}, {}
    for (method, over, name), rs in results.items():
        med = {k: harness.median(r["timings"][k] for r in rs) for k in ("total_s", "solve_s")}
        cpu = harness.median(r["cpu_s"] for r in rs)
        table[f"{method} {over} {name}"] = {**med, "cpu_s": cpu, "status": rs[0]["status"],
                                            "diagnostics": rs[0]["diagnostics"]}
        d, m = rs[0]["diagnostics"], rs[0]["metrics"]
        case = f"{method} {over if over != '{}' else ''}"
        print(f"{case:44s} {name:18s} {med['total_s']:8.2f} {med['solve_s']:8.2f} {cpu:7.1f} "
              f"{d.get('linear_solves', 0):6d} {d.get('cg_iterations', 0):6d} "
              f"{d.get('preconditioner_builds', 0):4d}+{d.get('preconditioner_refreshes', 0):<4d} "
              f"{m.get('newton_iterations', 0):6d}  "
              f"{rs[0]['status']}"
              + (f" at {m['failure_depth_mm']:.3g} mm" if "failure_depth_mm" in m else ""))
        sums[name] = sums.get(name, 0.0) + med["total_s"]
    base = sums.get("half")
    print("sum of the medians: " + ", ".join(
        f"{name} {t:.1f} s ({t / base:.2f}x half)" for name, t in sums.items()))
    return {"runs": table, "sum_of_medians_s": sums}


if __name__ == "__main__":
    main()
