"""Single-precision LU with refinement in double (pdverify.solvers.nested: SingleLU, the
refinement of pdverify.solvers.mixed, GMRES-IR)."""
import numpy as np
import pytest
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from pdverify.errors import NumericalError
from pdverify.solvers import mixed, nested, policy
from pdverify.solvers.checks import equilibrate
from pdverify.solvers.mixed import refine
from pdverify.solvers.nested import SingleLU, solve_nested
from pdverify.solvers.ordering import nested_dissection

EPS = np.finfo(float).eps
EPS32 = np.finfo(np.float32).eps


def lattice_operator(n, reach, seed=1):
    """A nonsymmetric operator coupling lattice nodes within ``reach`` (2D), diagonally
    dominant (condition ~20, numpy.linalg.cond)."""
    ij = np.stack(np.meshgrid(np.arange(n), np.arange(n), indexing="ij"), -1).reshape(-1, 2)
    d = np.abs(ij[:, None, :] - ij[None, :, :]).max(-1)
    rng = np.random.default_rng(seed)
    A = np.where(d <= reach, rng.uniform(-1, 0, d.shape), 0.0)
    np.fill_diagonal(A, 0.0)
    np.fill_diagonal(A, -A.sum(1) + 1.0)
    return sp.csr_matrix(A), ij.astype(float)


def split_system(n=24, reach=2):
    A, x = lattice_operator(n, reach)
    perm, (n1, n2) = nested_dissection(A, x, leaf=16, top_split=True)
    return A[perm][:, perm].tocsr(), n1, n2


def test_top_split_decouples_the_halves():
    """What the top separator's size (the float32 factor's choice) is measured on: no
    entry couples the two halves of the top split."""
    A, n1, n2 = split_system()
    assert n1 > 0 and n2 > 0 and n1 + n2 < A.shape[0]
    assert A[:n1, n1:n1 + n2].nnz == 0 and A[n1:n1 + n2, :n1].nnz == 0
    A, x = lattice_operator(3, 1)        # 9 unknowns, below the leaf: not split
    perm, top = nested_dissection(A, x, leaf=16, top_split=True)
    assert top == (0, 0) and np.array_equal(np.sort(perm), np.arange(9))


@pytest.mark.parametrize("trans", ["N", "T"])
def test_single_lu_in_double_is_an_exact_inverse(trans):
    """SingleLU in float64 is SuperLU's LU: condition ~20, n = 576, so a backward-stable
    solve is accurate to ~kappa n eps ~ 1e4 eps, one or several right-hand sides."""
    A, n1, n2 = split_system()
    b = np.random.default_rng(3).normal(size=(A.shape[0], 2))
    lu = SingleLU(A, dtype=np.float64)
    M = A.toarray() if trans == "N" else A.toarray().T
    exact = np.linalg.solve(M, b)
    x = lu.solve(b, trans=trans)
    assert np.abs(x - exact).max() / np.abs(exact).max() < 1e4 * EPS
    assert np.abs(lu.solve(b[:, 0], trans=trans) - exact[:, 0]).max() < 1e4 * EPS * np.abs(
        exact).max()


def test_float32_lu_refines_to_double_accuracy():
    """One float32 solve is accurate to ~kappa eps32 (kappa ~ 20: ~1e-5); the refinement
    then reaches LAPACK dsgesv's test, residual <= sqrt(n) eps."""
    A, n1, n2 = split_system()
    b = np.random.default_rng(4).normal(size=A.shape[0])
    lu = SingleLU(A)
    exact = np.linalg.solve(A.toarray(), b)
    once = lu.solve(b)
    err_once = np.abs(once - exact).max() / np.abs(exact).max()
    assert 1e3 * EPS < err_once < 1e3 * EPS32      # single, not double, precision
    x, steps, history, ok = refine(A, b, lu.solve)
    # each step gains ~1 / (kappa eps32) ~ 1e5, so the 1e-5 of one solve reaches the
    # 2 eps stop in 2 to 3 steps; 5 leaves room for a stalled last one
    assert ok and 1 <= steps <= 5
    assert history[-1] <= np.sqrt(A.shape[0]) * EPS
    # each step until the last (which may be the one that stalls) at least halves it
    assert all(h1 < 0.5 * h0 for h0, h1 in zip(history[:-1], history[1:-1]))
    assert np.abs(x - exact).max() / np.abs(exact).max() < 1e4 * EPS


