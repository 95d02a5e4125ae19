"""plate-crack, plate-edge-crack: stationary mode I cracks in finite plates (issue 54).

The problems (plane stress, thickness 1 m as the other references; E = 1 GPa, nu = 0.3,
sigma = 1 MPa):

- **plate-crack** (``kind="centre"``): a centre crack of length 2a in a plate of width
  2W and height 2H under the remote tension sigma on y = +-H (mode I). By symmetry a
  quarter is modelled, [0, W] x [0, H] (defaults W = 1 m, a = 0.5 m, H = 3 m): u_x = 0
  on x = 0; on y = 0 the crack face 0 <= x < a is traction free and the ligament
  a <= x <= W has u_y = 0; traction (0, sigma) on y = H; x = W free.
- **plate-edge-crack** (``kind="edge"``, :func:`edge_crack_plate`): a single edge crack of
  depth a in a strip of width b (``width``) and height 2H, the ends loaded by the uniform
  tension sigma and free to rotate (single-edge-notched tension, SENT). By the symmetry
  about the crack line a half is modelled, [0, b] x [0, H] (defaults b = 1 m, a = 0.5 m,
  H = 2 m): y = 0 as above (face 0 <= x < a free, ligament u_y = 0); u_x = 0 at the one
  node (b, 0) against the rigid translation along x; x = 0 and x = b free.

Elements and mesh: 9-node biquadratic quadrilaterals (vector ``ElementQuad2``, the
isoparametric machinery of ``mesh_elasticity``; the elements are rectangles, so the map
is affine) on a tensor grid graded toward the tip (a, 0): with L = min(a, W - a), the x
nodes on [0, a] and [a, W] and the y nodes on [0, L] are each ``cells * 2^l`` elements
(level l) power graded toward the tip (``meshing.power_graded`` with
``grading_power`` = 4: the elements at the tip shrink like n^-4; power > k / lambda =
2 / 0.5 recovers the optimal rate of Q2 for the r^(1/2) singularity, Babuska & Guo; see
``meshing.power_graded``), and y in [L, H] has ``n * max(1, round((H - L) / (4 L)))``
uniform elements. No quarter-point elements: the grading alone converges K (below).
Refining doubles the elements of every segment under the same grading map.

K_I, two stated methods:

1. **J by the equivalent domain integral** (Li, Shih & Needleman, Eng. Fract. Mech. 21,
   1985, area form; :func:`j_integral`) over the half model, doubled for the mirror
   half, with the weight q the Q2 interpolant of (1 - (r/R)^2)^2 (r < R) about the tip,
   so that the integrand is a polynomial of the element and the 4 x 4 Gauss rule
   integrates it exactly (``intorder`` 7, 8 and 12 agree to 1e-14); K = sqrt(E' J) with
   E' = E in plane stress (:func:`effective_modulus`). Three domains, R = 0.1, 0.2,
   0.4 L (``j_radii``); the compared K is the middle one.
2. **Opening fit** (:func:`opening_fit`, a check): Williams' mode I expansion on the
   upper crack face (theta = pi) is u_y = (4 / E) sqrt(r / 2 pi) (K + c_1 r + c_2 r^2
   + ...) in plane stress (the integer-power terms vanish there; symmetry leaves no rigid
   motion), fitted by least squares at 64 points uniform in r = a - x in
   [0.02, 0.3] L (``fit_window``).

The handbook (:func:`tada_centre`, :func:`tada_edge`; Tada, Paris & Irwin, The Stress
Analysis of Cracks Handbook, 3rd ed. 2000): centre crack K = sigma sqrt(pi a) F(a/W),
F = (1 - 0.025 l^2 + 0.06 l^4) sqrt(sec(pi l / 2)), accuracy 0.1 % for any l; SENT
K = sigma sqrt(pi a) F(a/b), F = sqrt(2b/(pi a) tan(pi a / 2b)) (0.752 + 2.02 (a/b) +
0.37 (1 - sin(pi a / 2b))^3) / cos(pi a / 2b), accuracy 0.5 % for any a/b. Both are for
the infinitely long strip: doubling the default height (H = 3W to 6W; SENT 2b to 4b)
changes the FEM K by 5e-6 and 1e-6 (relative, level 3; SENT with H = b: 3e-4), so the
defaults are long strips to well within the accuracy. The reference's own error budget
is a tenth of the handbook's accuracy (1e-4 centre, 5e-4 edge).

Refinement study (compared quantity K_I from J on the middle domain; each row's
``extra``: ``k_j_R0..2`` per domain, ``k_fit``, ``k_ratio`` = K / K_Tada,
``j_domain_spread_pct``, ``opening_mouth`` = u_y(0, 0), and from level 1
``field_change_pct``: the change of the field on the cell centres of the
``sample_spacing`` grid over the quarter, normalised as in ``plate.py``). Measured with
the defaults (4 elements per tip segment at level 0, five levels, finest 64: 128 x 128
elements, 132 098 DOFs, smallest edge 3.0e-8 m; each study 4-7 s under load):

- centre, a/W = 0.5: K/K_Tada = 0.99387, 0.99990, 1.000325, 1.000366, 1.000368
  (K = 1.48727e6 Pa m^0.5 against Tada's 1.48672e6: 0.037 %, inside the stated 0.1 %);
  changes 0.60, 0.043, 0.0041, 0.00029 % (a factor 10-14 per level); the J domain
  spread 0.23, 0.017, 2.5e-4, 3.5e-5, 2.0e-6 %; the opening fit 1.48725e6 (1.5e-5
  from J); the field change 0.47, 0.058, 0.0083, 0.0014 %.
- SENT, a/b = 0.5: K/K_Tada = 0.98724, 0.99809, 0.99919, 0.99928, 0.999291
  (K = 3.54008e6 against 3.54259e6: -0.071 %, inside 0.5 %); changes 1.09, 0.110,
  0.0097, 0.00067 %; domain spread 0.19, 0.019, 4.3e-4, 4.9e-5, 3.0e-6 %; the opening
  fit 9.4e-5 from J; the field change 1.27, 0.145, 0.013, 0.0014 %.
- other lengths (four levels, last change <= 1e-4): centre a/W = 0.2, 0.8:
  K/K_Tada = 1.000101, 1.000919; SENT a/b = 0.2, 0.8: 1.000479, 0.996882 (all inside
  Tada's stated accuracy; a/W = 0.8 uses 92 % of the centre crack's 0.1 %).
- the extraction on the Q2 interpolant of the exact Williams K field (no solve): J and
  the fit recover K within 1.1e-4 (level 2) and 8.3e-6 (level 3).

Evaluation: the field is a :class:`~reference_fem.mesh_field.MeshField` on the box
[0, W] x [0, H]; a point on y = 0 with x < a is on the upper crack face (u_y > 0); the
other quarters follow by the mirror images (u_x odd in x for the centre crack, u_y odd
in y); points outside the box raise ``ValueError``.
"""
from __future__ import annotations

