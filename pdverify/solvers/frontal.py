"""A multifrontal LU over the separator tree of a nested-dissection ordering
(:func:`pdverify.solvers.ordering.nested_dissection` with ``tree=True``): each front is a
dense matrix factored by LAPACK (getrf) and BLAS-3 (TRSM, GEMM), so the work runs at the
dense kernels' speed rather than a general sparse LU's.

Front ``k`` of the tree holds the permuted unknowns ``start[k]:stop[k]`` (its fully summed
variables) and the later unknowns coupled to its subtree in the pattern of A + A^T (its
update variables, all in ancestors' fronts). In post-order each front is assembled from
A's entries whose smaller index is one of its own and the update matrices of its children
(extend-add), its fully summed block is factored with partial pivoting inside that block,

    P F11 = L11 U11,  U12 = L11^-1 P F12,  L21 = F21 U11^-1,  update = F22 - L21 U12,

and its update matrix passes to its parent. A solve runs forward through the fronts in
post-order and back in reverse (:meth:`FrontalLU.solve`, also with A^T).

An unknown with a zero diagonal entry (the Taylor systems' ghost rows) is eliminated in the
front of its last coupled unknown, where its partners' elimination has filled its diagonal
(:meth:`FrontalLU._fronts_of`). Pivots are chosen only among a front's fully summed rows
(no delayed pivoting: tried, it made the factor 1.8x slower and its solves no more
accurate: record frontal-2026-11-27-delayed-pivoting); large fronts (:data:`MERGE_SIZE`)
give the pivot search enough rows."""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp
from scipy.linalg import get_lapack_funcs, get_blas_funcs, solve_triangular

from .mixed import scaled_solve

#: Subtrees of at most this many unknowns are one front (:meth:`SeparatorTree.merged`):
#: fewer, larger dense fronts, fewer Python steps, and more rows for each front's pivot
#: search, which is what sets the float32 factor's accuracy here: the float32 solve's
#: error on body3d-manufactured's order-2 Taylor system 0.17 at 4096 against 2.7 at 1024
#: (SuperLU's 0.21), at the price of fill on the smaller 3D systems (record
#: frontal-2026-11-27-merge).
MERGE_SIZE = 4096


_dlaswp, = get_lapack_funcs(("laswp",), dtype=np.float64)


#: From this many update unknowns a child's update matrix goes into its parent front
#: column run by column run (:func:`_extend_add`); below, by one ``np.ix_`` scatter:
#: 2.5-5x faster by runs at 4,258 update unknowns, even at 500 (record
#: frontal-2026-11-27-extend-add).
EXTEND_ADD_BY_RUNS_FROM = 512


def _extend_add(F, places, U, add: bool) -> None:
    """``F[np.ix_(places, places)] = U`` (``add``: ``+=``), the same stores and sums: a
    child's update unknowns land in runs of consecutive places of the parent front, and
    from :data:`EXTEND_ADD_BY_RUNS_FROM` unknowns each run's columns are one slice
    (``F[places, a:b]``), which numpy gathers and scatters faster than the 2D index."""
    if places.size < EXTEND_ADD_BY_RUNS_FROM:
        if add:
            F[np.ix_(places, places)] += U
        else:
            F[np.ix_(places, places)] = U
        return
    starts = np.flatnonzero(np.diff(places) != 1) + 1
    for s, e in zip(np.r_[0, starts], np.r_[starts, places.size]):
        cols = slice(places[s], places[s] + e - s)
        if add:
            F[places, cols] += U[:, s:e]
        else:
            F[places, cols] = U[:, s:e]


