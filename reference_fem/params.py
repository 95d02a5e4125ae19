"""Parameter records: frozen dataclasses built from keyword overrides with clear errors."""
from __future__ import annotations

import dataclasses
import math
import typing


def build(cls, reference: str, overrides: dict):
    """Instantiate the parameter dataclass ``cls`` from keyword overrides.

    Unknown names raise ``TypeError`` listing the allowed ones; values are coerced to the
    annotated type (so ``E=1e9`` and ``E=1000000000`` give the same cache key).
    """
    hints = typing.get_type_hints(cls)
    names = [f.name for f in dataclasses.fields(cls)]
    unknown = sorted(set(overrides) - set(names))
    if unknown:
        raise TypeError(f"{reference}: unknown parameter(s) {', '.join(unknown)}; "
                        f"allowed: {', '.join(names)}")
    kwargs = {}
    for name, value in overrides.items():
        typ = hints[name]
        try:
            if typ is bool:
                if not isinstance(value, (bool, int)):
                    raise TypeError
                kwargs[name] = bool(value)
            elif typ is int:
                if isinstance(value, float) and not value.is_integer():
                    raise TypeError
                kwargs[name] = int(value)
            elif typ is float:
                kwargs[name] = float(value)
            else:
                kwargs[name] = typ(value)
        except (TypeError, ValueError):
            raise TypeError(f"{reference}: parameter {name}={value!r} is not a valid "
                            f"{typ.__name__}") from None
    return cls(**kwargs)


def require(condition: bool, reference: str, message: str) -> None:
    """Raise ``ValueError('<reference>: <message>')`` unless ``condition``."""
    if not condition:
        raise ValueError(f"{reference}: {message}")


def positive(reference: str, **values: float) -> None:
    """Every value must be finite and > 0."""
    for name, v in values.items():
        require(math.isfinite(v) and v > 0, reference, f"{name} must be positive, got {v!r}")


def as_dict(p) -> dict:
    """Parameters as a JSON-ready dict (the cache key input and ``result.params``)."""
    return dataclasses.asdict(p)
