"""Solvers side by side on the same matrices: ours, scipy's default, PARDISO (if installed).

Plain script (no test runner):

    python benchmarks/solvers.py [--repeat N] [--slow-repeat M] [--json FILE] [--only CASE ...]

Every alternative runs on the same matrix in one process, alternating, median of
``--repeat`` (default 3); scipy's default ``spsolve`` on the SPD case takes ~2 minutes and
runs ``--slow-repeat`` times (default 1). PARDISO comes from ``pypardiso`` (the optional
extra ``bench``); without it those rows are skipped. Cases:

- ``spd``: a bond-based stiffness the size of seed 003's indentation block (160 x 160
  nodes, m = 6, constant micromodulus, bottom held, top pushed): 50,880 unknowns. Ours is
  CG with the two-level preconditioner (``pdverify.solvers.iterative``), set up once and
  reused, as in a Newton sequence: three solves with different right-hand sides and one
  with a changed matrix S K S, S = 1 + 0.05 sin(pi x) sin(pi y) per unknown (stiffness
  changed smoothly by up to 10 %, as a tangent does between steps). Budget (issue 12): < 0.5 s per solve,
  >= 8x PARDISO's factor-and-solve, >= 200x scipy's default, residual <= 1e-10.
- ``plate``: the seed-001 plane-strain plate at h = 0.01 (20,800 displacement unknowns).
  Today's direct solve of K (SuperLU, COLAMD) against ours (the augmented system under
  nested dissection: float32 LU, two halves in parallel, refined in float64), and PARDISO
  on both matrices. Budget: >= 1x PARDISO, >= 10x today. Ours is also compared (untimed)
  with the same ordering's float64 LU, the path before the mixed precision; ``--with-double``
  times that path as well.
- ``body3d``: body3d-traction, surface nodes, h = 0.1 and 0.05: the LU of K (dense at
  h = 0.05) against nested dissection and PARDISO; then ours alone at h = 1/30 (27,000
  unknowns, ~3 min and ~8 GB: the dense LU would need ~12 GB), the fitted exponent of its
  solve time over h = 0.1 ... 1/30, and the memory estimate of h = 0.025 and of a ~100 k-node
  body (h = 1/70), which are not run.
- ``crossover3d``: whole runs (assembly and solve, ``scene.run``) of the 3D scenes with
  ``solver=direct`` against ``solver=nested-dissection`` over small to default sizes:
  where ``solver=auto`` switches in 3D (``ND3D_FROM_UNKNOWNS``).
- ``crossover2d``: the same for plate2d-plane-strain at the report's sizes (h = 0.1 ...
  0.02, m = 3, 4, 5, 8): where it switches in 2D (``ND_FROM_UNKNOWNS``).
- ``pddo``: whole PDDO runs (its own square system, SuperLU), COLAMD against minimum
  degree on A + A^T (``PDDO_ORDERING``), 2D and 3D.
"""
from __future__ import annotations

import argparse
import math

import harness
import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from pdverify.pd import BondBasedModel, BoxGrid, build_stencil, get_influence
from pdverify.pd.influence import bond_micromodulus
from pdverify.scenes import get_scene
from pdverify.solvers.condense import condense
from pdverify.solvers.front import solve_with_dirichlet
from pdverify.solvers.iterative import Lattice, TwoLevelPreconditioner, cg_solve
from pdverify.solvers.nested import solve_nested

try:
    import pypardiso
except ImportError:  # the optional extra 'bench'
    pypardiso = None


def timed(fn):
    """(seconds, result) of one call."""
    t = harness.alternate({"x": fn}, 1)["x"]
    return t.median, t.last


def alternate(alternatives, repeat):
    """{name: fn}: run each in turn, ``repeat`` rounds (``harness.alternate``);
    {name: (median s, last result)}."""
    return {k: (t.median, t.last) for k, t in harness.alternate(alternatives, repeat).items()}


def pardiso_factor_solve(A, b):
    """A fresh PARDISO factorisation and solve (no cached factor)."""
    solver = pypardiso.PyPardisoSolver()
    A = sp.csr_matrix(A)
    solver.factorize(A)
    x = solver.solve(A, b)
    solver.free_memory(everything=True)
    return x


def rel_res(A, x, b):
    return float(np.linalg.norm(A @ x - b) / np.linalg.norm(b))