def test_solve_nested_mixed_matches_double():
    A, x = lattice_operator(24, 2)
    b = np.random.default_rng(5).normal(size=A.shape[0])
    u_m, info_m = solve_nested(A, b, x, where="test", mixed=True)
    u_d, info_d = solve_nested(A, b, x, where="test", mixed=False)
    # both are solutions to ~kappa n eps (kappa ~ 20, n = 576)
    assert np.linalg.norm(u_m - u_d) / np.linalg.norm(u_d) < 1e4 * EPS
    assert info_m["mixed_precision"].startswith("float32 LU")
    assert info_m["refinement_steps"] >= 1
    assert info_m["refinement_residuals"][-1] <= np.sqrt(A.shape[0]) * EPS
    # refined to REFINE_STOP = 2 eps in the max-norm measure; relative_residual's scaled
    # 2-norm measure of the same backward-stable solution: c eps with c ~ 1-10
    assert info_m["relative_residual"] < 1e2 * EPS
    # both estimate the exact 1-norm condition of the equilibrated matrix from below,
    # Hager-Higham estimates "rarely more than 3 times too small" (Higham, Accuracy and
    # Stability, 15.3); the float32 solves perturb the mixed one by ~kappa eps32 ~ 1e-6
    exact = np.linalg.cond(equilibrate(A, "test")[0].toarray(), 1)
    for info in (info_m, info_d):
        assert exact / 3 <= info["condition_estimate"] <= exact * (1 + 1e-5)
    assert "mixed_precision" not in info_d and "float32" not in info_d["solver"]
    assert info_m["solver"].endswith("nested-dissection ordering)")


def ill_conditioned(kappa, n=24, reach=2):
    """A symmetric lattice operator shifted to within ~1/kappa of singular."""
    A, x = lattice_operator(n, reach)
    S = 0.5 * (A + A.T).toarray()
    w, V = np.linalg.eigh(S)
    S = S - (w[0] - w[-1] / kappa) * np.eye(S.shape[0])    # smallest eigenvalue w[-1]/kappa
    return sp.csr_matrix(S), x


def test_ill_conditioned_system_is_solved_by_gmres_ir():
    """kappa = 1e9 > 1/eps32: plain refinement of the float32 factor stalls; GMRES
    preconditioned with that factor (GMRES-IR) solves it to ~kappa n eps, backward stable,
    without a double factor. Its estimate: the 1e9 built in, to within the estimator's
    usual factor 3 (Higham, Accuracy and Stability, 15.3) of the equilibrated matrix's."""
    A, x = ill_conditioned(1e9)
    b = np.random.default_rng(6).normal(size=A.shape[0])
    u, info = solve_nested(A, b, x, where="test", mixed=True)
    assert info["mixed_precision"] == ("float32 LU, refined in float64 by GMRES-IR (plain "
                                       "refinement stalled)")
    assert info["refinement"] == "GMRES-IR" and "GMRES-IR" in info["solver"]
    # each correction's GMRES stopped at GMRES_INNER_TOL, well inside its iteration limit,
    # and so did each of the estimator's three solves
    assert 0 < max(info["gmres_ir_iterations"]) < mixed.GMRES_MAX_ITERATIONS
    assert len(info["gmres_ir_estimator_iterations"]) == 3
    assert max(info["gmres_ir_estimator_iterations"]) < mixed.GMRES_MAX_ITERATIONS
    # the outer residual: REFINE_STOP = 2 eps (max-norm measure) or dsgesv's sqrt(n) eps
    assert info["gmres_ir_residuals"][-1] <= np.sqrt(A.shape[0]) * EPS
    # backward stable as the double LU: c eps with c ~ 1-10 in the scaled 2-norm measure
    assert info["relative_residual"] < 1e2 * EPS
    exact = np.linalg.solve(A.toarray(), b)
    assert np.linalg.norm(u - exact) / np.linalg.norm(exact) < 1e9 * A.shape[0] * EPS
    # Hager-Higham's factor 3 below; above, the estimate's rounding to ESTIMATE_DIGITS = 6
    # digits (up to 5e-6 relative) and the solves' residual (3 ESTIMATOR_RESIDUAL)
    kappa = np.linalg.cond(equilibrate(A, "test")[0].toarray(), 1)
    assert kappa / 3 <= info["condition_estimate"] <= kappa * (1 + 1e-5 + 3 * mixed.ESTIMATOR_RESIDUAL)


