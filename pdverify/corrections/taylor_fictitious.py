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

from ..pd.bonds import unique_ids
from ..pd.closure import Closure, real_identity, with_rows
from ..pd.problem import Face, LinearSystem, box_faces
from .assembly import boundary_nodes, model_of, shape_counts, unknown_coords
from .shape_fictitious import condition_rows, normal_closure
from .surface_nodes import crossing_bonds
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


def boundary_lines(grid, face: Face | str) -> np.ndarray:
    """Integer indices (n_lines, dim) of the real nodes nearest ``face`` (a
    :class:`~pdverify.pd.faces.Face` or its name): the anchor of each line
    perpendicular to it."""
    face = Face.named(face)
    real = grid.index[grid.interior_ids]
    return real[real[:, face.axis] == grid.boundary_layer(face)]


def boundary_value_rows(grid, order: int, face: Face | str) -> tuple[sp.csr_matrix, np.ndarray]:
    """Rows R (one per line perpendicular to ``face``) with R @ u_real = u at the boundary
    point of the line, by the 1D Taylor extrapolation of Eq. (58) from the ``order + 1``
    real nodes of the line nearest the face (the same rows serve every component,
    Remark 4). Returns ``(R, anchors)``, ``anchors`` the lines' boundary-node indices."""
    _check_size(grid, order)
    anchors = boundary_lines(grid, face)
    face = Face.named(face)
    axis = face.axis
    inward = 1 if face.side == 0 else -1
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
    """Constraint rows of clamped ``faces`` (their names): the displacement at the boundary point of every
    line perpendicular to a face, by the Taylor extrapolation of Eq. (58), for every
    component (Remark 4), the corner lines by the rule ``corners`` (:data:`CORNER_RULES`).

    Returns ``(B, points, components)``: B (n_constraints x dim * n_real, component-major)
    with (B u)_r = u_{components[r]}(points[r]) for fields of degree <= ``order``.
    """
    if corners not in CORNER_RULES:
        raise ValueError(f"corners={corners!r}; allowed: {', '.join(CORNER_RULES)}")
    faces = sorted({Face.named(name) for name in faces}, key=lambda f: f.code)
    n, d = grid.n_interior, grid.dim
    blocks, points, comps = [], [], []
    for face in faces:
        axis = face.axis
        R, anchors = boundary_value_rows(grid, order, face)
        x = grid.x[grid.ext_id(anchors)]
        x[:, axis] = grid.face_coordinate(face)
        for k in range(d):
            at_corner = np.zeros(anchors.shape[0], dtype=bool)
            for other in faces:
                if corners == "normal-only" and yields_component(axis, other.axis, k):
                    at_corner |= anchors[:, other.axis] == grid.boundary_layer(other)
            keep = np.flatnonzero(~at_corner)
            Rk = sp.coo_matrix(R[keep])
            blocks.append(sp.csr_matrix((Rk.data, (Rk.row, Rk.col + k * n)),
                                        shape=(keep.size, d * n)))
            points.append(x[keep])
            comps.append(np.full(keep.size, k))
    return sp.vstack(blocks).tocsr(), np.concatenate(points), np.concatenate(comps)


