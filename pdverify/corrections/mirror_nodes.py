"""The mirror node method (MNM; Zhao, Jafarzadeh, Chen and Bobaru 2020, engrXiv
10.31224/osf.io/7z8qr; seed 001 §5.2) on a box of cell-centred nodes, state-based; on
the 2D shapes along the local normal (:class:`MirrorNodesOnShape`); on the bond-based
boxes that state their conditions at the surface (:func:`assemble_mirror_bond_box`: the
same relations with the bond-based lattice's moduli, :func:`bond_lattice_moduli`).

Seed 001 describes the method in words only, and the original was written for
diffusion. What we implement, and which parts are our reading (a guess where marked):

1. A fictitious layer around the body, as thick as the stencil's reach (delta rounded up
   to whole cells): every real node's neighbourhood is complete; m of every node is the
   complete one. *Reading:* the paper's 2 delta layer exists so that the fictitious
   nodes' dilatations can be computed from their own neighbourhoods; we give each
   fictitious node its mirror node's dilatation instead (the mirror relation applied to
   theta), which needs only delta and is exact whenever the mirror relations reproduce
   the field.
2. The peridynamic gradient of a fictitious node f: n_f = sum_j (x_j - x_f) beta V_j over
   the real nodes j of its neighbourhood (the first moment of the body seen from f),
   pointing towards the more complete neighbourhoods (§5.2). Unit n_f.
3. The mirror point: along n_f, the ray from x_f enters the box at x_B (the boundary
   point); the mirror point is x_f + 2 (x_B - x_f), the same distance on the other side.
   The mirror node m is the real node nearest to it (cell containing it; a point on a
   cell boundary goes to the upper cell). On a straight face the mirror point is a node;
   near corners n_f tilts and the mirror node is only the nearest one.
4. Mirror relations, per component k, with the faces that contain x_B, chosen per
   boundary cell face (per surface point), not per face:
   - a face prescribing u_k at x_B (Dirichlet): u_f,k = 2 g_k(x_B) - u_m,k (odd
     reflection: the mean of u_f and u_m is the boundary value; exact for fields linear
     along n). A face that prescribes u_k on part of it only (``where`` over its
     boundary cells, e.g. seed 001 Fig. 8's row next to x = 0) does so at the x_B in
     the boundary cells it names: x_B's cell is the real cell containing it (a point on
     a cell boundary goes to the upper cell, as for the mirror point). *Reading:* the
     paper's mirror relations hold per face; this is their pointwise form;
   - otherwise, also on the rest of a partly prescribed face (Neumann):
     u_f,k = u_m,k + (x_f - x_m) . G_k, G_ka = du_k/dx_a from the traction t of the
     face normal to axis a that contains x_B (0 if none):
     du_a/dx_a = s t_a / (lambda + 2 mu), du_k/dx_a = s t_k / mu (k != a), s = the
     sign of the outward normal. *Reading (a guess):* the local traction condition with
     the tangential derivatives neglected, the elastic analogue of the diffusion
     paper's flux condition. It is exact for shear-free faces whose tangential strain
     vanishes, and not otherwise (the plate's loaded face: d v / d y = p / (lambda + 2 mu)
     against the exact p (1 - nu^2) / E, 18 % low at nu = 0.3); seed 001 attributes the
     MNM's large y errors to 'the approximated imposition of the Neumann boundary
     conditions via the mirror nodes'.
   The loads enter through these relations only (no nodal forces); the constant parts
   (2 g, the traction terms) become the right-hand side.

Further readings of seed 001 §5.2 (params; defaults as above, issue 33's study on
plate2d-plane-strain):

- ``mirror_point``: ``nearest`` (above), ``corrected`` (u_f = 2 g - u_m + (x_f + x_m -
  2 x_B) . grad u_m for a Dirichlet component: the mismatch between the mirror node and
  the mirror point corrected by the node's gradient; our variant, exact for affine
  fields) or ``at-mirror-point`` (the Neumann step taken from the mirror point x*
  instead of the node, u_f = u_m + (x_f - x*) . G: the text's 'same (symmetric)
  distance from the boundary' read literally, the mirror node standing for x*. Exact
  beside a straight face, where x_m = x*; not near corners, where it is wrong by
  (x* - x_m) . G).
- ``gradient_at``: the cell whose central differences give the tangential derivatives
  of the full traction relation, ``mirror`` (x_m's) or ``boundary`` (x_B's: the
  traction condition holds at the boundary). The same for affine fields.
- Not implemented: the paper's 2 delta fictitious layer with the fictitious nodes'
  dilatations computed from their own neighbourhoods (the engine computes dilatations
  of real nodes only; fictitious ones come through ``dilatation_map``). With
  displacement relations exact for affine fields it gives the same affine field (every
  neighbourhood it adds is complete), so it cannot change the plate's result.
"""
from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np
import scipy.sparse as sp

from ..pd.build import build_model
from ..pd.closure import Closure, real_identity
from ..pd.problem import Face, LinearSystem, box_faces
from .assembly import model_of, padded, traction_of, unknown_coords
from .bond_fictitious import BondBoxSystem, _plane_rows, bond_force_matrix, bordered
from .surface_nodes import crossing_bonds, face_crossings
from .taylor_fictitious import _surface_flux


