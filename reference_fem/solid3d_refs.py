"""cylinder3d-tension and block3d-cavity: the FEM references of issue 55's 3D bodies that
are not boxes (quadratic tetrahedra on mapped meshes, :mod:`reference_fem.solid3d`).

**cylinder3d-tension** (:func:`cylinder_tension`): the quarter x, y >= 0 of the cylinder
r < R, 0 < z < L under the axial traction sigma on z = L; u_x = 0 on x = 0, u_y = 0 on
y = 0, u_z = 0 on z = 0 (the symmetry planes, and the roller at the base; together they
remove every rigid motion), the mantle free. Defaults R = 0.5 m, L = 1 m, E = 1 GPa,
nu = 0.3, sigma = 1 MPa. Closed form (uniform axial stress, every boundary condition met
exactly): u_z = sigma z / E, u_r = -nu sigma r / E, i.e. u = (-nu sigma x, -nu sigma y,
sigma z) / E. The field is linear, in the span of the elements, and met by any mesh of a
prism with this cross-section (the faceted mantle's normal is still normal to z, so it
stays traction-free under the uniaxial stress): the FEM must reproduce it to round-off,
the check of the mesh, assembly, conditions and load (``closed_form_error_pct``, quoted
by the scene). Mesh: the quarter disk as three blocks (the core square [0, R/2]^2 and two
blocks from its edges to the arc, split at 45 degrees) extruded along z.

**block3d-cavity** (:func:`cavity_block`): the octant [0, W]^3 of a block with a
spherical cavity r < a at its centre under the remote traction sigma along z (on z = W);
u_x = 0 on x = 0, u_y = 0 on y = 0, u_z = 0 on z = 0 (the symmetry planes), the faces
x = W, y = W and the cavity free. Defaults W = 1 m, a = 0.3 m, E = 1 GPa, nu = 0.3,
sigma = 1 MPa. Mesh: three blocks, one per outer face; each logical cube maps to the rays
from the centre through that face (the gnomonic "cubed sphere" of the octant) between the
sphere and the face, graded toward the sphere by g(s) = expm1(beta s) / expm1(beta)
(beta: the first radial element as long as an arc element at the sphere, as
``hole_plate.grading_beta``). The classical check (:func:`large_block_check`, its test):
Goodier (1933; Timoshenko & Goodier, Theory of Elasticity, Art. 136) for the infinite
body: sigma_zz at the equator r = a, z = 0 is sigma (27 - 15 nu) / (2 (7 - 5 nu)) (2.045 at
nu = 0.3); a block with W / a large must approach it (finite size raises it, as
(a / W)^3; the faceted sphere's O(h^2) error is the other part).

Refinement study of both: level l has ``cells + l`` cells per block edge (each cell 24
tetrahedra; the cavity's finest default level, 4 per edge, has 22 k unknowns: 6 per edge
would have 71 k and take ~100 s and 1.9 GB under load, past the scene's budget); ``field_change_pct``: the change of the field on the sample points
(cell centres of the PD default grid inside the body) between successive levels, as
``hole_plate``; block3d-cavity's ``scf`` = sigma_zz(equator) / sigma at each level.

Measured with the defaults (under load, 2 shared cores): the cylinder at 1, 2 cells per
block edge (1 629, 11 319 unknowns) errs 1.1e-12 and 6.7e-13 % of max |u| against the
closed form, its field changes 1.5e-12 % (the study 9-15 s); the cavity at 2, 3, 4 cells
(3 075, 9 633, 21 987 unknowns): field change 1.17 then 0.378 %, u_z(0, 0, W) =
1.10073e-3, 1.10581e-3, 1.10755e-3 m, equator concentration 1.750, 1.926, 2.033 (the
study 12-40 s, 0.6 GB). The large block (W/a = 8) on the same meshes: 1.471, 1.750,
1.895, Richardson (O(h^2)) 1.974 then 2.081, Goodier 2.045. 6 cells per edge (71 427
unknowns) took 98 s to solve and 1.9 GB (concentration 2.101): past a scene's budget.
"""
from __future__ import annotations

