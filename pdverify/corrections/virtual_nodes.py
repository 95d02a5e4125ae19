"""Virtual nodes (seed 003 §4.1.2, variants 2 and 4 of Table 2): buffer layers of
thickness delta outside the clamped faces, on which the clamp's displacement is imposed
rigidly, so that every node of the body keeps a complete neighbourhood across those
faces. The other faces are left as they are or, with ``correct_sides``, corrected by the
directional factors of Eq. (14) counting only those faces (variant 4).

The grid is cell-centred: the body's cells, then ``layers`` rows of cells beyond each
clamped face, so the surface lies midway between the last body row and the first buffer
row (seed 003 Fig. 3). A scene imposes its clamp on the buffer nodes by elimination.
"""
from __future__ import annotations

import numpy as np

from ..errors import InputError
from ..pd import BoxGrid, Closure
from ..pd.problem import ClampedBox
from .energy_directional import directional_closure
from .protocols import ClampedGrid, Params


def buffered_grid(lower, upper, spacing: float, depth: float, axis: int):
    """``(grid, low, high)``: the cell-centred grid of the box ``[lower, upper]`` extended
    by ``depth`` beyond both faces normal to ``axis``, and the node numbers of the buffer
    layers below and above the box."""
    lower, upper = np.asarray(lower, dtype=float), np.asarray(upper, dtype=float)
    lengths, origin = upper - lower, lower.copy()
    lengths[axis] += 2 * depth
    origin[axis] -= depth
    grid = BoxGrid(tuple(lengths), tuple(origin), spacing)
    c = grid.x[:, axis]
    return grid, np.flatnonzero(c < lower[axis]), np.flatnonzero(c > upper[axis])


def virtual_nodes_closure(grid, lower, upper, horizon: float, influence, axis: int,
                          correct_sides: bool) -> Closure:
    """The uncorrected closure of the buffered grid, or (``correct_sides``) the
    directional factors with only the faces not normal to ``axis`` counted."""
    if not correct_sides:
        return Closure()
    sides = tuple(k for k in range(grid.dim) if k != axis)
    return directional_closure(grid, lower, upper, horizon, influence, axes=sides)


def clamp(problem: ClampedBox, params: Params) -> ClampedGrid:
    """The ``clamped-sheet`` role: ``(grid, closure, low, high)`` of a
    :class:`~pdverify.pd.problem.ClampedBox` under virtual nodes (the clamps act on the
    buffer layers)."""
    grid, low, high = buffered_grid(problem.lower, problem.upper, problem.spacing,
                                    problem.horizon, problem.axis)
    closure = virtual_nodes_closure(grid, problem.lower, problem.upper, problem.horizon,
                                    problem.influence, problem.axis, params["correct_sides"])
    return ClampedGrid(grid, closure, low, high)


def check_layers(_context, params: Params, where: str) -> None:
    """Buffer layers of thickness delta must be whole numbers of cells."""
    if abs(params["m_ratio"] - round(params["m_ratio"])) > 1e-12:
        raise InputError(f"{where}: m_ratio={params['m_ratio']:g} must be a whole number for "
                         "virtual-nodes (buffer layers of thickness delta)")