def peridynamic_gradient(grid, stencil) -> np.ndarray:
    """n_f (n_ext, d): sum over the real neighbours j of each node of (x_j - x_f) beta V_j,
    normalised (zero rows stay zero). One pass per stencil offset (vectorised over nodes)."""
    idx = grid.index
    shape = np.asarray(grid.nodes_per_axis)
    out = np.zeros((grid.n_ext, grid.dim))
    h = grid.spacing
    for k, beta in zip(stencil.offsets, stencil.beta):
        j = idx + k
        real = np.all((j >= 0) & (j < shape), axis=1)
        out[real] += (k * h) * (beta * grid.volume)
    norm = np.linalg.norm(out, axis=1)
    return np.divide(out, norm[:, None], out=np.zeros_like(out), where=norm[:, None] > 0)


def _box_entry(x, n, lo, hi):
    """Ray parameter t >= 0 where x + t n enters the box [lo, hi] (slab method)."""
    with np.errstate(divide="ignore", invalid="ignore"):
        t_lo = (lo - x) / n
        t_hi = (hi - x) / n
    t_enter = np.where(n > 0, t_lo, np.where(n < 0, t_hi, -np.inf))
    return np.maximum(np.max(t_enter, axis=1), 0.0)


def prescribed_parts(dirichlet):
    """``[(face, component, where)]`` of the prescribed components (``face``: a
    :class:`~pdverify.pd.faces.Face`): an item ``(face, component)`` (the face or its
    name) prescribes it on the whole face (``where=None``), an item ``(face, component,
    where)`` on the boundary cells where ``where(cells)`` (integer cell indices, (n, d))
    is true, as :class:`~pdverify.pd.problem.FaceCondition`."""
    return [(Face.named(item[0]), item[1], item[2] if len(item) > 2 else None)
            for item in dirichlet]


def prescribed_at(where, cells) -> np.ndarray | bool:
    """Which of the boundary ``cells`` a condition covers (``where=None``: all)."""
    return True if where is None else np.asarray(where(cells), dtype=bool)


def cells_of(grid, points) -> np.ndarray:
    """The real cell (integer index) containing each point, clipped into the body; a
    point on a cell boundary goes to the upper cell."""
    lo = np.asarray(grid.origin)
    return np.clip(np.floor((points - lo) / grid.spacing + 1e-9).astype(int), 0,
                   np.asarray(grid.nodes_per_axis) - 1)


NEUMANN_READINGS = ("full-traction", "normal-only")
MIRROR_POINTS = ("nearest", "corrected", "at-mirror-point")
GRADIENT_AT = ("mirror", "boundary")
#: order of the least-squares fit whose gradient gives a shape's tangential derivatives
#: (MirrorNodesOnShape): 2, exact for quadratics as the box's central differences are
#: along their axis (order 1, exact for affine fields only, is one-sided beside the
#: boundary: measured rel L2 0.218 / 0.251 on plate-hole / plate-l against 0.209 /
#: 0.233 at order 2, under gradient_at=mirror)
GRADIENT_ORDER = 2


def _difference_pairs(grid, cells, axis):
    """Real nodes either side of ``cells`` along ``axis`` (one-sided at the ends) and their
    distance: the central difference estimate of a derivative at those nodes."""
    n = grid.nodes_per_axis[axis]
    lo, hi = cells.copy(), cells.copy()
    lo[:, axis] = np.maximum(cells[:, axis] - 1, 0)
    hi[:, axis] = np.minimum(cells[:, axis] + 1, n - 1)
    return grid.ext_id(hi), grid.ext_id(lo), (hi[:, axis] - lo[:, axis]) * grid.spacing


