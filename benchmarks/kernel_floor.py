"""How much of a report's run time is the solvers' arithmetic (issue 32): the floor that
only other solvers or fewer runs would lower.

Plain script (no test runner):

    python benchmarks/kernel_floor.py [--quick] [--only SCENE ...] [--skip SCENE ...]
                                      [--jobs N] [--stats FILE]

Runs the report's cases (``pdverify.runner.plan``, the full report unless ``--quick``)
one after another in this process, each through ``Scene.run`` as a report worker runs it
(one BLAS thread), under cProfile, and sorts the time by where it was spent:

- **dense LAPACK**: the LAPACK and BLAS calls of the multifrontal factor
  (``pdverify/solvers/frontal.py``: getrf, laswp, trsm, gemm) and of the dense LU
  (``dense.py``), each wrapped here in a Python function so that cProfile times it apart
  (f2py's calls are not profiled; unwrapped they count in their caller's own time, with
  the caller's numpy work: the fronts' extend-add and copies), and scipy.linalg's and
  numpy.linalg's wrappers (their own time is their LAPACK call and argument checks);
- **SuperLU**: its factor (``gstrf``) and solves (the float32 factor's too,
  ``pdverify.solvers.nested.SingleLU``);
- **sparse products with vectors**: scipy's ``csr_matvec`` / ``csr_matvecs`` (CG's
  products, the refinement's residuals);
- **sparse assembly and conversions**: scipy's other compiled sparse routines (products
  of sparse matrices, format conversions, index sorting, duplicate summing);
- **perifit**: the third-party package's weight computation (0 with a warm cache);
- **Python and numpy**: the rest (the scenes' setup, numpy's array work, the
  interpreter).

Prints the seconds and shares of each class, the per-scene run time, and the floor the
solvers' arithmetic (the first three classes: the factorisations, their solves and the
products with vectors) sets for the report's runs on ``--jobs`` workers (their sum / N,
default 2): with the same solvers doing the same arithmetic, no other change brings the
runs' wall time below it. The sparse assembly and conversions are compiled too, but
partly avoidable (``pdverify.solvers.condense`` skips two conversions), so they are not
in the floor. cProfile's overhead falls on the Python class (the compiled calls are timed
once each), so the compiled shares are if anything understated; numpy's dense products
(``@``) count as numpy. ``--stats FILE`` keeps the profile (``python -m pstats FILE``).
Use the warm caches of a report (``PDVERIFY_CACHE_DIR``) to measure what a warm report
computes.
"""
from __future__ import annotations

import argparse
import collections
import contextlib
import cProfile
import pstats
import time

CLASSES = ("dense LAPACK", "SuperLU", "sparse products with vectors",
           "sparse assembly and conversions", "perifit", "Python and numpy")
#: the solvers' arithmetic: the floor's classes
ARITHMETIC = CLASSES[:3]


def _timed_lapack(f):
    """``f`` (an f2py LAPACK or BLAS routine) behind a Python function, which cProfile
    times apart: its own time is ``f``'s."""
    def _lapack_call(*args, **kw):
        return f(*args, **kw)
    return _lapack_call


class _TimedModule:
    """A module whose callables are :func:`_timed_lapack`'s wrappers (``dense.lapack``)."""

    def __init__(self, module):
        self._module = module

    def __getattr__(self, name):
        return _timed_lapack(getattr(self._module, name))


@contextlib.contextmanager
def lapack_timed_apart():
    """While open, the LAPACK and BLAS calls of ``pdverify.solvers.frontal`` and
    ``pdverify.solvers.dense`` go through :func:`_timed_lapack` (the same calls, the same
    results); restored on leaving."""
    from pdverify.solvers import dense, frontal
    saved = (frontal.get_lapack_funcs, frontal.get_blas_funcs, frontal._dlaswp, dense.lapack)
    get_lapack, get_blas = saved[:2]
    frontal.get_lapack_funcs = lambda *a, **k: tuple(map(_timed_lapack, get_lapack(*a, **k)))
    frontal.get_blas_funcs = lambda *a, **k: tuple(map(_timed_lapack, get_blas(*a, **k)))
    frontal._dlaswp = _timed_lapack(frontal._dlaswp)
    dense.lapack = _TimedModule(dense.lapack)
    try:
        yield
    finally:
        (frontal.get_lapack_funcs, frontal.get_blas_funcs, frontal._dlaswp,
         dense.lapack) = saved


