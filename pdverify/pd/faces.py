"""The faces of a box, by name: ``x-``, ``x+``, ``y-``, ``y+``, ``z-``, ``z+``.

A problem keys its conditions by these names and a treatment reads a face as a
:class:`Face` (``face.axis``, ``face.side``, ``face.sign``), never as a number. The grid
stores a face as the integer ``2 * axis + side`` in its arrays (``BoxGrid.surface_face``,
``BoxGrid.faces``); :attr:`Face.code` is the one conversion between the two.
"""
from __future__ import annotations

from dataclasses import dataclass

#: every face name in the grid's order (``x-``, ``x+``, ``y-``, ...: axis, then side)
FACES = ("x-", "x+", "y-", "y+", "z-", "z+")


@dataclass(frozen=True)
class Face:
    """One face of a box: its ``name``, the ``axis`` it is normal to and its ``side``
    (0: at the lower end of the axis, 1: at the upper end)."""

    name: str
    axis: int
    side: int

    @property
    def sign(self) -> float:
        """The outward normal's component along :attr:`axis` (-1.0 or 1.0)."""
        return -1.0 if self.side == 0 else 1.0

    @property
    def code(self) -> int:
        """The grid's storage code ``2 * axis + side`` (its surface arrays only)."""
        return 2 * self.axis + self.side

    @staticmethod
    def named(name) -> Face:
        """The face called ``name`` (a :class:`Face` is returned as it is)."""
        if isinstance(name, Face):
            return name
        if name not in FACES:
            raise ValueError(f"face {name!r}: allowed {', '.join(FACES)}")
        return _BY_NAME[name]

    @staticmethod
    def at(axis: int, side: int) -> Face:
        """The face normal to ``axis`` on ``side`` (0: lower, 1: upper)."""
        return _ALL[2 * axis + side]


_ALL = tuple(Face(name, i // 2, i % 2) for i, name in enumerate(FACES))
_BY_NAME = {f.name: f for f in _ALL}


def box_faces(dim: int) -> tuple[Face, ...]:
    """The 2 ``dim`` faces of a box in ``dim`` dimensions, in the grid's order."""
    return _ALL[:2 * dim]


def face_names(dim: int) -> tuple[str, ...]:
    """The names of :func:`box_faces`."""
    return tuple(f.name for f in box_faces(dim))
