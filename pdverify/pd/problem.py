"""Problems as scenes state them once: a body, its material, boundary conditions keyed by
face and component, loads, and the exact solution the errors are measured against.

A scene of the ``static-state`` family describes a :class:`StaticProblem` (a box of
cell-centred nodes, the linear state-based model, 1D to 3D) and never names a method; a
boundary treatment (``pdverify.corrections``) turns the description into a
:class:`LinearSystem` in its own way (eliminated unknowns, constraint rows, flux rows,
extra nodes), and the scene measures the solution.

Boundary conditions: ``conditions[face] = FaceCondition(prescribed=(k, ...), where=...,
traction=...)`` with faces named ``x-``, ``x+``, ``y-``, ``y+``, ``z-``, ``z+``. The
prescribed components take the exact solution's value (every scene here prescribes the
value its reference has); ``where(cells) -> mask`` restricts them to part of the face
(the boundary cells' integer indices; seed 001's edge constraints); ``traction(x,
normal) -> (n, d)`` is the applied traction (the other components; ``None``: free).
Faces not listed are traction-free. A treatment that cannot impose a condition as
stated (e.g. part of a face) says so through :meth:`StaticProblem.whole_faces`. A
treatment reads the faces as :class:`~pdverify.pd.faces.Face` values (name, axis, side,
outward sign; :meth:`StaticProblem.faces`, ``prescribed``, ``loaded``), never as numbers.

A body that is not a box (``shape``, 2D: ``pdverify.pd.shapes``) keys its conditions by
its boundary parts' names (``hole``, ``notch-x``, ...) instead of faces; a part's
condition covers the whole part.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Callable, Mapping

import numpy as np

from .build import Body, StateMaterial
from .faces import FACES, Face, box_faces, face_names


#: Gauss-Legendre points per tangential axis of a face resultant (exact to degree 5).
FACE_GAUSS = 3
#: How a boundary cell face's load is computed: the traction's resultant over the face
#: (``face-mean``, default) or its value at the face centre times the face area
#: (``centre``).
FACE_LOADS = ("face-mean", "centre")
#: Where the uncorrected model evaluates a surface load: at the loaded node itself
#: (``node``) or at the face centre on the surface (``surface``).
LOAD_POINTS = ("node", "surface")


def face_resultant(traction, centres, normals, spacing):
    """Mean of ``traction(x, n)`` over the square (2D: segment) cell face at each centre.

    A surface node represents the area A of its cell face (seed 001 §3), so the load of
    Eq. (36) is the resultant of the traction over that face: p_i A_i = int_(A_i) t dA.
    For constant or linear tractions this is the value at the centre; for the quadratic
    shear of Eq. (41) the centre value misses h^2/12 t'' and the flux equations see it.
    Tensor Gauss-Legendre with 3 points per tangential axis (exact to degree 5).
    """
    centres = np.asarray(centres, dtype=float)
    n, d = centres.shape
    axis = np.argmax(np.abs(normals), axis=1)
    t, w = np.polynomial.legendre.leggauss(FACE_GAUSS)
    t, w = 0.5 * spacing * t, 0.5 * w
    tangents = [(axis + k) % d for k in range(1, d)]
    out = np.zeros_like(centres)
    for combo in np.ndindex(*([FACE_GAUSS] * (d - 1))):
        x = centres.copy()
        weight = 1.0
        for tang, q in zip(tangents, combo):
            x[np.arange(n), tang] += t[q]
            weight *= w[q]
        out += weight * traction(x, normals)
    return out


@dataclass(frozen=True)
class ClampedBox:
    """The ``clamped-sheet`` family's description: the box ``[lower, upper]`` clamped on
    both faces normal to ``axis`` (a bond-based sheet of node ``spacing``, ``horizon``
    and ``influence``). A treatment with a role in the family (virtual nodes) returns
    ``(grid, closure, low, high)``: its grid, its closure and the nodes that carry the
    clamps below and above; the baseline and the closures keep the scene's own grid
    with nodes on the clamped faces."""

    lower: tuple
    upper: tuple
    spacing: float
    horizon: float
    influence: object
    axis: int


@dataclass(frozen=True)
class FaceCondition:
    """What one face prescribes (module docstring)."""

    prescribed: tuple[int, ...] = ()
    where: Callable[[np.ndarray], np.ndarray] | None = None
    traction: Callable[[np.ndarray, np.ndarray], np.ndarray] | None = None


@dataclass
class StaticProblem:
    """A static boundary-value problem of a state-based box (module docstring).

    ``stencil``, ``constants`` and ``influence`` build the model (the scene chooses the
    stencil's quadrature); ``thickness`` multiplies volumes and face areas (1D: the
    cross-section, 2D: 1 per unit thickness). ``body_force(x) -> (n, d)`` per unit
    volume; ``exact(x) -> (n, d)`` the reference solution (the prescribed values).
    ``face_load``/``load_point``: :data:`FACE_LOADS`, :data:`LOAD_POINTS`. ``solver``:
    ``auto``, ``direct`` or ``nested-dissection`` (``pdverify.solvers.policy``);
    ``ordering``: the direct solves' column ordering. ``where``: how messages name the run.
    """

    lengths: tuple
    origin: tuple
    spacing: float
    stencil: object
    constants: object
    influence: object
    conditions: Mapping[str, FaceCondition]
    exact: Callable[[np.ndarray], np.ndarray]
    body_force: Callable[[np.ndarray], np.ndarray] | None = None
    thickness: float = 1.0
    face_load: str = "face-mean"
    load_point: str = "surface"
    solver: str = "auto"
    #: SuperLU's column ordering of the direct solves (``permc_spec``); a scene whose
    #: systems factor faster under another states it (benchmarks/plate_solvers.py)
    ordering: str = "COLAMD"
    where: str = "static problem"
    #: m of a complete neighbourhood (``StateBasedModel``'s ``complete_m``)
    complete_m: str = "stencil"
    #: a body that is not the box (2D: ``pdverify.pd.shapes``, 3D:
    #: ``pdverify.pd.shapes3d``): ``lengths``/``origin`` are
    #: its bounding box, ``conditions`` are keyed by its boundary parts' names
    shape: object = None
    #: the real nodes' random displacement, a fraction of the spacing (shapes only)
    jitter: float = 0.0
    jitter_seed: int = 0

    def __post_init__(self):
        allowed = (face_names(len(self.lengths)) if self.shape is None
                   else self.shape.part_names)
        bad = [f for f in self.conditions if f not in allowed]
        if bad:
            raise ValueError(f"faces {bad}: allowed {allowed}")
        if self.shape is not None and any(c.where is not None
                                          for c in self.conditions.values()):
            raise ValueError("a shape's conditions cover whole parts (no 'where')")
        if self.face_load not in FACE_LOADS or self.load_point not in LOAD_POINTS:
            raise ValueError(f"face_load={self.face_load!r}, load_point={self.load_point!r}")

    @property
    def dim(self) -> int:
        return len(self.lengths)

    @property
    def body(self) -> Body:
        """The box of cell-centred nodes (``pdverify.pd.build``)."""
        return Body(tuple(self.lengths), tuple(self.origin), float(self.spacing),
                    thickness=self.thickness, shape=self.shape, jitter=self.jitter,
                    jitter_seed=self.jitter_seed)

    @property
    def material(self) -> StateMaterial:
        """The state-based material (``pdverify.pd.build``)."""
        return StateMaterial(self.constants, self.influence, self.complete_m)

    def faces(self) -> list[tuple[Face, FaceCondition]]:
        """``(face, condition)`` of every listed face (a :class:`Face`), in the faces'
        order (:data:`FACES`). A shape has no faces: its conditions are keyed by parts."""
        if self.shape is not None:
            raise ValueError(f"{self.where}: a shape's conditions are keyed by its parts "
                             f"{self.shape.part_names}, not by faces")
        return [(f, self.conditions[f.name]) for f in box_faces(self.dim)
                if f.name in self.conditions]

    def prescribed(self):
        """``[(face, component, where)]`` of every prescribed component (``face``: a
        :class:`Face`)."""
        return [(f, k, c.where) for f, c in self.faces() for k in c.prescribed]

    def loaded(self):
        """``[(face, traction)]`` of every face (a :class:`Face`) with an applied
        traction."""
        return [(f, c.traction) for f, c in self.faces() if c.traction is not None]

    def whole_faces(self) -> bool:
        """True when every prescribed component covers its whole face (a shape's
        conditions always cover their whole part)."""
        if self.shape is not None:
            return True
        return all(w is None for _, _, w in self.prescribed())

    def body_load(self, x, volume) -> np.ndarray:
        """b(x) times the node volume (zero without a body force)."""
        if self.body_force is None:
            return np.zeros((len(x), self.dim))
        return self.body_force(x) * volume

    def face_forces(self, face: Face | str, centres, normals, face_area) -> np.ndarray:
        """Force on each cell face of ``face`` (a :class:`Face` or its name) at
        ``centres``: :attr:`face_load`'s rule times the face area (and thickness)."""
        traction = self.conditions[Face.named(face).name].traction
        if self.face_load == "centre":
            t = traction(centres, normals)
        else:
            t = face_resultant(traction, centres, normals, self.spacing)
        return t * face_area * self.thickness


