"""The treatments of the ``static-state`` problem family: how each one turns a
:class:`~pdverify.pd.problem.StaticProblem` (a state-based box with boundary conditions
keyed by face and component) into a :class:`~pdverify.pd.problem.LinearSystem`.

- ``none`` and every closure treatment (bond methods): truncated neighbourhoods; a
  prescribed component is imposed on the real nodes nearest its face at the exact value
  there (seed 000 and seed 001 §4: the uncorrected baseline), a face's traction as the
  force of each boundary cell face on the node of that cell (evaluated at the node or on
  the surface: ``load_point``).
- ``surface-nodes`` (seeds 001, 002): surface-node unknowns carry the conditions, the
  other surface-node equations are the force flux of Eq. (36).
- ``taylor-fictitious`` (seed 000): the fictitious layer by Taylor extrapolation, the
  conditions by Lagrange multipliers (Eq. 63): prescribed values at the boundary point of
  every line perpendicular to a face (Eq. 58), tractions as the force flux through every
  boundary cell face (Eq. 60 in 1D; the face-crossing bonds of seed 001 §3.4 in 2D/3D).
- ``mirror-nodes`` and ``pddo`` (seed 001 §5): through the modules of the same name;
  both choose the Dirichlet or the traction relation per boundary cell face, so a
  component prescribed on part of a face is imposed there only.

Each function returns the system; the scene solves it (``pdverify.solvers.front``) and
measures it. Node counts and the budget's footprint come from :func:`footprint`.
"""
from __future__ import annotations

import math

import numpy as np
import scipy.sparse as sp

from ..pd import StateBasedModel
from ..pd.bonds import unique_ids
from ..pd.build import build_model
from ..pd.closure import Closure
from ..pd.problem import FACES, LinearSystem
from ..solvers.policy import static_solver
from .mirror_nodes import MirrorNodes
from .pddo import pddo_system
from .surface_nodes import crossing_bonds, flux_rows, surface_node_closure
from .taylor_fictitious import boundary_value_rows, fictitious_closure, yields_component


# ------------------------------------------------------------------------------ helpers
def _model(problem, grid, closure) -> StateBasedModel:
    return build_model(problem.body, problem.stencil, problem.material, closure, grid=grid)


def _side_sign(face: int) -> float:
    return -1.0 if face % 2 == 0 else 1.0


def _matrix(model, P, solver, map_last: bool = False):
    """K (direct) or the augmented system with the nodal scalars as unknowns (``map_last``:
    ``StateBasedModel.unknown_rows``)."""
    return (model.stiffness(P, map_last=map_last) if solver == "direct"
            else model.augmented_stiffness(P, map_last=map_last))


def _coords(model, nodes):
    """Coordinates of the unknowns: d displacement components of ``nodes``, then the
    closure's nodal scalars (dilatations; PALS: two per node) of the real nodes."""
    g = model.grid
    x_int = g.x[g.interior_ids]
    scalars = model.A_theta.shape[0] // len(x_int)
    return np.r_[np.tile(nodes, (g.dim, 1)), np.tile(x_int, (scalars, 1))]


def _pad(rhs, K):
    return np.r_[rhs, np.zeros(K.shape[0] - rhs.size)]


def _residual_reaction(system_K, rhs_of):
    """Reaction through a face from the residual R = K x - rhs of the prescribed
    unknowns on it (normal component, tension positive)."""
    def reaction(x, face, dofs_of):
        R = system_K @ x - rhs_of
        return float(_side_sign(face) * np.sum(R[dofs_of(face)]))
    return reaction


def _traction_of(problem):
    """``traction(x, normal, face)`` of the mirror and PDDO modules: zero on free faces."""
    def traction(x, n, face):
        cond = problem.conditions.get(FACES[face])
        if cond is None or cond.traction is None:
            return np.zeros_like(x)
        return cond.traction(x, n)
    return traction


def footprint(kind: str, cells, m_ratio: float):
    """``(extra unknown nodes, fictitious nodes)`` of a treatment kind on a box of
    ``cells`` (the budget's estimate)."""
    nodes = math.prod(cells)
    fictitious = math.prod(c + 2 * m_ratio for c in cells) - nodes
    if kind == "surface":
        return 2 * sum(nodes / c for c in cells), fictitious
    if kind == "fictitious":
        return 0.0, fictitious
    return 0.0, 0.0


