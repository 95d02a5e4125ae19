"""Classical-elasticity FEM references (scikit-fem); never imports pdverify.

Public API: one function per reference, each returning its converged, cached result::

    clamped_plate(**params)  -> PlateResult           seed 000 Sec. 6.2
    tension_sheet(**params)  -> TensionSheetResult    seed 003 Sec. 4.1.1
    clamped_sheet(**params)  -> ClampedSheetResult    seed 003 Sec. 4.1.2
    indentation(**params)    -> IndentationResult     seed 003 Sec. 4.2
    hole_plate(**params)     -> HolePlateResult       issue 35: plate with a hole
    l_plate(**params)        -> LPlateResult          issue 35: L-shaped bracket
    crack_plate(**params)    -> CrackPlateResult      issue 54: centre crack (mode I)
    edge_crack_plate(**params) -> CrackPlateResult    issue 54: single edge crack (SENT)
    inclined_crack(**params) -> InclinedCrackResult   issue 54: inclined centre crack
    cylinder_tension(**params) -> CylinderResult      issue 55: quarter cylinder, tension
    cavity_block(**params)   -> CavityResult          issue 55: block with a spherical cavity
    plate_pulse(**params)    -> PulseResult           issue 56: a pulse in a plate (dynamics)

Keyword arguments override the fields of the matching ``*Params`` dataclass;
``use_cache=False`` recomputes. The cache lives in ``$PDVERIFY_CACHE_DIR`` (default
``~/.cache/pdverify/reference_fem``). Helpers: :class:`Material`,
:class:`TensorElasticity` (assembly, condensation, reactions, energy), and
:class:`FieldSolution` (evaluation at points, energy density, VTU export); on the
domains that are not boxes, :class:`MeshElasticity` and :class:`MeshField` (isoparametric
9-node quadrilaterals); in 3D :class:`Solid3D` and :class:`TetField` (quadratic
tetrahedra on mapped meshes).
"""

__version__ = "0.1.0"

from .cache import cache_dir, cache_key  # noqa: E402
from .clamped_sheet import ClampedSheetParams, ClampedSheetResult, clamped_sheet  # noqa: E402
from .crack_plate import CrackPlateParams, CrackPlateResult, crack_plate, edge_crack_plate  # noqa: E402,E501
from .elasticity import Material, TensorElasticity  # noqa: E402
from .field import FieldSolution  # noqa: E402
from .hole_plate import HolePlateParams, HolePlateResult, hole_plate  # noqa: E402
from .inclined_crack import InclinedCrackParams, InclinedCrackResult, inclined_crack  # noqa: E402,E501
from .indentation import IndentationParams, IndentationResult, indentation  # noqa: E402
from .l_plate import LPlateParams, LPlateResult, l_plate  # noqa: E402
from .mesh_elasticity import MeshElasticity  # noqa: E402
from .mesh_field import MeshField  # noqa: E402
from .plate import PlateParams, PlateResult, clamped_plate  # noqa: E402
from .solid3d import Solid3D, TetField  # noqa: E402
from .solid3d_refs import (CavityParams, CavityResult, CylinderParams, CylinderResult,  # noqa: E402
                           cavity_block, cylinder_tension)
from .results import ReferenceResult, RefinementRow  # noqa: E402
from .wave_plate import PulseParams, PulseResult, plate_pulse  # noqa: E402
from .tension_sheet import TensionSheetParams, TensionSheetResult, tension_sheet  # noqa: E402

REFERENCES = {
    "plate2d-clamped": clamped_plate,
    "sheet2d-tension": tension_sheet,
    "sheet2d-clamped": clamped_sheet,
    "block2d-indentation": indentation,
    "plate-hole": hole_plate,
    "plate-l": l_plate,
    "plate-crack": crack_plate,
    "plate-edge-crack": edge_crack_plate,
    "plate-inclined-crack": inclined_crack,
    "cylinder3d-tension": cylinder_tension,
    "block3d-cavity": cavity_block,
    "plate-pulse": plate_pulse,
}

__all__ = [
    "__version__", "REFERENCES", "cache_dir", "cache_key",
    "clamped_plate", "tension_sheet", "clamped_sheet", "indentation", "hole_plate", "l_plate",
    "crack_plate", "edge_crack_plate", "inclined_crack", "cylinder_tension", "cavity_block", "plate_pulse",
    "PlateParams", "TensionSheetParams", "ClampedSheetParams", "IndentationParams",
    "HolePlateParams", "LPlateParams", "CrackPlateParams", "InclinedCrackParams",
    "CylinderParams", "CavityParams", "PulseParams",
    "PlateResult", "TensionSheetResult", "ClampedSheetResult", "IndentationResult",
    "HolePlateResult", "LPlateResult", "CrackPlateResult", "InclinedCrackResult",
    "CylinderResult", "CavityResult", "PulseResult",
    "ReferenceResult", "RefinementRow", "Material", "TensorElasticity", "FieldSolution",
    "MeshElasticity", "MeshField", "Solid3D", "TetField",
]
