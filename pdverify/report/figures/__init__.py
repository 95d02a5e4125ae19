"""Figures of the report: one module per family of scenes, each registering its draw function."""
from __future__ import annotations

import importlib
import os
import pkgutil

import matplotlib
import numpy as np

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

FAMILIES = {}


def family(name, failed: bool = False):
    """Register a figure function ``f(scene, results, folder) -> [(file, caption), ...]``;
    ``failed``: it also draws failed runs that kept a partial result (e.g. a load curve up
    to where the run broke down)."""
    def deco(fn):
        fn.draws_failed = failed
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
    ok = [r for r in results if r.fields and (r.status == "ok" or fn is not None
                                              and fn.draws_failed)]
    if fn is None or not ok:
        return []
    return fn(scene, ok, folder)


def fem_then_pd(scene, results, folder):
    """For scenes that run PD beside their FEM reference: the FEM figures, the FEM runs and
    the PD runs, as ``(figures, fem_runs, pd_runs)``."""
    fem = [r for r in results if r.method == "fem"]
    pd_runs = [r for r in results if r.method != "fem"]
    return (FAMILIES["fem-reference"](scene, fem, folder) if fem else []), fem, pd_runs


def label(result) -> str:
    extra = ", ".join(f"{k}={v}" for k, v in result.params.items() if k in ("order",))
    return result.method + (f" ({extra})" if extra else "")


def node_image(x, spacing, values, unit=1.0):
    """Values at the nodes of a uniform 2D grid as an image (rows: y) and its extent
    (node positions times ``unit``, e.g. 1e3 for mm), for ``imshow(origin="lower")``."""
    i = np.rint((x[:, 0] - x[:, 0].min()) / spacing).astype(int)
    j = np.rint((x[:, 1] - x[:, 1].min()) / spacing).astype(int)
    img = np.full((j.max() + 1, i.max() + 1), np.nan)
    img[j, i] = values
    ext = tuple(unit * v for v in (x[:, 0].min(), x[:, 0].max(), x[:, 1].min(), x[:, 1].max()))
    return img, ext


def save(fig, folder, name) -> str:
    path = os.path.join(folder, name)
    fig.savefig(path, dpi=110, bbox_inches="tight")
    plt.close(fig)
    return name