# ------------------------------------------------------------------------------ static assembly
def assemble_taylor(problem, order: int, corners: str = "normal-only") -> LinearSystem:
    """Seed 000's Taylor-extrapolated fictitious nodes with the conditions as constraint
    rows by Lagrange multipliers (Eq. 63) on a ``static-state`` problem. A prescribed component takes the
    rows of Eq. (58) on the lines of its face (``where``: on part of them); every other
    component of a face with a traction, or of a free face, takes the force flux rows:
    in 1D the bonds crossing the end plane (Eq. 60), in 2D/3D the face-crossing bonds of
    each boundary cell face weighted by alpha (seed 001 Eq. 35, the same rule as the
    surface nodes' flux). Where two faces that both prescribe a component k on their
    whole face meet, the line through the corner node perpendicular to each face would
    constrain k twice at the same corner; ``corners`` (Remark 4, ``CORNER_RULES``):
    ``normal-only`` keeps on such a line only the row of the component normal to its
    face (the tangential one is imposed by the other face's line), ``both`` keeps every
    row (the system is then singular: the over-constraint Remark 4 avoids). On faces
    prescribing different components (seed 001's plate) the rule changes nothing.

    3D (our extension; seed 000 is 1D/2D). Two findings of issue 30, each fixed at its
    cause. (1) The near-singular Lagrange system of the 3D boxes came from the flux
    rows, not from the corner rule: at an edge cell whose two faces both take flux rows,
    face a's row of component b and face b's row of component a are the shear force of
    one cell on its two faces (sigma_ab = sigma_ba), near-dependent rows, one direction
    per body edge; on the 8 x 6 x 6-cell box one combination was exactly dependent, on
    the quick 10 x 5 x 5 grid B was square and 20 rows short of full rank. One row of
    each pair is dropped (:func:`_shear_pair_lines`). (2) The corner rule handled pairs
    of faces only: on a box clamped all round, the component along an edge (tangential
    to both faces) was imposed on neither line; it now goes to the face of the lower axis
    (:func:`yields_component`). Both are pinned
    in tests/treatments/test_taylor_3d.py. What remains: B's smallest singular values
    (rows scaled to unit 1-norm) are still ~1e-4 at h = 0.1 (condition estimates 1e7 to
    1e10); on body3d-manufactured's cubic field order 1 gives 30 / 18 / 13 % at
    h = 1/12, 1/16, 1/20 (surface nodes N = 1: 1.9 % at 1/20), order 2 0.54 / 0.22 /
    0.105 % (surface nodes N = 2: 0.32 %); why order 1 is that far off is not yet
    investigated. body3d-manufactured's quick grid
    (10 x 5 x 5) keeps 2 dependent rows and fails as near-singular.

    A body that is not a box (``problem.shape``): :func:`_taylor_on_shape`."""
    if problem.shape is not None:
        return _taylor_on_shape(problem, order)
    g = problem.body.grid(problem.stencil.reach)
    d = g.dim
    # a face that prescribes every component on its whole face needs no flux rows; a box
    # clamped all round (seed 000's plate) then needs neither them nor the face-crossing
    # fictitious bonds, which enter no real node's equation
    clamped = all(c.where is None and len(c.prescribed) == d
                  for c in (problem.conditions.get(f.name) for f in box_faces(d))
                  if c is not None)
    clamped &= len(problem.conditions) == 2 * d
    if d == 1 or clamped:
        closure = fictitious_closure(g, order)
        flux = None
    else:
        keep, flux = crossing_bonds(g, problem.stencil)
        base = fictitious_closure(g, order)
        closure = Closure(keep=keep, weighted_volume="complete",
                          displacement_map=base.displacement_map,
                          dilatation_map=base.dilatation_map)
    model = model_of(problem, g, closure)
    ni = g.n_interior
    P = model.equilibrium_rows()
    x_int = g.x[g.interior_ids]
    rhs = problem.body_load(x_int, model.node_volume[g.interior_ids][:, None]).T.ravel()
    K_b = model.bond_force_matrix() if d == 1 else None
    # the constraint rows act on the augmented system's unknowns: the real displacements
    # and the real dilatations (the solver layer eliminates the latter for a direct LU)
    width = (d + 1) * ni
    rows, vals = [], []
    if flux is not None:   # force of each boundary cell face from the unknowns
        Fs = _flux_of_unknowns(model, flux, g.n_surface)
    for face in box_faces(d):
        axis = face.axis
        cond = problem.conditions.get(face.name)
        R, anchors = boundary_value_rows(g, order, face)
        xb = g.x[g.ext_id(anchors)]
        xb[:, axis] = g.face_coordinate(face)
        exact = problem.exact(xb)
        cells_face = anchors
        if d > 1:
            sel = np.flatnonzero(g.surface_on(face))
            cells_s = g.surface_cell[sel]
            nrm = g.surface_normal[sel]
            load = (problem.face_forces(face, g.surface_x[sel], nrm, g.face_area)
                    if cond is not None and cond.traction is not None
                    else np.zeros((sel.size, d)))
            # surface cells and anchors enumerate the same boundary cells: match them
            order_s = _match(cells_s, cells_face, axis, g)
        for k in range(d):
            pres = np.zeros(anchors.shape[0], dtype=bool)
            if cond is not None and k in cond.prescribed:
                pres[:] = True if cond.where is None else cond.where(cells_face)
            imposed = pres.copy()
            if corners == "normal-only" and k != axis:
                imposed &= ~_corner_lines(problem, g, anchors, axis, k)
            if np.any(imposed):
                Rk = sp.coo_matrix(R[np.flatnonzero(imposed)])
                rows.append(sp.csr_matrix((Rk.data, (Rk.row, Rk.col + k * ni)),
                                          shape=(int(imposed.sum()), width)))
                vals.append(exact[imposed, k])
            free = np.flatnonzero(~pres & ~_shear_pair_lines(problem, g, anchors, axis, k))
            if free.size == 0:
                continue
            if d == 1:
                sec = model.crossing_selector([g.face_coordinate(face)]) @ K_b
                # tension positive through the plane; the force on the body at the
                # face is the outward traction: + at x+, - at x-
                rows.append(sp.hstack([sp.csr_matrix(sec), sp.csr_matrix((1, width - sec.shape[1]))],
                                      format="csr"))
                t = (cond.traction(xb, np.array([[face.sign]]))[0, 0]
                     if cond is not None and cond.traction is not None else 0.0)
                vals.append(np.array([face.sign * t * g.face_area
                                      * problem.thickness]))
            else:
                idx = sel[order_s[free]]
                rows.append(Fs[k * g.n_surface + idx])
                vals.append(load[order_s[free], k])
    B = sp.vstack(rows).tocsr()
    c = np.concatenate(vals)

    def reaction(x, face):
        if d != 1:
            raise ValueError("the Taylor reaction is defined for 1D bars only")
        plane = g.face_coordinate(Face.named(face))
        return float((model.crossing_selector([plane]) @ K_b @ x[:ni])[0])
    counts = {"fictitious_nodes": int(g.n_ext - g.n_interior), "constraints": int(B.shape[0])}
    none = np.zeros(0, dtype=int), np.zeros(0)
    # the augmented system, the constraint rows beside it: the solver layer forms what its
    # solver needs (pdverify.solvers.front.solve_augmented: for nested dissection the
    # bordered system, whose separators are half as thick as those of K's Lagrange system,
    # 3x faster on the seed-001 plate (record solvers-2026-11-28-bordered), with the
    # multipliers of rows on the dilatations (3D) kept sparse)
    A = model.augmented_stiffness(P)
    return LinearSystem(model, A, np.r_[rhs, np.zeros(A.shape[0] - rhs.size)], *none, ni,
                        B=B, c=c, solver=problem.solver, coords=unknown_coords(model, x_int),
                        scalars=A.shape[0] - rhs.size, reaction=reaction, counts=counts)