def test_near_singular_system_is_refused_on_the_gmres_path():
    """Two rows equal but for 1e-12 on the diagonal (kappa_1 7e14 after equilibration, above
    CONDITION_LIMIT = 1e14): GMRES-IR converges on b and the probe, but the estimator's
    solves do not reach ESTIMATOR_RESIDUAL (the float32 factor preconditions nothing in
    the near-null direction), so the double LU decides, and refuses it, as with
    mixed=False. Before that check the mixed path accepted it with an estimate of 9.5e11
    (the probe's term alone: about kappa / n for a localised near-null vector)."""
    A, x = lattice_operator(24, 2)
    A = A.tolil()
    A[5, :] = A[4, :]
    A[5, 5] += 1e-12
    A = A.tocsr()
    b = np.random.default_rng(11).normal(size=A.shape[0])
    for mixed_precision in (True, False):
        with pytest.raises(NumericalError, match="test: near-singular"):
            solve_nested(A, b, x, where="test", mixed=mixed_precision)


class SpreadFactor:
    """An approximate factor of known error, in place of the float32 SingleLU: ``solve``
    applies M^-1 = A^-1 D (transposed: D A^-T), A^-1 by SuperLU in double and D diagonal,
    so the preconditioned matrix A M^-1 is D exactly, up to double rounding. The float32
    factor of a matrix near kappa ~ 1/eps32 leaves a preconditioned spectrum set by the
    rounding of its LU, which changes with the BLAS kernel (OPENBLAS_CORETYPE=Prescott,
    Sandybridge and this machine's default gave estimator passes of 31-33, 60-68 and
    62-95 iterations on one matrix, and a matrix built by eigh changes with the kernel
    too); D given here makes the iteration counts a property of the case, the same on any
    CPU."""

    kind = "SuperLU in float64, scaled"

    def __init__(self, A, spread):
        self.lu = spla.splu(sp.csc_matrix(A))
        self.d = spread
        self.factor_entries = int(self.lu.nnz)

    def solve(self, B, trans="N"):
        B = np.asarray(B, dtype=float)
        d = self.d.reshape(-1, *([1] * (B.ndim - 1)))
        return self.lu.solve(d * B) if trans == "N" else d * self.lu.solve(B, trans="T")


#: D's entries, evenly spread over [SPREAD_LOW, SPREAD_HIGH]: plain refinement multiplies
#: the residual by I - D, whose entries reach 1 - 3 = -2, so it stalls; GMRES on the
#: normal matrix D reduces the residual at least at the Chebyshev rate 2 q^k, q = (sqrt(c)
#: - 1) / (sqrt(c) + 1) = 0.868 for c = 3 / 0.015 = 200 (Saad, Iterative Methods for
#: Sparse Linear Systems, 2nd ed., Sec. 6.11.4 with the real-interval Chebyshev bound of
#: Sec. 6.11.2; the transposed passes' A^T D A^-T is similar to D, the bound times
#: kappa(A) ~ 20). Hence the
#: regime these two tests need, by construction: a correction held to
#: GMRES_MAX_ITERATIONS = 60 gains at least a factor 1 / (2 q^60) ~ 2.4e3 (measured
#: 3.6e3), so GMRES_OUTER_STEPS = 6 outer steps reach 2 eps from 0.3 (5 do); an
#: estimator's pass from zero is then still near 4e-4 (measured 3.6e-4) > ESTIMATOR_RESIDUAL
#: = 1e-4 after 60 iterations, and reaches a tenth of ESTIMATOR_RESIDUAL within
#: ln(2e5) / ln(1 / q) = 86 (measured 81), far below ESTIMATOR_MAX_ITERATIONS = 240
SPREAD_LOW, SPREAD_HIGH = 0.015, 3.0


@pytest.fixture
def spread_factor(monkeypatch):
    """solve_nested's single-precision factor replaced by a :class:`SpreadFactor`."""
    def factor(A_p, n1, n2, tree=None):
        return SpreadFactor(A_p, np.linspace(SPREAD_LOW, SPREAD_HIGH, A_p.shape[0])), ""
    monkeypatch.setattr(nested, "single_precision_factor", factor)


