"""A node-adding treatment written as one module against the ``static-state`` protocol
(tests/plugins/linear_layer_plugin: fictitious nodes by per-axis linear or constant
extrapolation, surface-node unknowns carrying the conditions), registered as a plugin
through the entry point group, run on every scene of its family."""
import math
import sys
from pathlib import Path

import numpy as np
import pytest

import entry_points

from pdverify.corrections import registry
from pdverify.corrections.protocols import ParamCheck, StaticAssembly, conformance
from pdverify.solvers.front import solve

PLUGIN = Path(__file__).resolve().parents[1] / "plugins" / "linear_layer_plugin"
sys.path.insert(0, str(PLUGIN))
sys.path.insert(0, str(Path(__file__).resolve().parent))
import pdverify_linear_layer as layer  # noqa: E402
from test_static_family import EXACT, _problem  # noqa: E402

NAME = "linear-layer"


@pytest.fixture
def registered(monkeypatch):
    """The plugin as pdverify finds an installed one: through its entry point."""
    entry_points.register(monkeypatch, NAME, "pdverify_linear_layer:METHOD",
                          lambda: layer.METHOD)
    try:
        assert NAME in registry.treatments(), registry.BROKEN
        yield registry.treatments()[NAME]
    finally:
        monkeypatch.undo()
        registry.reload()


def test_it_meets_the_family_protocol():
    assert conformance(layer.assemble, StaticAssembly) is None
    assert conformance(layer.METHOD.assemble, StaticAssembly) is None
    assert conformance(layer.check, ParamCheck) is None


def _error(dim, extrapolation):
    problem = _problem(dim)
    system = layer.assemble(problem, {"extrapolation": extrapolation})
    x, _ = solve(system, where=f"test/{NAME}")
    g = system.model.grid
    u = system.displacements(x)[:g.n_interior]
    ref = problem.exact(g.x[g.interior_ids])
    return np.abs(u - ref).max() / np.abs(ref).max()


@pytest.mark.parametrize("dim", [1, 2, 3])
def test_linear_extrapolation_is_exact_for_affine_fields(dim):
    """Affine field, its tractions on the free faces, moment-corrected weights (the
    discrete material has the continuum moduli): the linear steps reproduce the field on
    the layer, corners included, so the field is the PD solution (EXACT: round-off,
    tests/treatments/test_static_family.py)."""
    assert _error(dim, "linear") < EXACT


@pytest.mark.parametrize("dim", [1, 2, 3])
def test_constant_extrapolation_is_not_so_the_test_can_fail(dim):
    """Carrying the surface values outwards unchanged misses any gradient normal to a
    face: far more than round-off (1e-3: measured 6 to 14 %)."""
    assert _error(dim, "constant") > 1e-3


def _coarse(scene):
    """The scene's own quick case of surface nodes (or of ``none``), with the scene's
    parameters only: the smallest resolution its report runs."""
    for method in ("surface-nodes", "none"):
        for m, params in scene.report_cases(quick=True):
            if m == method:
                names = {p.name for p in scene.params}
                return {k: v for k, v in params.items() if k in names}
    return {}


@pytest.mark.slow
def test_it_runs_on_every_scene_of_its_family(registered):
    """Offered on every box of the static-state family and run there (finite errors);
    refused on the shapes with its ``box_only`` reason; exact to round-off on the
    traction bar, whose solution is linear (Eq. 64 relative to the largest displacement,
    as for the built-in surface nodes: tests/corrections/test_plugin.py). Slow tier: the
    ten runs take ~25 s alone, the two 3D boxes most of it."""
    import pdverify.scenes as scenes
    family = [s for s in scenes.all_scenes() if s.family == "static-state"]
    boxes = [s for s in family if not s.has_shape]
    # 13 boxes: 10 static ones and issue 56's two wave boxes and pulse plate (the
    # family's dynamic mode); the shapes: hole, L, three cracks, two 3D bodies
    assert len(boxes) == 13 and len(family) == 20
    for scene in family:
        why = registered.why_not(scene)
        if scene.has_shape:
            assert why is not None and "curved or cut boundary" in why, (scene.id, why)
            continue
        assert why is None, (scene.id, why)
        if scene.id == "wave2d-pulse":
            # surface-node unknowns on free edges: condensed per step, and the condensed
            # operator of the built-in surface nodes grows (a documented failure there);
            # the plugin's runs at the quick grid, ok or failing the same named way
            res = scene.run(NAME, {"spacing": 0.02})
            assert res.status == "ok" or "negative" in res.message, res.message
            continue
        res = scene.run(NAME, _coarse(scene))
        assert res.status == "ok", (scene.id, res.message)
        assert res.params["extrapolation"] == "linear", scene.id   # its own default
        errors = {k: v for k, v in res.metrics.items() if "error" in k}
        assert errors, (scene.id, res.metrics)
        assert all(math.isfinite(v) for v in errors.values()
                   if isinstance(v, float)), (scene.id, errors)
        assert res.size.get("surface_nodes", 0) > 0 or res.diagnostics, scene.id
        if scene.id == "bar1d-traction":
            # the traction bar's field is linear, which linear extrapolation reproduces:
            # round-off (1e-15) times the condition estimate (< 1e7 here), in per cent
            assert res.metrics["max_error_pct"] < 1e-9
        if scene.dim == 1:
            # in 1D each fictitious node has one line and one surface node: the linear
            # step is the surface nodes' order-1 Taylor series (seed 002 Eqs. 8-9), so
            # both solve the same system up to the round-off of the Taylor weights
            # (~1e-15, times condition estimates below 1e7 on these bars: 1e-6 relative)
            ref = scene.run("surface-nodes", {**_coarse(scene), "order": 1})
            for k in ("max_error_pct", "rel_l2_error"):
                assert res.metrics[k] == pytest.approx(ref.metrics[k], rel=1e-6, abs=1e-9)


def test_a_plugin_loaded_before_the_scenes_still_answers_for_every_scene():
    """The first call of the treatment registry may come before anything imported the
    scenes (a fresh process that asks for the methods first): the plugin is still asked
    about every scene. Fails when the registry loads it with no scene to answer for (then
    every scene says "the plugin was loaded before this scene")."""
    import subprocess
    script = f"""
import importlib.metadata as md, sys
sys.path.insert(0, {str(PLUGIN)!r})
from pdverify.corrections import registry
assert "pdverify.scenes" not in sys.modules
class EP:
    group = registry.ENTRY_POINT_GROUP
    name, value = {NAME!r}, "pdverify_linear_layer:METHOD"
    def load(self):
        import pdverify_linear_layer
        return pdverify_linear_layer.METHOD
md.entry_points = lambda group=None: [EP()]
t = registry.treatments()[{NAME!r}]
import pdverify.scenes as scenes
print(sum(t.why_not(s) is None for s in scenes.all_scenes()), len(t.answers))
"""
    root = Path(__file__).resolve().parents[2]
    out = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True,
                         cwd=root, env={**__import__("os").environ, "PYTHONPATH": str(root)},
                         timeout=120)
    assert out.returncode == 0, out.stderr[-2000:]
    offered, answered = map(int, out.stdout.split())
    import pdverify.scenes as scenes
    assert answered == len(scenes.all_scenes())
    assert offered == 13     # the thirteen boxes of the static-state family (the test above)
