"""Bring your own method: a plugin package (tests/plugins/demo_plugin) registers a
correction through the entry point group ``pdverify.methods`` and runs in ``list``,
``run`` and ``report`` like a built-in one."""
import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

PLUGIN = Path(__file__).resolve().parents[1] / "plugins" / "demo_plugin"


TREATMENT_PLUGIN = Path(__file__).resolve().parents[1] / "plugins" / "demo_treatment_plugin"


def _install(target: Path, plugin: Path = PLUGIN, package: str = "pdverify_demo_plugin",
             entry: str = "demo-uniform = pdverify_demo_plugin:METHOD") -> str:
    """pip install --target (the user's way); offline, where pip cannot fetch the build
    backend, lay out what that install writes: the package and its dist-info with the
    entry points."""
    r = subprocess.run([sys.executable, "-m", "pip", "install", "-q", "--no-deps",
                        "--target", str(target), str(plugin)], capture_output=True, text=True)
    if r.returncode == 0:
        return "pip"
    shutil.copytree(plugin / package, target / package)
    info = target / f"{package}-0.1.0.dist-info"
    info.mkdir()
    (info / "METADATA").write_text(f"Metadata-Version: 2.1\nName: {package}\n"
                                   "Version: 0.1.0\n")
    (info / "entry_points.txt").write_text(f"[pdverify.methods]\n{entry}\n")
    return "dist-info"


@pytest.fixture(scope="module")
def installed(tmp_path_factory):
    """Both demo plugins installed, each into a folder of its own, by two pip processes
    at once (issue 32: each pip spent 4 to 7 s, one after the other)."""
    from concurrent.futures import ThreadPoolExecutor
    jobs = {"method": (tmp_path_factory.mktemp("site"), PLUGIN, "pdverify_demo_plugin",
                       "demo-uniform = pdverify_demo_plugin:METHOD"),
            "treatment": (tmp_path_factory.mktemp("site-treatment"), TREATMENT_PLUGIN,
                          "pdverify_image_nodes", "image-nodes = pdverify_image_nodes:METHOD")}
    with ThreadPoolExecutor(max_workers=2) as pool:
        done = {k: pool.submit(_install, *args) for k, args in jobs.items()}
        for f in done.values():
            f.result()
    return {k: args[0] for k, args in jobs.items()}


def _env(target):
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join([str(target), env.get("PYTHONPATH", "")])
    return env


@pytest.fixture(scope="module")
def plugin_env(installed):
    return _env(installed["method"])


def cli(env, *args):
    return subprocess.run([sys.executable, "-m", "pdverify", *args], capture_output=True,
                          text=True, env=env)


def test_plugin_in_list(plugin_env):
    r = cli(plugin_env, "list")
    assert r.returncode == 0, r.stderr
    assert "method demo-uniform" in r.stdout
    assert "bond method demo-uniform: plugin pdverify_demo_plugin:METHOD" in r.stdout
    matrix = r.stdout.split("method x scene:\n", 1)[1].splitlines()
    head = matrix[0]
    row = next(line for line in matrix if line.startswith("stiffness2d-sheet "))
    i = head.index("demo-uniform")
    assert row[i:i + len("demo-uniform")].strip() == "x"


def test_plugin_in_run_and_report(plugin_env, tmp_path):
    """Factor 1 is the uncorrected model, so the plugin's run reproduces ``none`` to the
    last bit; factor 2 doubles every bond, so W_i / W_bulk = 2 in the bulk."""
    r = cli(plugin_env, "run", "stiffness2d-sheet", "--method", "demo-uniform",
            "--set", "factor=2", "--set", "spacing=0.0025")
    assert r.returncode == 0, r.stderr
    assert "interior_energy_error_pct 100" in r.stdout
    out = tmp_path / "rep"
    r = cli(plugin_env, "report", "--only", "stiffness2d-sheet", "--out", str(out))
    assert r.returncode == 0, r.stderr
    runs = json.loads((out / "results.json").read_text())["runs"]
    # the default configuration of each method (the scene also runs none at m = 6)
    by = {x["method"]: x for x in runs if x["params"]["m_ratio"] == 5.0}
    assert by["demo-uniform"]["status"] == "ok"
    assert by["demo-uniform"]["metrics"] == by["none"]["metrics"]
    assert "demo-uniform" in (out / "index.html").read_text()


def test_without_the_plugin_the_method_is_bad_input():
    r = subprocess.run([sys.executable, "-m", "pdverify", "run", "stiffness2d-sheet",
                        "--method", "demo-uniform"], capture_output=True, text=True)
    assert r.returncode == 2
    assert ("not supported by this scene; allowed: none, taylor-fictitious, surface-nodes, "
            "mirror-nodes, energy, energy-directional" in r.stderr)
    assert "demo-uniform" not in r.stderr.split("allowed:", 1)[1]


