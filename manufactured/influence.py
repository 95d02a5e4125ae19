"""Radial influence functions and the exact radial and angular moments the engine needs."""
from __future__ import annotations

from functools import lru_cache

import sympy as sp

INFLUENCES = ("gaussian", "hyperbolic", "constant", "conical")


def check_influence(influence):
    """Raise ValueError unless `influence` is one of :data:`INFLUENCES`."""
    if influence not in INFLUENCES:
        raise ValueError(f"influence: unknown {influence!r}; allowed: {', '.join(INFLUENCES)}")


def influence_function(influence, length, horizon):
    """Influence function omega(|xi|) as a sympy expression.

    Parameters
    ----------
    influence : {"gaussian", "hyperbolic", "constant", "conical"}
        gaussian exp(-|xi|^2/delta^2) (seed 001, Eq. 7); hyperbolic delta/|xi|
        (seed 000, Eq. 23); constant 1; conical 1 - |xi|/delta.
    length, horizon : sympy expression or number
        Bond length |xi| and horizon delta.
    """
    check_influence(influence)
    length, horizon = sp.sympify(length), sp.sympify(horizon)
    return {
        "gaussian": sp.exp(-length**2 / horizon**2),
        "hyperbolic": horizon / length,
        "constant": sp.Integer(1),
        "conical": 1 - length / horizon,
    }[influence]


def _lower_gamma_at_one(s):
    """gamma(s, 1) = int_0^1 t^(s-1) exp(-t) dt for s a positive integer or half-integer.

    Uses gamma(1/2, 1) = sqrt(pi) erf(1), gamma(1, 1) = 1 - 1/e and
    gamma(s + 1, 1) = s gamma(s, 1) - 1/e, so every moment is a combination of
    sqrt(pi) erf(1) and exp(-1) with rational coefficients, as in seed 001, Eqs. (53)-(55).
    """
    s = sp.Rational(s)
    if s == sp.Rational(1, 2):
        return sp.sqrt(sp.pi) * sp.erf(1)
    if s == 1:
        return 1 - sp.exp(-1)
    return sp.expand((s - 1) * _lower_gamma_at_one(s - 1) - sp.exp(-1))


@lru_cache(maxsize=None)
def radial_moment_unit(influence, k):
    """int_0^1 omega(t) t^k dt for a unit horizon (exact sympy number).

    The moment for horizon delta is ``delta**(k + 1)`` times this value, because every
    influence function here depends on |xi|/delta only.

    Parameters
    ----------
    influence : str
        One of :data:`INFLUENCES`.
    k : int
        Power of the bond length, k >= 0.

    Raises
    ------
    ValueError
        If the moment diverges (hyperbolic influence with k = 0).
    """
    check_influence(influence)
    k = int(k)
    if k < 0:
        raise ValueError(f"k: radial moment power must be >= 0 (got {k})")
    if influence == "gaussian":
        # t = l^2/delta^2: int_0^1 exp(-t^2) t^k dt = gamma((k+1)/2, 1) / 2
        return sp.expand(_lower_gamma_at_one(sp.Rational(k + 1, 2)) / 2)
    if influence == "hyperbolic":
        if k == 0:
            raise ValueError("influence: 'hyperbolic' gives a divergent radial moment "
                             "int_0^delta (delta/l) dl; this field/model needs a finite one")
        return sp.Rational(1, k)
    if influence == "constant":
        return sp.Rational(1, k + 1)
    return sp.Rational(1, (k + 1) * (k + 2))  # conical: 1/(k+1) - 1/(k+2)


def radial_moment(influence, k, horizon):
    """R_k = int_0^delta omega(l) l^k dl (exact sympy expression in `horizon`).

    Seed 001 Eq. (53): Delta_1 = R_4 for the Gaussian; Eq. (54) int_0^d int_s^d omega r^3
    dr ds = R_4; Eq. (55): Delta_2 = R_6 / 2.
    """
    return radial_moment_unit(influence, k) * sp.sympify(horizon) ** (k + 1)


@lru_cache(maxsize=None)
def sphere_moment(exponents):
    """Angular moment int_{S^{d-1}} m_1^a_1 ... m_d^a_d dOmega, exactly.

    d = len(exponents). For d = 1 the "sphere" is {-1, +1} with the counting measure, so
    that dV = l^(d-1) dl dOmega holds in every dimension. The closed form is
    2 prod Gamma((a_i + 1)/2) / Gamma((|a| + d)/2) when every a_i is even, else 0
    (seed 001, Eqs. 48-52 are the 3D cases).

    Parameters
    ----------
    exponents : tuple of int
        Non-negative exponents (a_1, ..., a_d).
    """
    exponents = tuple(int(a) for a in exponents)
    if any(a % 2 for a in exponents):
        return sp.Integer(0)
    d = len(exponents)
    num = sp.Integer(2)
    for a in exponents:
        num *= sp.gamma(sp.Rational(a + 1, 2))
    return sp.simplify(num / sp.gamma(sp.Rational(sum(exponents) + d, 2)))


def weighted_volume(influence, dim, horizon):
    """Weighted volume m = int_H omega |xi|^2 dV of a complete neighbourhood (seed 001, Eq. 8).

    m = |S^{d-1}| R_{d+1}; seed 001 Eq. (56): m = 4 pi Delta_1 (3D Gaussian); seed 000
    Eq. (25): m = delta^3 (1D hyperbolic, unit area).
    """
    return sphere_moment((0,) * dim) * radial_moment(influence, dim + 1, horizon)