class _Unknowns:
    """The dimension and unknown count of a system whose ``model`` has a grid."""

    @property
    def dim(self) -> int:
        return self.model.grid.dim

    @property
    def dofs(self) -> int:
        return self.dim * self.n_unknown_nodes


@dataclass
class LinearSystem(_Unknowns):
    """What a treatment makes of a :class:`StaticProblem`.

    ``K x = rhs`` with ``x[fixed] = values`` eliminated and, if ``B`` is set, the
    constraint rows ``B x = c`` by Lagrange multipliers (seed 000 Eq. 63). Unknowns:
    ``dofs`` displacements, component-major over the ``n_unknown_nodes`` unknown nodes
    (the real nodes first, then any extra nodes such as surface nodes), then any nodal
    scalars of an augmented system. ``solver``/``coords``: the linear solver and the
    unknowns' coordinates (nested dissection). ``model``: the PD model (its grid's real
    nodes are the measured ones); ``extra_x``: positions of the extra unknown nodes
    (surface nodes), measured too when the scene asks. ``reaction(x, face)``: the normal
    force the face (its name, :data:`FACES`) transmits, tension positive, as the
    treatment defines it (the force flux through the face, or the reactions of its
    prescribed unknowns). ``counts``:
    node counts the treatment reports beside the size. ``offset``: the displacement
    ``(n_ext, d)`` of the grid's nodes that the unknowns do not carry (the mirror nodes'
    affine part); every grid node's displacement is the model's ``A_U_full`` applied to
    the unknowns plus ``offset`` (None: zero). It is the only part of a system's
    displacement map that can depend on the prescribed values.
    """

    model: object
    K: object
    rhs: np.ndarray
    fixed: np.ndarray
    values: np.ndarray
    n_unknown_nodes: int
    solver: str = "direct"
    coords: np.ndarray | None = None
    B: object | None = None
    c: np.ndarray | None = None
    extra_x: np.ndarray | None = None
    reaction: Callable[[np.ndarray, str], float] | None = None
    counts: dict = field(default_factory=dict)
    offset: np.ndarray | None = None
    #: SuperLU's column ordering when the treatment's system wants another than the
    #: scene's ``StaticProblem.ordering`` (None: the scene's)
    ordering: str | None = None
    #: the augmented form's nodal scalars (dilatations; PALS: two per node): the last
    #: ``scalars`` unknowns, whose rows say ``theta = G u`` (``[[A_uu, A_ut], [G, -I]]``,
    #: ``StateBasedModel.augmented_stiffness``) and whose ``rhs`` is zero; constraint rows
    #: ``B`` may act on them too. The solver layer's front door
    #: (:func:`pdverify.solvers.front.solve`) forms what its solver needs from it: the
    #: condensed ``K = A_uu + A_ut G`` (and ``B_u + B_t G``) for a direct LU, the
    #: augmented system as it is for nested dissection. 0: ``K`` is solved as it is.
    scalars: int = 0


    def displacements(self, x: np.ndarray) -> np.ndarray:
        """(n_unknown_nodes, d) displacements of the unknown nodes from a solution."""
        return np.asarray(x[:self.dofs]).reshape(self.dim, self.n_unknown_nodes).T


