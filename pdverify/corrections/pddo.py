"""A PDDO boundary layer after Behera, Roy, Anicode, Madenci and Spencer (CMAME 393, 2022,
114734; seed 001 §5.3), on the linear state-based engine.

Seed 001 calls its comparison with this method qualitative (the original is a
non-ordinary state-based framework); what we implement is our reading of its three
subdomains, not a port:

- **Operators.** Peridynamic differential operators (Madenci's PDDO) of first and second
  order at every real node, from the moment matrix of its own (truncated) family:
  A_i = sum_j w(|xi|) P(xi) P(xi)^T beta V_j with the monomials P = (xi_k; xi_k xi_l,
  k <= l) and the scene's influence function as the weight w; then
  d^q u(x_i) = s_q e_q^T A_i^-1 sum_j w P(xi) (u_j - u_i) beta V_j, s_q = 2 for a
  square, 1 otherwise. Exact for quadratic fields whatever the family (tested).
- **Outer layer** (real nodes in the first cell layer along a face): the local boundary
  conditions, imposed on the boundary itself through the node's Taylor expansion with
  the PDDO derivatives: u(x_B) = u_i + D u . (x_B - x_i) + (x_B - x_i) . D^2 u
  (x_B - x_i) / 2 = g (Dirichlet), or sigma(grad u(x_B)) n = t with
  grad u(x_B) = D u + D^2 u (x_B - x_i) (traction). x_B is the node's projection on the
  face. Per component, a Dirichlet face takes precedence; otherwise the traction of the
  face normal to that component if the node touches it, else of its other face. The
  choice is made per node (per boundary cell), not per face: a face that prescribes a
  component on part of it only (``where`` over its boundary cells, e.g. seed 001
  Fig. 8's row next to x = 0) is a Dirichlet face for the nodes of the cells it names
  and a traction face for its other nodes (*reading:* the paper states its boundary
  conditions per face).
- **Surface layer** (the other nodes within 2 delta of the surface): the equilibrium
  equation with the PDDO operators, -(lambda + mu) grad div u - mu lap u = b (times the
  node volume, so the rows are forces like the PD rows).
- **Bulk** (farther than 2 delta): the standard linear state-based (LPS) equations of
  the uncorrected model; their neighbourhoods and their neighbours' are complete.
  *Reading* ``bulk_model="pddo"``: the bulk too takes the PDDO equilibrium of the layer.
  It stands in for the paper's non-ordinary bulk (seed 001 §5.3: 'based on the
  non-ordinary state-based Peridynamics framework'), whose equations, like these, are
  built from PDDO derivatives rather than ordinary bond forces; it is not a port of the
  bond-associated correspondence model. Both bulks are exact for affine fields (the
  PDDO operators are exact for quadratics; an affine field carries no LPS force in a
  complete neighbourhood), so on seed 001's plate the choice cannot change the
  round-off result.

The system is square and nonsymmetric (direct sparse LU). A node whose moment matrix is
singular to 1e-12 (too few neighbours in some direction) is a failed run naming it.

The bond-based form (the same operators and boundary rows, the lattice's own elasticity
tensor in them and the bond-based equations beyond 2 delta) is
:mod:`~pdverify.corrections.pddo_bond`.
"""
from __future__ import annotations

import itertools

import numpy as np
import scipy.sparse as sp

from ..pd.problem import LinearSystem, box_faces
from .assembly import boundary_nodes, model_of, shape_counts, traction_of
from .factors import node_moments, solve_per_node
from .mirror_nodes import prescribed_at, prescribed_parts


def monomial_orders(d: int) -> list[tuple[int, ...]]:
    """Multi-indices of the PDDO monomials: first order (k,), then second (k, l), k <= l."""
    return [(k,) for k in range(d)] + list(itertools.combinations_with_replacement(range(d), 2))


def _monomials(xi, orders):
    return np.stack([np.prod(xi[:, list(o)], axis=1) for o in orders], axis=1)