def _taylor_on_shape(problem, order: int) -> LinearSystem:
    """Taylor's fictitious nodes along the local normal of a shape, the conditions as
    constraint rows by Lagrange multipliers (``corrections.shape_fictitious``)."""
    g = problem.body.grid(problem.stencil.reach)
    # the fictitious layer completes the lattice: every real node keeps its whole cell
    # (a cut cell's outside part is the fictitious nodes'), so that an affine field, or
    # a quadratic one on an isotropic stencil, is a solution as on the box
    g.node_volume[g.interior_ids] = g.volume
    closure = normal_closure(g, problem.shape, order, problem.stencil)
    model = model_of(problem, g, closure)
    ni = g.n_interior
    x_int = g.x[g.interior_ids]
    rhs = problem.body_load(x_int, model.node_volume[g.interior_ids][:, None]).T.ravel()
    B, c, points = condition_rows(model, problem, order, boundary_nodes(g, problem.shape))
    if B.shape[0] > B.shape[1]:
        # more condition rows than displacement unknowns: the bordered system is singular
        # (the 3D shapes' quick grids: 390 rows on 312 unknowns on the quarter cylinder
        # at h = 1/8); named here rather than as SuperLU's factorisation failure
        from ..errors import NumericalError
        raise NumericalError(f"{B.shape[0]} condition rows at {points} boundary points on "
                             f"{B.shape[1]} displacement unknowns: the grid is too coarse "
                             f"for the shape's boundary (refine spacing)")
    counts = shape_counts(g, fictitious_nodes=int(np.sum(g.kind == 1)),
                           constraints=int(B.shape[0]), boundary_points=int(points),
                           bridging_bonds=closure.info["bridging_bonds"])
    none = np.zeros(0, dtype=int), np.zeros(0)
    if any(c.length for c in getattr(problem.shape, "cracks", ())):
        # a cracked plate (issue 54): the augmented system under the problem's solver, as
        # on the box (nested dissection from the unknowns' coordinates); the form below
        # took plate-crack at h = 1/40 (19 200 nodes) 156-262 s and 2.3-2.8 GB (orders 2,
        # 1, under load ~10), past the crack scenes' budget
        A = model.augmented_stiffness(model.equilibrium_rows())
        B = sp.hstack([B, sp.csr_matrix((B.shape[0], A.shape[0] - B.shape[1]))]).tocsr()
        return LinearSystem(model, A, np.r_[rhs, np.zeros(A.shape[0] - rhs.size)], *none,
                            ni, B=B, c=c, solver=problem.solver,
                            coords=unknown_coords(model, x_int),
                            scalars=A.shape[0] - rhs.size, counts=counts)
    # COLAMD: on the hole plate's bordered system SuperLU factors 4-6x faster than with
    # the scenes' minimum degree on A + A^T, whose fill the zero block of the multipliers
    # defeats (record plate_solvers-2026-11-26-hole-plate-bordered)
    return LinearSystem(model, model.stiffness(model.equilibrium_rows()), rhs, *none, ni,
                        B=B, c=c, counts=counts, ordering="COLAMD")


