"""The report's own linear systems solved by pdverify's solver pieces and by the sparse
direct libraries that install here: the measurement behind the solver decisions of
issue 51 (which home-made piece stays, which a library replaces).

Plain script (no test runner):

    PYTHONPATH=$PWD python benchmarks/solver_libraries.py [--only SCENE ...] [--quick]
        [--repeat N] [--json FILE] [--keep DIR] [--memory]

1. **Capture**: the report's cases (``pdverify.runner.plan``; ``--only``/``--quick`` as
   the report takes them) run in this process, one BLAS thread each as in the report,
   with the solver layer's leaves wrapped (``solve_constrained``, the front door's
   ``factor`` solves, ``solve_spd`` and the Newton tangents' CG): every system a run
   solves is timed as pdverify solves it (wall and CPU seconds, so a piece's threads are
   counted) and then, on the same matrix and right-hand side, by each library
   (factor + solve, in rotated order, median of ``--repeat``), with the relative residual
   of each answer. A run that solves many systems of one piece (a Newton sequence's
   tangents) has the libraries time its first ``--per-case`` (2) and the mean of those
   stand for the rest (rows marked ``extrapolated``). Which piece solved it is read from the leaf's own ``info["solver"]``.
2. **Memory** (``--memory``): the largest system of each piece is saved (``--keep``) and
   factored by each library and by pdverify's leaf in a fresh process each, whose peak
   resident memory above the loaded matrix is recorded.

pdverify's time includes what its leaves do beyond factor + solve (equilibration, the
condition estimate, the residual check, refinement of float32 factors); the libraries'
time is their factor + solve only, so a ratio in the libraries' favour is an upper bound
of what replacing the piece would gain. The order of the libraries rotates from system to
system and from repeat to repeat. Libraries (each optional; a missing one is listed
as such): SuperLU (scipy's ``splu``, the reference), UMFPACK (``scikit-umfpack``), MUMPS
(``python-mumps``, sequential), PARDISO (``pypardiso``, MKL). One thread each
(``OMP_NUM_THREADS=MKL_NUM_THREADS=OPENBLAS_NUM_THREADS=1``, set before import), as the
report's ``--jobs`` (one run per core) gives every run. The record names the machine, its
load before and after, and every library's version.
"""
from __future__ import annotations

import os

