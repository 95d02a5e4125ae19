"""Seed 000's Taylor fictitious nodes and seed 001's surface nodes on a bond-based box:
the ``bond-box`` family (the bond-based scenes that state their conditions at the body's
surface, :class:`~pdverify.pd.problem.SurfaceConditions`: the 2D sheets and stiffness
boxes, the 3D stiffness box, and in 1D seed 004's static bars, whose end force is the
traction sigma on the end faces and whose held midpoint is the symmetry point x = 0).

Both treatments lay the body out cell-centred (every real node carries its whole cell,
the surface half a spacing beyond the outermost nodes: the scene's box with the spacing
it gives, as virtual nodes lay out the clamped sheet), surround it with a fictitious layer
of the stencil's reach and keep every stencil pair with a real end (plus the
fictitious-fictitious pairs that cross a boundary cell face, which enter the flux), so
that every real node has a complete neighbourhood.

``taylor-fictitious`` (seed 000 §3-4, §6; its §7: "since bond-based Peridynamics is a
special case of the state-based one, the proposed method can be successfully used also
in bond-based models"): the fictitious displacements by the order-n Taylor extrapolation
about the nearest real node (:func:`~.taylor_fictitious.extrapolation_map`, the same map
as the state-based boxes), the unknowns the real displacements, the equations the real
nodes' equilibrium, the conditions as constraint rows by Lagrange multipliers (Eq. 63):
a prescribed component by the value at the boundary point of each line normal to its
face (Eq. 58, the corner rule of Remark 4), every other component by the force flux of
each boundary cell face (the face-crossing bonds weighted by alpha, seed 001 Eq. 35, as
the state-based boxes do; Eq. 60 in 1D) equal to the traction's resultant on it. What
the bond-based form drops: the dilatation extrapolation (Eq. 47) and the weighted
volume m; a bond's force is c omega(|xi|) e / |xi| V V, a function of its two ends'
displacements only. The claim checked: the extrapolation of order n reproduces a
polynomial field of degree <= n on the layer, so an affine field completes every real
node's neighbourhood as the bulk lattice and is a solution to round-off (the tension
sheet's uniform stress against the lattice's own moduli:
``tests/treatments/test_bond_fictitious.py``).

``surface-nodes`` (seed 001 §3, its state-based method read for bond-based PD; seed 001
leaves open, and we choose): the unknowns are the real nodes and one surface node at the
centre of every boundary cell face; the fictitious displacements by the order-N Taylor
extrapolation about the nearest surface node (steps 7-12, the same map as the state-based
boxes); a surface node's equations are its prescribed components (its own unknowns, held
at the values at its position) or its force flux (Eq. 36: the face-crossing bonds'
forces = the traction's resultant on its face). Left open by seed 001 for bond-based
PD: (1) no dilatations, so steps 1-6 (their order N - 1 extrapolation) and §3.2's
complete m have nothing to act on; (2) the flux's bond force is the pairwise force, so
Eq. 36 needs no neighbour's state; (3) seed 001 imposes no condition inside the body:
a scene's symmetry planes (``SurfaceConditions.planes``) are constraint rows by
Lagrange multipliers, the mean of the two nodes straddling the plane (exact for a
component odd about it, as every symmetric field's normal component is). The square
system is not symmetric (the extrapolation rows enter the real equations and the flux
rows are not the transpose of anything), so it goes to the sparse LU whatever the
scene's ``solver`` says.

At m = 2 the flux rows of a face are dependent (a checkerboard combination of the
shear rows of the side faces: 4 dependent rows on the tension sheet's 20 x 40 cells) and
the run fails as near-singular, a named failed run; at m = 4 (the quick grid) they
have full rank.

The scene's measurements see the displacements of every grid node (real and
fictitious, :attr:`BondBoxSystem.A`) and the force through a face
(:meth:`BondBoxSystem.face_force`: its boundary cell faces' fluxes).
"""
from __future__ import annotations

from dataclasses import dataclass, replace
from types import SimpleNamespace

import numpy as np
import scipy.sparse as sp

from ..errors import InputError
from ..pd.build import build_model
from ..pd.closure import Closure
from ..pd.faces import Face, box_faces
from ..pd.problem import BondProblem, BondSystem, face_resultant
from .surface_nodes import crossing_bonds, face_crossings, surface_node_closure
from .taylor_fictitious import (_corner_lines, _surface_flux, boundary_value_rows,
                                extrapolation_map)

