"""End-bond homogenisation of 1D bond-based bars (seed 004 §3-5): the bar and its factors.
The horizon ratio (m, beta) and the micromodulus constant c1 are the bar's
(:mod:`pdverify.pd.bar1d`), as the scenes describe it."""
from __future__ import annotations

from functools import lru_cache

import numpy as np

from ..errors import InputError
from ..pd import BondBasedModel, Closure, build_stencil, get_influence
from ..pd.bar1d import bar_micromodulus, check_micromodulus, split_horizon_ratio
from ..pd.build import Body, BondMaterial, build_model

END_WEIGHTS = ("full", "half")


def bond_profile(horizon_ratio: float, micromodulus: str = "triangular"):
    """Offsets k >= 1 and the per-offset weights c(k Delta)/c1 * v_k of the discrete bar.

    c(xi)/c1 is 1 (constant) or 1 - xi/delta (triangular, Eq. 6; the engine's ``conical``
    influence); v_k is the fraction of element k inside the horizon (1/2 for the element
    the horizon cuts in two, 1 otherwise: the 1D partial volume of the engine's stencil),
    which is the m(1/2 + beta) term of Eq. (9). Offsets whose weight vanishes (the
    triangle's tip at k = m when beta = 0) are dropped.
    """
    check_micromodulus(micromodulus)
    split_horizon_ratio(horizon_ratio)
    stencil = build_stencil(1, float(horizon_ratio))
    k = stencil.half_offsets[:, 0]
    weight = get_influence(micromodulus).omega(k, float(horizon_ratio)) * stencil.half_beta
    keep = weight > 0
    return k[keep], weight[keep]


def end_bond_closure(nodes: int, end_factors) -> Closure:
    """The ``homogenized`` closure: factor ``end_factors[k - 1]`` on the bonds (1, 1 + k) and
    (N, N - k) of an N-point bar (seed 004 §3.1), 1 on every other bond."""
    factors = np.asarray(end_factors, dtype=float)

    def bond_factor(a, b, _n):
        return end_bond_factors(a, b, nodes, factors)

    return Closure(bond_factor=bond_factor if factors.size else None)


def bond_bar(*, nodes: int, spacing: float, horizon_ratio: float, E: float, area: float = 1.0,
             end_weight: str = "full", micromodulus: str = "triangular",
             calibration: str = "discrete", end_factors=(),
             closure: Closure | None = None) -> BondBasedModel:
    """The bar of seed 004 as an engine model: N points x_i = (i - 1) Delta on the surface
    (``on-surface`` grid), linearised bond-based PD (Eq. 33). The bar is described here
    (body, stencil, material) and built by ``pdverify.pd.build``, with the end-bond
    closure of this module or another treatment's.

    Each point carries the element volume A Delta, or A Delta / 2 at both ends with
    ``end_weight="half"`` (Fig. 1 shows full weight). A bond of length k Delta has the
    spring stiffness alpha c1 (c(k Delta)/c1) v_k V_i V_j / (k Delta) (the engine's
    :class:`~pdverify.pd.BondBasedModel`), so that the force on i is Eq. (33) times the
    volume V_i of the subject point; alpha is the end-bond factor of
    :func:`end_bond_closure` (``end_factors``; ``()`` = the uncorrected bar).
    ``closure``: another boundary treatment of the uncorrected bar instead (a bond method
    of the registry, e.g. ``energy`` or ``volume``); it excludes ``end_factors``.
    """
    if end_weight not in END_WEIGHTS:
        raise ValueError(f"end_weight={end_weight!r}; allowed: {', '.join(END_WEIGHTS)}")
    m, _ = split_horizon_ratio(horizon_ratio)
    offsets, _ = bond_profile(horizon_ratio, micromodulus)
    if offsets.size == 0:
        raise ValueError(f"horizon_ratio={horizon_ratio}: no bond has a non-zero "
                         f"{micromodulus} micromodulus")
    if nodes < 2 * m + 1:
        raise ValueError(f"nodes={nodes} must be >= 2m + 1 = {2 * m + 1}")
    factors = np.asarray(end_factors, dtype=float)
    if factors.size and not (factors.size <= offsets.max() and np.all(factors > 0)):
        raise ValueError(f"end_factors={end_factors!r}: at most {offsets.max()} positive factors")
    if factors.size and closure is not None:
        raise ValueError("bond_bar: end_factors and closure are two boundary treatments; "
                         "give one")
    body = Body(((nodes - 1) * spacing,), (0.0,), spacing, placement="on-surface",
                boundary_volume="partial" if end_weight == "half" else "full", thickness=area)
    c1 = bar_micromodulus(horizon_ratio, E=E, area=area, spacing=spacing,
                          micromodulus=micromodulus, calibration=calibration)
    return build_model(body, build_stencil(1, float(horizon_ratio)),
                       BondMaterial(c1, get_influence(micromodulus)),
                       closure if closure is not None else end_bond_closure(nodes, factors))


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
    bar = bond_bar(nodes=n, spacing=1.0, horizon_ratio=horizon_ratio, E=1.0,
                   end_weight=end_weight, micromodulus=micromodulus)
    x = bar.grid.x[:, 0]
    u = x - x[n // 2]  # integers: every bond extension u_j - u_i is exact
    i, j, s = bar.bond_a, bar.bond_b, bar.bond_stiffness
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


def end_bond_factors(a, b, nodes: int, end_factors) -> np.ndarray:
    """The factor of each bond (a, b) of an N-point bar under :func:`end_bond_closure`."""
    alpha = np.ones(a.size)
    for k, f in enumerate(np.asarray(end_factors, dtype=float), start=1):
        # at most m - 1 offsets, not a loop over bonds
        alpha[(a == 0) & (b == k)] = f
        alpha[(b == nodes - 1) & (a == nodes - 1 - k)] = f
    return alpha


def homogenized_closure(params) -> Closure:
    """The ``homogenized`` treatment as a closure of the uncorrected bar: the factors of
    :func:`homogenization_factors` for the run's ``horizon_ratio``, ``end_weight`` and
    ``micromodulus`` on the end bonds of whatever bar it closes (the node count is the
    model's, so one closure serves a sweep over N)."""
    factors = homogenization_factors(float(params["horizon_ratio"]), params["end_weight"],
                                     params["micromodulus"])
    if not len(factors):
        return Closure()
    return Closure(geometric_factor=lambda model: end_bond_factors(
        model.bond_a, model.bond_b, model.grid.n_interior, factors),
        info={"end_factors": tuple(float(a) for a in factors)})


def check_homogenized(cells, params, where) -> None:
    """Refuse parameters for which the end-bond factors do not exist (one line)."""
    try:
        homogenization_factors(float(params["horizon_ratio"]), params["end_weight"],
                               params["micromodulus"])
    except InputError as exc:
        raise InputError(f"{where}: {exc}") from None
