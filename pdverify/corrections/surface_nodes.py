"""Surface node method (seeds 001 §3, 002): surface-node unknowns, Taylor-extrapolated
fictitious layer about the nearest surface node, force-flux rows of face-crossing bonds."""
from __future__ import annotations

from itertools import product

import numpy as np
import scipy.sparse as sp

from ..errors import InputError
from ..pd.bonds import bond_pairs
from ..pd.closure import Closure, real_identity, with_rows
from ..pd.problem import LinearSystem, box_faces
from .assembly import eliminated, model_of
from .protocols import GridMap, Params
from .taylor import extrapolation_rows, taylor_weights, window_start

MAX_ORDER = 3


def displacement_stencils(grid, order: int):
    """Source nodes of the displacement extrapolation around every surface node (steps 7-12).

    Around surface node s on a face normal to axis a: the surface nodes of the same face
    and the interior nodes of the first ``order`` cell layers under it (order + 1 levels
    along the normal), over a tangential window of 2 ceil(order / 2) + 1 cells centred
    on s's cell, shifted inwards next to an edge. Returns ``(unknown ids (n_s, n_src),
    offsets from s in spacings (n_s, n_src, dim))``; unknowns number interior nodes
    first, then surface nodes.
    """
    d = grid.dim
    width = 2 * ((order + 1) // 2) + 1
    ids, rel = [], []
    for face, (axis, side, _shape) in enumerate(grid.faces):
        lo, hi = grid.face_start[face], grid.face_start[face + 1]
        cells = grid.surface_cell[lo:hi]
        tang = grid.tangential_axes(axis)
        if d == 1:  # no tangential axes: one source per level
            tcells = np.zeros((cells.shape[0], 1, 0), dtype=int)
        else:
            win = np.indices((width,) * (d - 1)).reshape(d - 1, -1).T  # (w^(d-1), d-1)
            start = np.stack([window_start(cells[:, t], width, grid.cells[t]) for t in tang],
                             axis=1)
            tcells = start[:, None, :] + win[None, :, :]            # (n, W, d-1)
        n, W = tcells.shape[:2]
        levels = []
        for level in range(order + 1):
            c = np.zeros((n, W, d), dtype=int)
            c[..., list(tang)] = tcells
            depth = max(level - 1, 0)
            c[..., axis] = depth if side == 0 else grid.cells[axis] - 1 - depth
            if level == 0:
                uid = grid.n_interior + grid.surface_id(face, c)
                pos = grid.origin + (c + 0.5) * grid.spacing
                pos[..., axis] = grid.surface_x[lo, axis]
            else:
                uid = grid.interior_number[grid.ext_id(c)]
                pos = grid.origin + (c + 0.5) * grid.spacing
            levels.append((uid, pos))
        uid = np.concatenate([u for u, _ in levels], axis=1)
        pos = np.concatenate([p for _, p in levels], axis=1)
        ids.append(uid)
        rel.append((pos - grid.surface_x[lo:hi, None, :]) / grid.spacing)
    return np.concatenate(ids), np.concatenate(rel)


def nearest_surface_node(grid, ext_ids) -> np.ndarray:
    """Surface node nearest to each node (step 7); ties go to the first face in the
    faces' order (x-, x+, y-, ...)."""
    idx = grid.index[ext_ids]
    X = 2 * idx + 1  # doubled coordinates: nodes odd, cell faces even (exact ties)
    best_d, best = None, None
    for face, (axis, side, _shape) in enumerate(grid.faces):
        cell = np.clip(idx, 0, np.asarray(grid.cells) - 1)
        cell[:, axis] = 0 if side == 0 else grid.cells[axis] - 1
        Y = 2 * cell + 1
        Y[:, axis] = 0 if side == 0 else 2 * grid.cells[axis]
        dist = np.sum((X - Y) ** 2, axis=1)
        sid = grid.surface_id(face, cell)
        if best is None:
            best_d, best = dist, sid
        else:
            better = dist < best_d
            best_d = np.where(better, dist, best_d)
            best = np.where(better, sid, best)
    return best


def displacement_extrapolation(grid, order: int, fict_ids) -> sp.csr_matrix:
    """Rows (one per node in ``fict_ids``) of u_f in terms of interior + surface unknowns."""
    n_unk = grid.n_interior + grid.n_surface
    src_ids, src_rel = displacement_stencils(grid, order)
    s = nearest_surface_node(grid, fict_ids)
    tgt_rel = (grid.x[fict_ids] - grid.surface_x[s]) / grid.spacing
    W = taylor_weights(src_rel, tgt_rel, s, order)  # per-surface-node fit, gathered
    centre = grid.n_interior + s
    return extrapolation_rows(fict_ids.size, n_unk, W, src_ids[s], centre)


def dilatation_extrapolation(grid, order: int, fict_ids) -> sp.csr_matrix:
    """Rows of theta_f in terms of interior dilatations, order - 1 (steps 1-6)."""
    n_int = grid.n_interior
    cells = np.asarray(grid.cells)
    b_idx = np.clip(grid.index[fict_ids], 0, cells - 1)  # nearest interior node (step 1)
    b = grid.interior_number[grid.ext_id(b_idx)]
    if order <= 1:  # theta_f = theta_b
        return sp.csr_matrix((np.ones(fict_ids.size), (np.arange(fict_ids.size), b)),
                             shape=(fict_ids.size, n_int))
    deg = order - 1
    width = 2 * ((deg + 1) // 2) + 1
    ub, first = np.unique(b, return_index=True)
    bidx = b_idx[first]
    win = np.indices((width,) * grid.dim).reshape(grid.dim, -1).T
    start = window_start(bidx, width, cells)
    c = start[:, None, :] + win[None, :, :]
    src_ids = grid.interior_number[grid.ext_id(c)]
    src_rel = (c - bidx[:, None, :]).astype(float)
    group = np.searchsorted(ub, b)
    tgt_rel = (grid.index[fict_ids] - b_idx).astype(float)
    W = taylor_weights(src_rel, tgt_rel, group, deg)
    return extrapolation_rows(fict_ids.size, n_int, W, src_ids[group], b)


# --------------------------------------------------------------------------- force flux
def face_crossings(grid, a, b):
    """Bonds a-b crossing a surface node's cell face (seed 001 §3.4, Eqs. 35-36, Fig. 7).

    Works in doubled integer coordinates (nodes odd, cell faces even), so a crossing that
    lies on a face edge or vertex is detected exactly. For each crossing returns the
    surface node, the bond, alpha (1 inside the face, 1/2 on an edge, 1/4 at a vertex:
    1/2 per tangential coordinate on a cell boundary) and a sign: +1 when ``a`` is the end
    inside the body's side of the face plane (so f_b along a->b is the force on the inner
    end, m . n > 0 in Eq. 35), -1 otherwise.
    """
    X_all = 2 * grid.index + 1
    Xa, Xb = X_all[a], X_all[b]
    out_s, out_b, out_alpha, out_sign = [], [], [], []
    bonds = np.arange(a.size)
    for face, (axis, side, _shape) in enumerate(grid.faces):
        P = 0 if side == 0 else 2 * grid.cells[axis]
        inner_a = Xa[:, axis] > P if side == 0 else Xa[:, axis] < P
        inner_b = Xb[:, axis] > P if side == 0 else Xb[:, axis] < P
        hit = inner_a != inner_b
        if not np.any(hit):
            continue
        ia, ib, bi = Xa[hit], Xb[hit], bonds[hit]
        a_in = inner_a[hit]
        Xin = np.where(a_in[:, None], ia, ib)
        Xout = np.where(a_in[:, None], ib, ia)
        D = Xout[:, axis] - Xin[:, axis]
        sgn = np.sign(D)
        D = D * sgn
        tang = grid.tangential_axes(axis)
        ok = np.ones(bi.size, dtype=bool)
        choices, on_edge = [], []
        for t in tang:
            num = (Xin[:, t] * (Xout[:, axis] - Xin[:, axis])
                   + (P - Xin[:, axis]) * (Xout[:, t] - Xin[:, t])) * sgn
            ok &= (num >= 0) & (num <= 2 * grid.cells[t] * D)
            edge = (num % (2 * D)) == 0
            q = num // (2 * D)
            choices.append((np.where(edge, q - 1, q), q))
            on_edge.append(edge)
        for combo in product((0, 1), repeat=len(tang)):
            valid = ok.copy()
            alpha = np.ones(bi.size)
            cell = np.zeros((bi.size, grid.dim), dtype=int)
            for k, t in enumerate(tang):
                c = choices[k][combo[k]]
                if combo[k] == 1:
                    valid &= on_edge[k]  # second choice exists only on an edge
                valid &= (c >= 0) & (c < grid.cells[t])
                alpha *= np.where(on_edge[k], 0.5, 1.0)
                cell[:, t] = np.clip(c, 0, grid.cells[t] - 1)
            if not np.any(valid):
                continue
            cell[:, axis] = 0 if side == 0 else grid.cells[axis] - 1
            out_s.append(grid.surface_id(face, cell[valid]))
            out_b.append(bi[valid])
            out_alpha.append(alpha[valid])
            out_sign.append(np.where(a_in[valid], 1.0, -1.0))
    if not out_s:
        z = np.zeros(0)
        return z.astype(int), z.astype(int), z, z
    return (np.concatenate(out_s), np.concatenate(out_b), np.concatenate(out_alpha),
            np.concatenate(out_sign))


# --------------------------------------------------------------------------- the closure
def crossing_bonds(grid, stencil):
    """``(keep, flux)``: the bonds of a fictitious-layer closure whose conditions act
    through face fluxes (every stencil pair with an interior end, plus the
    fictitious-fictitious pairs that cross a surface node's face: they enter Eq. 36), and
    the crossings ``(surface node, bond, alpha, sign)`` in that bond numbering."""
    a, b, _ = bond_pairs(grid.ext_shape, stencil.half_offsets)
    ia, ib = grid.is_interior[a], grid.is_interior[b]
    keep = ia | ib
    cand = np.flatnonzero(~(ia & ib))
    s, bond, alpha, sign = face_crossings(grid, a[cand], b[cand])
    keep[cand[bond]] = True
    new_index = np.cumsum(keep) - 1
    return keep, (s, new_index[cand[bond]], alpha, sign)


def surface_node_closure(grid, stencil, order: int, *, dilatations: bool = True):
    """The surface node method's :class:`~pdverify.pd.closure.Closure` and its flux data.

    Unknowns: the interior nodes, then one surface node per boundary cell face. The grid
    must carry a fictitious layer of ``stencil.reach`` nodes. Fictitious displacements by
    order-N Taylor extrapolation about the nearest surface node (seed 001 steps 7-12;
    seed 002 Eqs. 8-9 in 1D), dilatations (``dilatations=True``, state-based) by order
    N - 1 about the nearest interior node (steps 1-6), m of a complete neighbourhood at
    every node (§3.2). Bonds: every stencil pair with an interior end, plus the
    fictitious-fictitious pairs that cross a surface node's face (they enter Eq. 36).

    Returns ``(closure, flux)`` with ``flux = (surface node, bond, alpha, sign)`` in the
    model's bond numbering (see :func:`face_crossings`); :func:`flux_rows` turns it into
    the force-flux equations of Eq. (36).
    """
    keep, flux = crossing_bonds(grid, stencil)
    fict = np.flatnonzero(~grid.is_interior)
    A_Theta = real_identity(grid)
    if fict.size and dilatations:
        A_Theta = with_rows(A_Theta, fict, dilatation_extrapolation(grid, order, fict))
    closure = Closure(keep=keep, weighted_volume="complete",
                      displacement_map=surface_node_displacement_map(grid, order),
                      dilatation_map=A_Theta, n_unknown_nodes=grid.n_interior + grid.n_surface)
    return closure, flux


def surface_node_displacement_map(grid, order: int) -> sp.csr_matrix:
    """All node displacements from [interior nodes, surface nodes]: identity on the interior,
    order-N Taylor extrapolation about the nearest surface node on the fictitious layer."""
    A_U = real_identity(grid, grid.n_interior + grid.n_surface)
    fict = np.flatnonzero(~grid.is_interior)
    if fict.size:
        A_U = with_rows(A_U, fict, displacement_extrapolation(grid, order, fict))
    return A_U


def flux_rows(model, flux) -> sp.csr_matrix:
    """The force-flux equations (Eq. 36) of every surface node, as rows over bond forces:
    sum over crossing bonds of alpha f_b (m . n) with m the bond direction from the inner
    end (``sign``), placed after the interior equations of each component."""
    s, bond, alpha, sign = flux
    return model.bond_force_rows(model.grid.n_interior + s, bond, alpha * sign)


def wave_extension(_problem: None, params: Params) -> GridMap:
    """The ``wave-bar`` role: the fictitious layer's displacements from the real nodes and
    the two surface nodes, extrapolated about the nearest surface node at Taylor order
    ``params["order"]`` (seed 002 Eqs. 8-9 at order 1), as a function of the bar's grid."""
    order = params["order"]
    return lambda grid: surface_node_displacement_map(grid, order)


def check_wave_order(real_nodes, params: Params, where: str) -> None:
    """Each end's extrapolation stencil needs order + 1 real nodes of its own half."""
    order = params["order"]
    if 2 * (order + 1) > real_nodes:
        raise InputError(f"{where}: order={order} needs 2 (order + 1) <= "
                         f"{real_nodes} real nodes (order <= {real_nodes // 2 - 1})")


# ------------------------------------------------------------------------------ static assembly
def assemble_surface_nodes(problem, order: int) -> LinearSystem:
    """Seed 001's surface node method on a ``static-state`` problem: surface-node unknowns
    carry the conditions, the other surface-node equations are the force flux of Eq. (36)
    (:func:`impose_on_surface_nodes`). On a shape: :func:`surface_nodes_on_shape`."""
    if problem.shape is not None:
        return surface_nodes_on_shape(problem, order)
    g = problem.body.grid(problem.stencil.reach)
    closure, flux = surface_node_closure(g, problem.stencil, order)
    return impose_on_surface_nodes(problem, g, closure, flux)


def surface_node_model(problem, order: int):
    """``(model, P)`` of seed 001's surface node method on ``problem``'s box: the model
    with its fictitious layer and surface nodes, and its rows over the grid's state
    (:func:`surface_node_rows`), before any condition is imposed."""
    g = problem.body.grid(problem.stencil.reach)
    closure, flux = surface_node_closure(g, problem.stencil, order)
    return surface_node_rows(problem, g, closure, flux)


def surface_node_rows(problem, g, closure, flux):
    """``(model, P)``: the model of a surface-node closure on the grid ``g`` and its
    rows, the real nodes' equilibrium, then each surface node's force flux (``flux``,
    seed 001 Eq. 36)."""
    model = model_of(problem, g, closure)
    return model, (model.equilibrium_rows() + flux_rows(model, flux)).tocsr()


def impose_on_surface_nodes(problem, g, closure, flux) -> LinearSystem:
    """The system of a closure whose unknowns are the real nodes, then one surface node
    per boundary cell face (``closure.n_unknown_nodes``): a prescribed component is set
    on the surface nodes of its face (elimination), every other surface-node equation is
    its force flux (``flux``, seed 001 Eq. 36) equal to the face's load (zero on a free
    face). Shared by ``surface-nodes`` and any treatment that carries the conditions on
    surface nodes (a plugin's, e.g.)."""
    model, P = surface_node_rows(problem, g, closure, flux)
    d, ni, nu_ = g.dim, g.n_interior, model.n_unknown_nodes
    # in 3D the extrapolation rows are wide (order N: (N + 1)(2 ceil(N/2) + 1)^2 sources),
    # so the displacement map is multiplied in last; in 1D and 2D the products keep the
    # order the runs' numbers were made with (the gain there is small)
    K = model.augmented_stiffness(P, map_last=d == 3)
    x_int = g.x[g.interior_ids]
    rhs = np.zeros((nu_, d))
    rhs[:ni] = problem.body_load(x_int, model.node_volume[g.interior_ids][:, None])
    xs, nrm = g.surface_x, g.surface_normal
    for face, _ in problem.loaded():
        sel = g.surface_on(face)
        rhs[ni:][sel] = problem.face_forces(face, xs[sel], nrm[sel], g.face_area)
    us_ref = problem.exact(xs)
    fixed, values, by_face = [], [], {}
    for face, k, where in problem.prescribed():
        mask = g.surface_on(face)
        if where is not None:
            mask &= where(g.surface_cell)
        nodes = np.flatnonzero(mask)
        fixed.append(k * nu_ + ni + nodes)
        values.append(us_ref[nodes, k])
    for face in box_faces(d):
        by_face[face] = face.axis * nu_ + ni + np.flatnonzero(g.surface_on(face))
    return eliminated(problem, model, K, rhs, fixed, values, np.r_[x_int, xs], by_face,
                       extra_x=xs, counts={"surface_nodes": int(g.n_surface),
                                           "fictitious_nodes": int(g.n_ext - g.n_interior)})


# ------------------------------------------------------------------------------ on a shape
#: SuperLU's column ordering on a shape: COLAMD (measured under load at h = 0.025,
#: order 2: the hole plate's solve 2.3 s against 3.7 s under minimum degree on A + A^T,
#: the L-plate's the same; the errors agree to the printed digits)
ORDERING_ON_SHAPE = "COLAMD"


def surface_nodes_on_shape(problem, order: int) -> LinearSystem:
    """Seed 001's surface node method on a 2D or 3D shape (issue 55; our generalisation, say
    "seed 001 along the normal"):

    - surface nodes: one per (boundary node, part) pair, at the boundary point of the
      Taylor extension on shapes (``shape_fictitious.boundary_points``: the mean of the
      part's samples that belong to the node, moved onto the part; on a straight face
      of cell faces the centre of the node's boundary cell face, as seed 001's);
    - the fictitious layer (``ShapeGrid``'s, every real node keeping its whole cell as
      in the Taylor extension on shapes): each fictitious node takes the order-N Taylor
      series about the surface node nearest its closest boundary point, through that
      surface node's value, its derivatives fitted by least squares to the real nodes
      nearest it (``shape_fictitious.centred_fit``; seed 001 steps 7-12 take them along
      lattice lines normal to a face, which a curved part has not); dilatations of
      order N - 1 from the real ones about the closest point, m complete; a bond that
      bridges a re-entrant notch reads its own value about the surface node nearest the
      point its real end sees (``Closure.shadow``, as the Taylor extension);
    - conditions: a prescribed component is the surface node's (eliminated); every
      other component's equation is, on a straight part, the force flux of the bonds
      crossing the surface node's stretch of the part (seed 001 Eq. 36; on cell faces
      its box rows), equal to the traction's resultant over the stretch, and on an arc
      the traction of the series at the surface node, sigma(grad u) n = t, with the
      continuum moduli (the flux through a short stretch of an arc is a lattice
      quadrature whose error does not vanish: ``shape_fictitious``).

    - crack faces (issue 54; ``shape_fictitious``, crack faces): surface nodes on each
      face like any part; every bond the crack cuts becomes, from each end, a one-sided
      bond to a fictitious node at the other end's place (``Closure.ghosts``), the
      series about the nearest surface node of the end's own face fitted over the real
      nodes of the end's side only; the faces' rows (the fit's traction on a face at an
      angle to the lattice) from one-sided fits; beside an edge crack's mouth the
      fictitious nodes and the bonds across the crack's line from one side. At the tip
      as Taylor's: the fictitious nodes stop there, the bonds round it stay real.
      Exact for the order's polynomials on the crack geometries and one-sided
      (tests/shapes/test_crack_faces.py). The tips carry no surface node of their own:
      a tip is a face's end, its nearest surface nodes the faces' last ones.
    - pins (issue 54: the crack scenes' parts of length h/2 holding the rigid motions):
      a surface node that no fictitious value is extrapolated from and that no row of
      its own reads (on a straight edge the flux rows are over bond forces; its
      boundary node's fictitious nodes all take another part's nearer surface node)
      has a column in no equation, so its conditions are imposed on its partner, the
      nearest surface node that is read (:func:`unread_surface_nodes`; on the pins the
      same boundary node's point on the adjacent edge part, h/2 away): a component
      the pin prescribes is prescribed on the partner (the problem's exact value at
      the partner's point; the partner's own row of it dropped), a free component's
      flux row is added to the partner's (the flux through both stretches equal to the
      resultant over both), and the unread surface node's free components equal the
      partner's. Only systems with such a surface node change (none but the crack
      scenes' among the report's: the other shapes' surface-node runs are unchanged
      bit for bit).

    Exactness kept (tests/shapes/test_shape_methods.py): order N reproduces every
    polynomial field of degree <= N with its body force when the real nodes' complete
    neighbourhoods do (affine: any stencil; quadratic: the moment-corrected one), with
    every part prescribed, and under tractions where the lattice's moduli are the
    continuum's (the moment-corrected stencil), as the Taylor extension on shapes.

    On a 3D shape (``pdverify.pd.shapes3d``; our generalisation again) the same with
    3D fits (``shape_fictitious.neighbours``: 16, 40 and 100 real nodes for orders 1, 2,
    3; a rank-deficient fit is refused) and surface nodes at the boundary nodes' points
    on planes, the mantle and the sphere; every part not prescribing a component takes
    the series' traction row, planes included (seed 001's force flux through a 3D
    patch would need the bonds' crossings of planes, a mantle and a sphere, which
    ``Shape3D`` does not compute; on a plane of cell faces the flux row and the traction
    row agree for fields the lattice's moduli reproduce). Bridging bonds as in 2D
    (``Shape3D.hides``; ``mirror_nodes.MirrorNodesOnShape`` gives the count). Exactness
    kept on the
    quarter cylinder and the cavity octant (tests/shapes/test_shape3d_methods.py): order
    1 the affine field on partial volumes, order 2 the quadratic one with its body force
    on the moment-corrected stencil, ``x-`` prescribed and the rest under tractions
    (with traction rows everywhere the partial-volume stencil's moduli do not enter)."""
    from scipy.spatial import cKDTree

    from ..pd.closure import uncut
    from .assembly import boundary_nodes, shape_counts
    from ..pd.shapes import CrackFace
    from .shape_fictitious import (_rows, boundary_points, bridging, centred_fit,
                                   crossing_keep, cut_ends, face_side, fit, free_rows,
                                   prescribed, seen_points, stacked_rows, traction_rows_3d)
    g = problem.body.grid(problem.stencil.reach)
    g.node_volume[g.interior_ids] = g.volume      # as the Taylor extension on shapes
    shape, st = problem.shape, problem.stencil
    samples = boundary_nodes(g, shape)
    pts, nrm, part, _, group = boundary_points(g, shape, samples)
    ni, ns, h, d = g.n_interior, len(pts), g.spacing, g.dim
    nu_ = ni + ns
    x_real = g.x[g.interior_ids]
    tree = cKDTree(pts)

    def centred(xf, p, real_ids=None, surface_ids=None):
        """The series at ``xf`` about the surface node nearest p (among
        ``surface_ids``), fitted over the real nodes ``real_ids`` (default: all):
        ``(columns over the unknowns, weights)`` and the dilatations' ``(real
        columns, weights)`` about p."""
        real_ids = np.arange(ni) if real_ids is None else real_ids
        if surface_ids is None:
            s = tree.query(p)[1]
        else:
            s = surface_ids[cKDTree(pts[surface_ids]).query(p)[1]]
        cols, w = centred_fit(x_real[real_ids], pts[s], ni + s, xf, order, h)
        cols = np.c_[cols[:, :1], real_ids[cols[:, 1:]]]
        nodes, wt = fit(x_real[real_ids], p, xf, order - 1, h)
        return (cols, w), (real_ids[nodes], wt)

    reach = (g.layers + 3) * h

    def extension(xf, p, owners=None):
        """Rows of the fictitious values at ``xf`` about the surface node nearest p,
        over the unknowns, and of their dilatations about p over the real nodes;
        beside a crack (an edge crack's mouth) from the side of ``owners`` only
        (default: the nodes themselves; ``shape_fictitious.sided_fit``)."""
        (cols, w), (nodes, wt) = centred(xf, p)
        owners = xf if owners is None else owners
        for c in getattr(shape, "cracks", ()):
            if not c.length:
                continue
            q, _ = c.faces[0].closest(xf)
            near = np.linalg.norm(xf - q, axis=1) <= reach
            for face in c.faces:
                sel = np.flatnonzero(near & (c.side(owners) == face.plus))
                if sel.size:
                    (cols[sel], w[sel]), (nodes[sel], wt[sel]) = centred(
                        xf[sel], p[sel], *face_sets(face))
        return _rows(cols, w, len(xf), nu_), _rows(nodes, wt, len(xf), ni)

    def face_sets(face):
        """The real nodes and the surface nodes on a crack face's side (its own surface
        nodes included, the other face's not)."""
        k_own = shape.part_names.index(face.name)
        k_other = next(i for i, q in enumerate(shape.parts) if isinstance(q, type(face))
                       and q.a == face.b and q.b == face.a)
        allowed = (face_side(face, pts) | (part == k_own)) & (part != k_other)
        return np.flatnonzero(face_side(face, x_real)), np.flatnonzero(allowed)

    fict = np.flatnonzero(g.kind == 1)
    U, T = extension(g.x[fict], shape.closest(g.x[fict])[0])
    A_U = (real_identity(g, nu_) + _place(U, fict, g.n_ext)).tocsr()
    A_T = (real_identity(g) + _place(T, fict, g.n_ext)).tocsr()
    a, b, _ = bond_pairs(g.ext_shape, st.offsets[st.half])
    # 3D: the bonds with a real end (no fictitious-fictitious flux bonds; docstring)
    keep = (crossing_keep(g, shape, st) if d == 2
            else (g.is_interior[a] | g.is_interior[b]) & ~g.is_void[a] & ~g.is_void[b])
    pairs, real, far = bridging(g, shape, a, b, uncut(g, a, b, keep))
    shadow = None
    if pairs.size:
        p_seen = seen_points(g, shape, real, far)[0]
        across = np.zeros(pairs.size, dtype=bool)
        for c in getattr(shape, "cracks", ()):
            if c.length:     # past an edge crack's mouth: as shape_fictitious.shadow_rows
                q, _ = c.faces[0].closest(g.x[far])
                across |= ((np.linalg.norm(g.x[far] - q, axis=1) <= reach)
                           & (c.side(g.x[real]) != c.side(g.x[far])))
        p_seen[across] = shape.closest(g.x[far[across]])[0]
        shadow = (pairs, *extension(g.x[far], p_seen, g.x[real]))
    ghosts = None
    ends = cut_ends(g, shape, st, keep)
    if ends is not None:      # crack faces: one-sided bonds (shape_fictitious, crack faces)
        g_pairs, real_a, _, ghost, groups = ends
        rows_u, rows_t = [], []
        for face, sel in groups:
            real_ids, surf = face_sets(face)
            k_own = shape.part_names.index(face.name)
            surf = surf[part[surf] == k_own]
            p_face, _ = face.closest(g.x[ghost[sel]])
            (cols, w), (nodes, wt) = centred(g.x[ghost[sel]], p_face, real_ids, surf)
            rows_u.append((sel, cols, w))
            rows_t.append((sel, nodes, wt))
        ghosts = (g_pairs, real_a, stacked_rows(rows_u, g_pairs.size, nu_),
                  stacked_rows(rows_t, g_pairs.size, ni))
    closure = Closure(keep=keep, weighted_volume="complete", displacement_map=A_U,
                      dilatation_map=A_T, n_unknown_nodes=nu_, shadow=shadow, ghosts=ghosts)
    model = model_of(problem, g, closure)
    K = model.augmented_stiffness(model.equilibrium_rows())
    cols, _, grad = centred_fit(x_real, pts, ni + np.arange(ns), pts, order, h,
                                gradient=True)
    for k, q in enumerate(shape.parts):     # a crack face's points: from its side only
        on = np.flatnonzero(part == k)
        if isinstance(q, CrackFace) and on.size:
            side = np.flatnonzero(face_side(q, x_real))
            c_k, _, g_k = centred_fit(x_real[side], pts[on], ni + on, pts[on], order, h,
                                      gradient=True)
            cols[on], grad[on] = np.c_[c_k[:, :1], side[c_k[:, 1:]]], g_k
    extra = K.shape[1] - d * nu_
    body = problem.body_load(x_real, model.node_volume[g.interior_ids][:, None])
    points = (pts, nrm, part, group)
    free = (free_rows(model, problem, samples, points, cols, grad, nu_) if d == 2
            else traction_rows_3d(problem, points, cols, grad, nu_))

    def conditions(pres, partner=None):
        """The surface nodes' rows added to K and the right-hand side; with ``partner``
        (:func:`unread_surface_nodes`) an unread surface node's free rows join its
        partner's (their sum: the flux through both stretches equal to the resultant
        over both) and its own rows tie its free components to the partner's."""
        rows, rhs = [], np.zeros((nu_, d))
        rhs[:ni] = body
        for k, blocks in enumerate(free):
            for ids, R, c in blocks:
                if partner is not None:
                    to = partner[ids]
                    keep = ~pres[to, k]
                    ids, R = to[keep], R.tocsr()[keep]
                    c = np.broadcast_to(c, keep.shape)[keep]
                R = sp.hstack([R, sp.csr_matrix((R.shape[0], extra))]).tocoo()
                rows.append(sp.csr_matrix((R.data, (k * nu_ + ni + ids[R.row], R.col)),
                                          shape=K.shape))
                if partner is None:
                    rhs[ni + ids, k] = c
                else:
                    np.add.at(rhs[:, k], ni + ids, c)
        if partner is not None:
            for k in range(d):
                s = unread[~pres_own[unread, k]]
                r = k * nu_ + ni + np.r_[s, s]
                c = k * nu_ + ni + np.r_[s, partner[s]]
                v = np.r_[np.ones(s.size), -np.ones(s.size)]
                rows.append(sp.csr_matrix((v, (r, c)), shape=K.shape))
        return (K + sum(rows)).tocsr() if rows else K, rhs

    pres = prescribed(problem, part)
    K_all, rhs = conditions(pres)
    unread, partner = unread_surface_nodes(K_all, pts, ni, nu_, d)
    if partner is not None:    # a pin: its conditions on the partner (docstring)
        pres_own, pres = pres, pres.copy()
        np.logical_or.at(pres, partner[unread], pres_own[unread])
        K_all, rhs = conditions(pres, partner)
    K = K_all
    exact = problem.exact(pts)
    fixed = [k * nu_ + ni + np.flatnonzero(pres[:, k]) for k in range(d)]
    values = [exact[pres[:, k], k] for k in range(d)]
    counts = shape_counts(g, surface_nodes=int(ns), fictitious_nodes=int(fict.size),
                          bridging_bonds=int(pairs.size))
    return eliminated(problem, model, K, rhs, fixed, values, np.r_[x_real, pts], {},
                      extra_x=pts, counts=counts, ordering=ORDERING_ON_SHAPE)


def unread_surface_nodes(K, pts, ni, nu_, d):
    """``(unread, partner)``: the surface nodes whose columns are empty in the system
    ``K`` (every row in place: no fictitious value is extrapolated from them and no row
    of theirs reads them, as a pin part of length h/2 on a straight edge, whose
    flux rows are over bond forces and whose every fictitious node's nearest surface node
    is another part's), and for every surface node the nearest one that is read (itself
    if read); ``partner`` is None when every surface node is read."""
    used = np.zeros(nu_ - ni, dtype=bool)
    Kc = K.tocsc(copy=True)
    Kc.eliminate_zeros()
    cols = Kc.indptr
    for k in range(d):
        lo = k * nu_ + ni
        used |= np.diff(cols[lo:lo + nu_ - ni + 1]) > 0
    unread = np.flatnonzero(~used)
    if not unread.size:
        return unread, None
    from scipy.spatial import cKDTree
    read = np.flatnonzero(used)
    partner = np.arange(nu_ - ni)
    partner[unread] = read[cKDTree(pts[read]).query(pts[unread])[1]]
    return unread, partner


def _place(block, rows, n_rows) -> sp.csr_matrix:
    """``block``'s rows placed on the node rows ``rows`` of an n_rows-row map."""
    block = sp.coo_matrix(block)
    return sp.csr_matrix((block.data, (np.asarray(rows)[block.row], block.col)),
                         shape=(n_rows, block.shape[1]))