class MirrorNodes:
    """Mirror nodes of a padded box grid and the affine map they give the fictitious nodes.

    ``dirichlet``: the prescribed (face, component) pairs, or (face, component, where)
    for part of a face (:func:`prescribed_parts`; a face by name or as a
    :class:`~pdverify.pd.faces.Face`), with ``exact(x) -> (n, d)`` giving the prescribed
    values g; ``traction(x, normal, face) -> (n, d)`` the applied traction of each face
    (``face``: a :class:`~pdverify.pd.faces.Face`; zero on free faces); ``moduli`` =
    (lambda, mu) of an isotropic material, or (C11, C12, C66) of a cubic one (the
    bond-based lattice's, :func:`bond_lattice_moduli`: C11 in lambda + 2 mu's place,
    C12 in lambda's, C66 in mu's); ``neumann``: how a traction becomes the gradient of
    the Neumann relation (:data:`NEUMANN_READINGS`); ``mirror_point``: the nearest node
    as it is, or with its mismatch corrected by its gradient, or taken as sitting at the
    mirror point (:data:`MIRROR_POINTS`); ``gradient_at``: the cell whose central
    differences give the tangential derivatives of the full traction relation, the
    mirror node's or the boundary point's (:data:`GRADIENT_AT`; module docstring).
    """

    def __init__(self, grid, stencil, dirichlet, exact, traction, moduli,
                 neumann="full-traction", mirror_point="nearest", gradient_at="mirror"):
        for name, value, allowed in (("neumann", neumann, NEUMANN_READINGS),
                                     ("mirror_point", mirror_point, MIRROR_POINTS),
                                     ("gradient_at", gradient_at, GRADIENT_AT)):
            if value not in allowed:
                raise ValueError(f"{name}={value!r}; allowed: {', '.join(allowed)}")
        g, d, h = grid, grid.dim, grid.spacing
        self.grid = g
        fict = np.flatnonzero(~g.is_interior)
        x = g.x[fict]
        n = peridynamic_gradient(g, stencil)[fict]
        lo = np.asarray(g.origin)
        hi = lo + np.asarray(g.lengths)
        t = _box_entry(x, n, lo, hi)
        xB = x + t[:, None] * n
        star = x + 2.0 * t[:, None] * n
        cell = cells_of(g, star)
        mirror = g.ext_id(cell)
        self.fictitious, self.mirror, self.boundary_point = fict, mirror, xB
        # the step of the Neumann relation: x_f - x_m, or x_f - x* when the mirror node
        # is taken as sitting at the mirror point x* (then wrong by x* - x_m near corners)
        step = x - (star if mirror_point == "at-mirror-point" else g.x[mirror])
        # (lambda, mu) of an isotropic material, or (C11, C12, C66) of a cubic one (the
        # bond-based lattice: bond_lattice_moduli); lambda + 2 mu, lambda, mu play C11,
        # C12, C66 in the traction relation
        if len(moduli) == 3:
            c11, lam, mu = moduli
        else:
            lam, mu = moduli
            c11 = lam + 2 * mu
        tol = 1e-9 * h
        nf = fict.size
        faces = box_faces(d)
        on_face = {face: np.abs(xB[:, face.axis] - g.face_coordinate(face)) < tol
                   for face in faces}
        dirichlet_k = np.zeros((nf, d), dtype=bool)
        const_d = np.zeros((nf, d))                  # 2 g of the Dirichlet components
        const = np.zeros((nf, d))                    # traction terms of the Neumann ones
        # which x_B each prescribed component holds at: on its face, in the boundary
        # cells it covers
        parts = prescribed_parts(dirichlet)
        boundary_cells = cells_of(g, xB)
        hits = [on_face[face] & prescribed_at(where, boundary_cells)
                for face, _, where in parts]
        # the boundary values there only (elsewhere x_B can lie outside the body, where a
        # FEM reference is not defined, or off the prescribed part of a face)
        used = np.zeros(nf, dtype=bool)
        for hit in hits:
            used |= hit
        g_exact = np.zeros((nf, d))
        if np.any(used):
            g_exact[used] = exact(xB[used])
        for (_, k, _), hit in zip(parts, hits):
            dirichlet_k[hit, k] = True
            const_d[hit, k] = 2.0 * g_exact[hit, k]
        # the gradient D_kb of component k along axis b at the mirror node, as
        # constant + sum over (node, component) entries: lists per (k, b)
        at = cell if gradient_at == "mirror" else boundary_cells
        pairs = [_difference_pairs(g, at, b) for b in range(d)]
        full = neumann == "full-traction"
        entries = []   # (fict mask, k, node ids, component j, coefficient per fict)
        dirichlet_entries = []

        def fd(mask, k, j, b, coef, into=entries):
            """coef * du_j/dx_b (central difference at the mirror) into row k."""
            p_, q_, dist = pairs[b]
            c = coef / dist
            into.append((mask, k, p_, j, c))
            into.append((mask, k, q_, j, -c))

        side_on = np.full((nf, d), -1)              # the side of the face (per axis) x_B lies on
        for face in faces:
            side_on[on_face[face], face.axis] = face.side
        for b in range(d):
            on_b = side_on[:, b] >= 0
            sgn = np.where(side_on[:, b] == 0, -1.0, 1.0)
            tr = np.zeros((nf, d))
            for face in (Face.at(b, 0), Face.at(b, 1)):
                hit = side_on[:, b] == face.side
                if np.any(hit):
                    nrm = np.zeros((int(hit.sum()), d))
                    nrm[:, b] = face.sign
                    tr[hit] = traction(xB[hit], nrm, face)
            for k in range(d):
                w = step[:, b]                       # D_kb enters with (x_f - x_m)_b
                if k == b:   # sigma_bb = (lam + 2 mu) u_b,b + lam sum_j u_j,j = s t_b
                    const[:, k] += np.where(on_b, w * sgn * tr[:, b] / c11, 0.0)
                    if full:
                        for j in range(d):
                            if j != b:
                                fd(on_b, k, j, j, -w * lam / c11)
                else:        # sigma_kb = mu (u_k,b + u_b,k) = s t_k
                    const[:, k] += np.where(on_b, w * sgn * tr[:, k] / mu, 0.0)
                    if full:
                        fd(on_b, k, b, k, -w)
                if full:     # an axis with no face at x_B: the gradient of the mirror
                    fd(~on_b, k, k, b, w)
        if mirror_point == "corrected":  # u_f = 2 g - u_m + (x_f + x_m - 2 x_B) . grad u_m
            off = x + g.x[mirror] - 2.0 * xB
            for k in range(d):
                for b in range(d):
                    fd(np.ones(nf, dtype=bool), k, k, b, off[:, b], into=dirichlet_entries)
        self.dirichlet_k, self.entries = dirichlet_k, entries
        self.dirichlet_entries = dirichlet_entries
        self.const = np.where(dirichlet_k, const_d, const)

    def displacement_map(self) -> sp.csr_matrix:
        """(d n_ext) x (d n_real), component-major: identity on real nodes; on a
        fictitious node -u_m,k for a Dirichlet component, u_m,k plus the gradient terms
        for a Neumann one."""
        g, d = self.grid, self.grid.dim
        ni, ne = g.n_interior, g.n_ext
        num = g.interior_number
        f, m = self.fictitious, self.mirror
        rows, cols, vals = [], [], []
        for k in range(d):
            rows += [k * ne + g.interior_ids, k * ne + f]
            cols += [k * ni + np.arange(ni), k * ni + num[m]]
            vals += [np.ones(ni), np.where(self.dirichlet_k[:, k], -1.0, 1.0)]
        for entries, want in ((self.entries, False), (self.dirichlet_entries, True)):
            for mask, k, nodes, j, coef in entries:
                use = mask & (self.dirichlet_k[:, k] == want) & (coef != 0)
                rows.append(k * ne + f[use])
                cols.append(j * ni + num[nodes[use]])
                vals.append(coef[use])
        return sp.csr_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))),
                             shape=(d * ne, d * ni))

    def dilatation_map(self) -> sp.csr_matrix:
        """n_ext x n_real: real nodes their own, fictitious nodes their mirror's."""
        g = self.grid
        return (real_identity(g)
                + sp.csr_matrix((np.ones(self.fictitious.size),
                                 (self.fictitious, g.interior_number[self.mirror])),
                                shape=(g.n_ext, g.n_interior))).tocsr()

    def constant_displacements(self) -> np.ndarray:
        """The affine part of the fictitious displacements, (n_ext, d); zero on real nodes."""
        out = np.zeros((self.grid.n_ext, self.grid.dim))
        out[self.fictitious] = self.const
        return out

    def closure(self) -> Closure:
        return Closure(weighted_volume="complete",
                       displacement_map_full=self.displacement_map(),
                       dilatation_map=self.dilatation_map())