import math
import time
from dataclasses import dataclass

import numpy as np
from skfem import Basis

from . import params as _p
from .cache import cached
from .elasticity import Material
from .mesh_elasticity import MeshElasticity, mapped_mesh
from .meshing import power_graded
from .results import MeshReferenceResult, RefinementRow, change_pct, field_change_pct

REFERENCE = "plate-crack"
EDGE_REFERENCE = "plate-edge-crack"
KINDS = ("centre", "edge")


@dataclass(frozen=True)
class CrackPlateParams:
    """Parameters of the cracked plate (the centre crack's defaults; see the module)."""

    kind: str = "centre"           # "centre": centre crack, quarter model; "edge": SENT, half
    width: float = 1.0             # W (centre: half-width; edge: the full width b) (m)
    height: float = 3.0            # H: half-height (the traction acts on y = H) (m)
    crack: float = 0.5             # a (centre: half-length; edge: the crack depth) (m)
    thickness: float = 1.0         # m
    E: float = 1e9                 # Pa
    nu: float = 0.3
    traction: float = 1e6          # sigma on y = H (Pa)
    cells: int = 4                 # level 0: elements along each of the tip's segments
    grading_power: float = 4.0     # power grading toward the tip (1: uniform)
    levels: int = 5                # refinement levels (cells x 2^l)
    j_radii: tuple = (0.1, 0.2, 0.4)       # J domains: radius R / min(a, W - a)
    fit_window: tuple = (0.02, 0.3)        # opening fit: r / min(a, W - a) in this window
    sample_spacing: float = 0.025  # grid of the field-change measure (PD default grid)

    def __post_init__(self):
        ref = reference_name(self.kind) if self.kind in KINDS else REFERENCE
        _p.require(self.kind in KINDS, ref, f"kind must be one of {', '.join(KINDS)}, "
                   f"got {self.kind!r}")
        _p.positive(ref, width=self.width, height=self.height, crack=self.crack,
                    thickness=self.thickness, E=self.E, sample_spacing=self.sample_spacing)
        _p.require(-1 < self.nu < 0.5, ref, f"nu must lie in (-1, 0.5), got {self.nu}")
        _p.require(math.isfinite(self.traction) and self.traction != 0, ref,
                   f"traction must be finite and nonzero, got {self.traction}")
        _p.require(0.05 <= self.crack / self.width <= 0.95, ref,
                   f"crack/width = {self.crack / self.width:g} must be in [0.05, 0.95]")
        _p.require(self.height >= min(self.crack, self.width - self.crack), ref,
                   f"height {self.height} must be at least min(a, W - a)")
        _p.require(2 <= self.cells <= 64, ref, f"cells must be 2..64, got {self.cells}")
        _p.require(math.isfinite(self.grading_power) and 1.0 <= self.grading_power <= 8.0,
                   ref, f"grading_power must be in [1, 8], got {self.grading_power}")
        _p.require(2 <= self.levels <= 7, ref, f"levels must be 2..7, got {self.levels}")
        radii = tuple(float(r) for r in self.j_radii)
        _p.require(len(radii) >= 1 and all(0 < r <= 0.9 for r in radii), ref,
                   f"j_radii must be fractions in (0, 0.9] of min(a, W - a), got {radii}")
        lo, hi = (float(r) for r in self.fit_window)
        _p.require(0 < lo < hi <= 0.9, ref,
                   f"fit_window must be 0 < r0 < r1 <= 0.9 (of min(a, W - a)), got {(lo, hi)}")
        for name, v in (("width", self.width), ("height", self.height)):
            n = v / self.sample_spacing
            _p.require(abs(n - round(n)) < 1e-9 * n and round(n) >= 1, ref,
                       f"sample_spacing {self.sample_spacing} must divide {name} {v}")
        nx, ny = self.finest_cells()
        _p.require(nx * ny <= 2 ** 18, ref,
                   f"the finest level would have {nx * ny} elements (at most 2^18)")

    @property
    def tip_length(self) -> float:
        """min(a, W - a): the length of the graded segments about the tip."""
        return min(self.crack, self.width - self.crack)

    def far_cells(self, n: int) -> int:
        """Elements on y in [L, H] at n cells per graded segment (L = tip_length)."""
        L = self.tip_length
        return 0 if self.height <= L * (1 + 1e-12) else n * max(
            1, int(round((self.height - L) / (self.grading_power * L))))

    def finest_cells(self) -> tuple[int, int]:
        """(n_x, n_y) elements of the finest level."""
        n = self.cells * 2 ** (self.levels - 1)
        return 2 * n, n + self.far_cells(n)


