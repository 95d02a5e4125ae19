"""A scene's uncorrected node set (:class:`NodeSet`: the real nodes of its ``none``
system with their volumes, loads and prescribed components; the system of a state-based
treatment, or a bond-based scene's own :class:`~pdverify.pd.problem.BondSystem`) and
what pdverify checks of a displacement field given on it by another code: the unknowns
it stands for (:func:`solution_vector`), its equilibrium in the scene's linear model
(:func:`equilibrium`, :func:`balance`), and the horizon that keeps exactly the model's
bonds for a code that tests |xi|^2 <= delta^2 (:func:`between_shells`). Used by
``export``/``score`` (:mod:`pdverify.exchange`) and the peer codes
(:mod:`pdverify.peers`); it imports no scene, so the treatments may use it. No printing.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .errors import InputError


@dataclass
class NodeSet:
    """The ``none`` problem of a scene as arrays (module docstring). ``fixed``: per
    component k, ``(nodes, values)`` of its prescribed nodes (0-based, ascending)."""

    scene: object
    params: dict
    problem: object
    system: object
    x: np.ndarray          # (n, d) positions [m]
    volume: np.ndarray     # (n,) node volumes [m^3] (thickness or cross-section included)
    forces: np.ndarray     # (n, d) nodal forces [N]
    fixed: dict            # k -> (nodes, values [m])

    @property
    def dim(self) -> int:
        return self.x.shape[1]

    @property
    def spacing(self) -> float:
        return float(self.problem.spacing)

    @property
    def horizon(self) -> float:
        """The model's horizon m h [m] (its influence function's delta)."""
        return float(self.system.model.horizon)

    @property
    def theory(self) -> str:
        """``bond-based`` (a :class:`~pdverify.pd.problem.BondProblem`) or ``state-based``."""
        from .pd.problem import BondProblem
        return "bond-based" if isinstance(self.problem, BondProblem) else "state-based"

    @property
    def bond_offsets(self) -> tuple[np.ndarray, np.ndarray]:
        """``(offsets, beta)``: the model's bond offsets of a full neighbourhood (integer,
        in spacings, both signs) and their weights beta. State-based: its stencil's. A
        bond-based model's bonds are its half offsets whose weight omega beta is not zero
        (:class:`~pdverify.pd.bondbased.BondBasedModel`: the tip of a conical
        micromodulus at integer m carries no bond), with their negatives."""
        model = self.system.model
        if self.theory == "bond-based":
            off = np.asarray(model.offsets)
            return np.r_[off, -off], np.r_[model.beta_k, model.beta_k]
        return np.asarray(model.stencil.offsets), np.asarray(model.stencil.beta)


def node_set_of(scene, p, problem, system) -> NodeSet:
    """The arrays of an uncorrected ``system`` of ``problem`` (any body the family's
    ``none`` assembles: a box, or a shape with cut volumes; or a bond-based scene's
    :class:`~pdverify.pd.problem.BondSystem`, every grid node real). Each component's
    prescribed nodes in ascending order."""
    g = system.model.grid
    ni, nu_, d = g.n_interior, system.n_unknown_nodes, g.dim
    if nu_ != ni or system.B is not None or system.offset is not None:
        raise InputError(f"{scene.id}: its uncorrected system has unknowns or rows beyond "
                         "the real nodes, which a node set cannot state; it is not exported")
    x = g.x[g.interior_ids]
    volume = np.asarray(system.model.node_volume)[g.interior_ids]
    forces = np.asarray(system.rhs[:d * nu_]).reshape(d, nu_).T
    fixed = {}
    comp, nodes = np.divmod(np.asarray(system.fixed), nu_)
    for k in range(d):
        on = np.flatnonzero(comp == k)
        if on.size:
            on = on[np.argsort(nodes[on], kind="stable")]
            fixed[k] = (nodes[on], np.asarray(system.values)[on])
    return NodeSet(scene, p, problem, system, x, volume, forces, fixed)


def _lattice_k2(dim: int, reach: int) -> np.ndarray:
    """|k|^2 of every integer offset k with |k_i| <= reach (0 included)."""
    axes = np.arange(-reach, reach + 1, dtype=np.int64)
    k = np.stack(np.meshgrid(*([axes] * dim), indexing="ij"), axis=-1).reshape(-1, dim)
    return np.sum(k * k, axis=1)


def written_horizon(ns: NodeSet) -> float:
    """The horizon another code is given for ``ns`` [m]: :func:`between_shells` of the
    model's bond offsets, so that its |xi|^2 <= delta^2 keeps exactly the model's bonds
    (the export's decks and the peer codes' alike)."""
    return between_shells(ns.spacing, ns.bond_offsets[0], ns.dim)


def between_shells(spacing: float, offsets, dim: int) -> float:
    """``h sqrt((K + K_next) / 2)`` of bond ``offsets`` (integer, in spacings) on the
    ``dim``-D lattice (:func:`export_horizon`)."""
    off = np.asarray(offsets, dtype=np.int64)
    k2_max = int(np.max(np.sum(off * off, axis=1)))
    lattice = _lattice_k2(dim, math.isqrt(k2_max) + 1)
    return spacing * math.sqrt(0.5 * (k2_max + int(lattice[lattice > k2_max].min())))


# ------------------------------------------------------------------------------ equilibrium
#: A field counts as an equilibrium of the scene's linear model when its distance to that
#: model's solution (relative L2 over the real nodes: the displacement its residual would
#: still move, K^-1 r) is at most this many times the field's largest relative bond
#: displacement |u_b - u_a| / |xi| (its strains and rotations). A geometrically nonlinear
#: code's exact equilibrium (LAMMPS's PERI bonds act along the deformed bond, with the
#: current length) differs from the linear one by O(displacement gradient): measured on the
#: peer runs, a third of it (body3d-traction: 2.4e-5 at a gradient of 7.4e-5; plate-l's
#: re-entrant corner: 5.0e-3 at 1.8e-2). A solver stopped early or bonds lost
#: leave distances of 1e-2 to 1. The relative residual ||(K u - f)_free|| / ||f_free|| is
#: recorded beside it but does not decide: normalised by the applied loads it grows where
#: the bond forces are large against them (0.2 at plate-l's corner for that 0.5 % field).
DISTANCE_PER_GRADIENT = 10.0
#: ... and at least this: the forward error of the scenes' own solvers against a direct
#: solve (their single-precision factors refined in double reach 1.3e-7 on
#: plate2d-plane-strain; tests/pdverify/test_export_score.py)
DISTANCE_FLOOR = 1e-6


def solution_vector(system, U: np.ndarray) -> np.ndarray:
    """The unknowns of an uncorrected ``system`` holding the displacements ``U`` (n, d) of
    its real nodes: component-major; for the augmented system (solver=nested-dissection)
    followed by its nodal scalars (dilatations) from the displacements, theta = A_theta
    A_e A_U u, so that K x - rhs (a reaction) is the direct system's (the displacement
    metrics do not read them)."""
    d = np.shape(U)[1]
    x = np.asarray(U, dtype=float).T.ravel()
    if system.K.shape[0] > x.size:
        model = system.model
        x = np.r_[x, model.A_theta @ (model.A_e @ (model.A_U_full @ x))]
    assert x.size == system.K.shape[0] or d == 0
    return x


def equilibrium(ns: NodeSet, U: np.ndarray, u_linear: np.ndarray | None = None) -> dict:
    """How far the displacements ``U`` (n, d) of the node set are from an equilibrium of
    its linear model (state-based or bond-based): ``distance`` to the linear solution
    ``u_linear`` (n, d; solved here when not given), ``residual`` (:func:`balance`),
    ``max_gradient``, ``limit`` and ``in_equilibrium`` (module constants above)."""
    system = ns.system
    d, n = ns.dim, len(ns.x)
    xa = solution_vector(system, U)
    model = system.model

    def extend(x):       # the augmented form's dilatations of a displacement vector
        if system.K.shape[0] == x.size:
            return x
        return np.r_[x, model.A_theta @ (model.A_e @ (model.A_U_full @ x))]

    motion = bond_gradients(model, xa[:d * n])
    gradient = float(np.max(motion)) if motion.size else 0.0
    if u_linear is None:
        u_linear = linear_solution(system, n, d)
    ref = float(np.linalg.norm(u_linear))
    gap = float(np.linalg.norm(np.asarray(U, dtype=float) - u_linear))
    distance = gap / ref if ref > 0 else gap
    limit = max(DISTANCE_PER_GRADIENT * gradient, DISTANCE_FLOOR)
    return {"distance": distance,
            "residual": balance(system.K, xa, system.rhs, system.fixed, system.values,
                                d * n, extend),
            "max_gradient": gradient, "limit": limit,
            "in_equilibrium": bool(np.isfinite(distance) and distance <= limit)}


def linear_solution(system, n: int, d: int) -> np.ndarray:
    """(n, d) displacements of the real nodes solving ``system`` (K, rhs, its prescribed
    ``fixed`` unknowns at ``values``): condensed and factored by SuperLU."""
    import scipy.sparse.linalg as spla
    from .solvers.condense import condense
    K_ff, f_f, expand = condense(system.K, np.asarray(system.rhs, dtype=float),
                                 np.asarray(system.fixed, dtype=int),
                                 np.asarray(system.values, dtype=float))
    x = expand(spla.spsolve(K_ff.tocsc(), f_f))
    return np.asarray(x[:d * n]).reshape(d, n).T


def bond_gradients(model, u) -> np.ndarray:
    """|u_b - u_a| / |xi| of every bond of ``model`` for the real nodes' displacements
    ``u`` (component-major): the displacement gradient along the bond, stretch and
    rotation both."""
    from .pd.bondbased import BondBasedModel
    full = (model.displacement_map() if isinstance(model, BondBasedModel)
            else model.A_U_full) @ np.asarray(u, dtype=float)
    U = full.reshape(model.grid.dim, -1)
    return np.linalg.norm(U[:, model.bond_b] - U[:, model.bond_a], axis=0) / model.bond_x


def balance(K, x, rhs, fixed, values, rows: int, extend=None) -> float:
    """The relative residual ||(K x - f)_free|| / scale over the first ``rows`` equations
    less the prescribed unknowns ``fixed`` (the scale is the larger of the free loads'
    norm and the free reactions of the prescribed ``values``, so a displacement-driven
    scene has a scale too). ``extend`` completes a displacement vector to all unknowns
    (the augmented forms' nodal scalars)."""
    extend = extend or (lambda v: v)
    free = np.ones(rows, dtype=bool)
    fixed = np.asarray(fixed, dtype=int)
    free[fixed[fixed < rows]] = False
    f = np.asarray(rhs, dtype=float)[:rows]
    r = (K @ x)[:rows] - f
    prescribed = np.zeros(rows)
    prescribed[fixed] = np.asarray(values, dtype=float)
    drive = (K @ extend(prescribed))[:rows]
    scale = max(float(np.linalg.norm(f[free])), float(np.linalg.norm(drive[free])))
    norm = float(np.linalg.norm(r[free]))
    return norm / scale if scale > 0 else norm


def not_in_equilibrium(balance: dict) -> str:
    """The message of a field that is not an equilibrium of the linear model."""
    return (f"not in equilibrium: {balance['distance']:.3g} (relative L2) from the scene's "
            f"linear solution, above {balance['limit']:.3g} ({DISTANCE_PER_GRADIENT:g} x the "
            f"field's largest relative bond displacement {balance['max_gradient']:.3g}); "
            f"relative residual {balance['residual']:.3g} of the free equations: a solver "
            "stopped early, lost bonds, or another model or other conditions than the "
            "export's")
