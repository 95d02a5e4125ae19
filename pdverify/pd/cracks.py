"""K_I from a displacement field on a straight mode I crack: the Williams fit of the opening
(issue 54); K_I and K_II of a mixed-mode crack at any angle to the lattice: the Williams
fit of the field in an annulus (:func:`fit_k_mixed`, its own section below). Numerics
only.

Method (stated once). Williams' mode I expansion about the tip, in polar coordinates
(r, theta) with theta = +-pi on the two crack faces, has the displacement

    u_y = sum_n a_n r^(n/2) / (2 mu) [(kappa - n/2 - (-1)^n) sin(n theta / 2)
                                       + (n/2) sin((n/2 - 2) theta)],

K_I = a_1 sqrt(2 pi); kappa = (3 - nu) / (1 + nu) in plane stress, 3 - 4 nu in plane
strain (:data:`PLANES`); mu = E / (2 (1 + nu)). u_y is odd in theta, so the opening of a
pair of points mirrored about the crack line, u_y(r, theta) - u_y(r, -theta), is twice it;
on the faces themselves (theta = pi) the even-n terms vanish and the opening is
(8 / E') sqrt(r / 2 pi) (K + c_1 r + c_2 r^2 + ...), E' = E (plane stress) or
E / (1 - nu^2) (plane strain).

(``reference_fem.crack_plate.opening_fit`` fits the face form at points on the face
itself, where a FEM field can be evaluated; a PD grid has no node there, hence this fit.)
A PD grid has no node on the crack faces: the nodes nearest a slit between two node rows
sit at +-h/2 from it. The fit therefore uses every term's full angular function at each
pair's own (r, theta) (the angle theta = pi - O(h / r) matters: at r = 3 h the leading
term alone differs from its face value by about (h / 2r)^2 = 3 %), least squares of the
measured openings of the mirrored pairs on the orders ``orders`` (default n = 1, 2, 3,
5). The even orders vanish on the faces (there the opening is the face form above), but
at +-h/2 from them n = 2 (the T-stress) adds to the opening a part that is constant along
a row and proportional to the row's distance from the crack ((kappa - 3) a_2 t / mu):
one row cannot tell it from sqrt(r) over a window a few horizons long, two rows can, so
the default fits the two node rows nearest the crack on each side (``rows``) with n = 2
among the orders. Measured on the converged FEM field of the centre-cracked plate
sampled at PD node positions (a/W = 0.5, H/W = 3, window below, h = 1/40 .. 1/160): the
odd orders (1, 3) on one row read K 1.8 .. 1.0 % high, (1, 3, 5) on one row 0.53 ..
0.16 %, the default -0.16 .. -0.07 % (``benchmarks/crack_k.py`` prints the fit of the
FEM field beside every PD number).

Window: the pairs behind the tip whose r (the node's distance to the tip) lies in
[``tip_zone`` horizons, ``reach`` x min(a, W - a)] (defaults 2 horizons and 0.8), with a
the crack's length from its tip to its other end or centre and W - a the ligament. Inside the tip zone PD and LEFM cannot
agree (the nonlocal zone: a PD crack tip has no r^(1/2) singularity, its opening is
blunted within a few horizons); beyond ``reach`` the finite body's higher terms grow.

Accuracy (:attr:`KFit.amplification`): the fitted K is a linear functional of the
openings, K = sum_i w_i d_i, so an error e_i in the openings (the series' truncation,
a blunted tip, a model's error) changes K by at most sum_i |w_i| max_i |e_i|;
``amplification`` is sum_i |w_i| (units K per metre of opening), the bound's factor for
any error the caller can bound.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

#: kappa of the two plane theories
PLANES = ("plane-stress", "plane-strain")


def kolosov(nu: float, plane: str) -> float:
    """Kolosov's kappa: (3 - nu)/(1 + nu) in plane stress, 3 - 4 nu in plane strain."""
    if plane not in PLANES:
        raise ValueError(f"plane={plane!r}: allowed {PLANES}")
    return (3.0 - nu) / (1.0 + nu) if plane == "plane-stress" else 3.0 - 4.0 * nu


def effective_modulus(E: float, nu: float, plane: str) -> float:
    """E' of the opening (8 / E') sqrt(r / 2 pi) K: E (plane stress), E / (1 - nu^2)."""
    kolosov(nu, plane)
    return E if plane == "plane-stress" else E / (1.0 - nu * nu)


