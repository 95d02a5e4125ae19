"""Text listing of registered scenes, their methods and parameters (``pdverify list``)."""
from __future__ import annotations

from .corrections import describe
from .scenes import all_scenes


def _fmt(value) -> str:
    return f"{value:g}" if isinstance(value, float) else str(value)


def format_param(p) -> str:
    """``name=default``, and the allowed values of a choice param: ``plane=strain
    {strain|stress}``."""
    text = f"{p.name}={_fmt(p.default)}"
    if p.choices:
        text += " {" + "|".join(_fmt(c) for c in p.choices) + "}"
    return text


def format_listing() -> str:
    lines = []
    for scene in all_scenes():
        lines.append(f"{scene.id}  [seed {scene.seed}; reference: {scene.reference}]  {scene.title}")
        params = ", ".join(format_param(p) for p in scene.params)
        lines.append(f"    params: {params}")
        for m in scene.all_methods:
            extra = ", ".join(format_param(p) for p in m.params)
            tag = " (default)" if m.name == scene.default_method else ""
            lines.append(f"    method {m.name}{tag}" + (f"  [{extra}]" if extra else "")
                         + (f"  - {describe(m.name)}" if describe(m.name) else ""))
    return "\n".join(lines)


def method_columns(scenes) -> list[str]:
    """Every method of ``scenes`` once: ``none`` first, the corrections by name, ``fem`` last."""
    methods = []
    for scene in scenes:
        for m in scene.all_methods:
            if m.name not in methods:
                methods.append(m.name)
    return sorted(methods, key=lambda m: (m == "fem", m != "none", m))


def format_matrix() -> str:
    """Which method runs on which scene: one row a scene, one column a method (``x``
    supported; the FEM reference is ``ref``), then the bond methods' origins and any
    plugin that is unavailable or failed to load."""
    from .corrections.registry import BROKEN, bond_methods
    scenes = all_scenes()
    methods = method_columns(scenes)
    width = max(len(s.id) for s in scenes)
    head = " " * width + "  " + "  ".join(methods)
    lines = ["method x scene:", head]
    for scene in scenes:
        have = {m.name for m in scene.all_methods}
        cells = [("ref" if m == "fem" else "x") if m in have else "." for m in methods]
        lines.append(scene.id.ljust(width) + "  " + "  ".join(c.center(len(m))
                                                           for c, m in zip(cells, methods)))
    for name, bm in bond_methods().items():
        state = f"unavailable: {bm.unavailable}" if bm.unavailable else bm.origin
        lines.append(f"bond method {name}: {state}; {bm.source}")
    for name, why in BROKEN.items():
        lines.append(f"plugin {name}: failed to load ({why})")
    return "\n".join(lines)
