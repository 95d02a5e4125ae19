"""plate-hole: square plate with a central circular hole under remote uniaxial tension.

The problem (issue 35, the first scene that is not a box): a square plate of half-width
W with a central circular hole of radius a, pulled by a uniform traction sigma on the two
edges normal to x, plane stress. By symmetry a quarter is modelled:

- domain: [0, W] x [0, W] minus the disk r < a about the origin; defaults W = 1 m,
  a = 0.2 m, E = 1 GPa, nu = 0.3, thickness 1 m, sigma = 1 MPa;
- u_x = 0 on x = 0 (a <= y <= W) and u_y = 0 on y = 0 (a <= x <= W) (the symmetry
  lines; they also remove every rigid motion); traction (sigma, 0) on x = W; the edge
  y = W and the arc are free.

Elements and mesh: 9-node biquadratic quadrilaterals (vector ``ElementQuad2`` on
``skfem.MeshQuad2``), isoparametric: each element map is the biquadratic interpolant of
an exact map, so the arc is met at three points per element edge and resolved to
O(h^3) (the optimal order of Q2 is kept: Ciarlet & Raviart 1972, Lenoir 1986). The mesh
is two mapped blocks split by the diagonal y = x. In the block next to the x-axis, the
logical square (s, t) in [0, 1]^2 maps to the ray from the origin through the outer
point O(t) = (W, W t), between the arc and O:

    P(s, t) = a O/|O| + g(s) (O - a O/|O|),      g(s) = expm1(beta s) / expm1(beta);

the other block is its mirror image in y = x (outer points (W (1 - t), W)). Along the arc
the nodes are at the angles atan(t) (resp. pi/2 - atan(1 - t)); radially they are graded
toward the hole by g. ``beta`` is chosen so that at theta = 0 the first radial element is
as long as the arc element (aspect one at the hole): beta / expm1(beta) =
a n_s / ((W - a) n_t) (beta = 0, uniform, when the right side is >= 1). Level l has
``radial_cells * 2^l`` elements along the rays and ``arc_cells * 2^l`` along the arc in
each block (uniform refinement of the logical squares under the same smooth map, so the
grading stays the same while the elements halve).

Refinement study: the compared quantity is u_x at (W, 0) (the loaded edge on the
symmetry line). Each row's ``extra`` has ``field_change_pct`` (from level 1), the change
of the whole field between successive levels on the sample points, normalised as in
``plate.py`` (100 max |u_l - u_{l-1}| / max |u_l|); the sample points are the centres of
the cells of a ``sample_spacing`` grid on [0, W]^2 (the PD default grid, 0.025 m) that lie
in the domain; and ``scf`` = sigma_xx(0, a) / sigma, the stress concentration factor (the
stress of the element at (0, a), the node where the arc meets x = 0).

Measured with the defaults (4 x 4 elements per block at level 0, five levels, finest
64 x 64 per block, 66 306 DOFs, the whole study about 5 s on one core): the field
changes on the sample points fall 0.195, 0.055, 0.0117, 0.0018 % (toward the h^3 factor
8), u_x(W, 0) = 1.22584e-3 m changes by 1.6e-4 % over the last refinement, and the stress
concentration is 3.3601 (changes falling by ~4, O(h^2)). The finite plate (W/a = 5)
concentrates more than Kirsch's infinite one (3); see :func:`large_plate_check`.

The Kirsch checks (:func:`kirsch_check`, :func:`large_plate_check`): Kirsch's solution of
the infinite plate with a hole (Kirsch 1898;
Timoshenko & Goodier Sec. 35) is an exact solution of this quarter with Kirsch's own
traction on x = W and y = W, so the FEM must converge to it at the rate of Q2 (O(h^3) in
the displacement; measured: 0.070, 0.0072, 0.00095, 0.000115 % of max |u| at 4..32
elements along each block's arc, a fitted rate 3.07, and the stress concentration
2.9914, 2.9981, 2.9995, 2.99988); and a plate with W/a large under uniform tension must
approach Kirsch's stress concentration 3 and displacement near the hole (measured at
W/a = 5, 10, 20, 40: 3.360, 3.085, 3.020, 3.004, i.e. 3 + ~8.5 (a/W)^2, and the
displacement on r = a, 2a within 12.7, 2.9, 0.72, 0.18 % of Kirsch's).

Evaluation: the field is a :class:`~reference_fem.mesh_field.MeshField`; a point of the
exact domain that the discrete domain misses (between the arc and its parabolic
interpolant, O(h^3), or 1e-12 outside by round-off) gets the nearest element's
polynomial extended (see that module); points outside the exact domain raise
``ValueError``.
"""
from __future__ import annotations

