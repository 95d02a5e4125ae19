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
    assert "0.001 &#9733;" in bar_row and "0.03<" in bar_row   # default run, best starred
    assert "1e-20" not in bar_row                                # sweep runs stay below
    assert 'title="plate2d-clamped/none: singular &lt;x&gt;">failed' in plate_row
    assert "reference" in plate_row
    assert "&#9733;" not in plate_row                            # one ok PD run: no ranking
