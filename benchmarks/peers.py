"""What the LAMMPS peer runs cost, and why LAMMPS is brought to equilibrium by FIRE.

Plain script (no test runner):

    python benchmarks/peers.py [--repeat N] [--only SCENE ...] [--minimisers] [--json FILE]

Times every peer run of the full report (pdverify.corrections.peer.REPORT_RUNS, both
settings) ``--repeat`` times (default 3), each in a fresh process, and prints the median
run time, LAMMPS's iterations and the sum (issue 49's budget: the peer runs add at most
60 s to a full report on 2 cores; their summed time over 2 workers bounds what they add).
``--minimisers`` runs the deck of body3d-traction (same-model, h = 0.1) with LAMMPS's
minimisers side by side (cg with the quadratic and forcezero line searches, fire) and
prints each one's stopping criterion, iterations, wall time and its field's relative L2
difference to pdverify's none (the minimiser the deck uses is the one that reaches the
force tolerance). ``--only`` times the named scenes' runs alone (issue 55's added scenes:
``--only sheet2d-clamped stiffness2d-sheet stiffness3d-box-bond bar1d-homogenization
bar1d-constraints``, budget ~10 s in all).
"""
from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time

import harness

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, ROOT)


def _one(scene_id, overrides) -> dict:
    code = ("import json, sys; from pdverify.scenes import get_scene; "
            "r = get_scene(sys.argv[1]).run('peer:lammps', json.loads(sys.argv[2])); "
            "print(json.dumps({'status': r.status, 'total_s': r.timings.get('total_s'), "
            "'iterations': r.diagnostics.get('peer', {}).get('iterations')}))")
    return harness.fresh([sys.executable, "-c", code, scene_id, json.dumps(overrides)],
                         cwd=ROOT, env=dict(os.environ, PYTHONPATH=ROOT))


def runs(repeat: int, only=None) -> list[dict]:
    from pdverify.corrections.peer import PeerTreatment
    from pdverify.scenes import get_scene
    from pdverify.corrections.registry import treatments
    peer = next(t for t in treatments().values() if isinstance(t, PeerTreatment))
    rows = []
    for scene_id in sorted(__import__("pdverify.corrections.peer", fromlist=["x"]).REPORT_RUNS):
        if only and scene_id not in only:
            continue
        for over in peer.report_runs(get_scene(scene_id), False):
            got = harness.alternate({"run": lambda: _one(scene_id, over)}, repeat)["run"].results
            rows.append({"scene": scene_id, "overrides": over,
                         "median_s": harness.median(g["total_s"] for g in got),
                         "iterations": got[0]["iterations"], "status": got[0]["status"]})
    return rows


def minimisers() -> list[dict]:
    import numpy as np
    from pdverify.exchange import node_set
    from pdverify.peers import lammps
    from pdverify.scenes import get_scene
    from pdverify.solvers.front import solve
    ns = node_set(get_scene("body3d-traction"), {"influence": "hyperbolic",
                                                 "quadrature": "full-cells", "spacing": 0.1})
    x, _ = solve(ns.system, where="bench")
    d, n = ns.dim, len(ns.x)
    u_none = np.asarray(x[:d * n]).reshape(d, n).T
    model = lammps.state_based_model(ns)
    exe, why = lammps.locate()
    if exe is None:
        raise SystemExit(f"LAMMPS unavailable: {why}")
    rows = []
    for style, extra in (("cg", "min_modify line quadratic"), ("cg", "min_modify line forcezero"),
                         ("fire", "")):
        files = lammps.deck(model, "same-model")
        text = files["in.lammps"].replace("min_style fire", f"min_style {style}\n{extra}")
        files["in.lammps"] = text
        with tempfile.TemporaryDirectory() as tmp:
            for name, body in files.items():
                with open(os.path.join(tmp, name), "w") as fh:
                    fh.write(body)
            start = time.perf_counter()
            subprocess.run([*exe.argv, "-in", "in.lammps", "-log", "log.lammps", "-screen",
                            "none", "-nocite"], cwd=tmp, env=exe.env, check=True)
            wall = time.perf_counter() - start
            info = lammps.parse_log(open(os.path.join(tmp, "log.lammps")).read())
            dump = np.loadtxt(os.path.join(tmp, "displaced.dump"), skiprows=9, ndmin=2)
            u = dump[np.argsort(dump[:, 0]), 1:1 + d] - ns.x
        rows.append({"minimiser": f"{style} {extra}".strip(), "stopping": info.get("stopping"),
                     "iterations": info.get("iterations"), "wall_s": wall,
                     "diff_to_none": float(np.linalg.norm(u - u_none) / np.linalg.norm(u_none))})
    return rows


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--only", nargs="+", metavar="SCENE", help="these scenes' runs only")
    ap.add_argument("--minimisers", action="store_true")
    ap.add_argument("--json", metavar="FILE")
    harness.add_arguments(ap)
    a = ap.parse_args(argv)
    with harness.Record(__file__, a, argv=argv) as rec:
        _measure(a, rec)
    return 0


def _measure(a, rec) -> None:
    from pdverify.results import machine_info
    doc = rec.results
    doc["machine"] = machine_info()     # as the report's results.json names it
    if a.minimisers:
        rec["minimisers"] = minimisers()
        for r in doc["minimisers"]:
            print(f"{r['minimiser']:32s} {r['stopping']:32s} {r['iterations']:>6} it "
                  f"{r['wall_s']:7.2f} s  diff to none {r['diff_to_none']:.3g}")
    rec["runs"] = runs(a.repeat, a.only)
    for r in doc["runs"]:
        print(f"{r['scene']:22s} {r['overrides'].get('setting'):11s} {r['status']:6s} "
              f"median {r['median_s']:7.2f} s  {r['iterations']} FIRE iterations")
    total = sum(r["median_s"] for r in doc["runs"])
    print(f"peer runs: {len(doc['runs'])}, summed median run time {total:.1f} s "
          f"(on 2 workers about {total / 2:.1f} s of a report's wall time)")
    if a.json:
        harness.write_json(a.json, doc)


if __name__ == "__main__":
    raise SystemExit(main())
