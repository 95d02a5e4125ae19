"""Text listing of registered scenes, their methods and parameters (``pdverify list``)."""
from __future__ import annotations

from .corrections import describe
from .scenes import all_scenes


def _fmt(value) -> str:
    return f"{value:g}" if isinstance(value, float) else str(value)


def format_param(p) -> str:
    """``name=default``, its unit if physical (``E=1e+09 Pa``), and the allowed values of
    a choice param: ``plane=strain {strain|stress}``."""
    text = f"{p.name}={_fmt(p.default)}" + (f" {p.unit}" if p.unit else "")
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
    from .corrections.registry import treatments
    for name, t in treatments().items():
        if t.kind != "closure" and t.unavailable:
            lines.append(f"method {name}: unavailable: {t.unavailable}")
    for name, why in BROKEN.items():
        lines.append(f"plugin {name}: failed to load ({why})")
    return "\n".join(lines)


def format_scene(scene) -> str:
    """``pdverify list SCENE``: one scene's parameters (default, unit, allowed values and
    meaning), its methods with their own parameters, and why each registered method it
    does not offer is missing."""
    lines = [f"{scene.id}: {scene.title}",
             f"  seed {scene.seed}; reference: {scene.reference}"
             + (f"; {scene.dim}D" if scene.dim else ""),
             "  params (name=default unit {allowed}: meaning):"]
    lines += [f"    {format_param(p)}: {p.doc}" for p in scene.params]
    lines.append("  methods:")
    offered = scene.offered()
    for m in scene.all_methods:
        tag = " (default)" if m.name == scene.default_method else ""
        why = getattr(offered.get(m.name), "unavailable", None)
        if why and getattr(offered.get(m.name), "kind", "") != "closure":
            tag += f" (unavailable: {why})"
        lines.append(f"    {m.name}{tag}" + (f"  - {describe(m.name)}" if describe(m.name)
                                               else ""))
        own = {p.name for p in scene.params}
        lines += [f"        {format_param(p)}: {p.doc}" for p in m.params if p.name not in own]
    missing = [(name, why) for (name, why), ids in empty_cells([scene]).items()]
    if missing:
        lines.append("  not offered here (method: reason):")
        lines += [f"    {name}: {why}" for name, why in missing]
    return "\n".join(lines)


#: the schema of ``pdverify list --json``
LIST_SCHEMA = "pdverify.list/1"


def _param_json(p) -> dict:
    from .results import _plain
    return {"name": p.name, "default": _plain(p.default), "type": p.kind.__name__,
            "unit": p.unit or None, "choices": None if p.choices is None else _plain(
                list(p.choices)), "doc": p.doc}


def listing_json(scenes=None) -> dict:
    """``pdverify list [SCENE] --json``: the scenes (all, or ``scenes``), each with its
    parameters, methods (with their own parameters) and the methods it does not offer
    with the reason, for another program to read."""
    scenes = all_scenes() if scenes is None else scenes
    out = []
    for scene in scenes:
        own = {p.name for p in scene.params}
        out.append({
            "id": scene.id, "title": scene.title, "seed": scene.seed,
            "reference": scene.reference, "dim": scene.dim,
            "default_method": scene.default_method,
            "params": [_param_json(p) for p in scene.params],
            "methods": [{"name": m.name, "description": describe(m.name) or None,
                         "params": [_param_json(p) for p in m.params if p.name not in own]}
                        for m in scene.all_methods],
            "not_offered": {name: why for (name, why) in empty_cells([scene])},
        })
    return {"schema": LIST_SCHEMA, "scenes": out}