#: the family's name (``Scene.role_families``)
FAMILY = "bond-box"
ANCHORS = ("real", "surface")


@dataclass
class BondBoxSystem(BondSystem):
    """A ``bond-box`` treatment's system: ``op x = op_rhs`` over its unknowns (the real
    nodes, then any surface nodes, component-major; then the multipliers of the
    constraint rows), ``A`` (d n_ext x d n_unknown) every grid node's displacement from
    them, ``face_rows``: the force on each boundary cell face from them (component-major
    over the grid's surface nodes)."""

    A: object = None
    op: object = None
    #: every unknown's position (the multipliers': their row's mean column position)
    coords: np.ndarray = None
    op_rhs: np.ndarray = None
    n_unknown: int = 0
    face_rows: object = None
    counts: dict = None

    def solve(self, where: str):
        """``(u, info)``: every grid node's displacement (component-major over the
        grid) and the solver's diagnostics."""
        from ..solvers.front import factor
        # nested dissection on the unknowns' positions: SuperLU's COLAMD took 10 s for
        # the tension sheet's 10,603 unknowns (records in the module docstring)
        lu = factor(self.op, "double", where=where, coords=self.coords)
        b = np.asarray(self.op_rhs, dtype=float)
        x = lu.solve(b)
        # one step of refinement with the same factor: the nested-dissection LU left
        # 2.5e-11 of relative residual on the tension sheet (surface nodes), 7e-8 of
        # relative error at its smallest u_x; the step takes it to round-off
        x = x + lu.solve(b - self.op @ x)
        info = {**lu.info, "refinement_steps": 1}
        residual = np.linalg.norm(self.op @ x - self.op_rhs)
        info = {**info, "bordered_residual": float(residual
                                                   / max(np.linalg.norm(self.op_rhs), 1e-300))}
        self.unknowns = x[:self.dim * self.n_unknown]
        return self.A @ self.unknowns, info

    def face_force(self, face: str) -> np.ndarray:
        """(d,) force the outside exerts on the body through ``face`` (its name): the sum
        of its boundary cell faces' fluxes under the last solution."""
        g = self.model.grid
        sel = np.flatnonzero(g.surface_on(Face.named(face)))
        ns = g.n_surface
        f = self.face_rows @ self.unknowns
        return np.array([f[k * ns + sel].sum() for k in range(self.dim)])


def bond_force_matrix(model) -> sp.csr_matrix:
    """Scalar bond forces s_b n_b . (u_b - u_a) (tension positive) as rows over every grid
    node's displacement (component-major)."""
    nb, ne, d = model.bond_a.size, model.grid.n_ext, model.dim
    rows = np.tile(np.arange(nb), 2 * d)
    cols = np.concatenate([k * ne + end for k in range(d)
                           for end in (model.bond_b, model.bond_a)])
    vals = np.concatenate([sgn * model.bond_stiffness * model.bond_n[:, k]
                           for k in range(d) for sgn in (1.0, -1.0)])
    return sp.csr_matrix((vals, (rows, cols)), shape=(nb, d * ne))