@dataclass(frozen=True)
class PartCondition:
    """What one named part of a bond-based body prescribes (:class:`BondProblem`):
    ``prescribed[k] = value`` holds component k of every node of the part at ``value``
    (eliminated unknowns); ``force(x) -> (n, d)`` the nodal forces [N] on the part's nodes
    at positions ``x`` (the scene's load sharing among them)."""

    prescribed: Mapping[int, float] = field(default_factory=dict)
    force: Callable[[np.ndarray], np.ndarray] | None = None


@dataclass(frozen=True)
class SurfaceConditions:
    """A bond-based box's conditions stated at its surface, for the treatments that
    impose them there (fictitious or surface nodes, the ``bond-box`` family): the body
    laid out cell-centred (whole cells, the surface half a spacing beyond the outermost
    nodes) and ``faces[name] = FaceCondition(prescribed=(k, ...), traction=...)`` as in
    :class:`StaticProblem` (whole faces; faces not listed are traction-free), the
    prescribed components taking ``value(x) -> (n, d)`` at the boundary points, and
    ``planes = ((axis, k), ...)``: u_k = 0 on the plane x_axis = 0 inside the body (a
    symmetry line; on a cell-centred grid the mean of the two nodes straddling it)."""

    faces: Mapping[str, FaceCondition]
    value: Callable[[np.ndarray], np.ndarray]
    planes: tuple = ()


