"""The heaviest 3D runs' solve: when the float32 factor's plain refinement stalls, the double
LU (before) or GMRES preconditioned with the same factor (GMRES-IR, now), side by side.

Plain script (no test runner):

    python benchmarks/mixed_precision.py [--case NAME ...] [--repeat N] [--json FILE]

Each case is one run of the full report whose float32 refinement stalled (full report at
b1cb6a1: ``mixed_precision = not used ...; double LU`` on exactly these five). Its
nested-dissection system is assembled once (the run's own ``solve_nested`` call is
intercepted), then solved in a fresh process per alternative (so that each peak memory,
``ru_maxrss``, is its own; one BLAS thread, as the report's workers), alternating, median
of ``--repeat`` (default 1: each solve takes 30-90 s):

- ``double-lu``: GMRES-IR switched off (``GMRES_OUTER_STEPS = 0``): plain refinement,
  then the double LU, the path before;
- ``gmres-ir``: plain refinement, then GMRES-IR on the same factor.

Printed per case: wall time of ``solve_nested``, peak memory of the process, which path
solved it, and the largest difference of the two solutions relative to the largest
entry, so that the time is not bought with accuracy.

``--stages``: in one process, the stages of the GMRES-IR path timed one by one (the
float32 factor, plain refinement, GMRES-IR, the condition estimator with one GMRES pass
per solve as ``GmresIR.solve`` does, and with each solve refined to round-off instead).
"""
from __future__ import annotations

import argparse
import json
import multiprocessing as mp
import os
import resource
import statistics
import tempfile
import time

import numpy as np

CASES = {
    "manufactured-snm3": ("body3d-manufactured", "surface-nodes", {"order": 3}),
    "manufactured-snm3-moment": ("body3d-manufactured", "surface-nodes",
                                 {"order": 3, "quadrature": "moment-corrected"}),
    "manufactured-snm3-centre": ("body3d-manufactured", "surface-nodes",
                                 {"order": 3, "surface_load": "centre"}),
    "manufactured-taylor2": ("body3d-manufactured", "taylor-fictitious", {"order": 2}),
    "traction-taylor1": ("body3d-traction", "taylor-fictitious", {"order": 1}),
}
ALTERNATIVES = ("double-lu", "gmres-ir")


class _Captured(Exception):
    pass


def _capture(case, folder):
    """Assemble the case's system (in this process) and save what ``solve_nested`` gets."""
    import scipy.sparse as sp

    import pdverify.solvers.front as front
    from pdverify.scenes import get_scene

    def grab(A, rhs, coords, where="", mixed=None):
        sp.save_npz(os.path.join(folder, "A.npz"), sp.csr_matrix(A))
        np.save(os.path.join(folder, "b.npy"), rhs)
        np.save(os.path.join(folder, "c.npy"), coords)
        raise _Captured

    front.solve_nested = grab
    scene_id, method, params = CASES[case]
    get_scene(scene_id).run(method, params)   # fails with _Captured, by design


def _solve(folder, alternative, queue):
    import scipy.sparse as sp
    from threadpoolctl import threadpool_limits

    from pdverify.solvers import mixed
    from pdverify.solvers.nested import solve_nested

    if alternative == "double-lu":
        mixed.GMRES_OUTER_STEPS = 0
    A = sp.load_npz(os.path.join(folder, "A.npz")).tocsr()
    b = np.load(os.path.join(folder, "b.npy"))
    c = np.load(os.path.join(folder, "c.npy"))
    with threadpool_limits(1):
        t0 = time.perf_counter()
        x, info = solve_nested(A, b, c, where=alternative)
        wall = time.perf_counter() - t0
    np.save(os.path.join(folder, f"x-{alternative}.npy"), x)
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1e6   # kB -> GB
    queue.put({"wall_s": wall, "peak_gb": peak, "path": info.get("mixed_precision", ""),
               "condition_estimate": info["condition_estimate"],
               "relative_residual": info["relative_residual"],
               "gmres_iterations": info.get("gmres_ir_iterations")})


