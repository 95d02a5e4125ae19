"""Scene registry: every module in this package registers its scenes on import."""
from __future__ import annotations

import importlib
import pkgutil

from ..errors import InputError, did_you_mean
from .base import (MethodSpec, Outcome, Published, Scene, cell_count, influence_param,
                   require_influence, whole_cells)

_REGISTRY: dict[str, Scene] = {}
_LOADED = False


def register(scene_cls):
    """Class decorator: instantiate and register a :class:`Scene` subclass by its id."""
    scene = scene_cls()
    if not scene.id or scene.id in _REGISTRY:
        raise RuntimeError(f"scene id {scene.id!r} is empty or registered twice")
    _REGISTRY[scene.id] = scene
    return scene_cls


def _load_all() -> None:
    global _LOADED
    if _LOADED:
        return
    for info in sorted(pkgutil.iter_modules(__path__), key=lambda i: i.name):
        if info.name != "base":
            importlib.import_module(f"{__name__}.{info.name}")
    _LOADED = True


def all_scenes() -> list[Scene]:
    _load_all()
    return list(_REGISTRY.values())


def get_scene(scene_id: str) -> Scene:
    _load_all()
    try:
        return _REGISTRY[scene_id]
    except KeyError:
        allowed = ", ".join(sorted(_REGISTRY))
        raise InputError(f"unknown scene {scene_id!r}{did_you_mean(scene_id, _REGISTRY)}; "
                         f"allowed: {allowed}") from None


def _tell_the_registry() -> None:
    """The treatment registry checks plugins' parameters against the scenes' (it sits
    below this package and does not import it)."""
    from ..corrections import registry
    registry.SCENES = all_scenes


_tell_the_registry()

__all__ = ["MethodSpec", "Outcome", "Published", "Scene", "influence_param", "register",
           "require_influence", "whole_cells", "cell_count", "all_scenes", "get_scene"]
