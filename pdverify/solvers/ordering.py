"""Geometric nested dissection: a fill-reducing ordering for sparse LU of PD systems.

PD couples every node to all nodes within the stencil's reach, so a sparse LU's cost is
set by its separators. Splitting the unknowns at the median coordinate of the longest
extent, and taking as separator the unknowns of one side that the matrix couples to the
other, gives separators one reach thick, the best possible for a lattice operator.
SuperLU's own orderings (COLAMD, minimum degree) do not see the geometry: on the seed-001
plane-strain plate at h = 0.01 (augmented system, 30,600 unknowns) this ordering makes
SuperLU's factor 3.1e7 entries against 6.6e7 under minimum degree (a side measurement),
and the whole solve 6.0x faster than today's COLAMD solve of the multiplied-out stiffness
(benchmarks/solvers.py: 3.22 s against 19.49 s). The first split also lets the two halves
be factored in parallel (:class:`pdverify.solvers.nested.SplitLU`).
"""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp

#: Subdomains of at most this many unknowns are not split further (measured: 16-64 give
#: the same factor time on the 2D plate; 256 is 25 % slower).
LEAF_SIZE = 64


def nested_dissection(A, coords, leaf: int = LEAF_SIZE, *, top_split: bool = False):
    """A permutation of the unknowns of the square sparse matrix ``A`` (coordinates
    ``coords``, one row per unknown): each subdomain's unknowns before its separator, the
    separators of larger subdomains last. The split is geometric, the separator is read off
    the pattern of A + A^T, so any coupling the matrix has (Taylor rows, dilatations) is
    respected.

    A subdomain of more than ``leaf`` unknowns is split at the median coordinate along its
    longest extent (by rank, half and half, when that leaves one side empty); its separator
    is the left side's unknowns coupled to the right side. The order is the post-order of
    that tree: left part, right part, separator; within a leaf or a separator, ascending
    index. All subdomains of one depth are split at once (they are not coupled to each
    other: separators lie between them), so the work is a few array passes per level.

    ``top_split=True`` returns ``(perm, (n1, n2))`` instead: the permuted matrix is
    ``[[A11, 0, A1s], [0, A22, A2s], [As1, As2, Ass]]`` with the two halves of the first
    split ``n1`` and ``n2`` unknowns long and the top separator last (``n1 = n2 = 0`` when
    ``A`` is not split at all, i.e. has at most ``leaf`` unknowns)."""
    A = sp.csr_matrix(A)
    n = A.shape[0]
    pattern = sp.csr_matrix(((A.data != 0).astype(float), A.indices, A.indptr), shape=A.shape)
    G = (pattern + pattern.T).tocsr()
    coords = np.asarray(coords, dtype=float).reshape(n, -1)
    pos = np.empty(n, dtype=np.int64)        # each unknown's place in the ordering
    # the unknowns still to place, grouped by subdomain (ascending index within one), the
    # subdomain of each, and where each subdomain's block of the ordering starts
    act = np.arange(n)
    dom = np.zeros(n, dtype=np.int64)
    start = np.zeros(1, dtype=np.int64)
    top = (0, 0)
    on_right = np.zeros(n)
    while act.size:
        count = np.bincount(dom, minlength=start.size)
        first = np.r_[0, np.cumsum(count)][:-1]
        leaf_of = count[dom] <= leaf
        pos[act[leaf_of]] = start[dom[leaf_of]] + np.arange(act.size)[leaf_of] - first[dom[
            leaf_of]]
        split = np.flatnonzero(count > leaf)
        if not split.size:
            break
        renumber = np.full(start.size, -1)
        renumber[split] = np.arange(split.size)
        act, dom = act[~leaf_of], renumber[dom[~leaf_of]]
        start, count = start[split], count[split]
        first = np.r_[0, np.cumsum(count)][:-1]
        x = coords[act]
        extent = np.maximum.reduceat(x, first, axis=0) - np.minimum.reduceat(x, first, axis=0)
        xa = x[np.arange(act.size), np.argmax(extent, axis=1)[dom]]
        order = np.lexsort((xa, dom))           # by coordinate within a subdomain, stable
        xs = xa[order]
        lo, hi = first + (count - 1) // 2, first + count // 2
        median = np.where(count % 2 == 1, xs[hi], (xs[lo] + xs[hi]) / 2)   # np.median's
        left = xa < median[dom]
        n_left = np.bincount(dom, weights=left, minlength=split.size)
        ties = (n_left == 0) | (n_left == count)
        if ties.any():        # halve by rank along the axis
            rank = np.empty(act.size, dtype=np.int64)
            rank[order] = np.arange(act.size) - first[dom[order]]
            t = ties[dom]
            left[t] = rank[t] < count[dom[t]] // 2
        on_right[act[~left]] = 1.0
        touches = left & ((G @ on_right)[act] > 0)
        on_right[act[~left]] = 0.0
        part = np.where(touches, 2, np.where(left, 0, 1))     # left, right, separator
        sizes = np.zeros((split.size, 3), dtype=np.int64)
        np.add.at(sizes, (dom, part), 1)
        if count[0] == n:                       # the first split
            top = (int(sizes[0, 0]), int(sizes[0, 1]))
        # separators are placed now, after their subdomain's two parts
        sep = part == 2
        ids = act[sep]
        key = dom[sep]
        grouped = np.lexsort((ids, key))
        sep_first = np.r_[0, np.cumsum(np.bincount(key, minlength=split.size))][:-1]
        where = np.empty(ids.size, dtype=np.int64)
        where[grouped] = np.arange(ids.size) - sep_first[key[grouped]]
        pos[ids] = start[key] + sizes[key, 0] + sizes[key, 1] + where
        # the parts become the next level's subdomains: 2 d (left), 2 d + 1 (right)
        act, child = act[~sep], 2 * dom[~sep] + part[~sep]
        regroup = np.lexsort((act, child))
        act, dom = act[regroup], child[regroup]
        start = np.stack([start, start + sizes[:, 0]], axis=1).ravel()
    perm = np.empty(n, dtype=np.int64)
    perm[pos] = np.arange(n)
    return (perm, top) if top_split else perm