def reference_name(kind: str) -> str:
    return REFERENCE if kind == "centre" else EDGE_REFERENCE


# --- handbook formulas (Tada, Paris & Irwin) -------------------------------------------------

def tada_centre(crack: float, width: float, sigma: float) -> float:
    """K_I of a centre crack 2a in a strip of width 2W under remote tension sigma:
    K = sigma sqrt(pi a) F(l), F = (1 - 0.025 l^2 + 0.06 l^4) sqrt(sec(pi l / 2)),
    l = a / W (Tada, Paris & Irwin, The Stress Analysis of Cracks Handbook, 3rd ed., 2000,
    p. 5.2, after Feddersen 1966 and Isida; accuracy 0.1 % for any l)."""
    lam = crack / width
    F = (1 - 0.025 * lam ** 2 + 0.06 * lam ** 4) * math.sqrt(1.0 / math.cos(0.5 * math.pi * lam))
    return sigma * math.sqrt(math.pi * crack) * F


def tada_edge(crack: float, width: float, sigma: float) -> float:
    """K_I of a single edge crack a in a strip of width b under remote tension sigma
    (ends free to rotate): K = sigma sqrt(pi a) F(a/b),
    F = sqrt(2b/(pi a) tan(pi a / 2b)) (0.752 + 2.02 (a/b) + 0.37 (1 - sin(pi a / 2b))^3)
    / cos(pi a / 2b) (Tada, Paris & Irwin, 3rd ed., p. 2.11; accuracy 0.5 % for any a/b)."""
    lam = crack / width
    c = 0.5 * math.pi * lam
    F = (math.sqrt(math.tan(c) / c) * (0.752 + 2.02 * lam + 0.37 * (1 - math.sin(c)) ** 3)
         / math.cos(c))
    return sigma * math.sqrt(math.pi * crack) * F


