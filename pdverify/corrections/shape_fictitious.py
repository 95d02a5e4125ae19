"""Seed 000's Taylor-extrapolated fictitious nodes on a body that is not a box (issue 35):
the series is taken along the local normal, its derivatives from a least-squares fit.

On a box (``taylor_fictitious``) a fictitious node copies the order-n Taylor series along
its lattice line normal to the face, from the n + 1 real nodes of that line. A curved or
cut boundary has no such lines, and a jittered node set no lattice at all, so here
(our generalisation; say "seed 000 along the normal" when citing it):

- the fictitious nodes are the lattice nodes outside the shape within the stencil's reach
  (``ShapeGrid``'s layer); each has its closest boundary point p and the outward normal
  n there, so x_f = p + s n, s its distance;
- its displacement is the order-n polynomial fitted by least squares to the displacements
  of the ``neighbours(n)`` real nodes nearest p (their actual positions: jitter
  included), evaluated at x_f: the Taylor series about p along the normal to order n, its
  derivatives those of the fit. Exact for every polynomial field of degree <= n (the fit
  reproduces it), as seed 000's series is; its dilatation the same fit of order n - 1 of
  the real nodes' dilatations (order 0: the nearest real node's), and m of a complete
  neighbourhood at every node (as on the box);
- a fictitious node seen from two sides (issue 55): at a re-entrant corner a fictitious
  node in the notch takes the series of its closest part, one arm's, and a real node of
  the other arm bonded to it would read that arm's field across the notch (finding
  035-l-plate-bridging). A bond whose real end does not see the fictitious node's
  closest point through the body (``Shape.hides``: the segment crosses another part)
  reads instead a value of its own (``Closure.shadow``), the same fit about the point
  of the nearest part the real end does see (:func:`seen_points`: the other notch
  face); its dilatation likewise. Every fit reproduces the polynomials of its order, so
  the exactness above is kept. On a convex corner, a straight part or along a hole's
  arc no bond changes; on plate-hole 6 bonds do at h = 0.05 and 1/30 (none at 0.025):
  beside the arc's end on a symmetry plane, where a fictitious node below the plane has
  that end as its closest point and a real node sees it only through the hole;
- crack faces (issue 54; ``pdverify.pd.shapes.Crack``): a slit has no outside, so its
  fictitious nodes are not lattice nodes but copies, one per bond a crack cuts and per
  end of it (:func:`crack_ghosts`, ``Closure.ghosts``): from each end a one-sided bond
  to a fictitious node at the other end's place, fitted as above about that place's
  closest point on the end's own face, over the real nodes on the end's side of the
  crack's line only (a ghost of the upper face lies among the lower face's nodes, but
  reads the upper field). The cut bond itself stays cut; a ghost has no equation and
  no share in the other node's dilatation. At the tip: ghosts exist only for the bonds
  the crack cuts, so the faces' fictitious nodes stop at the tip (a ghost ahead of it
  is fitted about the tip point); the nodes ahead of the tip keep their real bonds,
  the bonds round the tip stay real (not cut, no ghost), and a bond through the tip
  point counts half in each face's force flux (``CrackFace.crossings``). Beside an
  edge crack's mouth the lattice's fictitious nodes and the bonds to them across the
  crack's line are fitted from one side (:func:`sided_fit`). A face along a lattice
  axis takes the force-flux rows below; one at an angle to the lattice the fit's
  traction (the flux through its stretches is a lattice count, :func:`lattice_flux`),
  its fit one-sided (:func:`one_sided_fits`). Exact for the polynomials of the order
  at every node, the tip zone included, and one-sided (``tests/shapes/
  test_crack_faces.py``: a field different on the two sides is reproduced outside
  the ligament's zone, and a fit over both sides misses it);
- the conditions at boundary points by Lagrange multipliers (seed 000 Eq. 63): one point
  per boundary node and part (the mean of the part's boundary samples that belong to the
  node, ``assembly.boundary_nodes``, moved onto the part). A prescribed component's
  row sets the fitted value (Eq. 58's role). Every other component's row is, on a
  straight part, seed 001's force flux (Eqs. 35-36): the bonds crossing the point's
  stretch of the part (fictitious-fictitious bonds that cross it kept, half at a
  stretch's edge or a part's end), equal to the traction's resultant over the stretch;
  on a rectangle these are the box's rows. On an arc the flux through a short stretch
  is a lattice quadrature whose error does not vanish, so there the row is the traction
  sigma(grad u_fit) n of the fit's gradient with the continuum moduli of the PD
  constants, equal to the applied traction (zero on a free part).

On a 3D shape (``pdverify.pd.shapes3d``; issue 55) the same with 3D fits
(:func:`neighbours`: 16, 40, 100 real nodes for orders 1, 2, 3; a rank-deficient fit is
refused, :func:`_full_rank`), the boundary points on planes, the mantle and the sphere,
and on every part not prescribing a component the fit's traction row (plane parts too:
the force flux through a 3D patch needs the bonds' crossings of the parts, which
``Shape3D`` does not compute; :func:`traction_rows_3d`); no fictitious-fictitious bonds
(:func:`real_keep`); bridging bonds as in 2D (``Shape3D.hides``, exact crossings): none
on the convex quarter cylinder, 49 of 93 624 real-fictitious bonds at h = 0.1 on the
cavity octant, through the cavity (``benchmarks/shape3d_bridging.py``); they leave
block3d-cavity's Taylor errors unchanged to four digits.
Exactness kept: order n reproduces the polynomials of degree <= n as in 2D
(tests/shapes/test_shape3d_methods.py). A grid whose condition rows outnumber the
displacement unknowns (the quarter cylinder at h = 1/8) fails by name.

Vectorised: the neighbours by one k-d tree query, the fits as one batched pseudo-inverse
(points x neighbours x monomials); no loop over nodes.
"""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp
from scipy.spatial import cKDTree

