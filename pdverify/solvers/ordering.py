"""Geometric nested dissection: a fill-reducing ordering for sparse LU of PD systems.

PD couples every node to all nodes within the stencil's reach, so a sparse LU's cost is
set by its separators. Splitting the unknowns at the median coordinate of the longest
extent, and taking as separator the unknowns of one side that the matrix couples to the
other, gives separators one reach thick, the best possible for a lattice operator.
SuperLU's own orderings (COLAMD, minimum degree) do not see the geometry: on the seed-001
plane-strain plate at h = 0.01 the whole solve under this ordering is 6.0x faster than
COLAMD's of the multiplied-out stiffness (record solvers-2026-11-22-nested-dissection).
The first split also lets the two halves
be told apart (the top separator's size chooses the float32 factor,
:func:`pdverify.solvers.policy.frontal_factor`).
"""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp

#: Subdomains of at most this many unknowns are not split further: 16-64 give the same
#: factor time on the 2D plate, 256 is 25 % slower (record solvers-2026-11-22-leaf-size).
LEAF_SIZE = 64


def nested_dissection(A, coords, leaf: int = LEAF_SIZE, *, top_split: bool = False,
                      tree: bool = False):
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
    ``A`` is not split at all, i.e. has at most ``leaf`` unknowns).

    ``tree=True`` appends the separator tree to what is returned (``(perm, tree)`` or
    ``(perm, (n1, n2), tree)``): a :class:`SeparatorTree` of the fronts (each leaf subdomain
    and each separator, empty ones left out) in post-order, each a range of the permuted
    order; the permutation is the same."""
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
    # the tree: each front's (start, stop, parent front id; -1 for none), and each
    # subdomain's parent front (the separator of the subdomain it was split from)
    fronts = []
    dparent = np.full(1, -1, dtype=np.int64)
    while act.size:
        count = np.bincount(dom, minlength=start.size)
        first = np.r_[0, np.cumsum(count)][:-1]
        leaf_of = count[dom] <= leaf
        pos[act[leaf_of]] = start[dom[leaf_of]] + np.arange(act.size)[leaf_of] - first[dom[
            leaf_of]]
        split = np.flatnonzero(count > leaf)
        if tree:
            done = np.flatnonzero((count <= leaf) & (count > 0))
            fronts += zip(start[done], start[done] + count[done], dparent[done])
        if not split.size:
            break
        renumber = np.full(start.size, -1)
        renumber[split] = np.arange(split.size)
        act, dom = act[~leaf_of], renumber[dom[~leaf_of]]
        start, count = start[split], count[split]
        if tree:
            dparent = dparent[split]
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
        if tree:     # the separators' fronts, parents of the next level's subdomains
            sep_start = start[1::2] + sizes[:, 1]
            ids = len(fronts) + np.arange(split.size)
            fronts += zip(sep_start, sep_start + sizes[:, 2], dparent)
            dparent = np.repeat(ids, 2)
    perm = np.empty(n, dtype=np.int64)
    perm[pos] = np.arange(n)
    out = (perm, top) if top_split else (perm,)
    if tree:
        out += (SeparatorTree.from_fronts(fronts),)
    return out if len(out) > 1 else perm


class SeparatorTree:
    """The fronts of a nested-dissection ordering in post-order (children before their
    parent): front ``k`` holds the permuted unknowns ``start[k]:stop[k]``, its parent is
    ``parent[k]`` (-1 at a root). A front's subtree is a contiguous range of the ordering,
    and the matrix couples a front's unknowns only to unknowns of its subtree and its
    ancestors."""

    def __init__(self, start, stop, parent):
        self.start = np.asarray(start, dtype=np.int64)
        self.stop = np.asarray(stop, dtype=np.int64)
        self.parent = np.asarray(parent, dtype=np.int64)

    def __len__(self):
        return self.start.size

    @classmethod
    def from_fronts(cls, fronts):
        """From ``(start, stop, parent)`` rows in any order: empty fronts are left out (their
        children go to the nearest non-empty ancestor), the rest sorted by range (a
        separator's range follows its subdomain's parts, so that is post-order)."""
        f = np.array(list(fronts), dtype=np.int64).reshape(-1, 3)
        start, stop, parent = f[:, 0], f[:, 1], f[:, 2].copy()
        empty = stop == start
        # up past empty ancestors: a chain is at most the tree's depth (~log2 n) long
        while True:
            up = (parent >= 0) & empty[np.maximum(parent, 0)]
            if not up.any():
                break
            parent[up] = parent[parent[up]]
        keep = np.flatnonzero(~empty)
        keep = keep[np.argsort(stop[keep], kind="stable")]
        new_id = np.full(f.shape[0], -1, dtype=np.int64)
        new_id[keep] = np.arange(keep.size)
        parent = parent[keep]
        return cls(start[keep], stop[keep], np.where(parent >= 0, new_id[parent], -1))

    def merged(self, size: int) -> "SeparatorTree":
        """The same ordering with every subtree of at most ``size`` unknowns one front
        (fewer, larger dense fronts: a multifrontal factor's leaf size)."""
        k = len(self)
        first = self.start.copy()          # where each front's subtree begins
        for f in range(k):                 # post-order: children first (fronts, not unknowns)
            p = self.parent[f]
            if p >= 0:
                first[p] = min(first[p], first[f])
        total = self.stop - first
        small = total <= size
        # a front is kept if its subtree is large, or it is the top of a small subtree
        top = small & ~np.where(self.parent >= 0, small[np.maximum(self.parent, 0)], False)
        keep = ~small | top
        start = np.where(top, first, self.start)
        parent = self.parent.copy()
        ids = np.flatnonzero(keep)
        new_id = np.full(k, -1, dtype=np.int64)
        new_id[ids] = np.arange(ids.size)
        parent = parent[ids]
        return SeparatorTree(start[ids], self.stop[ids],
                             np.where(parent >= 0, new_id[np.maximum(parent, 0)], -1))
