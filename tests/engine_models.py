"""The model wrappers the tests use: a treatment's closure and rows on the engine's model.

``StateBox`` (seed 001's boxes: uncorrected, surface nodes, a bond method or mirror
nodes), ``StatePlate`` (seed 000's clamped plate: uncorrected or Taylor fictitious nodes
with the clamp's constraint rows) and ``StateBar`` (seed 000's bars) combine a model of
``pdverify.pd.build`` with a treatment's rows, so that the tests can check a closure's
exactness and a system's pieces one by one. The report's runs assemble the same pieces
through ``pdverify.corrections.static_state``.
"""
from __future__ import annotations

import functools

import numpy as np

from pdverify.corrections.surface_nodes import flux_rows, surface_node_closure
from pdverify.corrections.taylor_fictitious import (boundary_value_rows, clamped_rows,
                                                    fictitious_closure)
from pdverify.pd import StateBasedConstants, get_influence, state_based_stencil
from pdverify.pd.build import Body, StateMaterial, build_model
from pdverify.scenes.statebar import BAR_PARAMS, bar_model
from pdverify.scenes.plate2d import ORDERING
from pdverify.solvers.front import solve_constrained, solve_with_dirichlet

#: the plate's four edges as the grid numbers them (x-, x+, y-, y+: the clamped rows'
#: argument of ``taylor_fictitious.clamped_rows``)
ALL_FACES = (0, 1, 2, 3)


class StateBox:
    """A seed-001 box on the engine: the state-based model, uncorrected or with surface nodes.

    ``order=None``: the uncorrected model (seed 001 §4, 'without the fictitious and
    surface nodes'): bonds only between interior nodes, m_i and theta_i over the
    truncated neighbourhoods (Eqs. 22-23). ``order=N``: the surface node method's closure
    (``pdverify.corrections.surface_nodes.surface_node_closure``): a fictitious layer of
    thickness delta, one surface node per boundary cell face, order-N displacement and
    order N - 1 dilatation extrapolation, m of a complete neighbourhood, and one
    force-flux equation per surface node (Eq. 36) below the interior equations in P.
    ``quadrature``: the weights beta of Eqs. (22)-(24) (``pdverify.pd.bonds``); the
    moment correction uses the state-based weight omega |xi|^2. ``closure``: a bond
    method's closure on the uncorrected grid (``order=None`` only). ``mirror(grid,
    stencil) -> MirrorNodes``: the mirror node method's fictitious layer
    (``pdverify.corrections.mirror_nodes``; ``order=None``).
    """

    def __init__(self, lengths, origin, spacing, m_ratio, constants: StateBasedConstants,
                 order: int | None = None, quadrature: str = "partial-volume",
                 influence: str = "gaussian", closure=None, mirror=None):
        inf = get_influence(influence)
        stencil = state_based_stencil(len(lengths), m_ratio, spacing, inf, quadrature)
        self.order = order
        body = Body(tuple(lengths), tuple(origin), float(spacing))
        self.grid = body.grid(stencil.reach if order is not None or mirror is not None else 0)
        closure, flux = (surface_node_closure(self.grid, stencil, order) if order is not None
                         else (closure, None))
        self.mirror = None
        #: node counts a method reports beside the size (pddo: its three subdomains)
        self.counts = {}
        if mirror is not None:
            self.mirror = mirror(self.grid, stencil)
            closure = self.mirror.closure()
        self.model = model = build_model(body, stencil, StateMaterial(constants, inf), closure,
                                         grid=self.grid)
        self.P = model.equilibrium_rows()
        if flux is not None:
            self.P = (self.P + flux_rows(model, flux)).tocsr()
        self.horizon = model.horizon
        self.n_unknown_nodes = model.n_unknown_nodes
        self.A_U_full = model.A_U_full

    @property
    def dim(self) -> int:
        return self.grid.dim

    def stiffness(self):
        return self.model.stiffness(self.P)

    def augmented(self):
        """The system with dilatations as unknowns (StateBasedModel.augmented_stiffness)."""
        return self.model.augmented_stiffness(self.P)

    def unknown_coords(self):
        """Coordinates of the augmented system's unknowns: the displacement components of
        the interior then (surface nodes) surface nodes, then the interior dilatations (and
        any further nodal scalars of the closure, e.g. PALS's second one), node-major."""
        g = self.grid
        x_int = g.x[g.interior_ids]
        nodes = np.r_[x_int, g.surface_x] if self.order is not None else x_int
        scalars = self.model.A_theta.shape[0] // len(x_int)
        return np.r_[np.tile(nodes, (self.dim, 1)), np.tile(x_int, (scalars, 1))]

    def rows_of_state(self, U_ext, Theta_ext):
        return self.model.rows_of_state(U_ext, Theta_ext, self.P)

    def dilatation_of_field(self, u_fn, points):
        return self.model.dilatation_of_field(u_fn, points)

    def size(self) -> dict:
        g = self.grid
        out = {"interior_nodes": int(g.n_interior), "bonds": int(self.model.bond_a.size),
               "dofs": int(self.dim * self.n_unknown_nodes)}
        if self.order is not None:
            out["surface_nodes"] = int(g.n_surface)
            out["fictitious_nodes"] = int(g.n_ext - g.n_interior)
        return out