import math
import time
from dataclasses import dataclass

import numpy as np
from scipy.optimize import brentq

from . import params as _p
from .cache import cached
from .elasticity import Material
from .mesh_elasticity import MeshElasticity, mapped_mesh
from .results import MeshReferenceResult, RefinementRow, change_pct, field_change_pct

REFERENCE = "plate-hole"


@dataclass(frozen=True)
class HolePlateParams:
    """Parameters of the quarter plate with a hole (defaults: issue 35)."""

    width: float = 1.0            # W: the quarter is [0, W]^2 (m)
    radius: float = 0.2           # a: hole radius (m)
    thickness: float = 1.0        # m
    E: float = 1e9                # Pa
    nu: float = 0.3
    traction: float = 1e6         # sigma on x = W (Pa)
    radial_cells: int = 4         # level 0: elements along each ray (per block)
    arc_cells: int = 4            # level 0: elements along the arc in each of 2 blocks
    levels: int = 5               # refinement levels (cells x 2^l)
    sample_spacing: float = 0.025  # grid of the field-change measure (PD default grid)

    def __post_init__(self):
        _p.positive(REFERENCE, width=self.width, radius=self.radius,
                    thickness=self.thickness, E=self.E, sample_spacing=self.sample_spacing)
        _p.require(-1 < self.nu < 0.5, REFERENCE, f"nu must lie in (-1, 0.5), got {self.nu}")
        _p.require(math.isfinite(self.traction) and self.traction != 0, REFERENCE,
                   f"traction must be finite and nonzero, got {self.traction}")
        _p.require(self.radius < 0.95 * self.width, REFERENCE,
                   f"radius {self.radius} must be below 0.95 width ({self.width}): the hole "
                   "must leave a ligament")
        _p.require(self.width <= 1e3 * self.radius, REFERENCE,
                   f"width/radius = {self.width / self.radius:g} exceeds 1000")
        for name, v in (("radial_cells", self.radial_cells), ("arc_cells", self.arc_cells)):
            _p.require(1 <= v <= 64, REFERENCE, f"{name} must be 1..64, got {v}")
        _p.require(2 <= self.levels <= 7, REFERENCE, f"levels must be 2..7, got {self.levels}")
        n = self.width / self.sample_spacing
        _p.require(abs(n - round(n)) < 1e-9 * n and round(n) >= 1, REFERENCE,
                   f"sample_spacing {self.sample_spacing} must divide width {self.width}")
        ns, nt = self.finest_cells()
        _p.require(ns * nt <= 2 ** 18, REFERENCE,
                   f"the finest level would have {ns * nt} elements (at most 2^18)")

    def finest_cells(self) -> tuple[int, int]:
        """(n_s, 2 n_t) of the finest level: the two blocks together are an
        n_s x 2 n_t grid of Q2 elements, (2 n_s + 1)(4 n_t + 1) nodes, as a tensor grid of
        that many cells has (for a resource estimate)."""
        f = 2 ** (self.levels - 1)
        return self.radial_cells * f, 2 * self.arc_cells * f


# --- Kirsch's infinite plate ---------------------------------------------------------------

def kirsch_stress(x, y, radius: float, sigma: float):
    """Kirsch's stress (sxx, syy, sxy) of the infinite plane stretched by sigma along x
    with a traction-free hole r = radius (Kirsch 1898; Timoshenko & Goodier, Theory of
    Elasticity, 3rd ed., Art. 35)."""
    r = np.hypot(x, y)
    th = np.arctan2(y, x)
    q2, q4 = (radius / r) ** 2, (radius / r) ** 4
    c2, s2 = np.cos(2 * th), np.sin(2 * th)
    srr = 0.5 * sigma * (1 - q2) + 0.5 * sigma * (1 - 4 * q2 + 3 * q4) * c2
    stt = 0.5 * sigma * (1 + q2) - 0.5 * sigma * (1 + 3 * q4) * c2
    srt = -0.5 * sigma * (1 + 2 * q2 - 3 * q4) * s2
    c, s = np.cos(th), np.sin(th)
    sxx = srr * c * c + stt * s * s - 2 * srt * s * c
    syy = srr * s * s + stt * c * c + 2 * srt * s * c
    sxy = (srr - stt) * s * c + srt * (c * c - s * s)
    return sxx, syy, sxy


