"""Analytic 1D peridynamic and classical wave series of seed 002, Eqs. (10)-(12) (sign corrected)."""
from __future__ import annotations

from dataclasses import dataclass
from math import factorial

import numpy as np
from scipy.special import sici

#: The paper's pulse, Eq. (10): u(x, 0) = PULSE_PEAK exp(-PULSE_RATE (x - l/2)^2).
PULSE_PEAK = 0.02
PULSE_RATE = 100.0

# Below this k delta the closed form of Eq. (12) loses digits to cancellation
# (k delta Si(k delta) and cos(k delta) - 1 nearly cancel); the power series is used there.
_SERIES_BELOW = 1.0
_SERIES_TERMS = 12  # z^(2n+2) / ((2n+1)(2n+2)!) < 1e-30 for n = 12, z < 1


def gaussian_pulse(x, *, length=1.0, peak=PULSE_PEAK, rate=PULSE_RATE):
    """The initial displacement of Eq. (10), centred at l/2 (= 0.5 for the paper's l = 1)."""
    x = np.asarray(x, dtype=float)
    return peak * np.exp(-rate * (x - 0.5 * length) ** 2)


def nonlocal_factor(k, horizon):
    """psi(k, delta) of Eq. (12): the PD operator's eigenvalue on sin(kx) is -v^2 psi.

    psi = 2/delta^2 [k delta Si(k delta) + cos(k delta) - 1] > 0, and psi -> k^2 as
    delta -> 0 (psi ~ k^2 - k^4 delta^2 / 36; ERRATA seed 002). For k delta < 1 the
    power series psi = 2/delta^2 sum_n (-1)^n z^(2n+2) / ((2n+1) (2n+2)!), z = k delta,
    replaces the closed form, which cancels there. ``horizon=0`` gives the classical k^2.
    """
    k = np.asarray(k, dtype=float)
    if horizon < 0:
        raise ValueError(f"horizon={horizon} must be >= 0")
    if horizon == 0:
        return k ** 2
    z = np.abs(k) * horizon
    small = z < _SERIES_BELOW
    out = np.empty_like(z)
    zs = z[small]
    series = np.zeros_like(zs)
    for n in range(_SERIES_TERMS):
        series += (-1) ** n * zs ** (2 * n + 2) / ((2 * n + 1) * factorial(2 * n + 2))
    out[small] = series
    zl = z[~small]
    out[~small] = zl * sici(zl)[0] + np.cos(zl) - 1.0
    return 2.0 / horizon ** 2 * out


def sine_coefficients(initial, *, length=1.0, n_terms=40, panels=None, points=20):
    """Fourier sine coefficients b_m = 2/l int_0^l u0(x) sin(k_m x) dx, m = 1..n_terms.

    The projection of the initial displacement on the Dirichlet eigenfunctions, computed by
    composite Gauss-Legendre quadrature (``panels`` panels of ``points`` nodes; by default
    enough panels that every panel holds at most a quarter wavelength of the highest mode
    and at least 64 panels for the shape of u0). ``initial`` is a vectorised function of x.
    """
    m = np.arange(1, n_terms + 1)
    k = m * np.pi / length
    if panels is None:
        panels = max(64, 2 * n_terms)
    g, w = np.polynomial.legendre.leggauss(points)
    edges = np.linspace(0.0, length, panels + 1)
    half = 0.5 * np.diff(edges)
    xq = (0.5 * (edges[:-1] + edges[1:])[:, None] + half[:, None] * g[None, :]).ravel()
    wq = (half[:, None] * w[None, :]).ravel()
    u0 = np.asarray(initial(xq), dtype=float)
    return (2.0 / length) * (np.sin(np.outer(k, xq)) @ (wq * u0))


def paper_coefficients(n_terms=40, *, length=1.0):
    """The closed-form coefficients of Eq. (11): 0.004 sqrt(pi)/l sin(m pi/2) exp(-k_m^2/400).

    They are the projection of the paper's Gaussian with the integral extended over the
    whole line; for l = 1 the neglected tails are 0.02 sqrt(pi)/10 erfc(5) ~ 5e-15.
    Valid for the pulse of Eq. (10) with l = 1 (ERRATA seed 002).
    """
    m = np.arange(1, n_terms + 1)
    k = m * np.pi / length
    return 0.004 * np.sqrt(np.pi) / length * np.sin(m * np.pi / 2) * np.exp(-k ** 2 / 400.0)


@dataclass(frozen=True)
class WaveSeries:
    """A truncated separation-of-variables series u = sum b_m sin(k_m x) cos(omega_m t).

    ``omega = v sqrt(psi(k, delta))`` for PD (Eq. 11 with the corrected sign) and
    ``v k`` for classical mechanics (``horizon = 0``). ``tail`` estimates the truncation
    error max |u - u_series| over all x and t (:func:`truncation_estimate`).
    """

    length: float
    horizon: float
    wave_speed: float
    k: np.ndarray
    b: np.ndarray
    omega: np.ndarray
    tail: float

    def displacement(self, x, t):
        """u at points ``x`` and time(s) ``t``: shape x.shape for scalar t, else (t.size,) + x.shape."""
        x = np.asarray(x, dtype=float)
        t_arr = np.asarray(t, dtype=float)
        modes = np.sin(np.multiply.outer(x, self.k))           # x.shape + (M,)
        phase = np.cos(np.multiply.outer(np.atleast_1d(t_arr), self.omega)) * self.b  # (nt, M)
        u = np.tensordot(phase, modes, axes=([1], [modes.ndim - 1]))  # (nt,) + x.shape
        return u[0] if t_arr.ndim == 0 else u