def _stages(folder, queue):
    import scipy.sparse as sp
    from threadpoolctl import threadpool_limits

    from pdverify.solvers import mixed
    from pdverify.solvers.nested import ordered_system, single_precision_factor

    A = sp.load_npz(os.path.join(folder, "A.npz")).tocsr()
    b = np.load(os.path.join(folder, "b.npy"))
    c = np.load(os.path.join(folder, "c.npy"))
    out = {}
    with threadpool_limits(1):
        A_p, b_p, _, (n1, n2), _ = ordered_system(A, b, c, "stages")
        t = time.perf_counter()
        lu, _ = single_precision_factor(A_p, n1, n2)
        out["factor_s"] = time.perf_counter() - t
        probe = np.random.default_rng(20211121).standard_normal(b.size)
        stop = [mixed.REFINE_STOP, np.sqrt(b.size) * np.finfo(float).eps]
        rhs = np.column_stack([b_p, probe])
        t = time.perf_counter()
        Y, steps, _, ok = mixed.refine(A_p, rhs, lu.solve, stop=stop)
        out["plain_s"], out["plain_converged"] = time.perf_counter() - t, ok
        gm = mixed.GmresIR(A_p, lu)
        t = time.perf_counter()
        Y, _, _, ok = mixed.refine(A_p, rhs, gm.correction, stop=stop,
                                   max_steps=mixed.GMRES_OUTER_STEPS, start=Y)
        out["gmres_ir_s"], out["gmres_ir_converged"] = time.perf_counter() - t, ok
        out["gmres_ir_iterations"] = list(gm.iterations)
        t = time.perf_counter()
        out["estimate_one_pass"] = mixed.probe_condition_estimate(A_p, gm, probe, Y[:, 1])
        out["estimator_one_pass_s"] = time.perf_counter() - t
        out["estimator_worst_residual"] = gm.worst_residual

        class Refined:
            def solve(self, B, trans="N"):
                At = A_p if trans == "N" else A_p.T.tocsr()
                return mixed.refine(At, B, lambda R: gm.correction(R, trans),
                                    max_steps=mixed.GMRES_OUTER_STEPS)[0]

        t = time.perf_counter()
        out["estimate_refined"] = mixed.probe_condition_estimate(A_p, Refined(), probe, Y[:, 1])
        out["estimator_refined_s"] = time.perf_counter() - t
    queue.put(out)


def _in_fresh_process(target, *args):
    ctx = mp.get_context("spawn")
    queue = ctx.Queue()
    p = ctx.Process(target=target, args=args + (queue,))
    p.start()
    out = queue.get()
    p.join()
    return out


def _capture_in_process(case, folder, queue):
    try:
        _capture(case, folder)
    finally:
        queue.put(None)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--case", action="append", choices=sorted(CASES),
                    help="default: manufactured-snm3")
    ap.add_argument("--repeat", type=int, default=1)
    ap.add_argument("--json", default=None)
    ap.add_argument("--stages", action="store_true", help="time the GMRES-IR path's stages")
    args = ap.parse_args(argv)
    out = {}
    for case in args.case or ["manufactured-snm3"]:
        with tempfile.TemporaryDirectory() as folder:
            ctx = mp.get_context("spawn")
            q = ctx.Queue()
            p = ctx.Process(target=_capture_in_process, args=(case, folder, q))
            p.start()
            q.get()
            p.join()
            if args.stages:
                st = _in_fresh_process(_stages, folder)
                print(f"{case}: stages " + ", ".join(
                    f"{k} {v:.3g}" if isinstance(v, float) else f"{k} {v}"
                    for k, v in st.items()))
                out[case] = st
                continue
            runs = {a: [] for a in ALTERNATIVES}
            for _ in range(args.repeat):
                for a in ALTERNATIVES:
                    runs[a].append(_in_fresh_process(_solve, folder, a))
            xs = {a: np.load(os.path.join(folder, f"x-{a}.npy")) for a in ALTERNATIVES}
            diff = float(np.abs(xs["gmres-ir"] - xs["double-lu"]).max()
                         / np.abs(xs["double-lu"]).max())
        print(f"{case}: median of {args.repeat}")
        res = {}
        for a in ALTERNATIVES:
            wall = statistics.median(r["wall_s"] for r in runs[a])
            peak = statistics.median(r["peak_gb"] for r in runs[a])
            last = runs[a][-1]
            print(f"  {a:10s} solve {wall:7.1f} s  peak {peak:5.2f} GB  cond "
                  f"{last['condition_estimate']:.3g}  residual {last['relative_residual']:.2g}"
                  f"  [{last['path']}]" + (f" GMRES iterations {last['gmres_iterations']}"
                                           if last["gmres_iterations"] else ""))
            res[a] = {"wall_s": wall, "peak_gb": peak, **last}
        ratio = res["double-lu"]["wall_s"] / res["gmres-ir"]["wall_s"]
        print(f"  speed-up {ratio:.2f}x; solutions differ by {diff:.2g} (relative to max |x|)")
        out[case] = {**res, "speedup": ratio, "max_relative_difference": diff}
    if args.json:
        with open(args.json, "w") as fh:
            json.dump(out, fh, indent=2)


if __name__ == "__main__":
    main()