import math
import time
from dataclasses import dataclass

import numpy as np
from scipy.optimize import brentq

from . import params as _p
from .cache import cached
from .results import MeshReferenceResult, RefinementRow, change_pct, field_change_pct
from .solid3d import Solid3D, tet_mesh

CYLINDER, CAVITY = "cylinder3d-tension", "block3d-cavity"


def goodier_scf(nu: float) -> float:
    """Goodier's concentration at a spherical cavity's equator under uniaxial tension:
    (27 - 15 nu) / (2 (7 - 5 nu))."""
    return (27 - 15 * nu) / (2 * (7 - 5 * nu))


def _lattice_centres(upper, spacing):
    n = [int(round(u / spacing)) for u in upper]
    idx = np.indices(n).reshape(3, -1).T
    return (idx + 0.5) * spacing


class _SliceMixin:
    """``sample_grid`` of a 3D result: the plane y = 0 (a symmetry plane, inside the body
    by 1e-9 of its size): ``x`` and ``y`` hold x and z, ``ux`` and ``uy`` the
    displacement's x and z components, NaN outside the body."""

    def sample_grid(self, shape: tuple = (81, 81)) -> dict:
        b = self.field.bounds
        xs = np.linspace(b[0][0], b[0][1], shape[0])
        zs = np.linspace(b[2][0], b[2][1], shape[1])
        X, Z = np.meshgrid(xs, zs, indexing="ij")
        pts = np.stack([X.ravel(), np.full(X.size, 1e-9 * (b[2][1] - b[2][0])), Z.ravel()], 1)
        inside = self.inside(pts)
        u = np.full((len(pts), 3), np.nan)
        w = np.full(len(pts), np.nan)
        u[inside] = self.field.evaluate(pts[inside])
        w[inside] = self.field.strain_energy_density(pts[inside])
        return {"x": X, "y": Z, "ux": u[:, 0].reshape(shape), "uy": u[:, 2].reshape(shape),
                "strain_energy_density": w.reshape(shape)}


def _hexes_to_cells(hexes: int) -> tuple:
    """A tensor grid of Q2 elements with as many nodes as ``hexes`` cells of the 24-split
    (about 39 P2 nodes a cell, measured on both meshes): for the budget's estimate."""
    k = max(1, int(round(((39 * hexes) ** (1 / 3) - 1) / 2)))
    return (k, k, k)


# --- cylinder -------------------------------------------------------------------------------

@dataclass(frozen=True)
class CylinderParams:
    """The quarter cylinder under axial tension (defaults: issue 55)."""

    radius: float = 0.5
    length: float = 1.0
    E: float = 1e9
    nu: float = 0.3
    traction: float = 1e6
    cells: int = 1               # level l: cells + l cells per block edge (cross-section)
    levels: int = 2
    sample_spacing: float = 0.0625

    def __post_init__(self):
        _p.positive(CYLINDER, radius=self.radius, length=self.length, E=self.E,
                    sample_spacing=self.sample_spacing)
        _p.require(-1 < self.nu < 0.5, CYLINDER, f"nu must lie in (-1, 0.5), got {self.nu}")
        _p.require(math.isfinite(self.traction) and self.traction != 0, CYLINDER,
                   f"traction must be finite and nonzero, got {self.traction}")
        _p.require(1 <= self.cells <= 8 and 1 <= self.levels <= 4, CYLINDER,
                   f"cells must be 1..8 and levels 1..4, got {self.cells}, {self.levels}")

    def finest_cells(self) -> tuple:
        n = self.cells + self.levels - 1
        return _hexes_to_cells(3 * n * n * max(1, math.ceil(2 * n * self.length / self.radius)))


def cylinder_mesh(R, L, n):
    c = 0.5 * R
    nz = max(1, int(math.ceil(2 * n * L / R)))

    def core(s, t, u):
        return c * s, c * t, L * u

    def outer1(s, t, u):
        ix, iy = c + 0 * t, c * t
        ox, oy = R * np.cos(0.25 * np.pi * t), R * np.sin(0.25 * np.pi * t)
        return ix + s * (ox - ix), iy + s * (oy - iy), L * u

    def outer2(s, t, u):
        x, y, z = outer1(s, t, u)
        return y, x, z
    return tet_mesh([(core, (n, n, nz)), (outer1, (n, n, nz)), (outer2, (n, n, nz))],
                    tol=1e-9 * R)


