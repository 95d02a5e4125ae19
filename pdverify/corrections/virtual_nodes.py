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
from ..pd.faces import Face, face_names
from ..pd.problem import BondProblem, ClampedBox
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


def held_face(problem: BondProblem, params: Params) -> BondProblem:
    """The ``held-face`` role (our extension of §4.1.2 to a body held on some faces, e.g.
    the indentation block's bottom): the body extended by whole rows of thickness delta
    beyond every face its description holds in every component at a constant value,
    those rows held as the face is (the buffer, rigid at the clamp's displacement, as
    seed 003's buffer layers). The body keeps its layout: on a body whose nodes lie on
    its surface (``on-surface``) the held face's own row stays held and becomes a row of
    whole cells, the buffer's rows beyond it at the same spacing, so every node within
    delta of the face has a complete neighbourhood; the other faces stay as they are
    (variant 2 of Table 2; no side correction). A face whose prescribed value varies, or
    that prescribes some components only, has no rigid buffer: refused (a scene states
    which faces it holds)."""
    from dataclasses import replace as _replace
    body = problem.body
    d = len(body.lengths)
    h = body.spacing
    rows = int(round(problem.horizon / h))
    if abs(rows * h - problem.horizon) > 1e-9 * h:
        raise ValueError(f"the buffer of thickness delta = {problem.horizon:g} is not a "
                         f"whole number of rows of {h:g}")
    lengths, origin = list(body.lengths), list(body.origin)
    conditions, parts = dict(problem.conditions), dict(problem.parts)
    held = []
    for name, cond in problem.conditions.items():
        if name not in face_names(d) or len(cond.prescribed) != d or cond.force is not None:
            continue
        face = Face.named(name)
        lo, hi = origin[face.axis], origin[face.axis] + lengths[face.axis]
        bound = hi if face.side else lo
        beyond = (lambda x, a=face.axis, b=bound, s=face.sign:
                  s * (x[:, a] - b) > 1e-9 * h)
        lengths[face.axis] += rows * h
        if not face.side:
            origin[face.axis] -= rows * h
        conditions[f"{name}-buffer"] = cond
        parts[f"{name}-buffer"] = beyond
        held.append(name)
    if not held:
        raise ValueError("no face held in every component: nothing to buffer")
    if body.placement != "on-surface":
        raise ValueError("the held-face buffer is laid out for on-surface bodies")
    # the held face's own nodes keep their name: those on the original face coordinate
    for name in held:
        face = Face.named(name)
        coord = (body.origin[face.axis] + body.lengths[face.axis] if face.side
                 else body.origin[face.axis])
        parts[f"{name}-row"] = (lambda x, a=face.axis, c=coord:
                                np.abs(x[:, a] - c) <= 1e-9 * h)
        conditions[f"{name}-row"] = conditions.pop(name)
    return _replace(problem, body=_replace(body, lengths=tuple(lengths), origin=tuple(origin)),
                    conditions=conditions, parts=parts,
                    supports=problem.supports + f"; virtual nodes: {rows} rows of thickness "
                             f"delta beyond {', '.join(held)}, held as the face is")
