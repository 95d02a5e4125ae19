"""The parameter surface of every scene, as data (tests/test_vocabulary.py compares it
with the snapshot tests/data/param_surface_a694eb9.json taken at commit a694eb9, before
the shared parameter sets): per scene and method each parameter's name, default, type,
unit, choices, scene_default and its check's verdict on probe values, and the resolved
defaults. Help texts are left out (they were unified on purpose)."""
from __future__ import annotations

import json

#: values each check is asked about: signs, zero, the bounds the scenes use (1, 2, 0.5,
#: -1), whole and fractional values, and the ends of params.POSITIVE_RANGE
PROBES = (-2.0, -1.0, -0.5, 0.0, 5e-324, 1e-9, 0.25, 0.5, 0.75, 1.0, 1.5, 2.0, 2.5, 3.0,
          4.0, 9.0, 1e6, 1e301)


def _param(q) -> dict:
    verdicts = []
    if q.check is not None and q.kind in (int, float):
        for v in PROBES:
            try:
                verdicts.append(q.check(q.kind(v)) if q.kind is float or v == int(v)
                                else "skip")
            except Exception as exc:           # a check that raises is part of the surface
                verdicts.append(f"raises {type(exc).__name__}")
    return {"name": q.name, "default": repr(q.default), "kind": q.kind.__name__,
            "unit": q.unit, "choices": None if q.choices is None else list(map(repr, q.choices)),
            "scene_default": q.scene_default, "check": verdicts}


def surface() -> dict:
    from pdverify.scenes import all_scenes
    out = {}
    for sc in all_scenes():
        entry = {"params": [_param(q) for q in sc.params], "methods": {}}
        for m in sc.all_methods:
            try:
                resolved = {k: repr(v) for k, v in sc.resolve(m.name, {}).items()}
            except Exception as exc:
                resolved = f"raises {type(exc).__name__}"
            entry["methods"][m.name] = {"params": [_param(q) for q in m.params],
                                        "resolved": resolved}
        out[sc.id] = entry
    return out


if __name__ == "__main__":
    print(json.dumps(surface(), indent=1, sort_keys=True))
