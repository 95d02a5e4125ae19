"""The pyvista renderings of the 3D boxes (pdverify.report.figures.fields3d) are drawn.

The report wraps them so that a failing renderer costs only these images; this test is
where a failure shows: it calls the renderer directly, with nothing caught.
"""
import matplotlib.image as mpimg
import pytest

from pdverify.report.figures import fields3d, surface_nodes
from pdverify.scenes import get_scene


@pytest.fixture(scope="module")
def run():
    # 8 x 4 x 4 cells (128 nodes), about a second; spacing 0.125 is a valid box size
    # for the uncorrected model (the surface-node orders >= 3 need more cells)
    scene = get_scene("body3d-traction")
    r = scene.run("none", {"spacing": 0.125})
    assert r.status == "ok"
    return scene, r


def test_render_box_fields_writes_one_nonblank_png_per_scene(tmp_path, run):
    """One image per scene (issue 34): |u| of the first run, then each run's error on
    one shared scale, :data:`fields3d.RENDER_COLUMNS` panels a row."""
    scene, r = run
    out = fields3d.render_box_fields(scene, [r], str(tmp_path))
    assert [name for name, _ in out] == ["body3d-traction-3d.png"]
    assert "Eq. (38)" in out[0][1] and "[mm]" in out[0][1]
    path = tmp_path / out[0][0]
    assert path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    img = mpimg.imread(path)  # floats in [0, 1]
    cols = fields3d.RENDER_COLUMNS
    pw, ph = fields3d.PANEL_PX
    w, h = pw * cols, ph          # two panels (|u|, the error): one row
    assert img.shape[:2] == (h, w)
    rgb = img[..., :3]
    # a blank frame (all background) has std 0, one with only the panel titles and the
    # axes triads about 0.04 (measured, 1400 x 600); the rendering, a white background
    # with coloured bodies and colour bars, about 0.33: 0.15 lies well between
    assert rgb[:, : 2 * pw].std() > 0.15     # the two drawn panels
    # both panels drew their body: in each over 5 % of the pixels have a channel below
    # 0.5 (about 36 % in the former 1400 x 600 panels; the titles alone cover well under
    # 1 %); the third panel of the row is empty
    for k in range(2):
        panel = rgb[:, k * pw:(k + 1) * pw]
        assert (panel.min(axis=-1) < 0.5).mean() > 0.05
    assert (rgb[:, 2 * pw:].min(axis=-1) < 0.5).mean() < 0.01


def test_default_runs_pick_one_run_per_method_at_its_defaults():
    scene = get_scene("body3d-manufactured")

    class R:
        def __init__(self, method, **params):
            self.method = method
            self.params = scene.resolve(method, {"spacing": 0.1, **params})

    runs = [R("none"), R("none", load_point="surface"), R("surface-nodes", order=1),
            R("surface-nodes", order=3), R("surface-nodes", order=3, surface_load="centre")]
    picked = fields3d.default_runs(scene, runs)
    assert picked == [runs[0], runs[3]]  # surface-nodes defaults to order 3 here


def test_the_family_draws_the_renderings_after_its_maps(tmp_path, run):
    scene, r = run
    names = [name for name, _ in surface_nodes.surface_node_figures(scene, [r], str(tmp_path))]
    assert names == ["body3d-traction-maps.png", "body3d-traction-3d.png",
                     "body3d-traction-cost.png"]


def test_the_family_keeps_its_maps_when_the_renderer_fails(tmp_path, monkeypatch, run):
    scene, r = run

    def broken(*args):
        raise RuntimeError("no OpenGL")

    monkeypatch.setattr(fields3d, "render_box_fields", broken)
    with pytest.warns(RuntimeWarning, match="no 3D renderings.*no OpenGL"):
        figs = surface_nodes.surface_node_figures(scene, [r], str(tmp_path))
    assert figs and not any("-3d" in name for name, _ in figs)
    assert all((tmp_path / name).exists() for name, _ in figs)


def test_render_deformed_draws_seed001_fig11_beside_the_paper(tmp_path):
    """Seed 001 Fig. 11's view (issue 33): the deformed body of the exact field and of the
    best default run, one png; the caption puts the paper's colour-bar top (0.0021 m,
    read off the figure) beside the exact field's largest |u| with its deviation."""
    scene = get_scene("body3d-manufactured")
    r = scene.run("none", {"spacing": 0.125, "load_point": "node"})
    assert r.status == "ok"
    out = fields3d.render_deformed(scene, [r], str(tmp_path))
    assert [name for name, _ in out] == ["body3d-manufactured-deformed.png"]
    caption = out[0][1]
    assert "0.0021 m" in caption and f"{r.metrics['max_displacement']:.3g} m" in caption
    assert "001-fig11-body" in caption
    rgb = mpimg.imread(tmp_path / out[0][0])[..., :3]
    for half in (rgb[:, : rgb.shape[1] // 2], rgb[:, rgb.shape[1] // 2:]):
        # both bodies drawn (the thresholds of the test above)
        assert (half.min(axis=-1) < 0.5).mean() > 0.05


def test_render_deformed_needs_the_max_displacement_metric(tmp_path, run):
    scene, r = run            # body3d-traction records no max_displacement
    assert fields3d.render_deformed(scene, [r], str(tmp_path)) == []


def test_a_quick_report_draws_no_rendering(tmp_path, monkeypatch, run):
    """Issue 32: in a --quick report (figures.quick_figures) the 3D family draws its maps
    and cost figure but no pyvista rendering: the renderer is not even called."""
    from pdverify.report import figures
    scene, r = run
    called = []
    monkeypatch.setattr(fields3d, "render_box_fields", lambda *a: called.append(a) or [])
    monkeypatch.setattr(fields3d, "render_deformed", lambda *a: called.append(a) or [])
    with figures.quick_figures(True):
        names = [n for n, _ in surface_nodes.surface_node_figures(scene, [r], str(tmp_path))]
    assert names == ["body3d-traction-maps.png", "body3d-traction-cost.png"]
    assert called == []
    assert figures.QUICK is False        # the setting ends with the block
    surface_nodes.surface_node_figures(scene, [r], str(tmp_path))
    assert len(called) == 2              # outside it, both renderers are called
