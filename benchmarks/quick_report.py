"""Where the quick report's time goes (issue 32: ``report --quick`` warm in <= 30 s on 2
cores, cold <= 60 s): its phases, the figure tasks one by one, and the cold FEM cache.

Plain script (no test runner):

    python benchmarks/quick_report.py [--repeat N] [--jobs J]
                                      [--mode fresh|inprocess|both|figures]
                                      [--profile FILE] [--cold] [--only SCENE ...]
                                      [--runs-file FILE] [--against SRC] [--keep DIR]

``--mode fresh`` (default ``both``): ``python -m pdverify report --quick`` ``--repeat``
times (default 3), each in a fresh process into a temporary folder (the interpreter's
start and the imports included), the phases each report records in results.json
(``report_phases``), the wall time of the command and its CPU time (user + system, the
report process and every worker and drawing process it waited for: on a loaded machine
a steadier measure than the wall time; the wall time on 2 quiet cores is about half of
it), the number of runs and of failed
runs, the ``critical path:`` line; medians. ``--cold``: each of those reports with an
empty FEM cache (``$PDVERIFY_CACHE_DIR`` a fresh temporary folder), so the FEM
references are computed; prints the FEM runs' times, which dominate a cold report.
``--against SRC``: the same reports of another source tree, alternating round by round.

``--mode inprocess``: one process plans the quick report, runs its cases with ``--jobs``
workers (as the report does), then draws every figure task of the report serially (as a ``--quick`` report draws
them: ``pdverify.report.figures.quick_figures``),
``--repeat`` times, timing each (a scene's figures, the error-against-cost figures, the
convergence figures), and then the report's own parallel drawing (``--jobs`` processes)
once; prints the median of each task, the sum, the figures per task and the seconds per
figure, largest first. ``--runs-file FILE``: the results are pickled there and read back by the next call
(the figures timed without running the cases again). ``--profile FILE``: cProfile of
one serial drawing of all tasks
(``python -m pstats FILE``), its top entries printed by cumulative time.

``--mode figures --runs-file FILE [--against SRC] [--keep DIR]``: the figures alone,
side by side: for this tree and for ``SRC`` (another source tree, e.g. ``git archive`` of
an earlier commit unpacked), alternating, ``--repeat`` rounds, each in a fresh process
with that tree on ``PYTHONPATH``: the quick report's figure tasks drawn serially (wall
and CPU time, and the CPU time of each task) and then as the report draws them
(``--jobs`` forked processes, default 2: wall, and CPU time including the drawing
processes'); medians, and whether the two trees' files hold the same pixels. The runs
come from ``FILE`` (made by ``--mode inprocess --runs-file FILE``), so both trees draw
the same results.

The machine is shared: run the alternatives back to back, quote medians and the load
(the script prints ``os.getloadavg()`` before and after).

Findings of issue 32 (the quick report before and after, warm and cold, where the
figures' time goes): benchmarks/records/quick_report-2026-11-27-issue32-findings.json.
"""
from __future__ import annotations

import argparse
import json
import os
import pickle
import resource
import subprocess
import sys
import tempfile
import time

import harness

HERE = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
PHASES = ("runs_s", "figures_s", "fields_s", "pages_s", "total_s")


def _load() -> str:
    return " ".join(f"{v:.2f}" for v in os.getloadavg())