def derivative_operators(model) -> dict[tuple[int, ...], sp.csr_matrix]:
    """{multi-index: D (n_real x n_real)} with D @ u = that derivative of the nodal field u
    at every real node (a plain grid without fictitious nodes: a box's, or a shape's,
    whose other lattice nodes are void)."""
    g = model.grid
    # real-node numbering (a shape's grid: no void node; a plain box's: the identity)
    a, b = g.interior_number[model.bond_a], g.interior_number[model.bond_b]
    d, n = g.dim, g.n_interior
    orders = monomial_orders(d)
    q = len(orders)
    xi = model.bond_n * model.bond_x[:, None]
    w = model.bond_omega * model.bond_beta
    V = model.node_volume[g.interior_ids]
    ends = ((a, b, xi, w * V[b]), (b, a, -xi, w * V[a]))   # (node, neighbour, xi, weight)
    P_end = [_monomials(x_, orders) for _, _, x_, _ in ends]
    A = node_moments(np.r_[a, b], np.r_[ends[0][3], ends[1][3]], np.vstack(P_end), n)
    R = solve_per_node(A, np.broadcast_to(np.eye(q), (n, q, q)), "pddo: the moment matrix",
                       g.x[g.interior_ids])
    out = {}
    for qi, o in enumerate(orders):
        s = 2.0 if len(o) == 2 and o[0] == o[1] else 1.0
        rows, cols, vals = [], [], []
        for (node, other, _, wt), P in zip(ends, P_end):
            c = s * np.einsum("bk,bk->b", R[node, qi, :], P) * wt
            rows += [node, node]
            cols += [other, node]
            vals += [c, -c]
        D = sp.csr_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))),
                          shape=(n, n))
        out[o] = D.tocsr()
    return out


def _d2(D, l, m):
    return D[(min(l, m), max(l, m))]


def _choose_faces(touches, faces, parts, cells):
    """Per component k: (face, kind) of every node, kind 1 = Dirichlet, 2 = traction, 0 =
    none (not an outer node); the face as its position in ``faces`` (the box's faces,
    the columns of ``touches``; -1: none). Dirichlet first (a face prescribing k at the
    node's cell: ``parts`` as :func:`~pdverify.corrections.mirror_nodes.prescribed_parts`),
    then the face normal to k, then any."""
    n = touches.shape[0]
    out = []
    for k in range(cells.shape[1]):
        face_of, kind = np.full(n, -1), np.zeros(n, dtype=int)
        steps = ([(faces.index(f), touches[:, faces.index(f)] & prescribed_at(where, cells), 1)
                  for f, k_, where in sorted(parts, key=lambda q: faces.index(q[0])) if k_ == k]
                 + [(i, touches[:, i], 2) for i, f in enumerate(faces) if f.axis == k]
                 + [(i, touches[:, i], 2) for i in range(len(faces))])
        for face, on, kd in steps:
            hit = on & (face_of < 0)
            face_of[hit], kind[hit] = face, kd
        out.append((face_of, kind))
    return out


#: what governs the nodes farther than 2 delta from the surface: the LPS equations of the
#: uncorrected model, or the PDDO equilibrium as in the layer (the module docstring)
BULK_MODELS = ("lps", "pddo")


