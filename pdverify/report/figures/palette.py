"""One colour and marker per method across every figure of the report, from the method registry.

The built-in methods take the colours of :data:`COLOURS` and the markers of :data:`MARKERS`
in the registry's order (:func:`pdverify.corrections.registry.treatments`); a plugin method,
or any other name (``external:NAME``), takes a colour and marker from a hash of its name, so
that it keeps them whatever else is installed. Variants of one method in one figure (Taylor
orders, two spacings) share its colour and marker in shades (:func:`variant`)."""
from __future__ import annotations

import colorsys
import functools
import zlib
from dataclasses import dataclass

from matplotlib.colors import to_hex, to_rgb

#: the built-in methods' colours, in the registry's order (tab10 first, then dark shades
#: that tab10 lacks; no two alike in hue and lightness)
COLOURS = ("#d62728", "#1f77b4", "#2ca02c", "#9467bd", "#8c564b", "#e377c2", "#17becf",
           "#000000", "#ff7f0e", "#393b79", "#bcbd22", "#637939", "#843c39", "#7b4173",
           "#3182bd", "#e6550d")
#: the markers, in the same order
MARKERS = ("s", "o", "D", "^", "v", "P", "X", "*", "<", "p", ">", "h", "d", "H", "8", "o")


@dataclass(frozen=True)
class Style:
    """A method's look: ``colour`` (hex) and ``marker`` (matplotlib's code)."""
    colour: str
    marker: str


@functools.lru_cache(maxsize=1)
def _builtin_order() -> tuple[str, ...]:
    from ...corrections.registry import treatments
    return tuple(name for name, t in treatments().items()
                 if getattr(t, "origin", "built-in") == "built-in")


def style(method: str) -> Style:
    """The colour and marker of ``method`` in every figure."""
    order = _builtin_order()
    if method in order and order.index(method) < len(COLOURS):
        k = order.index(method)
        return Style(COLOURS[k], MARKERS[k])
    return _hashed(method)


def _hashed(name: str) -> Style:
    """A plugin's (or an external code's) style from its name alone: a hue from the name's
    CRC-32, at a saturation and lightness apart from the built-ins' grey and black."""
    h = zlib.crc32(name.encode("utf-8"))
    hue = (h % 360) / 360.0
    light = 0.35 + 0.1 * ((h >> 9) % 3)
    r, g, b = colorsys.hls_to_rgb(hue, light, 0.75)
    return Style(to_hex((r, g, b)), MARKERS[(h >> 12) % (len(MARKERS) - 1)])


def colour(method: str) -> str:
    return style(method).colour


def marker(method: str) -> str:
    return style(method).marker


def variant(method: str, k: int, n: int) -> str:
    """The colour of variant ``k`` of ``n`` of ``method`` in one figure (e.g. Taylor orders
    1, 2, 3): the method's colour, darker to lighter (variant 0 of 1 is the colour itself)."""
    if n <= 1:
        return colour(method)
    h, l, s = colorsys.rgb_to_hls(*to_rgb(colour(method)))
    # lightness from 0.6 l to l + 0.6 (1 - l): apart by eye, never white or black
    lo, hi = 0.6 * l, l + 0.55 * (1 - l)
    if l < 0.05:             # black (the FEM): greys
        lo, hi = 0.0, 0.6
    lk = lo + (hi - lo) * k / (n - 1)
    return to_hex(colorsys.hls_to_rgb(h, lk, s))
