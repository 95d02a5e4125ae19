"""The one model builder (``pdverify.pd.build``): every model of the package is built
there, from a body, a stencil, a material and a treatment's closure."""
from __future__ import annotations

import ast
import pathlib

import numpy as np
import pytest

import pdverify
from pdverify.corrections.taylor_fictitious import fictitious_closure
from pdverify.pd import (BondBasedModel, Closure, StateBasedConstants, StateBasedModel,
                         build_stencil, get_influence)
from pdverify.pd.build import Body, BondMaterial, StateMaterial, build_model

PACKAGE = pathlib.Path(pdverify.__file__).parent
CONSTRUCTORS = {"StateBasedModel", "BondBasedModel"}


def constructor_calls(source: str, name: str) -> list[str]:
    """``name:line constructor`` of every call of a model's constructor in ``source``."""
    out = []
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, ast.Call):
            f = node.func
            called = (f.id if isinstance(f, ast.Name)
                      else f.attr if isinstance(f, ast.Attribute) else None)
            if called in CONSTRUCTORS:
                out.append(f"{name}:{node.lineno} {called}")
    return out


def test_only_the_builder_calls_a_models_constructor():
    """Scenes and treatments describe (body, stencil, material, closure); the models are
    built in one place. Before the builder: 12 calls in 9 modules (8 in scene modules)."""
    calls = [c for path in sorted(PACKAGE.rglob("*.py")) if path.name != "build.py"
             for c in constructor_calls(path.read_text(), str(path.relative_to(PACKAGE)))]
    assert calls == []


def test_the_check_sees_a_constructor_call():
    """The check above can fail: a call by name and by attribute are both found."""
    source = ("from .pd import StateBasedModel\nimport pdverify.pd as pd\n"
              "a = StateBasedModel(1, 2, 3, 4)\nb = pd.BondBasedModel(1, 2, 3, 4)\n")
    assert constructor_calls(source, "probe.py") == ["probe.py:3 StateBasedModel",
                                                     "probe.py:4 BondBasedModel"]


def _state_parts(dim=2, m=3.0, h=0.1):
    inf = get_influence("gaussian")
    stencil = build_stencil(dim, m)
    material = StateMaterial(StateBasedConstants("plane-strain" if dim == 2 else "3d", 1e9, 0.25),
                             inf)
    return stencil, material


def test_state_model_equals_the_constructor_and_takes_the_body_thickness():
    """The builder adds nothing: the same bonds, weights and stiffness as the
    constructor's, bitwise (the same operations in the same order)."""
    stencil, material = _state_parts()
    body = Body((1.0, 0.6), (0.0, 0.0), 0.1, thickness=0.05)
    built = build_model(body, stencil, material)
    direct = StateBasedModel(body.grid(), stencil, material.constants, material.influence,
                             None, thickness=0.05)
    assert isinstance(built, StateBasedModel)
    assert np.array_equal(built.bond_a, direct.bond_a)
    assert np.array_equal(built.node_volume, direct.node_volume)
    assert (built.stiffness() != direct.stiffness()).nnz == 0


def test_a_closure_of_the_grid_gets_the_grid_with_its_layers():
    """A callable closure receives the grid the builder made, ``layers`` fictitious
    layers included (Taylor's fictitious layer of one horizon)."""
    stencil, material = _state_parts()
    body = Body((1.0, 0.6), (0.0, 0.0), 0.1)
    seen = {}

    def closure_of(grid):
        seen["layers"] = grid.layers
        return fictitious_closure(grid, 2)

    model = build_model(body, stencil, material, closure_of, layers=stencil.reach)
    assert seen["layers"] == stencil.reach == 3
    assert model.grid.layers == 3
    # the same model as the closure built by hand on the same grid
    grid = body.grid(stencil.reach)
    by_hand = build_model(body, stencil, material, fictitious_closure(grid, 2), grid=grid)
    assert (model.stiffness() != by_hand.stiffness()).nnz == 0


def test_bond_material_builds_the_bond_based_model():
    inf = get_influence("triangular")
    body = Body((8.0,), (0.0,), 1.0, placement="on-surface", boundary_volume="full")
    model = build_model(body, build_stencil(1, 4.0), BondMaterial(2.5, inf), Closure())
    assert isinstance(model, BondBasedModel)
    assert model.c == 2.5 and model.grid.nodes_per_axis == (9,)


def test_an_unknown_material_is_refused():
    stencil, _ = _state_parts()
    with pytest.raises(TypeError, match="StateMaterial or a BondMaterial"):
        build_model(Body((1.0, 1.0), (0.0, 0.0), 0.1), stencil, {"E": 1.0})
