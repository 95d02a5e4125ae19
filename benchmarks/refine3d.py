"""3D refinement past h = 0.05: the direct solver against iterative ones on the 3D box's
state-based systems (the condensed LPS system of ``body3d-manufactured``).

Plain script (no test runner):

    python benchmarks/refine3d.py [--spacing H ...] [--method M ...] [--only ALT ...]
                                  [--repeat N] [--direct-to H] [--ilu-to H]
    python benchmarks/refine3d.py --only direct --method surface-nodes mirror-nodes pddo \
                                  --spacing 0.05 0.0416667 0.0333333   # the direct reach

Why these systems: the condensed stiffness K = A_uu + A_ut G of LPS (``none``) and of the
bond methods that keep its energy (``volume``, ``pals``) is symmetric to round-off (each
run prints the measured |y.Kx - x.Ky| / (|y| |Kx|)); ``energy``'s is not (its factors
are not symmetric per bond), so CG does not apply to it. K couples nodes two horizons
apart and is never formed here: it is applied as A_uu x + A_ut (G x) from the augmented
system the treatment assembles (one horizon), the prescribed unknowns eliminated.

Alternatives, each run in a fresh process (its peak memory, ``ru_maxrss``, is its own,
the assembly included), alternating (``harness.alternate``), median of ``--repeat``; wall
and CPU seconds (``time.process_time``, BLAS threads included: the fairer comparison
when other processes load the machine) of the assembly, the preconditioner and the solve:

- ``direct``: the front door's solve as the report ran it before issue 55
  (``solver=auto`` then: nested dissection, the multifrontal float32 factor refined in
  double; ``solver=nested-dissection`` now); up to ``--direct-to``. ``--only direct``
  measures the reach of the direct solver alone, on any method of the scene (the node-
  adding ones: their systems are not symmetric);
- ``cg-jacobi``: scipy CG on K with the exact diagonal of K as preconditioner;
- ``cg-ilu``: scipy CG, preconditioned by SuperLU's incomplete LU of A_uu (drop
  tolerance 1e-3, fill factor 5; a looser one, 1e-2, is not positive definite enough
  for CG: 5,000 iterations without convergence at h = 0.05); up to ``--ilu-to``;
- ``cg-pyamg``: scipy CG, preconditioned by one V-cycle of pyamg's smoothed aggregation
  of A_uu (the bond part: symmetric positive definite, spectrally close to K since the
  dilatation part adds a positive semi-definite k_theta-term) with the rigid-body modes
  as near-null space, pyamg's defaults otherwise (symmetric Gauss-Seidel);
- ``cg-pyamg-jacobi``: the same with Jacobi smoothing (omega 4/3) in the cycle.

``cg-pyamg*`` need pyamg (the optional extra ``bench``: ``python -m pip install -e
".[bench]"``); without it those rows fail and the others run.

Every CG stops at a relative residual of 1e-10. Its error is measured against the direct
solution where ``direct`` ran, else against a CG solve to 1e-13; the run's method error
(``rel_l2_error`` against the manufactured field, the study's metric) is printed beside
it: the argument that the iterative solve leaves the discretisation error unchanged is
that its error is at least 100x below the method error.

Measured 2026-11-28 under load (load average 10-17 on the 2 cores, so wall times are
inflated several-fold and noisy; CPU seconds compare the alternatives fairly), ``none``
(records refine3d-2026-11-28-levels-0.05-to-1-36, -cpu-none-1-30, -cpu-none-1-36,
-cpu-volume-pals-1-30, -direct-reach); set-up of the preconditioner + solve, the assembly apart:

    spacing  unknowns  direct            cg-jacobi          cg-ilu        cg-pyamg
    0.05       8,000   15.6 s  0.58 GB   1.05 s  91 it      7.9 s  41 it  3.3 s  16 it
    1/24      13,824   25.0 s  0.91 GB   1.4 s  109 it     19.5 s  43 it  6.0 s  17 it
    1/30      27,000   67 s    2.04 GB   4.8 s CPU 137 it   -             5.4 s CPU 15 it
    1/36      46,656   -                 7.1 s CPU 165 it   -             8.1 s CPU 19 it

(peak with the assembly: CG 0.30, 0.47, 0.89, 1.52 GB; pyamg 5-10 % more). At 1/30
``volume``: Jacobi 4.95 s of CPU (136 it), pyamg 5.44 s; ``pals`` (two scalars a node):
Jacobi 5.92 s (138 it, 1.33 GB), pyamg 7.13 s. ``energy``'s K is 2.0e-5 off symmetric
at 1/24 (the others 4e-18 to 2e-17), so CG is not applied to it. Every CG solution is within 5e-10 of the
direct one (Jacobi and pyamg within 2.3e-11), against a method error (rel_l2_error) of
0.59 to 0.37: nine orders below it, far past the 100x the study needs. What it shows:
the multifrontal solve ends at h = 1/30 (2.0 GB); Jacobi-CG is the fastest up to 1/30
(no set-up, and its ~1/h iterations are cheap), and still at 1/36 (7.1 against 8.1 s
of CPU, record -cpu-none-1-36), though the gap narrows as Jacobi's iterations grow and
pyamg's do not, so pyamg's hierarchy may pay off on larger boxes; ILU's factorisation
costs more than it saves. The direct solve of the systems
that are not symmetric at spacing 1/24: energy 0.93 GB, mirror nodes 1.08 GB, PDDO
0.89 GB (6-10 s of CPU each), surface nodes 2.23 GB.
"""
from __future__ import annotations