def pddo_system(model, dirichlet, exact, traction, moduli, body_load=None,
                bulk_model="lps"):
    """The square system (A, rhs, counts) of the PDDO boundary layer on the uncorrected
    plain-grid ``model`` (its equilibrium rows serve the bulk): ``A`` (d n x d n,
    component-major: one row per component of every real node) and ``rhs``: the boundary
    data on the outer rows, ``body_load`` (n, d; b V per node) on the others.
    ``dirichlet``: (face, component) pairs prescribed at ``exact(x)``, or
    (face, component, where) on part of a face (per node: its cell), a face by name or
    as a :class:`~pdverify.pd.faces.Face`; ``traction(x, normal, face)`` (``face``: a
    :class:`~pdverify.pd.faces.Face`); ``bulk_model``: :data:`BULK_MODELS`."""
    if bulk_model not in BULK_MODELS:
        raise ValueError(f"bulk_model={bulk_model!r}; allowed: {', '.join(BULK_MODELS)}")
    g, d, h = model.grid, model.dim, model.spacing
    n = g.n_interior
    lam, mu = moduli
    D = derivative_operators(model)
    x, cells = g.x, g.index
    faces = box_faces(d)
    touches = np.stack([cells[:, f.axis] == g.boundary_layer(f) for f in faces], axis=1)
    outer = touches.any(axis=1)
    layer = ~outer & (g.distance_to_surface(x) <= 2.0 * model.horizon * (1 + 1e-12))
    if bulk_model == "pddo":
        layer = ~outer
    bulk = ~outer & ~layer
    # equilibrium with the PDDO operators: -(lam + mu) d_k d_j u_j - mu d_l d_l u_k, times V
    lap = sum(_d2(D, l, l) for l in range(d))
    Vd = sp.diags(model.node_volume)
    nav = [[None] * d for _ in range(d)]
    for k in range(d):
        for j in range(d):
            M = -(lam + mu) * _d2(D, k, j)
            nav[k][j] = Vd @ (M - mu * lap if j == k else M)
    bulk_rows = sp.diags(np.tile(bulk, d).astype(float)) @ model.equilibrium_rows()
    A = (model.stiffness(bulk_rows)
         + sp.diags(np.tile(layer, d).astype(float)) @ sp.bmat(nav)).tocoo()
    rows, cols, vals = [A.row], [A.col], [A.data]
    rhs = np.zeros(d * n)
    if body_load is not None:
        rhs += np.where(np.tile(outer, d), 0.0, np.asarray(body_load).T.ravel())
    chosen = _choose_faces(touches, faces, prescribed_parts(dirichlet), cells)
    for k, (face_of, kind) in enumerate(chosen):
        for i, face in enumerate(faces):
            axis = face.axis
            for kd in (1, 2):
                nodes = np.flatnonzero((face_of == i) & (kind == kd))
                if nodes.size == 0:
                    continue
                xB = x[nodes].copy()
                xB[:, axis] = g.face_coordinate(face)
                dl = sp.diags(xB[:, axis] - x[nodes, axis])   # x_B - x_i along the axis
                S = sp.csr_matrix((np.ones(nodes.size), (np.arange(nodes.size), nodes)),
                                  shape=(nodes.size, n))

                def grad_B(l):
                    """d/dx_l at x_B of a nodal field (Taylor with the PDDO derivatives)."""
                    return S @ D[(l,)] + dl @ (S @ _d2(D, l, axis))
                if kd == 1:   # u_k(x_B) = g_k, scaled to a force
                    scale = (lam + 2 * mu) * h ** (d - 2)
                    M = S + dl @ (S @ D[(axis,)]) + 0.5 * (dl @ dl) @ (S @ _d2(D, axis, axis))
                    blocks = {k: scale * M}
                    rhs[k * n + nodes] = scale * exact(xB)[:, k]
                else:         # t_k = s (lam delta_ka div u + mu (d_a u_k + d_k u_a))
                    s = face.sign
                    scale = s * h ** (d - 1)
                    nrm = np.zeros_like(xB)
                    nrm[:, axis] = s
                    blocks = {}
                    for j in range(d):
                        M = lam * grad_B(j) if k == axis else sp.csr_matrix(S.shape)
                        if j == k:
                            M = M + mu * grad_B(axis)
                        if j == axis:
                            M = M + mu * grad_B(k)
                        blocks[j] = scale * M
                    rhs[k * n + nodes] = h ** (d - 1) * traction(xB, nrm, face)[:, k]
                scatter_blocks(blocks, k, nodes, n, rows, cols, vals)
    A = sp.csr_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))),
                      shape=(d * n, d * n))
    return A, rhs, {"outer_nodes": int(outer.sum()), "layer_nodes": int(layer.sum()),
                    "bulk_nodes": int(bulk.sum())}


# ------------------------------------------------------------------------------ static assembly
#: SuperLU's column ordering of the PDDO system (square, nonsymmetric, partial pivoting):
#: minimum degree on A + A^T: plate2d-plane-strain's whole runs 2.1x faster than under
#: COLAMD at h = 0.0125, the exactness metrics still round-off (record
#: solvers-2026-11-26-pddo).
PDDO_ORDERING = "MMD_AT_PLUS_A"


def assemble_pddo(problem, bulk_model: str = "lps") -> LinearSystem:
    """Seed 001 §5's PDDO boundary layer (:func:`pddo_system`) on a ``static-state``
    problem: its own square, nonsymmetric system on the uncorrected model, solved by a
    direct LU; ``bulk_model`` (:data:`BULK_MODELS`) governs the nodes beyond 2 delta.
    On a shape: :func:`pddo_shape_system`."""
    g = problem.body.grid(0)
    model = model_of(problem, g, None)
    x_int = g.x[g.interior_ids]
    body = problem.body_load(x_int, model.node_volume[g.interior_ids][:, None])
    if problem.shape is not None:
        A, rhs, counts = pddo_shape_system(model, problem, body, bulk_model)
        return LinearSystem(model, A, rhs, np.zeros(0, dtype=int), np.zeros(0),
                            g.n_interior, solver="direct", counts=shape_counts(g, **counts),
                            ordering=PDDO_ORDERING)
    A, rhs, counts = pddo_system(model, problem.prescribed(), problem.exact,
                                 traction_of(problem), problem.constants.moduli(), body,
                                 bulk_model=bulk_model)
    return LinearSystem(model, A, rhs, np.zeros(0, dtype=int), np.zeros(0), g.n_interior,
                        solver="direct", counts=counts, ordering=PDDO_ORDERING)