# ------------------------------------------------------------------------------ none
def assemble_plain(problem, closure: Closure | None = None) -> LinearSystem:
    """The uncorrected model (with a closure treatment's ``closure``), module docstring."""
    g = problem.body.grid(0)
    model = _model(problem, g, closure)
    if problem.shape is not None:
        return _plain_on_shape(problem, g, model)
    d, ni, nu_ = g.dim, g.n_interior, model.n_unknown_nodes
    solver = static_solver(problem.solver, d, d * nu_)
    P = model.equilibrium_rows()
    K = _matrix(model, P, solver)
    x_int = g.x[g.interior_ids]
    cells = g.index[g.interior_ids]
    rhs = np.zeros((nu_, d))
    rhs[:ni] = problem.body_load(x_int, model.node_volume[g.interior_ids][:, None])
    for face, _ in problem.loaded():
        axis, side = divmod(face, 2)
        on = cells[:, axis] == g.boundary_layer(face)
        xs = x_int[on].copy()
        if problem.load_point == "surface":
            xs[:, axis] = g.face_coordinate(face)
        nrm = np.zeros_like(xs)
        nrm[:, axis] = _side_sign(face)
        rhs[:ni][on] += problem.face_forces(face, xs, nrm, g.face_area)
    u_ref = problem.exact(x_int)
    fixed, values, by_face = [], [], {}
    for face, k, where in problem.prescribed():
        mask = cells[:, face // 2] == g.boundary_layer(face)
        if where is not None:
            mask &= where(cells)
        nodes = np.flatnonzero(mask)
        fixed.append(k * nu_ + nodes)
        values.append(u_ref[nodes, k])
        if k == face // 2:
            by_face[face] = k * nu_ + nodes
    return _eliminated(model, K, rhs, fixed, values, solver, x_int, by_face)


def boundary_nodes(g, shape):
    """The boundary of a shape's grid as the uncorrected model sees it: Gauss samples
    along every part (``Shape.samples``: points, arc-length weights, outward normals,
    part) and the real node each belongs to: the node of the cell that holds the sample
    (the sample moved 1e-9 h inward, so a sample on a cell face counts for the cell
    inside), or, where that cell's centre lies outside the shape (a sliver of a cut
    cell), the nearest real node. On a box's face this is the layer of real nodes
    nearest the face, as in :func:`assemble_plain`."""
    from scipy.spatial import cKDTree
    P, W, N, part = shape.samples(g.spacing)
    inner = P - 1e-9 * g.spacing * N
    cell = np.floor((inner - np.asarray(g.origin)) / g.spacing).astype(int)
    cell = np.clip(cell, 0, np.asarray(g.nodes_per_axis) - 1)
    node = g.interior_number[g.ext_id(cell)]
    lost = node < 0
    if np.any(lost):
        tree = cKDTree(g.lattice_x[g.interior_ids])
        node[lost] = tree.query(inner[lost])[1]
    return P, W, N, part, node


def _plain_on_shape(problem, g, model) -> LinearSystem:
    """:func:`assemble_plain` on a shape (``problem.shape``): a part's prescribed
    components on the real nodes its samples belong to (:func:`boundary_nodes`), at the
    exact value at each node; a part's traction as the sum over its samples of
    t(x, n) w thickness on the node each belongs to, x the sample (``load_point=surface``)
    or the node (``node``)."""
    d, ni, nu_ = g.dim, g.n_interior, model.n_unknown_nodes
    solver = static_solver(problem.solver, d, d * nu_)
    K = _matrix(model, model.equilibrium_rows(), solver)
    x_int = g.x[g.interior_ids]
    rhs = np.zeros((nu_, d))
    rhs[:ni] = problem.body_load(x_int, model.node_volume[g.interior_ids][:, None])
    P, W, N, part, node = boundary_nodes(g, problem.shape)
    names = problem.shape.part_names
    u_ref = problem.exact(x_int)
    fixed, values = [], []
    for name, cond in problem.conditions.items():
        on = part == names.index(name)
        if cond.traction is not None:
            at = P[on] if problem.load_point == "surface" else x_int[node[on]]
            force = cond.traction(at, N[on]) * (W[on] * problem.thickness)[:, None]
            for k in range(d):
                rhs[:ni, k] += np.bincount(node[on], force[:, k], ni)
        nodes = np.unique(node[on])
        for k in cond.prescribed:
            fixed.append(k * nu_ + nodes)
            values.append(u_ref[nodes, k])
    counts = _shape_counts(g, boundary_nodes=int(np.unique(node).size))
    return _eliminated(model, K, rhs, fixed, values, solver, x_int, {}, counts=counts)


def _shape_counts(g, **counts) -> dict:
    """A shape system's counts, with the jittered nodes that stayed put (if jittered)."""
    if g.jitter:
        counts["jitter_kept"] = int(g.jitter_kept)
    return counts


def _eliminated(model, K, rhs, fixed, values, solver, nodes, by_face, **extra):
    """The system of prescribed unknowns ``fixed`` (lists per condition) eliminated:
    the right-hand side (n_unknown_nodes, d) flattened component-major and padded for the
    augmented system's nodal scalars, the unknowns' coordinates (``nodes``: the unknown
    nodes' positions) for nested dissection, and the reaction of each face's prescribed
    normal components (``by_face``: face -> their unknowns)."""
    fixed, values = _sorted(fixed, values)
    rhs = rhs.T.ravel()
    if solver != "direct":
        rhs = _pad(rhs, K)
    react = _residual_reaction(K, rhs)
    return LinearSystem(model, K, rhs, fixed, values, model.n_unknown_nodes, solver=solver,
                        coords=None if solver == "direct" else _coords(model, nodes),
                        reaction=lambda x, face: react(x, face, by_face.__getitem__), **extra)


def _sorted(fixed, values):
    """The prescribed unknowns once each, sorted: a node nearest two faces that prescribe
    the same component (a corner of a clamped plate) is listed by both, with the same
    exact value; listed twice, its column would be eliminated twice."""
    if not fixed:
        return np.zeros(0, dtype=int), np.zeros(0)
    fixed, values = np.concatenate(fixed), np.concatenate(values)
    fixed, first = np.unique(fixed, return_index=True)
    return fixed, values[first]


# ------------------------------------------------------------------------------ surface nodes
def assemble_surface_nodes(problem, order: int) -> LinearSystem:
    """Seed 001's surface node method (module docstring)."""
    g = problem.body.grid(problem.stencil.reach)
    closure, flux = surface_node_closure(g, problem.stencil, order)
    return impose_on_surface_nodes(problem, g, closure, flux)


def impose_on_surface_nodes(problem, g, closure, flux) -> LinearSystem:
    """The system of a closure whose unknowns are the real nodes, then one surface node
    per boundary cell face (``closure.n_unknown_nodes``): a prescribed component is set
    on the surface nodes of its face (elimination), every other surface-node equation is
    its force flux (``flux``, seed 001 Eq. 36) equal to the face's load (zero on a free
    face). Shared by ``surface-nodes`` and any treatment that carries the conditions on
    surface nodes (a plugin's, e.g.)."""
    model = _model(problem, g, closure)
    d, ni, nu_ = g.dim, g.n_interior, model.n_unknown_nodes
    solver = static_solver(problem.solver, d, d * nu_)
    P = (model.equilibrium_rows() + flux_rows(model, flux)).tocsr()
    # in 3D the extrapolation rows are wide (order N: (N + 1)(2 ceil(N/2) + 1)^2 sources),
    # so the displacement map is multiplied in last; in 1D and 2D the products keep the
    # order the runs' numbers were made with (the gain there is small)
    K = _matrix(model, P, solver, map_last=d == 3)
    x_int = g.x[g.interior_ids]
    rhs = np.zeros((nu_, d))
    rhs[:ni] = problem.body_load(x_int, model.node_volume[g.interior_ids][:, None])
    xs, nrm = g.surface_x, g.surface_normal
    for face, _ in problem.loaded():
        sel = g.surface_face == face
        rhs[ni:][sel] = problem.face_forces(face, xs[sel], nrm[sel], g.face_area)
    us_ref = problem.exact(xs)
    fixed, values, by_face = [], [], {}
    for face, k, where in problem.prescribed():
        mask = g.surface_face == face
        if where is not None:
            mask &= where(g.surface_cell)
        nodes = np.flatnonzero(mask)
        fixed.append(k * nu_ + ni + nodes)
        values.append(us_ref[nodes, k])
    for face in range(2 * d):
        by_face[face] = (face // 2) * nu_ + ni + np.flatnonzero(g.surface_face == face)
    return _eliminated(model, K, rhs, fixed, values, solver, np.r_[x_int, xs], by_face,
                       extra_x=xs, counts={"surface_nodes": int(g.n_surface),
                                           "fictitious_nodes": int(g.n_ext - g.n_interior)})


# ------------------------------------------------------------------------------ Taylor
def assemble_taylor(problem, order: int, corners: str = "normal-only") -> LinearSystem:
    """Seed 000's Taylor-extrapolated fictitious nodes with the conditions as constraint
    rows by Lagrange multipliers (module docstring). A prescribed component takes the
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
    (:func:`~pdverify.corrections.taylor_fictitious.yields_component`). Both are pinned
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
                  for c in (problem.conditions.get(f) for f in FACES[:2 * d]) if c is not None)
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
    model = _model(problem, g, closure)
    ni = g.n_interior
    P = model.equilibrium_rows()
    solver = static_solver(problem.solver, d, d * ni)
    x_int = g.x[g.interior_ids]
    rhs = problem.body_load(x_int, model.node_volume[g.interior_ids][:, None]).T.ravel()
    K_b = model.bond_force_matrix() if d == 1 else None
    # the constraint rows act on the solver's unknowns: the real displacements (direct),
    # or those and the real dilatations (the augmented system of nested dissection)
    width = d * ni if solver == "direct" else (d + 1) * ni
    rows, vals = [], []
    if flux is not None:   # force of each boundary cell face from the unknowns
        Fs = _flux_of_unknowns(model, flux, g.n_surface, solver)
    for face in range(2 * d):
        axis, side = divmod(face, 2)
        cond = problem.conditions.get(FACES[face])
        R, anchors = boundary_value_rows(g, order, face)
        xb = g.x[g.ext_id(anchors)]
        xb[:, axis] = g.face_coordinate(face)
        exact = problem.exact(xb)
        cells_face = anchors
        if d > 1:
            sel = np.flatnonzero(g.surface_face == face)
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
                rows.append(sp.csr_matrix(sec))
                t = (cond.traction(xb, np.array([[_side_sign(face)]]))[0, 0]
                     if cond is not None and cond.traction is not None else 0.0)
                vals.append(np.array([_side_sign(face) * t * g.face_area
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
        return float((model.crossing_selector([g.face_coordinate(face)]) @ K_b @ x[:ni])[0])
    counts = {"fictitious_nodes": int(g.n_ext - g.n_interior), "constraints": int(B.shape[0])}
    none = np.zeros(0, dtype=int), np.zeros(0)
    if solver == "direct":
        return LinearSystem(model, model.stiffness(P), rhs, *none, ni, B=B, c=c,
                            reaction=reaction, counts=counts)
    # the bordered augmented system [[A, B^T], [B, 0]] (dilatations and multipliers as
    # unknowns) under nested dissection: each block couples within one horizon, so its
    # separators are half as thick as K's (on the seed-001 plate at h = 0.0125: 6.7 s
    # against 19.6 s for the Lagrange system of K, same machine, solutions equal to
    # 5e-13); in 3D the flux rows too act on the dilatations as unknowns (_bond_forces);
    # a multiplier sits at the mean position of the nodes its row involves
    A = model.augmented_stiffness(P)
    absB = abs(B).tocsr()
    at = (absB @ np.tile(x_int, (d + 1, 1))) / np.asarray(absB.sum(axis=1))
    B_theta = B[:, d * ni:]
    if B_theta.nnz == 0:
        M = sp.bmat([[A, B.T], [B, None]], format="csr")
        return LinearSystem(model, M, np.r_[rhs, np.zeros(A.shape[0] - rhs.size), c], *none,
                            ni, solver=solver, coords=np.r_[_coords(model, x_int), at],
                            reaction=reaction, counts=counts)
    # rows on the dilatations (3D): the multipliers' forces on the displacements must be
    # those of the direct system, (B_u + B_theta G)^T lambda with G = A_theta A_e A_U
    # (theta = G u); B^T alone would put B_theta^T lambda into the dilatation rows and
    # solve another problem (7 % apart on body3d-manufactured, order 2, h = 0.0625).
    # Kept sparse by mu = B_theta^T lambda as ni more unknowns at the nodes:
    # [[A, [G^T; 0], [B_u^T; 0]], [0, I, -B_theta^T], [B, 0, 0]]
    G = (model.A_theta @ (model.A_e @ model.A_U_full)).tocsr()
    zero_theta = sp.csr_matrix((ni, ni))
    M = sp.bmat([[A, sp.vstack([G.T, zero_theta]), sp.vstack([B[:, :d * ni].T,
                                                                sp.csr_matrix((ni, B.shape[0]))])],
                 [None, sp.identity(ni, format="csr"), -B_theta.T],
                 [B, None, None]], format="csr")
    return LinearSystem(model, M, np.r_[rhs, np.zeros(A.shape[0] - rhs.size + ni), c], *none,
                        ni, solver=solver, coords=np.r_[_coords(model, x_int), x_int, at],
                        reaction=reaction, counts=counts)


def _taylor_on_shape(problem, order: int) -> LinearSystem:
    """Taylor's fictitious nodes along the local normal of a shape, the conditions as
    constraint rows by Lagrange multipliers (``corrections.shape_fictitious``)."""
    from .shape_fictitious import condition_rows, normal_closure
    g = problem.body.grid(problem.stencil.reach)
    # the fictitious layer completes the lattice: every real node keeps its whole cell
    # (a cut cell's outside part is the fictitious nodes'), so that an affine field, or
    # a quadratic one on an isotropic stencil, is a solution as on the box
    g.node_volume[g.interior_ids] = g.volume
    model = _model(problem, g, normal_closure(g, problem.shape, order, problem.stencil))
    ni = g.n_interior
    x_int = g.x[g.interior_ids]
    rhs = problem.body_load(x_int, model.node_volume[g.interior_ids][:, None]).T.ravel()
    B, c, points = condition_rows(model, problem, order, boundary_nodes(g, problem.shape))
    counts = _shape_counts(g, fictitious_nodes=int(np.sum(g.kind == 1)),
                           constraints=int(B.shape[0]), boundary_points=int(points))
    none = np.zeros(0, dtype=int), np.zeros(0)
    # COLAMD: on the hole plate's bordered system at h = 0.0125 m (13,016 unknowns, 622
    # rows) SuperLU factors in 8.5-10 s with 24 M entries in L + U, against 42-52 s and
    # 72-76 M with the scenes' minimum degree on A + A^T (the zero block of the
    # multipliers defeats it)
    return LinearSystem(model, model.stiffness(model.equilibrium_rows()), rhs, *none, ni,
                        B=B, c=c, counts=counts, ordering="COLAMD")


def _bond_forces(model, solver, bonds=None):
    """Scalar bond forces (times beta V_a V_b) as a matrix on the solver's unknowns, the
    flux rows' factor. Direct: of the real displacements (``model.bond_force_matrix``,
    whose dilatation term couples nodes two horizons apart). Augmented (displacements,
    then the real dilatations): in 3D [K_e A_e A_U, K_theta A_Theta], each block within
    one horizon, which (with the mu unknowns of assemble_taylor) takes body3d-traction at
    h = 0.05 from 11.0 M to 6.2 M non-zeros, 5.3 GB to 2.1 GB and 42 s to 36 s (whole
    runs, /usr/bin/time; benchmarks/taylor3d.py times the parts); in 2D the bond forces of
    the displacements beside zero dilatation columns, as before: there the one-horizon
    form raised the plane-strain plate's condition estimate at h = 0.0125 from 2.1e5 to
    6.8e9 and moved its errors by 3e-7 (relative). ``bonds``: only these rows
    (ascending; the flux rows need the face-crossing bonds only)."""
    if solver == "direct":
        return model.bond_force_matrix(bonds)
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
    for other in range(2 * g.dim):
        cond = problem.conditions.get(FACES[other])
        if (yields_component(axis, other // 2, k) and cond is not None
                and cond.where is None and k in cond.prescribed):
            out |= anchors[:, other // 2] == g.boundary_layer(other)
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
    for other in (2 * k, 2 * k + 1):
        cond = problem.conditions.get(FACES[other])
        edge = anchors[:, k] == g.boundary_layer(other)
        if cond is not None and axis in cond.prescribed:
            edge &= ~(np.ones_like(edge) if cond.where is None else cond.where(anchors))
        out |= edge
    return out


def _flux_of_unknowns(model, flux, n_surface, solver):
    """The force of each boundary cell face from the unknowns: :func:`_surface_flux`
    times :func:`_bond_forces`, the latter of the face-crossing bonds only (the other
    columns of the flux rows are zero; the same products, row by row)."""
    used = unique_ids(flux[1])
    return (_surface_flux(model, flux, n_surface)[:, used]
            @ _bond_forces(model, solver, used)).tocsr()


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


# ------------------------------------------------------------------------------ mirror, PDDO
def assemble_mirror(problem, neumann: str, mirror_point: str,
                    gradient_at: str = "mirror") -> LinearSystem:
    """Seed 001 §5's mirror node method (``corrections.mirror_nodes``): the loads and
    constraints enter through the mirror relations only."""
    g = problem.body.grid(problem.stencil.reach)
    mirror = MirrorNodes(g, problem.stencil, dirichlet=problem.prescribed(),
                         exact=problem.exact, traction=_traction_of(problem),
                         moduli=problem.constants.moduli(), neumann=neumann,
                         mirror_point=mirror_point, gradient_at=gradient_at)
    model = _model(problem, g, mirror.closure())
    d, ni, nu_ = g.dim, g.n_interior, model.n_unknown_nodes
    solver = static_solver(problem.solver, d, d * nu_)
    P = model.equilibrium_rows()
    K = _matrix(model, P, solver)
    x_int = g.x[g.interior_ids]
    rhs = np.zeros((nu_, d))
    rhs[:ni] = problem.body_load(x_int, model.node_volume[g.interior_ids][:, None])
    U_c = mirror.constant_displacements()
    e_c = model.A_e @ U_c.T.ravel()
    rhs[:ni] -= model.rows_of_state(U_c, model.A_Theta @ (model.A_theta @ e_c),
                                    P).reshape(d, nu_).T
    rhs = rhs.T.ravel()
    if solver != "direct":
        rhs = _pad(rhs, K)
    return LinearSystem(model, K, rhs, np.zeros(0, dtype=int), np.zeros(0), nu_,
                        solver=solver,
                        coords=None if solver == "direct" else _coords(model, x_int),
                        counts={"fictitious_nodes": int(g.n_ext - g.n_interior)}, offset=U_c)


#: SuperLU's column ordering of the PDDO system (square, nonsymmetric, partial pivoting):
#: minimum degree on A + A^T. Whole runs, COLAMD against it (benchmarks/solvers.py
#: --only pddo, medians of 3 alternating, a busy machine): plate2d-plane-strain 1.6x,
#: 2.3x, 2.1x at h = 0.025, 0.02, 0.0125 (11.1 -> 5.3 s), body3d-traction 1.5x,
#: body3d-manufactured 1.0x; the exactness metrics stay round-off (max_error_pct
#: 4.1e-11 -> 7.3e-11 % at h = 0.0125).
PDDO_ORDERING = "MMD_AT_PLUS_A"


def assemble_pddo(problem, bulk_model: str = "lps") -> LinearSystem:
    """Seed 001 §5's PDDO boundary layer (``corrections.pddo``): its own square,
    nonsymmetric system on the uncorrected model, solved by a direct LU; ``bulk_model``
    (``pddo.BULK_MODELS``) governs the nodes beyond 2 delta."""
    g = problem.body.grid(0)
    model = _model(problem, g, None)
    x_int = g.x[g.interior_ids]
    body = problem.body_load(x_int, model.node_volume[g.interior_ids][:, None])
    A, rhs, counts = pddo_system(model, problem.prescribed(), problem.exact,
                                 _traction_of(problem), problem.constants.moduli(), body,
                                 bulk_model=bulk_model)
    return LinearSystem(model, A, rhs, np.zeros(0, dtype=int), np.zeros(0), g.n_interior,
                        solver="direct", counts=counts, ordering=PDDO_ORDERING)