@dataclass
class BondProblem:
    """A static bond-based problem as a scene states it once, the twin of
    :class:`StaticProblem`: the ``body`` (``pdverify.pd.build.Body``), the horizon
    ``stencil``, the ``material`` (``BondMaterial``: c and the micromodulus's shape
    ``influence``, c(xi) = c omega(|xi|)), the ``horizon`` delta [m] as the scene gives it,
    and ``conditions`` keyed by named parts: the body's faces by name (``x-``, ``x+``,
    ``y-``, ... : the nodes on that face of an ``on-surface`` body, the outermost row of
    a cell-centred one) and the scene's own sets in ``parts`` (``name: x -> mask`` over
    the grid's node positions: symmetry lines, held points). Parts not listed are free
    and unloaded. :func:`assemble_bonds` turns it into a :class:`BondSystem` under a
    treatment's closure (a bond method: the same closure serves the state-based family)
    or, where the treatment has a role in the description's ``family``, its own grid and
    clamp nodes (``clamped-sheet``: virtual nodes' buffer layers, :class:`ClampedBox`).

    ``E`` [Pa], ``nu``: the continuum moduli c was calibrated to (``nu`` the one the
    bond-based model represents); ``kind``: the plane (``plane-stress``); ``loads``,
    ``supports``: what the conditions are, as a sentence each (the export README's)."""

    body: object
    stencil: object
    material: object
    horizon: float
    conditions: Mapping[str, PartCondition]
    E: float
    nu: float
    kind: str
    parts: Mapping[str, Callable[[np.ndarray], np.ndarray]] = field(default_factory=dict)
    family: str | None = None
    loads: str = ""
    supports: str = ""
    #: the same conditions stated at the body's surface (:class:`SurfaceConditions`),
    #: for the ``bond-box`` treatments; None: the scene states them on nodes only
    surface: SurfaceConditions | None = None

    def __post_init__(self):
        faces = face_names(len(self.body.lengths))
        clash = [k for k in self.parts if k in faces]
        bad = [k for k in self.conditions if k not in faces and k not in self.parts]
        if clash or bad:
            raise ValueError(f"parts {clash + bad}: a condition names a face {faces} or a "
                             f"part {tuple(self.parts)}; a part is not named as a face")

    @property
    def spacing(self) -> float:
        return float(self.body.spacing)

    @property
    def thickness(self) -> float:
        return float(self.body.thickness)

    @property
    def influence(self):
        return self.material.influence

    @property
    def dim(self) -> int:
        return len(self.body.lengths)

    def nodes(self, name: str, grid) -> np.ndarray:
        """Node numbers of the part ``name`` on ``grid`` (a face or a scene's set)."""
        x = grid.x
        if name in self.parts:
            return np.flatnonzero(self.parts[name](x))
        face = Face.named(name)
        lo = self.body.origin[face.axis]
        bound = lo + self.body.lengths[face.axis] if face.side else lo
        if self.body.placement != "on-surface":
            bound += (-0.5 if face.side else 0.5) * self.body.spacing
        return np.flatnonzero(np.isclose(x[:, face.axis], bound))

    def clamped_box(self) -> ClampedBox:
        """The :class:`ClampedBox` of a ``clamped-sheet`` description: the body's box
        with the two faces of one axis prescribed."""
        axes = {Face.named(k).axis for k, c in self.conditions.items()
                if k in FACES and c.prescribed}
        if len(axes) != 1:
            raise ValueError(f"a clamped box prescribes the faces of one axis, not {axes}")
        lower = tuple(self.body.origin)
        upper = tuple(o + L for o, L in zip(self.body.origin, self.body.lengths))
        return ClampedBox(lower, upper, self.spacing, self.horizon, self.influence,
                          axis=axes.pop())


