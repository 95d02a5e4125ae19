"""plate-l: L-shaped plate (a bracket) with a re-entrant corner, clamped and end-loaded.

The problem (issue 35): plane stress on

    [0, L] x [0, L] minus (L/2, L] x (L/2, L],     default L = 1 m,

with the re-entrant corner at (L/2, L/2); E = 1 GPa, nu = 0.3, thickness 1 m.
Conditions: clamped (u = v = 0) on x = 0 (0 <= y <= L); traction (0, -sigma) on the arm's
end x = L (0 <= y <= L/2), sigma = 1 MPa (the bracket loaded in shear); every other edge
is free (y = 0; y = L for x <= L/2; the re-entrant edges x = L/2, y >= L/2 and
y = L/2, x >= L/2).

Singularities: at the re-entrant corner (interior angle 3 pi / 2, both faces free) the
displacement goes like r^0.5445 (Williams 1952: for free faces meeting at the angle
2 alpha the exponents solve sin(2 alpha lambda) = -+ lambda sin(2 alpha); at
2 alpha = 3 pi / 2, lambda = 0.5445 (symmetric mode) and 0.9085); the corners where the
clamp meets a free edge, (0, 0) and (0, L), and the ends of the loaded edge, (L, 0) and
(L, L/2) (a shear traction meeting a free edge), are singular too (with exponents that
depend on nu); the grading below refines toward all of them.

Elements and mesh: 9-node biquadratic quadrilaterals (vector ``ElementQuad2``; the
elements are rectangles, so the map is affine). The domain is three squares of side
L/2, [0, L/2]^2, [L/2, L] x [0, L/2] and [0, L/2] x [L/2, L]; each is a tensor grid of
``cells * 2^l`` x ``cells * 2^l`` elements (level l) whose 1D nodes are power graded
toward both ends of the side (``meshing.power_graded(..., ends="both")`` with
``grading_power``), so every corner of every square, the re-entrant corner, the clamped
corners and the ends of the loaded edge among them, is refined like n^-power. Power
grading with power > k / lambda = 2 / 0.5445 = 3.7 recovers the optimal rate of degree-2
elements for the r^0.5445 singularity (Babuska & Guo; Schwab, p- and hp-FEM 1998, ch. 4;
see ``meshing.power_graded``); the default power is 4.

Refinement study: compared quantity u_y at (L, 0) (the loaded arm's lower end). Each
row's ``extra`` has ``field_change_pct`` (from level 1): the change of the whole field
between successive levels on the centres of the cells of a ``sample_spacing`` grid on
[0, L]^2 that lie in the domain (the PD default grid, 0.025 m), normalised as in
``plate.py``; and ``quantity_rate`` (from level 2): log2 of the ratio of the last two
changes of the compared quantity. The result's ``fitted_rate`` is the least-squares
slope of log |q_l - q_(l-1)| against l / log 2 over the levels (rate in powers of the
refinement factor 2), and ``extrapolated`` the Richardson value q + d / (2^rate - 1).

Measured with the defaults (4 elements per square side at level 0, five levels, finest
64 per side, 12 288 elements, 99 330 DOFs, smallest element edge 2.4e-7 m; the study
about 8 s on one core): u_y(L, 0) = -9.50326e-3 m, changing 1.72, 0.25, 0.024, 0.0020 %
per level (rates 2.78, 3.36, 3.60; fitted 3.26), the field on the sample points 1.46,
0.195, 0.018, 0.0023 %.

Evaluation: :class:`~reference_fem.mesh_field.MeshField` (exact domain test; a point on
an edge takes one of its elements); points outside the L raise ``ValueError``.
"""
from __future__ import annotations

import math
import time
from dataclasses import dataclass

import numpy as np

from . import params as _p
from .cache import cached
from .elasticity import Material
from .mesh_elasticity import MeshElasticity, mapped_mesh
from .meshing import power_graded
from .results import MeshReferenceResult, RefinementRow, change_pct, field_change_pct

REFERENCE = "plate-l"


