"""Multifrontal LU over the nested-dissection tree (pdverify.solvers.frontal.FrontalLU) and
the tree itself (nested_dissection(..., tree=True))."""
import numpy as np
import pytest
import scipy.sparse as sp

from pdverify.solvers import nested, policy
from pdverify.solvers.frontal import FrontalLU
from pdverify.solvers.ordering import nested_dissection

EPS = np.finfo(float).eps


def lattice_operator(shape, reach, dofs=1, seed=1):
    """A nonsymmetric operator coupling the ``dofs`` unknowns of lattice nodes within
    ``reach`` (max norm; 2D or 3D by ``shape``), diagonally dominant."""
    ij = np.stack(np.meshgrid(*map(np.arange, shape), indexing="ij"), -1).reshape(
        -1, len(shape))
    rng = np.random.default_rng(seed)
    i, j = np.nonzero(np.abs(ij[:, None, :] - ij[None, :, :]).max(-1) <= reach)
    rows = (dofs * i[:, None] + np.arange(dofs)).repeat(dofs, axis=1).ravel()
    cols = np.tile(dofs * j[:, None] + np.arange(dofs), dofs).ravel()
    A = sp.csr_matrix((rng.uniform(-1, 0, rows.size), (rows, cols)))
    A = A - sp.diags(A.diagonal())
    A = A + sp.diags(-np.asarray(A.sum(axis=1)).ravel() + 1.0)
    return A.tocsr(), np.repeat(ij.astype(float), dofs, axis=0)


