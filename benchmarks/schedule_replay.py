"""Replay a report's run times through the local pool's schedule (issue 32): which order
of the cases lets the workers finish together.

Plain script (no test runner):

    python benchmarks/schedule_replay.py RESULTS.json [--jobs N] [--quick]

Takes each run's ``total_s`` from RESULTS.json (a report of the same plan), and replays
the plan's cases on N workers (default 2) with the memory admission of
:mod:`pdverify.schedule` at several limits, in three orders: the plan's, the budget's
memory estimates largest first, and the known times longest first. Prints the rank
correlation of memory estimate and run time, each order's end time against the lower
bound (total run time / N), and the longest runs.
"""
from __future__ import annotations

import argparse
import statistics
import sys

from pdverify.results import run_key
from pdverify.runner import plan
from pdverify.scenes import get_scene
from pdverify.schedule import longest_first, memory_estimates, previous_times


def _ranks(values):
    order = sorted(range(len(values)), key=lambda i: values[i])
    out = [0] * len(values)
    for pos, i in enumerate(order):
        out[i] = pos
    return out


def replay(order, times, memory, limit, workers):
    """End time of the cases in ``order`` on ``workers`` workers; a case starts when a
    worker is free and the memory of the runs in flight and its own fit ``limit`` (the
    head of the queue waits; nothing overtakes it)."""
    pending, running, now = list(order), [], 0.0
    while pending or running:
        while pending and len(running) < workers and (
                not running or sum(memory[k] for _, k in running) + memory[pending[0]] <= limit):
            k = pending.pop(0)
            running.append((now + times[k], k))
        running.sort()
        now, _ = running.pop(0)
    return now


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("results")
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--quick", action="store_true", help="the results are a --quick report")
    a = ap.parse_args(argv)
    cases = plan(quick=a.quick)
    known = previous_times(a.results)
    keys = [run_key(s, m, get_scene(s).resolve(m, o)) for s, m, o in cases]
    times = [known.get(k, 0.0) for k in keys]
    print(f"{len(cases)} cases, {sum(k in known for k in keys)} with a time in {a.results}; "
          f"total run time {sum(times):.1f} s")
    memory = memory_estimates(cases)
    ra, rb = _ranks(memory), _ranks(times)
    ma, mb = statistics.mean(ra), statistics.mean(rb)
    rho = (sum((x - ma) * (y - mb) for x, y in zip(ra, rb))
           / (sum((x - ma) ** 2 for x in ra) * sum((y - mb) ** 2 for y in rb)) ** 0.5)
    print(f"Spearman rank correlation of memory estimate and run time: {rho:.3f}")
    mem_first = sorted(range(len(cases)), key=lambda k: -memory[k])
    orders = {"plan order": list(range(len(cases))), "memory estimate first": mem_first,
              "known times first": longest_first(cases, known)}
    print(f"lower bound (total / {a.jobs}): {sum(times) / a.jobs:.1f} s")
    for limit in (4e9, 8e9, float("inf")):
        print(f"memory limit {limit / 1e9:g} GB: " + ", ".join(
            f"{name} {replay(o, times, memory, limit, a.jobs):.1f} s"
            for name, o in orders.items()))
    print("longest runs:")
    for k in sorted(range(len(cases)), key=lambda k: -times[k])[:10]:
        print(f"  {times[k]:8.1f} s  estimate {memory[k] / 1e6:8.1f} MB  {cases[k][0]} "
              f"{cases[k][1]} {cases[k][2]}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