# ------------------------------------------------------------------ SPD (indentation size)
def spd_system(nodes=160, m=6):
    h = 1.0 / (nodes - 1)
    grid = BoxGrid((1.0, 1.0), (0.0, 0.0), h, placement="on-surface")
    model = BondBasedModel(grid, build_stencil(2, m, quadrature="partial-volume"),
                           bond_micromodulus("constant", 2, 1e9, m * h, plane="stress"),
                           get_influence("constant"))
    n, x = grid.n_ext, grid.x
    bottom = np.flatnonzero(np.isclose(x[:, 1], 0.0))
    fixed = np.r_[bottom, n + bottom]
    free = np.setdiff1d(np.arange(2 * n), fixed)
    K = model.K.tocsr()[free][:, free].tocsr()
    top = np.flatnonzero(np.isclose(x[:, 1], 1.0))
    loads = []
    for shear in (0.0, 0.3, -0.7):   # three right-hand sides, as three load steps
        f = np.zeros(2 * n)
        f[n + top] = -1.0
        f[top] = shear
        loads.append(f[free])
    lattice = Lattice.component_major(grid.index, grid.x, 2).take(free)
    return K, loads, lattice, m


def bench_spd(args, out):
    K, loads, lattice, m = spd_system()
    print(f"\n[spd] bond-based, 160 x 160 nodes, m = 6: {K.shape[0]} unknowns, {K.nnz} non-zeros")
    setup_s, pc = timed(lambda: TwoLevelPreconditioner(K, lattice, m))
    x = lattice.x
    S = sp.diags(1.0 + 0.05 * np.sin(np.pi * x[:, 0]) * np.sin(np.pi * x[:, 1]))
    K2 = (S @ K @ S).tocsr()
    ours = {f"ours: CG solve, load {i + 1}": (lambda b=b: cg_solve(K, b, pc, where="bench"))
            for i, b in enumerate(loads)}
    ours["ours: CG solve, changed matrix (Newton-like)"] = lambda: cg_solve(K2, loads[0], pc,
                                                                         where="bench")
    if pypardiso is not None:
        ours["PARDISO factor + solve"] = lambda: pardiso_factor_solve(K, loads[0])
    res = alternate(ours, args.repeat)
    if pypardiso is not None:
        ps = pypardiso.PyPardisoSolver()
        ps.factorize(K)
        res["PARDISO solve, factor reused"] = alternate({"x": lambda: ps.solve(K, loads[1])},
                                                        args.repeat)["x"]
        ps.free_memory(everything=True)
    slow = {"scipy spsolve (default)": lambda: spla.spsolve(K.tocsc(), loads[0]),
            "SuperLU symmetric mode (today's SPD path)": lambda: solve_with_dirichlet(
                K, loads[0], np.array([], int), np.array([]), "bench", spd=True)[0]}
    if args.slow_repeat > 0:
        res.update(alternate(slow, args.slow_repeat))
    per_solve = [v[0] for k, v in res.items() if k.startswith("ours: CG solve, load")]
    ours_med = float(np.median(per_solve))
    print(f"  ours: preconditioner setup {setup_s:.2f} s (once; coarse {pc.coarse_size})")
    for name, (t, r) in res.items():
        x = r[0] if isinstance(r, tuple) else r
        A = K2 if "changed" in name else K
        b = loads[1] if "factor reused" in name else loads[0]
        if name.startswith("ours: CG solve, load"):
            b = loads[int(name[-1]) - 1]
        extra = (f", {r[1]['iterations']} iterations" if isinstance(r, tuple) else "")
        print(f"  {name:46s} {t:8.3f} s   residual {rel_res(A, x, b):.1e}{extra}"
              f"   {t / ours_med:7.1f}x ours")
    print(f"  ours per solve (median over the three loads): {ours_med:.3f} s (budget < 0.5 s: "
          f"{'met' if ours_med < 0.5 else 'MISSED'})")
    for name, need in (("PARDISO factor + solve", 8), ("scipy spsolve (default)", 200)):
        if name in res:
            ratio = res[name][0] / ours_med
            print(f"  speed-up vs {name}: {ratio:.1f}x (budget >= {need}x: "
                  f"{'met' if ratio >= need else 'MISSED'})")
    out["spd"] = {"setup_s": setup_s, "per_solve_s": ours_med,
                  **{k: v[0] for k, v in res.items()}}