for _var in ("OMP_NUM_THREADS", "MKL_NUM_THREADS", "OPENBLAS_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import argparse
import collections
import json
import statistics
import sys
import time

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

import harness


# ------------------------------------------------------------------------ the libraries
def _superlu(A, b):
    return spla.splu(A.tocsc()).solve(b)


def _umfpack(A, b):
    import scikits.umfpack as um
    return um.splu(A.tocsc()).solve(b)


def _mumps(A, b):
    import mumps
    ctx = mumps.Context()
    ctx.set_matrix(A.tocoo())
    ctx.analyze()
    ctx.factor()
    return ctx.solve(b)


def _pardiso(A, b):
    import pypardiso
    solver = pypardiso.PyPardisoSolver()   # mtype 11: real non-symmetric, MKL's defaults
    x = solver.solve(A.tocsr(), b)
    solver.free_memory(everything=True)
    return x


LIBRARIES = {"superlu": ("scipy", _superlu), "umfpack": ("scikits.umfpack", _umfpack),
             "mumps": ("mumps", _mumps), "pardiso": ("pypardiso", _pardiso)}


def available() -> dict:
    """The libraries that import here, with their versions; a missing one with why."""
    out = {}
    for name, (module, _fn) in LIBRARIES.items():
        try:
            mod = __import__(module, fromlist=["_"])
        except Exception as exc:           # noqa: BLE001 -- listed, not fatal
            out[name] = {"available": False, "why": f"{type(exc).__name__}: {exc}"[:200]}
            continue
        version = getattr(mod, "__version__", None)
        if version is None:
            try:
                from importlib.metadata import version as _v
                version = _v({"scikits.umfpack": "scikit-umfpack", "mumps": "python-mumps",
                              "scipy": "scipy", "pypardiso": "pypardiso"}[module])
            except Exception:              # noqa: BLE001
                version = "?"
        out[name] = {"available": True, "version": version}
    return out


def timed(fn, *args):
    w0, c0 = time.perf_counter(), time.process_time()
    out = fn(*args)
    return out, time.perf_counter() - w0, time.process_time() - c0


def rel_res(A, x, b) -> float:
    x = np.asarray(x, dtype=float).ravel()
    return float(np.linalg.norm(A @ x - b) / max(np.linalg.norm(b), 1e-300))


# ---------------------------------------------------------------------------- capture
class Capture:
    """Wraps the solver layer's leaves; every call is timed as pdverify does it and then
    by each library on the same system."""

    def __init__(self, libs, repeat, keep, per_case=2):
        self.libs, self.repeat, self.keep, self.per_case = libs, repeat, keep, per_case
        self.rows = []
        self.sampled = collections.Counter()
        self.case = None
        self.largest = {}

    def record(self, piece_of, A, b, ours_wall, ours_cpu, ours_x, how=None):
        A = sp.csr_matrix(A)
        b = np.asarray(b, dtype=float).ravel()
        row = {"case": self.case, "piece": piece_of, "n": int(A.shape[0]), "nnz": int(A.nnz),
               "ours": {"wall_s": ours_wall, "cpu_s": ours_cpu,
                        "residual": rel_res(A, ours_x, b) if ours_x is not None else None}}
        names = list(self.libs)
        self.sampled[(self.case, piece_of)] += 1
        if self.sampled[(self.case, piece_of)] > self.per_case:
            # a Newton sequence's later tangents: ours timed, the libraries' time taken
            # as the mean of this case's sampled systems (marked ``extrapolated``)
            done = [r for r in self.rows if r["case"] == self.case and r["piece"] == piece_of
                    and not r.get("extrapolated")]
            for name in names:
                ok = [r[name]["wall_s"] for r in done if "wall_s" in r[name]]
                okc = [r[name]["cpu_s"] for r in done if "cpu_s" in r[name]]
                row[name] = ({"wall_s": float(np.mean(ok)), "cpu_s": float(np.mean(okc))}
                             if ok else {"failed": "not sampled"})
            row["extrapolated"] = True
            self.rows.append(row)
            return
        walls = collections.defaultdict(list)
        cpus = collections.defaultdict(list)
        res = {}
        for k in range(len(self.rows), len(self.rows) + (self.repeat if names else 0)):
            for name in names[k % len(names):] + names[: k % len(names)]:  # rotated
                try:
                    x, w, c = timed(LIBRARIES[name][1], A, b)
                except Exception as exc:   # noqa: BLE001 -- a library's failure is a row
                    res[name] = f"failed: {type(exc).__name__}: {exc}"[:160]
                    continue
                walls[name].append(w)
                cpus[name].append(c)
                res[name] = rel_res(A, x, b)
        for name in names:
            row[name] = ({"wall_s": statistics.median(walls[name]),
                          "cpu_s": statistics.median(cpus[name]), "residual": res[name]}
                         if walls[name] else {"failed": res.get(name)})
        self.rows.append(row)
        if self.keep and A.nnz > self.largest.get(piece_of, (0,))[0]:
            path = os.path.join(self.keep, f"{_slug(piece_of)}.npz")
            sp.save_npz(path, A)
            np.save(path[:-4] + "-rhs.npy", b)
            # how pdverify's front door factored it (its coordinates, symmetric mode,
            # ordering), so that the memory child runs the same piece; None: not a factor
            # of the front door (the Newton tangents' CG), whose memory is not measured
            how = dict(how) if how is not None else None
            if how is not None and how.get("coords") is not None:
                np.save(path[:-4] + "-coords.npy", np.asarray(how.pop("coords")))
            with open(path[:-4] + "-how.json", "w") as fh:
                json.dump(how, fh)
            self.largest[piece_of] = (A.nnz, path)

    def install(self):
        from pdverify.solvers import front, newton
        import pdverify.scenes.bar1d_bondbased as bb
        cap = self

        def wrap_constrained(orig):
            def leaf(K, f, B=None, c=None, **kw):
                (u, lam, info), w, cp = timed(lambda: orig(K, f, B, c, **kw))
                if B is not None and np.size(B):
                    Bm = sp.csr_matrix(np.atleast_2d(B) if not sp.issparse(B) else B)
                    A = sp.bmat([[sp.csr_matrix(K), Bm.T], [Bm, None]], format="csr")
                    rhs = np.concatenate([np.asarray(f, float), np.atleast_1d(np.asarray(c, float))])
                    x = np.concatenate([u, lam])
                else:
                    A, rhs, x = K, f, u
                cap.record(info.get("solver", "superlu"), A, rhs, w, cp, x,
                           {"ordering": kw.get("ordering", "COLAMD"),
                            "spd": bool(kw.get("spd", False)) and A is K})
                return u, lam, info
            return leaf

        def wrap_factored(orig):
            def leaf(A, b, where, **how):
                (u, info), w, cp = timed(lambda: orig(A, b, where, **how))
                cap.record(info.get("solver", "factor"), A, b, w, cp, u, how)
                return u, info
            return leaf

        def wrap_plain(orig, argc):
            def leaf(*args, **kw):
                (u, info), w, cp = timed(lambda: orig(*args, **kw))
                cap.record(info.get("solver", orig.__name__), args[0], args[1], w, cp, u)
                return u, info
            return leaf

        front.solve_constrained = wrap_constrained(front.solve_constrained)
        bb.solve_constrained = front.solve_constrained
        front._solved = wrap_factored(front._solved)      # every factor(A, precision)
        front.solve_spd = wrap_plain(front.solve_spd, 4)
        orig_cg = newton.cg_solve

        def cg_leaf(T, r, precond, **kw):
            (du, info), w, cp = timed(lambda: orig_cg(T, r, precond, **kw))
            cap.record("CG + two-level smoothed aggregation (Newton tangent, preconditioner "
                       "reused; its set-up not counted)", T, r, w, cp, du)
            return du, info
        newton.cg_solve = cg_leaf


def _slug(text: str) -> str:
    return "".join(ch if ch.isalnum() else "-" for ch in text)[:60].strip("-")


def capture(args, libs, partial=None) -> list:
    from pdverify.runner import plan
    from pdverify.scenes import get_scene
    cap = Capture(libs, args.repeat, args.keep, args.per_case)
    cap.install()
    cases = plan(args.only or None, args.quick)
    for k, (scene_id, method, overrides) in enumerate(cases):
        cap.case = f"{scene_id} --method {method} {json.dumps(overrides, sort_keys=True)}"
        t0 = time.perf_counter()
        result = get_scene(scene_id).run(method, overrides)
        print(f"[{k + 1}/{len(cases)}] {cap.case}: {result.status} "
              f"({time.perf_counter() - t0:.1f} s)", file=sys.stderr, flush=True)
        if partial:                        # the record so far, after every case
            partial(cap.rows, k + 1, len(cases))
    return cap.rows, cap.largest


# ----------------------------------------------------------------------------- memory
def _status_kb(field: str) -> int:
    """``VmRSS`` / ``VmHWM`` of this process from /proc/self/status, in kB."""
    with open("/proc/self/status") as fh:
        for line in fh:
            if line.startswith(field + ":"):
                return int(line.split()[1])
    raise OSError(f"{field} not in /proc/self/status")


def _memory_child(path, who):
    """In a fresh process: load the system, factor + solve it by ``who``; print the peak
    resident memory above the resident memory before the factor (MB) and the wall time.
    The library (or pdverify's solver layer) is imported and run once on a 4 x 4 system
    first, and the peak (``VmHWM``) is reset after that through /proc/self/clear_refs, so
    that neither imports nor the matrix's loading count."""
    A = sp.load_npz(path).tocsr()
    b = np.load(path[:-4] + "-rhs.npy")
    tiny, ones = sp.identity(4, format="csr") * 2.0, np.ones(4)
    if who == "ours":
        from pdverify.solvers.front import factor
        with open(path[:-4] + "-how.json") as fh:
            how = json.load(fh)
        if how is None:
            print(json.dumps({"skipped": "not a factor of the front door (CG)"}))
            return
        if os.path.exists(path[:-4] + "-coords.npy"):
            how["coords"] = np.load(path[:-4] + "-coords.npy")
        factor(tiny, "double", where="warm-up").solve(ones)
        run = lambda: factor(A, "auto", where="benchmark", **how).solve(b)  # noqa: E731
    else:
        LIBRARIES[who][1](tiny, ones)
        run = lambda: LIBRARIES[who][1](A, b)  # noqa: E731
    with open("/proc/self/clear_refs", "w") as fh:     # VmHWM := VmRSS
        fh.write("5")
    base = _status_kb("VmRSS")
    _, w, _ = timed(run)
    print(json.dumps({"peak_mb": (_status_kb("VmHWM") - base) / 1024, "wall_s": w}))


def memory(largest, libs) -> dict:
    out = {}
    for piece, (_nnz, path) in largest.items():
        out[piece] = {}
        for who in libs:
            try:
                out[piece][who] = harness.fresh([sys.executable, __file__, "--_child", path, who],
                                                timeout=1800)
            except (RuntimeError, OSError) as exc:   # a library's failure is a row
                out[piece][who] = {"failed": str(exc).strip().splitlines()[-1:]}
    return out


# ------------------------------------------------------------------------------ table
def summarize(rows, libs) -> dict:
    pieces = collections.defaultdict(lambda: {"systems": 0, "largest_n": 0, "ours_wall_s": 0.0,
                                              "ours_cpu_s": 0.0, **{f"{n}_wall_s": 0.0 for n in libs},
                                              **{f"{n}_failed": 0 for n in libs}})
    for row in rows:
        p = pieces[row["piece"]]
        p["systems"] += 1
        p["largest_n"] = max(p["largest_n"], row["n"])
        p["ours_wall_s"] += row["ours"]["wall_s"]
        p["ours_cpu_s"] += row["ours"]["cpu_s"]
        for n in libs:
            if "wall_s" in row[n]:
                p[f"{n}_wall_s"] += row[n]["wall_s"]
            else:
                p[f"{n}_failed"] += 1
    return dict(pieces)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--only", action="append", default=[])
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--per-case", type=int, default=2, help="systems of one piece in one run "
                    "that the libraries solve (a Newton run's later tangents: their mean)")
    ap.add_argument("--json", default=None)
    ap.add_argument("--keep", default=None, help="folder for the largest system of each piece")
    ap.add_argument("--memory", action="store_true")
    ap.add_argument("--no-timing", action="store_true", help="time only pdverify's solves "
                    "(with --memory: the libraries' memory of the largest systems only)")
    ap.add_argument("--_child", nargs=2, help=argparse.SUPPRESS)
    harness.add_arguments(ap)
    args = ap.parse_args(argv)
    if args._child:
        return _memory_child(*args._child)
    libs_info = available()
    libs = [n for n, v in libs_info.items() if v["available"]]
    if args.memory and not args.keep:
        ap.error("--memory needs --keep DIR")
    if args.keep:
        os.makedirs(args.keep, exist_ok=True)
    with harness.Record(__file__, args, argv=argv) as rec:
        _measure(args, rec, libs_info, libs)
    return 0