def cylinder_closed_form(x, E, nu, sigma):
    """u = (-nu sigma x, -nu sigma y, sigma z) / E (module docstring)."""
    x = np.asarray(x, float)
    return np.c_[-nu * x[:, 0], -nu * x[:, 1], x[:, 2]] * (sigma / E)


def solve_cylinder(p: CylinderParams, n: int):
    t0 = time.perf_counter()
    R, L = p.radius, p.length
    model = Solid3D(*cylinder_mesh(R, L, n), p.E, p.nu)
    tol = 1e-9 * R
    f = model.traction_load(lambda x: x[2] > L - tol,
                            lambda x: np.stack([0 * x[0], 0 * x[0], 0 * x[0] + p.traction]))
    fixed = np.concatenate([model.dofs(lambda x: np.abs(x[:, k]) < tol, k) for k in range(3)])
    K = model.stiffness()
    t1 = time.perf_counter()
    u = model.solve(K, f, fixed)
    return model, model.field(u), t1 - t0, time.perf_counter() - t1


@dataclass(frozen=True, eq=False, kw_only=True)
class CylinderResult(_SliceMixin, MeshReferenceResult):
    """Converged quarter cylinder (see :class:`ReferenceResult`).

    Attributes
    ----------
    uz_top : u_z at (0, 0, L) (= ``quantity``; closed form sigma L / E).
    closed_form_error_pct : 100 max |u_h - u_exact| / max |u_exact| over the P2 nodes and
        the sample points at the last level.
    field_change_pct : change of the field on the sample points over the last refinement.
    """

    uz_top: float
    closed_form_error_pct: float
    field_change_pct: float

    def inside(self, x):
        R, L = self.params["radius"], self.params["length"]
        return (np.hypot(x[:, 0], x[:, 1]) <= R) & (x[:, 0] >= 0) & (x[:, 2] >= 0) & (x[:, 2] <= L)

    def metrics(self) -> dict:
        return {"uz_top": float(self.uz_top),
                "closed_form_error_pct": float(self.closed_form_error_pct),
                "field_change_pct": float(self.field_change_pct),
                "refinement_change_pct": float(self.refinement_change_pct)}


def cylinder_samples(p) -> np.ndarray:
    x = _lattice_centres((p.radius, p.radius, p.length), p.sample_spacing)
    return x[np.hypot(x[:, 0], x[:, 1]) < p.radius]


def _refine(p, solve, top, pts, extra_of):
    """The study both references run: per level ``solve(p, cells)``, the quantity u_z at
    ``top``, the field at ``pts`` and ``extra_of(fld)``, with the changes against the level
    before. Returns the rows and the finest level's field, setup and solve seconds."""
    rows, prev_q, prev = [], None, None
    for level in range(p.levels):
        model, fld, ts, tv = solve(p, p.cells + level)
        q = float(fld.evaluate(np.array([top]))[0, 2])
        sample = fld.evaluate(pts)
        extra = extra_of(fld)
        if prev is not None:
            extra["field_change_pct"] = field_change_pct(sample, prev)
        rows.append(RefinementRow(level=level, dofs=model.N, h_min=model.min_edge(), quantity=q,
                                  change_pct=change_pct(q, prev_q), setup_s=ts, solve_s=tv,
                                  extra=extra))
        prev_q, prev = q, sample
    return rows, fld, ts, tv


