"""The FEM references as scenes (issue #5): metrics reach results.json and the report."""
import os

import pytest

from pdverify.cli import main
from pdverify.scenes import get_scene


@pytest.fixture(autouse=True)
def _cache(fem_cache_dir):
    """The session's cache folder (conftest; never the user's), shared with the other
    tests that need these references (issue 32)."""
    assert os.environ["PDVERIFY_CACHE_DIR"] == str(fem_cache_dir)


def test_clamped_sheet_scene_reproduces_table_2():
    # seed 003 Table 2: FEM 10.32 MPa; issue #5: +-0.02 MPa at the converged level
    res = get_scene("sheet2d-clamped").run("fem")
    assert res.status == "ok", res.message
    assert res.metrics["tensile_stress_mpa"] == pytest.approx(10.32, abs=0.02)
    assert res.fields["refinement"][-1]["dofs"] == res.size["dofs"]


def test_tension_sheet_scene_matches_closed_form():
    # issue #5: the closed form to 1e-10 relative (max_error_pct is in percent)
    res = get_scene("sheet2d-tension").run("fem")
    assert res.metrics["max_error_pct"] / 100 < 1e-10


def test_fem_scene_bad_input_exits_2(capsys):
    assert main(["run", "sheet2d-clamped", "--set", "nu=0.7"]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "nu" in err
    assert main(["run", "plate2d-clamped", "--set", "levels=1"]) == 2
    assert main(["run", "plate2d-clamped", "--set", "colour=1"]) == 2
