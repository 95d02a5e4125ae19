"""Linear layer: a node-adding ``static-state`` treatment in one module, written against
pdverify's family protocol (:class:`pdverify.corrections.protocols.StaticAssembly`).

It adds one horizon of fictitious nodes around the box and one surface-node unknown per
boundary cell face. A fictitious node f takes the displacement of the lattice
extrapolation from its nearest real node j (j = f's cell index clipped into the body)
through the surface nodes of j's own boundary faces: with ``r_a`` the number of cells f
lies outside along axis a and ``s_a`` the surface node on j's face across axis a,

    u_f = u_j + sum_a 2 |r_a| (u_{s_a} - u_j)        (``linear``)
    u_f = u_j + sum_a (u_{s_a} - u_j)                (``constant`` beyond the surface)

(s_a sits h/2 from j, f sits |r_a| h beyond j, so ``2 |r_a| (u_{s_a} - u_j)`` is the
linear step; summed over the axes it is exact for every affine field, corners
included; ``constant`` carries each surface value outwards unchanged). Dilatations copy the nearest real node's (exact for affine fields, whose
dilatation is constant). The surface nodes carry the boundary conditions and the
force-flux rows (seed 001 Eq. 36) through pdverify's public
``impose_on_surface_nodes``.

What the theory says: ``linear`` with complete neighbourhoods, an affine field is
reproduced to round-off wherever the discrete material has the continuum moduli
(moment-corrected weights); ``constant`` is not exact for any field with a gradient
normal to a face.
"""
from __future__ import annotations

from typing import Any, Mapping

import numpy as np
import scipy.sparse as sp

from pdverify.corrections.surface_nodes import crossing_bonds, impose_on_surface_nodes
from pdverify.corrections.treatment import Treatment
from pdverify.errors import InputError
from pdverify.params import Param
from pdverify.pd.closure import Closure, real_identity, with_rows
from pdverify.pd.problem import LinearSystem, StaticProblem

#: the extrapolations (the parameter is not called ``order``: a scene's treatment defaults
#: may set a parameter of that name, e.g. surface nodes' order 3 on body3d-manufactured)
EXTRAPOLATIONS = ("constant", "linear")


def layer_rows(grid, extrapolation: str):
    """``(fict, U, T)``: the fictitious nodes, the rows of their displacements over
    [real nodes, surface nodes] and of their dilatations over the real nodes (module
    docstring)."""
    if extrapolation not in EXTRAPOLATIONS:
        raise ValueError(f"extrapolation {extrapolation!r} not in {EXTRAPOLATIONS}")
    ni = grid.n_interior
    fict = np.flatnonzero(~grid.is_interior)
    cells = np.asarray(grid.cells)
    idx = grid.index[fict]
    near = np.clip(idx, 0, cells - 1)
    rel = idx - near
    j = grid.interior_number[grid.ext_id(near)]
    k = np.arange(fict.size)
    T = sp.csr_matrix((np.ones(fict.size), (k, j)), shape=(fict.size, ni))
    rows, cols, vals = [k], [j], [np.ones(fict.size)]
    for axis in range(grid.dim):
        out = np.flatnonzero(rel[:, axis] != 0)
        if out.size == 0:
            continue
        face = 2 * axis + (rel[out, axis] > 0)
        s = np.empty(out.size, dtype=int)
        for f in (2 * axis, 2 * axis + 1):
            on = face == f
            s[on] = grid.surface_id(f, near[out[on]])
        step = (2.0 * np.abs(rel[out, axis]) if extrapolation == "linear"
                else np.ones(out.size))
        rows += [out, out]
        cols += [ni + s, j[out]]
        vals += [step, -step]
    U = sp.csr_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))),
                      shape=(fict.size, ni + grid.n_surface))
    return fict, U, T


def assemble(problem: StaticProblem, params: Mapping[str, Any]) -> LinearSystem:
    """The ``static-state`` system under the linear layer (module docstring)."""
    g = problem.body.grid(problem.stencil.reach)
    keep, flux = crossing_bonds(g, problem.stencil)
    fict, U, T = layer_rows(g, params["extrapolation"])
    n_unknown = g.n_interior + g.n_surface
    closure = Closure(keep=keep, weighted_volume="complete",
                      displacement_map=with_rows(real_identity(g, n_unknown), fict, U),
                      dilatation_map=with_rows(real_identity(g), fict, T),
                      n_unknown_nodes=n_unknown)
    return impose_on_surface_nodes(problem, g, closure, flux)


def check(cells, params: Mapping[str, Any], where: str) -> None:
    """The fictitious layer must be a whole number of cells (its surface nodes' flux
    rows count the bonds crossing each boundary cell face)."""
    m = params["m_ratio"]
    if abs(m - round(m)) > 1e-12:
        raise InputError(f"{where}: m_ratio={m:g} must be a whole number for linear-layer")


class LinearLayer(Treatment):
    def assemble(self, problem: StaticProblem, params: Mapping[str, Any]) -> LinearSystem:
        return assemble(problem, params)

    def check(self, cells, params: Mapping[str, Any], where: str) -> None:
        check(cells, params, where)


METHOD = LinearLayer(
    "linear-layer", "fictitious layer by per-axis linear (or constant) extrapolation from "
    "the nearest real node through its boundary faces' surface nodes; the conditions and "
    "force-flux rows on the surface nodes", "pdverify's tests (tests/plugins)",
    params=(Param("extrapolation", "linear", "the fictitious layer's extrapolation from the "
                  "surface nodes", choices=EXTRAPOLATIONS),),
    theories=("state-based",), families=("static-state",), footprint="surface",
    box_only="its surface nodes sit at the centres of boundary cell faces and its steps run "
             "along lattice axes normal to a face; a curved or cut boundary has neither")