def williams_uy(r, theta, n: int, E: float, nu: float, plane: str) -> np.ndarray:
    """u_y of Williams' mode I term n with a_n = 1 (module docstring)."""
    kap = kolosov(nu, plane)
    mu = E / (2.0 * (1.0 + nu))
    h = 0.5 * n
    return r ** h / (2 * mu) * ((kap - h - (-1) ** n) * np.sin(h * theta)
                                + h * np.sin((h - 2) * theta))


def williams_ux(r, theta, n: int, E: float, nu: float, plane: str) -> np.ndarray:
    """u_x of Williams' mode I term n with a_n = 1."""
    kap = kolosov(nu, plane)
    mu = E / (2.0 * (1.0 + nu))
    h = 0.5 * n
    return r ** h / (2 * mu) * ((kap + h + (-1) ** n) * np.cos(h * theta)
                                - h * np.cos((h - 2) * theta))


def williams_field(x, tip, direction, coefficients, E, nu, plane) -> np.ndarray:
    """The displacement (n, 2) of the mode I series ``coefficients`` = (a_1, a_2, ...)
    about ``tip``, the crack running from the tip along -``direction`` (a unit vector
    along the crack line, pointing ahead of the tip)."""
    return williams_mixed_field(x, tip, direction, coefficients, (), E, nu, plane,
                                translation=None)


@dataclass(frozen=True)
class KFit:
    """A fit of the opening: ``k`` (K_I, Pa m^0.5), ``coefficients`` a_n of the orders,
    ``r`` and ``opening`` of the pairs used, ``window`` (r0, r1) (m), ``amplification``
    sum |w_i| (module docstring), ``residual`` the largest |fit - opening| (m)."""

    k: float
    coefficients: np.ndarray
    r: np.ndarray
    opening: np.ndarray
    window: tuple
    amplification: float
    residual: float


def opening_pairs(x, u, tip, direction, spacing: float):
    """The mirrored pairs of nodes about the crack line behind the tip: ``(r, theta,
    opening, t)`` with theta in (0, pi] of the upper node, r its distance to the tip and the
    opening u_n(upper) - u_n(lower) (u_n the component along the crack's left normal).
    Pairs are matched on the lattice (position rounded to ``spacing`` / 1000)."""
    x, u = np.asarray(x, float), np.asarray(u, float)
    e = np.asarray(direction, float) / np.linalg.norm(direction)
    nrm = np.array([-e[1], e[0]])
    d = x - np.asarray(tip, float)
    s, t = d @ e, d @ nrm
    behind = s < 0
    q = 1e-3 * spacing
    key = lambda a, b: np.round(a / q).astype(np.int64) * (1 << 31) + np.round(b / q).astype(
        np.int64)
    up = np.flatnonzero(behind & (t > 0))
    lo = np.flatnonzero(behind & (t < 0))
    order = np.argsort(key(s[lo], -t[lo]))
    klo = key(s[lo], -t[lo])[order]
    kup = key(s[up], t[up])
    pos = np.searchsorted(klo, kup)
    ok = (pos < klo.size) & (klo[np.minimum(pos, klo.size - 1)] == kup)
    iu, il = up[ok], lo[order][pos[ok]]
    r = np.hypot(s[iu], t[iu])
    th = np.arctan2(t[iu], s[iu])
    return r, th, (u[iu] - u[il]) @ nrm, t[iu]


