"""Seed 001 §5.3's PDDO boundary layer read for bond-based PD: its role in the
``bond-box`` family (the bond-based boxes that state their conditions at the body's
surface, :class:`~pdverify.pd.problem.SurfaceConditions`), the twin of
:mod:`.bond_fictitious` for a treatment that adds no node.

Seed 001 (and Behera et al.) state the method for state-based models; what the
bond-based form changes, and what we chose:

- **Bulk** (real nodes farther than 2 delta from the surface): the bond-based PD
  equations of the uncorrected model (its stiffness rows, K u = b V), not the LPS ones.
  Their neighbourhoods and their neighbours' are complete.
- **The moduli in the rows.** The layer's equilibrium and the outer nodes' traction rows
  take the discrete lattice's own elasticity tensor, not the continuum's E, nu: under a
  homogeneous strain eps every bond of a complete neighbourhood stretches by
  e = |xi| n.eps.n, so the node's energy density (the model's, half of each bond's
  energy s e^2 / 2 to each end, s = c omega beta V V / |xi|) is

      W = 1/(4 V) sum_k s_k e_k^2 = 1/2 eps : C : eps,
      C_ijkl = (c / 2) sum_k omega(|xi_k|) beta_k V |xi_k| n_i n_j n_k n_l

  (the sum over the whole stencil, V the bulk node volume with the thickness):
  :func:`lattice_tensor`. It is totally symmetric (the Cauchy relations of a pairwise
  central-force lattice): on the square and cubic stencils C11 = c A / 2, C12 = C44 =
  c B / 2 with A = sum w n_1^4, B = sum w n_1^2 n_2^2 (``sheets.lattice_moduli``'s E*,
  nu* in plane stress). The bond force density of a complete neighbourhood under a
  quadratic field u (Hessian H) is the same sum, f_i = C_ijkl H_kjl = (div sigma)_i, so
  the bulk rows and the layer's PDDO rows are one continuum equation for quadratics.
- **Operators, outer layer, layer**: as on the state-based box
  (:func:`~.pddo.derivative_operators` on the model's bonds with the micromodulus's
  shape omega(|xi|) beta as PDDO's weight; the first cell layer along a face takes the
  boundary rows at the face, x_B the node's projection on it, per component the
  Dirichlet face first, then the face normal to it, then any, :func:`~.pddo._choose_faces`;
  the other nodes within 2 delta the PDDO equilibrium -C_ijkl d_j d_l u_k V = b_i V).
  The traction is t_i = C_ijkl n_j d_l u_k(x_B), grad u(x_B) by the Taylor step with
  the PDDO second derivatives.
- **Symmetry planes** (``SurfaceConditions.planes``, seed 001 imposes no condition inside
  the body): the rows of :mod:`.bond_fictitious` (the mean of the two nodes straddling
  the plane at the ends of its trace) by Lagrange multipliers, which pin the rigid
  motions a body loaded by tractions only leaves free.

Exactness kept (tested, ``tests/treatments/test_pddo_bond.py``): every row holds exactly
for a quadratic field with its constant body force and the tractions of its stress under
C (the PDDO operators are exact for quadratics; the bulk rows for quadratics by the
identity above), so a quadratic field is the solution to round-off on any box with
m >= 2 where every outer node's moment matrix is regular.

The body is laid out cell-centred as the other ``bond-box`` treatments lay it (the
surface half a spacing beyond the outermost nodes) but with no fictitious layer: the
uncorrected model's truncated families. The measurements see the real nodes'
displacements (:class:`~.bond_fictitious.BondBoxSystem` with the identity map) and the
force through a face: the PDDO traction at each of its boundary cell faces' centres
(the owner node's Taylor step) times the cell face's area.
"""
from __future__ import annotations

from dataclasses import replace
from types import SimpleNamespace

import numpy as np
import scipy.sparse as sp

from ..pd.build import build_model
from ..pd.faces import box_faces
from ..pd.problem import BondProblem
from .bond_fictitious import BondBoxSystem, _plane_rows, bordered
from .mirror_nodes import prescribed_parts
from .pddo import _choose_faces, _d2, derivative_operators, scatter_blocks