def kirsch_displacement(x, y, radius: float, sigma: float, E: float, nu: float):
    """Kirsch's displacement (u_x, u_y), plane stress, of the same problem; zero rigid
    motion (it is odd in x for u_x and odd in y for u_y, as the symmetry conditions
    require). kappa = (3 - nu)/(1 + nu), mu = E / (2 (1 + nu)):

        u_r = sigma/(4 mu) [r ((kappa - 1)/2 + cos 2t) + a^2/r (1 + (1 + kappa) cos 2t)
                            - a^4/r^3 cos 2t]
        u_t = sigma/(4 mu) [(1 - kappa) a^2/r - r - a^4/r^3] sin 2t
    """
    kappa = (3 - nu) / (1 + nu)
    mu = E / (2 * (1 + nu))
    r = np.hypot(x, y)
    th = np.arctan2(y, x)
    a2, a4 = radius ** 2, radius ** 4
    c2, s2 = np.cos(2 * th), np.sin(2 * th)
    k = sigma / (4 * mu)
    ur = k * (r * ((kappa - 1) / 2 + c2) + a2 / r * (1 + (1 + kappa) * c2) - a4 / r ** 3 * c2)
    ut = k * ((1 - kappa) * a2 / r - r - a4 / r ** 3) * s2
    c, s = np.cos(th), np.sin(th)
    return ur * c - ut * s, ur * s + ut * c


# --- mesh and one level --------------------------------------------------------------------

def grading_beta(width: float, radius: float, n_s: int, n_t: int) -> float:
    """beta of the radial map g: beta / expm1(beta) = a n_s / ((W - a) n_t), 0 if >= 1."""
    c = radius * n_s / ((width - radius) * n_t)
    if c >= 1.0:
        return 0.0
    return float(brentq(lambda b: b / math.expm1(b) - c, 1e-12, 200.0, xtol=1e-14))


def hole_mesh(width: float, radius: float, n_s: int, n_t: int):
    """The two-block isoparametric mesh of the quarter (see the module docstring)."""
    W, a = float(width), float(radius)
    beta = grading_beta(W, a, n_s, n_t)

    def g(s):
        return s if beta == 0.0 else np.expm1(beta * s) / math.expm1(beta)

    def ray(ox, oy, s):
        norm = np.hypot(ox, oy)
        ix, iy = a * ox / norm, a * oy / norm
        gs = g(s)
        return ix + gs * (ox - ix), iy + gs * (oy - iy)

    def block_x(s, t):            # theta in [0, pi/4]: outer points on x = W
        return ray(W + 0 * t, W * t, s)

    def block_y(s, t):            # theta in [pi/4, pi/2]: outer points on y = W
        return ray(W * (1 - t), W + 0 * t, s)

    s = np.linspace(0.0, 1.0, n_s + 1)
    t = np.linspace(0.0, 1.0, n_t + 1)
    return mapped_mesh([(s, t, block_x), (s, t, block_y)], tol=1e-9 * W)


def domain(width: float, radius: float) -> dict:
    return {"box": [[0.0, width], [0.0, width]], "disks": [[0.0, 0.0, radius]]}


def solve_quarter(width, radius, E, nu, thickness, n_s, n_t, load, traction):
    """One solve of the quarter: ``load`` ``"uniform"`` (traction on x = W) or
    ``"kirsch"`` (Kirsch's traction on x = W and y = W). Returns (model, u, field,
    setup_s, solve_s)."""
    t0 = time.perf_counter()
    W, a = float(width), float(radius)
    model = MeshElasticity(hole_mesh(W, a, n_s, n_t),
                           Material(E, nu, "plane_stress", thickness), domain(W, a))
    if np.any(model.basis.dx <= 0):
        raise RuntimeError("plate-hole: an element map is not orientation preserving")
    tol = 1e-9 * W
    if load == "uniform":
        f = model.traction_load(lambda x, y: x > W - tol, [traction, 0.0])
    elif load == "kirsch":
        def kirsch_traction(x, y, nx, ny):
            sxx, syy, sxy = kirsch_stress(x, y, a, traction)
            return sxx * nx + sxy * ny, sxy * nx + syy * ny
        f = model.traction_load(lambda x, y: (x > W - tol) | (y > W - tol), kirsch_traction)
    else:
        raise ValueError(f"load must be 'uniform' or 'kirsch', got {load!r}")
    fixed = np.concatenate([model.dofs(lambda x, y: np.abs(x) < tol, components=[0]),
                            model.dofs(lambda x, y: np.abs(y) < tol, components=[1])])
    _ = model.stiffness
    t1 = time.perf_counter()
    u = model.solve(f, fixed)
    fld = model.field(u)
    return model, u, fld, t1 - t0, time.perf_counter() - t1


