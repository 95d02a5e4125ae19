"""pdverify export / score / report --include: a scene's uncorrected problem for another
PD code, and that code's displacements measured as pdverify measures its own runs."""
from __future__ import annotations

import json
import os
import subprocess
import sys
import xml.etree.ElementTree as ET  # the Body Force example (XML)
from pathlib import Path

import meshio
import numpy as np
import pytest

from pdverify.cli import main
from pdverify.exchange import MATCH_TOLERANCE, NO_EXPORT_WARNING
from pdverify.scenes import get_scene

ROOT = Path(__file__).resolve().parents[2]
DATA = ROOT / "tests" / "data" / "external_decks"
FORMATS = ("csv", "vtu", "peridigm", "perilab")
# Scoring puts the same doubles where the solve put its solution and runs the same
# measure: the metrics agree to the last bit. The text formats hold each double with
# repr (17 significant digits, read back exactly), so 1e-12 relative is a ceiling that
# only a lost digit or a different arithmetic would break.
METRIC_RTOL = 1e-12


def _native(scene_id, overrides=None):
    r = get_scene(scene_id).run("none", overrides or {})
    assert r.status == "ok", r.message
    x = np.asarray(r.fields["x"], dtype=float).reshape(len(r.fields["u"]), -1)
    u = np.asarray(r.fields["u"], dtype=float).reshape(len(x), -1)
    return r, x, u


def _exported_positions(folder: Path, fmt: str, dim: int) -> np.ndarray:
    """The node positions as a user reads them from the exported files of ``fmt``."""
    if fmt == "csv":
        rows = (folder / "nodes.csv").read_text().splitlines()
        assert rows[0].split(",")[1:1 + dim] == [f"{a} [m]" for a in "xyz"[:dim]]
        return np.array([[float(v) for v in r.split(",")[1:1 + dim]] for r in rows[1:]])
    if fmt == "vtu":
        return meshio.read(folder / "nodes.vtu").points[:, :dim]
    if fmt == "peridigm":
        lines = (folder / "peridigm" / "nodes.txt").read_text().splitlines()
        return np.array([[float(v) for v in ln.split()[:dim]] for ln in lines[1:]])
    if fmt == "lammps":   # nodes.data's Atoms section: id type volume density x y z
        lines = (folder / "lammps" / "same-model" / "nodes.data").read_text().splitlines()
        atoms = lines[lines.index("Atoms # peri") + 2:]
        return np.array([[float(v) for v in ln.split()[4:4 + dim]] for ln in atoms if ln])
    lines = (folder / "perilab" / "mesh.txt").read_text().splitlines()
    return np.array([[float(v) for v in ln.split()[:dim]] for ln in lines[1:]])


def _write_csv(path, x, u, reverse=True):
    """Positions and displacements as a user sends them back (rows in another order)."""
    d = x.shape[1]
    order = np.arange(len(x))[::-1] if reverse else np.arange(len(x))
    with open(path, "w") as fh:
        fh.write(",".join([f"{a} [m]" for a in "xyz"[:d]] + [f"u{a} [m]" for a in "xyz"[:d]])
                 + "\n")
        for i in order:
            fh.write(",".join(repr(float(v)) for v in (*x[i], *u[i])) + "\n")


def _write_vtu(path, x, u):
    pts = np.zeros((len(x), 3))
    pts[:, :x.shape[1]] = x
    disp = np.zeros((len(x), 3))
    disp[:, :u.shape[1]] = u
    meshio.write(path, meshio.Mesh(pts, [("vertex", np.arange(len(x)).reshape(-1, 1))],
                                   point_data={"displacement": disp}))


def _solution_at(x_native, u_native, positions):
    """pdverify's own solution at the exported positions (one match per node)."""
    from scipy.spatial import cKDTree
    dist, k = cKDTree(x_native).query(positions)
    assert dist.max() == 0.0 and len(set(k.tolist())) == len(k)
    return u_native[k]


def _assert_same_metrics(native, scored):
    # score adds the field's equilibrium residual in the scene's linear model: our own
    # solution, read back exactly, balances to round-off (a direct solve: ~1e-14)
    assert scored["metrics"]["equilibrium_residual"] < 1e-10
    # the distance to a direct solve: 0 for a direct solve read back, 1.3e-7 for a
    # single-precision factor refined in double (plate2d-plane-strain's nested
    # dissection): below nodeset.DISTANCE_FLOOR, the solvers' forward error
    from pdverify.nodeset import DISTANCE_FLOOR
    assert scored["metrics"]["equilibrium_distance"] < DISTANCE_FLOOR
    assert set(scored["metrics"]) - {"equilibrium_residual", "equilibrium_distance"} == set(
        native.metrics)
    for name, value in native.metrics.items():
        np.testing.assert_allclose(scored["metrics"][name], value, rtol=METRIC_RTOL,
                                   atol=0.0, err_msg=name)


def _round_trip(tmp_path, capsys, scene_id, overrides, formats=FORMATS):
    """Each format out and both ways back: the CSV inside the export folder with the
    export's --set (the export is found above the file), the VTU outside it with
    --export and no --set (the params come from the export's problem.json)."""
    native, x, u = _native(scene_id, overrides)
    sets = [a for k, v in overrides.items() for a in ("--set", f"{k}={v}")]
    for fmt in formats:
        folder = tmp_path / f"export-{fmt}"
        assert main(["export", scene_id, *sets, "--format", fmt, "--out", str(folder)]) == 0
        positions = _exported_positions(folder, fmt, x.shape[1])
        back = _solution_at(x, u, positions)
        for kind in ("csv", "vtu"):
            if kind == "csv":
                (folder / "results").mkdir()
                sent = folder / "results" / "back.csv"
                how = sets
            else:
                sent = tmp_path / f"{fmt}-back.vtu"
                how = ["--export", str(folder)]
            (_write_csv if kind == "csv" else _write_vtu)(sent, positions, back)
            record = tmp_path / f"{fmt}-{kind}.json"
            assert main(["score", scene_id, str(sent), *how, "--name", "selftest",
                         "--out", str(record)]) == 0, capsys.readouterr().err
            run = json.loads(record.read_text())["runs"][0]
            assert run["method"] == "external:selftest"
            assert run["params"] == json.loads(json.dumps(native.params))
            assert run["diagnostics"]["external"]["prescribed_max_deviation_m"] == 0.0
            assert run["diagnostics"]["external"]["export"]["folder"] == str(folder)
            assert run["diagnostics"]["external"]["export"]["params"] == run["params"]
            assert run["warnings"] == []
            assert run["timings"] == {"setup_s": 0.0, "solve_s": 0.0, "total_s": 0.0}
            _assert_same_metrics(native, run)
    capsys.readouterr()


def test_round_trip_bar(tmp_path, capsys):
    _round_trip(tmp_path, capsys, "bar1d-traction", {})


@pytest.mark.slow   # the plate's FEM reference, cold in the session's cache: ~9 s
def test_round_trip_plate(tmp_path, capsys):
    _round_trip(tmp_path, capsys, "plate2d-clamped", {})


def test_round_trip_shape_with_cut_cells(tmp_path, capsys):
    """A body that is not a box (issue 35): the plate with a hole at h = 0.05 (cut cells,
    part-keyed conditions, FEM reference), every format and both ways back."""
    _round_trip(tmp_path, capsys, "plate-hole", {"spacing": 0.05})


def test_round_trip_plane_strain_plate(tmp_path, capsys):
    """A 2D case in the fast tier (analytic reference, no FEM to compute): seed 001's
    plane-strain plate, a traction face and prescribed components."""
    _round_trip(tmp_path, capsys, "plate2d-plane-strain", {"spacing": 0.1})


