"""Taylor-based fictitious nodes, nearest-node strategy (seed 000 §3-4 in 1D, §6.1 in 2D).

One construction serves every dimension of a box grid whose fictitious layer surrounds the
real nodes:

- the nearest real node j of a fictitious node i is its index clipped into the body
  (seed 000 §6.1: the nearest-node strategy; all such j are boundary nodes);
- when i lies outside the body along one axis only (the edges in 2D, the two ends in 1D),
  i and j lie on one line perpendicular to the boundary and the 1D Taylor series of
  order n about j is used, its derivatives from the n + 1 real nodes of that line nearest
  the boundary (Eqs. 42-45; the same matrices for every displacement component);
- when i lies outside along k >= 2 axes (the corner regions), the k-dimensional Taylor
  series about the corner node j (Eq. 69, generalised from n = 2 to any order n) with its
  derivatives by finite differences on the principal lattice
  {j + s : s_a >= 0 inwards, s_1 + ... + s_k <= n} in the plane of those axes: the
  classical one-sided difference formulae (for n = 2: u_xx from three nodes along x,
  u_xy = u(1,1) - u(1,0) - u(0,1) + u(0,0), ...). That set is unisolvent for the
  polynomials of degree <= n, so the extrapolation reproduces them exactly.

Dilatations are extrapolated in the same way with order n - 1 (Eq. 47; order 0 copies
the nearest real node's value).
"""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from ..pd.closure import Closure, real_identity, with_rows
from .taylor import extrapolation_rows, monomial_exponents, taylor_extrapolation_weights, taylor_weights


def needed_nodes(order: int) -> int:
    """Real nodes an order-``order`` extrapolation needs along every axis (n + 1)."""
    return order + 1


def _check_size(grid, order: int):
    short = [a for a, n in enumerate(grid.nodes_per_axis) if n < needed_nodes(order)]
    if short:
        raise ValueError(f"Taylor order {order} needs {needed_nodes(order)} real nodes along "
                         f"every axis; axis {short[0]} has {grid.nodes_per_axis[short[0]]}")


def extrapolation_map(grid, order: int) -> sp.csr_matrix:
    """n_ext x n_real map: identity on the real nodes, the Taylor extrapolation of order
    ``order`` (see the module docstring) on every fictitious node."""
    _check_size(grid, order)
    base = real_identity(grid)
    fict = np.flatnonzero(~grid.is_interior)
    if fict.size == 0:
        return base
    n_axis = np.asarray(grid.nodes_per_axis)
    idx = grid.index[fict]
    near = np.clip(idx, 0, n_axis - 1)
    rel = idx - near                                   # nonzero on the axes it lies outside
    pattern = np.sign(rel)
    out = base
    for p in np.unique(pattern, axis=0):               # one pass per edge / corner region
        sel = np.all(pattern == p, axis=1)
        axes = np.flatnonzero(p)
        steps = monomial_exponents(axes.size, order)   # the lattice s, |s| = 1 .. n
        src = np.zeros((steps.shape[0], grid.dim), dtype=int)
        src[:, axes] = -p[axes] * steps                # inwards
        centre = near[sel]
        tgt_rel = rel[sel][:, axes].astype(float)
        if steps.shape[0] == 0:                        # order 0: copy the nearest node
            W = np.zeros((centre.shape[0], 0))
        else:
            W = taylor_weights(src[None][..., axes].astype(float), tgt_rel,
                               np.zeros(centre.shape[0], dtype=int), order)
        src_ids = grid.interior_number[grid.ext_id(centre[:, None, :] + src[None])]
        centre_ids = grid.interior_number[grid.ext_id(centre)]
        block = extrapolation_rows(centre.shape[0], grid.n_interior, W, src_ids, centre_ids)
        out = with_rows(out, fict[sel], block)
    return out


def fictitious_closure(grid, order: int) -> Closure:
    """The closure of ``taylor-fictitious`` on a grid whose fictitious layer surrounds the
    body: displacements of order n, dilatations of order n - 1 (Eqs. 45, 47, 69), m of a
    complete neighbourhood at every node (m = A delta^3 at integer m-ratio in 1D; ERRATA).
    Bonds: every stencil pair with a real end (fictitious nodes enter only through the
    real nodes' neighbourhoods)."""
    return Closure(weighted_volume="complete", displacement_map=extrapolation_map(grid, order),
                   dilatation_map=extrapolation_map(grid, order - 1))