def with_constraints(A, x, seed=2):
    """A bordered by unknowns with a zero diagonal entry, as the Taylor systems' ghost
    rows: unknown g couples to two lattice unknowns i, k only (row 1.5 u_i - 0.5 u_k,
    column the same), placed at node i."""
    n = A.shape[0]
    rng = np.random.default_rng(seed)
    i = rng.choice(n, size=n // 8, replace=False)
    k = (i + 1) % n
    g = n + np.arange(i.size)
    B = sp.csr_matrix((np.r_[np.full(i.size, 1.5), np.full(i.size, -0.5)],
                       (np.r_[g, g], np.r_[i, k])), shape=(n + i.size, n + i.size))
    big = sp.bmat([[A, None], [None, sp.csr_matrix((i.size, i.size))]]).tocsr()
    return (big + B + B.T).tocsr(), np.r_[x, x[i]]


CASES = {
    "2d": lambda: lattice_operator((24, 24), 2),
    "3d-3dofs": lambda: lattice_operator((7, 7, 7), 1, dofs=3),
    "constraints": lambda: with_constraints(*lattice_operator((20, 20), 2)),
}


def ordered(case, leaf=16):
    A, x = CASES[case]()
    perm, tree = nested_dissection(A, x, leaf=leaf, tree=True)
    return A[perm][:, perm].tocsr(), tree


def relative_residual(M, x, b):
    """max |M x - b| / (||M||_inf max |x|), per column: the normwise backward error."""
    norm = abs(M).sum(axis=1).max()
    return np.max(np.abs(M @ x - b).max(axis=0) / (norm * np.abs(x).max(axis=0)))


@pytest.mark.parametrize("case", list(CASES))
@pytest.mark.parametrize("merge", [0, 64, 256])
@pytest.mark.parametrize("trans", ["N", "T"])
def test_frontal_lu_in_double_is_backward_stable(case, merge, trans):
    """In float64 the factor is LU with partial pivoting inside each front's fully summed
    block: backward stable, |A x - b| <= gamma_n |L| |U| |x| (Higham, Accuracy and
    Stability, Thm 9.4), gamma_n ~ n eps; with little element growth on these diagonally
    dominant operators (and on the bordered ones, whose pivots come after fill) the
    normwise backward error is below n eps (measured ~2e-16). trans="T" solves A^T."""
    A, tree = ordered(case)
    n = A.shape[0]
    lu = FrontalLU(A, tree, dtype=np.float64, merge=merge)
    b = np.random.default_rng(3).normal(size=(n, 2))
    M = A if trans == "N" else A.T.tocsr()
    x = lu.solve(b, trans=trans)
    assert relative_residual(M, x, b) < n * EPS
    x1 = lu.solve(b[:, 0], trans=trans)
    assert x1.shape == (n,) and relative_residual(M, x1[:, None], b[:, :1]) < n * EPS
    assert lu.factor_entries > A.nnz / 2


def test_float32_factor_solves_to_single_precision_and_refines():
    """The float32 factor's solve is accurate to ~n eps_single (same bound in single
    precision), and refinement in double reaches the double solve."""
    from pdverify.solvers.mixed import refine_with_probe
    A, tree = ordered("3d-3dofs")
    n = A.shape[0]
    lu = FrontalLU(A, tree, merge=64)
    b = np.random.default_rng(4).normal(size=n)
    assert relative_residual(A, lu.solve(b)[:, None], b[:, None]) < n * np.finfo(
        np.float32).eps
    y, cond, diag = refine_with_probe(A, b, lu)
    # refine_with_probe's own stop: relative residual 2 eps (REFINE_STOP), measured in
    # its max-norm measure ||r|| / (||A|| ||x||)
    assert y is not None and relative_residual(A, y[:, None], b[:, None]) <= 2 * EPS
    assert "refinement" not in diag        # plain refinement, no GMRES-IR


@pytest.mark.parametrize("dtype", [np.float32, np.float64])
def test_the_factor_does_not_depend_on_the_order_of_a_rows_entries(dtype):
    """The nested-dissection ordering hands A over with unsorted rows: the factor is the
    same, bit for bit, as of the sorted A (each entry is placed once; the columns' copy
    is canonical either way)."""
    A, tree = ordered("3d-3dofs")
    A = A.sorted_indices()
    shuffled = A.copy()
    rng = np.random.default_rng(5)
    for i in range(A.shape[0]):        # each row's entries in another order
        lo, hi = shuffled.indptr[i], shuffled.indptr[i + 1]
        p = lo + rng.permutation(hi - lo)
        shuffled.indices[lo:hi], shuffled.data[lo:hi] = A.indices[p], A.data[p]
    shuffled = sp.csr_matrix((shuffled.data, shuffled.indices, shuffled.indptr),
                             shape=A.shape)
    assert not shuffled.has_sorted_indices
    b = np.random.default_rng(6).normal(size=A.shape[0])
    x, y = (FrontalLU(M, tree, dtype=dtype, merge=64) for M in (A, shuffled))
    for fx, fy in zip(x.fronts, y.fronts):
        for ax, ay in zip(fx, fy):
            assert (ax is None and ay is None) or np.array_equal(ax, ay)
    assert np.array_equal(x.solve(b), y.solve(b))


def test_singular_matrix_raises():
    """An exactly zero column: some front's pivot is exactly zero."""
    A, tree = ordered("2d")
    A = A.tolil()
    A[:, 100] = 0.0
    with pytest.raises(RuntimeError, match="pivot"):
        FrontalLU(sp.csr_matrix(A), tree, dtype=np.float64)


def test_constraint_unknowns_are_eliminated_after_their_partners():
    """A zero-diagonal unknown whose partners lie in an ancestor front has an all-zero
    column in its own front's block: it must move to its last partner's front (else the
    factor would raise)."""
    A, tree = ordered("constraints")
    step = FrontalLU._fronts_of(A, A.tocsc(), tree)
    by_start = np.argsort(tree.start)
    original = np.repeat(by_start, (tree.stop - tree.start)[by_start])
    zero = np.flatnonzero(A.diagonal() == 0)
    assert zero.size and np.any(step[zero] != original[zero])
    assert np.array_equal(step[A.diagonal() != 0], original[A.diagonal() != 0])


def subtree_first(tree):
    first = tree.start.copy()
    for k in range(len(tree)):
        if tree.parent[k] >= 0:
            first[tree.parent[k]] = min(first[tree.parent[k]], first[k])
    return first


@pytest.mark.parametrize("case", list(CASES))
@pytest.mark.parametrize("merge", [0, 64])
def test_tree_is_consistent(case, merge):
    """Every unknown in exactly one front; parents after their children; a front's
    unknowns are coupled (pattern of A + A^T) only to its subtree and its ancestors; the
    permutation is the one returned without the tree."""
    A0, x = CASES[case]()
    perm, tree = nested_dissection(A0, x, leaf=16, tree=True)
    assert np.array_equal(perm, nested_dissection(A0, x, leaf=16))
    p2, top, t2 = nested_dissection(A0, x, leaf=16, top_split=True, tree=True)
    assert np.array_equal(p2, perm) and top == nested_dissection(A0, x, leaf=16,
                                                                 top_split=True)[1]
    assert np.array_equal(t2.start, tree.start)
    if merge:
        tree = tree.merged(merge)
    n = A0.shape[0]
    assert len(tree) > 3
    owner = np.full(n, -1)
    for k in range(len(tree)):
        assert np.all(owner[tree.start[k]:tree.stop[k]] == -1)
        owner[tree.start[k]:tree.stop[k]] = k
    assert np.all(owner >= 0)
    roots = np.flatnonzero(tree.parent < 0)
    assert np.all(tree.parent[tree.parent >= 0] > np.flatnonzero(tree.parent >= 0))
    assert roots.size >= 1 and roots[-1] == len(tree) - 1
    A = A0[perm][:, perm]
    G = (abs(A) + abs(A.T)).tocsr()
    first = subtree_first(tree)
    for k in range(len(tree)):
        cols = G[tree.start[k]:tree.stop[k]].indices
        ancestors, p = [], tree.parent[k]
        while p >= 0:
            ancestors.append(p)
            p = tree.parent[p]
        inside = (cols >= first[k]) & (cols < tree.stop[k])
        assert np.all(inside | np.isin(owner[cols], ancestors)), k


def test_whole_matrix_factor_is_frontal_and_falls_back_to_superlu(monkeypatch):
    """single_precision_factor: with the tree, a large top separator gives the
    multifrontal factor, a small one SuperLU's; when the multifrontal one raises,
    SuperLU's, with the reason in the note."""
    A, tree = ordered("3d-3dofs")
    monkeypatch.setattr(policy, "frontal_factor", lambda s, n: False)
    lu, note = nested.single_precision_factor(A, 10, 10, tree)
    assert isinstance(lu, nested.SingleLU) and note == ""
    monkeypatch.setattr(policy, "frontal_factor", lambda s, n: True)
    lu, note = nested.single_precision_factor(A, 10, 10, tree)
    assert isinstance(lu, FrontalLU) and "multifrontal: top separator" in note

    def fail(*args, **kwargs):
        raise RuntimeError("zero or non-finite pivot")
    monkeypatch.setattr(nested, "FrontalLU", fail)
    lu, note = nested.single_precision_factor(A, 10, 10, tree)
    assert isinstance(lu, nested.SingleLU) and "multifrontal factor failed" in note


def test_duplicate_entries_are_summed():
    """A matrix given with duplicate entries (COO-style) is the sum of them: each entry
    split in two halves gives the same factor's solve (float64: the halves sum exactly,
    so bit for bit)."""
    A, tree = ordered("2d")
    A.sort_indices()
    # every row's entries twice, each with half the value (CSR arrays given directly: the
    # COO constructor would sum them)
    nnz = np.diff(A.indptr)
    rows = np.repeat(np.arange(A.shape[0]), nnz)
    order = np.argsort(np.r_[rows, rows], kind="stable")
    twice = sp.csr_matrix((np.r_[A.data, A.data][order] / 2,
                           np.r_[A.indices, A.indices][order], 2 * A.indptr), shape=A.shape)
    assert twice.nnz == 2 * A.nnz
    b = np.random.default_rng(5).normal(size=A.shape[0])
    x = FrontalLU(A, tree, dtype=np.float64).solve(b)
    assert np.array_equal(FrontalLU(twice, tree, dtype=np.float64).solve(b), x)


@pytest.mark.parametrize("add", [False, True])
@pytest.mark.parametrize("layout", ["runs", "scattered", "one run"])
def test_extend_add_by_column_runs_is_the_2d_scatter(add, layout):
    """frontal._extend_add stores and sums exactly what F[np.ix_(p, p)] (+)= U does, on
    either side of EXTEND_ADD_BY_RUNS_FROM."""
    from pdverify.solvers import frontal
    rng = np.random.default_rng(7)
    for nu in (frontal.EXTEND_ADD_BY_RUNS_FROM - 1, frontal.EXTEND_ADD_BY_RUNS_FROM + 37):
        m = 3 * nu
        if layout == "one run":
            places = np.arange(5, 5 + nu)
        elif layout == "scattered":
            places = np.sort(rng.choice(m, nu, replace=False))
        else:      # a few runs, not in ascending order (own and update places interleave)
            places = np.concatenate([np.arange(a, a + k) for a, k in
                                     zip((2 * nu, 10, nu + 3), (nu // 3, nu // 3,
                                                                nu - 2 * (nu // 3)))])
        U = np.asfortranarray(rng.standard_normal((nu, nu)).astype(np.float32))
        F0 = np.asfortranarray(rng.standard_normal((m, m)).astype(np.float32))
        F1 = F0.copy(order="F")
        if add:
            F0[np.ix_(places, places)] += U
        else:
            F0[np.ix_(places, places)] = U
        frontal._extend_add(F1, places, U, add=add)
        assert np.array_equal(F0.view(np.int32), F1.view(np.int32))


def test_the_factor_is_the_same_whichever_way_the_updates_are_added(monkeypatch):
    """The whole factor, bit for bit, with every extend-add by column runs and with every
    one by np.ix_."""
    from pdverify.solvers import frontal
    A, tree = ordered("3d-3dofs")
    b = np.random.default_rng(8).normal(size=A.shape[0])
    out = []
    for limit in (0, 10 ** 9):
        monkeypatch.setattr(frontal, "EXTEND_ADD_BY_RUNS_FROM", limit)
        lu = FrontalLU(A, tree, dtype=np.float32, merge=64)
        out.append((lu.fronts, lu.solve(b)))
    for fx, fy in zip(out[0][0], out[1][0]):
        for ax, ay in zip(fx, fy):
            assert (ax is None and ay is None) or np.array_equal(ax, ay)
    assert np.array_equal(out[0][1], out[1][1])
