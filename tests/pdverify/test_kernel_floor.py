"""benchmarks/kernel_floor.py's sorting of profiled time (issue 32): the floor it prints
rests on each compiled call landing in its class."""
import cProfile
import importlib.util
import pstats
from pathlib import Path

import numpy as np
import scipy.linalg as sl
import scipy.sparse as sp
import scipy.sparse.linalg as spla

ROOT = Path(__file__).resolve().parents[2]


def _module():
    spec = importlib.util.spec_from_file_location("kernel_floor",
                                                  ROOT / "benchmarks" / "kernel_floor.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def _work():
    rng = np.random.default_rng(0)
    A = sp.random(400, 400, density=0.02, random_state=1, format="csr") + 10 * sp.identity(400)
    A = A.tocsr()
    x = rng.standard_normal(400)
    for _ in range(50):
        A @ x                                   # csr_matvec
    (A @ A).tocsc()                             # csr_matmat, csr_tocsc
    spla.splu(A.tocsc()).solve(x)               # SuperLU
    sl.lu_factor(A.toarray())                   # LAPACK through scipy.linalg


def _profiled() -> pstats.Stats:
    prof = cProfile.Profile()
    prof.enable()
    _work()
    prof.disable()
    return pstats.Stats(prof)


def test_each_kind_of_call_lands_in_its_class():
    kf = _module()
    stats = _profiled().stats
    seen = {}
    for func in stats:
        name = func[2]
        for key in ("csr_matvec>", "csr_matmat>", "csr_tocsc>", "gstrf>", "'SuperLU' objects>"):
            if name.endswith(key):
                seen[key] = kf.classify(func)
        if func[0].endswith("scipy/linalg/_decomp_lu.py") and name == "lu_factor":
            seen["lu_factor"] = kf.classify(func)
    assert seen == {"csr_matvec>": "sparse products with vectors",
                    "csr_matmat>": "sparse assembly and conversions",
                    "csr_tocsc>": "sparse assembly and conversions",
                    "gstrf>": "SuperLU", "'SuperLU' objects>": "SuperLU",
                    "lu_factor": "dense LAPACK"}
    # a LAPACK call timed apart, the numpy work of the factor that makes it (its own
    # time once the calls are timed apart), a third-party package, plain Python
    assert kf.classify(("/x/benchmarks/kernel_floor.py", 60, "_lapack_call")) \
        == "dense LAPACK"
    assert kf.classify(("/x/pdverify/solvers/frontal.py", 64, "__init__")) \
        == "Python and numpy"
    assert kf.classify(("/x/site-packages/perifit/core/w.py", 1, "f")) == "perifit"
    assert kf.classify(("/x/pdverify/pd/grid.py", 1, "f")) == "Python and numpy"
    assert kf.classify(("~", 0, "<method 'take' of 'numpy.ndarray' objects>")) \
        == "Python and numpy"


def test_the_classes_add_up_to_the_profiled_time():
    kf = _module()
    st = _profiled()
    classes = kf.by_class(st)
    assert set(classes) == set(kf.CLASSES)
    # every function's own time in exactly one class: the same own times summed in
    # another grouping than pstats' total, so they agree within n eps of the total
    # (n < 10^4 functions here: < 2e-12 relative; 1e-9 bounds that with room)
    assert abs(sum(classes.values()) - st.total_tt) <= 1e-9 * max(st.total_tt, 1.0)
    assert classes["sparse products with vectors"] > 0 and classes["SuperLU"] > 0


def test_lapack_timed_apart_changes_no_bit_and_puts_the_factor_in_its_class():
    """The multifrontal factor and the dense LU give the same bits through the wrappers;
    their LAPACK calls are timed as dense LAPACK; leaving restores the modules."""
    from pdverify.solvers import dense, frontal
    from pdverify.solvers.frontal import FrontalLU
    from pdverify.solvers.ordering import nested_dissection
    kf = _module()
    ij = np.stack(np.meshgrid(np.arange(30), np.arange(30), indexing="ij"), -1).reshape(-1, 2)
    i, j = np.nonzero(np.abs(ij[:, None, :] - ij[None, :, :]).max(-1) <= 2)
    A = sp.csr_matrix((np.where(i == j, 30.0, -1.0 + 0.01 * (i - j) % 3), (i, j)))
    perm, tree = nested_dissection(A, ij.astype(float), leaf=16, tree=True)
    A = A[perm][:, perm].tocsr()
    b = np.arange(A.shape[0], dtype=float)
    saved = (frontal.get_lapack_funcs, frontal.get_blas_funcs, frontal._dlaswp, dense.lapack)

    def both():
        x = FrontalLU(A, tree, dtype=np.float64).solve(b)
        y = dense.solve_dense(A.toarray(), b)
        return x, np.asarray(y[0] if isinstance(y, tuple) else y)

    plain = both()
    prof = cProfile.Profile()
    with kf.lapack_timed_apart():
        prof.enable()
        wrapped = both()
        prof.disable()
    assert all(np.array_equal(p, w) for p, w in zip(plain, wrapped))
    assert (frontal.get_lapack_funcs, frontal.get_blas_funcs, frontal._dlaswp,
            dense.lapack) == saved
    st = pstats.Stats(prof)
    calls = {f: v for f, v in st.stats.items() if f[2] == "_lapack_call"}
    assert calls and all(kf.classify(f) == "dense LAPACK" for f in calls)
    assert sum(v[0] for v in calls.values()) >= 3     # getrf, trsm, gemm at least
