"""Taylor-based extrapolation over a fictitious layer, nearest-node strategy (seed 000 §3-4.1)."""
from __future__ import annotations

from math import factorial

import numpy as np


def taylor_extrapolation_weights(x_source, x_target, order: int, anchor: float, scale: float):
    """Weights W with u(x_target) = W @ u(x_source), the matrix T^Gamma [T^Omega]^-1 of Eq. (45).

    ``x_source`` are the ``order + 1`` real nodes nearest the boundary (Eq. 43), ``anchor``
    the boundary node the series is centred on (nearest-node strategy) and ``scale`` a
    length used to scale the Taylor factors (the spacing), which leaves W unchanged but
    keeps the small Vandermonde-type system well conditioned. W reproduces every
    polynomial of degree <= ``order`` exactly.
    """
    x_source = np.asarray(x_source, dtype=float)
    x_target = np.atleast_1d(np.asarray(x_target, dtype=float))
    if x_source.size != order + 1:
        raise ValueError(f"order {order} needs {order + 1} source nodes, got {x_source.size}")
    powers = np.arange(order + 1)
    fact = np.array([factorial(p) for p in powers], dtype=float)
    t_omega = ((x_source[:, None] - anchor) / scale) ** powers / fact
    t_gamma = ((x_target[:, None] - anchor) / scale) ** powers / fact
    # W = T_gamma T_omega^{-1}  <=>  T_omega^T W^T = T_gamma^T
    return np.linalg.solve(t_omega.T, t_gamma.T).T