# ------------------------------------------------------------------ state-based systems
def bench_state(args, out, scene_id, spacing, key):
    scene = get_scene(scene_id)
    systems = {}
    for solver in ("direct", "nested-dissection"):
        p = scene.resolve("surface-nodes", {"spacing": spacing, "solver": solver})
        t_setup, system = timed(lambda: scene.treatment("surface-nodes").assemble(
            scene.problem(p, "bench"), p))
        systems[solver] = (system, system.K, system.rhs, system.fixed, system.values, t_setup)
    model = systems["direct"][0]
    n_disp = systems["direct"][1].shape[0]
    print(f"\n[{key}] {scene_id}, surface nodes, h = {spacing}: {n_disp} unknowns; K "
          f"{systems['direct'][1].nnz} non-zeros, augmented {systems['nested-dissection'][1].nnz}")
    alts = {}
    for solver, (model, A, rhs, fixed, values, _) in systems.items():
        coords = None if solver == "direct" else model.coords
        label = ("today: direct (K multiplied out)" if solver == "direct"
                 else "ours: nested dissection (augmented)")
        alts[label] = (lambda A=A, rhs=rhs, fixed=fixed, values=values, solver=solver,
                       coords=coords: solve_with_dirichlet(A, rhs, fixed, values, "bench",
                                                           solver=solver, coords=coords))
        if pypardiso is not None:
            Af, bf, _ = condense(A, rhs, fixed, values)
            alts[f"PARDISO on {'K' if solver == 'direct' else 'the augmented system'}"] = (
                lambda Af=Af, bf=bf: pardiso_factor_solve(Af, bf))
    model, A, rhs, fixed, values, _ = systems["nested-dissection"]
    Af, bf, expand = condense(A, rhs, fixed, values)
    free = expand.free
    coords_free = np.asarray(model.coords)[free]
    if args.with_double:
        alts["ours before: nested dissection, float64 LU"] = (
            lambda: solve_nested(Af, bf, coords_free, where="bench", mixed=False))
    res = alternate(alts, args.repeat)
    ref = res["today: direct (K multiplied out)"][1][0]
    ours = res["ours: nested dissection (augmented)"][0]
    u_ours, info = res["ours: nested dissection (augmented)"][1]
    u_double = (res["ours before: nested dissection, float64 LU"][1][0] if args.with_double
                else solve_nested(Af, bf, coords_free, where="bench", mixed=False)[0])
    diff = np.abs(u_ours[free] - u_double).max() / np.abs(u_double).max()
    print(f"  ours: {info.get('mixed_precision', 'float64 LU')}; refinement steps "
          f"{info.get('refinement_steps', '-')}, residuals "
          f"{', '.join(f'{r:.1e}' for r in info.get('refinement_residuals', []))}; "
          f"condition estimate {info['condition_estimate']:.3e}; relative residual "
          f"{info['relative_residual']:.1e}")
    print(f"  ours vs the float64 LU of the same ordering: max |du| / max |u| = {diff:.1e}")
    for name, (t, r) in res.items():
        if name.startswith("ours before"):   # the free unknowns only
            x = expand(r[0])[:ref.size]
            agree = np.linalg.norm(x - ref) / np.linalg.norm(ref)
            note = f"solution vs today's {agree:.1e}"
        elif isinstance(r, tuple):
            x = r[0][:ref.size]
            agree = np.linalg.norm(x - ref) / np.linalg.norm(ref)
            note = f"solution vs today's {agree:.1e}"
        else:
            note = ""
        print(f"  {name:40s} {t:8.2f} s   {t / ours:6.2f}x ours   {note}")
    for name, setup in (("direct", systems["direct"][5]), ("augmented", systems["nested-dissection"][5])):
        print(f"  assembly ({name}): {setup:.2f} s")
    rows = {k: v[0] for k, v in res.items()}
    out[key] = {"unknowns": int(n_disp), **rows}
    return n_disp, rows