def lattice_tensor(model) -> np.ndarray:
    """C_ijkl (d, d, d, d) of the bond-based lattice (bulk, complete neighbourhood):
    the module docstring's sum over the stencil's offsets."""
    st = model.stencil
    r = np.linalg.norm(st.offsets, axis=1) * model.spacing
    n = st.offsets / np.linalg.norm(st.offsets, axis=1)[:, None]
    V = model.grid.volume * model.thickness
    w = 0.5 * model.c * model.influence.omega(r, model.horizon) * st.beta * V * r
    return np.einsum("b,bi,bj,bk,bl->ijkl", w, n, n, n, n)


def _combine(terms, shape) -> sp.csr_matrix:
    """sum of coefficient x matrix over the non-zero coefficients (an empty sum: zeros of
    ``shape``; the lattice tensor's entries with an odd count of an index vanish)."""
    out = sp.csr_matrix(shape)
    for c, M in terms:
        if c != 0.0:
            out = out + c * M
    return out


def _pddo_view(model):
    """The bond-based model as :func:`~.pddo.derivative_operators` reads a model: PDDO's
    weight omega(|xi|) beta of every bond (the micromodulus's shape)."""
    return SimpleNamespace(grid=model.grid, bond_a=model.bond_a, bond_b=model.bond_b,
                           bond_n=model.bond_n, bond_x=model.bond_x,
                           bond_omega=model.influence.omega(model.bond_x, model.horizon),
                           bond_beta=model.bond_beta, node_volume=model.node_volume)


def assemble_bond_pddo(problem: BondProblem) -> BondBoxSystem:
    """The PDDO system of ``problem`` (its surface conditions; module docstring)."""
    sc = problem.surface
    if sc is None:
        raise ValueError("the problem states no surface conditions")
    body = replace(problem.body, placement="cell-centred", boundary_volume="partial")
    g = body.grid(0)
    model = build_model(body, problem.stencil, problem.material, None, grid=g)
    d, n, h = g.dim, g.n_interior, g.spacing
    C = lattice_tensor(model)
    D = derivative_operators(_pddo_view(model))
    x, cells = g.x, g.index
    faces = box_faces(d)
    touches = np.stack([cells[:, f.axis] == g.boundary_layer(f) for f in faces], axis=1)
    outer = touches.any(axis=1)
    layer = ~outer & (g.distance_to_surface(x) <= 2.0 * model.horizon * (1 + 1e-12))
    bulk = ~outer & ~layer
    counts = {"real_nodes": int(n), "fictitious_nodes": 0, "outer_nodes": int(outer.sum()),
              "layer_nodes": int(layer.sum()), "bulk_nodes": int(bulk.sum())}
    # the layer: -C_ijkl d_j d_l u_k, times V (a force, like the bond rows)
    Vd = sp.diags(model.node_volume)
    nav = [[Vd @ _combine([(-C[i, j, k, l], _d2(D, j, l)) for j in range(d)
                           for l in range(d)], (n, n))
            for k in range(d)] for i in range(d)]
    A = (sp.diags(np.tile(bulk, d).astype(float)) @ model.K
         + sp.diags(np.tile(layer, d).astype(float)) @ sp.bmat(nav)).tocoo()
    rows, cols, vals = [A.row], [A.col], [A.data]
    rhs = np.zeros(d * n)
    dirichlet = [(name, k) for name, cond in sc.faces.items() for k in cond.prescribed]
    chosen = _choose_faces(touches, faces, prescribed_parts(dirichlet), cells)
    area = g.face_area * model.thickness
    C11 = C[0, 0, 0, 0]
    for i_c, (face_of, kind) in enumerate(chosen):
        for fi, face in enumerate(faces):
            cond = sc.faces.get(face.name)
            for kd in (1, 2):
                nodes = np.flatnonzero((face_of == fi) & (kind == kd))
                if nodes.size == 0:
                    continue
                xB = x[nodes].copy()
                xB[:, face.axis] = g.face_coordinate(face)
                S = sp.csr_matrix((np.ones(nodes.size), (np.arange(nodes.size), nodes)),
                                  shape=(nodes.size, n))
                step = xB[:, face.axis] - x[nodes, face.axis]
                if kd == 1:   # u_k(x_B) = g_k, scaled to a force
                    dl = sp.diags(step)
                    M = (S + dl @ (S @ D[(face.axis,)])
                         + 0.5 * (dl @ dl) @ (S @ _d2(D, face.axis, face.axis)))
                    scale = C11 * h ** (d - 2) * model.thickness
                    blocks = {i_c: scale * M}
                    rhs[i_c * n + nodes] = scale * sc.value(xB)[:, i_c]
                else:         # t_i = C_ijkl n_j d_l u_k(x_B), times the cell face area
                    nrm = np.zeros_like(xB)
                    nrm[:, face.axis] = face.sign
                    blocks = traction_blocks(C, D, S, step, face, i_c, area)
                    t = (np.zeros_like(xB) if cond is None or cond.traction is None
                         else cond.traction(xB, nrm))
                    rhs[i_c * n + nodes] = area * t[:, i_c]
                scatter_blocks(blocks, i_c, nodes, n, rows, cols, vals)
    K = sp.csr_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))),
                      shape=(d * n, d * n))
    planes = _plane_rows(g, sc.planes, n)
    op, op_rhs, coords, _ = bordered(K, rhs, planes, [np.zeros(b.shape[0]) for b in planes],
                                     np.tile(x, (d, 1)))
    counts.update(constraints=int(op.shape[0] - d * n), unknowns=int(op.shape[0]))
    parts = {f.name: np.flatnonzero(touches[:, fi]) for fi, f in enumerate(faces)}
    return BondBoxSystem(model, np.zeros(d * n), np.zeros(0, dtype=int), np.zeros(0), parts,
                         A=sp.identity(d * n, format="csr"), op=op, op_rhs=op_rhs,
                         n_unknown=n, face_rows=face_flux_rows(g, C, D, area),
                         counts=counts, coords=coords)