def _plane_rows(g, planes, n_cols_per_comp):
    """Rows u_k = 0 on the symmetry planes x_axis = 0 (2D), the node on the plane or
    else the mean of the two straddling it, only where they remove the rigid motions:
    the first plane at both ends of its trace (a translation and the rotation), the
    second at the end of its trace on the lower side (the other translation). On every
    line of the trace (as the uncorrected model holds its nodes) they over-constrain
    the surface nodes' unsymmetric system: with the tension sheet's two planes at
    h = 1.25 mm, 20 x 40 mm, its bordered system had a null vector (smallest singular
    value 1e-17 of the largest), a displacement balanced by reactions on the planes; the
    symmetric solution meets every line's row, so no exactness is lost. In 1D (a bar
    in tension, ``planes = ((0, 0),)``) the plane is a point and its one row removes
    the translation."""
    if not planes:
        return []
    if not ((g.dim == 2 and len(planes) <= 2) or (g.dim == 1 and len(planes) == 1)):
        raise ValueError("symmetry planes are taken in 2D (at most two) or 1D (one)")
    real = g.interior_ids
    idx, x, h = g.index[real], g.x[real], g.spacing
    rows = []
    for which, (axis, k) in enumerate(planes):
        on = np.flatnonzero(np.abs(x[:, axis]) < 1e-9 * h)
        below = np.flatnonzero(np.abs(x[:, axis] + 0.5 * h) < 1e-9 * h)
        if g.dim == 2:
            other = 1 - axis
            ends = (lambda ids: ids[np.isin(x[ids, other],
                                            [x[ids, other].min(), x[ids, other].max()]
                                            if which == 0 else [x[ids, other].min()])])
            on, below = ends(on) if on.size else on, ends(below) if below.size else below
        if on.size:
            r = sp.csr_matrix((np.ones(on.size), (np.arange(on.size), k * n_cols_per_comp + on)),
                              shape=(on.size, g.dim * n_cols_per_comp))
        elif below.size:
            step = np.zeros(g.dim, dtype=int)
            step[axis] = 1
            above = g.interior_number[g.ext_id(idx[below] + step)]
            m = below.size
            r = sp.csr_matrix((np.full(2 * m, 0.5),
                               (np.tile(np.arange(m), 2),
                                k * n_cols_per_comp + np.r_[below, above])),
                              shape=(m, g.dim * n_cols_per_comp))
        else:
            raise ValueError(f"no node on or straddling the plane x_{axis} = 0")
        rows.append(r)
    return rows


def check_bond_box(cells, p, where) -> None:
    """The extrapolation of order n needs more than 2 n nodes along every axis (seed 000
    App. D; the surface nodes' stencils need fewer)."""
    n = min(cells)
    if n <= 2 * p["order"]:
        raise InputError(f"{where}: order={p['order']} is too large for {n} nodes; seed 000 "
                         f"App. D needs nodes > 2 * order (order <= {(n - 1) // 2})")


def bordered(K, rhs, rows, values, coords):
    """``(op, op_rhs, coords, n_rows)``: K u = rhs bordered by the constraint ``rows``
    (sparse blocks over K's columns) = ``values`` with Lagrange multipliers, and the
    coordinates of the unknowns (a multiplier at the weighted mean of its row's nodes,
    for the nested-dissection ordering). Every constraint row is scaled to the
    stiffness's scale: the value rows (weights of order 1) beside bond stiffnesses of
    order E h^(d-1) made the bordered system look singular to the LU (condition estimate
    1e18 on the tension sheet; 1e3 once scaled); the multipliers scale with them and are
    not reported."""
    if not rows:
        return K.tocsc(), rhs, coords, 0
    B = sp.vstack(rows).tocsr()
    scale = abs(K).max() / np.maximum(abs(B).max(axis=1).toarray().ravel(), 1e-300)
    B = (sp.diags(scale) @ B).tocsr()
    op = sp.bmat([[K, B.T], [B, None]], format="csc")
    W = abs(B).tocsr()
    return (op, np.r_[rhs, scale * np.concatenate(values)],
            np.r_[coords, (W @ coords) / np.asarray(W.sum(axis=1))], B.shape[0])