class StatePlate:
    """A 2D state-based plate on the engine: cell-centred nodes on [0, l_x] x [0, l_y],
    the constants of ``constants`` (energy equivalence, any influence function), weights
    beta by ``quadrature``.

    ``order=None``: the uncorrected model (truncated neighbourhoods, m_i over the bonds a
    node has, Eq. 50). ``order=n``: the fictitious layer of thickness delta around the
    plate extrapolated by ``taylor-fictitious`` (edges by 1D Taylor along the normal,
    corners by the 2D expansion of Eq. 69 to order n; dilatations to order n - 1) and the
    clamped edges as constraint rows (Eq. 58 for u and v, corner lines by ``corners``).
    ``K`` = the equilibrium rows of the real nodes (component-major, u then v).
    ``closure``: another treatment of the uncorrected model (``order=None``): a bond
    method of the registry (``energy``, ``volume``, ``pals``), clamped as ``none`` is.
    """

    def __init__(self, lengths, spacing, m_ratio, constants, influence="hyperbolic",
                 order=None, quadrature="partial-volume", thickness=1.0,
                 corners="normal-only", closure=None):
        inf = get_influence(influence)
        stencil = state_based_stencil(2, m_ratio, spacing, inf, quadrature)
        self.order = order
        if order is not None:
            closure = functools.partial(fictitious_closure, order=order)
        self.model = build_model(Body(tuple(lengths), (0.0, 0.0), float(spacing),
                                      thickness=thickness), stencil,
                                 StateMaterial(constants, inf), closure,
                                 layers=stencil.reach if order is not None else 0)
        self.grid = g = self.model.grid
        self.horizon = self.model.horizon
        self.x = g.x[g.interior_ids]
        self.K = self.model.stiffness()
        if order is not None:
            self.B, self.constraint_points, self.constraint_components = clamped_rows(
                g, order, ALL_FACES, corners)

    def ring(self) -> np.ndarray:
        """Real-node numbers of the nodes nearest the boundary (the outermost ring)."""
        idx = self.grid.index[self.grid.interior_ids]
        last = np.asarray(self.grid.nodes_per_axis) - 1
        return np.flatnonzero(np.any((idx == 0) | (idx == last), axis=1))

    def rows_of_state(self, u_fn) -> np.ndarray:
        """K u for the exact field ``u_fn`` at every node (fictitious included), dilatations
        of complete neighbourhoods: the discrete operator applied to the field itself."""
        m, g = self.model, self.grid
        return m.rows_of_state(u_fn(g.x), m.dilatation_of_field(u_fn, g.x))

    def solve(self, f, boundary_values=None, ring_values=None, where="plate"):
        """u (n_real, 2) with K u = f: constraint rows = ``boundary_values`` (default 0) with
        Lagrange multipliers (corrected), or the ring nodes fixed at ``ring_values``
        (n_ring, 2; default 0) by elimination (uncorrected)."""
        n = self.grid.n_interior
        if self.order is not None:
            c = np.zeros(self.B.shape[0]) if boundary_values is None else boundary_values
            u, _, info = solve_constrained(self.K, f, self.B, c, where=where, ordering=ORDERING)
            info["constraints"] = int(self.B.shape[0])
        else:
            ring = self.ring()
            vals = np.zeros((ring.size, 2)) if ring_values is None else ring_values
            fixed = np.r_[ring, n + ring]
            u, info = solve_with_dirichlet(self.K, f, fixed, vals.T.ravel(), where,
                                           ordering=ORDERING)
            info["constraints"] = int(fixed.size)
        return u.reshape(2, n).T, info

    def size(self) -> dict:
        g = self.grid
        out = {"real_nodes": int(g.n_interior), "bonds": int(self.model.bond_a.size),
               "dofs": int(2 * g.n_interior), "stiffness_nnz": int(self.K.nnz)}
        if self.order is not None:
            out["fictitious_nodes"] = int(g.n_ext - g.n_interior)
            out["constraints"] = int(self.B.shape[0])
        return out


class StateBar:
    """A seed-000 bar on the engine: real nodes at cell centres x_i = (i - 1/2) Delta
    (Fig. 10), the 1D state-based model with ``influence`` (seed 000: hyperbolic), and
    with ``order`` the fictitious layers of ``taylor-fictitious`` (else the uncorrected
    model: truncated neighbourhoods, m_i from Eq. (50) over real neighbours).

    ``K`` = -S K_b (Eq. 55) over the real displacements; K_b (the bond forces, D6) is
    multiplied out once: in 1D it is banded, and both K and the section-force rows of
    Eq. (60) need it. ``closure``: a bond method's closure on the uncorrected bar.
    """

    def __init__(self, p: dict, order: int | None = None, closure=None):
        p = {**{q.name: q.default for q in BAR_PARAMS}, **p}  # unset keys: the paper's values
        if order:
            closure = functools.partial(fictitious_closure, order=order)
        self.order = order
        self.model = bar_model(p, closure, fictitious=bool(order))
        self.grid = g = self.model.grid
        self.K_b = self.model.bond_force_matrix()
        self.K = (self.model.equilibrium_rows() @ self.K_b).tocsr()
        self.x_real = g.x[g.interior_ids, 0]
        self.horizon = self.model.horizon
        self.length = p["length"]

    def boundary_value_row(self, side: str) -> np.ndarray:
        """Row r with r @ u = u at the end ``side`` by Taylor extrapolation (Eq. 58)."""
        face = 0 if side == "left" else 1
        return boundary_value_rows(self.grid, self.order, face)[0].toarray()[0]

    def flux_rows(self, planes):
        """Rows r with r @ u = A * tau(x_p, +1) at each plane (force through the section,
        Eq. 60): the summed force of the bonds crossing it."""
        return (self.model.crossing_selector(planes) @ self.K_b).tocsr()

    def size(self) -> dict:
        return {"nodes": int(self.grid.n_ext), "real_nodes": int(self.grid.n_interior),
                "dofs": int(self.grid.n_interior), "bonds": int(self.model.bond_a.size)}
