"""A scene's ``treatment_defaults`` (body3d-manufactured: order=3, load_point=node) set
the defaults of the parameters that declare ``scene_default`` only, each checked as a
given value is; a plugin's parameter of the same name keeps its own default."""
import numpy as np
import pytest

import entry_points

from pdverify.corrections import registry
from pdverify.corrections.registry import BondMethod
from pdverify.errors import InputError
from pdverify.params import Param
from pdverify.pd.closure import Closure

SCENE = "body3d-manufactured"


def _method(name, **param):
    return BondMethod(name=name, description="test: an order parameter of its own",
                      source="tests/corrections/test_scene_defaults.py",
                      closure=lambda p: Closure(force_factor=lambda m: np.ones(m.bond_a.size)),
                      params=(Param("order", 0, "its own order", choices=(0, 1), **param),))


@pytest.fixture
def register(monkeypatch):
    def install(*methods):
        entry_points.register(monkeypatch, "orders", "test:METHODS", lambda: list(methods))
    yield install
    monkeypatch.undo()
    registry.reload()


def test_a_plugin_order_keeps_its_own_default(register):
    """Before: the scene's order=3 replaced the plugin's default 0, unchecked against
    its choices (0, 1), and the run took order=3."""
    from pdverify.scenes import get_scene
    register(_method("own-order"))
    assert registry.broken_method("own-order") is None
    scene = get_scene(SCENE)
    assert scene.resolve("own-order")["order"] == 0
    assert scene.resolve("surface-nodes")["order"] == 3       # the built-in declares it
    assert scene.resolve("taylor-fictitious")["order"] == 3
    assert scene.resolve("none")["load_point"] == "node"
    with pytest.raises(InputError, match="order=3 is not allowed"):
        scene.resolve("own-order", {"order": 3})


def test_a_declared_scene_default_outside_its_choices_is_refused(register):
    """A plugin that takes the scene's order but allows 0 and 1 only is listed as broken
    with the reason (and left out), not run at order=3."""
    from pdverify.scenes import get_scene
    register(_method("takes-order", scene_default=True))
    # a plugin whose load fails is listed under its entry point's name ("orders"): the
    # load runs in a child process, so pdverify's own never learns the method's name
    why = registry.broken_method("orders")
    assert why and "order=3 is not allowed" in why and SCENE in why
    assert "takes-order" not in get_scene(SCENE).offered()