def _flat(rec) -> dict:
    """``--json FILE`` as before the harness: the results at the top level (``pieces``,
    ``systems``, ...), ``libraries`` the timed ones; the record's header beside them
    (its libraries as ``environment``)."""
    head = {k: v for k, v in rec.doc.items() if k != "results"}
    head["environment"] = head.pop("libraries")
    results = dict(rec.results)
    return {**head, "libraries": results.pop("libraries_timed"), **results}


def _measure(args, rec, libs_info, libs):
    rec.update({"libraries_timed": libs_info,
                "threads_per_run": os.environ["OMP_NUM_THREADS"]})
    record = rec.results
    t0 = time.perf_counter()

    timed_libs = [] if args.no_timing else libs

    def partial(rows, done, total):      # the record after every case
        rec.update({"cases_done": f"{done} of {total}", "pieces": summarize(rows, timed_libs),
                    "systems": rows})
        if args.json:
            harness.write_json(args.json, _flat(rec))
    rows, largest = capture(args, [] if args.no_timing else libs, partial)
    record["capture_wall_s"] = time.perf_counter() - t0
    record["pieces"] = summarize(rows, [] if args.no_timing else libs)
    record["systems"] = rows
    if args.memory:
        record["memory"] = memory(largest, ["ours", *libs])
    print(f"machine: {rec.doc['machine']}")
    print("libraries: " + ", ".join(f"{n} {v.get('version') or 'missing'}"
                                     for n, v in libs_info.items()))
    if args.no_timing:
        libs = []
    head = f"{'piece':70s} {'runs':>5s} {'max n':>7s} {'ours':>8s}" + "".join(
        f" {n:>9s}" for n in libs)
    print(head)
    for piece, p in sorted(record["pieces"].items(), key=lambda kv: -kv[1]["ours_wall_s"]):
        print(f"{piece[:70]:70s} {p['systems']:5d} {p['largest_n']:7d} {p['ours_wall_s']:8.2f}"
              + "".join(f" {p[f'{n}_wall_s']:8.2f}" + ("!" if p[f"{n}_failed"] else " ")
                        for n in libs))
    print("(seconds, summed over the systems; '!': the library failed on some system)")
    if args.memory:
        for piece, by in record["memory"].items():
            print(f"peak MB above the matrix, {piece[:60]}: " + ", ".join(
                f"{w} {v.get('peak_mb', float('nan')):.0f}" for w, v in by.items()))
    if args.json:
        harness.write_json(args.json, _flat(rec))


if __name__ == "__main__":
    sys.exit(main())