class MirrorNodesOnShape(MirrorNodes):
    """Mirror nodes on a 2D or 3D shape (issue 55; our generalisation of seed 001 §5.2, say
    "mirror nodes along the normal"): the box's construction with the local normal.

    - every fictitious node f (``ShapeGrid``'s layer; the real nodes keep whole cells,
      as in the Taylor extension on shapes) has its closest boundary point x_B, on a
      part with outward normal n there; the mirror point is x* = 2 x_B - x_f, the
      reflection of f across the part's tangent line at x_B (through the vertex when
      x_B is a corner, as on the box's corners), the mirror node m the real node
      nearest x*;
    - a component prescribed on a part that holds x_B (within 1e-9 h; at a vertex
      either part): u_f = 2 g(x_B) - u_m (odd reflection), ``corrected``: plus
      (x_f + x_m - 2 x_B) . grad u_m;
    - every other component (Neumann): u_f = u_m + G (x_f - x_m) (``at-mirror-point``:
      the step x_f - x*), G the gradient at x_B whose traction sigma(G) n is the
      applied one (zero on a free part): with the tangent tau and the tangential
      derivative b = G tau, G = a n^T + b tau^T, a = alpha n + beta tau, alpha = (t.n -
      lam b.tau) / (lam + 2 mu), beta = t.tau / mu - b.n; ``full-traction``: b from a
      least-squares fit of order :data:`GRADIENT_ORDER` of the real nodes about the
      mirror node (``gradient_at=mirror``) or x_B (``boundary``), where the box takes
      central differences along lattice lines; ``normal-only``: b = 0 (the box's
      reading);
    - dilatations: the mirror node's; m complete.

    Exactness: an affine field with ``mirror_point=corrected`` and ``full-traction`` is
    reproduced to round-off on the hole and the L, every part prescribed or loaded by
    the field's traction, on any stencil (the relations are exact for it and the real
    nodes' neighbourhoods complete). With the method's ``nearest`` mirror node a
    Dirichlet relation is exact only where x_m = x*: across a straight part of cell
    faces or through a vertex of cell corners (the box, the whole L: exact there), not
    along an arc (the hole with every part prescribed: 3.2e-3 relative; the test
    shows it); no reading is exact for quadratic fields (a first-order relation; the
    box's neither: 7.2e-4 on the hole, corrected). A bond that bridges a re-entrant
    notch (its real end does not see the fictitious node's closest point through the
    body, ``Shape.hides``) reads its own relation, about the point of the part its real
    end sees (``shape_fictitious.seen_points``; ``Closure.shadow`` per component), as
    the Taylor extension does: the relations stay exact for affine fields.

    On a 3D shape (``pdverify.pd.shapes3d``; our generalisation again) the same
    construction with the tangent plane: x* = 2 x_B - x_f reflects f across the tangent
    plane at x_B (a plane part, the mantle's tangent plane, the sphere's), the odd
    reflection unchanged, and the traction relation G = a n^T + T with T = H P the fit's
    gradient H on the tangent plane (P = I - n n^T) and the normal derivative a = n
    (t.n - lam tr T) / (lam + 2 mu) + P t / mu - P T^T n, the unique a with sigma(G) n
    = t (the 2D formula is its case P = tau tau^T); ``normal-only``: T = 0. The fits are
    3D quadratics over the 40 nearest real nodes (``shape_fictitious.neighbours``).
    Exactness kept: the affine field with ``corrected`` and ``full-traction`` to
    round-off on the quarter cylinder and the cavity octant, every part prescribed or
    loaded by the field's traction (tests/shapes/test_shape3d_methods.py); the method's
    ``nearest`` node is off across the mantle and the sphere (x_m != x*) for a prescribed
    component, not for a traction (its step is x_f - x_m). Bridging bonds as in 2D
    (``Shape3D.hides``: exact crossings of the planes, the mantle and the sphere): none
    on the convex quarter cylinder; on the cavity octant a real node may see a
    fictitious node's closest point on a symmetry plane's rim only through the cavity,
    49 of 93 624 real-fictitious bonds at block3d-cavity's h = 0.1
    (``benchmarks/shape3d_bridging.py``), which read their own relation (they move that
    scene's mirror-node rel L2 from 0.076 to 0.080)."""

    def __init__(self, grid, problem, neumann="full-traction", mirror_point="nearest",
                 gradient_at="mirror"):
        from ..pd.bonds import bond_pairs
        from ..pd.closure import uncut
        from .shape_fictitious import bridging, seen_points
        for name, value, allowed in (("neumann", neumann, NEUMANN_READINGS),
                                     ("mirror_point", mirror_point, MIRROR_POINTS),
                                     ("gradient_at", gradient_at, GRADIENT_AT)):
            if value not in allowed:
                raise ValueError(f"{name}={value!r}; allowed: {', '.join(allowed)}")
        g, shape = grid, problem.shape
        self.grid, self.problem = g, problem
        self.readings = (neumann, mirror_point, gradient_at)
        fict = np.flatnonzero(g.kind == 1)
        xB, nrm, _, part = shape.closest(g.x[fict])
        self.fictitious = fict
        rel = self._relations(g.x[fict], xB, nrm, part)
        self.mirror, self.boundary_point = rel["mirror"], xB
        self.dirichlet_k, self.entries = rel["dirichlet_k"], rel["entries"]
        self.dirichlet_entries, self.const = rel["dirichlet_entries"], rel["const"]
        # bonds that bridge a re-entrant notch: their own relation about the point the
        # real end sees (as the Taylor extension's ``Closure.shadow``)
        st = problem.stencil
        a, b, _ = bond_pairs(g.ext_shape, st.offsets[st.half])
        keep = (g.is_interior[a] | g.is_interior[b]) & ~g.is_void[a] & ~g.is_void[b]
        pairs, real, far = bridging(g, shape, a, b, uncut(g, a, b, keep))
        self.shadow_pairs, self.shadow_rel = pairs, None
        if pairs.size:
            p, ppart = seen_points(g, shape, real, far)
            pn = np.zeros_like(p)
            for k, q in enumerate(shape.parts):
                on = ppart == k
                if on.any():
                    pn[on] = q.closest(p[on])[1]
            self.shadow_rel = self._relations(g.x[far], p, pn, ppart)
        self.counts = {"fictitious_nodes": int(fict.size), "bridging_bonds": int(pairs.size)}

    def _relations(self, x, xB, nrm, part) -> dict:
        """The mirror relations of fictitious positions ``x`` about boundary points
        ``xB`` on ``part`` with outward normals ``nrm`` (class docstring): the mirror
        nodes (grid ids), the Dirichlet components, the gradient entries and the
        constants."""
        from scipy.spatial import cKDTree

        from .shape_fictitious import fit
        g, problem, d, h = self.grid, self.problem, self.grid.dim, self.grid.spacing
        neumann, mirror_point, gradient_at = self.readings
        shape = problem.shape
        star = 2.0 * xB - x
        x_real = g.x[g.interior_ids]
        mirror_real = cKDTree(x_real).query(star)[1]
        mirror = g.interior_ids[mirror_real]
        nf = len(x)
        lam, mu = problem.constants.moduli()
        names = shape.part_names
        # the parts that hold x_B (a vertex: both) and their conditions
        holds = np.stack([np.linalg.norm(q.closest(xB)[0] - xB, axis=1) <= 1e-9 * h
                          for q in shape.parts], axis=1)
        holds[np.arange(nf), part] = True
        dirichlet_k = np.zeros((nf, d), dtype=bool)
        for name, cond in problem.conditions.items():
            for k in cond.prescribed:
                dirichlet_k[:, k] |= holds[:, names.index(name)]
        used = dirichlet_k.any(axis=1)
        g_exact = np.zeros((nf, d))
        if used.any():
            g_exact[used] = problem.exact(xB[used])
        t = np.zeros((nf, d))
        for name, cond in problem.conditions.items():
            on = part == names.index(name)
            if cond.traction is not None and on.any():
                t[on] = cond.traction(xB[on], nrm[on])
        step = x - (star if mirror_point == "at-mirror-point" else x_real[mirror_real])
        entries, dirichlet_entries = [], []
        centre = x_real[mirror_real] if gradient_at == "mirror" else xB
        nodes, _, grad = fit(x_real, centre, centre, GRADIENT_ORDER, h, gradient=True)
        ids = g.interior_ids[nodes]
        all_f = np.ones(nf, dtype=bool)
        ns_ = np.einsum("fi,fi->f", nrm, step)
        if d == 3:
            const_n, entries = self._relations_3d(nrm, step, ns_, t, ids, grad, neumann)
        else:
            tau = np.c_[-nrm[:, 1], nrm[:, 0]]
            ts_ = np.einsum("fi,fi->f", tau, step)
            tn, tt = np.einsum("fi,fi->f", t, nrm), np.einsum("fi,fi->f", t, tau)
            # the constant part of G step: a's traction terms times n . step
            const_n = ns_[:, None] * (tn[:, None] / (lam + 2 * mu) * nrm
                                      + tt[:, None] / mu * tau)
        if neumann == "full-traction" and d == 2:
            wt = np.einsum("fl,flk->fk", tau, grad)             # b_j = wt . u_j
            for k in range(d):
                for j in range(d):
                    c = (ns_ * (-lam / (lam + 2 * mu) * nrm[:, k] * tau[:, j]
                                - tau[:, k] * nrm[:, j]) + (k == j) * ts_)
                    for col in range(ids.shape[1]):
                        entries.append((all_f, k, ids[:, col], j, c * wt[:, col]))
        if mirror_point == "corrected":   # + (x_f + x_m - 2 x_B) . grad u_m,k
            off = x + x_real[mirror_real] - 2.0 * xB
            mnodes, _, mgrad = fit(x_real, x_real[mirror_real], x_real[mirror_real],
                                   GRADIENT_ORDER, h, gradient=True)
            mids = g.interior_ids[mnodes]
            wo = np.einsum("fl,flk->fk", off, mgrad)
            for k in range(d):
                for col in range(mids.shape[1]):
                    dirichlet_entries.append((all_f, k, mids[:, col], k, wo[:, col]))
        return dict(mirror=mirror, dirichlet_k=dirichlet_k, entries=entries,
                    dirichlet_entries=dirichlet_entries,
                    const=np.where(dirichlet_k, 2.0 * g_exact, const_n))

    def _relations_3d(self, nrm, step, ns_, t, ids, grad, neumann):
        """The Neumann relation's constant and gradient entries on a 3D shape (class
        docstring): G = a n^T + T, T = H P the fit's gradient H on the tangent plane
        (P = I - n n^T), a = n (t.n - lam tr T) / (lam + 2 mu) + P t / mu - P T^T n, so
        (G step)_k = const_k + sum_jl c_kjl H_jl with c_kjl = n.step (-lam / (lam + 2
        mu) n_k P_lj - n_j P_kl) + delta_kj (P step)_l; ``normal-only``: T = 0."""
        lam, mu = self.problem.constants.moduli()
        nf, d = len(nrm), 3
        P = np.eye(d)[None] - nrm[:, :, None] * nrm[:, None, :]             # (F, d, d)
        tn = np.einsum("fi,fi->f", t, nrm)
        const_n = ns_[:, None] * (tn[:, None] / (lam + 2 * mu) * nrm
                                  + np.einsum("fki,fi->fk", P, t) / mu)
        entries = []
        if neumann != "full-traction":
            return const_n, entries
        all_f = np.ones(nf, dtype=bool)
        Ps = np.einsum("fli,fi->fl", P, step)
        eye = np.eye(d)
        for k in range(d):
            for j in range(d):
                c = (ns_[:, None] * (-lam / (lam + 2 * mu) * nrm[:, k, None] * P[:, :, j]
                                     - nrm[:, j, None] * P[:, k, :])
                     + eye[k, j] * Ps)                                        # (F, l)
                w = np.einsum("fl,flc->fc", c, grad)
                for col in range(ids.shape[1]):
                    entries.append((all_f, k, ids[:, col], j, w[:, col]))
        return const_n, entries

    def _rows_of(self, rel, rows, n_rows) -> sp.csr_matrix:
        """(d n_rows) x (d n_real), component-major: the relations ``rel`` on the node
        rows ``rows`` (nothing elsewhere)."""
        g, d = self.grid, self.grid.dim
        ni, num = g.n_interior, g.interior_number
        m, dk = rel["mirror"], rel["dirichlet_k"]
        R, C, V = [], [], []
        for k in range(d):
            R.append(k * n_rows + rows)
            C.append(k * ni + num[m])
            V.append(np.where(dk[:, k], -1.0, 1.0))
        for entries, want in ((rel["entries"], False), (rel["dirichlet_entries"], True)):
            for mask, k, nodes, j, coef in entries:
                use = mask & (dk[:, k] == want) & (coef != 0)
                R.append(k * n_rows + rows[use])
                C.append(j * ni + num[nodes[use]])
                V.append(coef[use])
        return sp.csr_matrix((np.concatenate(V), (np.concatenate(R), np.concatenate(C))),
                             shape=(d * n_rows, d * ni))

    def shadow(self):
        """``Closure.shadow`` of the bridging bonds (per component), or None."""
        rel = self.shadow_rel
        if rel is None:
            return None
        g = self.grid
        k = self.shadow_pairs.size
        T = sp.csr_matrix((np.ones(k), (np.arange(k), g.interior_number[rel["mirror"]])),
                          shape=(k, g.n_interior))
        return self.shadow_pairs, self._rows_of(rel, np.arange(k), k), T

    def constant_displacements(self) -> np.ndarray:
        """The affine part of the fictitious displacements, (n_ext, d), with the shadow
        ends' appended (``Closure.shadow``); zero on real nodes."""
        out = super().constant_displacements()
        if self.shadow_rel is not None:
            out = np.r_[out, self.shadow_rel["const"]]
        return out

    def closure(self) -> Closure:
        return Closure(weighted_volume="complete",
                       displacement_map_full=self.displacement_map(),
                       dilatation_map=self.dilatation_map(), shadow=self.shadow())


