"""The engine's side of the correction contract: what a boundary treatment hands a model."""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Callable

import numpy as np
import scipy.sparse as sp

#: How the weighted volume m of a node is computed: ``truncated`` = over the bonds the
#: node has (seed 000, Eq. 50; seed 001, Eq. 22), ``complete`` = m of a complete
#: neighbourhood at every node (the fictitious layer completes it; seed 000 §4,
#: seed 001 §3.2).
WEIGHTED_VOLUMES = ("truncated", "complete")


@dataclass
class Closure:
    """How a boundary treatment closes the PD equations near the surface.

    Every field has the default of the uncorrected model, so ``Closure()`` is the method
    ``none`` (truncated neighbourhoods, no extra nodes or rows). A correction in
    ``pdverify.corrections`` fills in what it changes:

    - ``keep``: which stencil pairs of the (extended) grid are bonds, as a mask over
      ``bond_pairs(grid.ext_shape, stencil.half_offsets)`` or a function ``keep(a, b)``
      returning one; default: pairs with at least one real node (and, on a shape's
      grid, no void node: ``ShapeGrid.is_void``). On a shape with cracks the pairs a
      crack cuts are dropped from either (:func:`uncut`).
    - ``weighted_volume``: ``truncated`` or ``complete`` (see :data:`WEIGHTED_VOLUMES`).
    - ``displacement_map`` (n_ext x n_unknown_nodes): all node displacements from the
      unknowns, per component (identity on real nodes, extrapolation rows on fictitious
      or mirror nodes, columns for extra unknowns such as surface nodes);
      ``n_unknown_nodes`` its column count. Default: the real nodes are the unknowns.
    - ``displacement_map_full`` (d n_ext x d n_unknown_nodes, component-major): instead
      of I_d kron ``displacement_map`` when the components map differently (mirror
      nodes: odd and even reflections). State-based models only.
    - ``dilatation_map`` (n_ext x n_real): all node dilatations from the real ones
      (state-based only). Default: zero on fictitious nodes.
    - ``bond_factor(a, b, n) -> factor``: a factor on each bond's weight beta (end-bond
      or directional corrections); ``n`` the unit bond vectors. In the state-based model it
      enters the weighted volume and the dilatation as well as the force. Default: 1.
    - ``geometric_factor(model) -> factor``: ``bond_factor`` computed from the model's
      geometry (``grid``, ``bond_a``, ``bond_b``, ``bond_n``, ``horizon``,
      ``influence``) instead of given pairs, entering exactly where ``bond_factor`` does
      (seed 003's directional factor on the grid's own box). Default: 1.
    - ``weight_factor(model) -> factor``: like ``bond_factor``, computed from the model's
      bonds once they are known (``bond_a``, ``bond_b``, ``bond_n``, ``bond_x``,
      ``bond_beta``, ``node_volume``, ``stencil``), before m and the operators (the
      volume correction). Default: 1.
    - ``force_factor(model) -> factor``: a factor on each bond's force only, computed
      from the built, uncorrected model (its bond forces under a given field included);
      m and the dilatation keep their weights (the energy correction). In the
      bond-based model weight and force factors both multiply the spring stiffness.
      Default: 1.
    - ``constitutive``: replaces the LPS force state of a state-based model (PALS): an
      object with ``operators(model) -> (K_e, K_theta, A_theta, A_Theta, ke_share_a)``
      (the model's factors, built from its bonds; the nodal scalar channel may carry
      more than one value per node; ``ke_share_a`` end a's part of the diagonal K_e)
      and ``bulk_work_density(model, strain)``. Plain grids only. Default: the
      model's own (LPS).

    - ``shadow``: per-bond values at a fictitious end (issue 55: a fictitious node seen
      from two sides of a re-entrant corner), ``(pairs, displacement rows, dilatation
      rows)``: ``pairs`` (k,) indices into ``bond_pairs(grid.ext_shape,
      stencil.half_offsets)`` of kept pairs with one real and one fictitious end; that
      bond reads its fictitious end's displacement from the k-th row of the
      displacement rows (k x n_unknown_nodes) and its dilatation from the k-th row of
      the dilatation rows (k x n_real) instead of the node's rows of the maps (a
      "shadow" of the node: its position, volume and m; the node's other bonds keep
      its own value); with ``displacement_map_full`` the displacement rows are (d k x
      d n_unknown_nodes), component-major like it. A displacement or dilatation given
      per node to the model (``rows_of_state``, ``bond_end_forces``' offset) reaches a
      shadow end as its node's, unless given with the shadow ends' rows appended
      (n_ext + k rows). State-based LPS models only (no ``constitutive``). Default:
      none.

    - ``ghosts``: one-sided bonds across a crack (issue 54: Taylor's fictitious nodes on
      crack faces), ``(pairs, real_is_a, displacement rows, dilatation rows)``:
      ``pairs`` (k,) indices into ``bond_pairs(grid.ext_shape, stencil.half_offsets)``
      of pairs a crack cuts (:func:`uncut` drops them); each adds a bond from its own
      end (``real_is_a``: end a, else end b; a real node, or a fictitious one whose
      bond then has no equation at either end and counts in a face's force flux only)
      to a ghost of the other end (the node's position, volume and m), whose
      displacement is the k-th row of the displacement rows (k x n_unknown_nodes) and
      dilatation the k-th row of the dilatation rows (k x n_real). The bond acts on
      its own end only: the ghost end has no equation and the bond does not enter the
      other node's dilatation (a pair is listed twice, once from each end). The added
      bonds follow the kept ones, oriented from the own end (``bond_a``) to the
      ghost's node (``bond_b``). LPS models without ``constitutive`` or
      ``displacement_map_full`` only. Default: none.

    Flux and constraint rows are built by the correction from the model's bonds after
    construction (e.g. :meth:`StateBasedModel.bond_force_rows`). ``info``: what the
    treatment reports about itself (no effect on the model).
    """

    keep: np.ndarray | Callable[[np.ndarray, np.ndarray], np.ndarray] | None = None
    weighted_volume: str = "truncated"
    displacement_map: sp.spmatrix | None = None
    dilatation_map: sp.spmatrix | None = None
    n_unknown_nodes: int | None = None
    displacement_map_full: sp.spmatrix | None = None
    bond_factor: Callable[[np.ndarray, np.ndarray, np.ndarray], np.ndarray] | None = None
    geometric_factor: Callable[[object], np.ndarray] | None = None
    weight_factor: Callable[[object], np.ndarray] | None = None
    force_factor: Callable[[object], np.ndarray] | None = None
    constitutive: object | None = None
    shadow: tuple | None = None
    ghosts: tuple | None = None
    #: facts the treatment reports beside the run's metrics (e.g. seed 004's
    #: ``end_factors``); no effect on the model
    info: dict = field(default_factory=dict, compare=False)

    def __post_init__(self):
        if self.weighted_volume not in WEIGHTED_VOLUMES:
            raise ValueError(f"weighted_volume={self.weighted_volume!r}; allowed: "
                             f"{', '.join(WEIGHTED_VOLUMES)}")

    def bond_mask(self, grid, a, b) -> np.ndarray:
        """Which of the candidate pairs a-b are bonds (see ``keep``), less the pairs a
        crack of the grid's shape cuts (:func:`uncut`), whatever the treatment keeps."""
        if self.keep is None:
            mask = grid.is_interior[a] | grid.is_interior[b]
            void = getattr(grid, "is_void", None)   # a shape's lattice outside its layer
            return uncut(grid, a, b, mask if void is None else mask & ~void[a] & ~void[b])
        mask = self.keep(a, b) if callable(self.keep) else np.asarray(self.keep, dtype=bool)
        if mask.shape != a.shape:
            raise ValueError(f"keep: {mask.shape[0]} flags for {a.size} candidate pairs")
        return uncut(grid, a, b, mask)


