"""Classical-elasticity FEM references (scikit-fem); never imports pdverify."""

__version__ = "0.1.0"

from .elasticity import Material, TensorElasticity  # noqa: E402
from .field import FieldSolution  # noqa: E402
from .plate import PlateResult, clamped_plate  # noqa: E402
from .results import ReferenceResult, RefinementRow  # noqa: E402

__all__ = ["__version__", "Material", "TensorElasticity", "FieldSolution", "ReferenceResult",
           "RefinementRow", "clamped_plate", "PlateResult"]