import argparse
import resource
import time
from dataclasses import replace

import numpy as np

import harness

ALTERNATIVES = ("direct", "cg-jacobi", "cg-ilu", "cg-pyamg", "cg-pyamg-jacobi")
SCENE = "body3d-manufactured"
RTOL = 1e-10
#: the tighter solve that stands for the exact one where the direct solver is not run
REFERENCE_RTOL = 1e-13


def _rss_mb() -> float:
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024


def _condensed_operator(system):
    """K = A_uu + A_ut G on the free displacement unknowns, applied, not formed; its
    right-hand side, exact diagonal, the free indices and A_uu's free block."""
    import scipy.sparse as sp
    A = sp.csr_matrix(system.K)
    n = A.shape[0] - int(system.scalars)
    A_uu, A_ut, G = A[:n, :n], A[:n, n:], A[n:, :n]
    keep = np.ones(n, dtype=bool)
    keep[np.asarray(system.fixed, dtype=int)] = False
    free = np.flatnonzero(keep)
    u0 = np.zeros(n)
    u0[system.fixed] = system.values
    rhs = np.asarray(system.rhs, dtype=float)[:n]
    r = (rhs - A_uu @ u0 - A_ut @ (G @ u0))[free]
    Af, Atf, Gf = A_uu[free][:, free].tocsr(), A_ut[free].tocsr(), G[:, free].tocsr()
    diag = Af.diagonal() + np.asarray(Atf.multiply(Gf.T).sum(axis=1)).ravel()
    return (lambda x: Af @ x + Atf @ (Gf @ x)), r, diag, free, Af, u0, G


def _rigid_modes(system, free):
    """The six rigid-body modes on the displacement unknowns (component-major)."""
    g = system.model.grid
    x = g.x[g.interior_ids]
    nn = x.shape[0]
    comp = np.repeat(np.arange(3), nn)
    X = np.tile(x, (3, 1))
    B = np.zeros((3 * nn, 6))
    B[np.arange(3 * nn), comp] = 1.0
    for k, (i, j) in enumerate(((0, 1), (1, 2), (2, 0))):
        B[:, 3 + k] = np.where(comp == i, -X[:, j], np.where(comp == j, X[:, i], 0.0))
    return B[free]