@dataclass(frozen=True)
class LPlateParams:
    """Parameters of the L-shaped bracket (defaults: issue 35)."""

    length: float = 1.0            # L: the plate is [0, L]^2 minus (L/2, L]^2 (m)
    thickness: float = 1.0         # m
    E: float = 1e9                 # Pa
    nu: float = 0.3
    traction: float = 1e6          # sigma: traction (0, -sigma) on x = L, y <= L/2 (Pa)
    cells: int = 4                 # level 0: elements along each side of each square
    grading_power: float = 4.0     # power grading toward each square's corners (1: uniform)
    levels: int = 5                # refinement levels (cells x 2^l)
    sample_spacing: float = 0.025  # grid of the field-change measure (PD default grid)

    def __post_init__(self):
        _p.positive(REFERENCE, length=self.length, thickness=self.thickness, E=self.E,
                    sample_spacing=self.sample_spacing)
        _p.require(-1 < self.nu < 0.5, REFERENCE, f"nu must lie in (-1, 0.5), got {self.nu}")
        _p.require(math.isfinite(self.traction) and self.traction != 0, REFERENCE,
                   f"traction must be finite and nonzero, got {self.traction}")
        _p.require(2 <= self.cells <= 64 and self.cells % 2 == 0, REFERENCE,
                   f"cells must be even, 2..64 (graded toward both ends), got {self.cells}")
        _p.require(math.isfinite(self.grading_power) and 1.0 <= self.grading_power <= 8.0,
                   REFERENCE, f"grading_power must be in [1, 8], got {self.grading_power}")
        _p.require(2 <= self.levels <= 7, REFERENCE, f"levels must be 2..7, got {self.levels}")
        n = self.length / self.sample_spacing
        _p.require(abs(n - round(n)) < 1e-9 * n and round(n) >= 2 and round(n) % 2 == 0,
                   REFERENCE, f"sample_spacing {self.sample_spacing} must divide length/2 "
                   f"({self.length / 2})")
        n_fine = self.finest_cells()[0]
        _p.require(3 * n_fine ** 2 <= 2 ** 18, REFERENCE,
                   f"the finest level would have {3 * n_fine ** 2} elements (at most 2^18)")

    def finest_cells(self) -> tuple[int, int]:
        """(n, 3 n), n elements per square side at the finest level: the L's
        12 n^2 + 8 n + 1 Q2 nodes are those of an n x 3n tensor grid (for a resource
        estimate)."""
        n = self.cells * 2 ** (self.levels - 1)
        return n, 3 * n


def l_mesh(length: float, n: int, power: float):
    """The three graded squares (see the module docstring)."""
    h = 0.5 * float(length)
    g = power_graded(0.0, 1.0, n, power, "both") if power != 1.0 else np.linspace(0, 1, n + 1)

    def square(x0, y0):
        return (g, g, lambda s, t: (x0 + h * s, y0 + h * t))

    return mapped_mesh([square(0.0, 0.0), square(h, 0.0), square(0.0, h)], tol=1e-9 * length)


def domain(length: float) -> dict:
    h = 0.5 * length
    # the removed quadrant extends past the box so that its edges x = L, y = L go too
    return {"box": [[0.0, length], [0.0, length]], "rects": [[h, h, 2 * length, 2 * length]]}


def solve_level(p: "LPlateParams", level: int):
    """One level: returns (model, u, field, setup_s, solve_s)."""
    t0 = time.perf_counter()
    L = p.length
    n = p.cells * 2 ** level
    model = MeshElasticity(l_mesh(L, n, p.grading_power),
                           Material(p.E, p.nu, "plane_stress", p.thickness), domain(L))
    tol = 1e-9 * L
    f = model.traction_load(lambda x, y: (x > L - tol) & (y < 0.5 * L + tol),
                            [0.0, -p.traction])
    clamped = model.dofs(lambda x, y: np.abs(x) < tol)
    _ = model.stiffness
    t1 = time.perf_counter()
    u = model.solve(f, clamped)
    fld = model.field(u)
    return model, u, fld, t1 - t0, time.perf_counter() - t1