def sample_points(width: float, radius: float, spacing: float) -> np.ndarray:
    """Cell centres of the ``spacing`` grid on [0, W]^2 with r >= a (the PD default grid
    inside the domain)."""
    n = int(round(width / spacing))
    c = (np.arange(n) + 0.5) * (width / n)
    X, Y = np.meshgrid(c, c, indexing="ij")
    pts = np.stack([X.ravel(), Y.ravel()], axis=1)
    return pts[np.hypot(pts[:, 0], pts[:, 1]) >= radius]


def _scf(fld, radius: float, traction: float) -> float:
    return float(fld.stress(np.array([[0.0, radius]]))[0, 0, 0] / traction)


# --- the reference --------------------------------------------------------------------------

@dataclass(frozen=True, eq=False, kw_only=True)
class HolePlateResult(MeshReferenceResult):
    """Converged plate with a hole (see :class:`ReferenceResult` for the common fields).

    Attributes
    ----------
    ux_load_point : u_x at (W, 0) (m); equals ``quantity``.
    scf : sigma_xx(0, a) / traction at the converged level.
    field_change_pct : change of the field on the sample points over the last refinement.
    """

    ux_load_point: float
    scf: float
    field_change_pct: float

    def metrics(self) -> dict:
        return {"ux_load_point": float(self.ux_load_point), "scf": float(self.scf),
                "field_change_pct": float(self.field_change_pct),
                "refinement_change_pct": float(self.refinement_change_pct)}


def compute(p: HolePlateParams) -> HolePlateResult:
    """Run the refinement study (no cache)."""
    t_start = time.perf_counter()
    pts = sample_points(p.width, p.radius, p.sample_spacing)
    load_point = np.array([[p.width, 0.0]])
    rows, prev_q, prev_sample = [], None, None
    for level in range(p.levels):
        f = 2 ** level
        model, u, fld, ts, tv = solve_quarter(p.width, p.radius, p.E, p.nu, p.thickness,
                                              p.radial_cells * f, p.arc_cells * f,
                                              "uniform", p.traction)
        t1 = time.perf_counter()
        q = float(fld.evaluate(load_point)[0, 0])
        sample = fld.evaluate(pts)
        extra = {"scf": _scf(fld, p.radius, p.traction)}
        if prev_sample is not None:
            extra["field_change_pct"] = field_change_pct(sample, prev_sample)
        tv += time.perf_counter() - t1
        rows.append(RefinementRow(level=level, dofs=int(model.basis.N), h_min=model.min_edge(),
                                  quantity=q, change_pct=change_pct(q, prev_q), setup_s=ts,
                                  solve_s=tv, extra=extra))
        prev_q, prev_sample = q, sample
    return HolePlateResult(
        reference=REFERENCE, params=_p.as_dict(p), quantity_name="u_x at (W, 0) (m)",
        quantity=q, refinement=tuple(rows), refinement_change_pct=rows[-1].change_pct,
        setup_s=ts, solve_s=tv, study_s=time.perf_counter() - t_start, field=fld,
        ux_load_point=q, scf=rows[-1].extra["scf"],
        field_change_pct=rows[-1].extra["field_change_pct"])


def hole_plate(*, use_cache: bool = True, **params) -> HolePlateResult:
    """Converged, cached FEM reference of the quarter plate with a hole (issue 35).

    Keyword arguments override :class:`HolePlateParams`; ``use_cache=False`` recomputes
    without reading or writing the cache.
    """
    p = _p.build(HolePlateParams, REFERENCE, params)
    return cached(REFERENCE, _p.as_dict(p), lambda: compute(p),
                  {"HolePlateResult": HolePlateResult}, use_cache=use_cache)


# --- the Kirsch checks ----------------------------------------------------------------------

@dataclass(frozen=True)
class KirschCheck:
    """Convergence of the quarter under Kirsch's traction to Kirsch's solution.

    Attributes
    ----------
    n_arc : elements along the arc per block, per level.
    error_pct : 100 max |u_h - u_K| / max |u_K| over the sample points and the Q2 nodes.
    scf : sigma_xx(0, a) / sigma of each level (Kirsch: 3).
    rate : least-squares slope of log(error) against log(1 / n_arc) (Q2: 3).
    """

    n_arc: tuple
    error_pct: tuple
    scf: tuple
    rate: float


