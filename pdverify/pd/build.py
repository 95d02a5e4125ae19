"""One model builder: a body, its stencil and material, and a boundary treatment's closure.

Every PD model of pdverify is built here, from a description:

- :class:`Body`: the box ``origin + [0, lengths]``, node ``spacing``, where the nodes sit
  (``placement``: cell centres or on the surface), the end cells' volumes
  (``boundary_volume``) and the ``thickness`` that multiplies volumes and face areas
  (1D: the cross-section, 2D: the thickness, 3D: 1); or a 2D or 3D ``shape``
  (``pdverify.pd.shapes``, ``pdverify.pd.shapes3d``) cut from the lattice of that box, its nodes moved by
  ``jitter`` (a fraction of the spacing, seeded: :class:`~pdverify.pd.grid.ShapeGrid`);
- the stencil (``pdverify.pd.bonds``: offsets and weights beta of one horizon);
- the material: :class:`StateMaterial` (the linear state-based model: constants of energy
  equivalence, the influence function, m of a complete neighbourhood) or
  :class:`BondMaterial` (bond-based: micromodulus and its shape);
- the closure of a boundary treatment (``pdverify.corrections``; the engine never imports
  them): ``None`` (truncated neighbourhoods), a :class:`~pdverify.pd.closure.Closure`, or
  a callable ``closure(grid) -> Closure`` of the grid the builder makes (a treatment whose
  closure depends on the grid, e.g. fictitious layers), with ``layers`` fictitious node
  layers around the body; a treatment that needs the grid before its closure builds it
  with :meth:`Body.grid` and hands it over.

The scenes describe; the treatments close; only this module calls the models'
constructors (``tests/pd/test_build.py`` checks that no other module of the package does).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Callable, Union

from .bondbased import BondBasedModel
from .bonds import Stencil
from .closure import Closure
from .grid import BoxGrid, ShapeGrid
from .influence import Influence, StateBasedConstants
from .statebased import StateBasedModel


@dataclass(frozen=True)
class Body:
    """A box of nodes, or a shape cut from one (module docstring); :meth:`grid` lays
    them out."""

    lengths: tuple
    origin: tuple
    spacing: float
    placement: str = "cell-centred"
    boundary_volume: str = "partial"
    thickness: float = 1.0
    shape: object = None
    jitter: float = 0.0
    jitter_seed: int = 0

    def grid(self, layers: int = 0) -> BoxGrid:
        """The body's nodes, extended by ``layers`` fictitious layers on every side."""
        if self.shape is not None:
            return ShapeGrid(tuple(self.lengths), tuple(self.origin), float(self.spacing),
                             layers, shape=self.shape, jitter=float(self.jitter),
                             jitter_seed=int(self.jitter_seed))
        if self.jitter:
            raise ValueError("jitter needs a shape's grid (a box: its shape's polygon)")
        return BoxGrid(tuple(self.lengths), tuple(self.origin), float(self.spacing), layers,
                       placement=self.placement, boundary_volume=self.boundary_volume)


@dataclass(frozen=True)
class StateMaterial:
    """The linear state-based material: ``constants`` (energy equivalence), the
    ``influence`` function omega and m of a complete neighbourhood (``complete_m``:
    ``stencil`` or ``continuum``, :class:`~pdverify.pd.StateBasedModel`)."""

    constants: StateBasedConstants
    influence: Influence
    complete_m: str = "stencil"


@dataclass(frozen=True)
class BondMaterial:
    """The linearised bond-based material: micromodulus ``c`` (c1 of the shape) and the
    shape ``influence`` of c(xi)."""

    micromodulus: float
    influence: Influence


ClosureOfGrid = Union[Closure, Callable[[BoxGrid], Closure], None]


def build_model(body: Body, stencil: Stencil, material: StateMaterial | BondMaterial,
                closure: ClosureOfGrid = None, *, layers: int = 0, grid: BoxGrid | None = None):
    """The model of ``body`` under ``material`` with a treatment's ``closure``.

    The body's grid has ``layers`` fictitious layers; ``grid``: that grid when a treatment
    already built it (``body.grid(layers)``, its closure needed it first). ``closure`` may
    be a callable of the grid (module docstring). The theory follows from the material.
    """
    grid = body.grid(layers) if grid is None else grid
    if callable(closure) and not isinstance(closure, Closure):
        closure = closure(grid)
    if isinstance(material, StateMaterial):
        return StateBasedModel(grid, stencil, material.constants, material.influence, closure,
                               thickness=body.thickness, complete_m=material.complete_m)
    if isinstance(material, BondMaterial):
        return BondBasedModel(grid, stencil, material.micromodulus, material.influence, closure,
                              thickness=body.thickness)
    raise TypeError(f"material {material!r}: a StateMaterial or a BondMaterial")