def test_broken_plugin_is_listed_not_fatal(monkeypatch):
    import importlib.metadata as md

    from pdverify.corrections import registry

    class EP:
        name, value, group = "broken", "no_such_module:X", registry.ENTRY_POINT_GROUP

        def load(self):
            raise ImportError("No module named 'no_such_module'")

    monkeypatch.setattr(md, "entry_points", lambda group=None: [EP()])
    registry.reload()
    try:
        methods = registry.bond_methods()
        assert {"energy", "volume"} <= set(methods)
        assert "No module named" in registry.BROKEN["broken"]
    finally:
        monkeypatch.undo()
        registry.reload()


# ------------------------------------------------------------ a treatment with nodes and rows
@pytest.fixture(scope="module")
def treatment_env(installed):
    """The plugin tests/plugins/demo_treatment_plugin: a mirror-node variant with
    surface-node unknowns (extra nodes) and their force-flux equations (extra rows),
    installed like a user's package; pdverify itself is unchanged."""
    return _env(installed["treatment"])


def test_treatment_plugin_serves_every_scene_of_its_family(treatment_env):
    """``list`` offers it on every static-state box (the seed-000 bars and clamped
    plate, the seed-001 boxes and plate, the state-based stiffness scenes) and says why
    not elsewhere (on the shape scenes: it does not declare shapes)."""
    import pdverify.scenes as scenes
    family = sorted(s.id for s in scenes.all_scenes()
                    if s.family == "static-state" and not s.has_shape)
    assert len(family) == 13    # 10 static boxes, issue 56's two wave boxes and pulse plate
    r = cli(treatment_env, "list")
    assert r.returncode == 0, r.stderr
    matrix = r.stdout.split("method x scene:\n", 1)[1].splitlines()
    i = matrix[0].index("image-nodes")
    served = sorted(line.split()[0] for line in matrix[1:]
                    if line[:1].strip() and line[i:i + len("image-nodes")].strip() == "x")
    assert served == family


def test_treatment_plugin_runs_and_is_exact_for_a_linear_field(treatment_env,
                                                               cli_concurrently):
    """The traction bar's solution is linear, and odd images about the surface nodes
    reproduce a linear field exactly: round-off (Eq. 64 relative to the largest
    displacement, times 1e3 eps per node row summed over ~40 bonds)."""
    # the four runs below, each its own process, started together (issue 32)
    bar = ("run", "bar1d-traction", "--method", "image-nodes")
    plate = ("run", "plate2d-plane-strain", "--method", "image-nodes", "--set",
             "spacing=0.05")
    stiff = {m: ("run", "stiffness2d-plate", "--method", m, "--set", "spacing=0.05")
             for m in ("image-nodes", "none")}
    runs = cli_concurrently([bar, plate, *stiff.values()], env=treatment_env)
    r = runs[bar]
    assert r.returncode == 0, r.stderr
    err = float(r.stdout.split("max_error_pct", 1)[1].split()[0])
    assert err < 1e-9
    r = runs[plate]
    assert r.returncode == 0, r.stderr
    assert "surface_max_error_pct" in r.stdout
    # on a stiffness scene it is judged by its nodal energy. Its odd images are exact for
    # fields linear along each face's normal, not at the corners, where the nearest
    # surface node is not the midpoint of a node and its image (measured: the nodes off
    # the bulk energy all lie within 2.5 h of a corner; 10.8 % at most, in shear): it
    # must still beat the truncated neighbourhoods there
    def energy_error(method):
        r = runs[stiff[method]]
        assert r.returncode == 0, r.stderr
        return float(r.stdout.split("surface_energy_error_pct", 1)[1].split()[0])
    assert energy_error("image-nodes") < energy_error("none")


def test_treatment_plugin_in_report_and_overview(treatment_env, tmp_path):
    out = tmp_path / "rep"
    r = cli(treatment_env, "report", "--quick", "--only", "bar1d-traction", "--out", str(out))
    assert r.returncode == 0, r.stderr
    runs = json.loads((out / "results.json").read_text())["runs"]
    mine = [x for x in runs if x["method"] == "image-nodes"]
    assert mine and all(x["status"] == "ok" for x in mine)
    html = (out / "index.html").read_text()
    overview = html.split("</table>", 1)[0]          # the matrix is the page's first table
    assert "<th>image-<wbr>nodes</th>" in overview    # its column head (breaks at hyphens)
