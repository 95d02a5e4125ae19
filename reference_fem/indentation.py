"""block2d-indentation: seed 003 Sec. 4.2, rigid circular indenter with sticking contact.

Seed 003 (Ritter et al.), Sec. 4.2: square block of edge 40 mm, rigid circular indenter
of radius R = 15 mm pressed into the middle of the top edge, depth ramped from 0 to 2 mm;
"parts of the surface that get in contact with the indenter move without slip along with
the indenter surface". The paper's FEM used square elements of 0.25 mm. ERRATA (chosen):
E = 1 GPa, nu = 1/3, plane stress, unit thickness, bottom edge fixed, sides free, indenter
centred, at least 20 depth steps, a surface node sticks once the indenter reaches it.

Frame: x in [-W/2, W/2], y in [-H, 0]; the top surface is y = 0 and the indenter at
depth d is the disc of radius R centred at (0, R - d).

Contact law (our exact choice; the paper gives only the sentence above):

- Candidates are all DOF nodes of the top edge (vertices and edge midpoints of the Q2
  mesh); the rest of the boundary cannot be reached for depth < R <= W/2.
- Small-strain linear elasticity; contact is checked on the deformed position
  x = X + u of each free candidate node. The paper does not state its FEM kinematics
  ("moving away from small-displacement situations"); at full depth the compressive
  strain under the indenter reaches about 13 %, so a finite-strain FEM may differ by an
  amount of that order (not quantified here).
- The depth is ramped in n_steps * substeps equal increments (20 * 8 = 160 by default)
  and reported at the n_steps output depths. The law is path dependent: with only 20
  increments the first one catches the whole geometric chord 2 sqrt(2 R Delta d) before
  the surface can deform, and the force at 0.1 mm comes out about 25 % low (0.2 mm: 4 %;
  2 mm: < 0.01 %); from 160 increments on, doubling changes every output force by less
  than 0.2 %. ``substeps=1`` gives the plain 20-step process, e.g. to match a PD run
  stepped the same way.
- At each increment the indenter moves down by Delta d. Every stuck
  node moves rigidly with it: u_y decreases by Delta d, u_x stays frozen (no slip, no
  separation; stuck nodes never release, whatever the sign of their force).
- Within the step: solve; every free candidate whose deformed position lies inside the
  disc (penetration > 1e-9 R) is caught: its u_x is frozen at its current value and its
  u_y is set so that it lies on the indenter surface at that x (vertical projection);
  re-solve; repeat until no free node penetrates. The set of stuck nodes only grows, so
  this terminates. A node so caught stays on the indenter surface at fixed x afterwards.
- Force = sum of the y reactions of the stuck nodes (positive = pushing the block
  down), for the given thickness (N; with unit thickness this is N per metre).
- Contact width = x distance between the outermost stuck nodes (deformed positions); it
  is quantised by the surface node spacing h / 2.

Symmetry (``symmetry="half"``, the default): block, indenter, mesh (checked: mirror
images to round-off, a vertex line on the axis) and the contact law are symmetric about
x = 0, and the law's catches, made per node by its own penetration, are too. Only the
right half x >= 0 is solved, with u_x = 0 on the axis (u_x odd, u_y even). Every
reported quantity is the full block's: the force and the bottom reaction are twice the
half's (the axis node's reaction, from one side only, is half the full block's like every
other node's), the contact width twice the outermost stuck x, the stuck-node count
mirrored (the axis node once), the field and contact points mirrored. A half model
cannot show an asymmetric solution; the full block shows none here: ``symmetry="full"``
(the whole block, kept) agrees with the half to round-off on the coarsest mesh
(tests/reference_fem/test_indentation_symmetry.py) and over the whole default studies
to the Newton tolerance's effect (benchmarks/fem_indentation.py).

Solution method (small strain): the fixed stiffness (bottom, and the axis u_x of the
half model) is factorised once per mesh. Stuck DOFs carry unknown point forces only, so
the candidate displacements are u_C = G_CS f_S with G = K^-1 restricted to the candidate
rows; the columns of G for a node are computed (two solves) when it is caught. Each
contact iteration is then a dense solve of size 2 |S| (less the axis node's u_x, held by
the symmetry condition). The full field is one more solve at full depth.

Solution method (finite strain, St Venant-Kirchhoff or neo-Hookean: ``law``): each
increment starts from the tangent predictor and iterates to a free residual below
:data:`NEWTON_RTOL` of the force scale. The sparse LU of the tangent is kept across iterations and increments (a modified
Newton step costs one residual and one back-substitution) as long as a step reduces the
free residual at least 10-fold (:data:`REUSE_CONTRACTION`); otherwise that iteration is a
Newton step with the tangent factorised at the iterate and a halving line search. A
catch changes the free set and so factorises anew. ``solve_level_finite(...,
newton="plain")`` factorises at every iterate (the former method, for measurement); the
two stop at the same rule and agree to its order (measured 3e-11 relative on the force).

Mesh: tensor-product Q2 mesh with uniform spacing h in |x| <= fine_half_width and in
y >= -fine_depth, growing geometrically (grading_ratio) outside; level l bisects every
element of level 0 l times (nested meshes, every element halves). The compared quantity
is the force at full depth; its level-to-level change (and that of the whole force-depth
curve) is recorded. The refinement table's ``dofs`` are those of the solved model (half
the block's for ``symmetry="half"``).
"""
from __future__ import annotations