@pytest.mark.parametrize("scene_id, overrides", [
    ("body3d-traction", {"spacing": 0.125}),           # 3D, a traction face
    ("plate2d-plane-strain", {"solver": "nested-dissection"}),  # the augmented system
    ("bar1d-sine-load", {}),                            # a load that varies node to node
])
def test_round_trip_csv_other_scenes(tmp_path, capsys, scene_id, overrides):
    """3D, and a system with the dilatations as unknowns (score fills them from the
    displacements; the metrics read only displacements and reactions of K x - rhs)."""
    native, x, u = _native(scene_id, overrides)
    sets = [a for k, v in overrides.items() for a in ("--set", f"{k}={v}")]
    _write_csv(tmp_path / "back.csv", x, u)
    assert main(["score", scene_id, str(tmp_path / "back.csv"), *sets, "--name", "c",
                 "--out", str(tmp_path / "r.json")]) == 0, capsys.readouterr().err
    _assert_same_metrics(native, json.loads((tmp_path / "r.json").read_text())["runs"][0])


def test_loads_and_conditions_are_the_none_system(tmp_path):
    """The exported forces and prescribed values are the uncorrected system's: the bar's
    end force on its last node, u_cl(x_1) on its first; the plate's body load b V."""
    assert main(["export", "bar1d-traction", "--format", "csv", "--out",
                 str(tmp_path / "bar")]) == 0
    loads = (tmp_path / "bar" / "loads.csv").read_text().splitlines()
    assert loads[0] == "node,x [m],fx [N],bx [N/m^3]"
    assert len(loads) == 2
    node, x, fx, bx = loads[1].split(",")
    # the last node's centre 0.975 m (one rounding of i h + h/2), the end force 1e4 N
    # exactly, its density f / (A h) = 1e4 / 5e-4
    assert node == "20" and float(x) == pytest.approx(0.975, rel=2 * np.finfo(float).eps)
    assert float(fx) == 1e4 and float(bx) == pytest.approx(2e7, rel=2 * np.finfo(float).eps)
    fixed = (tmp_path / "bar" / "prescribed_ux.csv").read_text().splitlines()
    assert fixed[0] == "node,x [m],ux [m]" and len(fixed) == 2
    # u_cl(x_1) = F x_1 / (E A) = 1e4 * 0.025 / (1e9 * 0.01), one rounding
    assert float(fixed[1].split(",")[2]) == pytest.approx(2.5e-5, rel=4 * np.finfo(float).eps)


# ------------------------------------------------------------------------------ mismatch
@pytest.fixture
def bar_back(tmp_path):
    _, x, u = _native("bar1d-traction")
    return tmp_path, x, u


