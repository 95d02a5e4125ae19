"""Text listing of registered scenes, their methods and parameters (``pdverify list``)."""
from __future__ import annotations

from .corrections import describe
from .scenes import all_scenes


def _fmt(value) -> str:
    return f"{value:g}" if isinstance(value, float) else str(value)


def format_listing() -> str:
    lines = []
    for scene in all_scenes():
        lines.append(f"{scene.id}  [seed {scene.seed}; reference: {scene.reference}]  {scene.title}")
        params = ", ".join(f"{p.name}={_fmt(p.default)}" for p in scene.params)
        lines.append(f"    params: {params}")
        for m in scene.methods:
            extra = ", ".join(f"{p.name}={_fmt(p.default)}" for p in m.params)
            tag = " (default)" if m.name == scene.default_method else ""
            lines.append(f"    method {m.name}{tag}" + (f"  [{extra}]" if extra else "")
                         + (f"  - {describe(m.name)}" if describe(m.name) else ""))
    return "\n".join(lines)
