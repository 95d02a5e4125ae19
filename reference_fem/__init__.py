"""Classical-elasticity FEM references (scikit-fem); never imports pdverify.

Public API: one function per reference, each returning its converged, cached result::

    clamped_plate(**params)  -> PlateResult           seed 000 Sec. 6.2
    tension_sheet(**params)  -> TensionSheetResult    seed 003 Sec. 4.1.1
    clamped_sheet(**params)  -> ClampedSheetResult    seed 003 Sec. 4.1.2
    indentation(**params)    -> IndentationResult     seed 003 Sec. 4.2

Keyword arguments override the fields of the matching ``*Params`` dataclass;
``use_cache=False`` recomputes. The cache lives in ``$PDVERIFY_CACHE_DIR`` (default
``~/.cache/pdverify/reference_fem``). Helpers: :class:`Material`,
:class:`TensorElasticity` (assembly, condensation, reactions, energy), and
:class:`FieldSolution` (evaluation at points, energy density, VTU export).
"""

__version__ = "0.1.0"

from .cache import cache_dir, cache_key  # noqa: E402
from .clamped_sheet import ClampedSheetParams, ClampedSheetResult, clamped_sheet  # noqa: E402
from .elasticity import Material, TensorElasticity  # noqa: E402
from .field import FieldSolution  # noqa: E402
from .indentation import IndentationParams, IndentationResult, indentation  # noqa: E402
from .plate import PlateParams, PlateResult, clamped_plate  # noqa: E402
from .results import ReferenceResult, RefinementRow  # noqa: E402
from .tension_sheet import TensionSheetParams, TensionSheetResult, tension_sheet  # noqa: E402

REFERENCES = {
    "plate2d-clamped": clamped_plate,
    "sheet2d-tension": tension_sheet,
    "sheet2d-clamped": clamped_sheet,
    "block2d-indentation": indentation,
}

__all__ = [
    "__version__", "REFERENCES", "cache_dir", "cache_key",
    "clamped_plate", "tension_sheet", "clamped_sheet", "indentation",
    "PlateParams", "TensionSheetParams", "ClampedSheetParams", "IndentationParams",
    "PlateResult", "TensionSheetResult", "ClampedSheetResult", "IndentationResult",
    "ReferenceResult", "RefinementRow", "Material", "TensorElasticity", "FieldSolution",
]
