"""End-bond homogenisation of 1D bond-based bars (seed 004 §3-5): the factor computation."""
from __future__ import annotations

from functools import lru_cache

import numpy as np

from ..bondbar1d import BondBar1D, bond_profile, split_horizon_ratio
from ..errors import InputError

#: A consistent system is solved to round-off (relative residual ~1e-16, the equations
#: are O(1) sums of at most 2m + 2 terms); an inconsistent one leaves an O(1/m) residual
#: (1/(2m + 1) for half-weight ends with the horizon between elements). This threshold
#: sits far from both.
CONSISTENCY_TOL = 1e-9


@lru_cache(maxsize=64)
def homogenization_factors(horizon_ratio: float, end_weight: str = "full",
                           micromodulus: str = "triangular") -> tuple[float, ...]:
    """Factors alpha_k on the bonds (1, 1 + k) and (N, N - k), k = 1..m-1 (Sec. 3.1).

    Computed, not tabulated: on a bar long enough that no equation sees both ends
    (the factors do not depend on N, Sec. 5.2), the linear field u = x must satisfy
    the equilibrium equations (33) of every point except the two loaded end points.
    The residual is affine in the factors (bond (1, 1 + k) enters only the equations
    of points 1 and 1 + k), so this is a small linear least-squares problem; the
    factors exist when its residual vanishes. For the triangular micromodulus this
    reproduces Eq. (64) / Table 6 (half weight, m - k + 1), Eq. (74) / Table 7 (full
    weight, (m - k + 1)/2) and Eq. (99) / Table 11 (between elements, j^2/(2j - 1) with
    j = m - k + 1; the printed Eq. (99) indexes the set in reverse, ERRATA).

    Raises :class:`InputError` for m < 2 (nothing to adjust) and when no factors exist:
    with half-weight ends and the horizon between elements, the bond (1, m + 1) is not
    one of the m - 1 adjusted bonds, yet it ties the half-weight point 1 into the
    equation of point m + 1 (Table 12: "n/a"). (Adjusting that bond as well would
    admit a solution, 2 on it and twice Eq. (99) on the others, but that is not the
    paper's method.) The same holds for the constant micromodulus with half-weight ends,
    whose bond (1, m + 1) does not vanish either.
    """
    m, beta = split_horizon_ratio(horizon_ratio)
    if m < 2:
        raise InputError(f"horizon_ratio={horizon_ratio:g} gives m = {m}; homogenisation "
                         "needs m >= 2 (seed 004 §3.1: m - 1 end bonds are adjusted)")
    reach = int(bond_profile(horizon_ratio, micromodulus)[0].max())
    n = 4 * reach + 3
    bar = BondBar1D(nodes=n, spacing=1.0, horizon_ratio=horizon_ratio, E=1.0,
                    end_weight=end_weight, micromodulus=micromodulus)
    u = bar.x - bar.x[n // 2]  # integers: every bond extension u_j - u_i is exact
    i, j, s = bar.bond_i, bar.bond_j, bar.bond_stiffness
    tension = s * (u[j] - u[i])
    # internal force of every point under the linear field, summed bond by bond (not K @ u,
    # whose diagonal term cancels large products and loses ~m^2 ulps)
    residual = np.bincount(i, tension, n) - np.bincount(j, tension, n)
    equations = np.arange(1, n - 1)
    J = np.zeros((n, m - 1))
    for k in range(1, m):  # one column per factor; the bond pair is found by a mask
        for end, other in ((0, k), (n - 1, n - 1 - k)):
            b = np.flatnonzero(((i == end) & (j == other)) | ((i == other) & (j == end)))
            force = s[b].sum() * (u[other] - u[end])  # on `end` from `other`, per unit factor
            J[end, k - 1] += force
            J[other, k - 1] -= force
    A, r = J[equations], residual[equations]
    delta, *_ = np.linalg.lstsq(A, -r, rcond=None)
    left = np.abs(A @ delta + r).max() / np.abs(bar.bond_stiffness).max()
    if not left <= CONSISTENCY_TOL:
        where = "between elements" if beta else "through an element"
        left_half = equations < n // 2  # name the point at the left end (the right mirrors it)
        worst = int(equations[left_half][np.argmax(np.abs(A @ delta + r)[left_half])]) + 1
        raise InputError(f"end_weight={end_weight!r} with horizon_ratio={horizon_ratio:g} "
                         f"({micromodulus} micromodulus, horizon {where}): no factors on the "
                         f"m - 1 end bonds make a linear field satisfy every equilibrium "
                         f"equation (point {worst} keeps a relative residual {left:.2g})")
    return tuple(float(a) for a in 1.0 + delta)
