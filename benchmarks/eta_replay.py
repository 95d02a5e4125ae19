"""How far off the progress ETA is over a report (issue 52): replays a report's records.

Plain script (no test runner):

    python benchmarks/eta_replay.py RESULTS.json [RESULTS.json ...] [--jobs N]
    python benchmarks/eta_replay.py --write-table FULL.json QUICK.json

Takes each run's ``total_s`` from RESULTS.json as its duration and replays the report's
cases on N workers (default 2) in the local pool's order
(:func:`pdverify.schedule.longest_first`, no previous report in the folder; the memory
admission is left out), feeding :class:`pdverify.progress.RunProgress` each start and
finish at the replayed times. At every finish it compares the ETA with the time the
replay really has left, and prints, per quarter of the report's duration, the median
and the largest relative error ``(ETA - left) / left``, and the ETA at the start against
the whole duration; for two cost models: ``size`` (the budget's size model, calibrated by
the runs done: the ETA before issue 52) and ``measured`` (the measured run times of
:data:`pdverify.schedule.MEASURED_TIMES`, cold references included, calibrated by the
runs done). A report whose records wrote the table measures only the calibration;
another report's records (another commit, another load, a cold cache) measure the model.

``--write-table``: writes :data:`pdverify.schedule.MEASURED_TIMES` from a full and a quick
report's results.json (each run's ``total_s``, the full report's where both have it; for a run that computes its scene's
reference, the seconds its reference study and converged solution took when computed:
``reference_study_s`` + ``reference_converged_setup_s`` + ``reference_converged_solve_s``).

Measured for issue 52 (median |ETA error| per quarter of a report, the measured times
against the size model): benchmarks/records/eta_replay-2026-11-28-issue52.json.
"""
from __future__ import annotations

import argparse
import heapq
import json
import statistics
import types

import harness
from pdverify import progress as progress_module
from pdverify.results import run_key
from pdverify.runner import plan
from pdverify.scenes import get_scene
from pdverify.schedule import (MEASURED_TIMES, case_costs, computes_reference, longest_first,
                               measured_times)

COLD_KEYS = ("reference_study_s", "reference_converged_setup_s", "reference_converged_solve_s")


def write_table(full: str, quick: str) -> None:
    rows = {}
    for path in (full, quick):
        for r in json.load(open(path))["runs"]:
            t = r.get("timings", {})
            if not isinstance(t.get("total_s"), (int, float)):
                continue
            row = {"scene": r["scene"], "method": r["method"], "params": r["params"],
                   "s": round(float(t["total_s"]), 4)}
            if computes_reference((r["scene"], r["method"], {})):
                row["cold_s"] = round(sum(float(t.get(k, 0.0)) for k in COLD_KEYS), 4)
            # a run in both reports keeps the first's time (the full report's)
            rows.setdefault(run_key(r["scene"], r["method"], r["params"]), row)
    doc = {"about": "measured run times the progress ETA starts from (pdverify.schedule."
                    "MEASURED_TIMES); written by benchmarks/eta_replay.py --write-table "
                    f"from {full} and {quick}",
           # who wrote it: the commit, machine and libraries (harness.header); the run
           # times themselves are the two reports' (their results.json name their machine)
           "header": harness.header(),
           "runs": list(rows.values())}
    with open(MEASURED_TIMES, "w") as fh:
        json.dump(doc, fh, separators=(",", ":"))
        fh.write("\n")
    print(f"{len(rows)} runs -> {MEASURED_TIMES}")


class _Clock:
    now = 0.0

    def monotonic(self):
        return self.now


def _cases(doc):
    """The report's cases, in its plan's order, with each run's duration."""
    runs = {run_key(r["scene"], r["method"], r["params"]): r for r in doc["runs"]}
    for quick in (False, True):
        cases = [c for c in plan(quick=quick)
                 if run_key(c[0], c[1], get_scene(c[0]).resolve(c[1], c[2])) in runs]
        if len(cases) == len(runs):
            break
    durations = [float(runs[run_key(c[0], c[1], get_scene(c[0]).resolve(c[1], c[2]))]
                       ["timings"]["total_s"]) for c in cases]
    return cases, durations


def replay(cases, durations, costs, jobs: int):
    """``[(time, ETA, left)]`` at the start and at every finish of the replay."""
    clock = _Clock()
    real_time = progress_module.time
    progress_module.time = types.SimpleNamespace(monotonic=clock.monotonic)
    try:
        shown = progress_module.RunProgress(cases, jobs, None, costs=costs)
        order = longest_first(cases)
        free = [(0.0, w) for w in range(jobs)]
        ends = []               # (end time, case)
        starts = {}
        for k in order:
            t, w = heapq.heappop(free)
            starts[k] = t
            ends.append((t + durations[k], k))
            heapq.heappush(free, (t + durations[k], w))
        total = max(e for e, _ in ends)
        events = sorted([(t, 0, k) for k, t in starts.items()] + [(e, 1, k) for e, k in ends])
        samples = [(0.0, None, total)]
        for t, kind, k in events:
            clock.now = t
            if kind == 0:
                shown.started(k)
                if t == 0.0:
                    samples[0] = (0.0, shown.eta(), total)
            else:
                res = types.SimpleNamespace(status="ok", outcome="ok",
                                            timings={"total_s": durations[k]})
                shown.finished(k, res)
                if t < total:
                    samples.append((t, shown.eta(), total - t))
        return samples, total
    finally:
        progress_module.time = real_time


def _errors(samples, total):
    quarters = [[] for _ in range(4)]
    for t, eta, left in samples[1:]:
        if eta is None or left <= 0:
            continue
        quarters[min(3, int(4 * t / total))].append((eta - left) / left)
    return quarters


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("results", nargs="*")
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--write-table", nargs=2, metavar=("FULL", "QUICK"))
    args = ap.parse_args(argv)
    if args.write_table:
        write_table(*args.write_table)
        return 0
    table = measured_times()
    for path in args.results:
        doc = json.load(open(path))
        cases, durations = _cases(doc)
        print(f"{path}: {len(cases)} runs, {sum(durations):.0f} s of runs, replayed on "
              f"{args.jobs} workers")
        for name, measured in (("size", {}), ("measured", table)):
            costs = case_costs(cases, measured=measured)
            samples, total = replay(cases, durations, costs, args.jobs)
            start = samples[0][1]
            quarters = _errors(samples, total)
            cells = []
            for q in quarters:
                if q:
                    med = statistics.median(abs(e) for e in q)
                    worst = max(q, key=abs)
                    cells.append(f"{100 * med:5.0f} % ({100 * worst:+.0f} %)")
                else:
                    cells.append("      -")
            print(f"  {name:9s} ETA at start {'?' if start is None else f'{start:.0f} s'} "
                  f"of {total:.0f} s; |error| median (worst) per quarter: "
                  + " | ".join(cells))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
