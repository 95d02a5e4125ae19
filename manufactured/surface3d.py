"""Closed forms of seed 001: the 3D manufactured solution (Eqs. 40-42), traction fields (39, 43).

Never imports pdverify. Constants are passed in (k_theta, k_e of seed 001 §2.1) so that
the loads are a function of the paper's formulas only.
"""
from __future__ import annotations

from math import erf, exp, pi, sqrt

import numpy as np

#: Eq. (40)-(42) constants, "randomly chosen" by the paper.
C_U, C_V, C_W = 0.05, -0.06, -0.02


def delta_1(horizon: float) -> float:
    """Delta_1 = (3/8 sqrt(pi) erf(1) - 5/4 exp(-1)) delta^5 (after Eq. 41)."""
    return (3.0 / 8.0 * sqrt(pi) * erf(1.0) - 5.0 / 4.0 * exp(-1.0)) * horizon ** 5


def delta_2(horizon: float) -> float:
    """Delta_2 = (15/32 sqrt(pi) erf(1) - 29/16 exp(-1)) delta^7 (after Eq. 41)."""
    return (15.0 / 32.0 * sqrt(pi) * erf(1.0) - 29.0 / 16.0 * exp(-1.0)) * horizon ** 7


def weighted_volume_3d(horizon: float) -> float:
    """m = 4 pi Delta_1 for the Gaussian influence in 3D (ERRATA seed 001)."""
    return 4.0 * pi * delta_1(horizon)


def constants_3d(E: float, nu: float) -> tuple[float, float]:
    """(k_theta, k_e) of seed 001 §2.1."""
    return -3.0 * (1 - 4 * nu) * E / (2 * (1 + nu) * (1 - 2 * nu)), 15.0 * E / (2 * (1 + nu))


def manufactured_displacement(x, cu=C_U, cv=C_V, cw=C_W) -> np.ndarray:
    """Eq. (42): u = (c_u x y, c_v x^3, c_w x z); ``x`` is (n, 3)."""
    x = np.asarray(x, dtype=float)
    X, Y, Z = x[..., 0], x[..., 1], x[..., 2]
    return np.stack([cu * X * Y, cv * X ** 3, cw * X * Z], axis=-1)


def manufactured_body_force(x, *, k_theta, k_e, cu=C_U, cv=C_V, cw=C_W) -> np.ndarray:
    """Eq. (40): b = (-c_w (k_t/3 + 2 k_e/15), -c_u (k_t/3 + 2 k_e/15) - c_v 2 k_e x / 5, 0)."""
    x = np.asarray(x, dtype=float)
    X = x[..., 0]
    a = k_theta / 3.0 + 2.0 * k_e / 15.0
    return np.stack([np.full_like(X, -cw * a), -cu * a - cv * 2.0 * k_e / 5.0 * X,
                     np.zeros_like(X)], axis=-1)


def manufactured_stress(x, *, k_theta, k_e, horizon, cu=C_U, cv=C_V, cw=C_W) -> np.ndarray:
    """Eq. (41): the PD stress tensor tau(x), shape (n, 3, 3)."""
    x = np.asarray(x, dtype=float)
    X, Y, Z = x[..., 0], x[..., 1], x[..., 2]
    lam2 = k_theta / 3.0 + k_e / 5.0   # lambda + 2 mu
    lam = k_theta / 3.0 + k_e / 15.0   # lambda
    ratio = delta_2(horizon) / delta_1(horizon)
    t = np.zeros(X.shape + (3, 3))
    t[..., 0, 0] = cu * lam2 * Y + cw * lam * X
    t[..., 1, 1] = cu * lam * Y + cw * lam * X
    t[..., 2, 2] = cu * lam * Y + cw * lam2 * X
    t12 = cu * k_e / 15.0 * X + cv * (k_e / 5.0 * X ** 2 + k_e / 35.0 * ratio)
    t13 = cw * k_e / 15.0 * Z
    t[..., 0, 1] = t[..., 1, 0] = t12
    t[..., 0, 2] = t[..., 2, 0] = t13
    return t


def manufactured_traction(x, normal, *, k_theta, k_e, horizon, cu=C_U, cv=C_V, cw=C_W):
    """tau(x, n) = tau(x) . n (after Eq. 41); ``normal`` (n, 3) outward unit normals."""
    tau = manufactured_stress(x, k_theta=k_theta, k_e=k_e, horizon=horizon, cu=cu, cv=cv, cw=cw)
    return np.einsum("...ij,...j->...i", tau, np.asarray(normal, dtype=float))


def traction_displacement_3d(x, *, p, E, nu, ly, lz) -> np.ndarray:
    """Eq. (39): u = p x / E, v = -nu p (y + l_y/2) / E, w = -nu p (z + l_z/2) / E."""
    x = np.asarray(x, dtype=float)
    return np.stack([p / E * x[..., 0], -nu * p / E * (x[..., 1] + ly / 2),
                     -nu * p / E * (x[..., 2] + lz / 2)], axis=-1)


def plate_displacement(x, *, p, E, nu, plane="strain") -> np.ndarray:
    """Eq. (43) (plane strain): u = -nu (1 + nu) p x / E, v = (1 - nu^2) p y / E.

    Plane stress (our addition): u = -nu p x / E, v = p y / E.
    """
    x = np.asarray(x, dtype=float)
    if plane == "strain":
        cx, cy = -nu * (1 + nu) * p / E, (1 - nu ** 2) * p / E
    else:
        cx, cy = -nu * p / E, p / E
    return np.stack([cx * x[..., 0], cy * x[..., 1]], axis=-1)
