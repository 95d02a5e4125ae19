"""A new bond method written as one module (tests/plugins/mean_ratio_plugin: the mean of
the two ends' horizon-volume ratios), registered through the entry point group
``pdverify.methods`` as a user's package would be, serves every scene that takes bond
methods, bond-based and state-based, through the one ``make_closure``."""
import sys
from pathlib import Path

import numpy as np
import pytest

import entry_points

from pdverify.corrections import registry
from pdverify.corrections.volume import volume_factors

PLUGIN = Path(__file__).resolve().parents[1] / "plugins" / "mean_ratio_plugin"
NAME = "mean-ratio"
#: machine-epsilon claims, relative (sums of a few hundred O(1) terms)
EPS = 1e-12


@pytest.fixture
def plugin(monkeypatch):
    """The plugin's entry point, as ``importlib.metadata`` lists an installed one; the
    registry loaded afresh with it, and without it after the test."""
    monkeypatch.syspath_prepend(str(PLUGIN))

    def load():
        import pdverify_mean_ratio
        return pdverify_mean_ratio.METHOD
    entry_points.register(monkeypatch, NAME, "pdverify_mean_ratio:METHOD", load)
    yield sys.modules.get("pdverify_mean_ratio") or __import__("pdverify_mean_ratio")
    monkeypatch.undo()
    registry.reload()


def bond_scenes():
    import pdverify.scenes as scenes
    return [s for s in scenes.all_scenes() if s.bond_methods()]


def test_offered_wherever_volume_is(plugin):
    """Every scene that offers the built-in ``volume`` (it has no theory, dimension or
    scene limits either) offers the plugin: bond-based and state-based, 1D to 3D."""
    assert registry.broken_method(NAME) is None
    served = bond_scenes()
    assert {s.model_theory for s in served} == {"bond-based", "state-based"}
    assert {s.dim for s in served} == {1, 2, 3}
    for s in served:
        assert ("volume" in s.bond_methods()) == (NAME in s.bond_methods()), s.id


def _models():
    """A bond-based 2D box (cell-centred and on-surface nodes) and a state-based 3D box."""
    from pdverify.pd import (BondBasedModel, BoxGrid, StateBasedConstants, StateBasedModel,
                             build_stencil, get_influence, state_based_stencil)

    def bond_model(cells, placement="cell-centred"):
        g = BoxGrid(tuple(float(c) for c in cells), (0.0, 0.0), 1.0, placement=placement)
        return BondBasedModel(g, build_stencil(2, 3.0), 1.0, get_influence("constant"))
    inf = get_influence("gaussian")
    state = StateBasedModel(BoxGrid((11.0, 11.0, 11.0), (0.0,) * 3, 1.0, 0),
                            state_based_stencil(3, 2.0, 1.0, inf),
                            StateBasedConstants("3d", 1.0, 0.3), inf)
    return [bond_model((14, 14)), state, bond_model((12, 9), "on-surface")]


def test_interior_is_untouched_and_the_means_identity(plugin):
    """Bonds whose two ends have complete neighbourhoods get factor 1 exactly as the bulk
    lattice's own sums (as ``volume``); on every bond, arithmetic times harmonic mean of
    the ends' ratios is their product, r_i r_j, and the arithmetic mean is never below
    the harmonic one (equal where V_i = V_j): checked against the built-in ``volume``.
    Machine epsilon."""
    for model in _models():
        f = plugin.mean_ratio_factors(model)
        r = plugin.node_ratios(model)
        a, b = model.bond_a, model.bond_b
        g = model.grid
        dist = g.distance_to_surface(g.x[g.interior_ids])
        complete = np.ones(g.n_ext, bool)
        complete[g.interior_ids] = dist > model.horizon
        both = complete[a] & complete[b]
        assert both.any() and (~both).any()
        assert np.allclose(f[both], 1.0, rtol=0, atol=EPS)
        assert np.any(f[~both] > 1.0 + 1e-3)           # it corrects the surface bonds
        v = volume_factors(model)
        assert np.allclose(f * v, r[a] * r[b], rtol=EPS, atol=0)
        assert np.all(f >= v * (1.0 - EPS))
        same = np.isclose(r[a], r[b], rtol=EPS, atol=0)
        assert np.allclose(f[same], v[same], rtol=EPS, atol=0)
        assert np.any(f[~same] > v[~same] * (1.0 + 1e-6))


def test_the_closure_is_the_plugins(plugin):
    """``make_closure`` of the registered method scales each bond's volume by the
    plugin's factors: a model built with it carries them (bond- and state-based)."""
    from pdverify.pd import Closure  # noqa: F401  (the type the plugin returns)
    method = registry.from_name(NAME)
    assert method.origin != "built-in"
    closure = method.make_closure({})
    for model in _models():
        assert np.array_equal(closure.weight_factor(model), plugin.mean_ratio_factors(model))


@pytest.mark.slow
def test_runs_on_every_scene_of_its_theory(plugin):
    """One run on each scene that takes bond methods (bond-based and state-based), at the
    scene's ``--quick`` configuration of an offered treatment: each is ok with finite
    metrics, and differs from ``none`` where the scene has truncated neighbourhoods."""
    done = []
    for scene in bond_scenes():
        res = scene.run(NAME, dict(scene.quick_overrides))
        assert res.status == "ok", (scene.id, res.message)
        vals = [v for v in res.metrics.values() if isinstance(v, float)]
        assert vals and all(np.isfinite(vals)), scene.id
        done.append(scene.id)
    assert len(done) == len(bond_scenes()) >= 20
