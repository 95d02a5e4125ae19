"""One vocabulary for the scenes' grids and parameters (issue 51): every scene states its
discretisation as (h, delta) in metres, the convergence studies read it there, and the
shared parameter sets leave every scene's parameter surface as it was at a694eb9."""
import json
import math
from pathlib import Path

import pytest

from pdverify.scenes import all_scenes
from pdverify.scenes.base import Discretisation

from param_surface import surface
from studies_snapshot import studies

DATA = Path(__file__).parent / "data"


def test_every_scene_states_its_discretisation_in_metres():
    for scene in all_scenes():
        method = scene.baseline_spec().name or scene.all_methods[0].name
        d = scene.discretisation(scene.resolve(method, {}))
        assert isinstance(d, Discretisation), scene.id
        assert math.isfinite(d.h) and math.isfinite(d.delta), scene.id
        # a horizon spans at least one spacing on every scene (m >= 1; the checks of
        # m_ratio, horizon_ratio and horizon/spacing say so)
        assert 0 < d.h <= d.delta, (scene.id, d)


def test_discretisation_follows_each_spelling():
    """Each scene's own names map to one (h, delta): a level changed in the scene's
    spelling moves h and delta as the scene's grid does."""
    from pdverify.scenes import get_scene
    cases = {"bar1d-sine-load": ({"spacing": 0.1, "m_ratio": 4.0}, 0.1, 0.4),
             "sheet2d-tension": ({"spacing": 0.0025, "horizon": 0.01}, 0.0025, 0.01),
             "sheet2d-clamped": ({"side_factor": 8.0, "m_ratio": 4.0}, 0.005 / 4, 0.005),
             "bar1d-vibration": ({"nodes": 51, "horizon_ratio": 4.0}, 1 / 50, 4 / 50),
             "wave1d-surface-nodes": ({"horizon": 0.1, "m_ratio": 10}, 0.01, 0.1)}
    for sid, (level, h, delta) in cases.items():
        scene = get_scene(sid)
        d = scene.discretisation(scene.resolve(scene.baseline_spec().name
                                               or scene.all_methods[0].name, level))
        # a few roundings of the same products in metres: a few ulp (eps 2.2e-16)
        assert d.h == pytest.approx(h, rel=1e-15) and d.delta == pytest.approx(delta, rel=1e-15), sid


#: studies a later issue extended on purpose: (scene, kind) -> the issue. Their levels of
#: a694eb9 must still be the first levels, bit for bit, and everything else unchanged.
EXTENDED = {("body3d-manufactured", "delta"): "issue 55: h = 1/24, 1/30 appended"}


def test_studies_unchanged_bit_for_bit():
    """Every study's levels, labels and refined lengths h (as float.hex) as at a694eb9,
    when convergence.py had four adapters of its own; a study of :data:`EXTENDED` keeps
    those levels first (and its quick levels as they were)."""
    before = json.loads((DATA / "studies_a694eb9.json").read_text())
    after = json.loads(json.dumps(studies()))
    # the methods a study skips grew by issue 55's bond-box methods on the sheets (their
    # cost, convergence.BOND_BOX_COST); every level, label and h is as it was
    bond_box = ["taylor-fictitious", "surface-nodes", "pddo", "mirror-nodes"]
    for row in after:
        if row["scene"] in ("sheet2d-tension", "sheet2d-clamped"):
            assert row["skip"][-4:] == bond_box, row["scene"]
            row["skip"] = row["skip"][:-4]
    assert len(after) == len(before)
    for old, new in zip(before, after):
        if (old["scene"], old["kind"]) in EXTENDED:
            levels = old["full"]["levels"]
            assert new["full"]["levels"][:len(levels)] == levels
            assert len(new["full"]["levels"]) > len(levels)
            new = {**new, "full": {**new["full"], "levels": new["full"]["levels"][:len(levels)]}}
        assert new == old


#: the method x scene cells added since a694eb9 (issue 55): the node-adding methods on the
#: 2D and 3D shapes (their parameters are the box scenes'), the seed methods across theories
#: and seed 003's correction on the shapes (its ray distance to the shape's parts);
#: each is a new method of a scene, every cell of a694eb9 stays as it was
ADDED_CELLS = (
    {(sid, m) for sid in ("plate-hole", "plate-l")
     for m in ("surface-nodes", "mirror-nodes", "pddo")}
    | {(sid, "energy-directional") for sid in (
        "bar1d-linear-load", "bar1d-sine-load", "bar1d-traction", "bar1d-uniform-load",
        "body3d-manufactured", "body3d-traction", "plate2d-clamped", "plate2d-plane-strain",
        "stiffness2d-plate", "stiffness3d-box")}
    | {(sid, m) for sid in ("sheet2d-clamped", "sheet2d-tension", "stiffness2d-sheet",
                            "stiffness3d-box-bond")
       for m in ("taylor-fictitious", "surface-nodes", "mirror-nodes")}
    | {(sid, "pddo") for sid in ("sheet2d-clamped", "sheet2d-tension")}
    | {("block2d-indentation", "virtual-nodes")}
    | {(sid, m) for sid in ("bar1d-homogenization", "bar1d-constraints")
       for m in ("taylor-fictitious", "surface-nodes", "pddo", "mirror-nodes")}
    | {(sid, "energy-directional") for sid in (
        "plate-hole", "plate-l", "plate-crack", "plate-edge-crack", "plate-inclined-crack",
        "cylinder3d-tension", "block3d-cavity")}
    | {(sid, m) for sid in ("cylinder3d-tension", "block3d-cavity")
       for m in ("mirror-nodes", "surface-nodes", "pddo", "taylor-fictitious")}
    # issue 54: Taylor's one-sided fictitious nodes on crack faces
    | {(sid, "taylor-fictitious") for sid in ("plate-crack", "plate-edge-crack",
                                              "plate-inclined-crack")}
    # issue 54: surface nodes on crack faces, the pins' conditions on their partners
    | {(sid, "surface-nodes") for sid in ("plate-crack", "plate-edge-crack",
                                          "plate-inclined-crack")}
    # issue 54/55 (LAMMPS): peri/lps energies on the LPS stiffness boxes (pe/atom
    # corrected) and its fix nve on seed 004's vibrating bar
    | {("stiffness3d-box", "peer:lammps"), ("stiffness2d-plate", "peer:lammps"),
       ("bar1d-vibration", "peer:lammps")}
    # and on the crack scenes (atom types keep it from bonding across the slit)
    | {(sid, "peer:lammps") for sid in ("plate-crack", "plate-edge-crack",
                                        "plate-inclined-crack")}
    # and on the 3D shapes (their node sets and parts as on the 2D shapes)
    | {(sid, "peer:lammps") for sid in ("cylinder3d-tension", "block3d-cavity")})


