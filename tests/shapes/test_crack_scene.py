"""The ``plate-crack`` scene (issue 54): its runs repeat the study of
``benchmarks/crack_k.py``, a crack of zero length is the uncracked plate, the treatments
that cannot serve crack faces say why, bad input is one line."""
import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from pdverify.scenes import get_scene

RECORD = (Path(__file__).resolve().parents[2] / "benchmarks" / "records"
          / "crack_k-2026-11-28-default.json")


def _run(tmp_path, *sets, method="none"):
    out = tmp_path / "run.json"
    r = subprocess.run([sys.executable, "-m", "pdverify", "run", "plate-crack", "--method",
                        method, *[a for s in sets for a in ("--set", s)], "--json", str(out)],
                       capture_output=True, text=True)
    return r, (json.loads(out.read_text())["runs"][0] if r.returncode == 0 else None)


def test_the_uncorrected_k_is_the_studys_at_h_1_40(tmp_path):
    """The scene builds the study's problem (one builder, ``pdverify.scenes.cracks``) and
    measures K with the study's fit, so K_PD / K_FEM and the opening error equal the
    record's. Tolerance 1e-8 relative: two solves of one system differ by at most its
    condition number times the backward error, and the refinement stops at 2 eps
    (``solvers.mixed.REFINE_STOP``): 1e-8 allows a condition up to ~2e7, the
    single-precision factor's own limit (``solvers.mixed``)."""
    rows = json.loads(RECORD.read_text())["results"]["rows"]
    study = next(r for r in rows if r["method"] == "none" and r["spacing"] == 0.025)
    r, run = _run(tmp_path)
    assert r.returncode == 0, r.stderr
    m = run["metrics"]
    assert m["k_ratio"] == pytest.approx(study["k_over_fem"], rel=1e-8)
    assert m["k_error_pct"] == pytest.approx(100 * (study["k_over_fem"] - 1), rel=1e-7)
    assert m["opening_error_pct"] == pytest.approx(study["opening_err_pct"], rel=1e-8)
    assert m["k_fit_bias_pct"] == pytest.approx(100 * (study["k_fit_fem_over_fem"] - 1),
                                                rel=1e-7)
    # the field metrics leave the tip zone out: 2 horizons of either tip
    h, delta = 0.025, 0.075
    assert m["tip_zone_nodes"] == 2 * sum(
        1 for i in range(-20, 20) for j in range(-20, 20)
        if np.hypot((i + 0.5) * h, (j + 0.5) * h) < 2 * delta)
    assert run["params"]["spacing"] == 0.025 and run["params"]["m_ratio"] == 3.0


def test_a_crack_of_zero_length_is_the_uncracked_plate():
    """The stiffness of the plate with a = 0 equals, bit for bit, that of the same polygon
    without cracks (``pd.shapes``: a crack of zero length is no crack); with a = 0.5 it
    does not (the check can fail)."""
    from dataclasses import replace

    from pdverify.corrections.plain import assemble_plain
    from pdverify.scenes.cracks import cracked_plate, plate_outline
    scene = get_scene("plate-crack")
    p = {**scene.default_params(), "spacing": 0.25}

    def stiffness(shape):
        problem = replace(scene.problem(p, "test"), shape=shape)
        return assemble_plain(problem, None).K.tocsr()

    k0 = stiffness(cracked_plate(1.0, 3.0, 0.0, 0.25))
    kp = stiffness(plate_outline(1.0, 3.0, 0.25))
    assert k0.shape == kp.shape and (k0 != kp).nnz == 0
    kc = stiffness(cracked_plate(1.0, 3.0, 0.5, 0.25))
    assert (kc != kp).nnz > 0


