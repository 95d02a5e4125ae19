"""The 2D nested-dissection memory estimate (``pdverify.budget.nested_dissection_2d``)
against the measured peak of each run, every case in a fresh process.

The crack scenes solve by nested dissection (``solvers.policy``: ``auto`` from 1000
unknowns in 2D); their estimate was ``budget.linear_system``'s sparse LU, 5.6 GB for
``plate-crack`` at h = 1/60 against a measured peak of 1.96 GB. This script runs the
uncorrected model (and PALS, whose setup holds the most) of both crack scenes at
several spacings, and ``plate2d-plane-strain``'s report cases that take nested dissection
too (the uncorrected model, PALS, and surface nodes at the largest m) (``python -m pdverify run``, the FEM references from the warm cache
so that the peak is the PD run's; the FEM study's own estimate is separate,
``budget.quadratic_elements``), and prints per case: the peak above a trivial run's,
the old sparse-LU estimate, the nested-dissection model's factor entries
``F = d^2 r^2 N log2(N / r^2)`` (d = 3 unknowns a node in the augmented system, r = m:
``budget.nested_dissection_2d``), the bytes per entry the peak implies after the
matrix's ``BYTES_PER_NONZERO`` share, and the estimate now made with its ratio to the
peak.

    python benchmarks/budget_nd2d.py [--quick]

Measured (record ``benchmarks/records/budget_nd2d-2026-11-28-default.json``; peaks do
not depend on the load, the machine's was ~15 on 2 cores):

    scene                method         h  nodes  peak MB  old MB old/pk  B/entry  est/pk
    plate-crack          none     0.03333  10800      445    1404   3.15     29.4    2.02
    plate-crack          none     0.02500  19200      816    2496   3.06     28.6    2.08
    plate-crack          none     0.01667  43200     1883    5616   2.98     27.0    2.21
    plate-edge-crack     none     0.01667   7200      298     936   3.14     31.4    1.92
    plate-edge-crack     none     0.01250  12800      563    1664   2.96     31.9    1.93
    plate-crack          pals     0.02500  19200     1292    2496   1.93     56.3    1.32
    plate-edge-crack     pals     0.01250  12800      904    1664   1.84     63.4    1.20
    plate2d-plane-strain none     0.02000   2500       91     325   3.58     29.6    1.91
    plate2d-plane-strain pals     0.02000   2500      146     325   2.23     63.1    1.19
    plate2d-plane-strain surface  0.02000   2500      225     802   3.57     29.5    2.11

The implied bytes per entry stay within 27-32 (uncorrected, surface nodes) over a
6x range of N: the N log N count follows the peaks (the sparse LU's count, linear in N
with 700 B an entry, overestimated them 3x). PALS holds about twice as much beyond the
matrix; the constant (80 B, ``budget.BYTES_PER_ND2D_ENTRY``) bounds it, so the bound
is loosest, 2.2x, for the uncorrected model.
"""
from __future__ import annotations

import argparse
import math
import sys

import harness
from pdverify import budget
from pdverify.budget import measured_peak
from pdverify.params import parse_assignments
from pdverify.scenes import get_scene
from pdverify.scenes.family import StaticStateScene

CASES = [
    ("plate-crack", "none", ["spacing=0.0333333333333333333"]),
    ("plate-crack", "none", []),
    ("plate-crack", "none", ["spacing=0.016666666666666666"]),
    ("plate-edge-crack", "none", ["spacing=0.016666666666666666"]),
    ("plate-edge-crack", "none", ["spacing=0.0125"]),
    ("plate-crack", "pals", []),
    ("plate-edge-crack", "pals", ["spacing=0.0125"]),
    # the other scene whose 2D solves take nested dissection (its report cases)
    ("plate2d-plane-strain", "none", []),
    ("plate2d-plane-strain", "pals", []),
    ("plate2d-plane-strain", "surface-nodes", ["order=1", "m_ratio=5"]),
]
QUICK = CASES[:2]


def _model(scene, p):
    lengths, _ = scene.box(p)
    nodes = math.prod(L / p["spacing"] for L in lengths)
    d, m = len(lengths), p["m_ratio"]
    n, nnz = budget._unknowns_and_nonzeros(nodes, d, d + 1, m)
    old = budget.linear_system(nodes, d, d, 2 * m).memory
    entries = (d + 1) ** 2 * m * m * nodes * math.log2(max(nodes / (m * m), 2.0))
    return nodes, nnz, old, entries


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true")
    harness.add_arguments(ap)
    args = ap.parse_args(argv)
    with harness.Record(__file__, args, argv=argv) as rec:
        run = [sys.executable, "-m", "pdverify", "run"]
        base = measured_peak(run + ["bar1d-traction"])
        rec["baseline_bytes"] = base
        rows = rec["cases"] = []
        print(f"interpreter and imports: {base / 1e6:.0f} MB (subtracted)")
        print(f"{'scene':17s} {'method':6s} {'h':>7s} {'nodes':>6s} {'peak MB':>8s} "
              f"{'old MB':>7s} {'old/pk':>6s} {'F':>9s} {'B/entry':>7s} {'est MB':>7s} "
              f"{'est/pk':>6s}")
        for scene_id, method, sets in (QUICK if args.quick else CASES):
            scene = get_scene(scene_id)
            p = scene.resolve(method, parse_assignments(sets))
            nodes, nnz, old, entries = _model(scene, p)
            est = StaticStateScene.estimate(scene, method, p).memory   # PD only
            cmd = run + [scene_id, "--method", method] + [a for s in sets
                                                          for a in ("--set", s)]
            used = max(measured_peak(cmd) - base, 1e6)
            implied = (used - budget.BYTES_PER_NONZERO * nnz) / entries
            print(f"{scene_id:17s} {method:6s} {p['spacing']:7.5f} {nodes:6.0f} "
                  f"{used / 1e6:8.0f} {old / 1e6:7.0f} {old / used:6.2f} {entries:9.3g} "
                  f"{implied:7.1f} {est / 1e6:7.0f} {est / used:6.2f}", flush=True)
            rows.append({"scene": scene_id, "method": method, "set": sets,
                         "spacing": p["spacing"], "nodes": nodes, "measured_bytes": used,
                         "old_estimate_bytes": old, "factor_entries": entries,
                         "implied_bytes_per_entry": implied, "estimate_bytes": est,
                         "ratio": est / used})
            rec.save()


if __name__ == "__main__":
    main()
