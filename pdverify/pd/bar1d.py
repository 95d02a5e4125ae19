"""The 1D bond-based bar of seed 004 as a discretisation: the horizon ratio delta / Delta
= m or m + 1/2 (through or between elements) and the micromodulus constant c1 of a bar
of points x_i = (i - 1) Delta (the engine's :func:`~pdverify.pd.bond_micromodulus` in 1D,
calibrated on the discrete horizon or the continuum). A scene describes its bar with
these (:class:`~pdverify.pd.problem.BondProblem`) and the end-bond homogenisation
(``pdverify.corrections.homogenized``) closes it like any bond method; its own bar and
factors read the horizon ratio and the calibration from here.
"""
from __future__ import annotations

import numpy as np

from .bonds import build_stencil
from .influence import bond_micromodulus

CALIBRATIONS = ("discrete", "continuum")
#: seed 004's micromodulus shapes: Eq. (6)'s triangle, or constant
MICROMODULI = ("triangular", "constant")


def check_micromodulus(micromodulus: str) -> None:
    if micromodulus not in MICROMODULI:
        raise ValueError(f"micromodulus={micromodulus!r}; allowed: {', '.join(MICROMODULI)}")


def split_horizon_ratio(horizon_ratio: float) -> tuple[int, float]:
    """(m, beta) with delta = (m + beta) Delta and beta in {0, 1/2} (seed 004 Eq. 7, Fig. 2).

    beta = 0: the horizon runs through the middle of element m ("through an element");
    beta = 1/2: it falls on the border between elements m and m + 1 ("between elements").
    Raises ``ValueError`` for any other ratio.
    """
    twice = 2.0 * float(horizon_ratio)
    if not np.isfinite(twice) or abs(twice - round(twice)) > 1e-12 or round(twice) < 2:
        raise ValueError(f"horizon_ratio={horizon_ratio!r} must be a whole or half-whole number "
                         ">= 1 (delta = m Delta or (m + 1/2) Delta)")
    twice_int = int(round(twice))
    return twice_int // 2, 0.5 * (twice_int % 2)


def bar_micromodulus(horizon_ratio: float, *, E: float, area: float, spacing: float,
                     micromodulus: str = "triangular", calibration: str = "discrete") -> float:
    """The micromodulus constant c1 of seed 004 Eq. (6) (c = c1 for the constant one).

    ``discrete``: equate the strain energy density of the discrete horizon to E eps^2 / 2,
    W_m = (c1 s^2 A / 2) sum_k c_k/c1 v_k k Delta^2 (Eqs. 9, 18), which gives Eq. (14)
    (beta = 0, = Eq. 26) and Eq. (22) (beta = 1/2, = Eq. 30) for the triangular
    micromodulus. ``continuum``: c_inf = 6E/(A delta^2) (triangular) or 2E/(A delta^2)
    (constant), exact only for infinitely many points in the horizon. Both are the
    engine's :func:`pdverify.pd.bond_micromodulus` in 1D."""
    if calibration not in CALIBRATIONS:
        raise ValueError(f"calibration={calibration!r}; allowed: {', '.join(CALIBRATIONS)}")
    check_micromodulus(micromodulus)
    split_horizon_ratio(horizon_ratio)
    return bond_micromodulus(micromodulus, 1, E, horizon_ratio * spacing, area=area,
                             calibration=calibration, spacing=spacing,
                             stencil=build_stencil(1, float(horizon_ratio)))


def micromodulus_factor(horizon_ratio: float, micromodulus: str = "triangular") -> float:
    """c1(m) / c_inf, the function f_1(m) of seed 004 Eqs. (27) and (31) (Tables 1, 2)."""
    args = dict(E=1.0, area=1.0, spacing=1.0, micromodulus=micromodulus)
    return (bar_micromodulus(horizon_ratio, calibration="discrete", **args)
            / bar_micromodulus(horizon_ratio, calibration="continuum", **args))