def classify(func) -> str:
    """The class of :data:`CLASSES` of a pstats function key ``(file, line, name)``."""
    filename, _, name = func
    if "perifit" in filename:
        return "perifit"
    if filename == "~":                              # a built-in (C) function
        if ("_superlu" in name or "SuperLU" in name
                or name == "<method 'acquire' of '_thread.lock' objects>"):
            return "SuperLU"
        if "_sparsetools" in name:
            return ("sparse products with vectors" if name.split(".")[-1].rstrip(">")
                    in ("csr_matvec", "csr_matvecs") else "sparse assembly and conversions")
        return "Python and numpy"
    if (name == "_lapack_call" or "scipy/linalg/" in filename
            or "numpy/linalg/" in filename):
        return "dense LAPACK"
    return "Python and numpy"


def by_class(stats: pstats.Stats) -> dict:
    """Own time (tottime) summed per class."""
    out = collections.Counter({c: 0.0 for c in CLASSES})
    for func, (_, _, tottime, _, _) in stats.stats.items():
        out[classify(func)] += tottime
    return out


def main(argv=None) -> None:
    import harness                      # beside this script (the tests load it by path)
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="the quick report's cases")
    ap.add_argument("--only", nargs="+", default=None, metavar="SCENE")
    ap.add_argument("--skip", nargs="+", default=(), metavar="SCENE")
    ap.add_argument("--jobs", type=int, default=2, help="workers of the floor (default 2)")
    ap.add_argument("--stats", default=None, metavar="FILE", help="keep the profile here")
    harness.add_arguments(ap)
    args = ap.parse_args(argv)
    with harness.Record(__file__, args, argv=argv) as rec:
        _measure(args, rec)


def _measure(args, rec) -> None:
    from pdverify.runner import plan
    from pdverify.scenes import get_scene
    cases = [c for c in plan(only=args.only, quick=args.quick) if c[0] not in args.skip]
    prof = cProfile.Profile()
    per_scene = collections.Counter()
    t0 = time.perf_counter()
    with lapack_timed_apart():
        for scene, method, overrides in (c[:3] for c in cases):
            t = time.perf_counter()
            prof.enable()
            try:
                get_scene(scene).run(method, overrides)
            finally:
                prof.disable()
            per_scene[scene] += time.perf_counter() - t
    wall = time.perf_counter() - t0
    stats = pstats.Stats(prof)
    if args.stats:
        stats.dump_stats(args.stats)
    classes = by_class(stats)
    total = sum(classes.values())
    print(f"{len(cases)} runs, {wall:.1f} s one after another (profiled: {total:.1f} s)")
    for c in CLASSES:
        print(f"  {c:38s} {classes[c]:8.1f} s  {100 * classes[c] / total:5.1f} %")
    floor = sum(classes[c] for c in ARITHMETIC)
    label = "solvers' arithmetic (the first three)"
    print(f"  {label:38s} {floor:8.1f} s  "
          f"{100 * floor / total:5.1f} %")
    print(f"floor of the runs' wall time on {args.jobs} workers from the solvers' "
          f"arithmetic alone: {floor / args.jobs:.1f} s")
    print("run time per scene (s):")
    for scene, s in per_scene.most_common():
        print(f"  {scene:28s} {s:8.1f}")
    rec.update({"runs": len(cases), "wall_s": wall, "profiled_s": total,
                "by_class_s": dict(classes), "arithmetic_floor_s": floor, "jobs": args.jobs,
                "floor_on_jobs_s": floor / args.jobs, "per_scene_s": dict(per_scene)})


if __name__ == "__main__":
    main()