# ------------------------------------------------------------------------------ static assembly
def assemble_mirror(problem, neumann: str, mirror_point: str,
                    gradient_at: str = "mirror") -> LinearSystem:
    """Seed 001 §5's mirror node method (:class:`MirrorNodes`) on a ``static-state``
    problem: the loads and constraints enter through the mirror relations only."""
    g = problem.body.grid(problem.stencil.reach)
    if problem.shape is not None:
        g.node_volume[g.interior_ids] = g.volume      # as the Taylor extension on shapes
        mirror = MirrorNodesOnShape(g, problem, neumann=neumann, mirror_point=mirror_point,
                                    gradient_at=gradient_at)
    else:
        mirror = MirrorNodes(g, problem.stencil, dirichlet=problem.prescribed(),
                             exact=problem.exact, traction=traction_of(problem),
                             moduli=problem.constants.moduli(), neumann=neumann,
                             mirror_point=mirror_point, gradient_at=gradient_at)
    model = model_of(problem, g, mirror.closure())
    d, ni, nu_ = g.dim, g.n_interior, model.n_unknown_nodes
    P = model.equilibrium_rows()
    K = model.augmented_stiffness(P)      # the solver layer forms what it needs
    x_int = g.x[g.interior_ids]
    rhs = np.zeros((nu_, d))
    rhs[:ni] = problem.body_load(x_int, model.node_volume[g.interior_ids][:, None])
    U_c = mirror.constant_displacements()
    e_c = model.A_e @ U_c.T.ravel()
    rhs[:ni] -= model.rows_of_state(U_c, model.A_Theta @ (model.A_theta @ e_c),
                                    P).reshape(d, nu_).T
    rhs = rhs.T.ravel()
    scalars = K.shape[0] - rhs.size
    rhs = padded(rhs, K)
    return LinearSystem(model, K, rhs, np.zeros(0, dtype=int), np.zeros(0), nu_,
                        solver=problem.solver, coords=unknown_coords(model, x_int),
                        scalars=scalars,
                        counts=getattr(mirror, "counts", None)
                        or {"fictitious_nodes": int(g.n_ext - g.n_interior)}, offset=U_c)


