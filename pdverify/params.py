"""Typed, range-checked parameters for scenes and methods (the --set KEY=VALUE layer)."""
from __future__ import annotations

import math
import re
from dataclasses import dataclass
from typing import Any, Callable, Mapping

from .errors import InputError, did_you_mean

Check = Callable[[Any], "str | None"]
#: what an integer parameter may be written as: decimal digits, an optional fraction that is
#: zero and an exponent (200, 2e2, 200.0); not 0x2, 0b10, 1_000
_DECIMAL = re.compile(r"[+-]?(\d+\.?\d*|\.\d+)([eE][+-]?\d+)?")
#: a unit in a parameter's doc: ``[m]``, ``[Pa]``, ``[kg/m^3]``, ``[N/m^4]``
_UNIT = re.compile(r"\[([A-Za-z][A-Za-z0-9^/*. -]{0,15})\]")


@dataclass(frozen=True)
class Param:
    """One named parameter with its default (the paper's value), type and check.

    ``check`` returns ``None`` when a value is allowed, else a short phrase such as
    ``"must be > 0"``; ``choices`` restricts string or numeric values to a set.
    ``scene_default``: a scene may set this parameter's default (its
    ``treatment_defaults``, by name); a parameter that does not declare it keeps its own
    default on every scene, whatever the scene's defaults of other parameters of the same
    name.
    """

    name: str
    default: Any
    doc: str = ""
    check: Check | None = None
    choices: tuple | None = None
    scene_default: bool = False

    @property
    def kind(self) -> type:
        return type(self.default)

    @property
    def unit(self) -> str:
        """The physical unit the declaration names in its ``doc`` (its first ``[...]``,
        e.g. ``"Pa"`` for ``"Young's modulus [Pa]"``); ``""`` for a dimensionless or
        non-numeric parameter."""
        if self.kind not in (int, float):
            return ""
        found = _UNIT.search(self.doc)
        return found.group(1) if found else ""

    def convert(self, raw: Any, where: str) -> Any:
        kind = self.kind
        if isinstance(raw, str) and kind is not str and not raw.isascii():
            # float() accepts full-width and other Unicode digits ('０.３'): refuse them, a
            # value must read the same to the user and to the program
            raise InputError(f"{where}: {self.name}={raw!r} must be written with ASCII "
                             f"characters (a {kind.__name__})")
        try:
            if isinstance(raw, str):
                if kind is bool:
                    low = raw.strip().lower()
                    if low not in ("true", "false", "1", "0", "yes", "no"):
                        raise ValueError(raw)
                    value = low in ("true", "1", "yes")
                elif kind is int:
                    if not _DECIMAL.fullmatch(raw.strip()):   # 0x2, 1_000, 0b1, "two"
                        raise InputError(f"{where}: {self.name}={raw!r} is not a decimal "
                                         "integer (digits, optionally with an exponent: "
                                         "200, 2e2)")
                    as_float = float(raw)
                    if as_float != int(as_float):
                        raise InputError(f"{where}: {self.name}={raw!r} is not a whole number")
                    value = int(as_float)
                else:
                    value = kind(raw)
            elif kind is float and isinstance(raw, (int, float)) and not isinstance(raw, bool):
                value = float(raw)
            elif kind is int and isinstance(raw, float) and raw == int(raw):
                value = int(raw)
            else:
                value = raw
            if not isinstance(value, kind):
                raise ValueError(raw)
        except InputError:
            raise
        except OverflowError:
            raise InputError(f"{where}: {self.name}={raw!r} is out of range for "
                             + ("an integer" if kind is int else f"a {kind.__name__}")) from None
        except (TypeError, ValueError):
            raise InputError(f"{where}: {self.name}={raw!r} is not a valid {kind.__name__}"
                             ) from None
        if kind is float and not math.isfinite(value):  # NaN, inf, and overflow such as 1e400
            raise InputError(f"{where}: {self.name}={raw!r} must be a finite number")
        if self.choices is not None and value not in self.choices:
            allowed = ", ".join(str(c) for c in self.choices)
            hint = did_you_mean(raw, self.choices) if isinstance(raw, str) else ""
            raise InputError(f"{where}: {self.name}={raw!r} is not allowed{hint}; "
                             f"allowed: {allowed}")
        if self.check is not None:
            problem = self.check(value)
            if problem:
                raise InputError(f"{where}: {self.name}={raw!r} {problem}")
        return value


#: the magnitudes a positive physical parameter may take: from the smallest normal double
#: (a subnormal such as 5e-324 keeps a few digits or none, and what it scales underflows to
#: zero) to 1e300 (a product with any factor above ~1.8e8 overflows). Linear problems
#: scaled by 1e+-300 give the default metrics (tests/reliability/test_hard_numerics.py).
POSITIVE_RANGE = (2.2250738585072014e-308, 1e300)