def test_converged_gmres_ir_is_not_refactored_for_its_estimator(spread_factor):
    """A solve that GMRES-IR converged stays on its approximate factor when the condition
    estimator's GMRES passes need more iterations than a correction's limit (issue 32:
    body3d-manufactured's order-2 Taylor system, 60 iterations where its transposed pass
    needs ~100, was factored again in double): each pass may run on to
    ESTIMATOR_MAX_ITERATIONS and does reach ESTIMATOR_RESIDUAL. The factor's error is
    given (:class:`SpreadFactor`, :data:`SPREAD_LOW`), so the regime holds on any CPU."""
    A, x = lattice_operator(24, 2)
    b = np.random.default_rng(6).normal(size=A.shape[0])
    u, info = solve_nested(A, b, x, where="test", mixed=True)
    assert info["mixed_precision"] == ("float32 LU, refined in float64 by GMRES-IR (plain "
                                       "refinement stalled)")
    # the corrections ran to their limit (the Chebyshev bound: 1e-8 needs ~140), the
    # outer refinement converged on them
    assert set(info["gmres_ir_iterations"]) == {mixed.GMRES_MAX_ITERATIONS}
    assert len(info["gmres_ir_residuals"]) - 1 <= mixed.GMRES_OUTER_STEPS
    # the mechanism: a pass beyond the corrections' limit, within its own
    assert len(info["gmres_ir_estimator_iterations"]) == 3
    assert (mixed.GMRES_MAX_ITERATIONS < max(info["gmres_ir_estimator_iterations"])
            < mixed.ESTIMATOR_MAX_ITERATIONS)
    # the outer residual: REFINE_STOP = 2 eps (max-norm measure) or dsgesv's sqrt(n) eps;
    # the solution to ~kappa n eps (kappa ~ 20, n = 576)
    assert info["gmres_ir_residuals"][-1] <= np.sqrt(A.shape[0]) * EPS
    exact = np.linalg.solve(A.toarray(), b)
    assert np.linalg.norm(u - exact) / np.linalg.norm(exact) < 1e4 * EPS
    # Hager-Higham's factor 3 below (Higham, Accuracy and Stability, 15.3); above, the
    # estimate's rounding to ESTIMATE_DIGITS = 6 digits (up to 5e-6 relative) and the
    # solves' residual (3 ESTIMATOR_RESIDUAL)
    kappa = np.linalg.cond(equilibrate(A, "test")[0].toarray(), 1)
    assert kappa / 3 <= info["condition_estimate"] <= kappa * (1 + 1e-5 + 3 * mixed.ESTIMATOR_RESIDUAL)


def test_estimator_held_to_the_corrections_limit_falls_back_to_the_double_lu(
        spread_factor, monkeypatch):
    """The same system with the estimator's passes held to GMRES_MAX_ITERATIONS (as before
    ESTIMATOR_MAX_ITERATIONS): its first pass ends above ESTIMATOR_RESIDUAL (near 4e-4:
    :data:`SPREAD_LOW`), the double LU takes over (and the later passes are skipped)."""
    monkeypatch.setattr(mixed, "ESTIMATOR_MAX_ITERATIONS", mixed.GMRES_MAX_ITERATIONS)
    A, x = lattice_operator(24, 2)
    b = np.random.default_rng(6).normal(size=A.shape[0])
    u, info = solve_nested(A, b, x, where="test", mixed=True)
    assert info["mixed_precision"].startswith("not used: GMRES-IR converged, but the "
                                              "condition estimator's solves did not")
    assert info["gmres_ir_estimator_iterations"] == [mixed.GMRES_MAX_ITERATIONS]
    assert "float32" not in info["solver"]
    # the double LU's solution: ~kappa n eps (kappa ~ 20, n = 576)
    exact = np.linalg.solve(A.toarray(), b)
    assert np.linalg.norm(u - exact) / np.linalg.norm(exact) < 1e4 * EPS


