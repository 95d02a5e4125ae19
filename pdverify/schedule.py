"""Which run a free local worker takes next, and the schedule a report prints when it ends
(issue 32).

- **Longest first**: the cases are ordered by their expected run time, longest first, so
  that the long runs start early and the workers finish together. The expected time is
  the run's own time in the previous report in the same output folder (same scene,
  method and params). The cases it does not know go first (an unknown run may be long),
  in the plan's order. Replayed on a full report's run
  times (``benchmarks/schedule_replay.py``), the known times longest first end at
  the lower bound and the memory estimates do not order the unknown cases
  (benchmarks/records/schedule_replay-2026-11-23-issue32-orders.json).
- **The memory budget holds for the runs in flight together**: a case starts only when
  its estimate and those of the runs still running fit the limit
  (:func:`pdverify.budget.memory_limit`), so a large run runs alone. A case that does not
  fit waits at the head of the queue (no smaller run overtakes it, which could keep it
  waiting to the very end); with nothing running, the head always starts.
- **References first, and no run waits on one while another can start**: a run that
  computes a scene's reference (:data:`REFERENCE_METHODS`: the FEM studies, cached after
  their first run) starts before every other case, and while it runs, the scene's other
  runs (which read that reference, waiting on its cache lock) are overtaken by cases of
  other scenes. On a warm cache these runs take hundredths of a second; on a cold one
  they are the longest of the quick report (the finite-strain indentation's ~9 s each),
  and a worker that took a run of the same scene sat idle on the lock.
- **The critical path**: the runs of the worker that finished last, printed at the end.
"""
from __future__ import annotations

import os
from dataclasses import dataclass, field


def default_jobs() -> int:
    """The cores this process may run on (``os.sched_getaffinity``; else the CPU count)."""
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except (AttributeError, OSError):   # not Linux
        return max(1, os.cpu_count() or 1)


def case_params(scene, method, overrides) -> dict | None:
    """The resolved params of a case; None when a plugin's check failed (not a refusal:
    :class:`~pdverify.corrections.registry.PluginCheckError`), a case that then fails in
    its run naming the plugin, while the report goes on."""
    from .corrections.registry import PluginCheckError
    try:
        return scene.resolve(method, overrides)
    except PluginCheckError:
        return None


def memory_estimates(cases) -> list[float]:
    """Each case's memory estimate in bytes (:meth:`Scene.estimate`; 0 when it has none)."""
    from .scenes import get_scene
    out = []
    for scene_id, method, overrides in cases:
        scene = get_scene(scene_id)
        params = case_params(scene, method, overrides)
        est = None if params is None else scene.estimate(method, params)
        out.append(float(est.memory) if est is not None else 0.0)
    return out


#: The measured run times the ETA starts from (:func:`measured_times`): each run of the
#: full and the quick plan, its ``total_s`` in a report on 2 cores, and, for a run that
#: computes its scene's reference (:func:`computes_reference`), the seconds that
#: computation took (the reference study and its converged solution) when the cache was
#: cold; written by ``benchmarks/eta_replay.py --write-table``
MEASURED_TIMES = os.path.join(os.path.dirname(__file__), "data", "run_times.json")


def measured_times() -> dict:
    """``{run key: (seconds, cold reference seconds)}`` of :data:`MEASURED_TIMES`; {}
    when the file is missing or unreadable (the ETA then starts from the size model)."""
    import json
    from .results import run_key
    try:
        with open(MEASURED_TIMES) as fh:
            rows = json.load(fh)["runs"]
        return {run_key(r["scene"], r["method"], r["params"]): (float(r["s"]),
                                                               float(r.get("cold_s", 0.0)))
                for r in rows}
    except (OSError, ValueError, KeyError, TypeError):
        return {}


