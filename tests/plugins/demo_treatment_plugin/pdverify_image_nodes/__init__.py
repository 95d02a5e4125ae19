"""Odd-image nodes: a boundary treatment from outside pdverify, with extra nodes and rows.

A variant of the mirror node method: every fictitious node f copies the odd image of its
reflection m through the boundary about an extra unknown, the surface node s nearest to
f: u_f = 2 u_s - u_m (the odd-image extension of a sine series, which pdverify's wave
scene uses as a reference model, generalised to boxes). The surface nodes carry the
scene's boundary conditions and their force-flux equations (extra rows), exactly as
pdverify's surface node method does; dilatations copy the nearest real node's.
Exact for fields that are linear along the normal of each face.
"""
import numpy as np
import scipy.sparse as sp

from pdverify.corrections.surface_nodes import (impose_on_surface_nodes, nearest_surface_node,
                                                surface_node_closure)
from pdverify.corrections.treatment import Treatment
from pdverify.pd import BoxGrid
from pdverify.pd.closure import Closure, real_identity, with_rows


class ImageNodes(Treatment):
    def assemble(self, problem, params):
        g = BoxGrid(problem.lengths, problem.origin, problem.spacing, problem.stencil.reach)
        base, flux = surface_node_closure(g, problem.stencil, 1)
        ni, ns = g.n_interior, g.n_surface
        fict = np.flatnonzero(~g.is_interior)
        n = np.asarray(g.nodes_per_axis)
        idx = g.index[fict]
        image = np.clip(np.where(idx < 0, -1 - idx, np.where(idx >= n, 2 * n - 1 - idx, idx)),
                        0, n - 1)
        m = g.interior_number[g.ext_id(image)]
        s = nearest_surface_node(g, fict)
        k = np.arange(fict.size)
        block = sp.csr_matrix((np.r_[np.full(fict.size, 2.0), -np.ones(fict.size)],
                               (np.r_[k, k], np.r_[ni + s, m])), shape=(fict.size, ni + ns))
        closure = Closure(keep=base.keep, weighted_volume="complete",
                          displacement_map=with_rows(real_identity(g, ni + ns), fict, block),
                          dilatation_map=base.dilatation_map, n_unknown_nodes=ni + ns)
        return impose_on_surface_nodes(problem, g, closure, flux)


METHOD = ImageNodes(
    "image-nodes", "odd images about surface-node unknowns (u_f = 2 u_s - u_m), the "
    "surface nodes' force-flux rows", "pdverify's plugin test (tests/plugins)",
    theories=("state-based",), families=("static-state",), footprint="surface")
