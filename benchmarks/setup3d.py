"""The 3D boxes' setup and assembly (issue 32): before and after, side by side in one run.

Plain script (no test runner):

    python benchmarks/setup3d.py [--before REV] [--repeat N] [--runs] [--only TEXT ...]
    python benchmarks/setup3d.py --profile {after,before} [--before REV] [--only TEXT ...]

Cases: every run the full report makes of ``body3d-manufactured`` and ``body3d-traction``
(``pdverify.runner.plan``) except ``perifit`` (its setup is the external package's);
``--only``: the cases whose label contains one of the texts (e.g. ``surface-nodes``).

Each timed case is a fresh ``python`` process running the tree's own code; this tree and
``--before REV`` (a git revision, default ``main``, extracted with ``git archive`` into a
temporary folder; or an existing folder holding another checkout) alternate within each
repeat, and the table shows medians of ``--repeat`` (default 3). Two modes:

- default: the run's setup only, as ``StaticStateScene.solve_problem`` does it (the
  problem described, the treatment's ``assemble``, BLAS on one thread as in a run): its
  wall and CPU time, and whether the assembled systems are the same (a digest of K with
  each row's entries sorted by column, the right-hand side, the prescribed unknowns
  and values, the constraint rows: equal bit for bit, or DIFFERENT);
- ``--runs``: the whole run (``Scene.run``): its setup and total wall time (the run's
  own timings), the process's CPU time for the run, and the metrics of both trees'
  first runs compared (``same``: bitwise; else the largest relative difference, and
  that metric's values).

``--profile after`` (this tree) or ``before``: cProfile of that tree's setup of each case:
the functions with the most own time, which is where the setup's time goes.

Measured for issue 32 (the surface-node setups' CPU time, 27.1 s -> 16.0 s summed, once
the displacement map is multiplied in last):
benchmarks/records/setup3d-2026-11-27-issue32-surface-nodes.json.
"""
from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path

import harness
from _trees import extract

ROOT = Path(__file__).resolve().parents[1]
SCENES = ("body3d-manufactured", "body3d-traction")
SKIP = ("perifit",)

#: one case in a fresh process: setup only (``assemble``) or the whole run; prints JSON
RUNNER = """
import hashlib, json, sys, time
import numpy as np
scene_id, method, over, mode = sys.argv[1], sys.argv[2], json.loads(sys.argv[3]), sys.argv[4]
from pdverify import blas
from pdverify.scenes import get_scene
from pdverify.corrections.registry import plugin_call
sc = get_scene(scene_id)


def canonical(A):
    # A's CSR arrays with each row's entries sorted by column: the same matrix gives the
    # same arrays whatever order a product left the entries in (the solvers sort them too)
    A = A.tocsr(copy=True)
    A.sort_indices()
    return A.indptr, A.indices, A.data


def digest(system):
    h = hashlib.sha256()
    parts = [*canonical(system.K), system.rhs, system.fixed, system.values]
    if system.B is not None:
        parts += [*canonical(system.B), system.c]
    for arr in parts:
        h.update(np.ascontiguousarray(arr).tobytes())
    return h.hexdigest()[:16]


if mode == "setup":
    p = sc.resolve(method, over)
    with blas.one_thread():
        w0, c0 = time.perf_counter(), time.process_time()
        problem = sc.problem(p, f"{scene_id}/{method}")
        t = sc.treatment(method)
        system = plugin_call(t, "assemble", t.assemble, problem, p)
        wall, cpu = time.perf_counter() - w0, time.process_time() - c0
    print(json.dumps({"setup_s": wall, "cpu_s": cpu, "digest": digest(system),
                      "nnz": int(system.K.nnz)}))
elif mode == "run":
    c0 = time.process_time()
    r = sc.run(method, over)
    print(json.dumps({"status": r.status, "setup_s": r.timings.get("setup_s"),
                      "total_s": r.timings.get("total_s"), "cpu_s": time.process_time() - c0,
                      "metrics": r.metrics}))
else:   # profile
    import cProfile, pstats
    p = sc.resolve(method, over)
    prof = cProfile.Profile()
    with blas.one_thread():
        prof.enable()
        problem = sc.problem(p, f"{scene_id}/{method}")
        t = sc.treatment(method)
        plugin_call(t, "assemble", t.assemble, problem, p)
        prof.disable()
    pstats.Stats(prof).sort_stats("tottime").print_stats(12)
"""


def cases(only) -> list[tuple[str, str, dict]]:
    sys.path.insert(0, str(ROOT))
    from pdverify.runner import plan
    out = [c for c in plan(only=list(SCENES)) if c[1] not in SKIP]
    if only:
        out = [c for c in out if any(t in label(c) for t in only)]
    return out


def label(case) -> str:
    scene, method, over = case
    short = {"body3d-manufactured": "manuf", "body3d-traction": "tract"}[scene]
    opts = ",".join(f"{k}={v:.4g}" if isinstance(v, float) else f"{k}={v}"
                    for k, v in over.items())
    return f"{short} {method}" + (f" {opts}" if opts else "")