def assemble_bond_box(problem: BondProblem, order: int, anchor: str) -> BondBoxSystem:
    """The system of ``problem`` (its :class:`~pdverify.pd.problem.SurfaceConditions`)
    under Taylor's fictitious nodes (``anchor="real"``) or the surface nodes
    (``anchor="surface"``): module docstring."""
    if anchor not in ANCHORS:
        raise ValueError(f"anchor={anchor!r}; allowed: {ANCHORS}")
    sc = problem.surface
    if sc is None:
        raise ValueError("the problem states no surface conditions")
    body = replace(problem.body, placement="cell-centred", boundary_volume="partial")
    g = body.grid(problem.stencil.reach)
    d, ni, ns = g.dim, g.n_interior, g.n_surface
    if anchor == "real":
        keep, _ = crossing_bonds(g, problem.stencil)
        closure = Closure(keep=keep, displacement_map=extrapolation_map(g, order))
        n_unk = ni
    else:
        closure, _ = surface_node_closure(g, problem.stencil, order, dilatations=False)
        closure = replace(closure, dilatation_map=None, weighted_volume="truncated")
        n_unk = ni + ns
    model = build_model(body, problem.stencil, problem.material, closure, grid=g)
    counts = {"real_nodes": int(ni), "fictitious_nodes": int(g.n_ext - ni)}
    if anchor == "surface":
        counts["surface_nodes"] = int(ns)
    if not sc.faces and not sc.planes:
        # free all round and unsupported: the rigid motions are free, nothing to solve
        # (the stiffness scenes give u at the unknowns); the model and its map only
        return BondBoxSystem(model, np.zeros(d * g.n_ext), np.zeros(0, dtype=int),
                             np.zeros(0), {}, A=model.displacement_map(), n_unknown=n_unk,
                             counts=counts)
    # the crossings in the model's own bond numbering (it drops zero-weight offsets)
    flux = face_crossings(g, model.bond_a, model.bond_b)
    A = model.displacement_map()
    face_rows = (_surface_flux(model, flux, ns) @ (bond_force_matrix(model) @ A)).tocsr()
    K = (model.K[model.real_rows()] @ A).tocsr()          # d ni x d n_unk
    conds = SimpleNamespace(conditions=sc.faces)
    loads = np.zeros((ns, d))
    for face in box_faces(d):
        cond = sc.faces.get(face.name)
        if cond is not None and cond.traction is not None:
            sel = np.flatnonzero(g.surface_on(face))
            loads[sel] = (face_resultant(cond.traction, g.surface_x[sel],
                                         g.surface_normal[sel], g.spacing)
                          * g.face_area * problem.thickness)
    rows, vals = [], []
    if anchor == "surface":
        # the surface nodes' own equations: a prescribed component or the face's flux
        eq_rows, eq_vals = [], []
        for face in box_faces(d):
            cond = sc.faces.get(face.name)
            sel = np.flatnonzero(g.surface_on(face))
            value = sc.value(g.surface_x[sel])
            for k in range(d):
                if cond is not None and k in cond.prescribed:
                    eq_rows.append(sp.csr_matrix(
                        (np.ones(sel.size), (np.arange(sel.size), k * n_unk + ni + sel)),
                        shape=(sel.size, d * n_unk)))
                    eq_vals.append(value[:, k])
                else:
                    eq_rows.append(face_rows[k * ns + sel])
                    eq_vals.append(loads[sel, k])
        K = sp.vstack([K] + eq_rows).tocsr()
        rhs = np.r_[np.zeros(d * ni), np.concatenate(eq_vals)]
    else:
        rhs = np.zeros(d * ni)
        for face in box_faces(d):
            cond = sc.faces.get(face.name)
            R, anchors = boundary_value_rows(g, order, face)
            xb = g.x[g.ext_id(anchors)]
            xb[:, face.axis] = g.face_coordinate(face)
            value = sc.value(xb)
            sel = np.flatnonzero(g.surface_on(face))
            for k in range(d):
                if cond is not None and k in cond.prescribed:
                    imposed = np.ones(anchors.shape[0], dtype=bool)
                    if k != face.axis:   # Remark 4's corner rule, as on the state-based boxes
                        imposed &= ~_corner_lines(conds, g, anchors, face.axis, k)
                    Rk = sp.coo_matrix(R[np.flatnonzero(imposed)])
                    rows.append(sp.csr_matrix((Rk.data, (Rk.row, Rk.col + k * ni)),
                                              shape=(int(imposed.sum()), d * ni)))
                    vals.append(value[imposed, k])
                else:
                    rows.append(face_rows[k * ns + sel])
                    vals.append(loads[sel, k])
    planes = _plane_rows(g, sc.planes, n_unk)
    rows += planes
    vals += [np.zeros(r.shape[0]) for r in planes]
    at = g.x[g.interior_ids] if anchor == "real" else np.r_[g.x[g.interior_ids], g.surface_x]
    op, op_rhs, coords, n_rows = bordered(K, rhs, rows, vals, np.tile(at, (d, 1)))
    counts.update(constraints=int(n_rows), unknowns=int(op.shape[0]))
    parts = {f.name: np.flatnonzero(~g.is_interior & (
        (g.index[:, f.axis] < 0) if f.side == 0
        else (g.index[:, f.axis] >= g.nodes_per_axis[f.axis]))) for f in box_faces(d)}
    return BondBoxSystem(model, np.zeros(d * g.n_ext), np.zeros(0, dtype=int), np.zeros(0),
                         parts, A=A, op=op, op_rhs=op_rhs, n_unknown=n_unk,
                         face_rows=face_rows, counts=counts, coords=coords)