def fit_k(x, u, tip, direction, *, E: float, nu: float, plane: str, horizon: float,
          spacing: float, crack_length: float, ligament: float, tip_zone: float = 2.0,
          reach: float = 0.8, orders: tuple = (1, 2, 3, 5), rows: int = 2) -> KFit:
    """K_I by the Williams fit of the opening (module docstring) from nodes ``x`` (n, 2)
    and their displacements ``u``: the node pairs of the ``rows`` rows nearest the crack
    on either side, r in [``tip_zone`` x ``horizon``, ``reach`` x min(``crack_length``,
    ``ligament``)], the Williams orders ``orders`` (1 first). ``ValueError`` when the
    window holds fewer pairs than twice the orders."""
    orders = tuple(int(n) for n in orders)
    if not (tip_zone >= 0 and 0 < reach <= 1 and rows >= 1 and orders[:1] == (1,)
            and len(set(orders)) == len(orders)):
        raise ValueError(f"tip_zone={tip_zone!r} must be >= 0, reach={reach!r} in (0, 1], "
                         f"rows={rows!r} >= 1, orders={orders!r} distinct, 1 first")
    terms = len(orders)
    r, th, op, t = opening_pairs(x, u, tip, direction, spacing)
    r0, r1 = tip_zone * horizon, reach * min(crack_length, ligament)
    nearest = t <= t.min() + (rows - 1 + 1e-6) * spacing if t.size else t.astype(bool)
    use = nearest & (r >= r0) & (r <= r1)
    if use.sum() < 2 * terms:
        raise ValueError(f"the window r in [{r0:g}, {r1:g}] holds {int(use.sum())} node pairs; "
                         f"the fit of {terms} terms needs at least {2 * terms}")
    r, th, op = r[use], th[use], op[use]
    A = np.stack([2 * williams_uy(r, th, n, E, nu, plane) for n in orders], 1)
    coef, *_ = np.linalg.lstsq(A, op, rcond=None)
    w = np.linalg.pinv(A)[0] * math.sqrt(2 * math.pi)
    order = np.argsort(r)
    return KFit(k=float(coef[0] * math.sqrt(2 * math.pi)), coefficients=coef, r=r[order],
                opening=op[order], window=(r0, r1), amplification=float(np.abs(w).sum()),
                residual=float(np.abs(A @ coef - op).max()))


# --- mixed mode: both modes from the field in an annulus -------------------------------------
#
# Williams' mode II terms (the companion of the mode I ones above; e.g. Karihaloo & Xiao,
# Int. J. Fract. 2001), in the tip frame:
#
#     u_x = b_n r^(n/2) / (2 mu) [(kappa + n/2 - (-1)^n) sin(n theta / 2)
#                                  - (n/2) sin((n/2 - 2) theta)],
#     u_y = b_n r^(n/2) / (2 mu) [-(kappa - n/2 + (-1)^n) cos(n theta / 2)
#                                  - (n/2) cos((n/2 - 2) theta)],
#
# K_II = b_1 sqrt(2 pi) (n = 1 is the textbook near-tip field; n = 2 is a rigid rotation).
# fit_k_mixed fits a_n and b_n of the orders ``orders`` plus a rigid translation to both
# displacement components of every node in the annulus r in [tip_zone horizons, reach]
# about the tip (theta in (-pi, pi] from the crack's own frame, so a node's face is its
# sign of theta): no node pairs, so the lattice may lie at any angle to the crack. The
# tip zone is left out as in fit_k (the nonlocal zone); ``reach`` must stay inside the
# series' disk of convergence (the distance to the other tip and to the body's edge).
# Accuracy as fit_k's: K_I and K_II are linear functionals of the displacements,
# K = sum_i w_i u_i, so an error e_i of the field changes them by at most
# sum_i |w_i| max |e_i| (``amplification``, one per mode). Orders: measured on the
# converged FEM field of plate-inclined-crack (beta = 30, a = 0.5, W = H = 1) sampled at
# the PD nodes, h = 1/30 .. 1/80, annulus [2 horizons, 0.4 m]: orders 1..5 read K_I,
# K_II 0.39-0.42 % and 0.35-0.39 % low, 1..7 (the default) within 0.005 % and 0.031 %,
# 1..9 within 0.003 % and 0.011 % (the amplification about the same, 3.1e9 Pa m^-0.5).


def williams_mode2(r, theta, n: int, E: float, nu: float, plane: str):
    """(u_x, u_y) of Williams' mode II term n with b_n = 1, in the tip frame."""
    kap = kolosov(nu, plane)
    mu = E / (2.0 * (1.0 + nu))
    h, sg = 0.5 * n, (-1.0) ** n
    f = r ** h / (2 * mu)
    return (f * ((kap + h - sg) * np.sin(h * theta) - h * np.sin((h - 2) * theta)),
            f * (-(kap - h + sg) * np.cos(h * theta) - h * np.cos((h - 2) * theta)))


def williams_mixed_field(x, tip, direction, mode1, mode2, E, nu, plane,
                         translation=(0.0, 0.0)) -> np.ndarray:
    """The displacement (n, 2) of the series ``mode1`` = (a_1, a_2, ...) and ``mode2`` =
    (b_1, b_2, ...) about ``tip`` (the crack behind it along -``direction``), plus a
    rigid ``translation`` (None: none added)."""
    x = np.asarray(x, float)
    e = np.asarray(direction, float) / np.linalg.norm(direction)
    nrm = np.array([-e[1], e[0]])
    d = x - np.asarray(tip, float)
    s, t = d @ e, d @ nrm
    r, th = np.hypot(s, t), np.arctan2(t, s)
    ul = np.zeros((len(x), 2))
    for n, a in enumerate(mode1, start=1):
        ul[:, 0] += a * williams_ux(r, th, n, E, nu, plane)
        ul[:, 1] += a * williams_uy(r, th, n, E, nu, plane)
    for n, b in enumerate(mode2, start=1):
        wx, wy = williams_mode2(r, th, n, E, nu, plane)
        ul[:, 0] += b * wx
        ul[:, 1] += b * wy
    out = ul[:, :1] * e + ul[:, 1:] * nrm
    return out if translation is None else out + np.asarray(translation, float)


