"""``report --failed``: which runs to run again, which to keep, and the two merged."""
from __future__ import annotations

import os

from .. import outputs
from ..errors import InputError
from ..results import run_key
from ..scenes import get_scene


def rerun_plan(cases, out: str):
    """``report --failed``: (the cases to run again, the previous runs to keep).

    Rerun: the planned cases whose run failed unexpectedly (outcome ``failed``, not a
    documented finding) or is missing in ``out/results.json``; kept: every other run of
    that file, as it was (a run of the previous report outside today's plan included).
    No readable results file there is bad input (exit 2), before any work."""
    from ..results import RunResult, load_results
    from ..runner import _params
    path = os.path.join(out, "results.json")
    if outputs.folder_state(out)[0] != "report" or not os.path.isfile(path):
        raise InputError(f"--failed: {out!r} holds no previous pdverify report (no "
                         "results.json); run the report without --failed first")
    try:
        doc = load_results(path)
    except (OSError, ValueError) as exc:
        raise InputError(f"--failed: the previous report's results cannot be read "
                         f"({exc})") from None
    previous = {}
    for k, run in enumerate(doc["runs"]):
        outputs.check_listed(out, run.get("files", []),
                             f"--failed: the previous report's results.json runs[{k}].files")
        r = RunResult.from_json(run)
        previous.setdefault(r.key, r)
    again = []
    for case in cases:
        scene_id, method, overrides = case
        key = run_key(scene_id, method, _params(get_scene(scene_id), method, overrides))
        prev = previous.get(key)
        if prev is None or prev.outcome == "failed":
            again.append(case)
            previous.pop(key, None)
    return again, list(previous.values())


def merged(kept, new) -> list:
    """``report --failed`` (and ``--include``): the previous runs kept and the runs made
    now (or the external runs included), grouped by scene in the order of the scene
    registry (a report's order), each group's runs in order."""
    from ..scenes import all_scenes
    rank = {s.id: k for k, s in enumerate(all_scenes())}
    return sorted(list(kept) + list(new), key=lambda r: rank.get(r.scene, len(rank)))