import math
import time
from dataclasses import dataclass

import numpy as np
import scipy.sparse.linalg as spla

from . import params as _p
from .cache import cached
from .elasticity import Material, TensorElasticity
from .hyperelastic import LAWS
from .field import FieldSolution, midpoint_refined
from .meshing import fine_then_geometric
from .results import ReferenceResult, RefinementRow, change_pct

REFERENCE = "block2d-indentation"
KINEMATICS = ("small", "finite")
SYMMETRIES = ("half", "full")


@dataclass(frozen=True)
class IndentationParams:
    """Parameters (defaults: seed 003 Sec. 4.2 and ERRATA)."""

    width: float = 0.040           # m, Sec. 4.2
    height: float = 0.040          # m, Sec. 4.2
    radius: float = 0.015          # indenter radius (m), Sec. 4.2
    depth: float = 0.002           # final indentation depth (m), Sec. 4.2
    n_steps: int = 20              # output depth steps, ERRATA: at least 20
    substeps: int = 8              # contact increments per output step (path dependence)
    E: float = 1e9                 # Pa, ERRATA (chosen)
    nu: float = 1.0 / 3.0          # ERRATA (chosen)
    thickness: float = 1.0         # m, ERRATA: unit thickness
    spacing: float = 0.001         # fine element edge of level 0 (m)
    fine_half_width: float = 0.010  # |x| range of the fine zone (m); contact half-width ~4.4 mm
    fine_depth: float = 0.004      # depth of the fine zone below the top (m)
    grading_ratio: float = 1.3     # element growth factor outside the fine zone (level 0)
    levels: int = 3                # level l halves every element l times
    kinematics: str = "small"      # small strain, or finite (St Venant-Kirchhoff, Newton)
    symmetry: str = "half"         # half (x >= 0, u_x = 0 on the axis) or the full block
    #: the finite-strain material law (``hyperelastic.LAWS``): St Venant-Kirchhoff (the
    #: reference the PD runs are measured against) or compressible neo-Hookean with the
    #: same Lame parameters (which law the paper's FEM used is not stated)
    law: str = "saint-venant-kirchhoff"

    def __post_init__(self):
        _p.positive(REFERENCE, width=self.width, height=self.height, radius=self.radius,
                    depth=self.depth, E=self.E, thickness=self.thickness,
                    spacing=self.spacing, fine_half_width=self.fine_half_width,
                    fine_depth=self.fine_depth)
        _p.require(-1 < self.nu < 0.5, REFERENCE, f"nu must lie in (-1, 0.5), got {self.nu}")
        _p.require(self.n_steps >= 1, REFERENCE, f"n_steps must be >= 1, got {self.n_steps}")
        _p.require(self.substeps >= 1, REFERENCE, f"substeps must be >= 1, got {self.substeps}")
        _p.require(self.depth < self.radius, REFERENCE, "depth must be below the radius")
        _p.require(self.radius <= self.width / 2, REFERENCE,
                   "radius must not exceed width / 2 (only the top edge can be reached)")
        _p.require(self.depth < self.height / 4, REFERENCE, "depth must be below height / 4")
        _p.require(1.0 <= self.grading_ratio <= 2.0, REFERENCE,
                   f"grading_ratio must lie in [1, 2], got {self.grading_ratio}")
        _p.require(2 <= self.levels <= 5, REFERENCE, f"levels must be 2..5, got {self.levels}")
        _p.require(self.kinematics in KINEMATICS, REFERENCE,
                   f"kinematics must be one of {', '.join(KINEMATICS)}, got {self.kinematics!r}")
        _p.require(self.symmetry in SYMMETRIES, REFERENCE,
                   f"symmetry must be one of {', '.join(SYMMETRIES)}, got {self.symmetry!r}")
        _p.require(self.law in LAWS, REFERENCE,
                   f"law must be one of {', '.join(LAWS)}, got {self.law!r}")
        _p.require(self.kinematics == "finite" or self.law == "saint-venant-kirchhoff",
                   REFERENCE, f"law={self.law} needs kinematics=finite (small strain has "
                   "one linear law)")

    def finest_cells(self) -> tuple[int, int]:
        """Elements along x and y of the finest level, counted without building the mesh
        (for a resource estimate): the fine zone at ``spacing``, then elements growing by
        ``grading_ratio`` up to each outer edge, then ``levels - 1`` bisections."""
        def cells(fine: float, outside: tuple[float, ...]) -> int:
            n = max(1, round(fine / self.spacing))
            h, r = fine / n, self.grading_ratio
            for rest in outside:
                if rest > 0:
                    n += (math.ceil(rest / (h * r)) if r == 1.0 else
                          max(1, math.ceil(math.log1p(rest * (r - 1) / (h * r)) / math.log(r))))
            return n
        half = min(self.fine_half_width, self.width / 2)
        fine_y = min(self.fine_depth, self.height)
        k = 2 ** (self.levels - 1)
        return (cells(2 * half, (self.width / 2 - half,) * 2) * k,
                cells(fine_y, (self.height - fine_y,)) * k)