# ------------------------------------------------------------------------------ on a shape
def _layer_rows(model, D, moduli, outer, layer, bulk):
    """The rows of the layer (PDDO equilibrium, times V) and of the bulk (LPS) over the
    real nodes' displacements (component-major), zero on the outer nodes."""
    d = model.dim
    lam, mu = moduli
    lap = sum(_d2(D, l, l) for l in range(d))
    Vd = sp.diags(model.node_volume[model.grid.interior_ids])
    nav = [[None] * d for _ in range(d)]
    for k in range(d):
        for j in range(d):
            M = -(lam + mu) * _d2(D, k, j)
            nav[k][j] = Vd @ (M - mu * lap if j == k else M)
    bulk_rows = sp.diags(np.tile(bulk, d).astype(float)) @ model.equilibrium_rows()
    return (model.stiffness(bulk_rows)
            + sp.diags(np.tile(layer, d).astype(float)) @ sp.bmat(nav)).tocsr()


def choose_points(pnode, ppart, nrm, problem, d):
    """Per component k, the boundary point each outer node's row of k uses (index into
    the points, one per outer node, nodes ascending): a point on a part that prescribes
    k first (the box's Dirichlet face), then the point whose outward normal is the most
    nearly along axis k (the box's face normal to k), ties to the first point. Returns
    ``[(points, dirichlet mask)]`` per component."""
    names = problem.shape.part_names
    out = []
    for k in range(d):
        pres = np.zeros(len(pnode), dtype=bool)
        for name, cond in problem.conditions.items():
            if k in cond.prescribed:
                pres |= ppart == names.index(name)
        score = np.where(pres, 3.0, 1.0 + np.abs(nrm[:, k]))
        order = np.lexsort((np.arange(len(pnode)), -score, pnode))
        _, first = np.unique(pnode[order], return_index=True)
        chosen = order[first]
        out.append((chosen, pres[chosen]))
    return out