def _bond_forces(model, bonds=None):
    """Scalar bond forces (times beta V_a V_b) as a matrix on the augmented system's
    unknowns (displacements, then the real dilatations), the flux rows' factor: in 3D
    [K_e A_e A_U, K_theta A_Theta], each block within
    one horizon, which (with the mu unknowns of assemble_taylor) takes body3d-traction at
    h = 0.05 from 5.3 GB to 2.1 GB (record taylor3d-2026-11-24-bond-forces); in 2D the
    bond forces of the displacements beside zero dilatation columns, as before: there the
    one-horizon form raised the plane-strain plate's condition estimate at h = 0.0125 from
    2.1e5 to 6.8e9 and moved its errors by 3e-7 (relative). ``bonds``: only these rows
    (ascending; the flux rows need the face-crossing bonds only)."""
    ni = model.A_theta.shape[0]
    rows = model.bond_a.size if bonds is None else len(bonds)
    if model.dim != 3:
        return sp.hstack([model.bond_force_matrix(bonds), sp.csr_matrix((rows, ni))])
    e = (model.A_e @ model.A_U_full).tocsr()
    K_e, K_theta = ((model.K_e, model.K_theta) if bonds is None
                    else (sp.csr_matrix(model.K_e)[bonds], sp.csr_matrix(model.K_theta)[bonds]))
    return sp.hstack([K_e @ e, K_theta @ model.A_Theta]).tocsr()