@pytest.mark.parametrize("scene_id", ["plate-crack", "plate-edge-crack"])
def test_the_list_shows_why_the_node_adding_treatments_do_not_run(scene_id):
    out = subprocess.run([sys.executable, "-m", "pdverify", "list", scene_id],
                         capture_output=True, text=True, check=True).stdout
    for method in ("mirror-nodes", "pddo"):
        assert f"{method}: crack faces are not served yet: its shape form" in out, method
    refused = out.split("not offered here")[1]
    assert "taylor-fictitious: " not in refused
    assert "surface-nodes: " not in refused         # its pins: surface_nodes_on_shape
    # LAMMPS runs here (its atom types keep it from bonding across the crack:
    # tests/peers/test_lammps.py)
    assert "peer:lammps: its code builds its own bonds" not in out
    offered = set(get_scene(scene_id).offered())
    assert offered == {"none", "energy", "volume", "pals", "energy-directional",
                       "taylor-fictitious", "surface-nodes", "peer:lammps"}


def test_the_cases_are_every_method_at_the_defaults_and_the_quick_grid():
    scene = get_scene("plate-crack")
    cases = scene.cases()
    assert {m for m, _ in cases} == {"fem", "none", "energy", "volume", "pals",
                                     "energy-directional", "taylor-fictitious",
                                     "surface-nodes"}
    ordered = ("taylor-fictitious", "surface-nodes")
    assert all(q == ({"order": 1} if m in ordered else {}) for m, q in cases)
    quick = scene.cases(quick=True)
    assert {m for m, _ in quick} == {m for m, _ in cases}
    assert {q.get("spacing") for m, q in quick if m != "fem"} == {1 / 30}
    d = scene.discretisation(scene.default_params())
    assert (d.h, d.delta) == pytest.approx((0.025, 0.075), rel=1e-15)   # m = 3, round-off


@pytest.mark.parametrize("assignment, words", [
    ("spacing=0.3", "must divide"),                 # the tips off the cell faces
    ("jitter=0.1", "allowed 0 only"),               # the fit pairs lattice nodes
    ("m_ratio=8", "fewer than two spacings"),       # the fit's window too short
])
def test_bad_input_is_one_line_before_any_work(tmp_path, assignment, words):
    r, _ = _run(tmp_path, assignment)
    assert r.returncode == 2
    assert words in r.stderr and len(r.stderr.strip().splitlines()) == 1


@pytest.mark.parametrize("scene_id", ["plate-crack", "plate-edge-crack"])
def test_export_refuses_the_cracked_plate_with_its_reason(tmp_path, scene_id):
    """A node set carries no cut bonds: another code would bond across the slit."""
    from pdverify.exchange import exportable_ids
    assert scene_id not in exportable_ids() and "plate-hole" in exportable_ids()
    r = subprocess.run([sys.executable, "-m", "pdverify", "export", scene_id,
                        "--format", "csv", "--out", str(tmp_path / "x")],
                       capture_output=True, text=True)
    assert r.returncode == 2 and "would bond across the slit" in r.stderr
    assert not (tmp_path / "x").exists()


def test_the_edge_crack_scene_shares_the_centre_cracks_builder_and_refines_k():
    """plate-edge-crack is a :class:`CrackScene` like plate-crack (one measure, one set of
    checks); its cases: fem, every method at the defaults (h = 1/40, H = b) and at the
    refinement's spacings (m = 3), the quick grid 1/30."""
    from pdverify.scenes.cracks import CrackScene
    edge, centre = get_scene("plate-edge-crack"), get_scene("plate-crack")
    assert isinstance(edge, CrackScene) and isinstance(centre, CrackScene)
    assert type(edge).measure is type(centre).measure is CrackScene.measure
    p = edge.default_params()
    assert (p["width"], p["height"], p["crack"], p["spacing"], p["m_ratio"]) == (
        1.0, 1.0, 0.5, 0.025, 3.0)
    assert edge.reference_params(p)["height"] == 1.0
    cases = edge.cases()
    methods = {"none", "energy", "volume", "pals", "energy-directional", "taylor-fictitious",
               "surface-nodes"}
    assert {m for m, _ in cases} == methods | {"fem"}
    assert sorted({q.get("spacing", 0.025) for m, q in cases if m != "fem"}) == sorted(
        (1 / 60, 0.025, 1 / 30))
    assert all(q.get("m_ratio", 3.0) == 3.0 for _, q in cases)
    assert {q.get("spacing") for m, q in edge.cases(quick=True) if m != "fem"} == {1 / 30}


