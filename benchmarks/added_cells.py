"""What a report's new runs cost: the runs of a report's ``results.json`` that a baseline
``results.json`` does not have (by scene, method and resolved parameters), their summed
run time (``timings.total_s``, on all workers) and largest peak memory, per scene and in
all (issue 55: its new cells may add 90 s to a full report on 2 cores; the sum over both
workers is about twice the wall time they add).

Plain script (no test runner):

    python benchmarks/added_cells.py NEW/results.json BASE/results.json [--only SCENE ...]

``--only``: the baseline's runs of these scenes only (a partial NEW report); the times
are as measured by the report (under whatever load the machine had).
"""
from __future__ import annotations

import argparse
import json
from collections import defaultdict


def _key(run) -> tuple:
    return (run["scene"], run["method"], json.dumps(run["params"], sort_keys=True))


def added(new: dict, base: dict) -> list[dict]:
    """The runs of ``new`` whose scene, method and parameters ``base`` has no run of."""
    have = {_key(r) for r in base["runs"]}
    return [r for r in new["runs"] if _key(r) not in have]


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("new", help="the report's results.json")
    ap.add_argument("base", help="the baseline report's results.json")
    ap.add_argument("--only", nargs="*", default=None, help="scenes to compare")
    args = ap.parse_args(argv)
    with open(args.new) as fh:
        new = json.load(fh)
    with open(args.base) as fh:
        base = json.load(fh)
    runs = added(new, base)
    if args.only:
        runs = [r for r in runs if r["scene"] in args.only]
    per = defaultdict(list)
    for r in runs:
        per[r["scene"]].append(r)
    total = 0.0
    for scene, rs in sorted(per.items()):
        t = sum(r["timings"].get("total_s", 0.0) for r in rs)
        total += t
        mem = max((r.get("resources", {}).get("peak_rss_gb", 0.0) for r in rs), default=0.0)
        methods = sorted({r["method"] for r in rs})
        print(f"{scene:24s} {len(rs):3d} runs {t:8.2f} s  peak {mem:.2f} GB  {', '.join(methods)}")
    print(f"{'all':24s} {len(runs):3d} runs {total:8.2f} s (summed over the workers)")


if __name__ == "__main__":
    main()