@dataclass(frozen=True)
class KMixedFit:
    """A fit of both modes: ``k1``, ``k2`` (Pa m^0.5), ``coefficients`` (a_n of the
    orders, then b_n, then the translation), ``nodes`` the number of nodes used,
    ``window`` (r0, r1) (m), ``amplification`` (sum |w_i| of K_I, of K_II: K per metre of
    displacement), ``residual`` the largest |fit - u| (m)."""

    k1: float
    k2: float
    coefficients: np.ndarray
    nodes: int
    window: tuple
    amplification: tuple
    residual: float


def fit_k_mixed(x, u, tip, direction, *, E: float, nu: float, plane: str, horizon: float,
                reach: float, tip_zone: float = 2.0, orders: tuple = (1, 2, 3, 4, 5, 6, 7),
                mask=None) -> KMixedFit:
    """K_I and K_II by the Williams fit of both displacement components in the annulus
    r in [``tip_zone`` x ``horizon``, ``reach``] about ``tip`` (the section's comment):
    nodes ``x`` (n, 2), displacements ``u`` (n, 2), the crack behind the tip along
    -``direction``; ``mask`` (optional, bool (n,)) restricts the nodes. ``ValueError``
    when the annulus holds fewer nodes than the unknowns."""
    orders = tuple(int(n) for n in orders)
    if not (tip_zone >= 0 and reach > tip_zone * horizon and orders[:1] == (1,)
            and len(set(orders)) == len(orders)):
        raise ValueError(f"tip_zone={tip_zone!r} must be >= 0, reach={reach!r} beyond the "
                         f"tip zone ({tip_zone * horizon:g}), orders={orders!r} distinct, "
                         "1 first")
    x, u = np.asarray(x, float), np.asarray(u, float)
    e = np.asarray(direction, float) / np.linalg.norm(direction)
    nrm = np.array([-e[1], e[0]])
    d = x - np.asarray(tip, float)
    s, t = d @ e, d @ nrm
    r, th = np.hypot(s, t), np.arctan2(t, s)
    r0 = tip_zone * horizon
    use = (r >= r0) & (r <= reach)
    if mask is not None:
        use &= np.asarray(mask, bool)
    terms = 2 * len(orders) + 2
    if 2 * use.sum() < 2 * terms:
        raise ValueError(f"the annulus r in [{r0:g}, {reach:g}] holds {int(use.sum())} nodes; "
                         f"the fit of {terms} unknowns needs at least {terms}")
    r, th = r[use], th[use]
    cols = []
    for n in orders:
        cols.append((williams_ux(r, th, n, E, nu, plane), williams_uy(r, th, n, E, nu, plane)))
    for n in orders:
        cols.append(williams_mode2(r, th, n, E, nu, plane))
    ones = np.ones_like(r)
    # the translation, in the global frame, expressed in the tip frame
    cols.append((ones * e[0], ones * nrm[0]))
    cols.append((ones * e[1], ones * nrm[1]))
    A = np.stack([np.concatenate(c) for c in cols], 1)         # (2 m, terms)
    ul = np.concatenate([u[use] @ e, u[use] @ nrm])
    scale = np.abs(A).max(axis=0)                                # column equilibration
    coef, *_ = np.linalg.lstsq(A / scale, ul, rcond=None)
    coef = coef / scale
    pinv = np.linalg.pinv(A / scale) / scale[:, None]
    i2 = len(orders)
    c = math.sqrt(2 * math.pi)
    return KMixedFit(k1=float(coef[0] * c), k2=float(coef[i2] * c), coefficients=coef,
                     nodes=int(use.sum()), window=(r0, float(reach)),
                     amplification=(float(np.abs(pinv[0]).sum() * c),
                                    float(np.abs(pinv[i2]).sum() * c)),
                     residual=float(np.abs(A @ coef - ul).max()))