def uncut(grid, a, b, mask) -> np.ndarray:
    """``mask`` over the pairs a-b without the pairs a crack cuts (``Shape.severs`` on
    the nodes' positions ``grid.x``; ``pdverify.pd.shapes`` states the conventions at the
    tip and on the crack's line). A grid without a cracked shape: ``mask`` itself."""
    shape = getattr(grid, "shape", None)
    if not getattr(shape, "cracks", ()):
        return mask
    live = np.flatnonzero(mask)
    out = np.array(mask, dtype=bool)
    out[live[shape.severs(grid.x[a[live]], grid.x[b[live]])]] = False
    return out


def real_identity(grid, n_cols: int | None = None) -> sp.csr_matrix:
    """n_ext x n_cols map that copies the real (interior) nodes and is zero elsewhere."""
    ni = grid.n_interior
    n_cols = ni if n_cols is None else n_cols
    return sp.csr_matrix((np.ones(ni), (grid.interior_ids, np.arange(ni))),
                         shape=(grid.n_ext, n_cols))


def with_rows(base: sp.csr_matrix, rows: np.ndarray, block: sp.spmatrix) -> sp.csr_matrix:
    """``base`` plus ``block`` placed on the node rows ``rows`` (extrapolation rows)."""
    block = sp.coo_matrix(block)
    extra = sp.csr_matrix((block.data, (np.asarray(rows)[block.row], block.col)),
                          shape=base.shape)
    return (base + extra).tocsr()
