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

``--estimator``: in one process, the condition estimator's three GMRES passes (the
transposed one from sign(A^-1 probe), then the unit vector and Higham's alternating
vector) one by one: iterations and true relative residual with the corrections' limit
(``GMRES_MAX_ITERATIONS``, the estimator before issue 32) and with
``ESTIMATOR_MAX_ITERATIONS``; and the float32 factor's own solves with A and A^T of a random
vector: their relative residuals against A and A^T, and against the factor's own M =
Pr^T L U Pc^T and M^T (its factors in double). Measured on manufactured-taylor2:
benchmarks/records/mixed_precision-2026-11-26-estimator.json.

``--threshold T ...``: per threshold, in a fresh process, the float32 factor with SuperLU's
diagonal pivot threshold T (``nested.FLOAT32_PIVOT_THRESHOLD``) and the refinement on it
(``refine_with_probe``): factor time and entries, refinement time, plain steps, GMRES-IR
and estimator iterations (if any), condition estimate.

``--run``: the case's whole run (``get_scene(...).run``) in a fresh process per variant,
``before`` (the estimator's passes held to ``GMRES_MAX_ITERATIONS``, as before issue 32),
``now``, ``threshold-0.1`` (the float32 factor at SuperLU's pivot threshold 0.1, the
candidate ``nested.FLOAT32_PIVOT_THRESHOLD`` describes), ``double-lu``
(``mixed=False``: the double LU alone) and ``reference`` (the double LU refined with
residuals in extended precision), median of ``--repeat``: wall time and peak memory of the
process (``ru_maxrss``), the path taken, the largest difference of the solution to the
reference (relative to its largest entry) and the largest relative difference of the
run's metrics to the reference's.

``--knobs``: SuperLU's own tuning knobs of the float32 factor, side by side: per
(``relax``, ``panel_size``, ``permc_spec``) of ``KNOB_GRID`` (``-`` is scipy's default,
SuperLU's ``sp_ienv``: panel_size 20, relax 10; neither may exceed 20, see there), in a
fresh process, alternating, median of ``--repeat``, the whole ``solve_nested`` at one
BLAS thread with its stages timed (the ordered system: equilibration, nested dissection,
permutation; the float32 factor, wall and CPU; plain refinement; the probe's condition
estimate), the factor's entries, the refinement steps, and the solution's largest
difference to the default's, relative to the largest entry of its displacement part (the
unknowns whose equation has a diagonal entry: an augmented system's multipliers have
none) and, apart, of its multiplier part. ``--system DIR`` takes a saved system
(``A.npz``, ``b.npy``, ``c.npy`` as ``_capture`` writes them) instead of assembling a
case's. Measured: no knob gains 15 %, and every one moves traction-taylor1's metrics
beyond 1e-9 (benchmarks/records/mixed_precision-2026-11-27-knobs.json).
"""
from __future__ import annotations

import argparse
import os
import resource
import tempfile
import time

import numpy as np

import harness

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


def _ordered_factor(folder, where):
    """The saved system of ``folder`` under its nested-dissection ordering and its
    single-precision factor: ``(A_p, b_p, lu, factor seconds)``."""
    import scipy.sparse as sp

    from pdverify.solvers.nested import ordered_system, single_precision_factor

    A = sp.load_npz(os.path.join(folder, "A.npz")).tocsr()
    b = np.load(os.path.join(folder, "b.npy"))
    c = np.load(os.path.join(folder, "c.npy"))
    A_p, b_p, _, (n1, n2), _ = ordered_system(A, b, c, where)
    t = time.perf_counter()
    lu, _ = single_precision_factor(A_p, n1, n2)
    return A_p, b_p, lu, time.perf_counter() - t


def _stages(folder, queue):
    from threadpoolctl import threadpool_limits

    from pdverify.solvers import mixed

    out = {}
    with threadpool_limits(1):
        A_p, b_p, lu, out["factor_s"] = _ordered_factor(folder, "stages")
        probe = np.random.default_rng(20211121).standard_normal(b_p.size)
        stop = [mixed.REFINE_STOP, np.sqrt(b_p.size) * np.finfo(float).eps]
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


def _estimator(folder, queue):
    from threadpoolctl import threadpool_limits

    from pdverify.solvers import mixed

    out = {}
    with threadpool_limits(1):
        A_p, b_p, lu, _ = _ordered_factor(folder, "estimator")
        AT = A_p.T.tocsr()
        n = A_p.shape[0]
        g = np.random.default_rng(1).standard_normal(n)
        for trans, M in (("N", A_p), ("T", AT)):
            out[f"float32_factor_residual_{trans}"] = float(
                np.linalg.norm(M @ lu.solve(g, trans=trans) - g) / np.linalg.norm(g))
        # the residuals against the factor's own M = Pr^T L U Pc^T (or M^T), its factors
        # in double: as large as against A when the float32 solves' rounding dominates
        # (whole-matrix factor only)
        if len(lu.lus) == 1:
            f = lu.lus[0]
            L, U = f.L.astype(float).tocsr(), f.U.astype(float).tocsr()
            inv_r = np.argsort(f.perm_r)

            def m_times(x, trans):          # M x = Pr^T L U Pc^T x, M^T x, as products
                if trans == "N":
                    return (L @ (U @ x[f.perm_c]))[f.perm_r]
                out_ = np.empty(n)
                out_[f.perm_c] = U.T @ (L.T @ x[inv_r])
                return out_

            for trans in ("N", "T"):
                out[f"float32_factor_residual_to_its_own_M_{trans}"] = float(
                    np.linalg.norm(m_times(lu.solve(g, trans=trans), trans) - g)
                    / np.linalg.norm(g))
            del L, U
        probe = np.random.default_rng(20211121).standard_normal(b_p.size)
        stop = [mixed.REFINE_STOP, np.sqrt(b_p.size) * np.finfo(float).eps]
        rhs = np.column_stack([b_p, probe])
        Y, _, _, _ = mixed.refine(A_p, rhs, lu.solve, stop=stop)
        gm = mixed.GmresIR(A_p, lu)
        Y, _, hist, ok = mixed.refine(A_p, rhs, gm.correction, stop=stop,
                                      max_steps=mixed.GMRES_OUTER_STEPS, start=Y)
        out["gmres_ir_converged"], out["gmres_ir_iterations"] = ok, list(gm.iterations)
        sign = np.sign(Y[:, 1])
        one = mixed.GmresIR(A_p, lu)
        z = one.solve(sign, trans="T")      # to find the unit vector, as the estimator does
        unit = np.zeros(n)
        unit[int(np.argmax(np.abs(z)))] = 1.0
        alt = (-1.0) ** np.arange(n) * (1.0 + np.arange(n) / max(n - 1, 1))
        for limit_name, limit in (("limit-60", mixed.GMRES_MAX_ITERATIONS),
                                  ("limit-now", mixed.ESTIMATOR_MAX_ITERATIONS)):
            mixed.ESTIMATOR_MAX_ITERATIONS = limit
            for name, v, trans in (("sign-T", sign, "T"), ("unit", unit, "N"),
                                   ("alternating", alt, "N")):
                gm = mixed.GmresIR(A_p, lu)
                t = time.perf_counter()
                gm.solve(v, trans=trans)
                out[f"{limit_name} {name}"] = (
                    f"{gm.iterations[0]} iterations, residual {gm.worst_residual:.2g}, "
                    f"{time.perf_counter() - t:.1f} s")
    queue.put(out)


def _threshold(folder, threshold, queue):
    """The float32 factor at SuperLU's diagonal pivot ``threshold`` and the refinement on
    it (``refine_with_probe``): times, fill, path."""
    import scipy.sparse as sp
    from threadpoolctl import threadpool_limits

    from pdverify.solvers import mixed, nested

    A = sp.load_npz(os.path.join(folder, "A.npz")).tocsr()
    b = np.load(os.path.join(folder, "b.npy"))
    c = np.load(os.path.join(folder, "c.npy"))
    nested.FLOAT32_PIVOT_THRESHOLD = threshold
    with threadpool_limits(1):
        A_p, b_p, _, (n1, n2), _ = nested.ordered_system(A, b, c, "threshold")
        t = time.perf_counter()
        lu, _ = nested.single_precision_factor(A_p, n1, n2)
        factor_s = time.perf_counter() - t
        t = time.perf_counter()
        y, cond, diag = mixed.refine_with_probe(A_p, b_p, lu)
        refine_s = time.perf_counter() - t
    queue.put({"factor_s": factor_s, "factor_entries": lu.factor_entries,
               "refine_s": refine_s, "condition_estimate": cond,
               "plain_steps": diag["refinement_steps"],
               "gmres_ir_iterations": diag.get("gmres_ir_iterations"),
               "estimator_iterations": diag.get("gmres_ir_estimator_iterations"),
               "path": diag.get("mixed_precision") or diag.get("refinement", "plain")})


def _whole_run(case, variant, folder, queue):
    import resource as res

    import pdverify.solvers.front as front
    from pdverify.scenes import get_scene
    from pdverify.solvers import mixed
    from pdverify.solvers.nested import solve_nested

    from pdverify.solvers import nested
    if variant == "threshold-0.1":
        nested.FLOAT32_PIVOT_THRESHOLD = 0.1
    if variant == "before":
        mixed.ESTIMATOR_MAX_ITERATIONS = mixed.GMRES_MAX_ITERATIONS
    seen = {}

    def keep(A, rhs, coords, where="", mixed=None):
        if variant == "reference":
            x, info = _reference_solve(A, rhs, coords, where)
        else:
            x, info = solve_nested(A, rhs, coords, where=where,
                                   mixed=False if variant == "double-lu" else mixed)
        seen["x"], seen["info"] = x, info
        return x, info

    front.solve_nested = keep
    scene_id, method, params = CASES[case]
    t0 = time.perf_counter()
    run = get_scene(scene_id).run(method, params)
    wall = time.perf_counter() - t0
    np.save(os.path.join(folder, f"x-{variant}.npy"), seen["x"])
    info = seen["info"]
    queue.put({"wall_s": wall, "peak_gb": res.getrusage(res.RUSAGE_SELF).ru_maxrss / 1e6,
               "run_total_s": run.timings.get("total_s"),
               "run_peak_rss_gb": run.resources.get("peak_rss_gb"),
               "status": run.status, "metrics": dict(run.metrics),
               "path": info.get("mixed_precision", info.get("solver", "")),
               "condition_estimate": info["condition_estimate"],
               "estimator_iterations": info.get("gmres_ir_estimator_iterations")})


def _reference_solve(A, rhs, coords, where):
    """The double LU's solution refined with residuals in extended precision
    (``np.longdouble``, 64-bit mantissa on x86): the forward error of the double LU alone
    (its backward error is that of threshold pivoting at 1e-3) is what is left of the
    difference, so the variants' solutions are measured against this one."""
    import scipy.sparse as sp

    from pdverify.solvers.checks import relative_residual
    from pdverify.solvers.lu import factor
    from pdverify.solvers.nested import ND_OPTIONS, ordered_system

    A_p, b_p, perm, _, col_max = ordered_system(sp.csr_matrix(A), np.asarray(rhs, float),
                                                coords, where)
    lu = factor(A_p.tocsc(), where, **ND_OPTIONS)
    y = lu.solve(b_p)
    data = A_p.data.astype(np.longdouble)
    residuals = []
    for _ in range(4):
        Ay = np.add.reduceat(data * y.astype(np.longdouble)[A_p.indices], A_p.indptr[:-1])
        r = b_p.astype(np.longdouble) - Ay
        residuals.append(float(np.abs(r).max()))
        y = (y.astype(np.longdouble) + lu.solve(r.astype(float))).astype(float)
    sol = np.empty_like(y)
    sol[perm] = y
    sol /= col_max
    return sol, {"condition_estimate": float("nan"), "relative_residual":
                 relative_residual(A, sol, rhs),
                 "solver": f"double LU + refinement in long double {residuals}"}


#: ``--knobs``: (relax, panel_size, permc_spec) of the float32 factor; None: as now
#: (scipy's defaults, SuperLU's sp_ienv(2) = 10 and sp_ienv(1) = 20; the nested-dissection
#: order, ``NATURAL``). Neither knob may exceed 20 with scipy's SuperLU: its StatInit sizes
#: the panel histogram by sp_ienv, max(20, 10) + 1 entries, and the factorisation counts
#: each relaxed supernode (up to ``relax`` columns) and panel (``panel_size``) at its size,
#: past that array's end: with relax 40 or 80 or panel_size 40, 2 of ~30 solves here died
#: of a corrupted heap (a TypeError from a mangled object; glibc's "munmap_chunk(): invalid
#: pointer").
#: COLAMD: SuperLU's own column order in place of the nested dissection's.
KNOB_GRID = ((None, None, None), (5, None, None), (15, None, None), (20, None, None),
             (None, 10, None), (None, 15, None), (None, None, "COLAMD"))


def _knob_name(relax, panel, permc):
    return f"relax {relax or '-'} panel {panel or '-'}" + (f" {permc}" if permc else "")


def _knobs(folder, relax, panel, permc, queue):
    """One ``solve_nested`` with the float32 factor's SuperLU ``relax``, ``panel_size`` and
    ``permc_spec`` (None: as now), its stages timed by wrapping the functions it calls."""
    import scipy.sparse as sp
    from threadpoolctl import threadpool_limits

    from pdverify.solvers import mixed, nested

    extra = {k: v for k, v in (("relax", relax), ("panel_size", panel),
                               ("permc_spec", permc)) if v is not None}
    base = nested._options
    nested._options = lambda dtype: ({**base(dtype), **extra}
                                     if np.dtype(dtype) == np.float32 else base(dtype))
    stages = {}

    def timed(name, fn):
        def wrapper(*a, **k):
            t, cpu = time.perf_counter(), time.process_time()
            try:
                return fn(*a, **k)
            finally:
                stages[name] = stages.get(name, 0.0) + time.perf_counter() - t
                if name == "factor_s":      # CPU time: the machine may be shared
                    stages["factor_cpu_s"] = time.process_time() - cpu
        return wrapper

    nested.ordered_system = timed("order_s", nested.ordered_system)
    nested.single_precision_factor = timed("factor_s", nested.single_precision_factor)
    nested.refine_with_probe = timed("refine_and_estimate_s", nested.refine_with_probe)
    mixed.probe_condition_estimate = timed("estimate_s", mixed.probe_condition_estimate)
    A = sp.load_npz(os.path.join(folder, "A.npz")).tocsr()
    b = np.load(os.path.join(folder, "b.npy"))
    c = np.load(os.path.join(folder, "c.npy"))
    with threadpool_limits(1):
        t0 = time.perf_counter()
        x, info = nested.solve_nested(A, b, c, where="knobs")
        wall = time.perf_counter() - t0
    np.save(os.path.join(folder, f"x-knobs-{relax}-{panel}-{permc}.npy"), x)
    stages["plain_refinement_s"] = (stages.pop("refine_and_estimate_s")
                                    - stages["estimate_s"])
    queue.put({"wall_s": wall, **stages, "factor_entries": info.get("factor_entries"),
               "refinement_steps": info.get("refinement_steps"),
               "path": info.get("mixed_precision", info.get("solver", "")),
               "condition_estimate": info["condition_estimate"]})


def _knob_table(name, folder, repeat):
    """``--knobs`` on the system saved in ``folder``: medians, printed and returned."""
    import scipy.sparse as sp

    runs = {k: t.results for k, t in harness.alternate(
        {knobs: (lambda knobs=knobs: _in_fresh_process(_knobs, folder, *knobs))
         for knobs in KNOB_GRID}, repeat, rotate=False).items()}
    A = sp.load_npz(os.path.join(folder, "A.npz")).tocsr()
    displacement = A.diagonal() != 0
    xs = {k: np.load(os.path.join(folder, "x-knobs-{}-{}-{}.npy".format(*k)))
          for k in KNOB_GRID}
    ref = xs[KNOB_GRID[0]]
    keys = ("wall_s", "order_s", "factor_s", "factor_cpu_s", "plain_refinement_s",
            "estimate_s")
    out = {}
    print(f"{name}: float32 factor by SuperLU's relax / panel_size, median of {repeat} "
          f"(one BLAS thread)")
    for k in KNOB_GRID:
        last = runs[k][-1]
        row = {key: harness.median(r[key] for r in runs[k]) for key in keys}
        d = np.abs(xs[k] - ref)
        row["solution_difference"] = float(d[displacement].max()
                                           / np.abs(ref[displacement]).max())
        row["multiplier_difference"] = (float(d[~displacement].max()
                                              / np.abs(ref[~displacement]).max())
                                        if (~displacement).any() else None)
        row.update(factor_entries=last["factor_entries"],
                   refinement_steps=last["refinement_steps"], path=last["path"],
                   all_wall_s=[r["wall_s"] for r in runs[k]])
        mult = row["multiplier_difference"]
        print(f"  {_knob_name(*k):27s} solve {row['wall_s']:6.2f} s (order "
              f"{row['order_s']:.2f}, factor {row['factor_s']:6.2f} / CPU "
              f"{row['factor_cpu_s']:6.2f}, refinement "
              f"{row['plain_refinement_s']:.2f}, estimate {row['estimate_s']:.2f})  "
              f"{row['factor_entries']:,d} entries  {row['refinement_steps']} steps  "
              f"solution diff {row['solution_difference']:.2g}"
              + (f" (multipliers {mult:.2g})" if mult is not None else ""), flush=True)
        out[_knob_name(*k)] = row
    return out


RUN_VARIANTS = ("before", "now", "threshold-0.1", "double-lu", "reference")


def _runs(case, repeat):
    with tempfile.TemporaryDirectory() as folder:
        runs = {v: t.results for v, t in harness.alternate(
            {v: (lambda v=v: _in_fresh_process(_whole_run, case, v, folder))
             for v in RUN_VARIANTS}, repeat, rotate=False).items()}
        xs = {v: np.load(os.path.join(folder, f"x-{v}.npy")) for v in RUN_VARIANTS}
    ref, ref_m = xs["reference"], runs["reference"][-1]["metrics"]
    out = {}
    print(f"{case}: whole run, median of {repeat}")
    for v in RUN_VARIANTS:
        last = runs[v][-1]
        m = last["metrics"]
        metric_diff = max((abs(m[k] - ref_m[k]) / abs(ref_m[k]) if ref_m[k] else abs(m[k]))
                          for k in ref_m)
        row = {"wall_s": harness.median(r["wall_s"] for r in runs[v]),
               "peak_gb": harness.median(r["peak_gb"] for r in runs[v]),
               "solution_difference": float(np.abs(xs[v] - ref).max() / np.abs(ref).max()),
               "metrics_largest_relative_difference": metric_diff, **last}
        print(f"  {v:14s} run {row['wall_s']:6.1f} s  peak {row['peak_gb']:5.2f} GB  "
              f"(the run's own: {row['run_total_s']:.1f} s, {row['run_peak_rss_gb']:.2f} GB)"
              f"  cond {row['condition_estimate']:.4g}  solution diff "
              f"{row['solution_difference']:.2g}  metrics diff {metric_diff:.2g}  "
              f"estimator iterations "
              f"{row['estimator_iterations']}  [{row['path']}]", flush=True)
        out[v] = row
    return out


class _Box:
    """Stands for the queue the targets put their one result on."""
    value = None

    def put(self, value):
        self.value = value


def _returning(target, *args):
    box = _Box()
    target(*args, box)
    return box.value


def _in_fresh_process(target, *args):
    """``target(*args, queue)`` in a fresh process (``harness.fresh_call``); what it put."""
    return harness.fresh_call(_returning, target, *args)


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
    ap.add_argument("--estimator", action="store_true",
                    help="the condition estimator's GMRES passes one by one")
    ap.add_argument("--threshold", type=float, nargs="+",
                    help="the float32 factor and its refinement at these pivot thresholds")
    ap.add_argument("--run", action="store_true",
                    help="the whole run, before/now/double LU, in fresh processes")
    ap.add_argument("--knobs", action="store_true",
                    help="the float32 factor at SuperLU's relax / panel_size (KNOB_GRID)")
    ap.add_argument("--system", action="append", metavar="DIR",
                    help="a saved system (A.npz, b.npy, c.npy) instead of a case's")
    harness.add_arguments(ap)
    args = ap.parse_args(argv)
    with harness.Record(__file__, args, argv=argv) as rec:
        _measure(args, rec)
        if args.json:
            harness.write_json(args.json, rec.results)


def _measure(args, out):
    if args.knobs and args.system:
        for folder in args.system:
            out[os.path.basename(os.path.normpath(folder))] = _knob_table(
                os.path.basename(os.path.normpath(folder)), folder, args.repeat)
        return
    for case in args.case or ["manufactured-snm3"]:
        if args.run:
            out[case] = _runs(case, args.repeat)
            continue
        with tempfile.TemporaryDirectory() as folder:
            _in_fresh_process(_capture_in_process, case, folder)
            if args.stages:
                st = _in_fresh_process(_stages, folder)
                print(f"{case}: stages " + ", ".join(
                    f"{k} {v:.3g}" if isinstance(v, float) else f"{k} {v}"
                    for k, v in st.items()))
                out[case] = st
                continue
            if args.threshold:
                print(f"{case}: float32 factor by SuperLU's diagonal pivot threshold")
                out[case] = {}
                for th in args.threshold:
                    st = _in_fresh_process(_threshold, folder, th)
                    print(f"  {th:g}: factor {st['factor_s']:.1f} s, {st['factor_entries']:,d}"
                          f" entries; refinement {st['refine_s']:.1f} s, plain steps "
                          f"{st['plain_steps']}, GMRES-IR {st['gmres_ir_iterations']}, "
                          f"estimator {st['estimator_iterations']}, cond "
                          f"{st['condition_estimate']}", flush=True)
                    out[case][th] = st
                continue
            if args.knobs:
                out[case] = _knob_table(case, folder, args.repeat)
                continue
            if args.estimator:
                st = _in_fresh_process(_estimator, folder)
                print(f"{case}: estimator")
                for k, v in st.items():
                    print(f"  {k}: {v}")
                out[case] = st
                continue
            runs = {a: t.results for a, t in harness.alternate(
                {a: (lambda a=a: _in_fresh_process(_solve, folder, a)) for a in ALTERNATIVES},
                args.repeat, rotate=False).items()}
            xs = {a: np.load(os.path.join(folder, f"x-{a}.npy")) for a in ALTERNATIVES}
            diff = float(np.abs(xs["gmres-ir"] - xs["double-lu"]).max()
                         / np.abs(xs["double-lu"]).max())
        print(f"{case}: median of {args.repeat}")
        res = {}
        for a in ALTERNATIVES:
            wall = harness.median(r["wall_s"] for r in runs[a])
            peak = harness.median(r["peak_gb"] for r in runs[a])
            last = runs[a][-1]
            print(f"  {a:10s} solve {wall:7.1f} s  peak {peak:5.2f} GB  cond "
                  f"{last['condition_estimate']:.3g}  residual {last['relative_residual']:.2g}"
                  f"  [{last['path']}]" + (f" GMRES iterations {last['gmres_iterations']}"
                                           if last["gmres_iterations"] else ""))
            res[a] = {"wall_s": wall, "peak_gb": peak, **last}
        ratio = res["double-lu"]["wall_s"] / res["gmres-ir"]["wall_s"]
        print(f"  speed-up {ratio:.2f}x; solutions differ by {diff:.2g} (relative to max |x|)")
        out[case] = {**res, "speedup": ratio, "max_relative_difference": diff}


if __name__ == "__main__":
    main()