from ..pd.bonds import unique_ids
from ..pd.closure import Closure


#: length of the fits' Gaussian weight, in spacings
WEIGHT_LENGTH = 1.0


def exponents(order: int, dim: int = 2) -> np.ndarray:
    """(M, dim) exponents of the monomials of total degree <= order: in 2D (i, j) of
    x^i y^j, in 3D (i, j, k) of x^i y^j z^k, by degree, x's power falling first."""
    if dim == 2:
        return np.array([(i, t - i) for t in range(order + 1) for i in range(t, -1, -1)])
    return np.array([(i, j, t - i - j) for t in range(order + 1)
                     for i in range(t, -1, -1) for j in range(t - i, -1, -1)]).reshape(-1, 3)


def neighbours(order: int, dim: int = 2) -> int:
    """Real nodes a fit of ``order`` takes: twice the monomials in 2D (one node for order
    0); in 3D four times (orders 1, 2: 16, 40 nodes) and five times for order 3 (100).
    Twice is too few in 3D: beside a plane of cell faces the 20 nearest nodes of a
    quadratic fit about a node lie on two lattice planes along the normal, so x and x^2
    cannot be told apart (rank 9 of 10). Measured on both 3D shapes at their test grids
    (h = 1/8, 1/10), about every fictitious node's closest point, every boundary point
    and every real node: 30 and 80 nodes still leave rank-deficient fits of order 2 and
    3 (957 and 813 centres on the cavity octant), 40 and 100 none (smallest relative
    singular value 7.7e-3 and 4.9e-4); :func:`fit` refuses a rank-deficient 3D fit."""
    if order == 0:
        return 1
    if dim == 2:
        return (order + 1) * (order + 2)
    return len(exponents(order, 3)) * (4 if order <= 2 else 5)


#: smallest singular value of a 3D fit's weighted Vandermonde matrix, relative to its
#: largest, below which the fit is refused (round-off scale; the fits of the 3D shapes
#: measure 4.9e-4 or more at neighbours(order, 3), rank-deficient ones below 1e-15)
RANK_TOLERANCE = 1e-10


def _full_rank(A, order):
    """Refuse a batch of 3D fits whose weighted Vandermonde matrices ``A`` (F, k, M) are
    rank deficient: pinv would return a minimum-norm fit that does not reproduce the
    polynomials of its order (a silent wrong extension)."""
    from ..errors import NumericalError
    sv = np.linalg.svd(A, compute_uv=False)
    ratio = sv[:, -1] / np.maximum(sv[:, 0], np.finfo(float).tiny)
    bad = int(np.sum(ratio < RANK_TOLERANCE))
    if bad:
        raise NumericalError(f"{bad} of {len(A)} least-squares fits of order {order} over "
                             f"their {A.shape[1]} nearest real nodes are rank deficient "
                             f"(smallest relative singular value {ratio.min():.1e} < "
                             f"{RANK_TOLERANCE:g}): the nodes do not span the polynomials")


def _vander(z, E):
    """Monomials of the scaled offsets z (..., 2) for the exponents E (M, 2)."""
    return np.prod(z[..., None, :] ** E, axis=-1)