#: the window of omitted modes :func:`truncation_estimate` sums: at least this many
TAIL_WINDOW = 64


def truncation_estimate(b_omitted, initial, length) -> float:
    """Estimate of the largest error over all x and t of a series truncated after M modes.

    The omitted part is sum_{m > M} b_m sin(k_m x) cos(omega_m t), and |sin cos| <= 1, so
    its size is at most sum_{m > M} |b_m|. ``b_omitted`` holds the projections of the next
    max(M, :data:`TAIL_WINDOW`) modes; their |b_m| summed is that bound over the window.
    Beyond it two things remain: the smooth part of u0, whose coefficients decay faster
    than any power of 1/m (for the paper's Gaussian as exp(-(m pi)^2 / 400): below 1e-30
    by m = 60, far inside the window), and u0's end values, which no sine mode carries
    (the series is 0 at x = 0 and l): its partial sums miss them by about their size near
    the ends, and their coefficients fall only as 1/m, so the window cannot sum them. The
    estimate adds |u0(0)| + |u0(l)| for that part (2.8e-13 each for the paper's pulse).
    It is an estimate, not a proof, for initial data whose coefficients are still large at
    the end of the window; for the pulses here the window's sum is dominated by its first
    terms.
    """
    ends = np.abs(np.asarray(initial(np.array([0.0, length])), dtype=float))
    return float(np.sum(np.abs(b_omitted)) + np.sum(ends))


def wave_series(*, horizon, wave_speed, length=1.0, n_terms=40, initial=None) -> WaveSeries:
    """Build the series of Eqs. (10)-(12) for initial displacement ``initial`` and zero velocity.

    ``horizon=0`` gives the classical (non-dispersive) series. ``initial`` defaults to the
    paper's Gaussian pulse centred at l/2. Coefficients come from the projection
    (:func:`sine_coefficients`), never from the closed form of Eq. (11).
    """
    if initial is None:
        def initial(x):
            return gaussian_pulse(x, length=length)
    if n_terms < 1:
        raise ValueError(f"n_terms={n_terms} must be >= 1")
    b_all = sine_coefficients(initial, length=length,
                              n_terms=n_terms + max(n_terms, TAIL_WINDOW))
    k = np.arange(1, n_terms + 1) * np.pi / length
    omega = wave_speed * np.sqrt(nonlocal_factor(k, horizon))
    return WaveSeries(length=length, horizon=horizon, wave_speed=wave_speed, k=k,
                      b=b_all[:n_terms], omega=omega,
                      tail=truncation_estimate(b_all[n_terms:], initial, length))


def pd_wave_displacement(x, t, *, horizon, wave_speed, length=1.0, n_terms=40, initial=None):
    """Analytic PD displacement of Eq. (10) at points ``x`` and time ``t`` (seed 002, Eq. 11).

    u(x, t) = sum_{m=1}^{n_terms} b_m sin(k_m x) cos(v sqrt(psi_m) t), k_m = m pi / l,
    psi_m from Eq. (12) (ERRATA: cos(v sqrt(psi) t), not sqrt(-psi)); b_m is the
    projection of ``initial`` (default: 0.02 exp(-100 (x - l/2)^2)) on sin(k_m x).
    ``n_terms`` counts all modes m = 1..n_terms (the even ones vanish for a pulse centred
    at l/2; the paper's "first 40 terms" of the odd series reach m = 79, far beyond
    where exp(-k^2/400) underflows relative to 1e-16). ``t`` may be an array.
    """
    series = wave_series(horizon=horizon, wave_speed=wave_speed, length=length,
                         n_terms=n_terms, initial=initial)
    return series.displacement(x, t)


def classical_wave_displacement(x, t, *, wave_speed, length=1.0, n_terms=40, initial=None):
    """Classical (non-dispersive) series: the same modes with omega_m = v k_m (delta = 0)."""
    return pd_wave_displacement(x, t, horizon=0.0, wave_speed=wave_speed, length=length,
                                n_terms=n_terms, initial=initial)


def dalembert_displacement(x, t, *, wave_speed, length=1.0, initial=None):
    """Classical solution by d'Alembert: the mean of the odd 2l-periodic extension shifted by +-vt.

    An independent check of the classical series (no truncation).
    """
    if initial is None:
        def initial(x):
            return gaussian_pulse(x, length=length)
    x = np.asarray(x, dtype=float)

    def odd_periodic(s):
        r = np.mod(s, 2 * length)
        return np.where(r <= length, initial(r), -initial(2 * length - r))

    return 0.5 * (odd_periodic(x - wave_speed * t) + odd_periodic(x + wave_speed * t))
