"""Surface node method (seed 001 §3): Taylor extrapolation in 2D/3D and face-crossing bonds."""
from __future__ import annotations

from itertools import product
from math import factorial

import numpy as np
import scipy.sparse as sp

MAX_ORDER = 3


# --------------------------------------------------------------------------- Taylor
def monomial_exponents(dim: int, order: int) -> np.ndarray:
    """Exponents (n_1, ..., n_d) with 1 <= n_1 + ... + n_d <= order (Eqs. 13, 25, 29)."""
    out = [e for n in range(1, order + 1)
           for e in product(range(n + 1), repeat=dim) if sum(e) == n]
    return np.asarray(out, dtype=int).reshape(-1, dim)


def taylor_monomials(r, exponents) -> np.ndarray:
    """Taylor factors prod_a r_a^n_a / n_a! of offsets ``r`` (..., dim) -> (..., n_mono)."""
    r = np.asarray(r, dtype=float)
    fact = np.array([[factorial(int(n)) for n in e] for e in exponents], dtype=float)
    powers = r[..., None, :] ** exponents  # (..., n_mono, dim)
    return np.prod(powers / fact, axis=-1)


def taylor_weights(src_rel, tgt_rel, group, order):
    """Weights of a Taylor series centred on a node, derivatives fitted on source nodes.

    For each target t (offset ``tgt_rel[t]`` from its centre node, scaled by the spacing)
    in ``group[t]``, returns w (n_targets, n_src) with
    u(target) = u(centre) + sum_q w_q (u(source_q) - u(centre)) (Eqs. 25-28 / 29-32: the
    series of order ``order`` about the centre, its derivatives from the expansions of
    the sources, Eqs. 26/30). ``src_rel`` (n_groups, n_src, dim) are source offsets from
    the centre; when there are more sources than derivatives the system of Eq. (26)/(30)
    is solved in the least-squares sense. Either way the weights reproduce every
    polynomial of degree <= order exactly (its Taylor series is exact and the fit
    recovers its derivatives when the sources are unisolvent).
    """
    dim = src_rel.shape[-1]
    exps = monomial_exponents(dim, order)
    M = taylor_monomials(src_rel, exps)          # (G, S, n_mono)
    G = np.linalg.pinv(M)                        # (G, n_mono, S)
    T = taylor_monomials(tgt_rel, exps)          # (n_targets, n_mono)
    return np.einsum("tm,tms->ts", T, G[group])


def _window(centre, width, n):
    """Start of a window of ``width`` cells nearest to ``centre`` inside [0, n)."""
    return np.clip(centre - width // 2, 0, n - width)


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
        win = np.indices((width,) * (d - 1)).reshape(d - 1, -1).T  # (w^(d-1), d-1)
        start = np.stack([_window(cells[:, t], width, grid.cells[t]) for t in tang], axis=1)
        tcells = start[:, None, :] + win[None, :, :]                # (n, W, d-1)
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
    """Surface node nearest to each node (step 7); ties go to the lowest face number."""
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
    return _assemble(fict_ids.size, n_unk, W, src_ids[s], centre)


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
    start = _window(bidx, width, cells)
    c = start[:, None, :] + win[None, :, :]
    src_ids = grid.interior_number[grid.ext_id(c)]
    src_rel = (c - bidx[:, None, :]).astype(float)
    group = np.searchsorted(ub, b)
    tgt_rel = (grid.index[fict_ids] - b_idx).astype(float)
    W = taylor_weights(src_rel, tgt_rel, group, deg)
    return _assemble(fict_ids.size, n_int, W, src_ids[group], b)


def _assemble(n_rows, n_cols, W, src, centre):
    rows = np.repeat(np.arange(n_rows), W.shape[1])
    vals = np.concatenate([W.ravel(), 1.0 - W.sum(axis=1)])
    rows = np.concatenate([rows, np.arange(n_rows)])
    cols = np.concatenate([src.ravel(), centre])
    out = sp.csr_matrix((vals, (rows, cols)), shape=(n_rows, n_cols))
    out.sum_duplicates()
    return out


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
