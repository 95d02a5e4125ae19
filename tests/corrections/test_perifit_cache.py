"""perifit's weights cached on disk (issue 32): the same weights bit for bit, perifit run
once per input, any change of input a miss, an unreadable entry recomputed, and the
weights' time kept in the run's cost."""
import numpy as np
import pytest

from pdverify import results
from pdverify.scenes import get_scene

pytest.importorskip("perifit")

#: a small sheet (10 x 20 cells): perifit's 2D weights in well under a second
SMALL = {"spacing": 0.005}


@pytest.fixture
def cache(tmp_path, monkeypatch):
    """A cache folder of the test's own, and a count of perifit's 2D computations."""
    import perifit
    monkeypatch.setenv("PDVERIFY_CACHE_DIR", str(tmp_path))
    calls = []
    real = perifit.compute_weights_2d

    def counted(*args, **kwargs):
        calls.append(1)
        return real(*args, **kwargs)

    monkeypatch.setattr(perifit, "compute_weights_2d", counted)
    return tmp_path, calls


def test_a_second_run_reads_the_same_weights_from_the_cache(cache):
    folder, calls = cache
    scene = get_scene("stiffness2d-sheet")
    first = scene.run("perifit", SMALL)
    second = scene.run("perifit", SMALL)
    assert first.status == second.status == "ok"
    assert len(calls) == 1                              # perifit ran once
    assert len(list((folder / "perifit").glob("*.npz"))) == 1
    # the same weights: every metric bit for bit (exactness of a stored float64 array)
    assert second.metrics == first.metrics
    assert first.diagnostics["perifit_weights"].startswith("computed")
    assert second.diagnostics["perifit_weights"].startswith("read from the cache")
    # the cached weights' time is the run's cost: what they took when computed, which
    # the first run measured inside its setup
    assert results.CACHED_SETUP not in first.timings
    cached = second.timings[results.CACHED_SETUP]
    assert 0 < cached <= first.timings["setup_s"]
    assert results.cost_s(second.timings) == pytest.approx(
        second.timings["setup_s"] + second.timings["solve_s"] + cached,
        rel=1e-15)  # the same three terms summed: at most round-off of the order


def test_every_input_of_the_weights_is_in_the_key(cache):
    """A change of positions, volumes, horizon or bonds is another entry."""
    import copy

    from pdverify.corrections.perifit_weights import _kind, cache_key
    model = _built_model()
    kind = _kind(model)
    base = cache_key(model, kind)
    assert cache_key(model, kind) == base               # deterministic
    changes = {
        "positions": lambda m: m.grid.__setattr__("x", m.grid.x + 1e-12),
        "volumes": lambda m: m.__setattr__("node_volume", m.node_volume * (1 + 1e-15)),
        "horizon": lambda m: m.__setattr__("horizon", np.nextafter(m.horizon, 1.0)),
        "bonds": lambda m: m.__setattr__("bond_b", m.bond_b[::-1].copy()),
    }
    for name, change in changes.items():
        m = copy.copy(model)
        m.grid = copy.copy(model.grid)
        change(m)
        assert cache_key(m, kind) != base, name


def test_an_unreadable_entry_is_computed_again_and_replaced(cache):
    folder, calls = cache
    from pdverify.corrections.perifit_weights import node_weights
    model = _built_model()
    w = node_weights(model)
    (entry,) = (folder / "perifit").glob("*.npz")
    for damage in (b"", b"not an npz", entry.read_bytes()[:100]):
        entry.write_bytes(damage)
        again = node_weights(model)
        np.testing.assert_array_equal(again, w)         # exact: the same computation
    assert len(calls) == 4                               # each damaged entry a miss
    np.testing.assert_array_equal(node_weights(model), w)
    assert len(calls) == 4                               # ... and replaced whole


def _built_model():
    """The uncorrected bond-based model of the small sheet (what perifit is given)."""
    from pdverify.pd import BondBasedModel, BoxGrid, build_stencil, get_influence
    g = BoxGrid((0.1, 0.05), (0.0, 0.0), 0.005, 0)
    return BondBasedModel(g, build_stencil(2, 5.0, quadrature="full-cells"), 1.0,
                          get_influence("constant"))


def test_a_note_outside_a_run_is_dropped_and_inside_is_collected():
    results.note(diagnostics={"x": 1}, timings={"t_s": 1.0})   # no run: nothing happens
    with results.collecting_notes() as notes:
        results.note(diagnostics={"x": 1}, timings={"t_s": 1.0})
        results.note(timings={"t_s": 0.5})
    assert notes == {"diagnostics": {"x": 1}, "timings": {"t_s": 1.5}}


def test_the_report_counts_the_cached_setup_in_the_cost_and_says_so():
    """The front page's cost and the scene table: setup + solve + the cached setup's
    time, and the row names the part read from the cache."""
    from pdverify.report import html
    sheet = get_scene("stiffness2d-sheet")
    timings = {"setup_s": 0.25, "solve_s": 0.5, "total_s": 0.8, results.CACHED_SETUP: 16.0}
    run = results.RunResult(scene=sheet.id, method="perifit",
                            params=sheet.resolve("perifit", {}), reference=sheet.reference,
                            metrics={"surface_energy_error_pct": 50.0}, timings=timings)
    assert html.cost_s(run) == 16.75                    # exact in binary floating point
    row = html._row(sheet, run, ["surface_energy_error_pct"])
    assert row["setup"] + row["cached"] == "0.25 (+ 16 s from the cache)"
    assert row["total"] == "16.8" and row["cached_note"] == "incl. 16 s cached"
    section = str(html.scene_section(sheet, [run], []))
    assert "(+ 16 s from the cache)" in section
    assert results.time_s(timings) == 16.8              # the summary's time: total + cached