def bench_3d_large(out, sizes):
    """Ours alone at h = 1/30 (27,000 unknowns; the dense LU would need ~12 GB): one whole
    run, whose setup and solve times the run itself records; the fitted exponent of ours
    over h = 0.1 ... 1/30; the budget's estimate for h = 0.025 and for a ~100 k-node body,
    which a run refuses above the memory limit, so they are not run."""
    import pdverify.budget as budget
    scene = get_scene("body3d-traction")
    name = "ours: nested dissection (augmented)"
    points = [(n, rows[name]) for n, rows in sizes]
    budget.set_limit("20G")
    r = scene.run("surface-nodes", {"spacing": 1 / 30})
    t = r.timings["solve_s"]
    n = r.size["dofs"]
    print(f"\n[body3d h=1/30] ours only: {n} unknowns, status {r.status}; setup "
          f"{r.timings['setup_s']:.1f} s, solve {t:.1f} s; factor entries "
          f"{r.diagnostics.get('factor_entries', 0):.3g}; refinement steps "
          f"{r.diagnostics.get('refinement_steps')}; rel_l2_error {r.metrics['rel_l2_error']:.6e}")
    out["body3d h=1/30"] = {"unknowns": int(n), name: t, "setup": r.timings["setup_s"]}
    points.append((n, t))
    a = np.polyfit(np.log([p[0] for p in points]), np.log([p[1] for p in points]), 1)[0]
    print(f"  fitted solve time ~ N^a over h = 0.1, 0.05, 1/30 (ours): a = {a:.2f}")
    out["body3d exponent"] = float(a)
    budget.set_limit(None)
    limit, _ = budget.memory_limit()
    for label, over in (("h = 0.025", {"spacing": 0.025}),
                        ("~100 k nodes (h = 1/70: 85,750 interior, 12,250 surface)",
                         {"spacing": 1 / 70})):
        budget.set_limit("1000T")            # resolve without the refusal
        est = scene.estimate("surface-nodes", scene.resolve("surface-nodes", over))
        budget.set_limit(None)
        verdict = ("within this machine's limit" if est.memory <= limit else
                   f"above this machine's limit of {budget.format_bytes(limit)}")
        print(f"  {label}: estimate {est.memory / 1e9:.1f} GB ({est.detail}); not run, "
              f"{verdict}")


def bench_crossover3d(args, out):
    """Whole runs, direct against nested dissection, 3D scenes at growing sizes."""
    print("\n[crossover3d] whole runs (setup + solve), solver=direct vs nested-dissection")
    cases = [("body3d-traction", "surface-nodes", h) for h in (0.125, 0.1, 1 / 12, 1 / 14, 1 / 16)]
    cases += [("body3d-manufactured", "surface-nodes", h) for h in (0.1, 1 / 12, 1 / 14)]
    cases += [("body3d-traction", "none", h) for h in (0.125, 0.1)]
    for scene_id, method, h in cases:
        row = direct_against_nd(args, get_scene(scene_id), method, {"spacing": h})
        print(f"  {scene_id:20s} {method:14s} h = {h:.4f} {row['text']}")
        out[f"crossover3d {scene_id} {method} h={h:.4f}"] = row["times"]


def direct_against_nd(args, scene, method, over):
    """Whole runs of ``scene`` with ``solver=direct`` and ``nested-dissection``,
    alternating, medians of ``--repeat``: ``{"times": ..., "text": one printed line}``."""
    alts = {solver: (lambda solver=solver: scene.run(method, {**over, "solver": solver}))
            for solver in ("direct", "nested-dissection")}
    res = alternate(alts, args.repeat)
    n = res["direct"][1].size["dofs"]
    t_d, t_n = res["direct"][0], res["nested-dissection"][0]
    err = [r[1].metrics["rel_l2_error"] for r in res.values()]
    text = (f"({n:5d} unknowns): direct {t_d:6.2f} s "
            f"({res['direct'][1].diagnostics.get('solver', '')[:24]}), nested dissection "
            f"{t_n:6.2f} s ({t_d / t_n:4.2f}x); rel_l2_error {err[0]:.6e} / {err[1]:.6e}")
    return {"times": {"unknowns": int(n), "direct": t_d, "nested-dissection": t_n},
            "text": text}


def bench_crossover2d(args, out):
    """Whole runs of plate2d-plane-strain, direct against nested dissection, at the sizes
    and m-ratios the report runs (where ``solver=auto`` switches in 2D: ND_FROM_UNKNOWNS)."""
    print("\n[crossover2d] whole runs (setup + solve), solver=direct vs nested-dissection, "
          "plate2d-plane-strain")
    cases = [(m, h, 3.0) for m in ("none", "surface-nodes") for h in (0.1, 0.05, 0.04, 0.025,
                                                                       0.02)]
    cases += [(m, 0.025, 8.0) for m in ("none", "surface-nodes", "taylor-fictitious")]
    cases += [(m, 0.02, r) for m in ("surface-nodes",) for r in (4.0, 5.0)]
    scene = get_scene("plate2d-plane-strain")
    for method, h, m_ratio in cases:
        row = direct_against_nd(args, scene, method, {"spacing": h, "m_ratio": m_ratio})
        print(f"  {method:17s} h = {h:.4f} m = {m_ratio:g} {row['text']}")
        out[f"crossover2d {method} h={h:.4f} m={m_ratio:g}"] = row["times"]