@pytest.mark.parametrize("change, needle", [
    ("moved", "node 20 of the file at (0.97505"),
    ("missing", "19 nodes, the exported set has 20; exported node 1 at (0.025)"),
    ("extra", "node 21 of the file at (1.025)"),
    ("duplicate", "node 21 of the file at (0.975) matches exported node 20"),
])
def test_node_mismatch_is_refused(bar_back, capsys, change, needle):
    tmp_path, x, u = bar_back
    x, u = x.copy(), u.copy()
    if change == "moved":   # 1e-3 spacings is the tolerance: 1.1e-3 spacings off
        x[-1, 0] += 1.1 * MATCH_TOLERANCE * 0.05
    elif change == "missing":
        x, u = x[1:], u[1:]
    elif change == "extra":
        x, u = np.r_[x, [[1.025]]], np.r_[u, u[-1:]]
    else:
        x, u = np.r_[x, x[-1:]], np.r_[u, u[-1:]]
    sent = tmp_path / "back.csv"
    _write_csv(sent, x, u, reverse=False)
    out = tmp_path / "never.json"
    assert main(["score", "bar1d-traction", str(sent), "--name", "c", "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and needle in err, err
    assert not out.exists()


def test_other_prescribed_values_are_scored_and_warned(bar_back, capsys):
    """A code that imposed another value on the prescribed node: its displacements are
    scored as given (the error shows it) and the record warns."""
    tmp_path, x, u = bar_back
    u = u.copy()
    u[0, 0] = 0.0        # the bar's first node, prescribed at u_cl(x_1) = 2.5e-5 m
    _write_csv(tmp_path / "back.csv", x, u)
    out = tmp_path / "r.json"
    assert main(["score", "bar1d-traction", str(tmp_path / "back.csv"), "--name", "c",
                 "--out", str(out)]) == 0
    run = json.loads(out.read_text())["runs"][0]
    # |0 - u_cl(x_1)|, u_cl(x_1) = 1e4 * 0.025 / (1e9 * 0.01): a few roundings
    assert run["diagnostics"]["external"]["prescribed_max_deviation_m"] == pytest.approx(
        2.5e-5, rel=4 * np.finfo(float).eps)
    # the file was scored without an export (issue 49: the record says so), and warned
    assert len(run["warnings"]) == 2 and run["warnings"][0] == NO_EXPORT_WARNING
    assert "prescribed nodes" in run["warnings"][1]


def test_node_within_tolerance_is_accepted(bar_back, capsys):
    tmp_path, x, u = bar_back
    x = x.copy()
    x[-1, 0] += 0.9 * MATCH_TOLERANCE * 0.05
    _write_csv(tmp_path / "back.csv", x, u)
    assert main(["score", "bar1d-traction", str(tmp_path / "back.csv"), "--name", "c"]) == 0


# ------------------------------------------------------------------------------ bad input
def test_bad_input_is_one_line_exit_2(tmp_path, capsys):
    foreign = tmp_path / "mine"
    foreign.mkdir()
    (foreign / "notes.txt").write_text("keep me")
    good = tmp_path / "good.csv"
    _, x, u = _native("bar1d-traction")
    _write_csv(good, x, u)
    nocols = tmp_path / "nocols.csv"
    nocols.write_text("x,uy\n0.025,0\n")
    binary = tmp_path / "binary.csv"
    binary.write_bytes(b"\xff\xfe\x00garbage")
    badvtu = tmp_path / "bad.vtu"
    badvtu.write_text("not xml")
    native = tmp_path / "native.json"
    assert main(["run", "bar1d-traction", "--method", "none", "--json", str(native)]) == 0
    cases = [
        (["export", "bar1d-tracton", "--format", "csv", "--out", str(tmp_path / "a")],
         "did you mean bar1d-traction"),
        # the list follows the scenes' registration order (which test imported which
        # scene module first): any order
        (["export", "bar1d-vibration", "--format", "csv", "--out", str(tmp_path / "a")],
         "these can: "),
        (["export", "bar1d-traction", "--method", "taylor-fictitious", "--format", "csv",
          "--out", str(tmp_path / "a")], "only the uncorrected problem"),
        (["export", "bar1d-traction", "--format", "abaqus", "--out", str(tmp_path / "a")],
         "invalid choice: 'abaqus'"),
        (["export", "bar1d-traction", "--format", "csv", "--out", str(foreign)],
         "holds no pdverify export"),
        (["export", "bar1d-traction", "--set", "nu=0.5", "--format", "csv", "--out",
          str(tmp_path / "a")], "nu"),
        (["score", "bar1d-traction", str(tmp_path / "none.csv"), "--name", "c"],
         "does not exist"),
        (["score", "bar1d-traction", str(nocols), "--name", "c"], "missing column(s) ux"),
        (["score", "bar1d-traction", str(good), "--name", ""], "--name"),
        (["score", "bar1d-traction", str(good), "--name", "c", "--out", str(good)],
         "displacement file"),
        (["score", "bar1d-vibration", str(good), "--name", "c"], "cannot be exported"),
        (["score", "bar1d-traction", str(binary), "--name", "c"], "cannot be read"),
        (["score", "bar1d-traction", str(badvtu), "--name", "c"], "cannot be read as vtu"),
        (["score", "bar1d-traction", str(tmp_path), "--name", "c"], "is a folder"),
        (["report", "--quick", "--only", "bar1d-traction", "--include",
          str(tmp_path / "none.json"), "--out", str(tmp_path / "rep")], "does not exist"),
        (["report", "--quick", "--only", "bar1d-traction", "--include", str(native),
          "--out", str(tmp_path / "rep")], "not an external run"),
        (["report", "--quick", "--only", "bar1d-traction", "--include", str(good),
          "--out", str(tmp_path / "rep")], "not valid JSON"),
    ]
    for argv, needle in cases:
        assert main(argv) == 2, argv
        err = capsys.readouterr().err
        assert err.count("\n") == 1 and needle in err, (argv, err)
    assert (foreign / "notes.txt").read_text() == "keep me"
    assert not (tmp_path / "a").exists() and not (tmp_path / "rep").exists()


def test_export_replaces_only_its_own_folder(tmp_path, capsys):
    out = tmp_path / "exp"
    assert main(["export", "bar1d-traction", "--format", "peridigm", "--out", str(out)]) == 0
    # a previous export is replaced as a whole: no peridigm/ files left by a csv export
    assert main(["export", "bar1d-traction", "--format", "csv", "--out", str(out)]) == 0
    assert not (out / "peridigm").exists() and (out / "nodes.csv").exists()
    (out / "mine.txt").write_text("x")
    assert main(["export", "bar1d-traction", "--format", "csv", "--out", str(out)]) == 2
    assert "'mine.txt'" in capsys.readouterr().err
    assert (out / "mine.txt").read_text() == "x"


def _write_exodus(path, x, u, names, layout):
    """An Exodus II file as NetCDF classic (64-bit offset), the subset a reader needs:
    coordinates, nodal variable names, and two time steps (zero, then ``u``) in
    ``layout`` ``per-variable`` (vals_nod_var1, ...) or ``combined`` (vals_nod_var)."""
    from scipy.io import netcdf_file
    n, d = x.shape
    with netcdf_file(path, "w", version=2) as nc:
        nc.createDimension("num_nodes", n)
        nc.createDimension("time_step", 2)
        nc.createDimension("num_nod_var", d)
        nc.createDimension("len_name", 33)
        nc.createVariable("time_whole", "d", ("time_step",))[:] = [0.0, 1.0]
        for k, a in enumerate("xyz"):
            nc.createVariable(f"coord{a}", "d", ("num_nodes",))[:] = (
                x[:, k] if k < d else np.zeros(n))
        nc.createVariable("name_nod_var", "c", ("num_nod_var", "len_name"))[:] = np.array(
            [list(name.ljust(33, "\0")) for name in names], dtype="S1")
        steps = np.stack([np.zeros_like(u), u])            # (time, node, component)
        if layout == "per-variable":
            for k in range(d):
                nc.createVariable(f"vals_nod_var{k + 1}", "d",
                                  ("time_step", "num_nodes"))[:] = steps[:, :, k]
        else:
            nc.createVariable("vals_nod_var", "d", ("time_step", "num_nod_var",
                                                    "num_nodes"))[:] = steps.transpose(0, 2, 1)


@pytest.mark.parametrize("names, layout", [
    (("DisplacementX", "DisplacementY"), "per-variable"),   # Peridigm's name + "X"
    (("Displacementsx", "Displacementsy"), "combined"),     # PeriLab's name + "x"
])
def test_round_trip_exodus_last_step(tmp_path, capsys, names, layout):
    """An Exodus result (NetCDF classic, read by scipy) scores the native metrics from
    its last time step; its first (the initial zero state) would not."""
    native, x, u = _native("plate2d-plane-strain", {"spacing": 0.1})
    sent = tmp_path / "result.e"
    _write_exodus(sent, x[::-1], u[::-1], names, layout)
    record = tmp_path / "r.json"
    assert main(["score", "plate2d-plane-strain", str(sent), "--set", "spacing=0.1",
                 "--name", "exo", "--out", str(record)]) == 0, capsys.readouterr().err
    run = json.loads(record.read_text())["runs"][0]
    assert run["diagnostics"]["external"]["kind"] == "exodus"
    assert run["diagnostics"]["external"]["time"] == 1.0
    _assert_same_metrics(native, run)


def test_exodus_netcdf4_file_needs_netcdf4(tmp_path, capsys):
    """A NetCDF-4 (HDF5) Exodus file is read through netCDF4; without it the message
    names the package (netCDF4 is not installed on the machine these tests ran on)."""
    import importlib.util
    if importlib.util.find_spec("netCDF4") is not None:
        pytest.skip("netCDF4 is installed: NetCDF-4 Exodus files are read")
    f = tmp_path / "result.e"
    f.write_bytes(b"\x89HDF\r\n\x1a\n")
    assert main(["score", "bar1d-traction", str(f), "--name", "c"]) == 2
    assert "netCDF4" in capsys.readouterr().err


# ------------------------------------------------------------------------------ decks
def _yaml(text: str) -> dict:
    """The block mappings of a deck (what Peridigm's and PeriLab's decks use): nested
    ``key: value`` by indentation, comments and quotes removed. Written here so that the
    test needs no YAML library; a list, flow style or anchor is refused."""
    root: dict = {}
    stack = [(-1, root)]
    for raw in text.splitlines():
        line = raw.split(" #", 1)[0].rstrip() if '"' not in raw else raw.rstrip()
        if not line.strip() or line.lstrip().startswith("#"):
            continue
        indent = len(line) - len(line.lstrip())
        key, sep, value = line.strip().partition(":")
        assert sep and not key.startswith(("-", "[", "{", "&", "*")), raw
        while stack[-1][0] >= indent:
            stack.pop()
        value = value.strip()
        if value.startswith('"') and value.endswith('"'):
            value = value[1:-1]
        if value:
            stack[-1][1][key] = value
        else:
            stack[-1][1][key] = {}
            stack.append((indent, stack[-1][1][key]))
    return root


#: a 1D bar (end force, one prescribed node) and a 2D plate (a traction face, prescribed
#: components on two faces; plane strain)
DECK_SCENES = ("bar1d-traction", "plate2d-plane-strain")


@pytest.fixture(scope="module")
def decks(tmp_path_factory):
    out = {}
    for scene_id in DECK_SCENES:
        for fmt in ("peridigm", "perilab"):
            folder = tmp_path_factory.mktemp(fmt)
            assert main(["export", scene_id, "--format", fmt, "--out",
                         str(folder / "x")]) == 0
            out[scene_id, fmt] = folder / "x" / fmt
    return out


def test_peridigm_deck_matches_its_examples(decks):
    example = _yaml((DATA / "peridigm_wave_in_bar.yaml").read_text())["Peridigm"]
    solver_ex = _yaml((DATA / "peridigm_tensile_test_solver.yaml").read_text())["Solver"]
    materials_ex = _yaml((DATA / "peridigm_Notched_Plate_materials.yaml").read_text())
    body_force = {p.get("value") for p in ET.parse(DATA / "peridigm_Body_Force_QS_bcs.xml")
                  .iter("Parameter") if p.get("name") == "Type"}
    # an excerpt (the opening of a deck): its Discretization list names the key
    infl = (DATA / "peridigm_InfluenceFunction_discretization.xml").read_text()
    header = (DATA / "peridigm_Compression_QS_3x2x2_TextFile.txt").read_text().splitlines()[0]
    for scene_id in DECK_SCENES:
        folder = decks[scene_id, "peridigm"]
        problem = json.loads((folder.parent / "problem.json").read_text())
        deck = _yaml((folder / "pdverify.yaml").read_text())
        assert list(deck) == ["Peridigm"]
        ours = deck["Peridigm"]
        assert set(ours) == set(example) - {"Output"} | {"Output"}
        assert ours["Discretization"]["Type"] == example["Discretization"]["Type"] == "Text File"
        assert set(ours["Discretization"]) - {"Influence Function"} == set(example["Discretization"])
        assert '<Parameter name="Influence Function"' in infl
        (material,) = ours["Materials"].values()
        ex_material = next(iter(materials_ex["Materials"].values()))
        assert material["Material Model"] == ex_material["Material Model"] == "Elastic"
        extra = set(material) - set(ex_material)
        assert extra <= {"Plane Stress", "Plane Strain"}, extra
        src = (DATA / "peridigm_Material_excerpt.cpp").read_text()
        assert all(f'"{k}"' in src for k in extra)
        (block,) = ours["Blocks"].values()
        assert set(block) == set(next(iter(example["Blocks"].values())))
        # the written horizon, with its margin (issue 49), not the model's m h
        assert float(block["Horizon"]) == problem["horizon_written_m"] > problem["horizon_m"]
        kind = problem["material"]["kind"]
        assert material.get("Plane Strain") == ("true" if kind == "plane-strain" else None)
        bcs = ours["Boundary Conditions"]
        ex_bc = next(v for v in example["Boundary Conditions"].values() if isinstance(v, dict))
        sets = {k: v for k, v in bcs.items() if not isinstance(v, dict)}
        assert all(k.startswith("Node Set") for k in sets)
        for name, bc in bcs.items():
            if not isinstance(bc, dict):
                continue
            assert set(bc) == set(ex_bc), name
            assert bc["Type"] in {"Prescribed Displacement"} | body_force
            assert bc["Node Set"] in sets and bc["Coordinate"] in "xyz"
            float(bc["Value"])
        assert set(ours["Solver"]["QuasiStatic"]) == set(solver_ex["QuasiStatic"])
        assert set(ours["Solver"]) - {"QuasiStatic"} <= set(solver_ex) | {"Verbose"}
        # the Text File discretisation: the example's header, x y z block_id volume
        lines = (folder / "nodes.txt").read_text().splitlines()
        assert lines[0] == header == "# x y z block_id volume"
        for ln in lines[1:]:
            x, y, z, block, vol = ln.split()
            assert int(block) == 1 and float(vol) > 0
        # node set files: 1-based ids, one per line, as the example's nodeset_1.txt
        for fname in sets.values():
            ids = [int(v) for v in (folder / fname).read_text().split()]
            assert min(ids) >= 1 and max(ids) <= len(lines) - 1
        assert (DATA / "peridigm_nodeset_1.txt").read_text().split() == ["1", "2", "3", "4"]


def test_perilab_deck_matches_its_examples(decks):
    example = _yaml((DATA / "perilab_ENFmodel.yaml").read_text())["PeriLab"]
    static = _yaml((DATA / "perilab_truss.yaml").read_text())["PeriLab"]["Solver"]
    solid = _yaml((DATA / "perilab_thermal_expansion_PD_Solid_static_head.yaml").read_text())
    ex_material = solid["PeriLab"]["Models"]["Material Models"]["Test"]
    disc_ex = _yaml((DATA / "perilab_DCB_discretization.yaml").read_text())["Discretization"]
    solver_src = (DATA / "perilab_Static_solver_excerpt.jl").read_text()
    for scene_id in DECK_SCENES:
        folder = decks[scene_id, "perilab"]
        problem = json.loads((folder.parent / "problem.json").read_text())
        deck = _yaml((folder / "pdverify.yaml").read_text())
        assert list(deck) == ["PeriLab"]
        ours = deck["PeriLab"]
        assert set(ours) <= set(example) and {"Discretization", "Models", "Blocks",
                                              "Boundary Conditions", "Solver",
                                              "Outputs"} == set(ours)
        disc = ours["Discretization"]
        assert disc["Type"] == "Text File" == example["Discretization"]["Type"]
        assert set(disc) <= set(example["Discretization"]) | set(disc_ex)
        (material,) = ours["Models"]["Material Models"].values()
        assert material["Material Model"] == ex_material["Material Model"] == "PD Solid Elastic"
        assert set(material) <= set(ex_material)
        assert material["Symmetry"] == {"1d": "isotropic plane stress",   # no 1D kind
                                        "plane-strain": "isotropic plane strain"}[
            problem["material"]["kind"]]
        (block,) = ours["Blocks"].values()
        ex_block = example["Blocks"]["block_3"]   # the example's block without damage
        assert set(block) == set(ex_block)
        ex_bc = example["Boundary Conditions"]["BC_2"]
        variables = set()
        for name, bc in ours["Boundary Conditions"].items():
            assert set(bc) == set(ex_bc), name
            assert bc["Type"] == "Dirichlet" and bc["Node Set"] in disc["Node Sets"]
            variables.add(bc["Variable"])
            float(bc["Value"])
        assert variables == {"Displacements", "Forces"}
        assert '"Forces"' in solver_src   # the Static solver applies nodal Forces
        assert set(ours["Solver"]["Static"]) <= set(static["Static"])
        assert set(ours["Solver"]) <= set(static)
        assert set(ours["Outputs"]["Output1"]) <= set(example["Outputs"]["Output1"])
        # the mesh: the example's 2D header (x y block_id volume), also for the 1D bar
        lines = (folder / "mesh.txt").read_text().splitlines()
        ex_mesh = [ln for ln in (DATA / "perilab_test_mesh_2D.txt").read_text().splitlines()
                   if ln.startswith("header")]
        assert lines[0] == ex_mesh[0] == "header: x y block_id volume"
        assert all(len(ln.split()) == 4 for ln in lines[1:])
        ns_header = [ln for ln in (DATA / "perilab_ns_ENFmodel_1.txt").read_text().splitlines()
                     if ln.startswith("header")]
        for fname in disc["Node Sets"].values():
            text = (folder / fname).read_text().splitlines()
            assert text[0] == ns_header[0] == "header: global_id"
            ids = [int(v) for v in text[1:]]
            assert min(ids) >= 1 and max(ids) <= len(lines) - 1


def test_perilab_3d_header():
    from pdverify.decks import perilab_files
    from pdverify.exchange import node_set, scene_of
    ns = node_set(scene_of("body3d-traction"), {"spacing": 0.125})
    mesh = perilab_files(ns)["perilab/mesh.txt"].splitlines()
    ex = [ln for ln in (DATA / "perilab_test_mesh_3D.txt").read_text().splitlines()
          if ln.startswith("header")]
    assert mesh[0] == ex[0] == "header: x y z block_id volume"


# ------------------------------------------------------------------------------ report
@pytest.mark.slow   # a --quick report of one scene in a subprocess: ~15 s
def test_report_include_and_compare(tmp_path):
    _, x, u = _native("bar1d-traction")
    sent = tmp_path / "back.csv"
    _write_csv(sent, x, u)
    record = tmp_path / "ext.json"
    env = {**os.environ, "PYTHONPATH": str(ROOT)}

    def cli(*args):
        return subprocess.run([sys.executable, "-m", "pdverify", *args], capture_output=True,
                              text=True, timeout=600, cwd=ROOT, env=env)

    assert cli("score", "bar1d-traction", str(sent), "--name", "mycode", "--out",
               str(record)).returncode == 0
    out = tmp_path / "rep"
    proc = cli("report", "--quick", "--only", "bar1d-traction", "--include", str(record),
               "--out", str(out), "--jobs", "1")
    assert proc.returncode == 0, proc.stderr[-2000:]
    doc = json.loads((out / "results.json").read_text())
    ext = [r for r in doc["runs"] if r["method"] == "external:mycode"]
    assert len(ext) == 1 and ext[0]["diagnostics"]["external"]["cost_measured"] is False
    assert (out / "figures" / "overview-pareto.png").is_file()
    html = (out / "index.html").read_text()
    assert html.count("external:mycode") >= 2   # the overview's column and the table's row
    assert "external:mycode" in (out / "tables" / "bar1d-traction.csv").read_text()
    # compare sees it: against itself nothing changes; a changed metric is a regression
    assert cli("compare", str(out / "results.json"), str(out / "results.json")).returncode == 0
    worse = json.loads((out / "results.json").read_text())
    run = next(r for r in worse["runs"] if r["method"] == "external:mycode")
    run["metrics"]["max_error_pct"] *= 2
    (tmp_path / "worse.json").write_text(json.dumps(worse))
    proc = cli("compare", str(out / "results.json"), str(tmp_path / "worse.json"))
    assert proc.returncode == 1 and "external:mycode" in proc.stdout
    # only external runs are included
    proc = cli("report", "--quick", "--only", "bar1d-traction", "--include",
               str(out / "results.json"), "--out", str(tmp_path / "rep2"))
    assert proc.returncode == 2 and "not an external run" in proc.stderr


def test_a_shape_body_exports_its_cut_volumes_and_part_loads(tmp_path):
    """A body that is not a box (pdverify.pd.shapes: the quarter plate with a hole), as
    the family's uncorrected model assembles it: the node set holds its real nodes with
    their cut volumes, its prescribed part's nodes, and the loads of its traction parts;
    the CSV and PeriLab writers take it as a box's."""
    from types import SimpleNamespace
    from pdverify.corrections.plain import assemble_plain
    from pdverify.decks import csv_files, perilab_files
    from pdverify.exchange import node_set_of
    from pdverify.pd import StateBasedConstants, get_influence, state_based_stencil
    from pdverify.pd.problem import FaceCondition, StaticProblem
    from pdverify.pd.shapes import quarter_hole
    h, t = 0.05, 0.01
    shape = quarter_hole(1.0, 0.2)
    inf = get_influence("hyperbolic")
    pull = FaceCondition(traction=lambda x, n: np.c_[np.full(len(x), 1e6), np.zeros(len(x))])
    conds = {k: (FaceCondition(prescribed=(0, 1)) if k == "x-" else
                 pull if k == "x+" else FaceCondition()) for k in shape.part_names}
    problem = StaticProblem(tuple(np.subtract(shape.upper, shape.lower)), (0.0, 0.0), h,
                            state_based_stencil(2, 3.0, h, inf, "partial-volume"),
                            StateBasedConstants("plane-stress", 1e9, 0.3), inf, conds,
                            exact=lambda x: np.zeros_like(x), thickness=t, solver="direct",
                            shape=shape)
    system = assemble_plain(problem)
    scene = SimpleNamespace(id="shape-test", title="quarter plate", reference="none",
                            default_params=dict)
    ns = node_set_of(scene, {}, problem, system)
    g = system.model.grid
    assert len(ns.x) == g.n_interior and ns.x.shape[1] == 2
    # the cut volumes are the model's own (cut cells of the hole below a whole cell),
    # together at most the plate's area times t (cells whose centre lies outside the
    # shape carry no node)
    np.testing.assert_array_equal(ns.volume, system.model.node_volume[g.interior_ids])
    assert ns.volume.max() <= h * h * t * (1 + 1e-12) and ns.volume.min() < 0.9 * h * h * t
    assert ns.volume.sum() <= t * (1 - np.pi * 0.04 / 4)
    # the x+ part's traction, 1e6 Pa in x over its length 1 m times t: its Gauss weights
    # sum to the length, so rounding only (a few eps of 1e4 N); nothing in y
    np.testing.assert_allclose(ns.forces[:, 0].sum(), 1e6 * t, rtol=1e-12, atol=0)
    assert np.all(ns.forces[:, 1] == 0.0)
    assert set(ns.fixed) == {0, 1} and np.all(ns.x[ns.fixed[0][0], 0] < 2 * h)
    files = {**csv_files(ns), **perilab_files(ns)}
    rows = files["nodes.csv"].splitlines()
    assert len(rows) == len(ns.x) + 1
    np.testing.assert_array_equal([float(r.split(",")[3]) for r in rows[1:]], ns.volume)
    assert files["perilab/mesh.txt"].splitlines()[0] == "header: x y block_id volume"


# ------------------------------------------------------------------------------ issue 49
def _model_pairs(ns) -> set:
    """The model's bonds as pairs of real nodes (0-based export order), i < j coded i n + j:
    the uncorrected model's bond_a / bond_b, both ends real (the none treatment has no
    fictitious nodes)."""
    m = ns.system.model
    g = m.grid
    a, b = g.interior_number[m.bond_a], g.interior_number[m.bond_b]
    assert np.all(a >= 0) and np.all(b >= 0)
    n = len(ns.x)
    return set((np.minimum(a, b) * n + np.maximum(a, b)).tolist())


def _distance_pairs(x, delta) -> set:
    """Pairs with |x_i - x_j|^2 <= delta^2, computed as a code does from the coordinates:
    cKDTree's candidates within a slightly larger radius (1e-6: only a superset is
    needed), then the exact test on the squared distance."""
    from scipy.spatial import cKDTree
    cand = cKDTree(x).query_pairs(delta * (1 + 1e-6), output_type="ndarray")
    d2 = np.sum((x[cand[:, 0]] - x[cand[:, 1]]) ** 2, axis=1)
    c = cand[d2 <= delta * delta]
    return set((c.min(axis=1) * len(x) + c.max(axis=1)).tolist())


def _deck_horizon(deck_file: Path) -> float:
    (line,) = [ln for ln in deck_file.read_text().splitlines()
               if ln.strip().startswith("Horizon:")]
    return float(line.split(":", 1)[1])


@pytest.mark.parametrize("scene_id, overrides", [
    ("body3d-traction", {"spacing": 0.1}),                     # 3D, partial volumes
    ("body3d-traction", {"spacing": 0.1, "quadrature": "full-cells"}),   # bonds at 3h
    ("plate2d-plane-strain", {"spacing": 0.1}),
    ("plate2d-plane-strain", {"spacing": 0.1, "quadrature": "moment-corrected"}),
    ("plate-hole", {"spacing": 0.05}),                         # a shape's real nodes
    ("bar1d-traction", {"spacing": 1 / 14}),   # 3h written as is lost 6 of 11 bonds at 3h
])
def test_written_horizon_keeps_exactly_the_model_bonds(tmp_path, scene_id, overrides):
    """Issue 49: a code that keeps a bond when |xi|^2 <= delta^2, from the coordinates and
    the horizon the decks write, has the model's bonds, no fewer (the horizon m h written
    as is drops bonds at exactly m h by rounding, and every node beyond m h whose cell
    the horizon cuts) and no more."""
    from pdverify.exchange import node_set, scene_of
    ns = node_set(scene_of(scene_id), overrides)
    ours = _model_pairs(ns)
    sets = [a for k, v in overrides.items() for a in ("--set", f"{k}={v}")]
    d = ns.dim
    for fmt in ("peridigm", "perilab"):
        folder = tmp_path / fmt
        assert main(["export", scene_id, *sets, "--format", fmt, "--out", str(folder)]) == 0
        delta = _deck_horizon(folder / fmt / "pdverify.yaml")
        x = _exported_positions(folder, fmt, d)
        kept = _distance_pairs(x, delta)
        assert len(kept - ours) == 0 and len(ours - kept) == 0, (fmt, len(ours - kept),
                                                                 len(kept - ours))
        from pdverify.exchange import export_horizon
        problem = json.loads((folder / "problem.json").read_text())
        assert problem["horizon_written_m"] == delta == export_horizon(ns)
        assert problem["horizon_m"] == ns.horizon < delta
        assert "horizon_written_m = h sqrt((K + K_next)/2)" in problem["horizon_rule"]
        assert f"Horizon` is {delta!r} m" in (folder / "README.md").read_text()


def test_written_horizon_of_a_split_shell_is_stated(tmp_path):
    """A stencil that takes part of a shell of equal |k|^2 (partial volumes in 2D at
    m = 4.5 keep (4, 3) but not (5, 0), both |k|^2 = 25): no sphere keeps exactly its
    bonds; the written horizon keeps all of them and the added offsets are stated."""
    from pdverify.exchange import node_set, scene_of
    overrides = {"spacing": 0.1, "m_ratio": 4.5}
    ns = node_set(scene_of("plate2d-plane-strain"), overrides)
    assert main(["export", "plate2d-plane-strain", "--set", "spacing=0.1", "--set",
                 "m_ratio=4.5", "--format", "csv", "--out", str(tmp_path / "e")]) == 0
    problem = json.loads((tmp_path / "e" / "problem.json").read_text())
    kept = _distance_pairs(_exported_positions(tmp_path / "e", "csv", 2),
                           problem["horizon_written_m"])
    ours = _model_pairs(ns)
    assert ours < kept
    n = len(ns.x)
    extra = np.array(sorted(kept - ours))
    k2 = np.sum(np.round((ns.x[extra % n] - ns.x[extra // n]) / 0.1) ** 2, axis=1)
    assert set(k2.tolist()) == {25.0}
    assert problem["bond_offsets"]["added"] == 4       # (+-5, 0), (0, +-5)
    assert "4 offset(s) more" in problem["horizon_rule"]
    assert "4 offset(s) more" in (tmp_path / "e" / "README.md").read_text()


@pytest.mark.parametrize("header, scale, ok", [
    (("x [mm]", "ux [mm]"), 1e3, True),
    (("x [m]", "ux [cm]"), (1.0, 1e2), True),
    (("x", "u_x [\u00b5m]"), (1.0, 1e6), True),
    (("x [nm]", "ux [um]"), (1e9, 1e6), True),
    (("x [m]", "ux [in]"), 1.0, "column 'ux [in]' has unit 'in'"),
    (("x [ft]", "ux [m]"), 1.0, "column 'x [ft]' has unit 'ft'"),
])
def test_length_units_in_csv_headers(tmp_path, capsys, header, scale, ok):
    """Issue 49: a length unit in brackets is honoured (positions and displacements,
    scaled to metres); any other is refused in one line naming the column and the unit
    and listing the allowed ones."""
    native, x, u = _native("bar1d-traction")
    sx, su = (scale, scale) if np.isscalar(scale) else scale
    sent = tmp_path / "back.csv"
    sent.write_text(",".join(header) + "\n" + "".join(
        f"{float(a) * sx!r},{float(b) * su!r}\n" for a, b in zip(x[:, 0], u[:, 0])))
    out = tmp_path / "r.json"
    rc = main(["score", "bar1d-traction", str(sent), "--name", "c", "--out", str(out)])
    err = capsys.readouterr().err
    if ok is True:
        assert rc == 0, err
        run = json.loads(out.read_text())["runs"][0]
        # each displacement went through two roundings (times and divided by the unit's
        # power of ten): 2 eps of u; the errors measured are above 1e-3 of u (the bar's
        # max_error_pct is ~24 %), so they move by less than 1e-12 relative
        for key in ("max_error_pct", "rel_l2_error"):
            np.testing.assert_allclose(run["metrics"][key], native.metrics[key], rtol=1e-12,
                                       err_msg=key)
        # the prescribed node's value came back within those roundings of u_cl(x_1)
        assert run["diagnostics"]["external"]["prescribed_max_deviation_m"] <= (
            4 * np.finfo(float).eps * np.abs(u).max())
    else:
        assert rc == 2 and err.count("\n") == 1 and ok in err, err
        assert "allowed length units: m, cm, mm, um, \u00b5m, nm" in err
        assert not out.exists()


def _exodus_at(path, x, u, *, steps=2):
    """:func:`_write_exodus`'s layout (per-variable) with ``steps`` time steps (0: a run
    that wrote none) and as many coordinates as ``x`` has columns."""
    from scipy.io import netcdf_file
    n, d = x.shape
    with netcdf_file(path, "w", version=2) as nc:
        nc.createDimension("time_step", steps if steps else None)   # None: unlimited, 0
        nc.createDimension("num_nodes", n)
        nc.createDimension("num_nod_var", u.shape[1])
        nc.createDimension("len_name", 33)
        nc.createVariable("time_whole", "d", ("time_step",))[:] = np.arange(float(steps))
        for k in range(d):
            nc.createVariable(f"coord{'xyz'[k]}", "d", ("num_nodes",))[:] = x[:, k]
        names = [f"Displacement{a}" for a in "XYZ"[:u.shape[1]]]
        nc.createVariable("name_nod_var", "c", ("num_nod_var", "len_name"))[:] = np.array(
            [list(name.ljust(33, "\0")) for name in names], dtype="S1")
        for k in range(u.shape[1]):
            v = nc.createVariable(f"vals_nod_var{k + 1}", "d", ("time_step", "num_nodes"))
            if steps:
                v[:] = np.stack([np.zeros(n)] * (steps - 1) + [u[:, k]])


@pytest.mark.parametrize("case, needle", [
    ("zeros", "every displacement is zero"),
    ("no-steps", "has no time steps"),
    ("one-coordinate", "its nodes have 1 coordinate(s), the scene 2"),
    ("no-rows", "holds no nodes (no data rows below its header)"),
])
def test_degenerate_files_are_refused(tmp_path, capsys, case, needle):
    """Issue 49: files that hold no answer are refused in one line (exit 2), never a
    traceback: all-zero displacements (a ZeroDivisionError in score's warning before),
    an Exodus file without time steps (an IndexError), a 2D scene's file with one
    coordinate per node (a KD-tree's dimension error), a CSV with a header only."""
    _, x, u = _native("plate2d-plane-strain", {"spacing": 0.1})
    sent = tmp_path / ("back.csv" if case in ("zeros", "no-rows") else "result.e")
    if case == "zeros":
        _write_csv(sent, x, np.zeros_like(u))
    elif case == "no-rows":
        _write_csv(sent, x[:0], u[:0])
    elif case == "no-steps":
        _exodus_at(sent, x, u, steps=0)
    else:
        _exodus_at(sent, x[:, :1], u)
    out = tmp_path / "r.json"
    assert main(["score", "plate2d-plane-strain", str(sent), "--set", "spacing=0.1",
                 "--name", "c", "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and needle in err and str(sent) in err, err
    assert not out.exists()


def test_csv_with_byte_order_mark_is_read(tmp_path, capsys):
    """Issue 49: a CSV saved with a UTF-8 byte-order mark (Excel's "CSV UTF-8") is read
    as without one: the same metrics to the last bit."""
    native, x, u = _native("bar1d-traction")
    plain = tmp_path / "plain.csv"
    _write_csv(plain, x, u)
    sent = tmp_path / "bom.csv"
    sent.write_bytes(b"\xef\xbb\xbf" + plain.read_bytes())
    out = tmp_path / "r.json"
    assert main(["score", "bar1d-traction", str(sent), "--name", "c", "--out",
                 str(out)]) == 0, capsys.readouterr().err
    _assert_same_metrics(native, json.loads(out.read_text())["runs"][0])


@pytest.fixture
def bar_export(tmp_path):
    """bar1d-traction exported with E = 2e9 Pa (not the default 1e9: the same nodes,
    twice the stiffness), and its solution."""
    folder = tmp_path / "export"
    assert main(["export", "bar1d-traction", "--set", "E=2e9", "--format", "csv",
                 "--out", str(folder)]) == 0
    native, x, u = _native("bar1d-traction", {"E": 2e9})
    return folder, native, x, u


def test_score_takes_the_params_of_its_export(bar_export, capsys):
    """Issue 49: a file inside an export folder (here a subfolder) is scored at the
    export's params without any --set (it was scored at the default E, status ok), and
    the record names the export."""
    folder, native, x, u = bar_export
    (folder / "mine").mkdir()
    sent = folder / "mine" / "back.csv"
    _write_csv(sent, x, u)
    out = folder.parent / "r.json"
    assert main(["score", "bar1d-traction", str(sent), "--name", "c", "--out",
                 str(out)]) == 0, capsys.readouterr().err
    printed = capsys.readouterr().out
    run = json.loads(out.read_text())["runs"][0]
    assert run["params"]["E"] == 2e9 and run["warnings"] == []
    _assert_same_metrics(native, run)
    export = run["diagnostics"]["external"]["export"]
    assert export["folder"] == str(folder) and export["params"] == run["params"]
    assert f"the export {folder}" in printed


@pytest.mark.parametrize("how, needle", [
    ("set", "--set E=1e9: --export"),
    ("scene", "is an export of scene 'bar1d-traction', not 'bar1d-uniform-load'"),
    ("not-export", "holds no pdverify export"),
])
def test_score_refuses_what_disagrees_with_its_export(bar_export, capsys, how, needle):
    """Issue 49: a --set that disagrees with the export's value, another scene than the
    export's, or an --export folder that is no export: one line, exit 2."""
    folder, _, x, u = bar_export
    sent = folder.parent / "back.csv"
    _write_csv(sent, x, u)
    argv = {"set": ["bar1d-traction", str(sent), "--export", str(folder), "--set",
                    "E=1e9"],
            "scene": ["bar1d-uniform-load", str(sent), "--export", str(folder)],
            "not-export": ["bar1d-traction", str(sent), "--export", str(folder.parent)],
            }[how]
    assert main(["score", *argv, "--name", "c"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and needle in err, err
    if how == "set":   # both values named
        assert "made with E=2000000000.0" in err


def test_score_without_an_export_warns(tmp_path, capsys):
    """Issue 49: no --export and no export above the file: scored at the --set given
    (defaults elsewhere), and the record and the printed output say the params were
    not checked."""
    native, x, u = _native("bar1d-traction")
    sent = tmp_path / "back.csv"
    _write_csv(sent, x, u)
    out = tmp_path / "r.json"
    assert main(["score", "bar1d-traction", str(sent), "--name", "c", "--out",
                 str(out)]) == 0
    printed = capsys.readouterr().out
    run = json.loads(out.read_text())["runs"][0]
    assert run["warnings"] == [NO_EXPORT_WARNING]
    assert "export" not in run["diagnostics"]["external"]
    assert f"warning: {NO_EXPORT_WARNING}" in printed
    _assert_same_metrics(native, run)


@pytest.mark.parametrize("quadrature, says, never", [
    ("full-cells", "by its whole cell (`quadrature=full-cells`)", "fraction beta"),
    ("partial-volume", "the exact fraction beta of the neighbour's cell inside the horizon "
                       "sphere (`quadrature=partial-volume`)", "whole cell ("),
    ("moment-corrected", "(`quadrature=moment-corrected`", "whole cell ("),
])
def test_export_readme_states_the_quadrature(tmp_path, quadrature, says, never):
    """Issue 49: the export README's bond weights are the quadrature's (whole cells were
    described as partial volumes)."""
    folder = tmp_path / "e"
    assert main(["export", "plate2d-plane-strain", "--set", "spacing=0.1", "--set",
                 f"quadrature={quadrature}", "--format", "peridigm", "--out",
                 str(folder)]) == 0
    (line,) = [ln for ln in (folder / "README.md").read_text().splitlines()
               if ln.startswith("- Bond weights:")]
    assert says in line and never not in line, line


def test_readme_names_every_exportable_scene():
    """Issue 49: the paragraph on export (docs/command-line.md, linked from the README
    since issue 52) names every scene export takes."""
    from pdverify.exchange import exportable_ids
    assert "docs/command-line.md" in (ROOT / "README.md").read_text()
    text = (ROOT / "docs" / "command-line.md").read_text()
    start = text.index("- Your own PD code against ours:")
    paragraph = text[start:text.index("\n- ", start + 1)]
    missing = [s for s in exportable_ids() if f"`{s}`" not in paragraph]
    assert missing == []


# ------------------------------------------------------------------------------ issue 49:
# the bond-based sheets (their own assembly, pdverify.scenes.sheets)
#: what a bond-based sheet is exported as: Peridigm's documented examples show no
#: bond-based material, so its deck is refused (test below)
BOND_FORMATS = ("csv", "vtu", "perilab", "lammps")


@pytest.mark.parametrize("scene_id, overrides, formats", [
    # end loads (tributary shares), supports on the symmetry lines, whole cells, m = 2
    ("sheet2d-tension", {"spacing": 0.0025}, BOND_FORMATS),
    # equal end loads, the conical micromodulus (its tip carries no bond) and partial
    # volumes at m = 4; LAMMPS's peri/pmb has no conical micromodulus (refused below)
    ("sheet2d-tension", {"spacing": 0.00125, "load_sharing": "equal",
                         "micromodulus": "conical", "quadrature": "partial-volume"},
     BOND_FORMATS[:3]),
    # prescribed non-zero displacements on the clamped rows, no loads, a FEM reference
    ("sheet2d-clamped", {}, BOND_FORMATS),
])
def test_round_trip_bond_based_sheets(tmp_path, capsys, scene_id, overrides, formats):
    """Issue 49: a bond-based sheet's own none solution, exported in every format it
    takes and sent back as CSV and VTU, scores the run's metrics to the last bit and an
    equilibrium residual of round-off."""
    _round_trip(tmp_path, capsys, scene_id, overrides, formats)


def _pair_coeff_horizon(in_lammps: Path) -> float:
    """The horizon of ``pair_coeff * * c horizon s00 alpha`` (peri/pmb)."""
    (line,) = [ln for ln in in_lammps.read_text().splitlines() if ln.startswith("pair_coeff")]
    return float(line.split()[4])


@pytest.mark.parametrize("scene_id, overrides", [
    ("sheet2d-tension", {"spacing": 0.0025}),                            # m = 2
    ("sheet2d-tension", {"spacing": 0.00125, "quadrature": "partial-volume"}),  # beyond m h
    # conical at m = 4: the offsets at |k| = 4 weigh 0 and carry no bond, so the written
    # horizon lies below m h (between |k|^2 = 13 and 16)
    ("sheet2d-tension", {"spacing": 0.00125, "micromodulus": "conical"}),
    ("sheet2d-clamped", {}),                                             # m = 6
])
def test_written_horizon_keeps_exactly_the_bond_based_model_bonds(tmp_path, scene_id,
                                                                 overrides):
    """Issue 49: the horizon PeriLab's deck and LAMMPS's same-model deck write keeps
    exactly the bond-based model's bonds (model.bond_a / bond_b) for a code that keeps
    |xi|^2 <= delta^2 from the written coordinates."""
    from pdverify.exchange import export_horizon, node_set, scene_of
    ns = node_set(scene_of(scene_id), overrides)
    ours = _model_pairs(ns)
    sets = [a for k, v in overrides.items() for a in ("--set", f"{k}={v}")]
    conical = overrides.get("micromodulus") == "conical"
    for fmt in ("perilab",) if conical else ("perilab", "lammps"):
        folder = tmp_path / fmt
        assert main(["export", scene_id, *sets, "--format", fmt, "--out", str(folder)]) == 0
        delta = (_deck_horizon(folder / fmt / "pdverify.yaml") if fmt == "perilab" else
                 _pair_coeff_horizon(folder / "lammps" / "same-model" / "in.lammps"))
        kept = _distance_pairs(_exported_positions(folder, fmt, 2), delta)
        assert len(kept - ours) == 0 and len(ours - kept) == 0, (fmt, len(ours - kept),
                                                                 len(kept - ours))
        problem = json.loads((folder / "problem.json").read_text())
        assert problem["horizon_written_m"] == delta == export_horizon(ns)
        assert (problem["horizon_m"] > delta) if conical else (problem["horizon_m"] < delta)


def test_bond_based_problem_json_states_the_model(tmp_path):
    """Issue 49: problem.json says the model is bond-based, its micromodulus c and what c
    multiplies, the micromodulus's shape and the thickness."""
    from pdverify.exchange import node_set, scene_of
    folder = tmp_path / "e"
    assert main(["export", "sheet2d-tension", "--set", "spacing=0.0025", "--format", "csv",
                 "--out", str(folder)]) == 0
    doc = json.loads((folder / "problem.json").read_text())
    ns = node_set(scene_of("sheet2d-tension"), {"spacing": 0.0025})
    material = doc["material"]
    assert material["model"].startswith("linear bond-based")
    assert material["c_N_per_m6"] == ns.system.model.c
    # seed 003's constant micromodulus in plane stress, 9 E / (pi delta^3): a closed form
    # evaluated with a few roundings (some eps)
    assert material["c_N_per_m6"] == pytest.approx(9e9 / (np.pi * 0.005 ** 3), rel=1e-14)
    assert "c omega(|xi|) (e / |xi|) V_b" in material["force_density"]
    assert material["micromodulus"] == "constant" and material["nu"] == 1 / 3
    assert doc["thickness_m"] == 1.0 and doc["influence"]["name"] == "constant"
    readme = (folder / "README.md").read_text()
    assert "Peridigm: no deck is written" in readme


@pytest.mark.parametrize("argv, needle", [
    (["--format", "peridigm"], "--format peridigm: sheet2d-tension is bond-based"),
    (["--set", "micromodulus=conical", "--format", "lammps"],
     "--format lammps: micromodulus=conical"),
])
def test_bond_based_export_refuses_a_deck_it_cannot_write(tmp_path, capsys, argv, needle):
    """Issue 49: Peridigm's documented examples show no bond-based material, and LAMMPS's
    peri/pmb has only the constant micromodulus: one line naming the allowed formats,
    exit 2, nothing written."""
    out = tmp_path / "a"
    assert main(["export", "sheet2d-tension", "--set", "spacing=0.0025", *argv,
                 "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and needle in err and "allowed: csv, vtu, perilab" in err, err
    assert not out.exists()


def test_perilab_bond_based_deck_matches_its_examples(tmp_path):
    """Issue 49: PeriLab's deck of a bond-based sheet takes the material of its
    Seminars truss example (``Bond-based Elastic`` with Symmetry, E, nu) and the state-based
    deck's layout otherwise (the example's Discretization, Blocks, Boundary Conditions)."""
    truss = _yaml((DATA / "perilab_truss.yaml").read_text())["PeriLab"]
    ex_material = truss["Models"]["Material Models"]["Test"]
    example = _yaml((DATA / "perilab_ENFmodel.yaml").read_text())["PeriLab"]
    folder = tmp_path / "e"
    assert main(["export", "sheet2d-clamped", "--format", "perilab", "--out",
                 str(folder)]) == 0
    ours = _yaml((folder / "perilab" / "pdverify.yaml").read_text())["PeriLab"]
    (material,) = ours["Models"]["Material Models"].values()
    assert material["Material Model"] == ex_material["Material Model"] == "Bond-based Elastic"
    assert set(material) == set(ex_material)
    assert material["Symmetry"] == "isotropic plane stress"
    assert float(material["Young's Modulus"]) == 1e9
    assert float(material["Poisson's Ratio"]) == 1 / 3
    (block,) = ours["Blocks"].values()
    assert set(block) == set(example["Blocks"]["block_3"])
    ex_bc = example["Boundary Conditions"]["BC_2"]
    values = set()
    for name, bc in ours["Boundary Conditions"].items():
        assert set(bc) == set(ex_bc) and bc["Type"] == "Dirichlet", name
        assert bc["Variable"] == "Displacements"          # the clamped sheet has no loads
        values.add((bc["Coordinate"], float(bc["Value"])))
    # u_x = 0 on both clamped rows, u_y = +-L/200 = +-1e-4 m (one rounding each)
    assert values == {("x", 0.0), ("y", 0.01 * 0.02 / 2), ("y", -0.01 * 0.02 / 2)}


def test_bond_based_score_of_a_scaled_field_fails_naming_its_residual(tmp_path):
    """Issue 49: the tension sheet's own none solution is in equilibrium in the bond-based
    model (K = model.K); scaled by 0.9 it misses the load by a tenth and fails."""
    from pdverify.exchange import score
    over = {"spacing": 0.0025}
    _, x, u = _native("sheet2d-tension", over)
    for factor, status in ((1.0, "ok"), (0.9, "failed")):
        sent = tmp_path / f"u{factor}.csv"
        _write_csv(sent, x, factor * u)
        r = score("sheet2d-tension", str(sent), name="t", overrides=over)
        assert r.status == status, r.message
    # K (0.9 u) - f = 0.9 (K u - f) - 0.1 f: a tenth of the load's norm, up to the direct
    # solve's round-off (~1e-14 of it); the limit, 10 x the largest bond strain, is ~1e-2
    assert r.metrics["equilibrium_residual"] == pytest.approx(0.1, rel=1e-9)
    assert "not in equilibrium: 0.1 (relative L2) from the scene's linear solution" in r.message


def test_bond_based_score_of_a_scaled_clamped_field_is_warned(tmp_path):
    """Issue 49: a displacement-driven sheet's field scaled by 0.9 still balances its free
    nodes (the model is linear and unloaded), so equilibrium cannot see it; its values on
    the clamped rows can: the record warns with the deviation, 0.1 x L/200."""
    from pdverify.exchange import score
    _, x, u = _native("sheet2d-clamped")
    sent = tmp_path / "u.csv"
    _write_csv(sent, x, 0.9 * u)
    r = score("sheet2d-clamped", str(sent), name="t")
    assert r.status == "ok"
    # (K 0.9 u)_free = 0.9 (K u)_free: 0.9 x the direct solve's round-off (~1e-14 of the
    # clamped rows' reactions), below the round trip's ceiling of 1e-10
    assert r.metrics["equilibrium_residual"] < 1e-10
    assert any("prescribed nodes" in w for w in r.warnings)
    # |0.9 uy - uy| on the clamped rows, uy = 0.01 x 0.02 / 2: a few roundings
    assert r.diagnostics["external"]["prescribed_max_deviation_m"] == pytest.approx(
        1e-5, rel=1e-12)