#: choices a parameter gained since a694eb9, each named by its issue: (scene, param) ->
#: the added choice (issue 55: whole-cell quadrature on the LPS stiffness boxes, which
#: LAMMPS's same-model run needs, as on body3d-traction)
WIDENED_CHOICES = {("stiffness3d-box", "quadrature"): "'full-cells'",
                   ("stiffness2d-plate", "quadrature"): "'full-cells'"}


def _narrowed(sid, q):
    """A parameter's surface entry without the choice it gained (WIDENED_CHOICES)."""
    extra = WIDENED_CHOICES.get((sid, q["name"]))
    if extra is None:
        return q
    assert q["choices"][-1] == extra, (sid, q["name"])
    return {**q, "choices": q["choices"][:-1]}


def test_parameter_surface_unchanged():
    """Every scene's and method's parameters (name, default, type, unit, choices,
    scene_default, the check's verdict on probe values) and resolved defaults as at
    a694eb9; only the help texts were unified. Methods a scene gained since are the
    cells of :data:`ADDED_CELLS`, no others."""
    before = json.loads((DATA / "param_surface_a694eb9.json").read_text())
    after = json.loads(json.dumps(surface()))
    # scenes added since, each named by its issue (their own tests cover their params)
    new_scenes = {"wave2d-manufactured", "wave3d-manufactured", "wave2d-pulse"}   # issue 56
    assert sorted(after) == sorted([*before, *new_scenes])
    added = set()
    for sid in before:
        params = [_narrowed(sid, q) for q in after[sid]["params"]]
        assert params == before[sid]["params"], sid
        for m, entry in before[sid]["methods"].items():
            assert after[sid]["methods"].get(m) == entry, (sid, m)
        added |= {(sid, m) for m in after[sid]["methods"] if m not in before[sid]["methods"]}
    assert added == ADDED_CELLS


def test_shared_quantities_declared_once():
    """E, nu, spacing, m_ratio and horizon are declared by the shared parameter sets of
    pdverify/params.py only, never by a scene module (a scene passes its defaults)."""
    import re
    pattern = re.compile(r"""Param\(\s*["'](E|nu|spacing|m_ratio|horizon|thickness)["']""")
    scenes = Path(__file__).parents[1] / "pdverify" / "scenes"
    found = [f"{path.name}: {m.group(0)}" for path in sorted(scenes.glob("*.py"))
             for m in pattern.finditer(path.read_text())]
    assert not found, found


def test_treatments_speak_face_names_only():
    """The treatments read a face as a ``Face`` (``face.axis``, ``face.side``,
    ``face.sign``) looked up by its name, never as a number ``2 * axis + side`` split by
    ``divmod`` or converted from a name (issue 51: face names only). The grid's arrays
    keep the integer code, read through ``Face.code`` / ``grid.surface_on`` only."""
    import re
    pattern = re.compile(r"divmod\(\s*face|face_number\(")
    corrections = Path(__file__).parents[1] / "pdverify" / "corrections"
    found = [f"{path.relative_to(corrections)}:{n}: {line.strip()}"
             for path in sorted(corrections.rglob("*.py"))
             for n, line in enumerate(path.read_text().splitlines(), 1)
             if pattern.search(line)]
    assert not found, found


def test_treatments_never_ask_the_solver_layer_what_to_build():
    """A treatment assembles one form of its system (the state-based ones: the augmented
    form, ``LinearSystem.scalars``) and the solver layer's front door forms what its
    solver needs (issue 51): no treatment module imports the solver policy or branches on
    the solver's name."""
    import ast
    corrections = Path(__file__).parents[1] / "pdverify" / "corrections"
    found = []
    for path in sorted(corrections.rglob("*.py")):
        tree = ast.parse(path.read_text())
        for node in ast.walk(tree):
            if isinstance(node, ast.ImportFrom) and node.module and "policy" in node.module:
                found.append(f"{path.name}:{node.lineno}: imports {node.module}")
            if (isinstance(node, ast.Compare) and isinstance(node.left, ast.Name)
                    and node.left.id == "solver"):
                found.append(f"{path.name}:{node.lineno}: compares the solver's name")
    assert not found, found