def fit(x_real, centres, targets, order: int, h: float, gradient: bool = False):
    """Least-squares weights of the order-``order`` fit about each centre, over its
    ``neighbours(order)`` nearest real nodes: ``(nodes (F, k), value weights at targets
    (F, k))``, and with ``gradient`` the weights of d/dx, d/dy (, d/dz) there (F, dim,
    k). 2D or 3D by the points' columns."""
    dim = x_real.shape[1]
    k = min(neighbours(order, dim), len(x_real))
    _, nodes = cKDTree(x_real).query(centres, k=k)
    nodes = nodes.reshape(len(centres), k)
    E = exponents(order, dim)
    z = (x_real[nodes] - centres[:, None, :]) / h                 # (F, k, dim)
    # weighted by the distance to the centre (WEIGHT_LENGTH spacings), so that nearby
    # centres sharing their nodes still get their own fit (equal rows would be singular)
    sw = np.exp(-0.5 * np.sum(z * z, axis=-1) / WEIGHT_LENGTH ** 2)[..., None]
    A = sw * _vander(z, E)
    if dim == 3:
        _full_rank(A, order)
    pinv = np.linalg.pinv(A) * np.swapaxes(sw, 1, 2)                  # (F, M, k)
    zt = (targets - centres) / h
    value = np.einsum("fm,fmk->fk", _vander(zt, E), pinv)
    if not gradient:
        return nodes, value
    out = []
    for axis in range(dim):
        dE = E.copy()
        c = dE[:, axis].astype(float)
        dE[:, axis] = np.maximum(dE[:, axis] - 1, 0)
        d = c * _vander(zt, dE) / h
        out.append(np.einsum("fm,fmk->fk", d, pinv))
    return nodes, value, np.stack(out, axis=1)


def centred_fit(x_real, centres, centre_cols, targets, order: int, h: float,
                gradient: bool = False):
    """The order-``order`` Taylor series about each centre whose value there is an
    unknown of its own (a surface node: column ``centre_cols``), its derivatives fitted
    by least squares to the differences u_j - u_centre of the ``neighbours(order)``
    real nodes nearest it (Gaussian weights as :func:`fit`): ``(columns (F, k + 1), value
    weights at targets (F, k + 1))``, the centre's column first, and with ``gradient``
    the weights of d/dx, d/dy there (F, 2, k + 1). Exact for every polynomial of degree
    <= order; the series passes through the centre's value (seed 001's Taylor series
    about the surface node, its derivatives from a fit instead of lattice lines).
    2D or 3D by the points' columns (then d/dz too)."""
    dim = x_real.shape[1]
    k = min(neighbours(order, dim), len(x_real))
    _, nodes = cKDTree(x_real).query(centres, k=k)
    nodes = nodes.reshape(len(centres), k)
    E = exponents(order, dim)[1:]                                  # no constant term
    z = (x_real[nodes] - centres[:, None, :]) / h
    sw = np.exp(-0.5 * np.sum(z * z, axis=-1) / WEIGHT_LENGTH ** 2)[..., None]
    A = sw * _vander(z, E)
    if dim == 3:
        _full_rank(A, order)
    pinv = np.linalg.pinv(A) * np.swapaxes(sw, 1, 2)                  # (F, M - 1, k)
    cols = np.c_[np.asarray(centre_cols)[:, None], nodes]
    zt = (targets - centres) / h

    def with_centre(w):
        return np.concatenate([-w.sum(axis=-1, keepdims=True), w], axis=-1)
    value = with_centre(np.einsum("fm,fmk->fk", _vander(zt, E), pinv))
    value[:, 0] += 1.0
    if not gradient:
        return cols, value
    out = []
    for axis in range(dim):
        dE = E.copy()
        c = dE[:, axis].astype(float)
        dE[:, axis] = np.maximum(dE[:, axis] - 1, 0)
        out.append(with_centre(np.einsum("fm,fmk->fk", c * _vander(zt, dE) / h, pinv)))
    return cols, value, np.stack(out, axis=1)


def _rows(nodes, weights, n_rows, n_cols, row_ids=None, col_offset=0):
    """Sparse rows of ``weights`` over the columns ``nodes`` (+ ``col_offset``: the
    component's block of the component-major unknowns)."""
    F, k = nodes.shape
    rows = np.repeat(np.arange(F) if row_ids is None else row_ids, k)
    return sp.csr_matrix((weights.ravel(), (rows, nodes.ravel() + col_offset)),
                         shape=(n_rows, n_cols))