# ------------------------------------------------------------------ bond-based boxes (bond-box)
def bond_lattice_moduli(stencil, c, influence, horizon, spacing) -> tuple[float, float, float]:
    """(C11, C12, C66) of the bond-based lattice in the bulk (a complete neighbourhood),
    the moduli of the mirror nodes' traction relation on a bond-based box.

    Derivation. A bond of the stencil's offset k (length r = |k| h, unit n, weight
    beta_k, cell volume V = h^d) under the homogeneous strain eps stretches by
    e = r n.eps.n and carries the force density c omega(r) e / r V on each end; half of
    its energy c omega(r) e^2 / (2 r) V goes to each end, so a bulk node's energy
    density is W = (c / 4) sum_k omega(r) r beta_k V (n.eps.n)^2 = C_abcd eps_ab eps_cd / 2
    with C_abcd = (c / 2) sum_k w_k n_a n_b n_c n_d, w_k = omega(r) r beta_k V: fully
    symmetric in its four indices (central pairwise forces), so C12 = C_xxyy equals
    C66 = C_xyxy (the Cauchy relation), and the square or cubic stencil gives cubic
    symmetry: C11 = C_xxxx = C_yyyy (= C_zzzz), C12 = C_xxyy = C_xxzz = C_yyzz. The
    traction on a face of normal e_b is then sigma_bb = C11 u_b,b + C12 sum_(j != b)
    u_j,j and sigma_kb = C66 (u_k,b + u_b,k), the relation :class:`MirrorNodes` takes
    with (lambda + 2 mu, lambda, mu) -> (C11, C12, C66). It is not the continuum's:
    C11 = 3 C12 (isotropy) only in the limit of a fine stencil (3.3 % off at m = 6, whole
    cells; ``stiffness2d-sheet``'s ``bulk_anisotropy_c11_3c12_pct``). The same sums as
    the tension sheet's reference moduli (``scenes.sheets.lattice_moduli``); tested
    against the model's own energy density under homogeneous strains
    (``tests/treatments/test_mirror_bond.py``)."""
    offsets = np.asarray(stencil.offsets, dtype=float)
    length = np.linalg.norm(offsets, axis=1)
    r, n = length * spacing, offsets / length[:, None]
    w = influence.omega(r, horizon) * r * np.asarray(stencil.beta) * spacing ** offsets.shape[1]
    c11 = 0.5 * c * np.sum(w * n[:, 0] ** 4)
    # a 1D bar has no transverse component: sigma = C11 u' alone
    c12 = 0.5 * c * np.sum(w * n[:, 0] ** 2 * n[:, 1] ** 2) if n.shape[1] > 1 else 0.0
    return float(c11), float(c12), float(c12)


