"""Bond families from one stencil of integer offsets (any dimension) and partial volumes beta."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

#: Gauss-Legendre points per smooth piece of the 3D partial-volume integral. With the
#: cosine substitution below every piece is analytic, so 24 points reach round-off.
_GAUSS_POINTS = 24


def unique_ids(ids) -> np.ndarray:
    """The distinct values of an integer array (node or bond numbers, keys of node pairs),
    ascending: what ``np.unique(ids)`` returns, by a sort. numpy >= 2.3's ``np.unique``
    without ``return_*`` hashes and then sorts, 40x slower on large id arrays
    (benchmarks/records/indentation-2026-11-27-unique-ids.json)."""
    s = np.sort(np.asarray(ids).ravel())
    if s.size:
        s = s[np.concatenate(([True], s[1:] != s[:-1]))]
    return s


def stencil_offsets(dim: int, m_ratio: float) -> np.ndarray:
    """Non-zero integer offsets k whose cell [k - 1/2, k + 1/2]^d meets the open ball of
    radius m_ratio (units of the spacing), i.e. whose partial volume beta is > 0."""
    reach = int(np.ceil(m_ratio + 0.5))
    axes = np.arange(-reach, reach + 1)
    k = np.stack(np.meshgrid(*([axes] * dim), indexing="ij"), axis=-1).reshape(-1, dim)
    nearest = np.maximum(np.abs(k) - 0.5, 0.0)
    keep = (np.sum(nearest ** 2, axis=1) < m_ratio ** 2) & np.any(k != 0, axis=1)
    return k[keep]


def half_stencil(offsets: np.ndarray) -> np.ndarray:
    """Mask of the offsets whose first non-zero component is positive (one per pair +-k)."""
    first = np.argmax(offsets != 0, axis=1)
    return offsets[np.arange(offsets.shape[0]), first] > 0


def _quarter_area(a, b, r):
    """Signed area of {0 <= y/a-side <= |a|, 0 <= z <= |b|} inside the disk of radius r.

    For a, b >= 0 this is the area of [0, a] x [0, b] inside y^2 + z^2 <= r^2; the sign is
    sign(a) sign(b), so a rectangle is a four-term inclusion-exclusion of corners.
    """
    s = np.sign(a) * np.sign(b)
    a, b = np.abs(a), np.abs(b)
    r = np.asarray(r, dtype=float)
    a, b, r = np.broadcast_arrays(a, b, r)
    ystar = np.sqrt(np.maximum(r * r - b * b, 0.0))  # where the arc crosses z = b
    u = np.minimum(a, r)
    v = np.minimum(ystar, u)

    def arc(y):  # int_0^y sqrt(r^2 - t^2) dt
        ratio = np.divide(y, r, out=np.zeros_like(y), where=r > 0)
        return 0.5 * (y * np.sqrt(np.maximum(r * r - y * y, 0.0))
                      + r * r * np.arcsin(np.clip(ratio, -1.0, 1.0)))

    return s * (b * v + arc(u) - arc(v))


def rectangle_disk_area(y0, y1, z0, z1, r):
    """Exact area of the rectangle [y0, y1] x [z0, z1] inside the disk of radius r at 0."""
    return (_quarter_area(y1, z1, r) - _quarter_area(y0, z1, r)
            - _quarter_area(y1, z0, r) + _quarter_area(y0, z0, r))


def partial_volumes(offsets: np.ndarray, m_ratio: float) -> np.ndarray:
    """Fraction beta of each neighbour cell inside the horizon (nodes at cell centres).

    Units of the spacing: the cell at offset k is [k - 1/2, k + 1/2]^d and the horizon a
    ball of radius ``m_ratio`` centred on the node. 1D: the length of the cell inside the
    interval (beta = 1/2 for the node at |xi| = delta at integer m_ratio). 2D: the exact area of a square inside
    a disk (closed form). 3D: beta = int A(x) dx with A the exact area of the cell's
    cross-section inside the disk of radius sqrt(R^2 - x^2); the x-range is split where
    that disk radius passes the cross-section's edge and corner distances, and each
    piece is integrated by Gauss-Legendre after the substitution x = a + (b - a)(1 -
    cos(pi t))/2, which removes the square-root end behaviour, so the result is accurate
    to round-off (seed 001 §3.1 asks for an accurate algorithm; ref. [6]).
    """
    offsets = np.atleast_2d(np.asarray(offsets, dtype=float))
    dim = offsets.shape[1]
    R = float(m_ratio)
    if dim == 1:
        # the interval [|k| - 1/2, |k| + 1/2] inside [-R, R]; at integer m_ratio the node
        # at |xi| = delta gets beta = 1/2 (ERRATA, seeds 000 and 002), which makes the
        # discrete weighted volume of a complete neighbourhood exact (seed 000, Eq. 25)
        return np.clip(R - np.abs(offsets[:, 0]) + 0.5, 0.0, 1.0)
    lo, hi = offsets - 0.5, offsets + 0.5
    if dim == 2:
        return np.clip(rectangle_disk_area(lo[:, 0], hi[:, 0], lo[:, 1], hi[:, 1], R), 0.0, 1.0)
    if dim != 3:
        raise ValueError(f"partial volumes need dim 1, 2 or 3, got {dim}")
    y0, y1, z0, z1 = lo[:, 1], hi[:, 1], lo[:, 2], hi[:, 2]
    dists = np.stack([np.abs(y0), np.abs(y1), np.abs(z0), np.abs(z1),
                      np.hypot(y0, z0), np.hypot(y0, z1), np.hypot(y1, z0), np.hypot(y1, z1)],
                     axis=1)
    xb = np.sqrt(np.maximum(R * R - dists ** 2, 0.0))
    a = np.clip(lo[:, 0], -R, R)
    b = np.clip(hi[:, 0], -R, R)
    cuts = np.concatenate([a[:, None], b[:, None], xb, -xb], axis=1)
    cuts = np.sort(np.clip(cuts, a[:, None], b[:, None]), axis=1)
    left, right = cuts[:, :-1], cuts[:, 1:]
    t, w = np.polynomial.legendre.leggauss(_GAUSS_POINTS)
    t, w = 0.5 * (t + 1.0), 0.5 * w  # on [0, 1]
    s = 0.5 * (1.0 - np.cos(np.pi * t))
    ds = 0.5 * np.pi * np.sin(np.pi * t)
    span = (right - left)[..., None]
    x = left[..., None] + span * s
    r = np.sqrt(np.maximum(R * R - x * x, 0.0))
    area = rectangle_disk_area(y0[:, None, None], y1[:, None, None],
                               z0[:, None, None], z1[:, None, None], r)
    return np.clip(np.sum(area * span * ds * w, axis=(1, 2)), 0.0, 1.0)


def fourth_moment_anisotropy(offsets: np.ndarray, weight: np.ndarray) -> float:
    """eta = A / (3 B) - 1 of the stencil's fourth moment (0 when it is isotropic).

    With M_abcd = sum_k weight_k n_a n_b n_c n_d (n = unit offset), a stencil with the
    symmetry of the cubic lattice has A = M_1111 = M_2222 (= M_3333) and B = M_1122 = ...;
    the continuum ball has A = 3 B. ``weight`` is the per-offset quadrature weight of the
    moment (e.g. omega |xi|^2 beta V).
    """
    n = offsets / np.linalg.norm(offsets, axis=1)[:, None]
    A = np.sum(weight * n[:, 0] ** 4)
    B = np.sum(weight * n[:, 0] ** 2 * n[:, 1] ** 2)
    return float(A / (3.0 * B) - 1.0)


def moment_corrected_volumes(offsets: np.ndarray, beta: np.ndarray,
                             weight: np.ndarray) -> np.ndarray:
    """Partial volumes adjusted so that the stencil's fourth moment is isotropic.

    Our addition (not in seed 001). Exact cell fractions ``beta`` leave the lattice
    moment M_abcd = sum_k weight_k beta_k n_a n_b n_c n_d with cubic, not isotropic,
    symmetry (``fourth_moment_anisotropy``): the discrete state-based material then has
    three moduli C11, C12, C44 instead of lambda and mu, about 1 % off at m = 3 in 2D
    (0.04 % in 3D). The single condition A = 3 B (cubic symmetry leaves no other) is a
    linear constraint sum_k beta'_k g_k = 0 with g = weight (S4 / d - 3 S22 / (d (d - 1))),
    S4 = sum_a n_a^4, S22 = sum_(a != b) n_a^2 n_b^2. We take the smallest change in the
    metric sum (beta' - beta)^2 / (beta (1 - beta)):
        beta' = beta + lam beta (1 - beta) g,  lam = -sum(beta g) / sum(beta (1 - beta) g^2),
    so only the cells cut by the horizon change (full and empty cells are exact), the
    change keeps the lattice symmetry (g has it) and stays small (< 2 % of a cell at
    m = 3). The second moment stays isotropic (cubic symmetry), so with m computed from
    the same weights the discrete bulk material has exactly the continuum moduli.
    """
    d = offsets.shape[1]
    n = offsets / np.linalg.norm(offsets, axis=1)[:, None]
    s4 = np.sum(n ** 4, axis=1)
    s22 = np.sum(n ** 2, axis=1) ** 2 - s4
    g = weight * (s4 / d - 3.0 * s22 / (d * (d - 1)))
    cut = beta * (1.0 - beta)
    lam = -np.sum(beta * g) / np.sum(cut * g * g)
    return beta + lam * cut * g


def bond_pairs(ext_shape, offsets: np.ndarray):
    """All node pairs (a, a + k) of a grid of shape ``ext_shape`` for each offset k.

    Built by array slicing, one block per offset (no per-bond loop). Returns flat node ids
    ``a``, ``b`` and ``which`` (index of the offset).
    """
    ext_shape = tuple(ext_shape)
    ids = np.arange(int(np.prod(ext_shape))).reshape(ext_shape)
    a_parts, b_parts, w_parts = [], [], []
    for n, k in enumerate(offsets):
        src, dst = [], []
        for axis, kk in enumerate(k):
            size = ext_shape[axis]
            kk = int(kk)
            if abs(kk) >= size:
                break
            src.append(slice(max(0, -kk), size - max(0, kk)))
            dst.append(slice(max(0, kk), size - max(0, -kk)))
        else:
            a = ids[tuple(src)].ravel()
            b = ids[tuple(dst)].ravel()
            a_parts.append(a)
            b_parts.append(b)
            w_parts.append(np.full(a.shape, n))
    if not a_parts:
        empty = np.zeros(0, dtype=int)
        return empty, empty, empty
    return np.concatenate(a_parts), np.concatenate(b_parts), np.concatenate(w_parts)


#: Weights beta of the one-point quadrature over a neighbourhood: ``partial-volume`` = the
#: exact fraction of each cell inside the horizon (seed 001 §3.1; in 1D the seed-000 rule),
#: ``moment-corrected`` (our addition) = those fractions minimally adjusted so that the
#: stencil's fourth moment is isotropic (2D and 3D; :func:`moment_corrected_volumes`),
#: ``full-cells`` = the whole cell of every neighbour whose node lies in the closed horizon
#: |xi| <= delta, none of the others (no partial volumes, as in Peridigm by default; it
#: reproduces seed 003's Tables 1 and 2).
QUADRATURES = ("partial-volume", "moment-corrected", "full-cells")


@dataclass(frozen=True)
class Stencil:
    """The integer offsets of one neighbourhood and their quadrature weights beta.

    ``offsets`` (n, dim) are every non-zero offset whose cell meets the horizon (both
    signs), ``beta`` their weights; ``half`` masks one offset of each pair +-k, the one
    bonds are built from (a bond a -> a + k for every half offset k).
    """

    dim: int
    m_ratio: float
    quadrature: str
    offsets: np.ndarray
    beta: np.ndarray

    @property
    def half(self) -> np.ndarray:
        return half_stencil(self.offsets)

    @property
    def half_offsets(self) -> np.ndarray:
        return self.offsets[self.half]

    @property
    def half_beta(self) -> np.ndarray:
        return self.beta[self.half]

    def vectors(self, spacing: float) -> tuple[np.ndarray, np.ndarray]:
        """Lengths |xi| and unit vectors xi / |xi| of every offset at ``spacing``."""
        xi = self.offsets * float(spacing)
        r = np.linalg.norm(xi, axis=1)
        return r, xi / r[:, None]

    @property
    def reach(self) -> int:
        """Largest offset along an axis: the fictitious layer that completes a neighbourhood."""
        return int(np.abs(self.offsets).max()) if self.offsets.size else 0


def homogeneous_extensions(lengths, units, strain) -> np.ndarray:
    """Linearised extensions e = |xi| n . strain . n of bonds under a homogeneous strain."""
    return lengths * np.einsum("bi,ij,bj->b", units, np.asarray(strain, dtype=float), units)


def build_stencil(dim: int, m_ratio: float, *, quadrature: str = "partial-volume",
                  moment_weight=None) -> Stencil:
    """The stencil of horizon ``m_ratio`` spacings with the weights of ``quadrature``.

    ``moment_weight(offsets) -> (n,)`` is the per-offset weight of the fourth moment that
    ``moment-corrected`` makes isotropic (state-based: omega |xi|^2; bond-based:
    omega |xi|); it is required for that quadrature only.
    """
    if quadrature not in QUADRATURES:
        raise ValueError(f"quadrature={quadrature!r}; allowed: {', '.join(QUADRATURES)}")
    offsets = stencil_offsets(dim, m_ratio)
    beta = partial_volumes(offsets, m_ratio)
    if quadrature == "full-cells":
        inside = np.linalg.norm(offsets, axis=1) <= m_ratio * (1.0 + 1e-12)
        offsets, beta = offsets[inside], np.ones(int(inside.sum()))
    if quadrature == "moment-corrected":
        if dim < 2:
            raise ValueError("quadrature='moment-corrected' needs dim 2 or 3 (a 1D stencil "
                             "has no fourth-moment anisotropy)")
        beta = moment_corrected_volumes(offsets, beta, moment_weight(offsets))
    return Stencil(dim, float(m_ratio), quadrature, offsets, beta)
