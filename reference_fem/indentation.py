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
  x = X + u of each free candidate node.
- At each depth step the indenter moves down by Delta d = depth / n_steps. Every stuck
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

Solution method: the bottom-fixed stiffness is factorised once per mesh. Stuck DOFs carry
unknown point forces only, so the candidate displacements are u_C = G_CS f_S with
G = K^-1 restricted to the candidate rows; the columns of G for a node are computed (two
solves) when it is caught. Each contact iteration is then a dense solve of size 2 |S|.
The full field is one more solve at full depth.

Mesh: tensor-product Q2 mesh with uniform spacing h in |x| <= fine_half_width and in
y >= -fine_depth, growing geometrically (grading_ratio) outside; level l bisects every
element of level 0 l times (nested meshes, every element halves). The compared quantity
is the force at full depth; its level-to-level change (and that of the whole force-depth
curve) is recorded.
"""
from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np
import scipy.sparse.linalg as spla

from . import params as _p
from .cache import cached
from .elasticity import Material, TensorElasticity
from .field import midpoint_refined
from .meshing import fine_then_geometric
from .results import ReferenceResult, RefinementRow, change_pct

REFERENCE = "block2d-indentation"


@dataclass(frozen=True)
class IndentationParams:
    """Parameters (defaults: seed 003 Sec. 4.2 and ERRATA)."""

    width: float = 0.040           # m, Sec. 4.2
    height: float = 0.040          # m, Sec. 4.2
    radius: float = 0.015          # indenter radius (m), Sec. 4.2
    depth: float = 0.002           # final indentation depth (m), Sec. 4.2
    n_steps: int = 20              # depth steps, ERRATA: at least 20
    E: float = 1e9                 # Pa, ERRATA (chosen)
    nu: float = 1.0 / 3.0          # ERRATA (chosen)
    thickness: float = 1.0         # m, ERRATA: unit thickness
    spacing: float = 0.001         # fine element edge of level 0 (m)
    fine_half_width: float = 0.010  # |x| range of the fine zone (m); contact half-width ~4.4 mm
    fine_depth: float = 0.004      # depth of the fine zone below the top (m)
    grading_ratio: float = 1.3     # element growth factor outside the fine zone (level 0)
    levels: int = 3                # level l halves every element l times

    def __post_init__(self):
        _p.positive(REFERENCE, width=self.width, height=self.height, radius=self.radius,
                    depth=self.depth, E=self.E, thickness=self.thickness,
                    spacing=self.spacing, fine_half_width=self.fine_half_width,
                    fine_depth=self.fine_depth)
        _p.require(-1 < self.nu < 1, REFERENCE, f"nu must lie in (-1, 1), got {self.nu}")
        _p.require(self.n_steps >= 1, REFERENCE, f"n_steps must be >= 1, got {self.n_steps}")
        _p.require(self.depth < self.radius, REFERENCE, "depth must be below the radius")
        _p.require(self.radius <= self.width / 2, REFERENCE,
                   "radius must not exceed width / 2 (only the top edge can be reached)")
        _p.require(self.depth < self.height / 4, REFERENCE, "depth must be below height / 4")
        _p.require(1.0 <= self.grading_ratio <= 2.0, REFERENCE,
                   f"grading_ratio must lie in [1, 2], got {self.grading_ratio}")
        _p.require(2 <= self.levels <= 5, REFERENCE, f"levels must be 2..5, got {self.levels}")


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
    curve_change_pct : max over steps of the force change between the last two levels,
        relative to the full-depth force (percent).
    max_constraint_error : max |u - prescribed| over stuck DOFs in the full-depth field,
        relative to the depth (a solver check).
    bottom_reaction : total y reaction of the fixed bottom edge at full depth (N); equals
        ``max_force`` by equilibrium (a check).
    step_change_pct : change of the full-depth force when the same finest mesh is
        stepped with 2 n_steps (path dependence of the sticking law), percent.
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
    max_constraint_error: float
    bottom_reaction: float
    step_change_pct: float


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


def solve_level(p: IndentationParams, level: int, check_steps: bool = False) -> dict:
    """Quasi-static sticking-contact stepping on one mesh (see the module docstring);
    with ``check_steps`` the stepping is repeated with 2 n_steps on the same mesh."""
    t0 = time.perf_counter()
    model = TensorElasticity(mesh_coordinates(p, level),
                             Material(p.E, p.nu, "plane_stress", p.thickness))
    K = model.stiffness
    N = model.basis.N
    tol = 1e-9 * p.height
    bottom = model.dofs(lambda x, y: y < -p.height + tol)
    free = np.setdiff1d(np.arange(N), bottom)
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
    nc = X0.size
    cand_rows = row_of[np.concatenate([cx, cy])]   # candidate DOF order: all u_x, then all u_y
    t_setup = time.perf_counter() - t0

    t1 = time.perf_counter()
    out = _contact_steps(p, p.n_steps, lu, free, cand_rows, X0)
    S, fS = out["order"], out["fS"]
    # full field at full depth: point forces on the stuck DOFs, bottom fixed
    f = np.zeros(N)
    f[cx[S]], f[cy[S]] = fS[0::2], fS[1::2]
    u = np.zeros(N)
    u[free] = lu.solve(f[free])
    if not np.all(np.isfinite(u)):
        raise FloatingPointError("indentation: non-finite displacement")
    target = out["target"]
    err = max(np.max(np.abs(u[cx[S]] - target[:, 0])), np.max(np.abs(u[cy[S]] - target[:, 1])))
    bottom_y = model.dofs(lambda x, y: y < -p.height + tol, [1])
    bottom_reaction = float((model.reactions(u)[bottom_y]).sum())
    solve_s = time.perf_counter() - t1
    step_change = float("nan")
    if check_steps:
        twice = _contact_steps(p, 2 * p.n_steps, lu, free, cand_rows, X0)
        step_change = change_pct(twice["forces"][-1], out["forces"][-1])
    return dict(model=model, field=model.field(u), depths=out["depths"], forces=out["forces"],
                widths=out["widths"], counts=out["counts"], contact_x=X0[S] + target[:, 0],
                contact_y=target[:, 1], constraint_error=float(err / p.depth),
                bottom_reaction=bottom_reaction, n_solves=out["n_solves"] + 1,
                step_change_pct=step_change, setup_s=t_setup, solve_s=solve_s,
                h_min=float(min(np.diff(model.coords[0]).min(), np.diff(model.coords[1]).min())))


def _contact_steps(p: IndentationParams, n_steps: int, lu, free: np.ndarray,
                   cand_rows: np.ndarray, X0: np.ndarray) -> dict:
    """Depth stepping with the sticking contact law of the module docstring.

    ``lu`` factorises the stiffness without the bottom DOFs (``free``); ``cand_rows`` are
    the rows (in ``free`` numbering) of the top-edge DOFs, all u_x then all u_y, in the
    order of their x coordinates ``X0``.
    """
    nc = X0.size
    R, dd = p.radius, p.depth / n_steps
    G = np.zeros((2 * nc, 2 * nc))     # columns 2j, 2j+1: unit forces x, y at order[j]
    order: list[int] = []              # stuck candidate nodes in catch order
    stuck = np.zeros(nc, dtype=bool)
    target = np.zeros((nc, 2))         # prescribed (u_x, u_y) of stuck nodes
    uc = np.zeros((nc, 2))             # current candidate displacements
    fS = np.zeros(0)
    depths, forces, widths, counts = [0.0], [0.0], [0.0], [0]
    n_solves = 0
    for step in range(1, n_steps + 1):
        d = p.depth * step / n_steps
        yc = R - d
        target[stuck, 1] -= dd
        while True:
            if order:
                S = np.asarray(order)
                rows = np.stack([S, nc + S], axis=1).ravel()
                fS = np.linalg.solve(G[rows][:, :2 * S.size], target[S].ravel())
                u = G[:, :2 * S.size] @ fS
                uc = np.stack([u[:nc], u[nc:]], axis=1)
            x, y = X0 + uc[:, 0], uc[:, 1]
            gap = np.hypot(x, y - yc) - R
            new = np.flatnonzero(~stuck & (gap < -1e-9 * R))
            if new.size == 0:
                break
            stuck[new] = True
            target[new, 0] = uc[new, 0]
            target[new, 1] = yc - np.sqrt(R ** 2 - x[new] ** 2)
            rhs = np.zeros((free.size, 2 * new.size))
            k = np.arange(new.size)
            rhs[cand_rows[new], 2 * k] = 1.0
            rhs[cand_rows[nc + new], 2 * k + 1] = 1.0
            cols = lu.solve(rhs)
            n_solves += rhs.shape[1]
            j0 = 2 * len(order)
            G[:, j0:j0 + 2 * new.size] = cols[cand_rows]
            order.extend(new.tolist())
        xs_stuck = X0[stuck] + target[stuck, 0]
        depths.append(d)
        forces.append(-float(fS[1::2].sum()))
        widths.append(float(xs_stuck.max() - xs_stuck.min()) if xs_stuck.size else 0.0)
        counts.append(int(stuck.sum()))
    S = np.asarray(order, dtype=np.int64)
    return dict(order=S, fS=fS, target=target[S], depths=np.array(depths),
                forces=np.array(forces), widths=np.array(widths), counts=np.array(counts),
                n_solves=n_solves)


def compute(p: IndentationParams) -> IndentationResult:
    """Run the refinement study (no cache)."""
    t_start = time.perf_counter()
    rows, prev = [], None
    for level in range(p.levels):
        s = solve_level(p, level, check_steps=level == p.levels - 1)
        q = float(s["forces"][-1])
        extra = {"contact_width_m": float(s["widths"][-1]),
                 "contact_nodes": int(s["counts"][-1]), "solves": int(s["n_solves"])}
        if prev is not None:
            extra["curve_change_pct"] = float(100 * np.max(np.abs(s["forces"] - prev["forces"]))
                                              / abs(q))
        rows.append(RefinementRow(level=level, dofs=int(s["model"].basis.N), h_min=s["h_min"],
                                  quantity=q, change_pct=change_pct(q, None if prev is None else prev["forces"][-1]),
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
        max_constraint_error=s["constraint_error"], bottom_reaction=s["bottom_reaction"],
        step_change_pct=s["step_change_pct"])


def indentation(*, use_cache: bool = True, **params) -> IndentationResult:
    """Converged, cached FEM reference of the rigid-indenter problem (seed 003 Sec. 4.2).

    Keyword arguments override :class:`IndentationParams`.
    """
    p = _p.build(IndentationParams, REFERENCE, params)
    return cached(REFERENCE, _p.as_dict(p), lambda: compute(p),
                  {"IndentationResult": IndentationResult}, use_cache=use_cache)