@dataclass(frozen=True, eq=False, kw_only=True)
class IndentationResult(ReferenceResult):
    """Converged indentation (see :class:`ReferenceResult`; ``field`` is at full depth).

    Attributes
    ----------
    depths : indenter depth per step, 0 first (m), shape (n_steps + 1,).
    forces : indentation force per step (N, for the thickness), same shape.
    contact_widths : contact width per step (m), same shape.
    contact_nodes : number of stuck surface nodes per step, same shape.
    max_force : force at full depth (N); equals ``quantity``.
    force_monotone : True if the force increases strictly with depth.
    contact_x, contact_y : deformed positions of the stuck nodes at full depth (m).
    curve_change_pct : max over output steps of the force change between the last two
        levels, relative to the full-depth force (percent).
    curve_rel_change_pct : the same change relative to each step's own force (percent);
        dominated by the first steps, where the contact spans few elements.
    max_constraint_error : max |u - prescribed| over stuck DOFs in the full-depth field,
        relative to the depth (a solver check).
    bottom_reaction : total y reaction of the fixed bottom edge at full depth (N); equals
        ``max_force`` by equilibrium (a check).
    step_change_pct : max over output steps of the relative force change when the finest
        mesh is stepped with twice the substeps (path dependence of the sticking law), %.
    """

    depths: np.ndarray
    forces: np.ndarray
    contact_widths: np.ndarray
    contact_nodes: np.ndarray
    max_force: float
    force_monotone: bool
    contact_x: np.ndarray
    contact_y: np.ndarray
    curve_change_pct: float
    curve_rel_change_pct: float
    max_constraint_error: float
    bottom_reaction: float
    step_change_pct: float

    def metrics(self) -> dict:
        """Scene metrics of issue 5."""
        return {"max_force": self.max_force, "force_monotone": float(self.force_monotone),
                "refinement_change_pct": float(self.refinement_change_pct)}


def _bisect(c: np.ndarray, times: int) -> np.ndarray:
    for _ in range(times):
        c = midpoint_refined(c)
    return c


def mesh_coordinates(p: IndentationParams, level: int):
    """Vertex coordinates (x, y) of refinement level ``level``."""
    xs = fine_then_geometric(-p.width / 2, p.width / 2, -p.fine_half_width, p.fine_half_width,
                             p.spacing, p.grading_ratio)
    ys = fine_then_geometric(-p.height, 0.0, -p.fine_depth, 0.0, p.spacing, p.grading_ratio)
    return _bisect(xs, level), _bisect(ys, level)


def _right_half(xs: np.ndarray) -> np.ndarray:
    """The vertices x >= 0 of a mesh line symmetric about x = 0 with a vertex there."""
    c = xs.size // 2
    if xs.size % 2 == 0 or xs[c] != 0.0 or np.max(np.abs(xs + xs[::-1])) > 1e-12 * np.ptp(xs):
        raise RuntimeError("indentation: the x mesh line is not symmetric about x = 0")
    return xs[c:]


