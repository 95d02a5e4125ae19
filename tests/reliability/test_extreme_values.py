"""Extreme values of every scene's numeric parameters (issue 31): 0, the smallest
subnormal, the largest decades of a double, -1 and NaN give a one-line refusal before work
or, when accepted, a run that ends ok or failed with a message naming what happened; never a
traceback, never the catch-all "internal error"."""
import math

import pytest

from pdverify import budget
from pdverify.errors import InputError
from pdverify.scenes import all_scenes, get_scene

EXTREMES = ("0", "5e-324", "1e308", "-1", "nan")


def _numeric_params(scene, method):
    return [p for p in scene.params + scene.method(method).params
            if p.kind in (int, float) and not p.choices and p.kind is not bool]


def _cases():
    for scene in all_scenes():
        method = scene.default_method
        for p in _numeric_params(scene, method):
            for value in EXTREMES:
                yield scene.id, method, p.name, value


CASES = list(_cases())
#: scenes whose default run takes under a second here: their accepted extremes are run
CHEAP = {"bar1d-traction", "bar1d-uniform-load", "bar1d-linear-load", "bar1d-sine-load",
         "bar1d-homogenization", "bar1d-constraints", "bar1d-vibration", "bar1d-force-flux",
         "stiffness2d-sheet", "stiffness3d-box", "stiffness3d-box-bond", "stiffness2d-plate",
         "wave1d-surface-nodes"}


def test_the_sweep_covers_every_scene():
    assert {c[0] for c in CASES} == {s.id for s in all_scenes()}
    assert len(CASES) >= 5 * 100


def test_every_extreme_is_refused_in_one_line_or_accepted():
    """Resolving (the checks and the budget, all before work) raises nothing but
    InputError, with one line that names the parameter."""
    accepted = []
    for scene_id, method, name, value in CASES:
        scene = get_scene(scene_id)
        try:
            scene.resolve(method, {name: value})
        except InputError as exc:
            text = str(exc)
            assert "\n" not in text and name in text, (scene_id, name, value, text)
        else:
            accepted.append((scene_id, name, value))
    # what is left is physically meaningful: signs of loads, nu = 0 and the like
    assert all(v in ("0", "-1", "5e-324", "1e308") for _, _, v in accepted)


@pytest.mark.parametrize("scene_id", sorted(CHEAP))
def test_accepted_extremes_end_with_a_named_outcome(scene_id):
    scene = get_scene(scene_id)
    method = scene.default_method
    for p in _numeric_params(scene, method):
        for value in EXTREMES:
            try:
                scene.resolve(method, {p.name: value})
            except InputError:
                continue
            res = scene.run(method, {p.name: value})
            assert res.status in ("ok", "failed")
            if res.status == "failed":
                assert res.message and not res.message.startswith("internal error"), \
                    (p.name, value, res.message)
            else:
                assert all(math.isfinite(v) for v in res.metrics.values()
                           if isinstance(v, float)), (p.name, value)


def test_ratio_printed_with_the_digits_that_differ_from_one():
    from pdverify.solvers.explicit import ratio_above_one
    assert ratio_above_one(1.0003) == "1.0003"
    assert ratio_above_one(1 + 2 ** -52) == "1.0000000000000002"
    assert ratio_above_one(1.5) == "1.5"
    res = get_scene("bar1d-vibration").run("none", {"dt_factor": 1.0003})
    assert res.status == "failed" and "(ratio 1.0003 > 1;" in res.message, res.message


def test_default_memory_limit_is_half_the_smallest_ceiling(tmp_path, monkeypatch):
    """Not MemAvailable: the total memory, a cgroup limit or RLIMIT_AS, the smallest."""
    import os
    import resource
    total = os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES")
    monkeypatch.delenv(budget.MEMORY_ENV, raising=False)
    budget.set_limit(None)
    cg = tmp_path / "memory.max"
    monkeypatch.setattr(budget, "_CGROUP_LIMITS", (str(cg),))
    cg.write_text("max\n")                                   # v2: no limit
    soft = resource.getrlimit(resource.RLIMIT_AS)[0]
    expect = min([total] + ([soft] if soft != resource.RLIM_INFINITY else []))
    assert budget.memory_limit()[0] == int(0.5 * expect)
    cg.write_text(f"{2 ** 30}\n")                            # a 1 GiB cgroup
    limit, source = budget.memory_limit()
    assert limit == 2 ** 29 and "the cgroup's memory limit" in source
    # the same answer every time: nothing momentary goes in
    assert {budget.memory_limit()[0] for _ in range(5)} == {2 ** 29}


def test_rlimit_as_lowers_the_default_limit():
    import subprocess
    import sys
    code = ("import resource; hard = resource.getrlimit(resource.RLIMIT_AS)[1]; "
            "resource.setrlimit(resource.RLIMIT_AS, (8 * 2 ** 30, hard)); "
            "from pdverify import budget; print(*budget.memory_limit(), sep='|')")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         timeout=120, env={**__import__("os").environ,
                                           budget.MEMORY_ENV: ""}).stdout.strip()
    limit, source = out.split("|")
    assert int(limit) == 4 * 2 ** 30 and "RLIMIT_AS" in source, out