@dataclass
class MirrorBondBoxSystem(BondBoxSystem):
    """A ``bond-box`` system whose grid displacements are affine in its unknowns,
    ``A x + offset`` (the mirror relations' constants: the prescribed values' 2 g and the
    tractions' terms); the model's unknowns are every grid node (identity map), so
    :attr:`unknowns` after a solve is the whole grid's displacement and ``face_rows``
    act on it. The equations (``op``, ``op_rhs``, ``face_rows``) are built on the first
    solve (``rows``): the stiffness boxes only apply the relations."""

    offset: np.ndarray = None
    rows: object = None

    def _built(self):
        if self.op is None and self.rows is not None:
            self.op, self.op_rhs, self.face_rows, self.coords, more = self.rows()
            self.counts.update(more)

    def solve(self, where: str):
        self._built()
        u, info = super().solve(where)
        self.unknowns = u + self.offset
        return self.unknowns, info

    def face_force(self, face: str) -> np.ndarray:
        self._built()
        return super().face_force(face)

    def grid_displacement(self, x_real) -> np.ndarray:
        """Every grid node's displacement when the real nodes carry ``x_real``
        (component-major): the relations applied, no solve."""
        return self.A @ np.asarray(x_real, dtype=float) + self.offset


def assemble_mirror_bond_box(problem, neumann: str = "full-traction",
                             mirror_point: str = "nearest", gradient_at: str = "mirror"):
    """Seed 001 §5.2's mirror nodes on a bond-based box (the ``bond-box`` family: a
    :class:`~pdverify.pd.problem.BondProblem` with its conditions stated at the surface,
    :class:`~pdverify.pd.problem.SurfaceConditions`); our reading for bond-based PD.

    The grid is ``bond_fictitious``' (cell-centred, whole cells, a fictitious layer of the
    stencil's reach; the bonds with a real end and the fictitious pairs crossing a
    boundary cell face). The fictitious displacements are :class:`MirrorNodes`' relations
    on it, face by face as on the state-based boxes: a prescribed component by the odd
    reflection about the boundary value, u_f = 2 g(x_B) - u_m; every other one (a
    traction or free face) by the even reflection with the Neumann step, u_f = u_m +
    (x_f - x_m) . G with G from the face's traction through the bond-based lattice's own
    moduli (:func:`bond_lattice_moduli`: C11, C12, C66 of the stencil, not the LPS
    constants). The unknowns are the real displacements, the equations the real nodes'
    equilibrium with the relations' constants (2 g and the traction terms) on the
    right-hand side: the loads and the prescribed values enter through the relations
    only, as on the state-based boxes. A scene's symmetry planes
    (``SurfaceConditions.planes``) are constraint rows by Lagrange multipliers, as for
    Taylor's and the surface nodes' (``bond_fictitious._plane_rows``). The square system
    is not symmetric (the reflections enter the real equations) and goes to the sparse LU.

    Exactness: the relations reproduce an affine field whose tractions are the faces'
    (and whose values are the prescribed ones) wherever the mirror point is a node
    (straight faces; the ``corrected`` mirror point everywhere), so the real nodes'
    neighbourhoods are the bulk lattice's and the field is a solution to round-off: the
    tension sheet's uniform stress against the lattice's moduli, the stiffness boxes'
    homogeneous strains with ``corrected`` (``tests/treatments/test_mirror_bond.py``).
    With the method's ``nearest`` mirror node a prescribed face is exact only where the
    mirror point is a node: not at the boxes' edges and corners, where the stiffness
    boxes' surface energy misses by a few per cent (as on the state-based boxes). What a
    non-affine field shows: the traction-free condition is the first-order even
    reflection, not a flux row as Taylor's, so on the clamped sheet each free side
    carries a normal force through its boundary cell faces (7.7 kN against the clamp's
    196 kN; the four faces' forces still balance to round-off, the test above)."""
    sc = problem.surface
    if sc is None:
        raise ValueError("the problem states no surface conditions")
    body = replace(problem.body, placement="cell-centred", boundary_volume="partial")
    g = body.grid(problem.stencil.reach)
    d, ni, ne, ns = g.dim, g.n_interior, g.n_ext, g.n_surface
    keep, _ = crossing_bonds(g, problem.stencil)
    # the model's unknowns: every grid node (the relations are affine, not linear)
    model = build_model(body, problem.stencil, problem.material,
                        Closure(keep=keep, displacement_map=sp.identity(ne, format="csr"),
                                n_unknown_nodes=ne), grid=g)
    moduli = bond_lattice_moduli(problem.stencil, model.c, model.influence, model.horizon,
                                 g.spacing)
    faces = dict(sc.faces)

    def traction(x, normal, face):
        cond = faces.get(Face.named(face).name)
        if cond is None or cond.traction is None:
            return np.zeros_like(x)
        return cond.traction(x, normal)

    mirror = MirrorNodes(g, problem.stencil,
                         [(name, k) for name, cond in faces.items() for k in cond.prescribed],
                         sc.value, traction, moduli, neumann=neumann,
                         mirror_point=mirror_point, gradient_at=gradient_at)
    A = mirror.displacement_map()                         # d n_ext x d ni
    offset = mirror.constant_displacements().T.ravel()    # component-major

    def rows():
        """The real nodes' equilibrium with the relations' constants on the right, the
        plane rows bordered, the boundary cell faces' flux rows; the coordinates of the
        unknowns (nested dissection) and their counts."""
        K_real = model.K[model.real_rows()]
        K = (K_real @ A).tocsr()
        rhs = -(K_real @ offset)
        planes = _plane_rows(g, sc.planes, ni)
        op, op_rhs, coords, n_rows = bordered(K, rhs, planes,
                                              [np.zeros(b.shape[0]) for b in planes],
                                              np.tile(g.x[g.interior_ids], (d, 1)))
        flux = face_crossings(g, model.bond_a, model.bond_b)
        face_rows = (_surface_flux(model, flux, ns) @ bond_force_matrix(model)).tocsr()
        return op, op_rhs, face_rows, coords, {
            "constraints": int(n_rows), "unknowns": int(op.shape[0])}

    counts = {"real_nodes": int(ni), "fictitious_nodes": int(ne - ni)}
    parts = {f.name: np.flatnonzero(~g.is_interior & (
        (g.index[:, f.axis] < 0) if f.side == 0
        else (g.index[:, f.axis] >= g.nodes_per_axis[f.axis]))) for f in box_faces(d)}
    return MirrorBondBoxSystem(
        model, np.zeros(d * ne), np.zeros(0, dtype=int), np.zeros(0), parts, A=A,
        n_unknown=ni, counts=counts, offset=offset, rows=rows)
