"""Influence functions and micromoduli (registered by name), weighted volumes, PD constants.

One registry serves both theories: in the state-based model omega(|xi|) is the influence
function of the force state; in the bond-based model the micromodulus is c omega(|xi|)
with c from energy equivalence. Every entry has the exact radial moments
R_k = int_0^delta omega(l) l^k dl in closed form, from which follow the continuum weighted
volume m (state-based), the bond-based micromodulus c, and the checks of both against
``manufactured.constants`` (tests).
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Callable

import numpy as np

from ..errors import InputError

#: Measure of the unit sphere in d dimensions (1D: the two directions +-1).
SPHERE = {1: 2.0, 2: 2.0 * math.pi, 3: 4.0 * math.pi}
#: int_S n_1^4 dOmega over the unit sphere (1D: 2; 2D: 3 pi / 4; 3D: 4 pi / 5).
SPHERE_N1_4 = {1: 2.0, 2: 0.75 * math.pi, 3: 0.8 * math.pi}


def _lower_gamma_at_one(s2: int) -> float:
    """gamma(s, 1) = int_0^1 t^(s-1) e^-t dt for s = s2 / 2 (s2 = 1, 2, 3, ...), exactly.

    gamma(1/2, 1) = sqrt(pi) erf(1), gamma(1, 1) = 1 - 1/e, gamma(s + 1, 1) =
    s gamma(s, 1) - 1/e (seed 001, Eqs. 53-55 use the same reduction).
    """
    s = 0.5 if s2 % 2 else 1.0
    value = math.sqrt(math.pi) * math.erf(1.0) if s2 % 2 else 1.0 - math.exp(-1.0)
    while s < s2 / 2:
        value = s * value - math.exp(-1.0)
        s += 1.0
    return value


@dataclass(frozen=True)
class Influence:
    """A radial influence function omega(|xi| / delta) and its unit radial moments."""

    name: str
    description: str
    source: str
    shape: Callable[[np.ndarray], np.ndarray]      # omega as a function of t = |xi| / delta
    partial_moment: Callable[[int, np.ndarray], np.ndarray]  # int_0^s omega(t) t^k dt

    def unit_moment(self, k: int) -> float:
        """int_0^1 omega(t) t^k dt."""
        return float(self.partial_moment(k, np.float64(1.0)))

    def radial_ratio(self, dim: int, reach, horizon: float) -> np.ndarray:
        """int_0^delta omega xi^D dxi / int_0^reach omega xi^D dxi (seed 003, Eq. 14)."""
        s = np.asarray(reach, dtype=float) / horizon
        return self.unit_moment(dim) / self.partial_moment(dim, s)

    def omega(self, length, horizon) -> np.ndarray:
        return self.shape(np.asarray(length, dtype=float) / horizon)

    def radial_moment(self, k: int, horizon: float) -> float:
        """R_k = int_0^delta omega(l) l^k dl = delta^(k+1) * unit moment."""
        return self.unit_moment(k) * horizon ** (k + 1)

    def weighted_volume(self, dim: int, horizon: float) -> float:
        """Continuum m = int_H omega |xi|^2 dV of a complete neighbourhood (per unit area in
        1D, per unit thickness in 2D): |S^(d-1)| R_(d+1)."""
        return SPHERE[dim] * self.radial_moment(dim + 1, horizon)


INFLUENCES: dict[str, Influence] = {}


def register_influence(influence: Influence) -> Influence:
    if influence.name in INFLUENCES:
        raise RuntimeError(f"influence {influence.name!r} registered twice")
    INFLUENCES[influence.name] = influence
    return influence


def _gaussian_partial(k, s):
    """int_0^s exp(-t^2) t^k dt = gamma((k + 1)/2, s^2) / 2 (s = 1: exact recursion)."""
    if np.ndim(s) == 0 and s == 1.0:
        return 0.5 * _lower_gamma_at_one(k + 1)
    from scipy.special import gamma, gammainc
    a = 0.5 * (k + 1)
    return 0.5 * gamma(a) * gammainc(a, np.asarray(s, dtype=float) ** 2)


register_influence(Influence(
    "gaussian", "exp(-|xi|^2 / delta^2)", "seed 001, Eq. (7)",
    lambda t: np.exp(-t * t), _gaussian_partial))
register_influence(Influence(
    "hyperbolic", "delta / |xi|", "seed 000, Eq. (23); seed 002, Eq. (3) as c v^2 / xi^2",
    lambda t: 1.0 / t, lambda k, s: np.asarray(s, dtype=float) ** k / k))
register_influence(Influence(
    "constant", "1", "seed 003 (constant micromodulus); seed 004, constant c",
    lambda t: np.ones_like(t), lambda k, s: np.asarray(s, dtype=float) ** (k + 1) / (k + 1)))
register_influence(Influence(
    "conical", "max(1 - |xi| / delta, 0)",
    "seed 004, Eq. (6) (triangular micromodulus); Le and Bobaru",
    # zero, not negative, at the centres of partial cells beyond delta (2D/3D stencils)
    lambda t: np.maximum(1.0 - t, 0.0),
    lambda k, s: (np.asarray(s, dtype=float) ** (k + 1) / (k + 1)
                  - np.asarray(s, dtype=float) ** (k + 2) / (k + 2))))

#: Seed 004 calls the conical micromodulus "triangular".
ALIASES = {"triangular": "conical"}


def get_influence(name: str) -> Influence:
    """The registered influence function ``name``; :class:`InputError` lists the others."""
    key = ALIASES.get(name, name)
    try:
        return INFLUENCES[key]
    except KeyError:
        allowed = ", ".join(sorted(INFLUENCES) + sorted(ALIASES))
        raise InputError(f"influence={name!r} is not registered; allowed: {allowed}") from None


# --------------------------------------------------------------------------- state-based
#: Kinds of linear state-based material: the dimension and, in 2D, the plane condition.
MATERIAL_KINDS = ("1d", "plane-strain", "plane-stress", "3d")


def material_kind(dim: int, plane: str | None = None) -> str:
    if dim == 2:
        if plane not in ("strain", "stress"):
            raise ValueError(f"2D needs plane='strain' or 'stress', got {plane!r}")
        return "plane-" + plane
    return {1: "1d", 3: "3d"}[dim]


@dataclass(frozen=True)
class StateBasedConstants:
    """c_theta, k_theta, k_e of the linear ordinary state-based force state.

    Force scalar state t = k_theta omega |xi| theta / m + k_e omega e / m and dilatation
    theta = c_theta / m int omega |xi| e dV (seed 000, Eqs. 13-19; seed 001, Eqs. 8-11).
    From energy equivalence under homogeneous strain with the moments
    int omega x^2 n_a n_b = m delta_ab / d and the fourth moment m / (d (d + 2)):
    sigma = (k_theta c_theta / d^2 + k_e / (d (d + 2))) tr(eps) I + 2 k_e / (d (d + 2)) eps.
      1d:           c_theta = 1 - 2 nu, k_theta = nu E / ((1 - 2 nu)(1 + nu)),
                    k_e = E / (1 + nu), so c_theta k_theta + k_e = E      (seed 000, Eq. 19)
      3d:           c_theta = 3, k_theta = -3 (1 - 4 nu) E / (2 (1 + nu)(1 - 2 nu)),
                    k_e = 15 E / (2 (1 + nu))                              (seed 001, §2.1)
      plane-strain: c_theta = 2, k_theta = -(1 - 4 nu) E / ((1 + nu)(1 - 2 nu)),
                    k_e = 4 E / (1 + nu)                                    (seed 001, §5)
      plane-stress: c_theta = 2, k_theta = -(1 - 3 nu) E / (1 - nu^2), k_e = 4 E / (1 + nu)
                    (same derivation with lambda* = nu E / (1 - nu^2); c_theta = 2 keeps
                    theta the in-plane trace)
    The constants do not depend on the influence function: it enters through m. All
    four kinds are cross-checked against the symbolic derivation of
    ``manufactured.constants`` (tests).
    """

    kind: str
    E: float
    nu: float

    def __post_init__(self):
        if self.kind not in MATERIAL_KINDS:
            raise ValueError(f"kind={self.kind!r}; allowed: {', '.join(MATERIAL_KINDS)}")

    @property
    def dim(self) -> int:
        return {"1d": 1, "3d": 3}.get(self.kind, 2)

    @property
    def c_theta(self) -> float:
        if self.kind == "1d":
            return 1.0 - 2.0 * self.nu
        return 3.0 if self.kind == "3d" else 2.0

    @property
    def k_theta(self) -> float:
        E, nu = self.E, self.nu
        if self.kind == "1d":
            return nu * E / ((1.0 - 2.0 * nu) * (1.0 + nu))
        if self.kind == "3d":
            return -3.0 * (1 - 4 * nu) * E / (2 * (1 + nu) * (1 - 2 * nu))
        if self.kind == "plane-strain":
            return -(1 - 4 * nu) * E / ((1 + nu) * (1 - 2 * nu))
        return -(1 - 3 * nu) * E / (1 - nu ** 2)

    @property
    def k_e(self) -> float:
        if self.kind == "1d":
            return self.E / (1.0 + self.nu)
        return (15.0 / 2.0 if self.kind == "3d" else 4.0) * self.E / (1 + self.nu)

    def moduli(self) -> tuple[float, float]:
        """The classical (lambda, mu) the constants reproduce (plane stress: lambda*; 1D:
        a bar sees only lambda + 2 mu, which is E there, with mu = E / (2 (1 + nu)))."""
        mu = self.E / (2 * (1 + self.nu))
        if self.kind == "1d":
            return self.E - 2 * mu, mu
        if self.kind == "plane-stress":
            return self.E * self.nu / (1 - self.nu ** 2), mu
        return self.E * self.nu / ((1 + self.nu) * (1 - 2 * self.nu)), mu


# --------------------------------------------------------------------------- bond-based
#: Micromodulus calibrations: ``continuum`` = energy equivalence over a complete continuous
#: horizon (seed 003, ERRATA; c_inf of seed 004); ``discrete`` = the same over the
#: discrete horizon of the stencil, so that the discrete bulk has the target modulus
#: (seed 004, Eqs. 14 and 22).
CALIBRATIONS = ("continuum", "discrete")


def bond_based_nu(dim: int, plane: str | None = None) -> float | None:
    """The one Poisson ratio a bond-based model represents: 1/4 in 3D and plane strain,
    1/3 in plane stress (None in 1D, where only E is matched)."""
    if dim == 1:
        return None
    return 1.0 / 3.0 if (dim == 2 and plane == "stress") else 0.25


def bond_micromodulus(influence: str, dim: int, E: float, horizon: float, *,
                      plane: str | None = None, area: float = 1.0,
                      calibration: str = "continuum", stencil=None, spacing=None) -> float:
    """The constant c of the micromodulus c omega(|xi|) by energy equivalence.

    Bond force density c omega(l) (e / l) on each end, bond energy c omega e^2 / (2 l),
    so W = 1/4 int_H c omega e^2 / l dV with e = l eps : n n. Matching the pure shear term
    gives c = 6 mu / M4 in 2D and 3D, and matching E eps^2 / 2 gives c = 2 E / M4 in 1D,
    with M4 = int_H omega l n_1^4 dV (1D: dV = A dl). ``continuum``: M4 = R_d int_S n_1^4
    (x A in 1D), e.g. 6 E / (A delta^2) for the triangular 1D micromodulus and
    9 E / (pi delta^3) for the constant one in plane stress. ``discrete``: M4 is the sum
    over the ``stencil``'s offsets, sum_k omega l_k n_k1^4 beta_k V (``spacing`` needed);
    in 1D this is seed 004's Eq. (14)/(22). mu = E / (2 (1 + nu)) with the bond-based
    nu of :func:`bond_based_nu`.
    """
    if calibration not in CALIBRATIONS:
        raise ValueError(f"calibration={calibration!r}; allowed: {', '.join(CALIBRATIONS)}")
    inf = get_influence(influence)
    nu = bond_based_nu(dim, plane)
    target = 2.0 * E if dim == 1 else 6.0 * E / (2.0 * (1.0 + nu))
    if calibration == "continuum":
        m4 = inf.radial_moment(dim, horizon) * SPHERE_N1_4[dim]
    else:
        xi = stencil.offsets * spacing
        length = np.linalg.norm(xi, axis=1)
        n1 = xi[:, 0] / length
        m4 = float(np.sum(inf.omega(length, horizon) * length * n1 ** 4 * stencil.beta)
                   * spacing ** dim)
    return target / (m4 * (area if dim == 1 else 1.0))
