"""Text read from files (plugin names and messages, the names and messages of a results
file) reaches the terminal escaped: a control character (C0, DEL, C1, a bidirectional
override) is shown as its Python escape (``\\x1b``, ``\\u202e``), so that no file can move
the cursor, clear the screen, recolour or reorder what pdverify prints (issue 50).

:func:`printable` escapes one name or message (newlines too: it stays one line);
:class:`EscapingStream` wraps a command's stdout/stderr and escapes every control
character but newline and tab in what the command prints.
"""
from __future__ import annotations

import re

#: C0 controls, DEL, C1 controls, and the bidirectional formatting characters
_CONTROL = re.compile("[\x00-\x1f\x7f-\x9f\u061c\u200e\u200f\u202a-\u202e\u2066-\u2069]")
_CONTROL_KEEP_LINES = re.compile("[\x00-\x08\x0b-\x1f\x7f-\x9f\u061c\u200e\u200f"
                                 "\u202a-\u202e\u2066-\u2069]")


def _escape(match) -> str:
    c = match.group(0)
    return f"\\x{ord(c):02x}" if ord(c) < 0x100 else f"\\u{ord(c):04x}"


def printable(text) -> str:
    """``text`` (any object: ``str`` of it) with every control character escaped."""
    return _CONTROL.sub(_escape, str(text))


class EscapingStream:
    """A text stream that escapes the control characters (but newline and tab) of what
    is written to it before ``stream`` gets it."""

    def __init__(self, stream):
        self._stream = stream

    def write(self, text):
        return self._stream.write(_CONTROL_KEEP_LINES.sub(_escape, text))

    def __getattr__(self, name):
        return getattr(self._stream, name)
