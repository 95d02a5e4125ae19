"""plate2d-clamped: seed 000 Sec. 6.2, plate clamped on all edges under a uniform body load in x.

Seed 000 (Scabbia et al. 2021), Sec. 6.2, Table 4: l_x = 3 m, l_y = 2 m, thickness
h = 0.05 m, E = 1 GPa, nu = 0.2, all four edges clamped (ERRATA: Neumann conditions in 2D
were not developed in that paper), uniform body force b in x. Plane stress (ERRATA).

Choices where the paper is silent:

- body force b = 1e6 N/m^3 (ERRATA: magnitude not given; the errors of Eq. 70 are
  normalised by max |u_FEM|, so it only scales the field);
- domain [0, l_x] x [0, l_y] (origin at a corner, x along l_x);
- clamped means u = v = 0 on the whole boundary, corners included;
- the compared quantity is max |u| over the Q2 nodes (at the plate centre by symmetry);
  the refinement table also records the Eq. (70)-type change of the whole field between
  successive levels on the 0.1 m PD grid of Table 4 (``field_change_pct``).

Elements: 9-node biquadratic quadrilaterals on uniform meshes with ``spacing / 2^l``,
l = 0 .. levels - 1. The paper's FEM used 0.05 m; the default finest level is 0.025 m.
"""
from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np

from . import params as _p
from .cache import cached
from .elasticity import Material, TensorElasticity
from .meshing import uniform
from .results import ReferenceResult, RefinementRow, change_pct

REFERENCE = "plate2d-clamped"


@dataclass(frozen=True)
class PlateParams:
    """Parameters (defaults: seed 000 Table 4 and ERRATA)."""

    length: float = 3.0          # l_x (m), Table 4
    width: float = 2.0           # l_y (m), Table 4
    thickness: float = 0.05      # h (m), Table 4
    E: float = 1e9               # Pa, Table 4
    nu: float = 0.2              # Table 4
    body_force: float = 1e6      # N/m^3 along x; ERRATA: not given, errors are normalised
    spacing: float = 0.2         # element edge of level 0 (m); must divide length and width
    levels: int = 4              # refinement levels (finest edge = spacing / 2^(levels-1))
    sample_spacing: float = 0.1  # grid of the field-change measure (Table 4 PD spacing)

    def __post_init__(self):
        _p.positive(REFERENCE, length=self.length, width=self.width, thickness=self.thickness,
                    E=self.E, spacing=self.spacing, sample_spacing=self.sample_spacing)
        _p.require(-1 < self.nu < 0.5, REFERENCE, f"nu must lie in (-1, 0.5), got {self.nu}")
        _p.require(self.body_force != 0, REFERENCE, "body_force must be nonzero")
        _p.require(2 <= self.levels <= 7, REFERENCE, f"levels must be 2..7, got {self.levels}")
        for name, L in (("length", self.length), ("width", self.width)):
            n = L / self.spacing
            _p.require(abs(n - round(n)) < 1e-9 * n and round(n) >= 1, REFERENCE,
                       f"spacing {self.spacing} must divide {name} {L}")

    def finest_cells(self) -> tuple[int, int]:
        """Elements along x and y of the finest level (for a resource estimate)."""
        h = self.spacing / 2 ** (self.levels - 1)
        return round(self.length / h), round(self.width / h)


@dataclass(frozen=True, eq=False, kw_only=True)
class PlateResult(ReferenceResult):
    """Converged clamped plate (see :class:`ReferenceResult` for the common fields).

    Attributes
    ----------
    max_displacement : max |u| over the Q2 nodes (m); equals ``quantity``.
    max_abs_u, max_abs_v : max |u_x| and max |u_y| over the Q2 nodes (m).
    """

    max_displacement: float
    max_abs_u: float
    max_abs_v: float

    def metrics(self) -> dict:
        """Scene metrics of issue 5."""
        return {"max_displacement": self.max_displacement,
                "refinement_change_pct": float(self.refinement_change_pct)}


def _sample_points(p: PlateParams) -> np.ndarray:
    nx = int(round(p.length / p.sample_spacing))
    ny = int(round(p.width / p.sample_spacing))
    X, Y = np.meshgrid(np.linspace(0, p.length, nx + 1), np.linspace(0, p.width, ny + 1),
                       indexing="ij")
    return np.stack([X.ravel(), Y.ravel()], axis=1)


def solve_level(p: PlateParams, level: int):
    """One level: returns (model, u, field, setup_s, solve_s)."""
    t0 = time.perf_counter()
    h = p.spacing / 2 ** level
    xs = uniform(0.0, p.length, round(p.length / h))
    ys = uniform(0.0, p.width, round(p.width / h))
    model = TensorElasticity((xs, ys), Material(p.E, p.nu, "plane_stress", p.thickness))
    f = model.body_load([p.body_force, 0.0])
    _ = model.stiffness
    L, W = p.length, p.width
    tol = 1e-9 * max(L, W)
    clamped = model.dofs(lambda x, y: (x < tol) | (x > L - tol) | (y < tol) | (y > W - tol))
    t1 = time.perf_counter()
    u = model.solve(f, clamped)
    fld = model.field(u)
    return model, u, fld, t1 - t0, time.perf_counter() - t1


def compute(p: PlateParams) -> PlateResult:
    """Run the refinement study (no cache)."""
    t_start = time.perf_counter()
    pts = _sample_points(p)
    rows, prev_q, prev_sample = [], None, None
    for level in range(p.levels):
        model, u, fld, ts, tv = solve_level(p, level)
        q = fld.max_displacement()
        sample = fld.evaluate(pts)
        extra = {}
        if prev_sample is not None:
            peak = np.max(np.abs(sample))          # scale-free: normalise before squaring
            scale = peak * np.max(np.linalg.norm(sample / peak, axis=1))
            extra["field_change_pct"] = float(100 * np.max(np.abs(sample - prev_sample)) / scale)
        rows.append(RefinementRow(level=level, dofs=int(model.basis.N),
                                  h_min=p.spacing / 2 ** level, quantity=q,
                                  change_pct=change_pct(q, prev_q), setup_s=ts, solve_s=tv,
                                  extra=extra))
        prev_q, prev_sample = q, sample
    nodal = fld.nodal_displacement()
    return PlateResult(
        reference=REFERENCE, params=_p.as_dict(p), quantity_name="max_displacement (m)",
        quantity=q, refinement=tuple(rows), refinement_change_pct=rows[-1].change_pct,
        setup_s=ts, solve_s=tv, study_s=time.perf_counter() - t_start, field=fld,
        max_displacement=q, max_abs_u=float(np.max(np.abs(nodal[:, 0]))),
        max_abs_v=float(np.max(np.abs(nodal[:, 1]))))


def clamped_plate(*, use_cache: bool = True, **params) -> PlateResult:
    """Converged, cached FEM reference of the clamped plate (seed 000 Sec. 6.2).

    Keyword arguments override :class:`PlateParams`; ``use_cache=False`` recomputes
    without reading or writing the cache.
    """
    p = _p.build(PlateParams, REFERENCE, params)
    return cached(REFERENCE, _p.as_dict(p), lambda: compute(p), {"PlateResult": PlateResult},
                  use_cache=use_cache)