def normal_closure(g, shape, order: int, stencil=None) -> Closure:
    """The closure of the fictitious layer of a ``ShapeGrid`` (module docstring)."""
    ni, h = g.n_interior, g.spacing
    x_real = g.x[g.interior_ids]
    fict = np.flatnonzero(g.kind == 1)
    p = shape.closest(g.x[fict])[0]
    eye = sp.csr_matrix((np.ones(ni), (g.interior_ids, np.arange(ni))), shape=(g.n_ext, ni))
    reach = (g.layers + 3) * h
    nodes, w = sided_fit(shape, x_real, p, g.x[fict], order, h, reach)
    A_U = (eye + _rows(nodes, w, g.n_ext, ni, fict)).tocsr()
    nodes, w = sided_fit(shape, x_real, p, g.x[fict], order - 1, h, reach)
    A_T = (eye + _rows(nodes, w, g.n_ext, ni, fict)).tocsr()
    keep = shadow = ghosts = None
    if stencil is not None:
        # 3D: no fictitious-fictitious flux bonds (no crossings in Shape3D)
        keep = real_keep(g, stencil) if g.dim == 3 else crossing_keep(g, shape, stencil)
        shadow = shadow_rows(g, shape, stencil, keep, order)
        ghosts = crack_ghosts(g, shape, stencil, keep, order)
    info = {"fictitious_nodes": int(fict.size),
            "bridging_bonds": 0 if shadow is None else int(shadow[0].size)}
    if ghosts is not None:
        info["crack_ghost_bonds"] = int(ghosts[0].size)
    return Closure(keep=keep, weighted_volume="complete", displacement_map=A_U,
                   dilatation_map=A_T, shadow=shadow, ghosts=ghosts, info=info)


def sided_fit(shape, x_real, centres, targets, order: int, h: float, reach: float,
              owners=None):
    """:func:`fit` of the fictitious nodes ``targets``, those within ``reach`` of a
    crack (beside an edge crack's mouth) over the real nodes on one side of its line
    only, the side of ``owners`` (default: the targets themselves; a bond's real end
    for its own value of the node): a fit there over both sides' nodes would bond the
    faces' nodes to values read across the open mouth. Without a crack, :func:`fit`
    itself."""
    nodes, w = fit(x_real, centres, targets, order, h)
    owners = targets if owners is None else owners
    for c in getattr(shape, "cracks", ()):
        if not c.length:
            continue
        q, _ = c.faces[0].closest(targets)
        near = np.linalg.norm(targets - q, axis=1) <= reach
        plus = c.side(owners)
        for face in c.faces:
            sel = np.flatnonzero(near & (plus == face.plus))
            if sel.size:
                side = np.flatnonzero(face_side(face, x_real))
                n_k, w_k = fit(x_real[side], centres[sel], targets[sel], order, h)
                nodes[sel], w[sel] = side[n_k], w_k
    return nodes, w


def face_side(face, x) -> np.ndarray:
    """Which rows of ``x`` (the real nodes) a fictitious node of the crack face ``face``
    is fitted from: those on the face's side of its crack's line."""
    return face.sees(x)


def cut_ends(g, shape, stencil, keep):
    """The ends of the pairs a crack cuts among those the closure keeps (``keep``), one
    row per pair and end: ``(pairs, own end is a, own node, other node, [(face,
    rows)])``, the rows grouped by the face of the own end's side of the first crack
    that cuts the pair. None without a cut pair."""
    cracks = [c for c in getattr(shape, "cracks", ()) if c.length]
    if not cracks:
        return None
    from ..pd.bonds import bond_pairs
    a, b, _ = bond_pairs(g.ext_shape, stencil.offsets[stencil.half])
    live = np.flatnonzero(keep)
    cut = live[shape.severs(g.x[a[live]], g.x[b[live]])]
    if cut.size == 0:
        return None
    # one ghost per end of every cut pair (the closure keeps no void end): (pair, the
    # bond's own end is a); a fictitious own end (beside an edge crack's mouth) gives a
    # bond with no equation at either end, which counts in the face's force flux only
    pairs = np.r_[cut, cut]
    real_a = np.r_[np.ones(cut.size, dtype=bool), np.zeros(cut.size, dtype=bool)]
    own = np.where(real_a, a[pairs], b[pairs])
    ghost = np.where(real_a, b[pairs], a[pairs])
    groups = []
    done = np.zeros(pairs.size, dtype=bool)
    for c in cracks:            # the first crack that cuts a pair serves it
        mine = ~done & c.cuts(g.x[own], g.x[ghost])
        done |= mine
        for face in c.faces:
            sel = np.flatnonzero(mine & (c.side(g.x[own]) == face.plus))
            if sel.size:
                groups.append((face, sel))
    return pairs, real_a, own, ghost, groups