def traction_blocks(C, D, S, step, face, i, area) -> dict:
    """{k: the rows of t_i = C_ijkl n_j d_l u_k at x_B over u_k} (times ``area``) of the
    nodes ``S`` selects, x_B - x = ``step`` along the face's axis: grad u(x_B) = D u +
    D^2 u (x_B - x)."""
    d = C.shape[0]
    a = face.axis
    dl = sp.diags(step)

    def grad_B(l):
        return S @ D[(l,)] + dl @ (S @ _d2(D, l, a))
    G = [grad_B(l) for l in range(d)]
    return {k: area * face.sign * _combine([(C[i, a, k, l], G[l]) for l in range(d)],
                                           S.shape)
            for k in range(d)}


def face_flux_rows(g, C, D, area) -> sp.csr_matrix:
    """The force the outside exerts through every boundary cell face (component-major
    over the grid's surface nodes) as rows over the real nodes' displacements: the
    PDDO traction at the cell face's centre from its owner node (the real node of the
    boundary cell), times the cell face's area."""
    d, n = g.dim, g.n_interior
    out = [[None] * d for _ in range(d)]
    blocks = {i: {k: [] for k in range(d)} for i in range(d)}
    order = []
    for face in box_faces(d):
        sel = np.flatnonzero(g.surface_on(face))
        order.append(sel)
        owner = g.interior_number[g.ext_id(g.surface_cell[sel])]
        S = sp.csr_matrix((np.ones(sel.size), (np.arange(sel.size), owner)),
                          shape=(sel.size, n))
        step = g.surface_x[sel, face.axis] - g.x[owner, face.axis]
        for i in range(d):
            for k, M in traction_blocks(C, D, S, step, face, i, area).items():
                blocks[i][k].append(M)
    perm = np.argsort(np.concatenate(order))          # back to the surface numbering
    for i in range(d):
        for k in range(d):
            out[i][k] = sp.vstack(blocks[i][k]).tocsr()[perm]
    return sp.bmat(out, format="csr")