def run_once(path: Path, case, mode: str) -> dict | str:
    scene, method, over = case
    env = {**os.environ, "PYTHONPATH": str(path)}
    cmd = [sys.executable, "-c", RUNNER, scene, method, json.dumps(over), mode]
    if mode == "profile":
        return subprocess.run(cmd, env=env, cwd=path, check=True, capture_output=True,
                              text=True).stdout
    return harness.fresh(cmd, env=env, cwd=path)


def metric_check(a: dict, b: dict) -> str:
    """``same`` when every metric is bitwise equal, else the largest relative difference."""
    if a.keys() != b.keys():
        return "different metrics"
    worst, name = 0.0, ""
    for k in a:
        x, y = a[k], b[k]
        if x == y or (x != x and y != y):
            continue
        if not isinstance(x, (int, float)) or not isinstance(y, (int, float)):
            return f"{k}: {x!r} vs {y!r}"
        rel = abs(x - y) / max(abs(x), 1e-300)
        if rel > worst:
            worst, name = rel, f" ({k}: {x!r} -> {y!r})"
    return "same" if worst == 0.0 else f"rel diff {worst:.1e}{name}"


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--before", default="main", metavar="REV",
                    help="git revision (or folder) to time as 'before' (default main)")
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--runs", action="store_true", help="whole runs, not the setup only")
    ap.add_argument("--profile", choices=("after", "before"),
                    help="cProfile the setups of this tree (after) or of --before")
    ap.add_argument("--only", nargs="*", default=[], metavar="TEXT")
    harness.add_arguments(ap)
    args = ap.parse_args(argv)
    with harness.Record(__file__, args, argv=argv, enabled=args.record and not args.profile) as rec:
        _measure(args, rec)


def _measure(args, rec):
    todo = cases(args.only)
    mode = "run" if args.runs else "setup"
    with tempfile.TemporaryDirectory() as tmp:
        before = (Path(args.before) if Path(args.before).is_dir()
                  else extract(args.before, Path(tmp)))
        trees = {"before": before, "after": ROOT}
        if args.profile:
            for case in todo:
                print(f"== {label(case)}")
                print(run_once(trees[args.profile], case, "profile"), flush=True)
            return
        if mode == "setup":
            head = (f"{'case':52s} {'setup before':>12s} {'after':>7s} {'cpu before':>10s} "
                    f"{'after':>7s}  system")
        else:
            head = (f"{'case':52s} {'setup before':>12s} {'after':>7s} {'total before':>12s} "
                    f"{'after':>7s} {'cpu before':>10s} {'after':>7s}  metrics")
        print(f"{mode} of {len(todo)} cases, medians of {args.repeat} (seconds); before = "
              f"{args.before}")
        print(head)
        sums = {k: [0.0, 0.0, 0.0] for k in trees}
        for case in todo:
            timed = harness.alternate({name: (lambda path=path: run_once(path, case, mode))
                                       for name, path in trees.items()}, args.repeat,
                                      rotate=False)
            got = {k: t.results for k, t in timed.items()}
            med = {k: {q: harness.median(r[q] for r in v)
                       for q in ("setup_s", "cpu_s") + (("total_s",) if mode == "run" else ())}
                   for k, v in got.items()}
            for k in trees:
                sums[k][0] += med[k]["setup_s"]
                sums[k][1] += med[k]["cpu_s"]
                sums[k][2] += med[k].get("total_s", 0.0)
            b, a = med["before"], med["after"]
            if mode == "setup":
                dig = {r["digest"] for v in got.values() for r in v}
                check = "same" if len(dig) == 1 else "DIFFERENT"
                rec[label(case)] = {"median": med, "system": check}
                print(f"{label(case):52s} {b['setup_s']:12.2f} {a['setup_s']:7.2f} "
                      f"{b['cpu_s']:10.2f} {a['cpu_s']:7.2f}  {check}", flush=True)
            else:
                check = metric_check(got["before"][0]["metrics"], got["after"][0]["metrics"])
                rec[label(case)] = {"median": med, "metrics": check}
                print(f"{label(case):52s} {b['setup_s']:12.2f} {a['setup_s']:7.2f} "
                      f"{b['total_s']:12.2f} {a['total_s']:7.2f} {b['cpu_s']:10.2f} "
                      f"{a['cpu_s']:7.2f}  {check}", flush=True)
        b, a = sums["before"], sums["after"]
        if mode == "setup":
            print(f"{'sum':52s} {b[0]:12.2f} {a[0]:7.2f} {b[1]:10.2f} {a[1]:7.2f}")
        else:
            print(f"{'sum':52s} {b[0]:12.2f} {a[0]:7.2f} {b[2]:12.2f} {a[2]:7.2f} "
                  f"{b[1]:10.2f} {a[1]:7.2f}")


if __name__ == "__main__":
    main()