def crack_ghosts(g, shape, stencil, keep, order: int):
    """``Closure.ghosts`` of the normal closure on a shape with cracks (module
    docstring, crack faces): every stencil pair the closure would keep (``keep``) that
    a crack cuts becomes, from each end, a one-sided bond to a fictitious node at the
    other end's position, fitted as a fictitious node of the end's face: the
    order-``order`` fit about the other end's closest point on that face (the tip
    beyond it), over the real nodes on the end's side of the crack's line only (the
    face's side, :func:`face_side`); its dilatation the fit of order - 1 of those
    nodes' dilatations. None without a crack that cuts a pair."""
    ends = cut_ends(g, shape, stencil, keep)
    if ends is None:
        return None
    pairs, real_a, _, ghost, groups = ends
    ni, h = g.n_interior, g.spacing
    x_real = g.x[g.interior_ids]
    rows_u, rows_t = [], []
    for face, sel in groups:
        side = np.flatnonzero(face_side(face, x_real))   # the face's real nodes
        p, _ = face.closest(g.x[ghost[sel]])
        for order_k, rows in ((order, rows_u), (order - 1, rows_t)):
            nodes, w = fit(x_real[side], p, g.x[ghost[sel]], order_k, h)
            rows.append((sel, side[nodes], w))
    return pairs, real_a, stacked_rows(rows_u, pairs.size, ni), stacked_rows(
        rows_t, pairs.size, ni)


def stacked_rows(blocks, n_rows: int, n_cols: int) -> sp.csr_matrix:
    """The sparse rows of ``[(row ids, columns, weights)]`` blocks summed."""
    parts = [_rows(cols, w, n_rows, n_cols, sel) for sel, cols, w in blocks]
    return sum(parts[1:], parts[0]).tocsr()


def boundary_points(g, shape, samples):
    """One point per (boundary node, part) pair: the mean of that pair's samples moved onto
    the part, its outward normal, part and node, and each sample's point (``samples``:
    what ``assembly.boundary_nodes`` returns)."""
    P, W, _, part, node = samples
    key = node * len(shape.parts) + part
    keys, inv = np.unique(key, return_inverse=True)
    wsum = np.bincount(inv, W)
    mean = np.stack([np.bincount(inv, W * P[:, i]) for i in range(P.shape[1])],
                    axis=1) / wsum[:, None]
    kpart = keys % len(shape.parts)
    pts, nrm = np.zeros_like(mean), np.zeros_like(mean)
    for k, q in enumerate(shape.parts):
        on = kpart == k
        if on.any():
            pts[on], nrm[on] = q.closest(mean[on])
    return pts, nrm, kpart, keys // len(shape.parts), inv


def real_keep(g, stencil):
    """The bonds of a 3D shape's closure: every stencil pair with a real end and no void
    end (its conditions are traction rows, so no fictitious-fictitious bond carries a
    flux; ``Shape3D`` has no crossings)."""
    from ..pd.bonds import bond_pairs
    a, b, _ = bond_pairs(g.ext_shape, stencil.offsets[stencil.half])
    return (g.is_interior[a] | g.is_interior[b]) & ~g.is_void[a] & ~g.is_void[b]


def crossing_keep(g, shape, stencil):
    """The closure's bonds: every stencil pair with a real end (no void end), and the
    pairs of fictitious nodes whose bond crosses a boundary part (near corners: they
    carry part of the force flux through it, as seed 001's face-crossing bonds do)."""
    from ..pd.bonds import bond_pairs
    a, b, _ = bond_pairs(g.ext_shape, stencil.offsets[stencil.half])
    keep = (g.is_interior[a] | g.is_interior[b]) & ~g.is_void[a] & ~g.is_void[b]
    ff = np.flatnonzero((g.kind[a] == 1) & (g.kind[b] == 1))
    seg = shape.crossings(g.x[a[ff]], g.x[b[ff]])[0]
    keep[ff[np.unique(seg)]] = True
    return keep


def bridging(g, shape, a, b, pairs):
    """The pairs (of the mask ``pairs`` over a-b) that join a real node to a fictitious
    one whose closest boundary point the real node does not see through the body
    (``Shape.hides``: the segment between them crosses another part, as across a
    re-entrant corner's notch), with the real and fictitious ends: ``(pair ids, real,
    fictitious)``."""
    mixed = np.flatnonzero(pairs & (g.is_interior[a] != g.is_interior[b]))
    real = np.where(g.is_interior[a[mixed]], a[mixed], b[mixed])
    fict = np.where(g.is_interior[a[mixed]], b[mixed], a[mixed])
    if mixed.size == 0:
        return mixed, real, fict
    p, _, _, part = shape.closest(g.x[fict])
    hidden = shape.hides(g.x[real], p, part)
    return mixed[hidden], real[hidden], fict[hidden]