def compute_cylinder(p: CylinderParams) -> CylinderResult:
    t_start = time.perf_counter()
    pts = cylinder_samples(p)

    def closed_form(fld):
        x = np.concatenate([pts, fld.node_coords])
        exact = cylinder_closed_form(x, p.E, p.nu, p.traction)
        return {"closed_form_error_pct": float(100 * np.max(np.abs(fld.evaluate(x) - exact))
                                               / np.max(np.abs(exact)))}
    rows, fld, ts, tv = _refine(p, solve_cylinder, (0.0, 0.0, p.length), pts, closed_form)
    q = rows[-1].quantity
    return CylinderResult(
        reference=CYLINDER, params=_p.as_dict(p), quantity_name="u_z at (0, 0, L) (m)",
        quantity=q, refinement=tuple(rows), refinement_change_pct=rows[-1].change_pct,
        setup_s=ts, solve_s=tv, study_s=time.perf_counter() - t_start, field=fld,
        uz_top=q, closed_form_error_pct=rows[-1].extra["closed_form_error_pct"],
        field_change_pct=rows[-1].extra.get("field_change_pct", float("nan")))


def cylinder_tension(*, use_cache: bool = True, **params) -> CylinderResult:
    """Converged, cached FEM reference of the quarter cylinder under tension."""
    p = _p.build(CylinderParams, CYLINDER, params)
    return cached(CYLINDER, _p.as_dict(p), lambda: compute_cylinder(p),
                  {"CylinderResult": CylinderResult}, use_cache=use_cache)


# --- block with a spherical cavity ----------------------------------------------------------

@dataclass(frozen=True)
class CavityParams:
    """The octant of a block with a spherical cavity under remote tension along z."""

    width: float = 1.0
    radius: float = 0.3
    E: float = 1e9
    nu: float = 0.3
    traction: float = 1e6
    cells: int = 2               # level l: cells + l cells per block edge (3 blocks)
    levels: int = 3
    sample_spacing: float = 0.1

    def __post_init__(self):
        _p.positive(CAVITY, width=self.width, radius=self.radius, E=self.E,
                    sample_spacing=self.sample_spacing)
        _p.require(-1 < self.nu < 0.5, CAVITY, f"nu must lie in (-1, 0.5), got {self.nu}")
        _p.require(math.isfinite(self.traction) and self.traction != 0, CAVITY,
                   f"traction must be finite and nonzero, got {self.traction}")
        _p.require(self.radius < 0.9 * self.width, CAVITY,
                   f"radius {self.radius} must be below 0.9 width ({self.width})")
        _p.require(1 <= self.cells <= 8 and 2 <= self.levels <= 4
                   and self.cells + self.levels - 1 <= 6, CAVITY,
                   f"cells 1..8, levels 2..4 and at most 6 cells per block edge at the "
                   f"finest level (71 k unknowns, ~2 GB), got cells={self.cells}, levels={self.levels}")

    def finest_cells(self) -> tuple:
        return _hexes_to_cells(3 * (self.cells + self.levels - 1) ** 3)


def cavity_beta(W, a):
    """beta / expm1(beta) = a (pi/4) / (W - a) (0: uniform, when >= 1)."""
    c = a * 0.25 * np.pi / (W - a)
    if c >= 1:
        return 0.0
    return float(brentq(lambda b: b / math.expm1(b) - c, 1e-12, 200.0, xtol=1e-14))


def cavity_mesh(W, a, n):
    beta = cavity_beta(W, a)

    def g(s):
        return s if beta == 0.0 else np.expm1(beta * s) / math.expm1(beta)

    def block(perm):
        def F(s, t, u):
            d = [W + 0 * s, W * t, W * u]
            dx, dy, dz = d[perm[0]], d[perm[1]], d[perm[2]]
            r = np.sqrt(dx * dx + dy * dy + dz * dz)
            gs = g(s)
            return tuple(a * c / r + gs * (c - a * c / r) for c in (dx, dy, dz))
        return F
    # block k: the rays through the face x_k = W (perm puts the W coordinate at axis k)
    blocks = [(block((0, 1, 2)), (n, n, n)), (block((2, 0, 1)), (n, n, n)),
              (block((1, 2, 0)), (n, n, n))]
    return tet_mesh(blocks, tol=1e-9 * W)


