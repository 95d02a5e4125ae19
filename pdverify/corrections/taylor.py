"""Taylor extrapolation about a node (any dimension), shared by taylor-fictitious and surface-nodes."""
from __future__ import annotations

from itertools import product
from math import factorial

import numpy as np
import scipy.sparse as sp


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
    dim = src_rel.shape[-1]
    exps = monomial_exponents(dim, order)
    M = taylor_monomials(src_rel, exps)          # (G, S, n_mono)
    G = np.linalg.pinv(M)                        # (G, n_mono, S)
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