def seen_points(g, shape, real, fict):
    """For each bridging bond (:func:`bridging`), the boundary point its fictitious node
    is extrapolated about as seen from its real end: the fictitious node's closest point
    on the nearest part whose closest point the real node sees (``Shape.hides``); where
    no part qualifies, the node's own closest point (the bond then bridges as before).
    Returns ``(points, their parts)``."""
    xf, xr = g.x[fict], g.x[real]
    best = np.full(len(fict), np.inf)
    out, _, _, part = shape.closest(xf)
    for k, q in enumerate(shape.parts):
        pk, _ = q.closest(xf)
        dist = np.linalg.norm(xf - pk, axis=1)
        ok = ~shape.hides(xr, pk, np.full(len(fict), k)) & (dist < best)
        best = np.where(ok, dist, best)
        out[ok], part[ok] = pk[ok], k
    return out, part


def shadow_rows(g, shape, stencil, keep, order: int):
    """``Closure.shadow`` of the normal closure (module docstring): every bridging bond's
    fictitious value and dilatation fitted, as the node's own, about the point its real
    end sees (:func:`seen_points`)."""
    from ..pd.bonds import bond_pairs
    from ..pd.closure import uncut
    a, b, _ = bond_pairs(g.ext_shape, stencil.offsets[stencil.half])
    pairs, real, fict = bridging(g, shape, a, b, uncut(g, a, b, keep))
    if pairs.size == 0:
        return None
    ni, h = g.n_interior, g.spacing
    x_real = g.x[g.interior_ids]
    p, _ = seen_points(g, shape, real, fict)
    reach = (g.layers + 3) * h
    across = np.zeros(pairs.size, dtype=bool)
    for c in getattr(shape, "cracks", ()):
        if c.length:     # a bond past an edge crack's mouth: the node's own point, and
            q, _ = c.faces[0].closest(g.x[fict])     # the fit from the real end's side
            across |= ((np.linalg.norm(g.x[fict] - q, axis=1) <= reach)
                       & (c.side(g.x[real]) != c.side(g.x[fict])))
    p[across] = shape.closest(g.x[fict[across]])[0]
    nodes, w = sided_fit(shape, x_real, p, g.x[fict], order, h, reach, g.x[real])
    U = _rows(nodes, w, pairs.size, ni)
    nodes, w = sided_fit(shape, x_real, p, g.x[fict], order - 1, h, reach, g.x[real])
    return pairs, U, _rows(nodes, w, pairs.size, ni)


def crossings(model, shape):
    """Every crossing of a boundary part by a bond of the model whose ends both lie
    within a horizon of the boundary: ``(bond, part, arc length, sign, alpha)``
    (``Shape.crossings``: sign +1 when end a lies on the body's side of the part)."""
    g = model.grid
    a, b = model.bond_a, model.bond_b
    near = shape.closest(g.x)[2] <= model.horizon * (1 + 1e-12)
    cand = np.flatnonzero(near[a] & near[b])
    seg, part, s, sign, alpha = shape.crossings(g.x[a[cand]], g.x[b[cand]])
    return cand[seg], part, s, sign, alpha


def condition_rows(model, problem, order: int, samples):
    """The constraint rows B u = c of the conditions (module docstring) on the real
    displacements (component-major, 2 n_real columns): a prescribed component's fitted
    value at each boundary point; every other component's force flux through the
    point's stretch of a straight part (:func:`stretches`), equal to the traction's
    resultant over that stretch, or on an arc the fit's traction (:func:`_traction_rows`)
    equal to the applied traction (zero on a free part)."""
    g, shape = model.grid, problem.shape
    ni, h, d = g.n_interior, g.spacing, g.dim
    x_real = g.x[g.interior_ids]
    pts, nrm, part, _, group = boundary_points(g, shape, samples)
    nodes, value, grad = fit(x_real, pts, pts, order, h, gradient=True)
    one_sided_fits(shape, x_real, pts, part, order, h, (nodes, value, grad))
    exact = problem.exact(pts)
    pres = prescribed(problem, part)
    points = (pts, nrm, part, group)
    free = (free_rows(model, problem, samples, points, nodes, grad, ni) if d == 2
            else traction_rows_3d(problem, points, nodes, grad, ni))
    rows, vals = [], []
    for k in range(d):
        if pres[:, k].any():
            sel = np.flatnonzero(pres[:, k])
            rows.append(_rows(nodes[sel], value[sel], sel.size, d * ni, col_offset=k * ni))
            vals.append(exact[sel, k])
        for _, R, c in free[k]:
            rows.append(R)
            vals.append(c)
    return sp.vstack(rows).tocsr(), np.concatenate(vals), len(pts)