#: stated accuracy of the handbook formulas (fraction)
HANDBOOK_ACCURACY = {"centre": 1e-3, "edge": 5e-3}


def handbook_k(p: CrackPlateParams) -> float:
    f = tada_centre if p.kind == "centre" else tada_edge
    return f(p.crack, p.width, p.traction)


def effective_modulus(E: float, nu: float) -> float:
    """E' of K = sqrt(E' J) in plane stress: E' = E (plane strain would be E / (1 - nu^2))."""
    return E


# --- mesh and one level ----------------------------------------------------------------------

def crack_nodes(p: CrackPlateParams, n: int) -> tuple[np.ndarray, np.ndarray]:
    """1D node positions (x, y) of the tensor grid graded toward the tip (a, 0)."""
    a, W, H, L = p.crack, p.width, p.height, p.tip_length
    g = p.grading_power
    left = a - power_graded(0.0, a, n, g, "a")[::-1]            # [0, a], fine at a
    right = a + power_graded(0.0, W - a, n, g, "a")             # [a, W], fine at a
    x = np.concatenate([left, right[1:]])
    y = power_graded(0.0, L, n, g, "a")
    m = p.far_cells(n)
    if m:
        y = np.concatenate([y, np.linspace(L, H, m + 1)[1:]])
    return x, y


def crack_mesh(p: CrackPlateParams, n: int):
    x, y = crack_nodes(p, n)
    sx = np.linspace(0.0, 1.0, x.size)
    sy = np.linspace(0.0, 1.0, y.size)

    def F(s, t):               # piecewise linear in each logical direction: rectangles
        return np.interp(s, sx, x), np.interp(t, sy, y)

    h = min(np.diff(x).min(), np.diff(y).min())
    return mapped_mesh([(sx, sy, F)], tol=1e-3 * h)


def domain(p: CrackPlateParams) -> dict:
    return {"box": [[0.0, p.width], [0.0, p.height]]}


def solve_level(p: CrackPlateParams, level: int, material: Material | None = None):
    """One level: returns (model, u, field, setup_s, solve_s)."""
    t0 = time.perf_counter()
    n = p.cells * 2 ** level
    mat = material or Material(p.E, p.nu, "plane_stress", p.thickness)
    model = MeshElasticity(crack_mesh(p, n), mat, domain(p))
    W, H, a = p.width, p.height, p.crack
    tol = 1e-9 * W
    f = model.traction_load(lambda x, y: y > H - 1e-9 * H, [0.0, p.traction])
    ligament = model.dofs(lambda x, y: (np.abs(y) < tol) & (x > a - tol), components=[1])
    if p.kind == "centre":
        other = model.dofs(lambda x, y: np.abs(x) < tol, components=[0])
    else:   # one point against the rigid translation along x: the ligament's end (W, 0)
        other = model.dofs(lambda x, y: (np.abs(x - W) < tol) & (np.abs(y) < tol),
                           components=[0])
    _ = model.stiffness
    t1 = time.perf_counter()
    u = model.solve(f, np.concatenate([ligament, other]))
    fld = model.field(u)
    return model, u, fld, t1 - t0, time.perf_counter() - t1


# --- K extraction -------------------------------------------------------------------------------

