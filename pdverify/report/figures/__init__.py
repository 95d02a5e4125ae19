"""Figures of the report: one module per family of scenes, each registering its draw function."""
from __future__ import annotations

import importlib
import os
import pkgutil

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

FAMILIES = {}


def family(name):
    """Register a figure function ``f(scene, results, folder) -> [(file, caption), ...]``."""
    def deco(fn):
        FAMILIES[name] = fn
        return fn
    return deco


def _load_all():
    for info in pkgutil.iter_modules(__path__):
        importlib.import_module(f"{__name__}.{info.name}")


def draw(scene, results, folder) -> list[tuple[str, str]]:
    """Draw ``scene``'s figure family for its successful runs; returns (file, caption) pairs."""
    _load_all()
    fn = FAMILIES.get(scene.figure)
    ok = [r for r in results if r.status == "ok" and r.fields]
    if fn is None or not ok:
        return []
    return fn(scene, ok, folder)


def label(result) -> str:
    extra = ", ".join(f"{k}={v}" for k, v in result.params.items() if k in ("order",))
    return result.method + (f" ({extra})" if extra else "")


def save(fig, folder, name) -> str:
    path = os.path.join(folder, name)
    fig.savefig(path, dpi=110, bbox_inches="tight")
    plt.close(fig)
    return name