def kirsch_check(levels: int = 4, **params) -> KirschCheck:
    """(a) Exactness and rate: the quarter of :class:`HolePlateParams` (``params``
    override it; its ``levels`` is replaced by ``levels``) with Kirsch's infinite-plate
    traction on x = W and y = W instead of the uniform one. The symmetry conditions are
    the same; Kirsch's displacement satisfies them with no rigid motion, so the FEM
    displacement converges to it. Q2 elements with a quadratic boundary converge like
    h^3 in the displacement (L2 and pointwise for a smooth solution), the expected rate."""
    p = _p.build(HolePlateParams, REFERENCE, {**params, "levels": levels})
    pts = sample_points(p.width, p.radius, p.sample_spacing)
    n_arc, err, scf = [], [], []
    for level in range(p.levels):
        f = 2 ** level
        _, _, fld, _, _ = solve_quarter(p.width, p.radius, p.E, p.nu, p.thickness,
                                        p.radial_cells * f, p.arc_cells * f, "kirsch",
                                        p.traction)
        x = np.concatenate([pts, fld.node_coords])
        uh = fld.evaluate(x)
        ux, uy = kirsch_displacement(x[:, 0], x[:, 1], p.radius, p.traction, p.E, p.nu)
        uk = np.stack([ux, uy], axis=1)
        err.append(float(100 * np.max(np.abs(uh - uk)) / np.max(np.abs(uk))))
        scf.append(_scf(fld, p.radius, p.traction))
        n_arc.append(p.arc_cells * f)
    rate = -float(np.polyfit(np.log(n_arc), np.log(err), 1)[0])
    return KirschCheck(n_arc=tuple(n_arc), error_pct=tuple(err), scf=tuple(scf), rate=rate)


@dataclass(frozen=True)
class LargePlateCheck:
    """The uniform-tension plate with W/a large against Kirsch's infinite plate.

    Attributes
    ----------
    width_ratio : W / a.
    scf : sigma_xx(0, a) / sigma of the FEM (finest level).
    scf_change_pct : change of ``scf`` over the last refinement (discretisation error).
    displacement_error_pct : 100 max |u_h - u_K| / max |u_K| on the arc r = a and the
        ring r = 2 a (the displacement near the hole).
    """

    width_ratio: float
    scf: float
    scf_change_pct: float
    displacement_error_pct: float


def large_plate_check(width_ratio: float = 20.0, levels: int = 3, **params) -> LargePlateCheck:
    """(b) The plate of :class:`HolePlateParams` with W = ``width_ratio`` a under the
    uniform traction; its stress concentration and near-hole displacement are compared
    with Kirsch's (3 and :func:`kirsch_displacement`). The finite width raises the
    stress concentration by about 3 (a/W)^2 (Heywood's formula for a strip,
    K_tg = (2 + (1 - d/D)^3) / (1 - d/D), d/D = a/W: 3.0075 at W/a = 20)."""
    base = _p.build(HolePlateParams, REFERENCE, params)
    W = width_ratio * base.radius
    p = _p.build(HolePlateParams, REFERENCE, {**params, "width": W, "levels": levels,
                                                "sample_spacing": W})
    scf, fld = [], None
    for level in range(p.levels):
        f = 2 ** level
        _, _, fld, _, _ = solve_quarter(p.width, p.radius, p.E, p.nu, p.thickness,
                                        p.radial_cells * f, p.arc_cells * f, "uniform",
                                        p.traction)
        scf.append(_scf(fld, p.radius, p.traction))
    th = np.linspace(0.0, 0.5 * np.pi, 91)
    x = np.concatenate([np.stack([r * np.cos(th), r * np.sin(th)], axis=1)
                        for r in (p.radius, 2 * p.radius)])
    uh = fld.evaluate(x)
    ux, uy = kirsch_displacement(x[:, 0], x[:, 1], p.radius, p.traction, p.E, p.nu)
    uk = np.stack([ux, uy], axis=1)
    return LargePlateCheck(width_ratio=float(width_ratio), scf=scf[-1],
                           scf_change_pct=change_pct(scf[-1], scf[-2]),
                           displacement_error_pct=float(100 * np.max(np.abs(uh - uk))
                                                        / np.max(np.abs(uk))))