@pytest.mark.parametrize("size", [1e-300, 1e300])
def test_gmres_ir_takes_right_hand_sides_of_any_size(size):
    """GMRES's norms are taken of the residual scaled by a power of two (exact), so a
    right-hand side of 1e+-300 is solved by GMRES-IR as at size 1 (before: its norm
    under- or overflowed, the pass returned zero and the double LU took over); the same
    solution, scaled, to kappa n eps (kappa 1e9, n = 576)."""
    A, x = ill_conditioned(1e9)
    b = np.random.default_rng(6).normal(size=A.shape[0])
    u, info = solve_nested(A, size * b, x, where="test", mixed=True)
    assert info["refinement"] == "GMRES-IR"
    assert info["mixed_precision"].startswith("float32 LU")
    ref = np.linalg.solve(A.toarray(), b)
    assert np.linalg.norm(u / size - ref) / np.linalg.norm(ref) < 1e9 * A.shape[0] * EPS


def test_ill_conditioned_system_falls_back_to_the_double_lu(monkeypatch):
    """When GMRES-IR fails too (here: GMRES held to one iteration per correction, so each
    outer step gains ~kappa eps32 > 1), the double LU solves it to ~kappa n eps. Its
    estimate: the 1e9 built in, to within the estimator's usual factor 3 and what the
    diagonal equilibration changes (> 1e8)."""
    monkeypatch.setattr(mixed, "GMRES_MAX_ITERATIONS", 1)
    A, x = ill_conditioned(1e9)
    b = np.random.default_rng(6).normal(size=A.shape[0])
    u, info = solve_nested(A, b, x, where="test", mixed=True)
    assert info["mixed_precision"] == ("not used: refinement of the single-precision factor "
                                       "did not converge, nor GMRES-IR; double LU")
    assert "float32" not in info["solver"]
    assert info["condition_estimate"] > 1e8
    exact = np.linalg.solve(A.toarray(), b)
    assert np.linalg.norm(u - exact) / np.linalg.norm(exact) < 1e9 * A.shape[0] * EPS


def test_moderately_conditioned_system_stays_mixed():
    """kappa = 1e4: kappa eps32 ~ 1e-3, so the refinement converges (a few more steps than
    at kappa 20) and the double LU is not needed."""
    A, x = ill_conditioned(1e4)
    b = np.random.default_rng(7).normal(size=A.shape[0])
    u, info = solve_nested(A, b, x, where="test", mixed=True)
    assert info["mixed_precision"].startswith("float32 LU")
    exact = np.linalg.solve(A.toarray(), b)
    assert np.linalg.norm(u - exact) / np.linalg.norm(exact) < 1e4 * A.shape[0] * EPS
    # the estimate from the probe: below the exact 1-norm condition, within Hager-Higham's
    # usual factor 3 (the float32 solves perturb it by ~kappa eps32 ~ 1e-3)
    kappa = np.linalg.cond(equilibrate(A, "test")[0].toarray(), 1)
    assert kappa / 3 <= info["condition_estimate"] <= kappa * (1 + 1e-2)


@pytest.mark.parametrize("mixed", [True, False])
def test_singular_system_is_refused_either_way(mixed):
    """Two equal rows, and equal right-hand sides there: the system is consistent, so the
    refinement of b alone converges on a float32 factor that rounding made regular; the
    random probe refined alongside cannot, and the double LU refuses the system."""
    A, x = lattice_operator(10, 1)
    A = A.tolil()
    A[5, :] = A[4, :]
    with pytest.raises(NumericalError, match="test: (singular|near-singular)"):
        solve_nested(A.tocsr(), np.ones(A.shape[0]), x, where="test", mixed=mixed)


def test_refinement_reports_divergence():
    """An approximate inverse that is not one (half the true solve) does not converge."""
    A, n1, n2 = split_system()
    lu = SingleLU(A, dtype=np.float64)
    b = np.ones(A.shape[0])
    _, _, history, ok = refine(A, b, lambda r: -0.5 * lu.solve(r))
    assert not ok and history[-1] > 0.5 * history[-2]


