"""Taylor extrapolation about a node (any dimension), shared by taylor-fictitious and surface-nodes."""
from __future__ import annotations

from itertools import product
from math import factorial

import numpy as np
import scipy.sparse as sp

from ..errors import NumericalError

#: Above this condition number of the (column-scaled) Taylor fit its weights lose more than
#: 12 of double precision's ~16 digits: the fit is refused as numerically singular.
FIT_CONDITION_LIMIT = 1e12


def monomial_exponents(dim: int, order: int) -> np.ndarray:
    """Exponents (n_1, ..., n_d) with 1 <= n_1 + ... + n_d <= order (seed 001 Eqs. 13, 25, 29)."""
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
    u(target) = u(centre) + sum_q w_q (u(source_q) - u(centre)): the series of order
    ``order`` about the centre, its derivatives from the expansions of the sources
    (seed 000 Eqs. 42-45 in 1D; seed 001 Eqs. 25-28 / 29-32). ``src_rel``
    (n_groups, n_src, dim) are source offsets from the centre; when there are more
    sources than derivatives the system is solved in the least-squares sense. Either way
    the weights reproduce every polynomial of degree <= order exactly (its Taylor series
    is exact and the fit recovers its derivatives when the sources are unisolvent).
    """
    src_rel = np.asarray(src_rel, dtype=float)
    tgt_rel = np.asarray(tgt_rel, dtype=float)
    dim = src_rel.shape[-1]
    group = np.asarray(group)
    if dim == 1 and src_rel.shape[1] == order:
        # a square 1D fit is interpolation: the weights are the Lagrange polynomials of the
        # nodes {0} + sources at the target, evaluated as products (stable at any order,
        # where the monomial fit below loses every digit from order ~20 on)
        nodes = src_rel[group, :, 0]                              # (T, S)
        t = tgt_rel[:, 0][:, None]
        all_nodes = np.concatenate([np.zeros((nodes.shape[0], 1)), nodes], axis=1)
        W = np.ones_like(nodes)
        for k in range(order + 1):
            other = all_nodes[:, k][:, None]
            factor = np.where(np.arange(1, order + 1)[None, :] == k, 1.0,
                              (t - other) / np.where(nodes == other, 1.0, nodes - other))
            W *= factor
        return W
    exps = monomial_exponents(dim, order)
    M = taylor_monomials(src_rel, exps)          # (G, S, n_mono)
    scale = np.abs(M).max(axis=1, keepdims=True)  # column scaling: monomials differ by k!
    scale[scale == 0] = 1.0
    sv = np.linalg.svd(M / scale, compute_uv=False)
    worst = float(np.max(sv[:, 0] / np.maximum(sv[:, -1], 1e-300)))
    if worst > FIT_CONDITION_LIMIT:
        raise NumericalError(f"Taylor fit of order {order} in {dim}D on {src_rel.shape[1]} "
                             f"nodes is numerically singular (condition {worst:.1e} > "
                             f"{FIT_CONDITION_LIMIT:.0e}): its weights would not extrapolate "
                             "polynomials of that degree; use a lower order")
    G = np.linalg.pinv(M / scale) / np.swapaxes(scale, 1, 2)   # (G, n_mono, S)
    T = taylor_monomials(tgt_rel, exps)          # (n_targets, n_mono)
    return np.einsum("tm,tms->ts", T, G[group])


def taylor_extrapolation_weights(x_source, x_target, order: int, anchor: float, scale: float):
    """1D weights W with u(x_target) = W @ u(x_source), the matrix T^Gamma [T^Omega]^-1 of
    seed 000 Eq. (45).

    ``x_source`` are ``order + 1`` nodes, one of them the ``anchor`` the series is centred
    on (nearest-node strategy: the real node nearest the boundary in seed 000, the surface
    node in seed 002); ``scale`` (the spacing) scales the Taylor factors, which leaves W
    unchanged but keeps the fit well conditioned. Computed by :func:`taylor_weights`, so
    W reproduces every polynomial of degree <= ``order`` exactly.
    """
    x_source = np.asarray(x_source, dtype=float)
    x_target = np.atleast_1d(np.asarray(x_target, dtype=float))
    if x_source.size != order + 1:
        raise ValueError(f"order {order} needs {order + 1} source nodes, got {x_source.size}")
    centre = np.flatnonzero(x_source == anchor)
    if centre.size != 1:
        raise ValueError(f"the anchor {anchor} must be one of the source nodes")
    others = np.flatnonzero(x_source != anchor)
    src_rel = ((x_source[others] - anchor) / scale)[None, :, None]
    tgt_rel = ((x_target - anchor) / scale)[:, None]
    w = taylor_weights(src_rel, tgt_rel, np.zeros(x_target.size, dtype=int), order)
    W = np.zeros((x_target.size, x_source.size))
    W[:, others] = w
    W[:, centre[0]] = 1.0 - w.sum(axis=1)
    return W


def extrapolation_rows(n_rows, n_cols, W, src, centre) -> sp.csr_matrix:
    """Sparse rows u_row = u(centre) + sum_q W_q (u(src_q) - u(centre)) (one per target)."""
    rows = np.repeat(np.arange(n_rows), W.shape[1])
    vals = np.concatenate([W.ravel(), 1.0 - W.sum(axis=1)])
    rows = np.concatenate([rows, np.arange(n_rows)])
    cols = np.concatenate([np.asarray(src).ravel(), centre])
    out = sp.csr_matrix((vals, (rows, cols)), shape=(n_rows, n_cols))
    out.sum_duplicates()
    return out


def window_start(centre, width, n):
    """Start of a window of ``width`` cells nearest to ``centre`` inside [0, n)."""
    return np.clip(centre - width // 2, 0, n - width)