def one_sided_fits(shape, x_real, pts, part, order: int, h: float, fits):
    """Overwrite, in ``fits`` = ``(nodes, value, grad)`` of :func:`fit` at the boundary
    points ``pts`` (on the parts ``part``), the rows of the points on a crack's face by
    the fit over the real nodes on that face's side of the crack's line only (a fit
    about a point of the slit would otherwise take the other face's nodes)."""
    from ..pd.shapes import CrackFace
    nodes, value, grad = fits
    for k, q in enumerate(shape.parts):
        on = np.flatnonzero(part == k)
        if not isinstance(q, CrackFace) or on.size == 0:
            continue
        side = np.flatnonzero(q.sees(x_real))
        n_k, v_k, g_k = fit(x_real[side], pts[on], pts[on], order, h, gradient=True)
        nodes[on], value[on], grad[on] = side[n_k], v_k, g_k


def lattice_flux(q) -> bool:
    """Whether the force flux of the bonds crossing a stretch of the part ``q`` is the
    traction's resultant for every affine field (seed 001's identity): a straight part
    along a lattice axis. A crack's face at an angle to the lattice is not (the bonds
    crossing a stretch of it are a lattice count whose error does not vanish: on a
    slit at 30 degrees, h = 0.025, the flux of an affine field missed the resultant by
    0.5 and 2 % over a face of length 0.2); there, as on an arc, the row is the fit's
    traction. Every other part keeps the flux, as before."""
    from ..pd.shapes import CrackFace
    if not q.straight:
        return False
    if not isinstance(q, CrackFace):
        return True
    e = np.subtract(q.b, q.a)
    return bool(min(abs(e[0]), abs(e[1])) <= 1e-12 * q.length)


def prescribed(problem, part) -> np.ndarray:
    """(n, d): whether the part of each point prescribes each component."""
    names = problem.shape.part_names
    out = np.zeros((len(part), problem.shape.dim), dtype=bool)
    for name, cond in problem.conditions.items():
        for k in cond.prescribed:
            out[:, k] |= part == names.index(name)
    return out


def free_rows(model, problem, samples, points, nodes, grad, n_cols):
    """Per component k, the rows of the boundary points (``points``: ``(pts, nrm,
    part, group)`` of :func:`boundary_points`) whose part does not prescribe k, over
    the unknowns' displacements (component-major, 2 ``n_cols`` columns): ``[(point ids,
    rows, values)]``, first the straight parts' force flux through each point's
    stretch (equal to the traction's resultant over it), then the arcs' traction of
    the fit (``nodes``, ``grad``: the fits' columns and gradient weights at the points)
    equal to the applied traction."""
    g, shape = model.grid, problem.shape
    h = g.spacing
    pts, nrm, part, group = points
    P, W = samples[0], samples[1]
    curved = ~np.array([lattice_flux(q) for q in shape.parts])[part]
    lam, mu = problem.constants.moduli()
    names = shape.part_names
    # each crossing counts for the boundary point whose stretch of its part holds it
    # (the stretch: the node's samples, to the midpoints between neighbouring points;
    # on a straight face one cell face), half for each on the edge between two (seed
    # 001's alpha = 1/2 on a cell face's edge); the traction's resultant over the
    # stretch from the samples
    bonds, cpart, cs, sign, alpha = crossings(model, shape)
    spart = samples[3]
    sign = sign * alpha
    share_c = stretches(shape, pts, part, _params(shape, P, spart), spart, group, cs, cpart, h)
    share_s = sp.csr_matrix((np.ones(len(P)), (np.arange(len(P)), group)),
                            shape=(len(P), len(pts)))
    used = unique_ids(bonds)
    forces = model.bond_force_matrix(used)           # rows: the crossing bonds, ascending
    col = sp.csr_matrix((np.ones(bonds.size), (np.arange(bonds.size),
                                               np.searchsorted(used, bonds))),
                        shape=(bonds.size, used.size))
    F = (col @ forces).tocsr()                       # each crossing's bond force
    resultant = share_s.T @ (W[:, None] * problem.thickness
                             * _traction_at(problem, P, samples[2], spart, names))
    traction_pts = _traction_at(problem, pts, nrm, part, names)
    pres = prescribed(problem, part)
    out = []
    for k in range(2):
        mine = []
        free = np.flatnonzero(~pres[:, k] & ~curved)
        if free.size:
            S = (share_c[:, free].T @ sp.diags(sign * model.bond_n[bonds, k])).tocsr()
            mine.append((free, (S @ F).tocsr(), resultant[free, k]))
        bent = np.flatnonzero(~pres[:, k] & curved)
        if bent.size:
            mine.append((bent, _traction_rows(nodes[bent], grad[bent], nrm[bent], k, lam,
                                              mu, n_cols), traction_pts[bent, k]))
        out.append(mine)
    return out


