"""Taylor-based fictitious nodes, nearest-node strategy (seed 000 §3-4): closure and BC rows."""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from ..pd.closure import Closure, real_identity
from .taylor import taylor_extrapolation_weights


def _end_stencil(grid, order: int, side: str):
    """The ``order + 1`` real nodes nearest one end (seed 000 Eq. 43) and the end node."""
    nr = grid.n_interior
    near = np.arange(order + 1) if side == "left" else nr - 1 - np.arange(order + 1)
    return near, near[0]


def _extension(grid, order: int) -> sp.csr_matrix:
    """Identity on the real nodes plus Taylor blocks on the fictitious ones (seed 000 D1/D4).

    Each end's fictitious nodes are extrapolated by the order-``order`` Taylor series
    centred on the real node nearest that end, its derivatives from the ``order + 1``
    nearest real nodes (Eq. 45).
    """
    x = grid.x[:, 0]
    xr = x[grid.interior_ids]
    fict_left = np.flatnonzero(grid.index[:, 0] < 0)
    fict_right = np.flatnonzero(grid.index[:, 0] >= grid.n_interior)
    rows, cols, vals = [], [], []
    for side, tgt in (("left", fict_left), ("right", fict_right)):
        src, anchor = _end_stencil(grid, order, side)
        W = taylor_extrapolation_weights(xr[src], x[tgt], order, xr[anchor], grid.spacing)
        rows.append(np.repeat(tgt, src.size))
        cols.append(np.tile(src, tgt.size))
        vals.append(W.ravel())
    extra = sp.csr_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))),
                          shape=(grid.n_ext, grid.n_interior))
    return (real_identity(grid) + extra).tocsr()


def fictitious_closure(grid, order: int) -> Closure:
    """The closure of ``taylor-fictitious`` on a 1D bar whose grid carries the fictitious
    layers: displacements of order n (Eq. 45), dilatations of order n - 1 (Eq. 47), m of a
    complete neighbourhood at every node (m = A delta^3 at integer m-ratio; ERRATA)."""
    if grid.dim != 1:
        raise ValueError("taylor-fictitious is implemented for 1D bars (seed 000 §4)")
    return Closure(weighted_volume="complete", displacement_map=_extension(grid, order),
                   dilatation_map=_extension(grid, order - 1))


def boundary_value_row(grid, order: int, side: str, point: float) -> np.ndarray:
    """Row r with r @ u_real = u at the boundary ``point`` by Taylor extrapolation (Eq. 58)."""
    xr = grid.x[grid.interior_ids, 0]
    src, anchor = _end_stencil(grid, order, side)
    row = np.zeros(grid.n_interior)
    row[src] = taylor_extrapolation_weights(xr[src], [point], order, xr[anchor],
                                            grid.spacing)[0]
    return row
