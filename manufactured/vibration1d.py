"""Rao's series for a released, uniformly pre-strained bar, fixed at x = 0 and free at x = L.

Seed 004 Eq. (105) (Rao, Mechanical Vibrations): initial displacement eps x, zero initial
velocity, classical wave equation with speed c = sqrt(E / rho).
"""
from __future__ import annotations

import numpy as np


def wave_speed(E: float, density: float) -> float:
    """c = sqrt(E / rho)."""
    return float(np.sqrt(E / density))


def first_mode_frequency(*, length: float, wave_speed: float) -> float:
    """f_1 = c / (4 L) [Hz], the n = 0 term of Eq. (105)."""
    return wave_speed / (4.0 * length)


def rao_series(x, t, *, strain: float, length: float, wave_speed: float, terms: int):
    """Eq. (105) summed over n = 0..terms-1; returns an array of shape (len(t), len(x)).

    u(x, t) = 8 eps L / pi^2 sum_n (-1)^n / (2n+1)^2 sin((2n+1) pi x / (2L))
              cos((2n+1) pi c t / (2L)).
    The tail after ``terms`` terms is at most :func:`series_tail_bound`.
    """
    x = np.atleast_1d(np.asarray(x, dtype=float))
    t = np.atleast_1d(np.asarray(t, dtype=float))
    out = np.zeros((t.size, x.size))
    for n in range(terms):  # a loop over series terms, each vectorised over (t, x)
        q = (2 * n + 1) * np.pi / (2.0 * length)
        out += ((-1) ** n / (2 * n + 1) ** 2) * np.outer(np.cos(q * wave_speed * t), np.sin(q * x))
    return 8.0 * strain * length / np.pi ** 2 * out


def series_tail_bound(*, strain: float, length: float, terms: int) -> float:
    """|Eq. (105) - its first ``terms`` terms| <= 8 eps L / pi^2 * 1 / (4 terms).

    sum_{n >= M} 1/(2n+1)^2 <= int_{M - 1/2}^inf dn / (2n+1)^2 = 1 / (4M).
    """
    return 8.0 * strain * length / np.pi ** 2 / (4.0 * terms)


def _quarter_wave_extension(s, strain, length):
    """eps x on [0, L], extended odd about 0, even about L, 4L-periodic (a triangle wave)."""
    r = np.mod(s + length, 4.0 * length) - length  # in [-L, 3L)
    return strain * np.where(r <= length, r, 2.0 * length - r)


def rao_displacement(x, t, *, strain: float, length: float, wave_speed: float):
    """The exact sum of Eq. (105), shape (len(t), len(x)).

    Each term of Eq. (105) is a standing wave (sin(q(x - ct)) + sin(q(x + ct)))/2, so the
    series is d'Alembert's (g(x - ct) + g(x + ct)) / 2 with g the sine series of eps x on
    [0, L] in the quarter-wave modes: eps x extended odd about x = 0, even about x = L,
    with period 4L. At x = L this is the triangle wave eps L (1 - 2|theta|/pi).
    """
    x = np.atleast_1d(np.asarray(x, dtype=float))
    t = np.atleast_1d(np.asarray(t, dtype=float))
    ct = wave_speed * t[:, None]
    return 0.5 * (_quarter_wave_extension(x[None, :] - ct, strain, length)
                  + _quarter_wave_extension(x[None, :] + ct, strain, length))


def exact_sum_error_bound(*, strain: float, length: float, wave_speed: float,
                          t_max: float) -> float:
    """A bound on |rao_displacement - Eq. (105)| for 0 <= t <= t_max, 0 <= x <= L: the
    exact sum has no truncation, only the rounding of its few operations.

    With s = x -+ c t (|s| <= L + c t_max =: S, two roundings), r = mod(s + L, 4L) - L
    (the addition and the subtraction round, the modulo of doubles is exact or rounds
    once when it adds 4L), every rounding at most eps times a quantity below S + 4L, so
    |r - r_exact| <= 5 eps (S + 4L); the triangle wave has slope +-strain, and the
    product, 2L - r and the mean add 3 eps |u| <= 3 eps strain L. In all:
    strain eps (5 S + 23 L), with eps the double's unit roundoff 2^-53 doubled (2.2e-16)
    for margin.
    """
    eps = float(np.finfo(float).eps)
    S = length + abs(wave_speed) * t_max
    return strain * eps * (5.0 * S + 23.0 * length)