def _run(args):
    """One alternative at one size, in its own process: times, iterations, peak memory,
    the free displacements and the method error of the solution."""
    import scipy.sparse.linalg as spla
    from pdverify.scenes import get_scene
    from pdverify.solvers.front import solve
    method, h, alt, rtol = args
    scene = get_scene(SCENE)
    p = scene.resolve(method, {"spacing": h})
    t0, c0 = time.perf_counter(), time.process_time()
    problem = scene.problem(p, "bench")
    system = scene.treatment(method).assemble(problem, p)
    setup_s = time.perf_counter() - t0
    out = {"setup_s": setup_s, "setup_cpu_s": time.process_time() - c0,
           "assembly_peak_mb": _rss_mb(), "unknowns": int(system.K.shape[0])}
    t1, c1 = time.perf_counter(), time.process_time()
    try:
        if alt == "direct":
            if system.scalars:        # the solver auto took in 3D before issue 55
                system = replace(system, solver="nested-dissection")
            x, info = solve(system, where="bench/direct")
            out.update(precond_s=0.0, solve_s=time.perf_counter() - t1, iterations=0,
                       precond_cpu_s=0.0, solve_cpu_s=time.process_time() - c1,
                       solver=info.get("solver"))
            n = system.K.shape[0] - int(system.scalars)
            keep = np.ones(n, dtype=bool)
            keep[np.asarray(system.fixed, dtype=int)] = False
            u_free = x[:n][keep]
        else:
            apply_K, r, diag, free, Af, u0, G = _condensed_operator(system)
            N = free.size
            rng = np.random.default_rng(0)
            a, b = rng.standard_normal(N), rng.standard_normal(N)
            Ka = apply_K(a)
            out["asymmetry"] = float(abs(b @ Ka - a @ apply_K(b))
                                     / (np.linalg.norm(b) * np.linalg.norm(Ka)))
            K = spla.LinearOperator((N, N), matvec=apply_K, dtype=float)
            if alt == "cg-jacobi":
                M = spla.LinearOperator((N, N), matvec=lambda v: v / diag, dtype=float)
            elif alt == "cg-ilu":
                ilu = spla.spilu(Af.tocsc(), drop_tol=1e-3, fill_factor=5)
                M = spla.LinearOperator((N, N), matvec=ilu.solve, dtype=float)
            else:
                import pyamg
                kw = {}
                if alt == "cg-pyamg-jacobi":
                    jac = ("jacobi", {"omega": 4.0 / 3.0, "iterations": 1})
                    kw = {"presmoother": jac, "postsmoother": jac}
                ml = pyamg.smoothed_aggregation_solver(Af, B=_rigid_modes(system, free),
                                                       max_coarse=500, **kw)
                M = ml.aspreconditioner(cycle="V")
            t2, c2 = time.perf_counter(), time.process_time()
            count = [0]
            u_free, code = spla.cg(K, r, M=M, rtol=rtol, atol=0.0, maxiter=20000,
                                   callback=lambda xk: count.__setitem__(0, count[0] + 1))
            res = float(np.linalg.norm(apply_K(u_free) - r) / np.linalg.norm(r))
            out.update(precond_s=t2 - t1, solve_s=time.perf_counter() - t2,
                       precond_cpu_s=c2 - c1, solve_cpu_s=time.process_time() - c2,
                       iterations=count[0], relative_residual=res, converged=code == 0)
            u = u0.copy()
            u[free] = u_free
            x = np.r_[u, G @ u]
    except Exception as exc:        # a failure is a result here, not a crash
        return {**out, "failed": f"{type(exc).__name__}: {exc}"[:300]}
    metrics = scene.measure(p, problem, system, x, {}).metrics
    out.update(peak_mb=_rss_mb(), rel_l2_error=float(metrics["rel_l2_error"]),
               u_free=u_free)
    return out


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--spacing", nargs="+", type=float,
                    default=[0.05, 1 / 24, 1 / 30, 1 / 36])
    ap.add_argument("--method", nargs="+", default=["none", "volume", "pals"])
    ap.add_argument("--only", nargs="+", choices=ALTERNATIVES, default=list(ALTERNATIVES))
    ap.add_argument("--repeat", type=int, default=1)
    ap.add_argument("--direct-to", type=float, default=1 / 30,
                    help="the finest spacing the direct solver is run at")
    ap.add_argument("--ilu-to", type=float, default=1 / 24,
                    help="the finest spacing the ILU preconditioner is run at")
    harness.add_arguments(ap)
    a = ap.parse_args(argv)
    with harness.Record(__file__, a, argv=argv) as rec:
        rec["rows"] = rows = []
        for method in a.method:
            for h in a.spacing:
                alts = [alt for alt in a.only
                        if not (alt == "direct" and h < a.direct_to * (1 - 1e-9))
                        and not (alt == "cg-ilu" and h < a.ilu_to * (1 - 1e-9))]
                timed = harness.alternate(
                    {alt: (lambda alt=alt: harness.fresh_call(_run, (method, h, alt, RTOL)))
                     for alt in alts}, a.repeat)
                if "direct" in alts and "failed" not in timed["direct"].results[0]:
                    ref, ref_name = timed["direct"].results[0]["u_free"], "direct"
                elif alts == ["direct"]:          # the direct solver's reach alone
                    ref, ref_name = None, None
                else:
                    ref = harness.fresh_call(_run, (method, h, "cg-jacobi",
                                                    REFERENCE_RTOL))["u_free"]
                    ref_name = f"cg-jacobi to {REFERENCE_RTOL:g}"
                for alt in alts:
                    runs = timed[alt].results
                    first = runs[0]
                    row = {"method": method, "spacing": h, "delta": 3 * h, "alternative": alt,
                           **{k: v for k, v in first.items() if k != "u_free"}}
                    if "failed" not in first:
                        for k in ("setup_s", "precond_s", "solve_s", "setup_cpu_s",
                                  "precond_cpu_s", "solve_cpu_s"):
                            row[k] = harness.median(r[k] for r in runs)
                        row["peak_mb"] = max(r["peak_mb"] for r in runs)
                        row["solver_error"] = (0.0 if ref is None else float(
                            np.linalg.norm(first["u_free"] - ref) / np.linalg.norm(ref)))
                        row["solver_error_against"] = ref_name
                        row["method_error_over_solver_error"] = (
                            row["rel_l2_error"] / row["solver_error"]
                            if row["solver_error"] > 0 else float("inf"))
                    rows.append(row)
                    if "failed" in first:
                        print(f"{method:7s} h={h:.4f} {alt:16s} failed: {first['failed']}",
                              flush=True)
                        continue
                    print(f"{method:7s} h={h:.4f} {alt:16s} n {row['unknowns']:>6d} setup "
                          f"{row['setup_s']:6.2f} prec {row['precond_s']:6.2f} solve "
                          f"{row['solve_s']:6.2f} s (cpu {row['precond_cpu_s'] + row['solve_cpu_s']:6.2f}) "
                          f"it {row['iterations']:4d}  peak "
                          f"{row['peak_mb']:6.0f} MB  rel_l2 {row['rel_l2_error']:.4g}  "
                          f"solver err {row['solver_error']:.1e}"
                          + (f"  asym {row['asymmetry']:.1e}" if "asymmetry" in row else ""),
                          flush=True)
                rec.save()
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
