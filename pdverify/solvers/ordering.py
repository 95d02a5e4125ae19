"""Geometric nested dissection: a fill-reducing ordering for sparse LU of PD systems.

PD couples every node to all nodes within the stencil's reach, so a sparse LU's cost is
set by its separators. Splitting the unknowns at the median coordinate of the longest
extent, and taking as separator the unknowns of one side that the matrix couples to the
other, gives separators one reach thick, the best possible for a lattice operator.
SuperLU's own orderings (COLAMD, minimum degree) do not see the geometry: on the seed-001
plane-strain plate at h = 0.01 (augmented system, 30,600 unknowns) this ordering makes
SuperLU's factor 3.1e7 entries against 6.6e7 under minimum degree (a side measurement),
and the whole solve 6.0x faster than today's COLAMD solve of the multiplied-out stiffness
(benchmarks/solvers.py: 3.22 s against 19.49 s).
"""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp

#: Subdomains of at most this many unknowns are not split further (measured: 16-64 give
#: the same factor time on the 2D plate; 256 is 25 % slower).
LEAF_SIZE = 64


def nested_dissection(A, coords, leaf: int = LEAF_SIZE) -> np.ndarray:
    """A permutation of the unknowns of the square sparse matrix ``A`` (coordinates
    ``coords``, one row per unknown): each subdomain's unknowns before its separator, the
    separators of larger subdomains last. The split is geometric, the separator is read off
    the pattern of A + A^T, so any coupling the matrix has (Taylor rows, dilatations) is
    respected."""
    G = (abs(sp.csr_matrix(A)) + abs(sp.csr_matrix(A)).T).tocsr()
    G.data[:] = 1.0
    coords = np.asarray(coords, dtype=float)
    n = G.shape[0]
    on_right = np.zeros(n)
    pieces: list[np.ndarray] = []
    stack: list[tuple[np.ndarray, bool]] = [(np.arange(n), False)]
    # iterative post-order: a subdomain's separator follows both halves
    while stack:
        idx, emit = stack.pop()
        if emit or idx.size <= leaf:
            pieces.append(idx)
            continue
        x = coords[idx]
        axis = int(np.argmax(np.ptp(x, axis=0)))
        split = np.median(x[:, axis])
        left = x[:, axis] < split
        if left.all() or not left.any():  # ties: halve by rank
            left = np.zeros(idx.size, bool)
            left[np.argsort(x[:, axis], kind="stable")[: idx.size // 2]] = True
        L, R = idx[left], idx[~left]
        on_right[R] = 1.0
        touches = (G[L] @ on_right) > 0
        on_right[R] = 0.0
        stack.append((L[touches], True))    # the separator, emitted last
        stack.append((R, False))
        stack.append((L[~touches], False))
    return np.concatenate(pieces)