def sample_points(length: float, spacing: float) -> np.ndarray:
    """Cell centres of the ``spacing`` grid on [0, L]^2 outside (L/2, L]^2."""
    n = int(round(length / spacing))
    c = (np.arange(n) + 0.5) * (length / n)
    X, Y = np.meshgrid(c, c, indexing="ij")
    pts = np.stack([X.ravel(), Y.ravel()], axis=1)
    return pts[~((pts[:, 0] > 0.5 * length) & (pts[:, 1] > 0.5 * length))]


def fitted_rate(quantities) -> float:
    """Least-squares slope of -log2 |q_l - q_(l-1)| against l (the order of convergence
    in the element size, which halves per level); NaN with fewer than 3 levels."""
    q = np.asarray(quantities, dtype=float)
    d = np.abs(np.diff(q))
    if d.size < 2 or np.any(d == 0):
        return float("nan")
    return -float(np.polyfit(np.arange(d.size), np.log2(d), 1)[0])


@dataclass(frozen=True, eq=False, kw_only=True)
class LPlateResult(MeshReferenceResult):
    """Converged L-shaped bracket (see :class:`ReferenceResult` for the common fields).

    Attributes
    ----------
    uy_load_corner : u_y at (L, 0) (m); equals ``quantity``.
    field_change_pct : change of the field on the sample points over the last refinement.
    fitted_rate : fitted order of convergence of the compared quantity (see module).
    extrapolated : Richardson extrapolation of the compared quantity with that rate.
    """

    uy_load_corner: float
    field_change_pct: float
    fitted_rate: float
    extrapolated: float

    def metrics(self) -> dict:
        return {"uy_load_corner": float(self.uy_load_corner),
                "field_change_pct": float(self.field_change_pct),
                "fitted_rate": float(self.fitted_rate),
                "refinement_change_pct": float(self.refinement_change_pct)}


def compute(p: LPlateParams) -> LPlateResult:
    """Run the refinement study (no cache)."""
    t_start = time.perf_counter()
    pts = sample_points(p.length, p.sample_spacing)
    corner = np.array([[p.length, 0.0]])
    rows, qs, prev_sample = [], [], None
    for level in range(p.levels):
        model, u, fld, ts, tv = solve_level(p, level)
        t1 = time.perf_counter()
        q = float(fld.evaluate(corner)[0, 1])
        sample = fld.evaluate(pts)
        extra = {}
        if prev_sample is not None:
            extra["field_change_pct"] = field_change_pct(sample, prev_sample)
        if len(qs) >= 2:
            d1, d2 = abs(qs[-1] - qs[-2]), abs(q - qs[-1])
            extra["quantity_rate"] = float(np.log2(d1 / d2)) if d1 > 0 and d2 > 0 else float("nan")
        tv += time.perf_counter() - t1
        rows.append(RefinementRow(level=level, dofs=int(model.basis.N), h_min=model.min_edge(),
                                  quantity=q, change_pct=change_pct(q, qs[-1] if qs else None),
                                  setup_s=ts, solve_s=tv, extra=extra))
        qs.append(q)
        prev_sample = sample
    rate = fitted_rate(qs)
    extrapolated = (q + (q - qs[-2]) / (2.0 ** rate - 1.0)
                    if np.isfinite(rate) and rate > 0 else float("nan"))
    return LPlateResult(
        reference=REFERENCE, params=_p.as_dict(p), quantity_name="u_y at (L, 0) (m)",
        quantity=q, refinement=tuple(rows), refinement_change_pct=rows[-1].change_pct,
        setup_s=ts, solve_s=tv, study_s=time.perf_counter() - t_start, field=fld,
        uy_load_corner=q, field_change_pct=rows[-1].extra["field_change_pct"],
        fitted_rate=rate, extrapolated=float(extrapolated))


def l_plate(*, use_cache: bool = True, **params) -> LPlateResult:
    """Converged, cached FEM reference of the L-shaped bracket (issue 35).

    Keyword arguments override :class:`LPlateParams`; ``use_cache=False`` recomputes
    without reading or writing the cache.
    """
    p = _p.build(LPlateParams, REFERENCE, params)
    return cached(REFERENCE, _p.as_dict(p), lambda: compute(p), {"LPlateResult": LPlateResult},
                  use_cache=use_cache)
