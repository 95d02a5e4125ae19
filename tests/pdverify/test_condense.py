"""pdverify.solvers.condense: the system left after u[fixed] = values."""
import numpy as np
import pytest
import scipy.sparse as sp

from pdverify.solvers.condense import condense


def _system(n=60, seed=0):
    """A sparse matrix with small integer entries (every product and sum below is exact
    in float64, so the checks are equalities), a load and prescribed values."""
    rng = np.random.default_rng(seed)
    K = sp.random(n, n, density=0.15, random_state=seed, format="csr",
                  data_rvs=lambda k: rng.integers(-9, 10, k).astype(float))
    K = (K + sp.diags(rng.integers(20, 30, n).astype(float))).tocsr()
    fixed = np.sort(rng.choice(n, n // 4, replace=False))
    return K, rng.integers(-5, 6, n).astype(float), fixed, rng.integers(-3, 4, fixed.size) * 1.0


def _expected(K, f, fixed, values):
    D = K.toarray()
    free = np.array([i for i in range(K.shape[0]) if i not in set(fixed)])
    return D[np.ix_(free, free)], f[free] - D[np.ix_(free, fixed)] @ values, free


@pytest.mark.parametrize("form", ["canonical", "unsorted", "duplicates", "csc"])
def test_condense_is_the_free_block_and_the_moved_load(form):
    """K_ff, f_f - K_fp u_p and the free unknowns, exactly (integer data), whatever the
    storage of K: canonical CSR (the fast path), unsorted indices, duplicate entries
    (summed), CSC."""
    K, f, fixed, values = _system()
    D_ff, r_exp, free = _expected(K, f, fixed, values)
    if form == "unsorted":
        K = K.copy()
        for i in range(K.shape[0]):
            a, b = K.indptr[i], K.indptr[i + 1]
            K.indices[a:b] = K.indices[a:b][::-1]
            K.data[a:b] = K.data[a:b][::-1]
        K.has_sorted_indices = False
        assert not K.has_canonical_format
    elif form == "duplicates":
        C = K.tocoo()
        half = np.floor(C.data / 2)
        K = sp.csr_matrix((np.r_[half, C.data - half], (np.r_[C.row, C.row],
                                                          np.r_[C.col, C.col])),
                          shape=K.shape)
        K.has_canonical_format = False
    elif form == "csc":
        K = K.tocsc()
    K_ff, r, expand = condense(K, f, fixed, values)
    np.testing.assert_array_equal(K_ff.toarray(), D_ff)
    np.testing.assert_array_equal(r, r_exp)
    np.testing.assert_array_equal(expand.free, free)
    u = expand(np.arange(free.size, dtype=float))
    np.testing.assert_array_equal(u[fixed], values)
    np.testing.assert_array_equal(u[free], np.arange(free.size))


def test_condense_without_prescribed_unknowns():
    K, f, _, _ = _system()
    K_ff, r, expand = condense(K, f, np.array([], dtype=int), np.array([]))
    np.testing.assert_array_equal(K_ff.toarray(), K.toarray())
    np.testing.assert_array_equal(r, f)
    np.testing.assert_array_equal(expand.free, np.arange(K.shape[0]))


def test_the_fast_path_keeps_the_entries_in_order():
    """The canonical CSR route gives what the CSC route gave, array for array (its
    indices sorted), so the solvers see the same matrix bit for bit."""
    K, f, fixed, values = _system(seed=3)
    K_ff, r, _ = condense(K, f, fixed, values)
    free = np.setdiff1d(np.arange(K.shape[0]), fixed)
    ref = K.tocsc()[:, free].tocsr()[free]
    assert K_ff.has_sorted_indices
    for name in ("indptr", "indices", "data"):
        np.testing.assert_array_equal(getattr(K_ff, name), getattr(ref, name))
