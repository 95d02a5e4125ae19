"""Closed forms of the 1D state-based bar of seed 000: classical solutions and Tables 1, 2, B1."""
from __future__ import annotations

import numpy as np

# ----------------------------------------------------------------- classical solutions


def traction_displacement(x, *, force, E, area):
    """u_cl = f x / (E A): clamped bar, end force f, seed 000 Eq. (65)."""
    return force / (E * area) * np.asarray(x, dtype=float)


def uniform_load_displacement(x, *, b0, E, length):
    """u_cl = b0 / E (l x - x^2 / 2): clamped-free bar, uniform load, Eq. (66)."""
    x = np.asarray(x, dtype=float)
    return b0 / E * (length * x - x ** 2 / 2)


def linear_load_displacement(x, *, b1, E, length):
    """u_cl = b1 / E (l^2 x / 2 - x^3 / 6): clamped-free bar, load b1 x, Eq. (67)."""
    x = np.asarray(x, dtype=float)
    return b1 / E * (length ** 2 * x / 2 - x ** 3 / 6)


def sine_load_displacement(x, *, bs, E, length):
    """u_cl = bs / E (l / pi)^2 (pi x / l + sin(pi x / l)): load bs sin(pi x / l), Eq. (68)."""
    x = np.asarray(x, dtype=float)
    k = np.pi / length
    return bs / E / k ** 2 * (k * x + np.sin(k * x))


# ----------------------------------------------------------------- surface effect (§2.2)


def _split(x, horizon, length):
    s = np.asarray(x, dtype=float) / horizon
    r = (length - np.asarray(x, dtype=float)) / horizon
    return s, r


def weighted_volume_ratio(x, *, horizon, length):
    """m / m_inf along a finite bar under omega = delta / |xi|, seed 000 Table 1 (Eq. 27).

    Valid for length >= 2 delta (each point is near at most one end).
    """
    s, r = _split(x, horizon, length)
    out = np.ones_like(s)
    left, right = s < 1, r < 1
    out[left] = 0.5 * s[left] ** 2 + 0.5
    out[right] = 0.5 * r[right] ** 2 + 0.5
    return out


def _flux_near(s):
    """tau / tau_inf at distance s = x / delta <= 1 from an end (first row of Table 2, Eq. 28)."""
    return (2 * (1 - 2 * s) * np.arctan(s) + np.log(s ** 2 + 1) + 0.5 * s ** 2
            + np.pi * s / 2)


def _flux_second(s):
    """tau / tau_inf at 1 <= s <= 2 (second row of Table 2, Eq. 29), s = x / delta."""
    t = s - 1
    return (2 * t * np.arctan(t) - np.log(0.5 * t ** 2 + 0.5) - 0.5 * t ** 2
            + (1 - np.pi / 2) * t + 0.5)


def force_flux_ratio(x, *, horizon, length):
    """tau(x, +1) / tau_inf under a constant strain, seed 000 Table 2 (Eqs. 28-29).

    The l-end rows of Table 2 are the mirror images of the 0-end rows; they are
    evaluated here through the distance to the nearer end. Valid for length >= 4 delta.
    """
    s, r = _split(x, horizon, length)
    d = np.minimum(s, r)
    out = np.ones_like(d)
    near, second = d <= 1, (d > 1) & (d < 2)
    out[near] = _flux_near(d[near])
    out[second] = _flux_second(d[second])
    return out


def body_force_ratio(x, *, horizon, length):
    """b / (tau_inf / delta) that keeps a finite bar at constant strain, seed 000 Table B1.

    Antisymmetric about the middle of the bar (the l-end rows are minus the mirrored
    0-end rows). Valid for length >= 4 delta.
    """
    s, r = _split(x, horizon, length)
    out = np.zeros_like(s)

    def near(t):
        return 4 * np.arctan(t) + 2 * (t - 1) / (t ** 2 + 1) - t - np.pi / 2

    def second(t):
        return -2 * np.arctan(t - 1) + t - 2 + np.pi / 2

    m1, m2 = s < 1, (s >= 1) & (s < 2)
    out[m1] = near(s[m1])
    out[m2] = second(s[m2])
    m1, m2 = r < 1, (r >= 1) & (r < 2)
    out[m1] = -near(r[m1])
    out[m2] = -second(r[m2])
    return out


def flux_features(n_grid: int = 200001):
    """Peak of Table 2 near an end and where tau returns to tau_inf, both in units of delta.

    Returns ``(max_ratio, argmax, crossing)``: the maximum of tau/tau_inf over
    0 <= x/delta <= 2, its location, and the point in 0 < x/delta < 1 where the first row
    of Table 2 equals 1 (paper, §2.2: about 1.263 at 0.772 and 0.394). Found by a dense
    grid refined with Brent's method on the closed form.
    """
    from scipy.optimize import brentq, minimize_scalar

    s = np.linspace(0.0, 2.0, n_grid)
    ratio = np.where(s <= 1, _flux_near(s), _flux_second(np.maximum(s, 1.0)))
    k = int(np.argmax(ratio))
    lo, hi = s[max(k - 1, 0)], s[min(k + 1, n_grid - 1)]
    f = _flux_near if s[k] <= 1 else _flux_second
    opt = minimize_scalar(lambda t: -f(t), bounds=(lo, hi), method="bounded",
                          options={"xatol": 1e-13})
    crossing = brentq(lambda t: _flux_near(t) - 1.0, 1e-9, s[k] if s[k] <= 1 else 1.0,
                      xtol=1e-14)
    return float(-opt.fun), float(opt.x), float(crossing)