@dataclass
class BondSystem(_Unknowns):
    """A bond-based problem's linear system: ``model.K u = rhs`` over every node of the
    model's grid (component-major) with the unknowns ``fixed`` (component-major indices)
    prescribed at ``values``. It reads as a :class:`LinearSystem` without constraint
    rows or extra unknowns (``B``, ``offset``: None), so the node set
    (:mod:`pdverify.nodeset`) and its checks take it as they take a treatment's system;
    K is the model's, assembled on first use. ``parts``: the node numbers of every named
    part of the description on the model's grid (a treatment's own clamp nodes where
    it brought them)."""

    model: object
    rhs: np.ndarray
    fixed: np.ndarray
    values: np.ndarray
    parts: dict = field(default_factory=dict)
    B = None
    offset = None

    @property
    def K(self):
        return self.model.K

    @property
    def n_unknown_nodes(self) -> int:
        return int(self.model.grid.n_ext)


def assemble_bonds(problem: BondProblem, closure=None, own=None) -> BondSystem:
    """The :class:`BondSystem` of ``problem``: the model of its body, stencil and
    material under a bond method's ``closure`` (None: uncorrected), or under ``own`` =
    ``(grid, closure, {face: nodes})``, what a treatment's role in the description's
    family brings (its grid, closure and the nodes that carry those faces' conditions;
    the body is then laid out cell-centred). Every part's prescribed components are
    eliminated at their values, its forces added to the right-hand side."""
    from dataclasses import replace

    from .build import build_model
    from .closure import Closure
    body, grid, faces = problem.body, None, {}
    if own is not None:
        grid, closure, faces = own
        body = replace(body, placement="cell-centred", boundary_volume="partial")
    model = build_model(body, problem.stencil, problem.material,
                        Closure() if closure is None else closure, grid=grid)
    g = model.grid
    n, d = g.n_ext, g.dim
    parts = {name: (np.asarray(faces[name]) if name in faces else problem.nodes(name, g))
             for name in (*problem.conditions, *problem.parts)}
    rhs = np.zeros(d * n)
    fixed, values = [], []
    for name, cond in problem.conditions.items():
        ids = parts[name]
        if cond.force is not None:
            force = cond.force(g.x[ids])
            for k in range(d):
                rhs[k * n + ids] += force[:, k]
        for k, value in cond.prescribed.items():
            fixed.append(k * n + ids)
            values.append(np.full(ids.size, float(value)))
    fixed = np.concatenate(fixed) if fixed else np.zeros(0, dtype=int)
    values = np.concatenate(values) if values else np.zeros(0)
    return BondSystem(model, rhs, fixed, values, parts)


