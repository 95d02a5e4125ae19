"""The ``static-state`` problem family's shared assembly: what every treatment of the
family needs to turn a :class:`~pdverify.pd.problem.StaticProblem` (a state-based box or
shape with boundary conditions keyed by face or part and component) into a
:class:`~pdverify.pd.problem.LinearSystem`, and nothing method-specific.

Each treatment's own assembly sits in its module, beside its closure:

- ``none`` and every closure treatment (bond methods): :mod:`.plain`;
- ``surface-nodes`` (seeds 001, 002): :mod:`.surface_nodes`;
- ``taylor-fictitious`` (seed 000): :mod:`.taylor_fictitious` (on a shape, with
  :mod:`.shape_fictitious`);
- ``mirror-nodes`` (seed 001 §5.2): :mod:`.mirror_nodes`;
- ``pddo`` (seed 001 §5.3): :mod:`.pddo`.

A treatment returns the system (the signature a plugin meets:
:class:`~pdverify.corrections.protocols.StaticAssembly`); the scene solves it
(``pdverify.solvers.front``) and measures it. The budget's node counts come from
:func:`footprint`.
"""
from __future__ import annotations

import math

import numpy as np
from scipy.spatial import cKDTree

from ..pd import StateBasedModel
from ..pd.build import build_model
from ..pd.problem import Face, LinearSystem


def model_of(problem, grid, closure) -> StateBasedModel:
    return build_model(problem.body, problem.stencil, problem.material, closure, grid=grid)




def unknown_coords(model, nodes):
    """Coordinates of the unknowns: d displacement components of ``nodes``, then the
    closure's nodal scalars (dilatations; PALS: two per node) of the real nodes, or of
    every node of the grid where the closure keeps one per grid node (PALS on a shape's
    lattice, whose void nodes carry decoupled scalars)."""
    g = model.grid
    x_int = g.x[g.interior_ids]
    rows = model.A_theta.shape[0]
    owners = g.x if rows % g.n_ext == 0 else x_int
    return np.r_[np.tile(nodes, (g.dim, 1)), np.tile(owners, (rows // len(owners), 1))]


def padded(rhs, K):
    return np.r_[rhs, np.zeros(K.shape[0] - rhs.size)]


def residual_reaction(system_K, rhs_of):
    """Reaction through a face from the residual R = K x - rhs of the prescribed
    unknowns on it (normal component, tension positive; ``face``: a
    :class:`~pdverify.pd.faces.Face`)."""
    def reaction(x, face, dofs_of):
        R = system_K @ x - rhs_of
        return float(face.sign * np.sum(R[dofs_of(face)]))
    return reaction


def traction_of(problem):
    """``traction(x, normal, face)`` of the mirror and PDDO modules (``face``: a
    :class:`~pdverify.pd.faces.Face` or its name): zero on free faces."""
    def traction(x, n, face):
        cond = problem.conditions.get(Face.named(face).name)
        if cond is None or cond.traction is None:
            return np.zeros_like(x)
        return cond.traction(x, n)
    return traction


def footprint(kind: str, cells, m_ratio: float):
    """``(extra unknown nodes, fictitious nodes)`` of a treatment kind on a box of
    ``cells`` (the budget's estimate)."""
    nodes = math.prod(cells)
    fictitious = math.prod(c + 2 * m_ratio for c in cells) - nodes
    if kind == "surface":
        return 2 * sum(nodes / c for c in cells), fictitious
    if kind == "fictitious":
        return 0.0, fictitious
    return 0.0, 0.0


def boundary_nodes(g, shape):
    """The boundary of a shape's grid as the uncorrected model sees it: Gauss samples
    along every part (``Shape.samples``: points, arc-length weights, outward normals,
    part) and the real node each belongs to: the node of the cell that holds the sample
    (the sample moved 1e-9 h inward, so a sample on a cell face counts for the cell
    inside), or, where that cell's centre lies outside the shape (a sliver of a cut
    cell), the nearest real node. On a box's face this is the layer of real nodes
    nearest the face, as in :func:`~pdverify.corrections.plain.assemble_plain`."""
    P, W, N, part = shape.samples(g.spacing)
    inner = P - 1e-9 * g.spacing * N
    cell = np.floor((inner - np.asarray(g.origin)) / g.spacing).astype(int)
    cell = np.clip(cell, 0, np.asarray(g.nodes_per_axis) - 1)
    node = g.interior_number[g.ext_id(cell)]
    lost = node < 0
    if np.any(lost):
        tree = cKDTree(g.lattice_x[g.interior_ids])
        node[lost] = tree.query(inner[lost])[1]
    return P, W, N, part, node


def shape_counts(g, **counts) -> dict:
    """A shape system's counts, with the jittered nodes that stayed put (if jittered)."""
    if g.jitter:
        counts["jitter_kept"] = int(g.jitter_kept)
    return counts


def eliminated(problem, model, K, rhs, fixed, values, nodes, by_face, **extra):
    """The augmented system ``K`` (``StateBasedModel.augmented_stiffness``; the solver
    layer forms what its solver needs, ``LinearSystem.scalars``) with the prescribed
    unknowns ``fixed`` (lists per condition) eliminated: the right-hand side
    (n_unknown_nodes, d) flattened component-major and padded for the nodal scalars, the
    unknowns' coordinates (``nodes``: the unknown nodes' positions) for nested
    dissection, and the reaction of each face's prescribed normal components
    (``by_face``: :class:`~pdverify.pd.faces.Face` -> their unknowns; the system's
    ``reaction`` takes the face's name), solved by ``problem.solver``."""
    fixed, values = _sorted(fixed, values)
    rhs = rhs.T.ravel()
    scalars = K.shape[0] - rhs.size
    rhs = padded(rhs, K)
    react = residual_reaction(K, rhs)
    return LinearSystem(model, K, rhs, fixed, values, model.n_unknown_nodes,
                        solver=problem.solver, coords=unknown_coords(model, nodes),
                        scalars=scalars,
                        reaction=lambda x, face: react(x, Face.named(face), by_face.__getitem__),
                        **extra)


def _sorted(fixed, values):
    """The prescribed unknowns once each, sorted: a node nearest two faces that prescribe
    the same component (a corner of a clamped plate) is listed by both, with the same
    exact value; listed twice, its column would be eliminated twice."""
    if not fixed:
        return np.zeros(0, dtype=int), np.zeros(0)
    fixed, values = np.concatenate(fixed), np.concatenate(values)
    fixed, first = np.unique(fixed, return_index=True)
    return fixed, values[first]
