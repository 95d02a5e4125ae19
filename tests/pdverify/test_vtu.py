"""Every field file of a report opens with meshio and pyvista and holds the values of its
run in results.json (issue: report, VTU export)."""
from __future__ import annotations

import json
import os
import subprocess
import sys

import meshio
import numpy as np
import pytest

pv = pytest.importorskip("pyvista")

REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
# one scene per rule of pdverify.export: several node sets (constraints), snapshots in
# time (wave), a FEM grid (sheet), 1D, 2D and 3D displacement fields
SCENES = ["bar1d-traction", "bar1d-constraints", "wave1d-surface-nodes", "sheet2d-clamped",
          "plate2d-plane-strain", "body3d-traction"]
# ||u - u_ref|| / ||u_ref|| summed in another order than the scene's: rounding only,
# a few N * eps for N <= 1e4 nodes
NORM_RTOL = 1e-12


@pytest.fixture(scope="module")
def report(tmp_path_factory):
    out = tmp_path_factory.mktemp("vtu") / "report"
    proc = subprocess.run([sys.executable, "-m", "pdverify", "report", "--quick", "--only",
                           *SCENES, "--out", str(out)], cwd=REPO, capture_output=True,
                          text=True, timeout=900)
    assert proc.returncode == 0, proc.stderr[-2000:]
    with open(out / "results.json") as fh:
        return out, json.load(fh)


@pytest.mark.slow  # slow tier (issue 32): its report 292 s of the suite's 3811 s (loaded machine)
def test_every_run_with_fields_has_files_and_no_stray_files(report):
    out, doc = report
    listed = {f for r in doc["runs"] for f in r.get("files", [])}
    on_disk = {os.path.join("fields", f) for f in os.listdir(out / "fields")}
    assert listed == on_disk
    # every PD run of these scenes keeps node fields, every FEM run its grid
    assert all(r.get("files") for r in doc["runs"]), [
        (r["scene"], r["method"]) for r in doc["runs"] if not r.get("files")]
    fem = [r for r in doc["runs"] if r["method"] == "fem"]
    assert fem and all(any(f.endswith("-fem-grid.vtu") for f in r["files"]) for r in fem)
    for f in listed:  # readable by others: the umask's mode, not mkstemp's 0600
        assert os.stat(out / f).st_mode & 0o044 == 0o044 & ~_umask()


def _umask() -> int:
    current = os.umask(0)
    os.umask(current)
    return current


@pytest.mark.slow  # slow tier (issue 32): shares the 292 s report (loaded machine)
def test_files_open_and_hold_the_runs_values(report):
    out, doc = report
    checked_norms = 0
    for run in doc["runs"]:
        for f in run.get("files", []):
            mesh = meshio.read(out / f)
            grid = pv.read(out / f)
            assert grid.n_points == len(mesh.points) > 0
            # the run's metrics, bit for bit (float64 in both files)
            for name, value in run["metrics"].items():
                if isinstance(value, (int, float)):
                    assert mesh.field_data[f"metric:{name}"][0] == value, (f, name)
                    assert grid.field_data[f"metric:{name}"][0] == value, (f, name)
            for name, values in mesh.point_data.items():  # same arrays through pyvista
                np.testing.assert_array_equal(grid.point_data[name], values)
            pd = mesh.point_data
            if {"u", "u_ref"} <= set(pd) and "rel_l2_error" in run["metrics"]:
                e = np.linalg.norm(pd["u"] - pd["u_ref"]) / np.linalg.norm(pd["u_ref"])
                ref = run["metrics"]["rel_l2_error"]
                assert e == pytest.approx(ref, rel=NORM_RTOL, abs=1e-300), (f, e, ref)
                checked_norms += 1
    # 1D, 2D and 3D runs of four scenes recompute their error from the file
    assert checked_norms >= 20


@pytest.mark.slow  # slow tier (issue 32): shares the 292 s report (loaded machine)
def test_node_sets_and_snapshots(report):
    out, doc = report
    by = {(r["scene"], r["method"]): r for r in doc["runs"]}
    constraints = by[("bar1d-constraints", "none")]["files"]
    assert len(constraints) == 3 and all(meshio.read(out / f).point_data["u"].ndim == 1
                                         for f in constraints)
    wave = meshio.read(out / by[("wave1d-surface-nodes", "surface-nodes")]["files"][0])
    assert {"u_t0", "u_ref_t0", "u_classical_t0"} <= set(wave.point_data)
    body = meshio.read(out / by[("body3d-traction", "none")]["files"][0])
    assert body.points.shape[1] == 3 and body.point_data["u"].shape[1] == 3


def test_run_vtu_writes_the_same_file(tmp_path):
    proc = subprocess.run([sys.executable, "-m", "pdverify", "run", "bar1d-traction",
                           "--vtu", str(tmp_path / "bar.vtu"), "--json", str(tmp_path / "r.json")],
                          cwd=REPO, capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stderr
    with open(tmp_path / "r.json") as fh:
        run = json.load(fh)["runs"][0]
    assert run["files"] == [str(tmp_path / "bar.vtu")]
    mesh = meshio.read(tmp_path / "bar.vtu")
    assert mesh.field_data["metric:max_error_pct"][0] == run["metrics"]["max_error_pct"]
    bad = subprocess.run([sys.executable, "-m", "pdverify", "run", "bar1d-traction", "--vtu",
                          str(tmp_path / "bar.txt")], cwd=REPO, capture_output=True, text=True)
    assert bad.returncode == 2 and "must end in .vtu" in bad.stderr
