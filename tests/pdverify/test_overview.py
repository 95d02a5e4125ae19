"""The report's front-page matrix (issue 17, part): headline error per scene and method at
the method's default params, best starred, failures red with the reason on hover."""
from pdverify.report.html import overview
from pdverify.results import RunResult
from pdverify.scenes import get_scene


def _run(scene, method, over=None, status="ok", message="", **metrics):
    return RunResult(scene=scene.id, method=method, params=scene.resolve(method, over or {}),
                     reference=scene.reference, status=status, message=message,
                     metrics=metrics, timings={"total_s": 0.5})


def test_matrix_cells_best_failed_and_reference():
    bar, plate = get_scene("bar1d-traction"), get_scene("plate2d-clamped")
    runs = [_run(bar, "none", rel_l2_error=0.03),
            _run(bar, "taylor-fictitious", {"order": 3}, rel_l2_error=1e-20),  # not default
            _run(bar, "taylor-fictitious", rel_l2_error=1e-3),
            _run(plate, "fem"),
            _run(plate, "none", status="failed", message="plate2d-clamped/none: singular <x>"),
            _run(plate, "taylor-fictitious", rel_l2_error=0.0166)]
    text = overview([bar, plate], runs)
    bar_row, plate_row = text.split("<tr>")[2:4]
    # default runs in per cent, the best method starred (issue 34: one unit)
    assert "0.1 %</span> &#9733;" in bar_row and ">3 %<" in bar_row
    # the sweep's more accurate run is the method's best configuration, shown as exact
    # (round-off) beneath the default with its params (issue 34)
    best = bar_row.split('class="best"')[1]
    assert ">exact<" in best and "order=<wbr>3" in best
    assert 'title="plate2d-clamped/none: singular &lt;x&gt;">failed' in plate_row
    assert "reference" in plate_row
    assert "&#9733;" not in plate_row                            # one ok PD run: no ranking