def solve_cavity(p: CavityParams, n: int, width: float | None = None):
    t0 = time.perf_counter()
    W = p.width if width is None else width
    a = p.radius
    model = Solid3D(*cavity_mesh(W, a, n), p.E, p.nu)
    tol = 1e-9 * W
    f = model.traction_load(lambda x: x[2] > W - tol,
                            lambda x: np.stack([0 * x[0], 0 * x[0], 0 * x[0] + p.traction]))
    fixed = np.concatenate([model.dofs(lambda x: np.abs(x[:, k]) < tol, k) for k in range(3)])
    K = model.stiffness()
    t1 = time.perf_counter()
    u = model.solve(K, f, fixed)
    return model, model.field(u), t1 - t0, time.perf_counter() - t1


def cavity_scf(fld, a, sigma) -> float:
    """sigma_zz / sigma at the equator point (a cos 22.5deg, a sin 22.5deg, 0), taken a
    1e-9 a inside the body (the element that holds it)."""
    th = np.pi / 8
    x = np.array([[a * (1 + 1e-9) * np.cos(th), a * (1 + 1e-9) * np.sin(th), 1e-9 * a]])
    return float(fld.stress(x)[0, 2, 2] / sigma)


@dataclass(frozen=True, eq=False, kw_only=True)
class CavityResult(_SliceMixin, MeshReferenceResult):
    """Converged block with a cavity (see :class:`ReferenceResult`).

    Attributes
    ----------
    uz_top : u_z at (0, 0, W) (= ``quantity``).
    scf : sigma_zz at the equator / sigma (finest level).
    field_change_pct : change of the field on the sample points over the last refinement.
    """

    uz_top: float
    scf: float
    field_change_pct: float

    def inside(self, x):
        W, a = self.params["width"], self.params["radius"]
        return np.all((x >= 0) & (x <= W), axis=1) & (np.linalg.norm(x, axis=1) >= a)

    def metrics(self) -> dict:
        return {"uz_top": float(self.uz_top), "scf": float(self.scf),
                "field_change_pct": float(self.field_change_pct),
                "refinement_change_pct": float(self.refinement_change_pct)}


def cavity_samples(p) -> np.ndarray:
    x = _lattice_centres((p.width,) * 3, p.sample_spacing)
    return x[np.linalg.norm(x, axis=1) > p.radius]


def compute_cavity(p: CavityParams) -> CavityResult:
    t_start = time.perf_counter()
    pts = cavity_samples(p)
    rows, fld, ts, tv = _refine(p, solve_cavity, (0.0, 0.0, p.width), pts,
                                lambda fld: {"scf": cavity_scf(fld, p.radius, p.traction)})
    q = rows[-1].quantity
    return CavityResult(
        reference=CAVITY, params=_p.as_dict(p), quantity_name="u_z at (0, 0, W) (m)",
        quantity=q, refinement=tuple(rows), refinement_change_pct=rows[-1].change_pct,
        setup_s=ts, solve_s=tv, study_s=time.perf_counter() - t_start, field=fld,
        uz_top=q, scf=rows[-1].extra["scf"],
        field_change_pct=rows[-1].extra.get("field_change_pct", float("nan")))


def cavity_block(*, use_cache: bool = True, **params) -> CavityResult:
    """Converged, cached FEM reference of the block octant with a spherical cavity."""
    p = _p.build(CavityParams, CAVITY, params)
    return cached(CAVITY, _p.as_dict(p), lambda: compute_cavity(p),
                  {"CavityResult": CavityResult}, use_cache=use_cache)


def large_block_check(width_ratio: float = 8.0, cells: tuple = (2, 3, 4), **params) -> dict:
    """The block of :class:`CavityParams` with W = ``width_ratio`` a: its equator
    concentration per mesh (``cells`` per block edge) against Goodier's infinite-body
    value (module docstring). Returns ``{"scf": [...], "goodier": ..., "cells": ...}``."""
    p = _p.build(CavityParams, CAVITY, params)
    W = width_ratio * p.radius
    scf = [cavity_scf(solve_cavity(p, n, width=W)[1], p.radius, p.traction) for n in cells]
    return {"scf": scf, "goodier": goodier_scf(p.nu), "cells": list(cells),
            "width_ratio": float(width_ratio)}