def pddo_shape_system(model, problem, body_load, bulk_model="lps"):
    """PDDO's boundary layer on a 2D or 3D shape (issue 55; our generalisation of seed 001 §5.3's
    box rows): ``(A, rhs, counts)`` as :func:`pddo_system`.

    - outer nodes: the real nodes the boundary samples belong to
      (``assembly.boundary_nodes``: the cut cells' nodes along an arc, the layer nearest
      a straight part); each has one boundary point x_B per part it touches (the mean of
      its samples moved onto the part, ``shape_fictitious.boundary_points``) with that
      part's outward normal n (the local normal of an arc);
    - per component k one row per outer node (:func:`choose_points`): u_k(x_B) = g_k
      through the full second-order Taylor expansion with the PDDO derivatives,
      u_i + D u . d + d . D^2 u d / 2 (d = x_B - x_i, any direction, not one axis as on
      the box), or the traction sigma(grad u(x_B)) n = t with grad u(x_B) = D u + D^2 u d
      and n the part's normal at x_B (zero t on a free part);
    - the layer: the other nodes within two of the stencil's longest bonds and half a
      cell's diagonal of the boundary (the shape's Euclidean distance: the box's
      2 delta counts along its axes, and a cut cell's volume is partial), so that every
      bulk node's LPS row sees complete, whole-cell families only; the bulk as on the
      box.

    Exactness kept: the PDDO derivatives of the truncated families are exact for
    quadratic fields (moment matrices of first and second order), so the outer rows
    hold exactly for a quadratic field and its traction, the layer rows for a quadratic
    field with its constant body force; the bulk's LPS rows for an affine field always,
    for a quadratic one on a stencil whose complete neighbourhoods are exact for it (the
    moment-corrected weights). Tested on the hole and the L
    (tests/shapes/test_shape_methods.py).

    On a 3D shape (``pdverify.pd.shapes3d``) the same construction unchanged (every step
    above is written for d dimensions: 3D moment matrices of the ten monomials to
    second order, boundary points on planes, the mantle and the sphere with their
    normals); the same exactness, tested on the quarter cylinder and the cavity octant
    (tests/shapes/test_shape3d_methods.py)."""
    from .shape_fictitious import boundary_points
    if bulk_model not in BULK_MODELS:
        raise ValueError(f"bulk_model={bulk_model!r}; allowed: {', '.join(BULK_MODELS)}")
    g, d, h = model.grid, model.dim, model.spacing
    n = g.n_interior
    lam, mu = problem.constants.moduli()
    shape = problem.shape
    D = derivative_operators(model)
    x = g.x[g.interior_ids]
    samples = boundary_nodes(g, shape)
    pts, nrm, ppart, pnode, _ = boundary_points(g, shape, samples)
    outer = np.zeros(n, dtype=bool)
    outer[pnode] = True
    # the layer: every node whose LPS row would see a neighbour's truncated or cut-cell
    # family (two of the stencil's longest bonds and a cut cell's half-diagonal; on a
    # box the layer's 2 delta counts along the lattice's axes, here along any direction)
    reach = np.max(np.linalg.norm(model.stencil.offsets, axis=1)) * h
    layer = ~outer & (shape.closest(x)[2] <= (2.0 * reach + np.sqrt(0.5) * h) * (1 + 1e-12))
    if bulk_model == "pddo":
        layer = ~outer
    bulk = ~outer & ~layer
    A = _layer_rows(model, D, (lam, mu), outer, layer, bulk).tocoo()
    rows, cols, vals = [A.row], [A.col], [A.data]
    rhs = np.where(np.tile(outer, d), 0.0, np.asarray(body_load).T.ravel())
    traction = _traction_at_points(problem, pts, nrm, ppart)
    exact = problem.exact(pts)
    for k, (chosen, dirichlet) in enumerate(choose_points(pnode, ppart, nrm, problem, d)):
        nodes, dl = pnode[chosen], pts[chosen] - x[pnode[chosen]]
        S = sp.csr_matrix((np.ones(nodes.size), (np.arange(nodes.size), nodes)),
                          shape=(nodes.size, n))
        SD = {o: S @ M for o, M in D.items()}

        def grad_B(l):
            """d/dx_l at x_B of a nodal field (Taylor with the PDDO derivatives)."""
            return SD[(l,)] + sum(sp.diags(dl[:, m]) @ _d2(SD, l, m) for m in range(d))
        blocks = {}
        value = np.zeros(nodes.size)
        sel = np.flatnonzero(dirichlet)
        if sel.size:      # u_k(x_B) = g_k, scaled to a force
            scale = (lam + 2 * mu) * h ** (d - 2)
            M = S + sum(sp.diags(dl[:, l]) @ SD[(l,)] for l in range(d))
            M = M + 0.5 * sum(sp.diags(dl[:, l] * dl[:, m]) @ _d2(SD, l, m)
                              for l in range(d) for m in range(d))
            blocks[k] = sp.diags(dirichlet.astype(float)) @ (scale * M)
            value[sel] = scale * exact[chosen[sel], k]
        free = ~dirichlet
        if free.any():    # t_k = lam n_k div u + mu sum_l n_l (d_l u_k + d_k u_l)
            nk = nrm[chosen]
            G = [grad_B(l) for l in range(d)]
            scale = h ** (d - 1)
            for j in range(d):
                M = (sp.diags(lam * nk[:, k]) @ G[j] + sp.diags(mu * nk[:, j]) @ G[k])
                if j == k:
                    M = M + mu * sum(sp.diags(nk[:, l]) @ G[l] for l in range(d))
                M = sp.diags(free.astype(float) * scale) @ M
                blocks[j] = M if j not in blocks else blocks[j] + M
            value[free] = scale * traction[chosen[free], k]
        rhs[k * n + nodes] = value
        scatter_blocks(blocks, k, nodes, n, rows, cols, vals)
    A = sp.csr_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))),
                      shape=(d * n, d * n))
    return A, rhs, {"outer_nodes": int(outer.sum()), "layer_nodes": int(layer.sum()),
                    "bulk_nodes": int(bulk.sum()), "boundary_points": int(len(pts))}


def scatter_blocks(blocks, k, nodes, n, rows, cols, vals) -> None:
    """Append to the triplets ``rows, cols, vals`` the row blocks of component ``k`` at
    ``nodes``: ``blocks[j]`` (one row per node, over the n nodes of component j) placed
    at rows ``k n + nodes`` and columns ``j n + ...``."""
    for j, M in blocks.items():
        M = sp.coo_matrix(M)
        rows.append(k * n + nodes[M.row])
        cols.append(j * n + M.col)
        vals.append(M.data)


def _traction_at_points(problem, x, n, xpart):
    """The applied traction at boundary points on their parts (zero on free parts)."""
    out = np.zeros_like(x)
    names = problem.shape.part_names
    for name, cond in problem.conditions.items():
        on = xpart == names.index(name)
        if cond.traction is not None and on.any():
            out[on] = cond.traction(x[on], n[on])
    return out
