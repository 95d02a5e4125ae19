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
- the conditions at boundary points by Lagrange multipliers (seed 000 Eq. 63): one point
  per boundary node and part (the mean of the part's boundary samples that belong to the
  node, ``static_state.boundary_nodes``, moved onto the part), where a prescribed
  component's row sets the fitted value (Eq. 58's role) and every other component's row
  the traction sigma(grad u_fit) n of the fit's gradient with the continuum moduli of
  the PD constants, equal to the part's traction (zero on a free part). This replaces
  seed 000's force-flux rows (Eq. 60; in 2D the face-crossing bonds of each boundary
  cell face), which need cell faces on the boundary.

Vectorised: the neighbours by one k-d tree query, the fits as one batched pseudo-inverse
(points x neighbours x monomials); no loop over nodes.
"""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp
from scipy.spatial import cKDTree

from ..pd.closure import Closure


#: length of the fits' Gaussian weight, in spacings
WEIGHT_LENGTH = 1.0


def exponents(order: int) -> np.ndarray:
    """(M, 2) exponents (i, j) of the monomials x^i y^j with i + j <= order."""
    return np.array([(i, t - i) for t in range(order + 1) for i in range(t, -1, -1)])


def neighbours(order: int) -> int:
    """Real nodes a fit of ``order`` takes: twice the monomials (one node for order 0)."""
    return 1 if order == 0 else (order + 1) * (order + 2)


def _vander(z, E):
    """Monomials of the scaled offsets z (..., 2) for the exponents E (M, 2)."""
    return np.prod(z[..., None, :] ** E, axis=-1)


def fit(x_real, centres, targets, order: int, h: float, gradient: bool = False):
    """Least-squares weights of the order-``order`` fit about each centre, over its
    ``neighbours(order)`` nearest real nodes: ``(nodes (F, k), value weights at targets
    (F, k))``, and with ``gradient`` the weights of d/dx, d/dy there (F, 2, k)."""
    k = min(neighbours(order), len(x_real))
    _, nodes = cKDTree(x_real).query(centres, k=k)
    nodes = nodes.reshape(len(centres), k)
    E = exponents(order)
    z = (x_real[nodes] - centres[:, None, :]) / h                 # (F, k, 2)
    # weighted by the distance to the centre (WEIGHT_LENGTH spacings), so that nearby
    # centres sharing their nodes still get their own fit (equal rows would be singular)
    sw = np.exp(-0.5 * np.sum(z * z, axis=-1) / WEIGHT_LENGTH ** 2)[..., None]
    pinv = np.linalg.pinv(sw * _vander(z, E)) * np.swapaxes(sw, 1, 2)   # (F, M, k)
    zt = (targets - centres) / h
    value = np.einsum("fm,fmk->fk", _vander(zt, E), pinv)
    if not gradient:
        return nodes, value
    out = []
    for axis in (0, 1):
        dE = E.copy()
        c = dE[:, axis].astype(float)
        dE[:, axis] = np.maximum(dE[:, axis] - 1, 0)
        d = c * _vander(zt, dE) / h
        out.append(np.einsum("fm,fmk->fk", d, pinv))
    return nodes, value, np.stack(out, axis=1)


def _rows(nodes, weights, n_rows, n_cols, row_ids=None):
    F, k = nodes.shape
    rows = np.repeat(np.arange(F) if row_ids is None else row_ids, k)
    return sp.csr_matrix((weights.ravel(), (rows, nodes.ravel())), shape=(n_rows, n_cols))


def normal_closure(g, shape, order: int) -> Closure:
    """The closure of the fictitious layer of a ``ShapeGrid`` (module docstring)."""
    ni, h = g.n_interior, g.spacing
    x_real = g.x[g.interior_ids]
    fict = np.flatnonzero(g.kind == 1)
    p = shape.closest(g.x[fict])[0]
    eye = sp.csr_matrix((np.ones(ni), (g.interior_ids, np.arange(ni))), shape=(g.n_ext, ni))
    nodes, w = fit(x_real, p, g.x[fict], order, h)
    A_U = (eye + _rows(nodes, w, g.n_ext, ni, fict)).tocsr()
    nodes, w = fit(x_real, p, g.x[fict], order - 1, h)
    A_T = (eye + _rows(nodes, w, g.n_ext, ni, fict)).tocsr()
    return Closure(weighted_volume="complete", displacement_map=A_U, dilatation_map=A_T,
                   info={"fictitious_nodes": int(fict.size)})


def boundary_points(g, shape, samples):
    """One point per (boundary node, part) pair: the mean of that pair's samples moved onto
    the part, its outward normal, part and node (``samples``: what
    ``static_state.boundary_nodes`` returns)."""
    P, W, _, part, node = samples
    key = node * len(shape.parts) + part
    keys, inv = np.unique(key, return_inverse=True)
    wsum = np.bincount(inv, W)
    mean = np.c_[np.bincount(inv, W * P[:, 0]), np.bincount(inv, W * P[:, 1])] / wsum[:, None]
    kpart = keys % len(shape.parts)
    pts, nrm = np.zeros_like(mean), np.zeros_like(mean)
    for k, q in enumerate(shape.parts):
        on = kpart == k
        if on.any():
            pts[on], nrm[on] = q.closest(mean[on])
    return pts, nrm, kpart, keys // len(shape.parts)


def condition_rows(g, problem, order: int, samples, moduli):
    """The constraint rows B u = c of the conditions (module docstring) on the real
    displacements (component-major, 2 n_real columns)."""
    shape = problem.shape
    ni, h = g.n_interior, g.spacing
    x_real = g.x[g.interior_ids]
    pts, nrm, part, _ = boundary_points(g, shape, samples)
    nodes, value, grad = fit(x_real, pts, pts, order, h, gradient=True)
    lam, mu = moduli
    names = shape.part_names
    exact = problem.exact(pts)
    rows, vals = [], []
    for k in range(2):
        pres = np.zeros(len(pts), dtype=bool)
        load = np.zeros(len(pts))
        for name, cond in problem.conditions.items():
            on = part == names.index(name)
            if k in cond.prescribed:
                pres |= on
            elif cond.traction is not None and on.any():
                load[on] = cond.traction(pts[on], nrm[on])[:, k]
        if pres.any():
            sel = np.flatnonzero(pres)
            rows.append(_rows(nodes[sel], value[sel], sel.size, ni)
                        @ _component(k, ni))
            vals.append(exact[sel, k])
        free = np.flatnonzero(~pres)
        if free.size:
            # t_k = lam (du0/dx + du1/dy) n_k + mu sum_l (du_k/dx_l + du_l/dx_k) n_l
            blocks = []
            for a in range(2):          # the displacement component the row weighs
                c = np.zeros((free.size, nodes.shape[1]))
                c += lam * nrm[free, k][:, None] * grad[free, a]
                c += mu * (nrm[free, a][:, None] * grad[free, k] if a != k else 0.0)
                if a == k:
                    c += mu * np.einsum("fl,flk->fk", nrm[free], grad[free])
                    c += mu * nrm[free, k][:, None] * grad[free, k]
                blocks.append(_rows(nodes[free], c, free.size, ni) @ _component(a, ni))
            rows.append(blocks[0] + blocks[1])
            vals.append(load[free])
    return sp.vstack(rows).tocsr(), np.concatenate(vals), len(pts)


def _component(k, ni):
    """(ni x 2 ni) selector of component k of the component-major unknowns."""
    return sp.csr_matrix((np.ones(ni), (np.arange(ni), k * ni + np.arange(ni))),
                         shape=(ni, 2 * ni))