def fresh_report(jobs=None, cold=False, only=None, src=HERE) -> dict:
    """One ``report --quick`` of the source tree ``src`` in a fresh process; its phases,
    wall and CPU time and runs."""
    env = {**os.environ, "PYTHONPATH": src + os.pathsep + os.environ.get("PYTHONPATH", "")}
    with tempfile.TemporaryDirectory() as tmp:
        if cold:
            env["PDVERIFY_CACHE_DIR"] = os.path.join(tmp, "fem-cache")
        out = os.path.join(tmp, "report")
        cmd = [sys.executable, "-m", "pdverify", "report", "--quick", "--out", out]
        cmd += ["--jobs", str(jobs)] if jobs else []
        cmd += ["--only", *only] if only else []
        t0 = time.perf_counter()
        r0 = resource.getrusage(resource.RUSAGE_CHILDREN)
        done = subprocess.run(cmd, cwd=tmp, env=env, capture_output=True, text=True)
        wall = time.perf_counter() - t0
        r1 = resource.getrusage(resource.RUSAGE_CHILDREN)
        cpu = (r1.ru_utime - r0.ru_utime) + (r1.ru_stime - r0.ru_stime)
        with open(os.path.join(out, "results.json")) as fh:
            doc = json.load(fh)
        figures = len(os.listdir(os.path.join(out, "figures")))
    lines = (done.stdout + done.stderr).splitlines()
    path = [x for x in lines if x.startswith("critical path:")]
    fem = sorted(((r["timings"].get("total_s", 0.0), f"{r['scene']} fem "
                   + " ".join(f"{k}={v}" for k, v in r["params"].items()
                              if k in ("kinematics", "law", "levels")))
                  for r in doc["runs"] if r["method"] == "fem"), reverse=True)
    return {**doc["report_phases"], "wall_s": wall, "cpu_s": cpu, "runs": len(doc["runs"]),
            "last": next((x for x in reversed(lines) if x.startswith("report: ")), ""),
            "exit": done.returncode, "figures": figures, "fem": fem,
            "critical_path": path[-1] if path else ""}


def fresh(a) -> dict:
    trees = {"this tree": HERE}
    if a.against:
        trees[f"against {a.against}"] = os.path.abspath(a.against)
    print(f"load before: {_load()}")
    timed = harness.alternate(       # alternating, so that the machine's load weighs alike
        {name: (lambda src=src: fresh_report(a.jobs, a.cold, a.only, src))
         for name, src in trees.items()}, a.repeat, rotate=False)
    print(f"load after:  {_load()}")
    return {name: _summary(a, name, t.results) for name, t in timed.items()}


def _summary(a, name, rounds) -> dict:
    kind = "cold (empty FEM cache)" if a.cold else "warm"
    r0 = rounds[0]
    print(f"{name}: report --quick, {kind}, fresh processes, median of {a.repeat}: "
          f"{r0['runs']} runs, "
          f"exit codes {[r['exit'] for r in rounds]}, {r0['figures']} figure files")
    print(f"  {r0['last']}")
    for k in PHASES + ("wall_s", "cpu_s"):
        vals = [r.get(k, 0.0) for r in rounds]
        print(f"  {k[:-2]:8s} {harness.median(vals):7.2f} s   "
              f"(rounds: {', '.join(f'{v:.1f}' for v in vals)})")
    for r in rounds:
        print(f"  {r['critical_path']}")
    if a.cold:
        print("  FEM runs of the first round (their references computed):")
        for t, what in r0["fem"]:
            print(f"    {t:7.2f} s  {what}")
    return {"median_s": {k: harness.median(r.get(k, 0.0) for r in rounds)
                         for k in PHASES + ("wall_s", "cpu_s")}, "rounds": rounds}


def _tasks(cases, results, figdir):
    """The figure tasks of the report, as ``pdverify.report.build`` makes them
    (``pdverify.report.drawing.figure_tasks``; in a source tree from before the report
    package's split, ``pdverify.report.figure_tasks``; from before that: the same list,
    scenes first, the overview and all convergence figures last)."""
    drawing = _drawing()
    from pdverify.convergence import collect
    from pdverify.results import run_key
    from pdverify.scenes import get_scene
    order = list(dict.fromkeys(c[0] for c in cases))
    owned = []
    for scene_id in order:
        scene = get_scene(scene_id)
        own = {run_key(scene_id, m, scene.resolve(m, o)) for m, o in scene.report_cases(True)}
        owned.append((scene, [r for r in results if r.scene == scene_id and r.key in own]))
    studies = collect(results, True)
    if hasattr(drawing, "figure_tasks"):
        return [(_short_name(what), draw, args, empty) for what, draw, args, empty
                in drawing.figure_tasks(owned, results, studies, figdir)]
    from pdverify.report import figures
    from pdverify.report.figures import convergence, overview
    scenes = [s for s, _ in owned]
    return ([(scene.id, figures.draw, (scene, mine, figdir), []) for scene, mine in owned]
            + [("error-against-cost", overview.pareto, (scenes, results, figdir), []),
               ("convergence", convergence.draw, (studies, figdir), {})])


