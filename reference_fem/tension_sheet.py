"""sheet2d-tension: seed 003 Sec. 4.1.1, free sheet under uniform end traction (closed form).

Seed 003 (Ritter et al.), Sec. 4.1.1: sheet 50 mm x 100 mm, E = 1 GPa, uniform traction
sigma = 1 MPa in y on the ends y = +-50 mm, sides free. The paper compares with "the
analytical solution"; the FEM here checks that the discrete reference reproduces it.

Closed form (uniaxial stress sigma_yy = sigma, all other stresses zero), origin at the
sheet centre:

- plane stress:  u_x = -nu sigma x / E,               u_y = sigma y / E;
- plane strain:  u_x = -nu (1 + nu) sigma x / E,      u_y = (1 - nu^2) sigma y / E.

Choices where the paper is silent:

- plane stress, nu = 1/3, unit thickness (ERRATA, seed 003 "Unstated and chosen");
- domain [-25, 25] x [-50, 50] mm (the paper's y = +-50 mm ends, centred in x);
- supports: the traction problem is pure Neumann, so rigid motions are removed by the
  minimal constraints u_x = u_y = 0 at the centre (0, 0) and u_x = 0 at the top-centre
  point (0, +50 mm). The closed form satisfies both, so they add no reaction (the
  computed reactions are round-off) and the closed form is the exact solution of the
  constrained problem. Element counts are even so both points are nodes.

Biquadratic elements contain the linear closed form, so the FEM is exact up to round-off
on every mesh; the refinement study shows the change is round-off as well.
"""
from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np

from . import params as _p
from .cache import cached
from .elasticity import MODES, Material, TensorElasticity
from .meshing import uniform
from .results import ReferenceResult, RefinementRow, change_pct

REFERENCE = "sheet2d-tension"


@dataclass(frozen=True)
class TensionSheetParams:
    """Parameters (defaults: seed 003 Sec. 4.1.1 and ERRATA)."""

    width: float = 0.050         # x extent (m), Sec. 4.1.1
    length: float = 0.100        # y extent (m), Sec. 4.1.1
    traction: float = 1e6        # Pa on y = +-length/2, Sec. 4.1.1
    E: float = 1e9               # Pa, Sec. 4.1.1
    nu: float = 1.0 / 3.0        # ERRATA: chosen (bond-based PD plane stress)
    thickness: float = 1.0       # m, ERRATA: unit thickness
    mode: str = "plane_stress"   # ERRATA: plane stress
    spacing: float = 0.005       # element edge of level 0 (m); the horizon of Sec. 4.1.1
    levels: int = 2

    def __post_init__(self):
        _p.positive(REFERENCE, width=self.width, length=self.length, E=self.E,
                    thickness=self.thickness, spacing=self.spacing)
        _p.require(self.mode in MODES[:2], REFERENCE,
                   f"mode must be plane_stress or plane_strain, got {self.mode!r}")
        _p.require(-1 < self.nu < 0.5, REFERENCE, f"nu must lie in (-1, 0.5), got {self.nu}")
        _p.require(self.traction != 0, REFERENCE, "traction must be nonzero")
        _p.require(2 <= self.levels <= 6, REFERENCE, f"levels must be 2..6, got {self.levels}")
        for name, L in (("width", self.width), ("length", self.length)):
            n = L / self.spacing
            _p.require(abs(n - round(n)) < 1e-9 * n and round(n) % 2 == 0, REFERENCE,
                       f"{name} {L} must be an even multiple of spacing {self.spacing}")

    def finest_cells(self) -> tuple[int, int]:
        """Elements along x and y of the finest level (for a resource estimate)."""
        h = self.spacing / 2 ** (self.levels - 1)
        return round(self.width / h), round(self.length / h)


@dataclass(frozen=True, eq=False, kw_only=True)
class TensionSheetResult(ReferenceResult):
    """Converged tension sheet (see :class:`ReferenceResult`).

    Attributes
    ----------
    max_error_ux_pct, max_error_uy_pct : 100 max |u_FEM - u_exact| / max |u_exact| per
        component over the Q2 nodes and 1000 seeded interior points.
    max_error_pct : the larger of the two.
    max_reaction_n : largest |reaction| at the three supported DOFs (N; round-off).
    """

    max_error_ux_pct: float
    max_error_uy_pct: float
    max_error_pct: float
    max_reaction_n: float

    def closed_form(self, points: np.ndarray) -> np.ndarray:
        """Exact displacement at points (m), shape (n, 2)."""
        return closed_form(points, **{k: self.params[k]
                                      for k in ("traction", "E", "nu", "mode")})

    def metrics(self) -> dict:
        """Scene metrics of issue 5."""
        return {"max_error_pct": self.max_error_pct, "max_error_ux_pct": self.max_error_ux_pct,
                "max_error_uy_pct": self.max_error_uy_pct,
                "refinement_change_pct": float(self.refinement_change_pct)}


