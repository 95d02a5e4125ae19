"""What the report's front page and the end-of-run summary say about each scene: its
headline error, the run of each method at its default parameters, the best method."""
from __future__ import annotations

from dataclasses import dataclass

from ..errors import InputError

#: The error each scene is ranked by (a scene may set ``headline``).
HEADLINE_DEFAULT = "rel_l2_error"


def headline(scene) -> str:
    return getattr(scene, "headline", HEADLINE_DEFAULT)


def headline_value(scene, result):
    """The run's headline error as a fraction (``*_pct`` metrics divided by 100), or None
    for a failed run, the FEM reference, or a run without that metric."""
    if result.status != "ok" or result.method == "fem":
        return None
    metric = headline(scene)
    v = result.metrics.get(metric)
    if isinstance(v, bool) or not isinstance(v, (int, float)):
        return None
    return abs(float(v)) / (100.0 if metric.endswith("_pct") else 1.0)


def default_run(scene, method, runs):
    """The run of ``method`` at its default params, else its first run."""
    mine = [r for r in runs if r.method == method]
    try:
        defaults = scene.resolve(method, {})
    except InputError:
        defaults = None
    return next((r for r in mine if r.params == defaults), mine[0] if mine else None)


@dataclass
class SceneSummary:
    scene: str
    metric: str
    best: str | None        # the most accurate method at default params (None: < 2 methods)
    best_error: float | None  # its headline error as a fraction
    best_time_s: float | None
    runs: int
    failed: list            # (method, message) of the failed runs


def summarise(scene, runs) -> SceneSummary:
    methods = []
    for r in runs:
        if r.method not in methods:
            methods.append(r.method)
    picked = {m: default_run(scene, m, runs) for m in methods}
    values = {m: headline_value(scene, r) for m, r in picked.items() if r is not None}
    values = {m: v for m, v in values.items() if v is not None}
    best = min(values, key=values.get) if len(values) > 1 else None
    return SceneSummary(
        scene=scene.id, metric=headline(scene), best=best,
        best_error=values.get(best), runs=len(runs),
        best_time_s=picked[best].timings.get("total_s") if best else None,
        failed=[(r.method, r.message) for r in runs if r.status != "ok"])