def traction_rows_3d(problem, points, nodes, grad, n_cols):
    """:func:`free_rows` on a 3D shape: every boundary point whose part does not
    prescribe component k has the row of the fit's traction sigma(grad u_fit) n equal
    to the applied one (zero on a free part), on plane and curved parts alike (a 3D
    force flux through a point's patch of a part would need the bonds' crossings of
    planes, a mantle and a sphere, which ``Shape3D`` does not compute)."""
    pts, nrm, part, _ = points
    lam, mu = problem.constants.moduli()
    t = _traction_at(problem, pts, nrm, part, problem.shape.part_names)
    pres = prescribed(problem, part)
    out = []
    for k in range(3):
        free = np.flatnonzero(~pres[:, k])
        out.append([(free, _traction_rows(nodes[free], grad[free], nrm[free], k, lam, mu,
                                          n_cols), t[free, k])] if free.size else [])
    return out


def _params(shape, x, xpart):
    """Arc length on its part of each point of ``x``."""
    out = np.zeros(len(x))
    for k, q in enumerate(shape.parts):
        on = xpart == k
        if on.any():
            out[on] = q.param(x[on])
    return out


def stretches(shape, pts, part, s_samples, spart, group, s_all, xpart, h) -> sp.csr_matrix:
    """(len(s_all) x len(pts)) weights of positions ``s_all`` (arc length on their parts
    ``xpart``) over the boundary points: 1 for the point whose stretch holds it (the
    arc-length range of the point's samples, extended to the midpoints between
    neighbouring points; beyond a part's first or last point, that point), 1/2 for each
    of two points within 1e-9 h of the edge between their stretches."""
    rows, cols, vals = [], [], []
    n = len(pts)
    lo = np.full(n, np.inf)
    hi = np.full(n, -np.inf)
    np.minimum.at(lo, group, s_samples)
    np.maximum.at(hi, group, s_samples)
    for k in range(len(shape.parts)):
        mine = np.flatnonzero(part == k)
        on = np.flatnonzero(xpart == k)
        if mine.size == 0 or on.size == 0:
            continue
        mine = mine[np.argsort(lo[mine])]
        edges = 0.5 * (hi[mine[:-1]] + lo[mine[1:]])
        s = s_all[on]
        j = np.searchsorted(edges, s)
        rows.append(on), cols.append(mine[j]), vals.append(np.ones(on.size))
        if edges.size:   # on an edge: half to each side
            tie_lo = np.abs(s - edges[np.clip(j - 1, 0, edges.size - 1)]) <= 1e-9 * h
            tie_lo &= j > 0
            tie_hi = np.abs(s - edges[np.clip(j, 0, edges.size - 1)]) <= 1e-9 * h
            tie_hi &= j < edges.size
            vals[-1] = np.where(tie_lo | tie_hi, 0.5, 1.0)
            rows.append(on[tie_lo]), cols.append(mine[j[tie_lo] - 1])
            vals.append(np.full(int(tie_lo.sum()), 0.5))
            rows.append(on[tie_hi]), cols.append(mine[j[tie_hi] + 1])
            vals.append(np.full(int(tie_hi.sum()), 0.5))
    return sp.csr_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))),
                         shape=(len(s_all), n))


def _traction_rows(nodes, grad, nrm, k, lam, mu, n_cols):
    """Rows of the traction component k, sigma(grad u_fit) n with the continuum moduli
    (plane or 3D: t_k = lam (div u) n_k + mu sum_l (d_l u_k + d_k u_l) n_l), over the
    fit's nodes' displacements (d ``n_cols`` columns, d = 2 or 3 by ``nrm``)."""
    blocks = []
    F, d = len(nodes), nrm.shape[1]
    for a in range(d):          # the displacement component the row weighs
        c = lam * nrm[:, k][:, None] * grad[:, a]
        c = c + mu * nrm[:, a][:, None] * grad[:, k]
        if a == k:
            c = c + mu * np.einsum("fl,flk->fk", nrm, grad)
        blocks.append(_rows(nodes, c, F, d * n_cols, col_offset=a * n_cols))
    out = blocks[0] + blocks[1]
    for extra in blocks[2:]:
        out = out + extra
    return out.tocsr()


def _traction_at(problem, x, n, xpart, names):
    """The applied traction at boundary samples (zero on free parts)."""
    out = np.zeros_like(x)
    for name, cond in problem.conditions.items():
        on = xpart == names.index(name)
        if cond.traction is not None and on.any():
            out[on] = cond.traction(x[on], n[on])
    return out
