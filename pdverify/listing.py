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


def empty_cells(scenes=None) -> dict[tuple[str, str], list[str]]:
    """Every empty cell of the method x scene matrix, grouped: (method, reason) -> the
    scenes, in the order of :func:`~pdverify.corrections.registry.treatments`."""
    from .corrections.registry import treatments
    scenes = all_scenes() if scenes is None else scenes
    out: dict[tuple[str, str], list[str]] = {}
    for name, t in treatments().items():
        for scene in scenes:
            if name in {m.name for m in scene.all_methods}:
                continue
            out.setdefault((name, t.why_not(scene) or "not offered"), []).append(scene.id)
    return out


def format_matrix() -> str:
    """Which method runs on which scene: one row a scene, one column a method (``x``
    supported; the FEM reference is ``ref``), the count of filled cells per method, why
    each empty cell is empty, then the bond methods' origins and any plugin that is
    unavailable or failed to load."""
    from .corrections.registry import BROKEN, bond_methods
    scenes = all_scenes()
    methods = method_columns(scenes)
    width = max(len(s.id) for s in scenes)
    head = " " * width + "  " + "  ".join(methods)
    lines = ["method x scene:", head]
    count = dict.fromkeys(methods, 0)
    for scene in scenes:
        have = {m.name for m in scene.all_methods}
        for m in have:
            count[m] += 1
        cells = [("ref" if m == "fem" else "x") if m in have else "." for m in methods]
        lines.append(scene.id.ljust(width) + "  " + "  ".join(c.center(len(m))
                                                           for c, m in zip(cells, methods)))
    lines.append(f"filled cells: {sum(count.values())} of {len(scenes) * len(methods)} ("
                 + ", ".join(f"{m} {n}" for m, n in count.items()) + ")")
    lines.append("why a cell is empty (method: reason; scenes):")
    for (name, why), ids in empty_cells(scenes).items():
        lines.append(f"  {name}: {why}; {', '.join(ids)}")
    for name, bm in bond_methods().items():
        state = f"unavailable: {bm.unavailable}" if bm.unavailable else bm.origin
        lines.append(f"bond method {name}: {state}; {bm.source}")
    for name, why in BROKEN.items():
        lines.append(f"plugin {name}: failed to load ({why})")
    return "\n".join(lines)