def _drawing():
    """The module that holds ``figure_tasks`` and ``draw_all``: ``pdverify.report.drawing``,
    or in a source tree from before the report package's split (``--against``) the
    package itself, whose ``_draw_all`` it names ``draw_all`` here."""
    try:
        from pdverify.report import drawing
        return drawing
    except ImportError:
        from types import SimpleNamespace
        from pdverify import report
        return SimpleNamespace(draw_all=report._draw_all,
                               **({"figure_tasks": report.figure_tasks}
                                  if hasattr(report, "figure_tasks") else {}))


def _short_name(what):
    """A task's name in the tables: the scene, ``error-against-cost``, ``convergence
    SCENE``."""
    if what.startswith("figure for "):
        return what[len("figure for "):]
    if what.startswith("convergence figures of "):
        return "convergence " + what[len("convergence figures of "):]
    return what.replace(" figures", "")


def _count(value) -> int:
    if isinstance(value, dict):
        return sum(len(v) for v in value.values())
    return len(value)


def inprocess(a) -> dict:
    draw_all = _drawing().draw_all
    from pdverify.runner import plan, run_cases
    print(f"load before: {_load()}")
    cases = plan(only=a.only, quick=True)
    if a.runs_file and os.path.exists(a.runs_file):
        with open(a.runs_file, "rb") as fh:
            results = pickle.load(fh)
        runs_s = float("nan")
        print(f"runs: read from {a.runs_file} (not run)")
    else:
        t0 = time.perf_counter()
        results = run_cases(cases, jobs=a.jobs, progress=None)
        runs_s = time.perf_counter() - t0
        if a.runs_file:
            with open(a.runs_file, "wb") as fh:
                pickle.dump(results, fh)
    failed = sum(r.counts_as_failure for r in results)
    total = sum(r.timings.get("total_s", 0.0) for r in results)
    print(f"runs: {len(results)} ({failed} failed), {runs_s:.1f} s wall with --jobs "
          f"{a.jobs or 'default'}, {total:.1f} s summed over the runs")
    per_scene = {}
    for r in results:
        per_scene[r.scene] = per_scene.get(r.scene, 0.0) + r.timings.get("total_s", 0.0)
    for s, t in sorted(per_scene.items(), key=lambda x: -x[1])[:8]:
        print(f"  {s:28s} {t:7.2f} s")
    times, cpu, counts = {}, {}, {}
    from pdverify.report import figures
    with tempfile.TemporaryDirectory() as figdir, figures.quick_figures(True):
        tasks = _tasks(cases, results, figdir)
        for _ in range(a.repeat):
            for what, draw, args, _empty in tasks:
                t, c = time.perf_counter(), time.process_time()
                value = draw(*args)
                times.setdefault(what, []).append(time.perf_counter() - t)
                cpu.setdefault(what, []).append(time.process_time() - c)
                counts[what] = _count(value)
        if a.profile:
            import cProfile
            import pstats
            prof = cProfile.Profile()
            prof.enable()
            for _what, draw, args, _empty in tasks:
                draw(*args)
            prof.disable()
            prof.dump_stats(a.profile)
            pstats.Stats(a.profile).sort_stats("cumulative").print_stats(25)
        t = time.perf_counter()
        draw_all(tasks, a.jobs, sys.stderr)
        parallel = time.perf_counter() - t
    med = {w: harness.median(v) for w, v in times.items()}
    mcpu = {w: harness.median(v) for w, v in cpu.items()}
    print(f"figure tasks, serial, median of {a.repeat} (wall s, CPU s of this process, "
          "figures, wall s per figure):")
    for w, t in sorted(med.items(), key=lambda x: -x[1]):
        n = counts[w]
        print(f"  {w:28s} {t:7.2f} {mcpu[w]:7.2f} {n:4d} {t / n if n else 0.0:7.3f}")
    print(f"  {'sum':28s} {sum(med.values()):7.2f} {sum(mcpu.values()):7.2f} "
          f"{sum(counts.values()):4d}")
    print(f"the report's drawing (--jobs {a.jobs or 'default'} processes): {parallel:.2f} s")
    print(f"load after:  {_load()}")
    return {"runs": len(results), "failed": failed, "runs_wall_s": runs_s,
            "runs_summed_s": total, "per_scene_s": per_scene,
            "figure_tasks_median_s": med, "figure_tasks_cpu_median_s": mcpu,
            "figures_per_task": counts, "parallel_drawing_s": parallel}


