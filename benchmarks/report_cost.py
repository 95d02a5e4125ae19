"""Where a report's time goes: runs, figures, VTU export, pages (issue 17's budget:
figures and VTU export under 15 % of the report's total time).

Plain script (no test runner):

    python benchmarks/report_cost.py [--repeat N] [--json FILE] [--full] [--only SCENE ...]
                                     [--against SRC]

Runs ``python -m pdverify report --quick`` (``--full``: the full report) ``--repeat``
times (default 3) into a temporary folder, each in a fresh process, and reads the phase
times the report records in results.json (``report_phases``: runs_s, figures_s,
fields_s, pages_s, total_s). Prints the median of each phase, its share of the total,
and the share of figures + VTU export against the 15 % budget. ``--against SRC``: also
run the report of another source tree (e.g. a ``git worktree`` of an earlier commit, put
first on PYTHONPATH), alternating with this one, and print both and the ratio of totals.
"""
from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile

PHASES = ("runs_s", "figures_s", "fields_s", "pages_s")
BUDGET = 0.15   # issue 17: figures and VTU export < 15 % of the report's total time


def one_report(full: bool, only, src=None) -> dict:
    env = dict(os.environ)
    if src:
        env["PYTHONPATH"] = os.pathsep.join([os.path.abspath(src), env.get("PYTHONPATH", "")])
    with tempfile.TemporaryDirectory() as tmp:
        out = os.path.join(tmp, "report")
        cmd = [sys.executable, "-m", "pdverify", "report", "--out", out]
        cmd += [] if full else ["--quick"]
        cmd += ["--only", *only] if only else []
        subprocess.run(cmd, check=False, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                       env=env, cwd=tmp)
        with open(os.path.join(out, "results.json")) as fh:
            doc = json.load(fh)
    return {"runs": len(doc["runs"]), **doc["report_phases"]}


def summary(name, rounds, repeat) -> dict:
    med = {k: statistics.median(r.get(k, 0.0) for r in rounds) for k in PHASES + ("total_s",)}
    drawn = (med["figures_s"] + med["fields_s"]) / med["total_s"]
    print(f"{name} ({rounds[0]['runs']} runs), median of {repeat}:")
    for k in PHASES:
        print(f"  {k[:-2]:8s} {med[k]:8.2f} s  {100 * med[k] / med['total_s']:5.1f} %")
    print(f"  {'total':8s} {med['total_s']:8.2f} s")
    print(f"  figures + VTU export: {100 * drawn:.1f} % of the total "
          f"(budget < {100 * BUDGET:.0f} %): {'met' if drawn < BUDGET else 'MISSED'}")
    return {"median": med, "figures_and_vtu_share": drawn, "rounds": rounds}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--full", action="store_true", help="the full report (default: --quick)")
    ap.add_argument("--only", nargs="+", default=None, help="scenes (default: all)")
    ap.add_argument("--json", default=None, help="write the medians and every round here")
    ap.add_argument("--against", default=None, metavar="SRC",
                    help="also time the report of this source tree, alternating")
    a = ap.parse_args(argv)
    kind = "full" if a.full else "quick"
    trees = {"this tree": None, **({f"against {a.against}": a.against} if a.against else {})}
    rounds = {name: [] for name in trees}
    for _ in range(a.repeat):
        for name, src in trees.items():
            rounds[name].append(one_report(a.full, a.only, src))
    out = {name: summary(f"report ({kind}), {name}", rs, a.repeat) for name, rs in rounds.items()}
    if a.against:
        mine, other = (out[n]["median"]["total_s"] for n in trees)
        print(f"total, this tree / against: {mine:.1f} s / {other:.1f} s = {mine / other:.2f}")
    if a.json:
        with open(a.json, "w") as fh:
            json.dump(out, fh, indent=1)
    return 0


if __name__ == "__main__":
    sys.exit(main())