def case_costs(cases, known=None, measured=None) -> list[tuple]:
    """Each case's predicted cost for the progress ETA: ("known", its seconds in the
    previous report) when ``known`` has it, else from the measured times
    (``measured``, default :func:`measured_times`): ("known", its seconds there), or, for
    a run that computes its scene's reference, ("reference", those seconds plus the cold
    reference's: a warm cache makes it a fraction of a second, and such a run starts
    first and ends at once), else ("size", the budget's size model: the memory estimate in
    bytes times the explicit steps or load increments, at least 1), else (None, None). The
    progress calibrates each kind by the runs done."""
    from .scenes import get_scene
    from .results import run_key
    known = known or {}
    measured = measured_times() if measured is None else measured
    out = []
    for scene_id, method, overrides in cases:
        scene = get_scene(scene_id)
        params = case_params(scene, method, overrides)
        if params is None:
            out.append((None, None))
            continue
        key = run_key(scene_id, method, params)
        t = known.get(key)
        if t is not None:
            out.append(("known", float(t)))
            continue
        if key in measured:
            t, cold = measured[key]
            reference = computes_reference((scene_id, method, overrides)) and cold > 0
            out.append(("reference", t + cold) if reference else ("known", t))
            continue
        est = scene.estimate(method, params)
        if est is None or not est.memory > 0:
            out.append((None, None))
        else:
            out.append(("size", float(est.memory) * max(1, est.time_steps + est.increments)))
    return out


def previous_times(path) -> dict:
    """Run time (``total_s``) by :func:`~pdverify.results.run_key` from the results file
    ``path`` of an earlier report; {} if there is none or it cannot be read."""
    import json
    from .results import run_key
    try:
        with open(path) as fh:
            doc = json.load(fh)
        return {run_key(r["scene"], r["method"], r["params"]): float(r["timings"]["total_s"])
                for r in doc["runs"]}
    except (OSError, ValueError, KeyError, TypeError):
        return {}


#: Methods whose run computes the reference its scene's other runs read (module
#: docstring): the FEM studies of the FEM-referenced scenes.
REFERENCE_METHODS = ("fem",)


def computes_reference(case) -> bool:
    """Whether the case ``(scene, method, overrides)`` computes its scene's reference."""
    return case[1] in REFERENCE_METHODS


def longest_first(cases, known=None) -> list[int]:
    """Indices of ``cases`` in the order to start them: the runs that compute a reference
    (:func:`computes_reference`), then the cases without a known time, both in the plan's
    order, then the known ones by their time, longest first; ties keep the plan's order
    (the sort is stable)."""
    from .scenes import get_scene
    from .results import run_key
    known = known or {}
    keys = []
    for case in cases:
        scene_id, method, overrides = case
        params = case_params(get_scene(scene_id), method, overrides)
        t = None if params is None else known.get(run_key(scene_id, method, params))
        keys.append((-1, 0.0) if computes_reference(case) else
                    (0, 0.0) if t is None else (1, -t))
    return sorted(range(len(cases)), key=lambda k: keys[k])


def next_case(pending, cases, running) -> int:
    """The place in ``pending`` (case indices, in start order) of the case to start next,
    ``running`` the indices of the cases in flight: the first case that computes a
    reference or whose scene has no reference run in flight; the head (0) when every case
    waits on one."""
    waiting = {cases[k][0] for k in running if computes_reference(cases[k])}
    return next((i for i, k in enumerate(pending)
                 if computes_reference(cases[k]) or cases[k][0] not in waiting), 0)


@dataclass
class Slot:
    """One worker's place in the pool and the runs it ran: (case index, start, end), in
    seconds since the pool started."""

    runs: list = field(default_factory=list)
    #: worker processes this place has had (a worker is recycled: ``runner.retire``)
    processes: int = 0

    @property
    def end(self) -> float:
        return self.runs[-1][2] if self.runs else 0.0

    @property
    def busy(self) -> float:
        return sum(e - s for _, s, e in self.runs)


def critical_path(slots, cases, shown: int = 5) -> str:
    """The last-finishing worker's runs (the chain that set the report's run time), its
    longest runs, and when every worker finished."""
    from .progress import describe
    used = [s for s in slots if s.runs]
    if not used:
        return "critical path: no runs"
    last = max(used, key=lambda s: s.end)
    longest = sorted(last.runs, key=lambda r: r[1] - r[2])[:shown]
    ends = ", ".join(f"{s.end:.1f}" for s in used)
    text = (f"critical path: worker {slots.index(last) + 1} of {len(slots)} finished last, at "
            f"{last.end:.1f} s ({len(last.runs)} runs, busy {last.busy:.1f} s; the workers "
            f"finished at {ends} s); its longest runs: "
            + "; ".join(f"{describe(cases[k])} {e - s:.1f} s" for k, s, e in longest))
    return text