def figures_child(runs_file, out, jobs) -> None:
    """In a process of its own (``PYTHONPATH`` the tree timed): the report's figure tasks
    drawn once serially into ``out/serial`` (wall and CPU time of each) and once as the
    report draws them, by ``jobs`` forked processes, into ``out/parallel`` (wall, and the
    CPU time of this process and of the drawing processes); one JSON line on stdout."""
    from pdverify.report import figures
    draw_all = _drawing().draw_all
    from pdverify.runner import plan
    with open(runs_file, "rb") as fh:
        results = pickle.load(fh)
    cases = plan(quick=True)
    row = {"tasks": {}}
    with figures.quick_figures(True):
        os.makedirs(os.path.join(out, "serial"))
        t0, c0 = time.perf_counter(), time.process_time()
        for what, draw, args, _empty in _tasks(cases, results, os.path.join(out, "serial")):
            t, c = time.perf_counter(), time.process_time()
            draw(*args)
            row["tasks"][what] = (time.perf_counter() - t, time.process_time() - c)
        row["serial_wall_s"] = time.perf_counter() - t0
        row["serial_cpu_s"] = time.process_time() - c0
        os.makedirs(os.path.join(out, "parallel"))
        tasks = _tasks(cases, results, os.path.join(out, "parallel"))
        r0 = resource.getrusage(resource.RUSAGE_CHILDREN)
        t0, c0 = time.perf_counter(), time.process_time()
        draw_all(tasks, jobs, sys.stderr)
        r1 = resource.getrusage(resource.RUSAGE_CHILDREN)
        row["parallel_wall_s"] = time.perf_counter() - t0
        row["parallel_cpu_s"] = (time.process_time() - c0 + r1.ru_utime - r0.ru_utime
                                 + r1.ru_stime - r0.ru_stime)
    print(json.dumps(row))