def _half_model(p: IndentationParams, level: int):
    """The model of the mesh that is solved (the right half for ``symmetry="half"``), the
    full mesh's x line, and the Dirichlet dofs: the bottom edge, and u_x on the axis x = 0
    for the half model (the mirror condition of a problem symmetric about the axis: u_x
    odd, u_y even)."""
    xs, ys = mesh_coordinates(p, level)
    half = p.symmetry == "half"
    model = TensorElasticity((_right_half(xs) if half else xs, ys),
                             Material(p.E, p.nu, "plane_stress", p.thickness))
    tol = 1e-9 * p.height
    fixed = model.dofs(lambda x, y: y < -p.height + tol)
    if half:
        fixed = np.union1d(fixed, model.dofs(lambda x, y: np.abs(x) < tol, [0]))
    return model, xs, fixed


def _mirrored_field(field: FieldSolution, xs: np.ndarray) -> FieldSolution:
    """The full block's field from the right half's (u_x odd, u_y even about x = 0)."""
    left = field.values[:0:-1].copy()
    left[..., 0] *= -1.0
    return FieldSolution(coords=(xs, field.coords[1]),
                         values=np.concatenate([left, field.values]), lam=field.lam,
                         mu=field.mu)


def _mirrored_points(x: np.ndarray, y: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Points x >= 0 (increasing) and their mirror images, the axis point once."""
    off = x > 0.0
    return (np.concatenate([-x[off][::-1], x[~off], x[off]]),
            np.concatenate([y[off][::-1], y[~off], y[off]]))


def solve_level(p: IndentationParams, level: int, check_steps: bool = False) -> dict:
    """Quasi-static sticking-contact stepping on one mesh (see the module docstring);
    with ``check_steps`` the stepping is repeated with 2 n_steps on the same mesh."""
    t0 = time.perf_counter()
    model, xs, fixed = _half_model(p, level)
    half = p.symmetry == "half"
    K = model.stiffness
    N = model.basis.N
    tol = 1e-9 * p.height
    free = np.setdiff1d(np.arange(N), fixed)
    lu = spla.splu(K[free][:, free].tocsc(), permc_spec="MMD_AT_PLUS_A")
    row_of = np.full(N, -1)
    row_of[free] = np.arange(free.size)
    on_top = lambda x, y: y > -tol  # noqa: E731
    cx, cy = model.dofs(on_top, [0]), model.dofs(on_top, [1])
    cx = cx[np.argsort(model.dof_coords[0, cx])]
    cy = cy[np.argsort(model.dof_coords[0, cy])]
    X0 = model.dof_coords[0, cx]
    if not np.allclose(X0, model.dof_coords[0, cy]):
        raise RuntimeError("top-edge x and y DOFs do not pair up")
    # candidate DOF order: all u_x, then all u_y; -1: held by the symmetry condition
    cand_rows = row_of[np.concatenate([cx, cy])]
    t_setup = time.perf_counter() - t0

    t1 = time.perf_counter()
    store = _FlexibilityColumns(lu, free.size, cand_rows)
    out = _contact_steps(p, p.substeps, store, X0, half)
    S, fS = out["order"], out["fS"]
    # full field at full depth: point forces on the stuck DOFs, bottom (and axis) fixed
    f = np.zeros(N)
    f[cx[S]], f[cy[S]] = fS[0::2], fS[1::2]
    u = np.zeros(N)
    u[free] = lu.solve(f[free])
    if not np.all(np.isfinite(u)):
        raise FloatingPointError("indentation: non-finite displacement")
    target = out["target"]
    err = max(np.max(np.abs(u[cx[S]] - target[:, 0])), np.max(np.abs(u[cy[S]] - target[:, 1])))
    bottom_y = model.dofs(lambda x, y: y < -p.height + tol, [1])
    bottom_reaction = (2.0 if half else 1.0) * float((model.reactions(u)[bottom_y]).sum())
    solve_s = time.perf_counter() - t1
    step_change = float("nan")
    if check_steps:
        twice = _contact_steps(p, 2 * p.substeps, store, X0, half)
        step_change = float(100 * np.max(np.abs(twice["forces"] - out["forces"])[1:]
                                         / twice["forces"][1:]))
    field, contact_x, contact_y = model.field(u), X0[S] + target[:, 0], target[:, 1]
    if half:
        order = np.argsort(contact_x)
        field = _mirrored_field(field, xs)
        contact_x, contact_y = _mirrored_points(contact_x[order], contact_y[order])
    return dict(model=model, field=field, depths=out["depths"], forces=out["forces"],
                widths=out["widths"], counts=out["counts"], contact_x=contact_x,
                contact_y=contact_y, constraint_error=float(err / p.depth),
                stuck_dofs=np.stack([cx[S], cy[S]]), stuck_targets=target,
                bottom_reaction=bottom_reaction, n_solves=store.n_solves + 1,
                step_change_pct=step_change, setup_s=t_setup, solve_s=solve_s,
                h_min=float(min(np.diff(model.coords[0]).min(), np.diff(model.coords[1]).min())))


def solve_level_finite(p: IndentationParams, level: int, check_steps: bool = False,
                       newton: str = "reuse") -> dict:
    """The contact law of the module docstring with finite-strain kinematics
    (:class:`~reference_fem.hyperelastic.StVenantKirchhoff`): each increment is solved by
    Newton's method, candidates are tested at their deformed positions as before; with
    ``check_steps`` the stepping is repeated with twice the increments. ``newton``:
    ``"reuse"`` keeps a factorised tangent while it converges fast (:func:`_newton`),
    ``"plain"`` factorises the tangent at every iterate (the former method, kept to
    measure against)."""
    if newton not in NEWTON_METHODS:
        raise ValueError(f"newton must be one of {', '.join(NEWTON_METHODS)}, got {newton!r}")
    t0 = time.perf_counter()
    model, xs, fixed = _half_model(p, level)
    half = p.symmetry == "half"
    svk = LAWS[p.law](model)
    tol = 1e-9 * p.height
    on_top = lambda x, y: y > -tol  # noqa: E731
    cx, cy = model.dofs(on_top, [0]), model.dofs(on_top, [1])
    cx = cx[np.argsort(model.dof_coords[0, cx])]
    cy = cy[np.argsort(model.dof_coords[0, cy])]
    X0 = model.dof_coords[0, cx]
    t_setup = time.perf_counter() - t0
    t1 = time.perf_counter()
    out = _finite_steps(p, p.substeps, svk, fixed, cx, cy, X0, newton)
    solve_s = time.perf_counter() - t1
    step_change = float("nan")
    if check_steps:
        twice = _finite_steps(p, 2 * p.substeps, svk, fixed, cx, cy, X0, newton)
        step_change = float(100 * np.max(np.abs(twice["forces"] - out["forces"])[1:]
                                         / twice["forces"][1:]))
    u, stuck, target = out["u"], out["stuck"], out["target"]
    f = svk.internal_force(u)
    bottom_y = model.dofs(lambda x, y: y < -p.height + tol, [1])
    err = max(np.max(np.abs(u[cx[stuck]] - target[stuck, 0]), initial=0.0),
              np.max(np.abs(u[cy[stuck]] - target[stuck, 1]), initial=0.0))
    field = model.field(u)
    contact_x, contact_y = X0[stuck] + u[cx[stuck]], target[stuck, 1]
    if half:
        field = _mirrored_field(field, xs)
        contact_x, contact_y = _mirrored_points(contact_x, contact_y)
    return dict(model=model, field=field, depths=out["depths"], forces=out["forces"],
                widths=out["widths"], counts=out["counts"], contact_x=contact_x,
                contact_y=contact_y, constraint_error=float(err / p.depth),
                bottom_reaction=(2.0 if half else 1.0) * float(f[bottom_y].sum()),
                n_solves=out["solves"], n_factorisations=out["factorisations"],
                step_change_pct=step_change, setup_s=t_setup, solve_s=solve_s,
                h_min=float(min(np.diff(model.coords[0]).min(), np.diff(model.coords[1]).min())),
                min_jacobian=out["min_jacobian"])


def _finite_steps(p, substeps, svk, fixed_dofs, cx, cy, X0, newton="reuse") -> dict:
    """The finite-strain stepping on the solved mesh; forces, widths and counts are the
    full block's (doubled, mirrored) for ``p.symmetry == "half"``."""
    N = svk.basis.N
    R = p.radius
    half = p.symmetry == "half"
    n_inc = p.n_steps * substeps
    dd = p.depth / n_inc
    fixed = np.zeros(N, dtype=bool)
    fixed[fixed_dofs] = True
    stuck = np.zeros(X0.size, dtype=bool)
    target = np.zeros((X0.size, 2))    # prescribed (u_x, u_y) of stuck nodes
    u = np.zeros(N)
    depths, forces, widths, counts = [0.0], [0.0], [0.0], [0]
    solves, min_jac = 0, 1.0
    tangent = _Tangent(svk, keep=newton == "reuse")
    for step in range(1, n_inc + 1):
        d = p.depth * step / n_inc
        yc = R - d
        previous = u.copy()
        target[stuck, 1] -= dd
        u[cy[stuck]] = target[stuck, 1]
        while True:
            solves += _newton(svk, u, fixed, previous, d, tangent)
            det, x = svk.min_jacobian(u)
            min_jac = min(min_jac, det)
            if det <= 0:
                raise FloatingPointError(f"indentation (finite strain): the mesh folds at "
                                         f"depth {d * 1e3:.4g} mm, det F = {det:.3g} at "
                                         f"({x[0] * 1e3:.3g}, {x[1] * 1e3:.3g}) mm")
            x, y = X0 + u[cx], u[cy]
            new = ~stuck & (np.hypot(x, y - yc) - R < -1e-9 * R)
            if not new.any():
                break
            previous = u.copy()
            target[new, 0] = u[cx[new]]
            target[new, 1] = yc - np.sqrt(R ** 2 - x[new] ** 2)
            u[cy[new]] = target[new, 1]
            stuck |= new
            fixed[cx[new]] = fixed[cy[new]] = True
        if step % substeps:
            continue
        f = svk.internal_force(u)
        xs = X0[stuck] + u[cx[stuck]]
        depths.append(d)
        if half:   # the axis node's y reaction is half the full block's, like every other
            forces.append(-2.0 * float(f[cy[stuck]].sum()))
            widths.append(2.0 * float(xs.max()) if xs.size else 0.0)
            counts.append(2 * int(stuck.sum()) - int(np.sum(stuck & (X0 == 0.0))))
        else:
            forces.append(-float(f[cy[stuck]].sum()))
            widths.append(float(xs.max() - xs.min()) if xs.size else 0.0)
            counts.append(int(stuck.sum()))
    return dict(u=u, stuck=stuck, target=target, depths=np.array(depths), forces=np.array(forces),
                widths=np.array(widths), counts=np.array(counts), solves=solves,
                factorisations=tangent.n_factorisations, min_jacobian=min_jac)


#: Newton's stopping rule for the finite-strain steps: the free residual below 1e-10 of
#: the larger of its start and the reactions (the forces are compared at 1e-2 and below).
NEWTON_RTOL = 1e-10
NEWTON_METHODS = ("reuse", "plain")
#: a step with the kept factorisation is taken if it reduces the free residual at least
#: this much; otherwise the tangent is refactorised at the iterate (a Newton step). A
#: cost trade-off only (the stopping rule fixes the accuracy); chosen by measurement
#: (benchmarks/fem_indentation.py).
REUSE_CONTRACTION = 0.1


class _Tangent:
    """The tangent K at some state and the sparse LU of its free block. With ``keep`` it
    is kept (modified Newton) until the free set changes or :func:`_newton` asks for a
    fresh one; without, every :meth:`at` factorises anew (plain Newton)."""

    def __init__(self, svk, keep: bool):
        self.svk, self.keep = svk, keep
        self.K = self.lu = self.fixed = None
        self.n_factorisations = 0

    def at(self, u, fixed) -> "_Tangent":
        """Factorise the tangent at ``u`` on the free dofs of ``fixed``."""
        self.K = self.svk.tangent(u)
        free = np.flatnonzero(~fixed)
        self.lu = spla.splu(self.K[free][:, free].tocsc(), permc_spec="MMD_AT_PLUS_A")
        self.fixed = fixed.copy()
        self.n_factorisations += 1
        return self

    def kept(self, u, fixed) -> "_Tangent":
        """The kept factorisation if it is for the same free set, else one at ``u``."""
        if self.keep and self.fixed is not None and np.array_equal(fixed, self.fixed):
            return self
        return self.at(u, fixed)


def _newton(svk, u, fixed, previous, depth, tangent: _Tangent, maxiter: int = 30) -> int:
    """Equilibrium on the free dofs, in place, from the tangent predictor at ``previous``
    (the last equilibrium; ``u`` holds the new prescribed values); returns the number of
    linear solves.

    The predictor uses the kept factorisation (``tangent.kept``; a fresh one at
    ``previous`` when the free set has changed, and always with ``newton="plain"``). Each
    iteration first tries a step with it (not with ``"plain"``); if that step does not
    reduce the free residual by :data:`REUSE_CONTRACTION`, the iteration is a Newton step
    with the tangent factorised at the iterate, halved by a line search until the
    residual decreases. The stopping rule (:data:`NEWTON_RTOL`) is the same either way."""
    free = np.flatnonzero(~fixed)
    change = np.where(fixed, u - previous, 0.0)
    t = tangent.kept(previous, fixed)
    r0 = svk.internal_force(previous) + t.K @ change
    u[free] = previous[free] - t.lu.solve(r0[free])
    solves = 1
    f = svk.internal_force(u)
    norm = float(np.linalg.norm(f[free]))
    scale = max(norm, float(np.linalg.norm(f[fixed])))
    for _ in range(maxiter):
        if norm <= NEWTON_RTOL * scale:
            return solves
        n_t = np.inf
        if tangent.keep:      # a step with the kept factorisation (of this free set)
            trial = u.copy()
            trial[free] -= tangent.lu.solve(f[free])
            solves += 1
            f_t = svk.internal_force(trial)
            n_t = float(np.linalg.norm(f_t[free]))
        if n_t > REUSE_CONTRACTION * norm:     # a Newton step at the iterate, line search
            du = -tangent.at(u, fixed).lu.solve(f[free])
            solves += 1
            step = 1.0
            for _ in range(13):
                trial = u.copy()
                trial[free] += step * du
                f_t = svk.internal_force(trial)
                n_t = float(np.linalg.norm(f_t[free]))
                if n_t <= (1 - 1e-4 * step) * norm:
                    break
                step *= 0.5
            else:
                raise FloatingPointError(f"indentation (finite strain): Newton's line search "
                                         f"failed at depth {depth * 1e3:.4g} mm")
        u[:] = trial
        f, norm = f_t, n_t
        scale = max(scale, float(np.linalg.norm(f[fixed])))
    raise FloatingPointError(f"indentation (finite strain): Newton did not converge in "
                             f"{maxiter} iterations at depth {depth * 1e3:.4g} mm")


class _FlexibilityColumns:
    """Columns of G = K^-1 (rows: candidate DOFs) for unit forces at candidate nodes,
    computed once per node (two solves) when first needed.

    ``cand_rows`` are the rows (in the numbering of the factorised system) of the top-edge
    DOFs, all u_x then all u_y, -1 for a DOF held fixed (u_x on the axis of the half
    model: its row and column of G are zero, :attr:`active` is False); column 2 i
    (2 i + 1) of :attr:`G` is the response to a unit x (y) force at candidate node i.
    """

    def __init__(self, lu, n_free: int, cand_rows: np.ndarray):
        self.lu, self.n_free, self.rows = lu, n_free, cand_rows
        self.active = cand_rows >= 0
        self.nc = cand_rows.size // 2
        self.G = np.zeros((2 * self.nc, 2 * self.nc))
        self.known = np.zeros(self.nc, dtype=bool)
        self.n_solves = 0

    def ensure(self, nodes: np.ndarray) -> None:
        new = nodes[~self.known[nodes]]
        if new.size == 0:
            return
        rhs = np.zeros((self.n_free, 2 * new.size))
        k = np.arange(new.size)
        for col, dof in ((2 * k, new), (2 * k + 1, self.nc + new)):
            on = self.active[dof]
            rhs[self.rows[dof[on]], col[on]] = 1.0
        cols = np.where(self.active[:, None], self.lu.solve(rhs)[self.rows], 0.0)
        self.G[:, 2 * new] = cols[:, 0::2]
        self.G[:, 2 * new + 1] = cols[:, 1::2]
        self.known[new] = True
        self.n_solves += rhs.shape[1]


def _contact_steps(p: IndentationParams, substeps: int, store: _FlexibilityColumns,
                   X0: np.ndarray, half: bool = False) -> dict:
    """Depth stepping with the sticking contact law of the module docstring, in
    ``p.n_steps * substeps`` equal increments, recorded at the ``p.n_steps`` output depths.
    ``X0`` are the x coordinates of the candidate nodes (the order of ``store``). With
    ``half`` the candidates are those of the right half (x >= 0) and the recorded forces,
    widths and counts the full block's (doubled, mirrored).
    """
    nc = X0.size
    n_inc = p.n_steps * substeps
    R, dd = p.radius, p.depth / n_inc
    stuck = np.zeros(nc, dtype=bool)
    target = np.zeros((nc, 2))         # prescribed (u_x, u_y) of stuck nodes
    uc = np.zeros((nc, 2))             # current candidate displacements
    S = np.zeros(0, dtype=np.int64)    # stuck nodes
    fS = np.zeros(0)                   # their forces, interleaved (x, y)
    depths, forces, widths, counts = [0.0], [0.0], [0.0], [0]
    for step in range(1, n_inc + 1):
        d = p.depth * step / n_inc
        yc = R - d
        target[stuck, 1] -= dd
        while True:
            if S.size:
                cols = np.stack([2 * S, 2 * S + 1], axis=1).ravel()
                rows = np.stack([S, nc + S], axis=1).ravel()
                on = store.active[rows]        # the forces that are unknowns
                GS = store.G[:, cols[on]]
                fS = np.zeros(cols.size)
                fS[on] = np.linalg.solve(GS[rows[on]], target[S].ravel()[on])
                u = GS @ fS[on]
                uc = np.stack([u[:nc], u[nc:]], axis=1)
            x, y = X0 + uc[:, 0], uc[:, 1]
            gap = np.hypot(x, y - yc) - R
            new = np.flatnonzero(~stuck & (gap < -1e-9 * R))
            if new.size == 0:
                break
            stuck[new] = True
            target[new, 0] = uc[new, 0]
            target[new, 1] = yc - np.sqrt(R ** 2 - x[new] ** 2)
            store.ensure(new)
            S = np.concatenate([S, new])
        if step % substeps:
            continue
        xs_stuck = X0[stuck] + target[stuck, 0]
        depths.append(d)
        if half:   # the axis node's y force is half the full block's, like every other
            forces.append(-2.0 * float(fS[1::2].sum()))
            widths.append(2.0 * float(xs_stuck.max()) if xs_stuck.size else 0.0)
            counts.append(2 * int(stuck.sum()) - int(np.sum(stuck & (X0 == 0.0))))
        else:
            forces.append(-float(fS[1::2].sum()))
            widths.append(float(xs_stuck.max() - xs_stuck.min()) if xs_stuck.size else 0.0)
            counts.append(int(stuck.sum()))
    return dict(order=S, fS=fS, target=target[S], depths=np.array(depths),
                forces=np.array(forces), widths=np.array(widths), counts=np.array(counts))


def compute(p: IndentationParams, newton: str = "reuse") -> IndentationResult:
    """Run the refinement study (no cache); ``newton`` as in :func:`solve_level_finite`
    (finite strain only)."""
    t_start = time.perf_counter()
    rows, prev = [], None
    for level in range(p.levels):
        if p.kinematics == "small":
            s = solve_level(p, level, check_steps=level == p.levels - 1)
        else:
            s = solve_level_finite(p, level, check_steps=level == p.levels - 1, newton=newton)
        q = float(s["forces"][-1])
        q_prev = None if prev is None else prev["forces"][-1]
        extra = {"contact_width_m": float(s["widths"][-1]),
                 "contact_nodes": int(s["counts"][-1]), "solves": int(s["n_solves"])}
        if "n_factorisations" in s:
            extra["factorisations"] = int(s["n_factorisations"])
        if prev is not None:
            dF = np.abs(s["forces"] - prev["forces"])[1:]
            extra["curve_change_pct"] = float(100 * np.max(dF) / abs(q))
            extra["curve_rel_change_pct"] = float(100 * np.max(dF / s["forces"][1:]))
        rows.append(RefinementRow(level=level, dofs=int(s["model"].basis.N), h_min=s["h_min"],
                                  quantity=q, change_pct=change_pct(q, q_prev),
                                  setup_s=s["setup_s"], solve_s=s["solve_s"], extra=extra))
        prev = s
    forces = s["forces"]
    return IndentationResult(
        reference=REFERENCE, params=_p.as_dict(p), quantity_name="force at full depth (N)",
        quantity=q, refinement=tuple(rows), refinement_change_pct=rows[-1].change_pct,
        setup_s=s["setup_s"], solve_s=s["solve_s"], study_s=time.perf_counter() - t_start,
        field=s["field"], depths=s["depths"], forces=forces, contact_widths=s["widths"],
        contact_nodes=s["counts"], max_force=float(forces.max()),
        force_monotone=bool(np.all(np.diff(forces) > 0)), contact_x=s["contact_x"],
        contact_y=s["contact_y"], curve_change_pct=rows[-1].extra["curve_change_pct"],
        curve_rel_change_pct=rows[-1].extra["curve_rel_change_pct"],
        max_constraint_error=s["constraint_error"], bottom_reaction=s["bottom_reaction"],
        step_change_pct=s["step_change_pct"])


def indentation(*, use_cache: bool = True, **params) -> IndentationResult:
    """Converged, cached FEM reference of the rigid-indenter problem (seed 003 Sec. 4.2).

    Keyword arguments override :class:`IndentationParams`.
    """
    p = _p.build(IndentationParams, REFERENCE, params)
    return cached(REFERENCE, _p.as_dict(p), lambda: compute(p),
                  {"IndentationResult": IndentationResult}, use_cache=use_cache)