def test_the_edge_crack_fem_field_is_the_half_models_mirror_image():
    """u_x even and u_y odd in y; at y >= 0 the half model's own values."""
    scene = get_scene("plate-edge-crack")
    p = scene.default_params()
    field = scene.reference_field(p)
    ref = scene.reference_of(p)
    x = np.array([[0.3, 0.2], [0.7, 0.01], [0.45, 0.6]])
    low = x * [1, -1]
    np.testing.assert_array_equal(field(x), ref.field.evaluate(x))
    np.testing.assert_array_equal(field(low), ref.field.evaluate(x) * [1, -1])
    assert ref.k_ratio == pytest.approx(1.0, abs=5e-3)   # Tada's SENT accuracy, 0.5 %


def test_an_edge_crack_of_zero_length_is_the_uncracked_strip():
    """As for the centre crack: the strip's stiffness with a = 0 equals, bit for bit, that
    of the outline without a crack; with a = 0.5 it does not."""
    from dataclasses import replace

    from pdverify.corrections.plain import assemble_plain
    from pdverify.scenes.cracks import edge_cracked_strip, edge_outline
    scene = get_scene("plate-edge-crack")
    p = {**scene.default_params(), "spacing": 0.125}

    def stiffness(shape):
        problem = replace(scene.problem(p, "test"), shape=shape)
        return assemble_plain(problem, None).K.tocsr()

    k0 = stiffness(edge_cracked_strip(1.0, 1.0, 0.0, 0.125))
    kp = stiffness(edge_outline(1.0, 1.0, 0.125))
    assert k0.shape == kp.shape and (k0 != kp).nnz == 0
    assert (stiffness(edge_cracked_strip(1.0, 1.0, 0.5, 0.125)) != kp).nnz > 0


def test_the_edge_scenes_fem_checks_name_the_edge_reference(tmp_path):
    """The FEM method's bad input is checked as the edge crack's reference (kind fixed)."""
    r = subprocess.run([sys.executable, "-m", "pdverify", "run", "plate-edge-crack",
                        "--method", "fem", "--set", "cells=1"], capture_output=True, text=True)
    assert r.returncode == 2 and len(r.stderr.strip().splitlines()) == 1
    assert "plate-edge-crack --method fem: plate-edge-crack: cells must be 2..64" in r.stderr


@pytest.mark.parametrize("method", ["taylor-fictitious", "surface-nodes"])
def test_taylor_runs_on_the_edge_crack_with_the_tip_and_face_errors(tmp_path, method):
    """Taylor's one-sided fictitious nodes and the surface nodes run on a crack scene
    (order 1, the quick grid; the surface nodes' pin, of length h/2, read by no
    fictitious node, imposes its conditions on its partner: surface_nodes_on_shape,
    a singular system without it); the errors near the tip (the ring of 2 to 5
    horizons) and along the faces are parts of the errors outside the tip zone, on its
    scale."""
    out = tmp_path / "t.json"
    r = subprocess.run([sys.executable, "-m", "pdverify", "run", "plate-edge-crack",
                        "--method", method, "--set", "order=1",
                        "--set", f"spacing={1 / 30!r}", "--json", str(out)],
                       capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    run = json.loads(out.read_text())["runs"][0]
    m = run["metrics"]
    assert run["status"] == "ok"
    assert 0 < m["near_tip_max_error_pct"] <= m["max_error_pct"]
    assert 0 < m["faces_max_error_pct"] <= m["boundary_max_error_pct"]
