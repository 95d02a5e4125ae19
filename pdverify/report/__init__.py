"""The main job: run every scene and method, write results.json, figures and index.html."""
from __future__ import annotations

import os
import sys
import time

from ..results import atomic_write_text, write_results
from ..runner import plan, run_cases
from ..scenes import get_scene

DEFAULT_OUT = os.path.join("reports", "latest")


def build_report(*, out=None, quick=False, only=None, jobs=1, progress=None) -> int:
    """Run the report; returns 0, or 1 if any run failed. Bad input raises before work."""
    progress = progress or sys.stderr
    out = out or DEFAULT_OUT
    cases = plan(only=only, quick=quick)  # raises InputError on unknown scenes
    t0 = time.perf_counter()
    results = run_cases(cases, jobs=jobs, progress=progress)
    figdir = os.path.join(out, "figures")
    os.makedirs(figdir, exist_ok=True)
    from . import figures, html
    sections = []
    order = []
    for scene_id, _, _ in cases:
        if scene_id not in order:
            order.append(scene_id)
    for scene_id in order:
        scene = get_scene(scene_id)
        mine = [r for r in results if r.scene == scene_id]
        try:
            figs = figures.draw(scene, mine, figdir)
        except Exception as exc:  # a broken figure must not lose the numbers
            print(f"figure for {scene_id} failed: {type(exc).__name__}: {exc}", file=progress)
            figs = []
        sections.append((scene, html.scene_section(scene, mine, figs)))
    doc = write_results(os.path.join(out, "results.json"), results)
    atomic_write_text(os.path.join(out, "index.html"),
                      html.page(doc, sections, time.perf_counter() - t0))
    failed = sum(r.status != "ok" for r in results)
    print(f"report: {len(results)} runs, {failed} failed, "
          f"{time.perf_counter() - t0:.1f} s -> {os.path.join(out, 'index.html')}", file=progress)
    return 1 if failed else 0


__all__ = ["build_report"]