@dataclass
class WaveSystem:
    """A bond-based bar's explicit-dynamics system (the ``wave-bar`` family,
    :func:`assemble_wave`): the free accelerations are ``a = A u_free + A_bc u_bc``,
    ``A = -diag(1/V) K_real @ map`` multiplied out once (a banded matrix plus the few
    columns an extension adds), ``u_bc`` the prescribed end values at ``x_bc``.
    ``surface``: the ends' values sit on two surface nodes (no bonds) and every real node
    is free; else the end real nodes carry them."""

    model: object
    A: object
    A_bc: object
    free: np.ndarray
    x_bc: np.ndarray
    surface: bool
    n_real: int

    @property
    def spacing(self) -> float:
        return float(self.model.spacing)

    @property
    def x_lattice(self) -> np.ndarray:
        return self.model.grid.x[:, 0]

    @property
    def n_fict(self) -> int:
        return int(self.model.grid.layers)

    @property
    def x_real(self) -> np.ndarray:
        return self.x_lattice[self.n_fict:self.n_fict + self.n_real]

    @property
    def x_free(self) -> np.ndarray:
        return self.x_real[self.free]

    def real_displacements(self, u_free, u_bc=(0.0, 0.0)) -> np.ndarray:
        """All real nodes' displacements from the free ones (truncated: the end nodes get
        ``u_bc``)."""
        u_free = np.asarray(u_free, dtype=float)
        if self.surface:
            return u_free
        out = np.empty(u_free.shape[:-1] + (self.n_real,))
        out[..., self.free] = u_free
        out[..., 0], out[..., -1] = u_bc[0], u_bc[1]
        return out

    def size(self) -> dict:
        surface = 2 if self.surface else 0
        return {"nodes": int(self.n_real + 2 * self.n_fict + surface),
                "real_nodes": int(self.n_real), "fictitious_nodes": int(2 * self.n_fict),
                "dofs": int(self.free.size), "bonds": self.model.n_bonds(),
                "operator_nnz": int(self.A.nnz)}


def assemble_wave(problem: BondProblem, extension=None) -> WaveSystem:
    """The :class:`WaveSystem` of a 1D bar ``problem`` whose faces ``x-`` and ``x+`` are
    prescribed: with a treatment's ``extension`` (its ``wave-bar`` role: a function of
    the grid giving the fictitious layer's displacement map from the real nodes and two
    surface nodes at the ends, which carry the prescribed values), else truncated
    neighbourhoods with the end real nodes held."""
    import scipy.sparse as sp

    from .build import build_model
    from .closure import Closure
    surface = extension is not None
    closure = ((lambda g: Closure(displacement_map=extension(g),
                                  n_unknown_nodes=g.n_interior + 2)) if surface else None)
    model = build_model(problem.body, problem.stencil, problem.material, closure,
                        layers=problem.stencil.reach if surface else 0)
    grid = model.grid
    nr = int(grid.n_interior)
    full = (sp.diags(-1.0 / model.node_volume[grid.interior_ids]) @ model.reduced()).tocsc()
    if surface:
        free = np.arange(nr)
        origin, length = problem.body.origin[0], problem.body.lengths[0]
        x_bc = np.array([origin, origin + length])
        A, A_bc = full[:, :nr].tocsr(), full[:, nr:].tocsr()
    else:
        fixed = np.r_[problem.nodes("x-", grid), problem.nodes("x+", grid)]  # no layers
        free = np.setdiff1d(np.arange(nr), fixed)
        x_bc = grid.x[grid.interior_ids][fixed, 0]
        rows = full.tocsr()[free].tocsc()
        A, A_bc = rows[:, free].tocsr(), rows[:, fixed].tocsr()
    A.sort_indices()
    return WaveSystem(model, A, A_bc, free, x_bc, surface, nr)