class FrontalLU:
    """Multifrontal LU of the nested-dissection-ordered square sparse ``A`` over ``tree``
    (a :class:`~pdverify.solvers.ordering.SeparatorTree`; each subtree of at most ``merge``
    unknowns made one front, 0: as it is), computed in ``dtype``.

    ``solve(B, trans="N"|"T")``: one or several right-hand sides, float64 in and out,
    computed in ``dtype`` (each column scaled by a power of two near its largest entry, as
    :class:`~pdverify.solvers.nested.SingleLU` does). ``factor_entries``: entries stored
    (L and U of all fronts). Raises RuntimeError when a pivot is exactly zero or not finite.
    """

    kind = "multifrontal LU"

    def __init__(self, A, tree, dtype=np.float32, *, merge: int = MERGE_SIZE):
        # the columns in the factor's precision (the fronts are), canonical (sorted, no
        # duplicates: a transposition sorts, linear time); the rows from A itself unless
        # it has duplicates (memory: one copy of A fewer while the fronts are factored).
        # The values are cast after the transposition: scipy's astype first sorts and sums
        # the duplicates of its input, and the nested-dissection ordering hands A over
        # with unsorted rows (2.5x faster, the same C bit for bit: record
        # frontal-2026-11-27-cast-order)
        self.dtype = np.dtype(dtype)
        A = sp.csr_matrix(A)
        C = A.tocsc().astype(self.dtype)
        C.sum_duplicates()
        if C.nnz != A.nnz:
            A = C.tocsr()
        n = A.shape[0]
        self.shape = A.shape
        if merge:
            tree = tree.merged(merge)
        self.tree = tree
        if np.sum(tree.stop - tree.start) != n:
            raise ValueError("the tree does not cover the matrix")
        step = self._fronts_of(A, C, tree)
        # each front's own unknowns (ascending), the fronts in post-order
        order = np.argsort(step, kind="stable")
        owns = np.split(order, np.cumsum(np.bincount(step, minlength=len(tree)))[:-1])
        getrf, laswp = get_lapack_funcs(("getrf", "laswp"), dtype=self.dtype)
        trsm, gemm = get_blas_funcs(("trsm", "gemm"), dtype=self.dtype)
        children = [[] for _ in range(len(tree))]
        for k, p in enumerate(tree.parent):
            if p >= 0:
                children[p].append(k)
        loc = np.zeros(n, dtype=np.int64)      # global unknown -> place in the current front
        mark = np.zeros(n, dtype=bool)
        updates = {}                            # front -> (update unknowns, update matrix)
        self.fronts = []
        entries = 0
        for k, own in enumerate(owns):
            nf = own.size
            # update unknowns: those of the own rows' pattern and of the children's update
            # sets that are eliminated later
            R = A[own].tocoo()
            Q = C[:, own].tocoo()
            mark[R.col] = True
            mark[Q.row] = True
            kids = [c for c in children[k] if c in updates]   # (a child may have none)
            for c in kids:
                mark[updates[c][0]] = True
            upd = np.flatnonzero(mark)
            mark[upd] = False
            upd = upd[step[upd] > k]
            nu = upd.size
            m = nf + nu
            loc[own] = np.arange(nf)
            loc[upd] = nf + np.arange(nu)
            F = np.zeros((m, m), dtype=self.dtype, order="F")
            # extend-add: the largest child's update matrix is set (F is zero there, a
            # plain scatter, ~6x faster than adding: record
            # frontal-2026-11-27-set-largest-child), the others added
            kids = sorted(kids, key=lambda c: -updates[c][0].size)
            for i, c in enumerate(kids):
                cu, U = updates.pop(c)
                _extend_add(F, loc[cu], U, add=i > 0)
                del U
            # A's entries whose first eliminated index is an own one (no duplicates: +=),
            # placed by their offsets in F's Fortran-ordered buffer: one-dimensional
            # indexing, the same sums, half the time of F[rows, cols] (record
            # frontal-2026-11-27-flat-index)
            flat = F.reshape(-1, order="F")     # a view
            keep = step[R.col] >= k
            flat[R.row[keep] + loc[R.col[keep]] * m] += R.data[keep]
            keep = step[Q.row] > k
            flat[loc[Q.row[keep]] + Q.col[keep].astype(np.int64) * m] += Q.data[keep]
            del flat
            del R, Q
            if not nf:      # all its unknowns went to later fronts: pass the sum on
                if nu:
                    updates[k] = (upd, F)
                continue
            lu, piv, info = getrf(F[:nf, :nf], overwrite_a=1)
            d = np.diagonal(lu)
            if info > 0 or not np.all(np.isfinite(d)):
                raise RuntimeError(f"zero or non-finite pivot in front {k} of {len(owns)} "
                                   f"({nf} unknowns)")
            # the row order P applies: P v = v[perm] (the swaps applied to 0, 1, ...)
            perm = _dlaswp(np.arange(nf, dtype=float).reshape(-1, 1), piv)[:, 0].astype(
                np.int64)
            if nu:
                U12 = trsm(1.0, lu, laswp(np.asfortranarray(F[:nf, nf:]), piv),
                           lower=1, diag=1, overwrite_b=1)
                L21 = trsm(1.0, lu, np.asfortranarray(F[nf:, :nf]), side=1, lower=0,
                           overwrite_b=1)
                F22 = np.asfortranarray(F[nf:, nf:])
                del F
                F22 = gemm(-1.0, L21, U12, beta=1.0, c=F22, overwrite_c=1)
                updates[k] = (upd, F22)
            else:
                U12 = L21 = None
                del F
            self.fronts.append((own, upd, lu, perm, U12, L21))
            entries += nf * nf + 2 * nf * nu
        if updates:
            raise RuntimeError("update matrices left without a parent front")
        self.factor_entries = int(entries)

    @staticmethod
    def _fronts_of(A, C, tree):
        """The front that eliminates each unknown: its tree front, except that an unknown
        with a zero diagonal entry (a constraint row) goes to the front of its last coupled
        unknown, where the elimination of its partners has filled its diagonal (a static
        form of delayed pivoting: in its own front its column may have no pivot at all).
        The coupled unknowns of a front's unknowns lie in its subtree and its ancestors, so
        the last one is in the front itself or an ancestor, and the tree stays valid."""
        n = A.shape[0]
        by_start = np.argsort(tree.start)
        step = np.repeat(by_start, (tree.stop - tree.start)[by_start])
        zero = np.flatnonzero(A.diagonal() == 0)
        if zero.size:
            # the last unknown coupled to each (in its row of A or its column)
            last = np.arange(n)
            for M in (A, C):
                counts = np.diff(M.indptr)
                top = np.maximum.reduceat(M.indices, np.minimum(M.indptr[:-1], M.nnz - 1))
                last = np.where(counts > 0, np.maximum(last, top), last)
            step[zero] = step[last[zero]]
        return step

    def solve(self, b, trans: str = "N"):
        # each column scaled by a power of two, as SingleLU.solve (mixed.scaled_solve)
        return scaled_solve(b, trans, self._solve)

    def _solve(self, b, trans):
        X = b.astype(self.dtype)
        one = X.ndim == 1
        if one:
            X = X[:, None]
        X = (self._solve_T(X) if trans == "T" else self._solve_N(X)).astype(float)
        return X[:, 0] if one else X

    def _solve_N(self, X):
        for own, upd, lu, perm, U12, L21 in self.fronts:
            z = solve_triangular(lu, X[own[perm]], lower=True, unit_diagonal=True,
                                 check_finite=False)
            X[own] = z
            if L21 is not None:
                X[upd] -= L21 @ z
        for own, upd, lu, perm, U12, L21 in reversed(self.fronts):
            v = X[own] if U12 is None else X[own] - U12 @ X[upd]
            X[own] = solve_triangular(lu, v, check_finite=False)
        return X

    def _solve_T(self, X):
        for own, upd, lu, perm, U12, L21 in self.fronts:
            w = solve_triangular(lu, X[own], trans="T", check_finite=False)
            X[own] = w
            if U12 is not None:
                X[upd] -= U12.T @ w
        for own, upd, lu, perm, U12, L21 in reversed(self.fronts):
            v = X[own] if L21 is None else X[own] - L21.T @ X[upd]
            X[own[perm]] = solve_triangular(lu, v, trans="T", lower=True,
                                            unit_diagonal=True, check_finite=False)
        return X