def j_integral(model: MeshElasticity, u: np.ndarray, tip: tuple, radius: float,
               intorder: int = 8) -> float:
    """J of the symmetric (mode I) crack from the upper half model by the equivalent
    domain integral (Li, Shih & Needleman 1985, area form):

        J = 2 int_A (sigma_ij u_i,1 - w delta_1j) q_,j dA,

    the crack along -x from the tip; q the Q2 interpolant of (1 - (r/R)^2)^2 for r < R,
    0 beyond (q = 1 at the tip, 0 outside the disk r < R: LSN's weight as nodal values
    interpolated by the element's shape functions, so that on these rectangles the
    integrand is a polynomial of degree <= 6 in each variable and the 4 x 4 Gauss rule of
    ``intorder`` 8 integrates it exactly); the factor 2 for the lower half (the ligament
    y = 0 adds nothing: sigma_12 = 0 and u_2 = 0 there)."""
    b = Basis(model.mesh, model.element, intorder=intorder)
    bs = Basis(model.mesh, model.scalar.elem, intorder=intorder)
    lam, mu = model.material.lame()
    G = b.interpolate(u).grad                                   # (2, 2, el, qp): du_i/dx_j
    eps = 0.5 * (G + np.swapaxes(G, 0, 1))
    tr = eps[0, 0] + eps[1, 1]
    sig = 2 * mu * eps
    sig[0, 0] += lam * tr
    sig[1, 1] += lam * tr
    w = 0.5 * np.einsum("ijeq,ijeq->eq", sig, eps)
    xn, yn = bs.doflocs
    s = ((xn - tip[0]) ** 2 + (yn - tip[1]) ** 2) / radius ** 2
    qn = np.where(s < 1.0, (1.0 - np.minimum(s, 1.0)) ** 2, 0.0)
    qj = bs.interpolate(qn).grad                               # (2, el, qp)
    integrand = np.einsum("ijeq,ieq,jeq->eq", sig, G[:, 0], qj) - w * qj[0]
    return float(2.0 * np.sum(integrand * b.dx))


def opening_fit(fld, p: CrackPlateParams, n_points: int = 64) -> float:
    """K_I from the crack opening behind the tip: on the upper face (r = a - x, theta =
    pi) Williams' mode I expansion gives u_y = (kappa + 1)/(2 mu) sqrt(r / 2 pi)
    (K + c_1 r + c_2 r^2 + ...) (the integer-power terms vanish at theta = pi, and by
    symmetry there is no rigid motion), in plane stress (kappa + 1)/(2 mu) = 4 / E;
    least squares of u_y E sqrt(2 pi / r) / 4 on (1, r, r^2) over ``n_points`` points
    uniform in r in the fit window."""
    L = p.tip_length
    r = np.linspace(p.fit_window[0] * L, p.fit_window[1] * L, n_points)
    pts = np.stack([p.crack - r, np.zeros_like(r)], axis=1)
    uy = fld.evaluate(pts)[:, 1]
    kr = uy * p.E * np.sqrt(2 * np.pi / r) / 4.0
    coef = np.polynomial.polynomial.polyfit(r, kr, 2)
    return float(coef[0])


def sample_points(p: CrackPlateParams) -> np.ndarray:
    """Cell centres of the ``sample_spacing`` grid on [0, W] x [0, H] (the PD default grid)."""
    nx = int(round(p.width / p.sample_spacing))
    ny = int(round(p.height / p.sample_spacing))
    cx = (np.arange(nx) + 0.5) * (p.width / nx)
    cy = (np.arange(ny) + 0.5) * (p.height / ny)
    X, Y = np.meshgrid(cx, cy, indexing="ij")
    return np.stack([X.ravel(), Y.ravel()], axis=1)


# --- the reference --------------------------------------------------------------------------

@dataclass(frozen=True, eq=False, kw_only=True)
class CrackPlateResult(MeshReferenceResult):
    """Converged cracked plate (see :class:`ReferenceResult` for the common fields).

    Attributes
    ----------
    k_j : K_I = sqrt(E' J) (Pa m^0.5) from the domain integral on the middle J domain;
        equals ``quantity``.
    k_j_domains : K_I of each J domain (``params["j_radii"]``), finest level.
    j_domain_spread_pct : 100 (max - min) / mean of ``k_j_domains``.
    k_fit : K_I from the crack-opening fit (finest level).
    k_handbook : Tada's K_I of the plate; ``k_ratio`` = k_j / k_handbook.
    handbook_accuracy_pct : the formula's stated accuracy (percent).
    opening_mouth : u_y at (0, 0), the crack face at the plate's centre (centre crack:
        half the central opening) or at the mouth (edge crack) (m).
    field_change_pct : change of the field on the sample points over the last refinement.
    """

    k_j: float
    k_j_domains: tuple
    j_domain_spread_pct: float
    k_fit: float
    k_handbook: float
    k_ratio: float
    handbook_accuracy_pct: float
    opening_mouth: float
    field_change_pct: float

    def metrics(self) -> dict:
        return {"k_j": float(self.k_j), "k_fit": float(self.k_fit),
                "k_handbook": float(self.k_handbook), "k_ratio": float(self.k_ratio),
                "j_domain_spread_pct": float(self.j_domain_spread_pct),
                "opening_mouth": float(self.opening_mouth),
                "field_change_pct": float(self.field_change_pct),
                "refinement_change_pct": float(self.refinement_change_pct)}


