"""The quick report's budget (issue 32: ``report --quick`` in 30 s on 2 cores): what it
leaves out or makes lighter, and what it must keep (every scene, every method)."""
from __future__ import annotations

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pytest  # noqa: E402
from matplotlib.transforms import Bbox  # noqa: E402

from pdverify import convergence  # noqa: E402
from pdverify.report import figures  # noqa: E402
from pdverify.runner import plan  # noqa: E402
from pdverify.scenes import all_scenes, get_scene  # noqa: E402


def test_the_quick_report_runs_every_method_of_every_scene():
    """A quick report shows every scene and every method: the quick plan has, for each
    scene, every method the full plan has (only grids and levels may shrink)."""
    def methods(quick):
        out = {}
        for scene, method, _ in plan(quick=quick):
            out.setdefault(scene, set()).add(method)
        return out
    full, quick = methods(False), methods(True)
    assert set(quick) == set(full) == {s.id for s in all_scenes()}
    for scene in full:
        assert quick[scene] == full[scene], scene


def _levels(kind, scene, quick):
    st = next(s for s in convergence.STUDIES if s.scene == scene and s.kind == kind)
    return st, st.used_levels(quick)


def test_the_3d_studies_of_the_quick_report_stay_at_six_cells_a_side_or_coarser():
    """body3d-manufactured's quick delta-refinement runs h = 0.1 and 1/12 (not 0.0625),
    its m-refinement (finer level h = 1/18) only in the full report; the full report's
    levels are the study's own (five since issue 55: h = 1/24 and 1/30 appended)."""
    st, quick = _levels("delta", "body3d-manufactured", True)
    assert [lv["spacing"] for lv in quick] == [0.1, 1 / 12]
    assert st.used_levels(False) == st.levels and len(st.levels) == 5
    st, quick = _levels("m", "body3d-manufactured", True)
    assert quick == () and len(st.used_levels(False)) == 2
    finest = min(o["spacing"] for s, _, o in plan(only=["body3d-manufactured"], quick=True)
                 if "spacing" in o)
    assert finest == 1 / 12


def test_a_study_left_out_of_the_quick_report_has_no_entry():
    """collect() skips a study without quick levels (no entry without levels)."""
    from types import SimpleNamespace
    runs = [SimpleNamespace(scene="body3d-manufactured", key=None)]
    entries = convergence.collect(runs, quick=True)
    assert {e["study"] for e in entries} == {"delta"}
    assert all(len(e["levels"]) == 2 for e in entries)


def test_the_clamped_sheets_quick_delta_refinement_says_its_m():
    st, quick = _levels("delta", "sheet2d-clamped", True)
    assert {lv["m_ratio"] for lv in quick} == {3.0}
    assert st.fixed_in(True) == "m = 3" and st.fixed_in(False) == "m = 6"


@pytest.mark.parametrize("scene_id, spacing", [("sheet2d-tension", 0.00125),
                                               ("stiffness2d-sheet", 0.002)])
def test_sheets_quick_cases_share_one_coarser_grid(scene_id, spacing):
    scene = get_scene(scene_id)
    pd_cases = [(m, o) for m, o in scene.report_cases(quick=True) if m != "fem"]
    assert pd_cases and all(o["spacing"] == spacing for _, o in pd_cases)
    # the full report keeps the paper's grid (1 mm)
    assert all(scene.resolve(m, o)["spacing"] == 0.001
               for m, o in scene.report_cases(quick=False)[:2] if m != "fem")


def _saved(monkeypatch, fig):
    seen = {}

    def fake(self, path, **kw):
        seen.update(kw)
    monkeypatch.setattr(type(fig), "savefig", fake)
    return seen