def closed_form(points: np.ndarray, *, traction: float, E: float, nu: float,
                mode: str = "plane_stress") -> np.ndarray:
    """Uniaxial-stress displacement, origin at the sheet centre (module docstring)."""
    pts = np.asarray(points, dtype=float)
    if mode == "plane_stress":
        exx, eyy = -nu * traction / E, traction / E
    elif mode == "plane_strain":
        exx, eyy = -nu * (1 + nu) * traction / E, (1 - nu ** 2) * traction / E
    else:
        raise ValueError(f"mode must be plane_stress or plane_strain, got {mode!r}")
    return np.stack([exx * pts[:, 0], eyy * pts[:, 1]], axis=1)


def _errors(fld, p: TensionSheetParams):
    rng = np.random.default_rng(4101)  # fixed seed: interior sample points
    a, b = p.width / 2, p.length / 2
    pts = np.concatenate([fld.nodes(), rng.uniform([-a, -b], [a, b], size=(1000, 2))])
    exact = closed_form(pts, traction=p.traction, E=p.E, nu=p.nu, mode=p.mode)
    err = np.abs(fld.evaluate(pts) - exact)
    scale = np.max(np.abs(exact), axis=0)
    return 100 * err[:, 0].max() / scale[0], 100 * err[:, 1].max() / scale[1]


def compute(p: TensionSheetParams) -> TensionSheetResult:
    """Run the refinement study (no cache)."""
    t_start = time.perf_counter()
    a, b = p.width / 2, p.length / 2
    rows, prev_q = [], None
    for level in range(p.levels):
        t0 = time.perf_counter()
        h = p.spacing / 2 ** level
        model = TensorElasticity((uniform(-a, a, round(p.width / h)),
                                  uniform(-b, b, round(p.length / h))),
                                 Material(p.E, p.nu, p.mode, p.thickness))
        tol = 1e-9 * p.length
        f = (model.traction_load(lambda x, y: y > b - tol, [0.0, p.traction])
             + model.traction_load(lambda x, y: y < -b + tol, [0.0, -p.traction]))
        _ = model.stiffness
        at_centre = lambda x, y: (np.abs(x) < tol) & (np.abs(y) < tol)  # noqa: E731
        at_top_centre = lambda x, y: (np.abs(x) < tol) & (y > b - tol)  # noqa: E731
        fixed = np.concatenate([model.dofs(at_centre), model.dofs(at_top_centre, [0])])
        if fixed.size != 3:
            raise RuntimeError(f"expected 3 supported DOFs, found {fixed.size}")
        t1 = time.perf_counter()
        u = model.solve(f, fixed)
        fld = model.field(u)
        ex, ey = _errors(fld, p)
        reaction = float(np.max(np.abs(model.reactions(u, f)[fixed])))
        q = fld.max_displacement()
        tv = time.perf_counter() - t1
        rows.append(RefinementRow(level=level, dofs=int(model.basis.N), h_min=h, quantity=q,
                                  change_pct=change_pct(q, prev_q), setup_s=t1 - t0,
                                  solve_s=tv, extra={"max_error_ux_pct": float(ex),
                                                     "max_error_uy_pct": float(ey),
                                                     "max_reaction_n": reaction}))
        prev_q = q
    return TensionSheetResult(
        reference=REFERENCE, params=_p.as_dict(p), quantity_name="max_displacement (m)",
        quantity=q, refinement=tuple(rows), refinement_change_pct=rows[-1].change_pct,
        setup_s=t1 - t0, solve_s=tv, study_s=time.perf_counter() - t_start, field=fld,
        max_error_ux_pct=float(ex), max_error_uy_pct=float(ey), max_error_pct=float(max(ex, ey)),
        max_reaction_n=reaction)


def tension_sheet(*, use_cache: bool = True, **params) -> TensionSheetResult:
    """Converged, cached FEM reference of the tension sheet (seed 003 Sec. 4.1.1).

    Keyword arguments override :class:`TensionSheetParams`.
    """
    p = _p.build(TensionSheetParams, REFERENCE, params)
    return cached(REFERENCE, _p.as_dict(p), lambda: compute(p),
                  {"TensionSheetResult": TensionSheetResult}, use_cache=use_cache)