def compute(p: CrackPlateParams) -> CrackPlateResult:
    """Run the refinement study (no cache)."""
    t_start = time.perf_counter()
    pts = sample_points(p)
    mouth = np.array([[0.0, 0.0]])
    tip = (p.crack, 0.0)
    Ep = effective_modulus(p.E, p.nu)
    kh = handbook_k(p)
    mid = len(p.j_radii) // 2
    rows, prev_q, prev_sample = [], None, None
    for level in range(p.levels):
        model, u, fld, ts, tv = solve_level(p, level)
        t1 = time.perf_counter()
        ks = [math.sqrt(Ep * max(j_integral(model, u, tip, r * p.tip_length), 0.0))
              for r in p.j_radii]
        q = ks[mid]
        sample = fld.evaluate(pts)
        extra = {f"k_j_R{k}": v for k, v in enumerate(ks)}
        extra.update(k_fit=opening_fit(fld, p), k_ratio=q / kh,
                     j_domain_spread_pct=float(100 * (max(ks) - min(ks)) / np.mean(ks)),
                     opening_mouth=float(fld.evaluate(mouth)[0, 1]))
        if prev_sample is not None:
            extra["field_change_pct"] = field_change_pct(sample, prev_sample)
        tv += time.perf_counter() - t1
        rows.append(RefinementRow(level=level, dofs=int(model.basis.N), h_min=model.min_edge(),
                                  quantity=q, change_pct=change_pct(q, prev_q), setup_s=ts,
                                  solve_s=tv, extra=extra))
        prev_q, prev_sample = q, sample
    last = rows[-1].extra
    return CrackPlateResult(
        reference=reference_name(p.kind), params=_p.as_dict(p),
        quantity_name="K_I from J (Pa m^0.5)", quantity=q, refinement=tuple(rows),
        refinement_change_pct=rows[-1].change_pct, setup_s=ts, solve_s=tv,
        study_s=time.perf_counter() - t_start, field=fld, k_j=q, k_j_domains=tuple(ks),
        j_domain_spread_pct=last["j_domain_spread_pct"], k_fit=last["k_fit"],
        k_handbook=kh, k_ratio=q / kh, handbook_accuracy_pct=100 * HANDBOOK_ACCURACY[p.kind],
        opening_mouth=last["opening_mouth"], field_change_pct=last["field_change_pct"])


def _run(defaults: dict, params: dict, use_cache: bool) -> CrackPlateResult:
    merged = {**defaults, **params}
    ref = reference_name(merged.get("kind", "centre"))
    p = _p.build(CrackPlateParams, ref, merged)
    return cached(reference_name(p.kind), _p.as_dict(p), lambda: compute(p),
                  {"CrackPlateResult": CrackPlateResult}, use_cache=use_cache)


def crack_plate(*, use_cache: bool = True, **params) -> CrackPlateResult:
    """Converged, cached FEM reference of the centre-cracked plate (issue 54), quarter
    model. Keyword arguments override :class:`CrackPlateParams`; ``use_cache=False``
    recomputes without reading or writing the cache."""
    return _run({}, params, use_cache)


#: the edge crack's defaults that differ from the centre crack's
EDGE_DEFAULTS = {"kind": "edge", "height": 2.0}


def edge_crack_plate(*, use_cache: bool = True, **params) -> CrackPlateResult:
    """Converged, cached FEM reference of the single-edge-notched tension plate (issue
    54), half model; defaults :class:`CrackPlateParams` with ``EDGE_DEFAULTS``."""
    return _run(EDGE_DEFAULTS, params, use_cache)
