"""taylor-fictitious on the 3D boxes: its three ways to the same solution side by side.

Plain script (no test runner):

    python benchmarks/taylor3d.py [--scene ID ...] [--spacing H ...] [--order N]
                                  [--repeat N] [--only ALT ...] [--json FILE]

Alternatives, each run in a fresh process (so that its peak memory, ``ru_maxrss``, is
its own), alternating (``harness.alternate``), median of ``--repeat`` (default 3) of
setup (assembly) and solve:

- ``direct``: the Lagrange system [[K, B^T], [B, 0]] of the real displacements, sparse LU
  (``solver=direct``); K couples nodes two horizons apart.
- ``nd-k-rows``: the bordered augmented system (dilatations as unknowns) under nested
  dissection with the flux rows of K's bond forces, which also couple two horizons
  apart (the form before issue 30).
- ``nd``: the same with the flux rows on the augmented unknowns (K_e on the
  displacements, K_theta on the dilatations: one horizon), what ``solver=auto`` runs.

Each prints its solution's largest difference to the first alternative's (relative to the
largest displacement) and the condition estimate, so that the speed is not bought with
accuracy.
"""
from __future__ import annotations

import argparse
import resource
import time

import numpy as np

import harness

ALTERNATIVES = ("direct", "nd-k-rows", "nd")


def _system(scene_id, spacing, order, alternative):
    """The LinearSystem of one alternative (``nd-k-rows`` rebuilt from the direct one's
    constraint rows and the augmented stiffness, as assemble_taylor did before)."""
    import scipy.sparse as sp

    from pdverify.corrections.registry import treatments
    from pdverify.pd.problem import LinearSystem
    from pdverify.scenes import get_scene
    scene = get_scene(scene_id)
    solver = "direct" if alternative in ("direct", "nd-k-rows") else "nested-dissection"
    p = scene.resolve("taylor-fictitious", {"spacing": spacing, "order": order,
                                            "solver": solver})
    system = treatments()["taylor-fictitious"].assemble(scene.problem(p, "bench"), p)
    if alternative != "nd-k-rows":
        return system
    model, B, ni, d = system.model, system.B, system.model.grid.n_interior, system.model.dim
    A = model.augmented_stiffness(model.equilibrium_rows())
    Bx = sp.hstack([B, sp.csr_matrix((B.shape[0], A.shape[0] - B.shape[1]))]).tocsr()
    M = sp.bmat([[A, Bx.T], [Bx, None]], format="csr")
    x_int = model.grid.x[model.grid.interior_ids]
    absB = abs(B).tocsr()
    at = (absB @ np.tile(x_int, (d, 1))) / np.asarray(absB.sum(axis=1))
    coords = np.r_[np.tile(x_int, (d, 1)), x_int, at]
    none = np.zeros(0, dtype=int), np.zeros(0)
    return LinearSystem(model, M, np.r_[system.rhs, np.zeros(A.shape[0] - d * ni), system.c],
                        *none, ni, solver="nested-dissection", coords=coords,
                        counts=system.counts)


def _run(args):
    """One alternative, in its own (fresh) process: its times, peak memory, solution."""
    from pdverify.solvers.front import solve
    scene_id, spacing, order, alternative = args
    t0 = time.perf_counter()
    try:
        system = _system(scene_id, spacing, order, alternative)
        t1 = time.perf_counter()
        x, info = solve(system, where=f"bench/{alternative}")
    except Exception as exc:   # a near-singular system is a result here, not a crash
        return {"failed": str(exc)}
    t2 = time.perf_counter()
    u = system.displacements(x)[:system.model.grid.n_interior]
    return {"setup_s": t1 - t0, "solve_s": t2 - t1, "nnz": int(system.K.nnz),
            "condition": float(info.get("condition_estimate", np.nan)),
            "peak_gb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 2 ** 20, "u": u}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--scene", nargs="+", default=["body3d-traction", "body3d-manufactured"])
    ap.add_argument("--spacing", nargs="+", type=float, default=[0.1, 0.05])
    ap.add_argument("--order", type=int, default=1)
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--only", nargs="+", choices=ALTERNATIVES, default=list(ALTERNATIVES))
    ap.add_argument("--json")
    harness.add_arguments(ap)
    a = ap.parse_args(argv)
    with harness.Record(__file__, a, argv=argv) as rec:
        rec["rows"] = rows = []
        _measure(a, rows, rec)
        if a.json:
            harness.write_json(a.json, rows)
    return 0


def _measure(a, rows, rec):
    for scene_id in a.scene:
        for h in a.spacing:
            first = None
            timed = harness.alternate(
                {alt: (lambda alt=alt: harness.fresh_call(_run, (scene_id, h, a.order, alt)))
                 for alt in a.only}, a.repeat)
            for alt in a.only:
                runs = timed[alt].results
                if "failed" in runs[0]:
                    print(f"{scene_id} h={h:g} {alt:10s} failed: {runs[0]['failed']}")
                    rows.append({"scene": scene_id, "spacing": h, "alternative": alt,
                                 "failed": runs[0]["failed"]})
                    continue
                u = runs[0]["u"]
                first = u if first is None else first
                row = {"scene": scene_id, "spacing": h, "alternative": alt,
                       "setup_s": harness.median(r["setup_s"] for r in runs),
                       "solve_s": harness.median(r["solve_s"] for r in runs),
                       "peak_gb": max(r["peak_gb"] for r in runs), "nnz": runs[0]["nnz"],
                       "condition": runs[0]["condition"],
                       "diff_to_first": float(np.abs(u - first).max() / np.abs(first).max())}
                rows.append(row)
                print(f"{scene_id} h={h:g} {alt:10s} setup {row['setup_s']:7.2f} s  solve "
                      f"{row['solve_s']:7.2f} s  peak {row['peak_gb']:5.2f} GB  nnz "
                      f"{row['nnz']:>10,d}  cond {row['condition']:.2e}  "
                      f"diff {row['diff_to_first']:.1e}", flush=True)
            rec.save()


if __name__ == "__main__":
    raise SystemExit(main())