def positive(value) -> str | None:
    lo, hi = POSITIVE_RANGE
    if not value > 0:
        return "must be a finite number > 0"
    if not lo <= value <= hi:
        return (f"must lie in {lo:.3g}..{hi:g} (from the smallest normal double: a "
                "subnormal keeps too few digits; to 1e300: products of it overflow)")
    return None


def magnitude(value) -> str | None:
    """Any sign, zero included, but no magnitude outside :data:`POSITIVE_RANGE`."""
    lo, hi = POSITIVE_RANGE
    if value == 0 or lo <= abs(value) <= hi:
        return None
    return (f"must be 0 or of magnitude {lo:.3g}..{hi:g} (from the smallest normal double: "
            "a subnormal keeps too few digits; to 1e300: products of it overflow)")


def at_least(bound) -> Check:
    def check(value):
        return None if value >= bound else f"must be >= {bound}"
    return check


def open_interval(lo, hi) -> Check:
    def check(value):
        return None if lo < value < hi else f"must be in ({lo}, {hi})"
    return check


# -- the shared parameter sets: each name declared once, with the scene's defaults -----
# Every scene states its material and its grid with these (issue 51): one name, one unit,
# one check per quantity; a scene passes its paper's defaults and, where its paper says
# more (a table, a node count), a ``note`` appended to the shared help text. The grid's
# names are the papers' and the command line's; the scenes translate them to one
# (h, delta) in metres in ``Scene.discretisation``.

def _doc(text: str, note: str) -> str:
    return f"{text} ({note})" if note else text


def youngs_modulus(default: float, note: str = "") -> Param:
    return Param("E", default, _doc("Young's modulus [Pa]", note), positive)


def poisson_ratio(default: float = 0.3, note: str = "") -> Param:
    return Param("nu", default, _doc("Poisson's ratio", note), open_interval(-1.0, 0.5))


def material_params(E: float, nu: float | None = None, note: str = "") -> tuple[Param, ...]:
    """``E`` [Pa] and, where the scene's model has one, Poisson's ratio ``nu``."""
    return (youngs_modulus(E, note),) + (() if nu is None else (poisson_ratio(nu),))


def spacing_param(default: float, note: str = "") -> Param:
    return Param("spacing", default, _doc("grid spacing Delta [m]", note), positive)


def horizon_param(default: float, note: str = "") -> Param:
    return Param("horizon", default, _doc("horizon delta [m]", note), positive)


def m_ratio_param(default: float, least: float = 1.0, note: str = "") -> Param:
    """The m-ratio delta / Delta; ``least``: the smallest the scene's grid takes (its
    type as the scene's check reports it: ``>= 1`` for an integer ratio)."""
    return Param("m_ratio", default, _doc("m-ratio delta / Delta (horizon / spacing)", note),
                 at_least(least))


def grid_params(spacing: float, m_ratio: float, least_m: float = 1.0,
                note: str = "") -> tuple[Param, ...]:
    """A grid stated as ``spacing`` and ``m_ratio`` (delta = m_ratio x spacing), the most
    common spelling; the others combine :func:`spacing_param`, :func:`horizon_param` and
    :func:`m_ratio_param`."""
    return spacing_param(spacing, note), m_ratio_param(m_ratio, least_m)


def resolve(specs: tuple[Param, ...], overrides: Mapping[str, Any], where: str) -> dict:
    """Defaults of ``specs`` updated with converted, checked ``overrides``.

    Unknown keys raise :class:`InputError` listing the allowed ones.
    """
    by_name = {p.name: p for p in specs}
    unknown = [k for k in overrides if k not in by_name]
    if unknown:
        allowed = ", ".join(sorted(by_name)) or "(none)"
        raise InputError(f"{where}: unknown key {unknown[0]!r}"
                         f"{did_you_mean(unknown[0], by_name)}; allowed: {allowed}")
    values = {p.name: p.default for p in specs}
    for key, raw in overrides.items():
        values[key] = by_name[key].convert(raw, where)
    return values


def parse_assignments(items) -> dict:
    """Parse ``KEY=VALUE`` strings (from ``--set``) into a dict of raw strings."""
    out = {}
    for item in items or ():
        key, sep, value = item.partition("=")
        key = key.strip()
        if not sep or not key:
            raise InputError(f"--set {item!r}: expected KEY=VALUE")
        if key in out:
            raise InputError(f"--set {item!r}: key {key!r} given twice")
        out[key] = value.strip()
    return out