def bench_pddo(args, out):
    """Whole PDDO runs (its square nonsymmetric system, SuperLU with partial pivoting),
    COLAMD against minimum degree on A + A^T (``pddo.PDDO_ORDERING``)."""
    import pdverify.corrections.pddo as pddo_module
    print("\n[pddo] whole runs, SuperLU column ordering COLAMD vs MMD_AT_PLUS_A")
    cases = [("plate2d-plane-strain", {"spacing": h}) for h in (0.025, 0.02, 0.0125)]
    cases += [("plate2d-plane-strain", {"spacing": 0.025, "m_ratio": 8.0}),
              ("body3d-traction", {}), ("body3d-manufactured", {})]
    keep = pddo_module.PDDO_ORDERING
    try:
        for scene_id, over in cases:
            scene = get_scene(scene_id)

            def run(order, scene=scene, over=over):
                pddo_module.PDDO_ORDERING = order
                return scene.run("pddo", over)
            alts = {o: (lambda o=o: run(o)) for o in ("COLAMD", "MMD_AT_PLUS_A")}
            res = alternate(alts, args.repeat)
            t_c, t_m = res["COLAMD"][0], res["MMD_AT_PLUS_A"][0]
            err = [res[o][1].metrics["max_error_pct"] for o in res]
            print(f"  {scene_id:20s} {over}: COLAMD {t_c:6.2f} s, MMD_AT_PLUS_A {t_m:6.2f} s "
                  f"({t_c / t_m:4.2f}x; {res['COLAMD'][1].diagnostics.get('solver', '')[:22]}); "
                  f"max_error_pct {err[0]:.3e} / {err[1]:.3e}")
            out[f"pddo {scene_id} {over}"] = {"COLAMD": t_c, "MMD_AT_PLUS_A": t_m}
    finally:
        pddo_module.PDDO_ORDERING = keep


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=3, help="rounds per alternative (median)")
    ap.add_argument("--slow-repeat", type=int, default=1,
                    help="rounds for scipy's default spsolve and today's SuperLU on the SPD "
                         "case (~3 min a round; 0 skips them)")
    ap.add_argument("--json", default=None, help="write the medians to this file")
    ap.add_argument("--with-double", action="store_true",
                    help="also time ours with the float64 LU (the path before mixed precision)")
    ap.add_argument("--only", nargs="*", choices=("spd", "plate", "body3d", "crossover3d",
                                                "crossover2d", "pddo"),
                    default=("spd", "plate", "body3d"))
    harness.add_arguments(ap)
    args = ap.parse_args(argv)
    with harness.Record(__file__, args, argv=argv) as rec:
        _measure(args, rec)
        if args.json:
            harness.write_json(args.json, rec.results)


def _measure(args, out):
    print(f"median of {args.repeat}; PARDISO: {'pypardiso' if pypardiso else 'not installed'}")
    if "spd" in args.only:
        bench_spd(args, out)
    if "plate" in args.only:
        _, rows = bench_state(args, out, "plate2d-plane-strain", 0.01, "plate")
        ours = rows["ours: nested dissection (augmented)"]
        today = rows["today: direct (K multiplied out)"]
        print(f"  speed-up vs today: {today / ours:.1f}x (budget >= 10x: "
              f"{'met' if today / ours >= 10 else 'MISSED'})")
        if "PARDISO on K" in rows:
            r = rows["PARDISO on K"] / ours
            print(f"  vs PARDISO on K: {r:.2f}x (budget >= 1x: {'met' if r >= 1 else 'MISSED'})")
    if "body3d" in args.only:
        sizes = []
        for h in (0.1, 0.05):
            n, rows = bench_state(args, out, "body3d-traction", h, f"body3d h={h}")
            sizes.append((n, rows))
        for name in sizes[0][1]:
            (n0, r0), (n1, r1) = sizes[0], sizes[1]
            a = math.log(r1[name] / r0[name]) / math.log(n1 / n0)
            print(f"  fitted time ~ N^a over h = 0.1, 0.05 ({name}): a = {a:.2f}")
        bench_3d_large(out, sizes)
    if "crossover3d" in args.only:
        bench_crossover3d(args, out)
    if "crossover2d" in args.only:
        bench_crossover2d(args, out)
    if "pddo" in args.only:
        bench_pddo(args, out)


if __name__ == "__main__":
    main()