def test_equilibrate_unchanged():
    """The scaled matrix is the diagonal-product form's, entry for entry."""
    A, _ = lattice_operator(12, 2, seed=9)
    A = sp.diags(np.logspace(-6, 6, A.shape[0])) @ A @ sp.diags(np.logspace(3, -3, A.shape[0]))
    A = sp.csr_matrix(A)
    A.data[::7] = 0.0                       # stored zeros
    A_s, r, c = equilibrate(A, "test")
    ref = sp.diags(1 / r) @ A
    ref = (ref @ sp.diags(1 / abs(ref).max(axis=0).toarray().ravel())).tocsr()
    assert abs(A_s - ref).max() == 0 and A_s.nnz == ref.nnz == np.count_nonzero(A.data)
    assert np.array_equal(r, abs(sp.csr_matrix(A)).max(axis=1).toarray().ravel())
    # each column's largest is 1 up to the rounding of x * (1 / x)
    assert np.abs(abs(A_s).max(axis=0).toarray() - 1.0).max() <= EPS


def test_default_switch_is_by_size(monkeypatch):
    A, x = lattice_operator(12, 2)
    b = np.ones(A.shape[0])
    monkeypatch.setattr(policy, "MIXED_FROM_UNKNOWNS", A.shape[0] + 1)
    assert "mixed_precision" not in solve_nested(A, b, x, where="test")[1]
    monkeypatch.setattr(policy, "MIXED_FROM_UNKNOWNS", A.shape[0])
    assert solve_nested(A, b, x, where="test")[1]["mixed_precision"].startswith("float32")


@pytest.mark.parametrize("size", [1e-300, 1e300])
def test_right_hand_sides_beyond_single_precision_range(size):
    """Single precision spans 1e-38..3e38; each right-hand side is scaled into it (by a
    power of two, exactly), so the refinement still converges and the solution is the
    scaled one to the double LU's accuracy (condition ~20, n = 576: 1e4 eps)."""
    A, x = lattice_operator(24, 2)
    b = np.random.default_rng(10).normal(size=A.shape[0])
    u, info = solve_nested(A, size * b, x, where="test", mixed=True)
    assert info["mixed_precision"].startswith("float32 LU")
    ref, _ = solve_nested(A, b, x, where="test", mixed=False)
    assert np.abs(u / size - ref).max() / np.abs(ref).max() < 1e4 * EPS


def test_solve_in_a_forked_process():
    """A child forked after the parent solved (as report workers may be) solves the same
    system bit for bit."""
    import multiprocessing
    A, x = lattice_operator(24, 2)
    b = np.ones(A.shape[0])
    parent, _ = solve_nested(A, b, x, where="test", mixed=True)
    ctx = multiprocessing.get_context("fork")
    with ctx.Pool(1) as pool:
        child, info = pool.apply_async(solve_nested, (A, b, x),
                                       {"where": "test", "mixed": True}).get(timeout=120)
    assert info["mixed_precision"].startswith("float32 LU")
    assert np.array_equal(child, parent)      # the same operations: bit for bit


def _malloc_in_use():
    """Bytes the C allocator has handed out and not got back (glibc's mallinfo2: every
    arena's blocks in use plus the mmapped ones), or None without glibc >= 2.33."""
    import ctypes

    class MallInfo2(ctypes.Structure):
        _fields_ = [(name, ctypes.c_size_t) for name in
                    "arena ordblks smblks hblks hblkhd usmblks fsmblks uordblks fordblks "
                    "keepcost".split()]
    try:
        f = ctypes.CDLL(None).mallinfo2
    except (OSError, AttributeError):
        return None
    f.restype = MallInfo2
    info = f()
    return info.uordblks + info.hblkhd


def test_a_dropped_float32_factor_gives_its_memory_back():
    """A float32 factor made and dropped (three times) leaves less than one factor's
    bytes behind (its entries, 8 bytes each in float32 with their row indices; what the
    interpreter's own caches keep is far below that). SplitLU, which it replaced, made
    its halves in worker threads, where scipy's SuperLU had to free them too (its
    allocations are tracked per thread; scipy issue 15921)."""
    import gc
    n = 100
    A = sp.diags([-1.0, -1.0, 4.0, -1.0, -1.0], [-n, -1, 0, 1, n],
                 shape=(n * n, n * n)).tocsr()
    if _malloc_in_use() is None:
        pytest.skip("needs glibc's mallinfo2")
    entries = SingleLU(A).factor_entries

    def one():
        lu = SingleLU(A)
        lu.solve(np.ones(n * n))
        del lu
        gc.collect()

    one()                               # the first allocations
    before = _malloc_in_use()
    for _ in range(3):
        one()
    assert _malloc_in_use() - before < 8 * entries, (_malloc_in_use() - before, entries)
