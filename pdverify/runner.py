"""Running scenes: one run for the CLI, and a batch (optionally in parallel) for the report."""
from __future__ import annotations

import sys
from concurrent.futures import ProcessPoolExecutor

from .errors import InputError
from .results import RunResult, write_results
from .scenes import get_scene


def format_metrics(metrics: dict, limit: int = 4) -> str:
    items = list(metrics.items())[:limit]
    return " ".join(f"{k}={v:.4g}" if isinstance(v, float) else f"{k}={v}" for k, v in items)


def run_one(scene_id: str, *, method=None, overrides=None, json_path=None, stream=None) -> int:
    """``pdverify run``: resolve (exit 2 on bad input), run, print, optionally write JSON."""
    stream = stream or sys.stdout
    scene = get_scene(scene_id)
    method = method or scene.default_method
    scene.resolve(method, overrides)  # bad input fails here, before any work
    result = scene.run(method, overrides)
    print(f"{scene.id} --method {method}: {result.status}"
          + (f" ({result.message})" if result.message else ""), file=stream)
    for key, value in result.metrics.items():
        print(f"  {key:24s} {value:.10g}" if isinstance(value, float) else f"  {key:24s} {value}",
              file=stream)
    t = result.timings
    print(f"  time: setup {t['setup_s']:.4f} s, solve {t['solve_s']:.4f} s, "
          f"total {t['total_s']:.4f} s; size {result.size}", file=stream)
    if json_path:
        write_results(json_path, [result])
    return 0 if result.status == "ok" else 1


def _run_case(case) -> RunResult:
    scene_id, method, overrides = case
    return get_scene(scene_id).run(method, overrides)


def plan(only=None, quick=False) -> list[tuple[str, str, dict]]:
    """The (scene, method, overrides) cases of a report; validates every case up front."""
    from .scenes import all_scenes
    scenes = [get_scene(s) for s in only] if only else all_scenes()
    cases = []
    for scene in scenes:
        for method, overrides in scene.cases(quick=quick):
            scene.resolve(method, overrides)
            cases.append((scene.id, method, overrides))
    return cases


def run_cases(cases, *, jobs: int = 1, progress=None) -> list[RunResult]:
    """Run ``cases`` in order (or over ``jobs`` processes); one progress line per run."""
    if jobs < 1:
        raise InputError(f"--jobs={jobs} must be >= 1")
    total = len(cases)
    results: list[RunResult] = []

    def note(k, res):
        if progress is not None:
            params = " ".join(f"{k}={v:g}" if isinstance(v, float) else f"{k}={v}"
                              for k, v in sorted(cases[k][2].items()))
            status = res.status if res.status == "ok" else f"FAILED: {res.message}"
            print(f"[{k + 1}/{total}] {res.scene} {res.method} {params} ... {status} "
                  f"({res.timings.get('total_s', 0):.2f} s) {format_metrics(res.metrics, 2)}",
                  file=progress, flush=True)

    if jobs == 1 or total <= 1:
        for k, case in enumerate(cases):
            res = _run_case(case)
            note(k, res)
            results.append(res)
        return results
    with ProcessPoolExecutor(max_workers=jobs) as pool:
        for k, res in enumerate(pool.map(_run_case, cases)):
            note(k, res)
            results.append(res)
    return results