@pytest.mark.parametrize("layout", ["constrained", None])
def test_quick_figures_skip_the_tight_bbox_of_a_constrained_figure(tmp_path, monkeypatch,
                                                                   layout):
    """Under quick_figures, a constrained-layout figure is saved without the tight-bbox
    pass (it fits its canvas already); any other keeps it (its legends may sit outside
    the axes); outside quick_figures every figure is cropped tight."""
    for quick in (True, False):
        fig, ax = plt.subplots(layout=layout)
        ax.loglog([1, 10, 100], [1, 2, 3])
        seen = _saved(monkeypatch, fig)
        with figures.quick_figures(quick):
            figures.save(fig, str(tmp_path), "a.png")
        tight = not (quick and layout == "constrained")
        # the tight box is measured in save (the figure laid out once), handed as a Bbox
        box = seen["bbox_inches"]
        assert isinstance(box, Bbox) if tight else box is None, (quick, layout)
        minor = ax.xaxis.get_minor_locator()
        assert isinstance(minor, matplotlib.ticker.NullLocator) == quick


def _busy_figure(layout):
    """A figure with what the report's figures lay out: panels with titles, log and
    linear axes, an image with a colour bar, a suptitle, and (without a layout engine) a
    legend and a text outside the axes, which the tight box takes in."""
    fig, (a, b) = plt.subplots(1, 2, figsize=(7, 3), layout=layout)
    a.loglog([1e-3, 1e-1, 3.0], [2e-6, 4e-3, 0.5], "o-", label="a method (rate 1.98)")
    a.set_title("delta-refinement", fontsize=8)
    a.set_xlabel("h [m]")
    a.legend(fontsize=6, loc="upper left", bbox_to_anchor=(1.01, 1.0))
    im = b.imshow(np.arange(12.0).reshape(3, 4), origin="lower", extent=(0, 2, 0, 1))
    b.set_title("error [%]\nsecond line", fontsize=7)
    b.text(0, 1.25, "run (max 11 %)", fontsize=8, fontweight="bold", transform=b.transAxes)
    fig.colorbar(im, ax=b, shrink=0.8)
    fig.suptitle("scene: convergence of every method", fontsize=9)
    return fig


@pytest.mark.parametrize("layout", ["constrained", None])
@pytest.mark.parametrize("quick", [True, False])
def test_a_figure_laid_out_once_is_the_file_savefig_writes(tmp_path, quick, layout):
    """save lays a figure out once and draws it once; savefig with the layout engine
    and the tight box lays it out in a draw of its own first. The two files hold the
    same pixels, exactly (the same layout and the same renderer: nothing to round)."""
    from matplotlib.image import imread
    from matplotlib.layout_engine import ConstrainedLayoutEngine
    with figures.quick_figures(quick):
        figures.save(_busy_figure(layout), str(tmp_path), "once.png")
        fig = _busy_figure(layout)        # as save wrote it before: savefig does it all
        figures._tidy_axes(fig)
        if quick:
            figures._no_minor_log_ticks(fig)
        tight = not (quick and isinstance(fig.get_layout_engine(), ConstrainedLayoutEngine))
        fig.savefig(tmp_path / "savefig.png", dpi=figures.DPI,
                    bbox_inches="tight" if tight else None)
        plt.close(fig)
    once, ref = imread(tmp_path / "once.png"), imread(tmp_path / "savefig.png")
    assert once.shape == ref.shape
    assert np.array_equal(once, ref)


def test_the_plates_quick_m_refinement_says_its_delta():
    st, quick = _levels("m", "plate2d-clamped", True)
    assert {round(lv["spacing"] * lv["m_ratio"], 12) for lv in quick} == {0.4}
    assert st.fixed_in(True) == "delta = 0.4" and st.fixed_in(False) == "delta = 0.2"
    assert st.used_levels(False) == st.levels


def test_quick_levels_must_keep_what_the_study_fixes():
    """What a study fixes is read from the scene's Discretisation of its levels: quick
    levels that do not keep it are refused when the study says what it fixes."""
    st = convergence._m("plate2d-clamped", "m", [(0.1, 2), (0.05, 4)],
                        quick=[(0.2, 2), (0.1, 3)])
    assert st.fixed_in(False) == "delta = 0.2"
    with pytest.raises(ValueError, match="--quick.*do not keep delta fixed"):
        st.fixed_in(True)
    st = convergence._m("plate2d-clamped", "delta", [(0.2, 3), (0.1, 3)],
                        quick=[(0.2, 3), (0.1, 2)])
    assert st.fixed_in(False) == "m = 3"
    with pytest.raises(ValueError, match="--quick.*do not keep m fixed"):
        st.fixed_in(True)