def _corner_lines(problem, g, anchors, axis, k):
    """Which of the lines of a face (``anchors``, normal ``axis``) run through a corner
    (or, in 3D, edge) node shared with another face prescribing component ``k`` on its
    whole face that takes ``k`` over (:func:`yields_component`)."""
    out = np.zeros(anchors.shape[0], dtype=bool)
    for other in box_faces(g.dim):
        cond = problem.conditions.get(other.name)
        if (yields_component(axis, other.axis, k) and cond is not None
                and cond.where is None and k in cond.prescribed):
            out |= anchors[:, other.axis] == g.boundary_layer(other)
    return out


def _shear_pair_lines(problem, g, anchors, axis, k):
    """Which lines of a face (``anchors``, normal ``axis``) give up their flux row of the
    tangential component ``k`` (3D only): those through an edge cell whose face on axis k
    has a flux row of component ``axis`` too, when ``axis > k``. The two rows are the
    shear force of one edge cell on its two faces, sigma_{axis k} and sigma_{k axis}:
    equal in the continuum, near-equal on the lattice, so imposing both makes the
    constraint rows (near-)dependent, one direction per body edge (measured on 10 x 7 x 7
    cells at m = 3: the smallest singular values of the row-normalised B 7e-7 ... 8e-6,
    concentrated on the edge cells' rows, 1e-4 with one row of each pair dropped;
    on the quick 10 x 5 x 5 grid B was square and 20 rows short of full rank, full rank
    without them). The row of the face with the lower axis is kept (either serves: a
    field meeting the kept row meets the dropped one to the lattice error). In 2D the
    corner cells hold the same pair; kept there, the published 2D runs unchanged."""
    out = np.zeros(anchors.shape[0], dtype=bool)
    if g.dim != 3 or k == axis or axis < k:
        return out
    for other in (Face.at(k, 0), Face.at(k, 1)):
        cond = problem.conditions.get(other.name)
        edge = anchors[:, k] == g.boundary_layer(other)
        if cond is not None and axis in cond.prescribed:
            edge &= ~(np.ones_like(edge) if cond.where is None else cond.where(anchors))
        out |= edge
    return out


def _flux_of_unknowns(model, flux, n_surface):
    """The force of each boundary cell face from the unknowns: :func:`_surface_flux`
    times :func:`_bond_forces`, the latter of the face-crossing bonds only (the other
    columns of the flux rows are zero; the same products, row by row)."""
    used = unique_ids(flux[1])
    return (_surface_flux(model, flux, n_surface)[:, used]
            @ _bond_forces(model, used)).tocsr()


def _surface_flux(model, flux, n_surface):
    """Rows (d n_surface x bonds): the force of the face-crossing bonds of every boundary
    cell face, component-major (sum alpha f_b sign n_b)."""
    s, bond, alpha, sign = flux
    d = model.dim
    w = alpha * sign
    rows = np.concatenate([k * n_surface + s for k in range(d)])
    cols = np.tile(bond, d)
    vals = np.concatenate([w * model.bond_n[bond, k] for k in range(d)])
    return sp.csr_matrix((vals, (rows, cols)), shape=(d * n_surface, model.bond_a.size))


def _match(cells_s, anchors, axis, g):
    """Positions in ``cells_s`` (surface cells of a face) of each anchor's cell."""
    key_s = np.ravel_multi_index(tuple(np.delete(cells_s, axis, axis=1).T),
                                 tuple(np.delete(np.asarray(g.cells), axis)))
    key_a = np.ravel_multi_index(tuple(np.delete(anchors, axis, axis=1).T),
                                 tuple(np.delete(np.asarray(g.cells), axis)))
    pos = np.argsort(key_s)
    return pos[np.searchsorted(key_s[pos], key_a)]