def boundary_lines(grid, face: int) -> np.ndarray:
    """Integer indices (n_lines, dim) of the real nodes nearest ``face`` (= 2 axis + side):
    the anchor of each line perpendicular to that face."""
    real = grid.index[grid.interior_ids]
    return real[real[:, face // 2] == grid.boundary_layer(face)]


def boundary_value_rows(grid, order: int, face: int) -> tuple[sp.csr_matrix, np.ndarray]:
    """Rows R (one per line perpendicular to ``face``) with R @ u_real = u at the boundary
    point of the line, by the 1D Taylor extrapolation of Eq. (58) from the ``order + 1``
    real nodes of the line nearest the face (the same rows serve every component,
    Remark 4). Returns ``(R, anchors)``, ``anchors`` the lines' boundary-node indices."""
    _check_size(grid, order)
    axis, side = divmod(face, 2)
    anchors = boundary_lines(grid, face)
    inward = 1 if side == 0 else -1
    x_anchor = grid.x[grid.ext_id(anchors[:1]), axis][0]
    target = (grid.face_coordinate(face) - x_anchor) / grid.spacing   # in spacings
    s = np.arange(order + 1)
    w = taylor_extrapolation_weights(s * inward, [target], order, anchor=0.0, scale=1.0)[0]
    nodes = anchors[:, None, :] + np.outer(s * inward, np.eye(grid.dim, dtype=int)[axis])[None]
    cols = grid.interior_number[grid.ext_id(nodes)]
    rows = np.repeat(np.arange(anchors.shape[0]), s.size)
    R = sp.csr_matrix((np.tile(w, anchors.shape[0]), (rows, cols.ravel())),
                      shape=(anchors.shape[0], grid.n_interior))
    return R, anchors


#: Which lines carry which components where two clamped faces meet (Remark 4):
#: ``normal-only`` = on a line through a corner node only the component normal to the
#: line's face is constrained (the paper's suggestion), ``both`` = every component on every
#: line (the corner node's two lines then both fix both components).
CORNER_RULES = ("normal-only", "both")


def yields_component(axis: int, other_axis: int, k: int) -> bool:
    """Whether, under ``normal-only``, a line of a face with normal ``axis`` through a
    node it shares with a face of normal ``other_axis`` (both prescribing component
    ``k`` on their whole face) leaves ``k`` to the other face's line: when ``k`` is the
    other face's normal component (Remark 4's rule for two faces), or, in 3D, when ``k``
    is tangential to both faces and the other face has the lower axis. Without that
    second case the component along a 3D box edge (u_z where x- and y- meet) was on
    neither line: not imposed there at all (the system stays regular; the edge nodes'
    equilibrium set it), where every other boundary node has each component imposed on
    exactly one line."""
    return k != axis and (other_axis == k or (other_axis != axis and other_axis < axis))


def clamped_rows(grid, order: int, faces, corners: str = "normal-only"):
    """Constraint rows of clamped ``faces``: the displacement at the boundary point of every
    line perpendicular to a face, by the Taylor extrapolation of Eq. (58), for every
    component (Remark 4), the corner lines by the rule ``corners`` (:data:`CORNER_RULES`).

    Returns ``(B, points, components)``: B (n_constraints x dim * n_real, component-major)
    with (B u)_r = u_{components[r]}(points[r]) for fields of degree <= ``order``.
    """
    if corners not in CORNER_RULES:
        raise ValueError(f"corners={corners!r}; allowed: {', '.join(CORNER_RULES)}")
    faces = sorted(set(faces))
    n, d = grid.n_interior, grid.dim
    blocks, points, comps = [], [], []
    for face in faces:
        axis = face // 2
        R, anchors = boundary_value_rows(grid, order, face)
        x = grid.x[grid.ext_id(anchors)]
        x[:, axis] = grid.face_coordinate(face)
        for k in range(d):
            at_corner = np.zeros(anchors.shape[0], dtype=bool)
            for other in faces:
                if corners == "normal-only" and yields_component(axis, other // 2, k):
                    at_corner |= anchors[:, other // 2] == grid.boundary_layer(other)
            keep = np.flatnonzero(~at_corner)
            Rk = sp.coo_matrix(R[keep])
            blocks.append(sp.csr_matrix((Rk.data, (Rk.row, Rk.col + k * n)),
                                        shape=(keep.size, d * n)))
            points.append(x[keep])
            comps.append(np.full(keep.size, k))
    return sp.vstack(blocks).tocsr(), np.concatenate(points), np.concatenate(comps)