def figures_side_by_side(a) -> dict:
    """``--mode figures``: :func:`figures_child` of this tree and of ``--against``,
    alternating, ``--repeat`` rounds; medians side by side, and whether the two trees
    drew the same pixels (each figure file of the last round's serial drawing)."""
    if not (a.runs_file and os.path.exists(a.runs_file)):
        raise SystemExit("--mode figures draws the runs of --runs-file FILE: make it first "
                         "with --mode inprocess --runs-file FILE")
    trees = {"this tree": HERE}
    if a.against:
        trees["against"] = os.path.abspath(a.against)
    keep = a.keep or tempfile.mkdtemp(prefix="figures-")
    rounds = {name: 0 for name in trees}

    def one(name, src):
        out = os.path.join(keep, f"{'this' if name == 'this tree' else 'against'}-"
                                 f"{rounds[name]}")
        rounds[name] += 1
        env = {**os.environ, "PYTHONPATH": src + os.pathsep + os.environ.get("PYTHONPATH", "")}
        return harness.fresh([sys.executable, os.path.abspath(__file__), "--figures-child",
                              a.runs_file, out, str(a.jobs or 2)], env=env)
    print(f"load before: {_load()}")
    timed = harness.alternate({name: (lambda name=name, src=src: one(name, src))
                               for name, src in trees.items()}, a.repeat, rotate=False)
    rows = {name: t.results for name, t in timed.items()}
    print(f"load after:  {_load()}")
    med = {name: {key: harness.median(r[key] for r in rs) for key in
                  ("serial_wall_s", "serial_cpu_s", "parallel_wall_s", "parallel_cpu_s")}
           for name, rs in rows.items()}
    names = list(trees)
    print(f"figures, quick report's tasks, median of {a.repeat} rounds (alternating), "
          f"--jobs {a.jobs or 2}: " + " | ".join(f"{n}: {trees[n]}" for n in names))
    print(f"  {'':28s}" + "".join(f"{n:>22s}" for n in names))
    for key in ("serial_cpu_s", "serial_wall_s", "parallel_wall_s", "parallel_cpu_s"):
        vals = [med[n][key] for n in names]
        extra = f"   ratio {vals[0] / vals[1]:.2f}" if len(vals) == 2 else ""
        print(f"  {key:28s}" + "".join(f"{v:22.2f}" for v in vals) + extra)
        for n in names:
            print(f"    {n} rounds: {', '.join(f'{r[key]:.1f}' for r in rows[n])}")
    print("  CPU s per task (serial, median):")
    tasks = list(dict.fromkeys(t for n in names for t in rows[n][0]["tasks"]))
    cpu = {n: {t: harness.median(r["tasks"][t][1] for r in rows[n])
               for t in rows[n][0]["tasks"]} for n in names}
    for t in sorted(tasks, key=lambda t: -max(cpu[n].get(t, 0.0) for n in names)):
        print(f"    {t:34s}" + "".join(f"{cpu[n][t]:10.2f}" if t in cpu[n] else f"{'-':>10s}"
                                      for n in names))
    if len(names) == 2:
        _same_pixels(os.path.join(keep, f"this-{a.repeat - 1}", "serial"),
                     os.path.join(keep, f"against-{a.repeat - 1}", "serial"))
    print(f"  figure files kept in {keep}")
    return {"median_s": med, "rounds": rows, "cpu_per_task_median_s": cpu}


def _same_pixels(one, two) -> None:
    import numpy as np
    from PIL import Image
    files = sorted(set(os.listdir(one)) | set(os.listdir(two)))
    differ = []
    for f in files:
        try:
            a, b = (np.asarray(Image.open(os.path.join(d, f))) for d in (one, two))
        except FileNotFoundError:
            differ.append(f + " (in one tree only)")
            continue
        if a.shape != b.shape or (a != b).any():
            differ.append(f"{f} ({a.shape[1]}x{a.shape[0]} against {b.shape[1]}x{b.shape[0]})")
    print(f"  pixels: {len(files) - len(differ)} of {len(files)} files identical"
          + "".join(f"\n    differs: {d}" for d in differ))


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--jobs", type=int, default=None)
    ap.add_argument("--mode", choices=("fresh", "inprocess", "both", "figures"),
                    default="both")
    ap.add_argument("--keep", default=None, metavar="DIR",
                    help="figures mode: the figure files of every round kept in DIR")
    ap.add_argument("--figures-child", nargs=3, default=None, help=argparse.SUPPRESS)
    ap.add_argument("--profile", default=None, metavar="FILE")
    ap.add_argument("--cold", action="store_true", help="fresh reports with an empty FEM cache")
    ap.add_argument("--against", default=None, metavar="SRC",
                    help="fresh and figures modes: also time this source tree (e.g. `git "
                         "archive` of an earlier commit unpacked), alternating with this one")
    ap.add_argument("--only", nargs="+", default=None)
    ap.add_argument("--runs-file", default=None, metavar="FILE",
                    help="inprocess: the runs' results pickled here on the first call and "
                         "read back on later ones (to time the figures alone; delete the "
                         "file after a change to the runs)")
    harness.add_arguments(ap)
    a = ap.parse_args(argv)
    if a.figures_child:
        runs_file, out, jobs = a.figures_child
        figures_child(runs_file, out, int(jobs))
        return 0
    with harness.Record(__file__, a, argv=argv) as rec:
        if a.mode == "figures":
            rec["figures"] = figures_side_by_side(a)
            return 0
        if a.mode in ("fresh", "both"):
            rec["fresh"] = fresh(a)
        if a.mode in ("inprocess", "both"):
            rec["inprocess"] = inprocess(a)
    return 0


if __name__ == "__main__":
    sys.exit(main())
