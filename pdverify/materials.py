"""Material constants: 1D linearised state-based PD (seed 000) and influence functions."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class StateBased1D:
    """Constants of the 1D linear state-based model of seed 000, Eqs. (13) and (19).

    c_theta = 1 - 2 nu (dilatation coefficient, Eq. 14), k_theta = nu E / ((1 - 2 nu)(1 + nu))
    and k_e = E / (1 + nu) (Eq. 19, derived in App. A), so c_theta k_theta + k_e = E
    (Eq. 22).
    """

    E: float
    nu: float

    @property
    def c_theta(self) -> float:
        return 1.0 - 2.0 * self.nu

    @property
    def k_theta(self) -> float:
        return self.nu * self.E / ((1.0 - 2.0 * self.nu) * (1.0 + self.nu))

    @property
    def k_e(self) -> float:
        return self.E / (1.0 + self.nu)


def hyperbolic_influence(xi, horizon):
    """omega = delta / |xi|, seed 000 Eq. (23)."""
    return horizon / np.abs(xi)
