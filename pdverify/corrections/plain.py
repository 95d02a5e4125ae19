"""The uncorrected model's static assembly (``none``, and every closure treatment: a
bond method changes the model's bonds and keeps these boundary conditions): truncated
neighbourhoods; a prescribed component is imposed on the real nodes nearest its face at
the exact value there (seed 000 and seed 001 §4: the uncorrected baseline), a face's
traction as the force of each boundary cell face on the node of that cell (evaluated at
the node or on the surface: ``load_point``). On a shape, the same through the boundary's
Gauss samples (:func:`~pdverify.corrections.assembly.boundary_nodes`).
"""
from __future__ import annotations

import numpy as np

from ..pd.closure import Closure
from ..pd.problem import LinearSystem
from .assembly import boundary_nodes, eliminated, model_of, shape_counts


def assemble_plain(problem, closure: Closure | None = None) -> LinearSystem:
    """The uncorrected model (with a closure treatment's ``closure``), module docstring."""
    g = problem.body.grid(0)
    model = model_of(problem, g, closure)
    if problem.shape is not None:
        return _plain_on_shape(problem, g, model)
    d, ni, nu_ = g.dim, g.n_interior, model.n_unknown_nodes
    K = model.augmented_stiffness(model.equilibrium_rows())
    x_int = g.x[g.interior_ids]
    cells = g.index[g.interior_ids]
    rhs = np.zeros((nu_, d))
    rhs[:ni] = problem.body_load(x_int, model.node_volume[g.interior_ids][:, None])
    for face, _ in problem.loaded():
        on = cells[:, face.axis] == g.boundary_layer(face)
        xs = x_int[on].copy()
        if problem.load_point == "surface":
            xs[:, face.axis] = g.face_coordinate(face)
        nrm = np.zeros_like(xs)
        nrm[:, face.axis] = face.sign
        rhs[:ni][on] += problem.face_forces(face, xs, nrm, g.face_area)
    u_ref = problem.exact(x_int)
    fixed, values, by_face = [], [], {}
    for face, k, where in problem.prescribed():
        mask = cells[:, face.axis] == g.boundary_layer(face)
        if where is not None:
            mask &= where(cells)
        nodes = np.flatnonzero(mask)
        fixed.append(k * nu_ + nodes)
        values.append(u_ref[nodes, k])
        if k == face.axis:
            by_face[face] = k * nu_ + nodes
    return eliminated(problem, model, K, rhs, fixed, values, x_int, by_face)


def _plain_on_shape(problem, g, model) -> LinearSystem:
    """:func:`assemble_plain` on a shape (``problem.shape``): a part's prescribed
    components on the real nodes its samples belong to (:func:`boundary_nodes`), at the
    exact value at each node; a part's traction as the sum over its samples of
    t(x, n) w thickness on the node each belongs to, x the sample (``load_point=surface``)
    or the node (``node``)."""
    d, ni, nu_ = g.dim, g.n_interior, model.n_unknown_nodes
    K = model.augmented_stiffness(model.equilibrium_rows())
    x_int = g.x[g.interior_ids]
    rhs = np.zeros((nu_, d))
    rhs[:ni] = problem.body_load(x_int, model.node_volume[g.interior_ids][:, None])
    P, W, N, part, node = boundary_nodes(g, problem.shape)
    names = problem.shape.part_names
    u_ref = problem.exact(x_int)
    fixed, values = [], []
    for name, cond in problem.conditions.items():
        on = part == names.index(name)
        if cond.traction is not None:
            at = P[on] if problem.load_point == "surface" else x_int[node[on]]
            force = cond.traction(at, N[on]) * (W[on] * problem.thickness)[:, None]
            for k in range(d):
                rhs[:ni, k] += np.bincount(node[on], force[:, k], ni)
        nodes = np.unique(node[on])
        for k in cond.prescribed:
            fixed.append(k * nu_ + nodes)
            values.append(u_ref[nodes, k])
    counts = shape_counts(g, boundary_nodes=int(np.unique(node).size))
    return eliminated(problem, model, K, rhs, fixed, values, x_int, {}, counts=counts)
