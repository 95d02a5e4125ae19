"""On-disk cache: hits, misses, keys, bad input."""
import time

import numpy as np
import pytest

import reference_fem as rf
from reference_fem import cache

# a cheap configuration of the tension sheet (closed-form exact on any mesh)
CHEAP = dict(spacing=0.025, levels=2)


@pytest.fixture
def cache_dir(tmp_path, monkeypatch):
    monkeypatch.setenv(cache.ENV_VAR, str(tmp_path))
    return tmp_path


def test_unchanged_parameters_hit_changed_miss(cache_dir):
    first = rf.tension_sheet(**CHEAP)
    assert not first.from_cache
    assert len(list(cache_dir.glob("sheet2d-tension-*.npz"))) == 1
    again = rf.tension_sheet(**CHEAP)
    assert again.from_cache and again.cache_key == first.cache_key
    # the cached copy is the same result
    assert again.quantity == first.quantity and again.params == first.params
    np.testing.assert_array_equal(again.field.values, first.field.values)
    assert [r.quantity for r in again.refinement] == [r.quantity for r in first.refinement]
    pts = np.array([[0.01, 0.02]])
    np.testing.assert_array_equal(again.evaluate(pts), first.evaluate(pts))
    # any changed parameter misses, and gets its own file
    changed = rf.tension_sheet(traction=2e6, **CHEAP)
    assert not changed.from_cache and changed.cache_key != first.cache_key
    assert len(list(cache_dir.glob("sheet2d-tension-*.npz"))) == 2
    np.testing.assert_allclose(changed.quantity, 2 * first.quantity, rtol=1e-10)


def test_equal_values_of_other_type_share_the_key(cache_dir):
    a = rf.tension_sheet(**CHEAP)
    b = rf.tension_sheet(E=1000000000, spacing=0.025, levels=2.0)
    assert b.from_cache and b.cache_key == a.cache_key


def test_key_covers_version(monkeypatch):
    params = {"x": 1.0}
    k1 = cache.cache_key("r", params)
    monkeypatch.setattr(rf, "__version__", "999")
    assert cache.cache_key("r", params) != k1


def test_use_cache_false_neither_reads_nor_writes(cache_dir):
    res = rf.tension_sheet(use_cache=False, **CHEAP)
    assert not res.from_cache
    assert list(cache_dir.iterdir()) == []


def test_corrupt_cache_file_is_recomputed(cache_dir):
    rf.tension_sheet(**CHEAP)
    (path,) = cache_dir.glob("*.npz")
    path.write_bytes(b"not an npz")
    res = rf.tension_sheet(**CHEAP)
    assert not res.from_cache
    assert rf.tension_sheet(**CHEAP).from_cache


def test_default_cache_dir_is_under_user_cache(monkeypatch, tmp_path):
    monkeypatch.delenv(cache.ENV_VAR, raising=False)
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path))
    assert cache.cache_dir() == tmp_path / "pdverify" / "reference_fem"


def test_bad_parameters_fail_before_work(cache_dir):
    with pytest.raises(TypeError, match=r"unknown parameter\(s\) horizn; allowed: horizon"):
        rf.clamped_sheet(horizn=0.01)
    with pytest.raises(TypeError, match="levels=2.5 is not a valid int"):
        rf.clamped_plate(levels=2.5)
    with pytest.raises(ValueError, match="block2d-indentation: depth must be below the radius"):
        rf.indentation(depth=0.02)
    with pytest.raises(ValueError, match="spacing 0.7 must divide length"):
        rf.clamped_plate(spacing=0.7)
    assert list(cache_dir.iterdir()) == []


def test_cached_reuse_is_fast(cache_dir):
    rf.tension_sheet(**CHEAP)
    t0 = time.perf_counter()
    rf.tension_sheet(**CHEAP)
    # generous functional bound (issue budget 1 s is checked in the bench test)
    assert time.perf_counter() - t0 < 5.0


def test_two_processes_needing_one_reference_compute_it_once(cache_dir):
    """A report's FEM run and a PD run of the same scene ask for the same reference at
    once: the first computes it under the key's lock, the other waits and reads it."""
    import multiprocessing as mp
    with mp.get_context("fork").Pool(2) as pool:
        got = pool.map(_sheet, [str(cache_dir)] * 2)
    assert got[0][0] == got[1][0]                       # the same entry
    assert sorted(g[1] for g in got) == [False, True]   # computed once, read once
    assert (cache_dir / "calls").read_text() == "x"
    assert len(list(cache_dir.glob("sheet2d-tension-*.npz"))) == 1


def _sheet(folder):
    from pathlib import Path

    from reference_fem.tension_sheet import TensionSheetResult

    def slow():
        with open(Path(folder) / "calls", "a") as f:
            f.write("x")
        time.sleep(1.0)            # long enough for the other process to arrive
        return rf.tension_sheet(use_cache=False, **CHEAP)
    res = cache.cached("sheet2d-tension", {"probe": 1}, slow,
                       {"TensionSheetResult": TensionSheetResult})
    return res.cache_key, res.from_cache
