"""Every run records its peak memory beside its time (issue 32: the 2 GB budget is about
the heaviest run's process, so each run's own peak has to be known)."""
import os
import sys

import numpy as np
import pytest

from pdverify import budget
from pdverify.results import RunResult
from pdverify.scenes import get_scene

pytestmark = pytest.mark.skipif(not sys.platform.startswith("linux"),
                                reason="/proc/self/clear_refs and VmHWM are Linux's")

MB = 1e6


def test_the_peak_is_reset_and_follows_an_allocation():
    assert budget.reset_peak_rss()
    before = budget.peak_rss()
    block = np.ones(300 * 1_000_000 // 8)          # 300 MB, touched
    grown = budget.peak_rss()
    del block
    assert budget.reset_peak_rss()
    after = budget.peak_rss()
    # the 300 MB block shows in the peak (page granularity: 250 MB is a safe floor) and
    # is gone from it after the reset (the block was freed back to the system)
    assert grown - before >= 250 * MB
    assert after < grown - 250 * MB


def test_a_run_records_its_peak_and_results_json_keeps_it(tmp_path):
    r = get_scene("bar1d-traction").run("none")
    peak = r.resources["peak_rss_gb"]
    # at least the interpreter with numpy and scipy loaded (> 30 MB), far below the
    # machine's 24 GB
    assert 0.03 < peak < 24
    again = RunResult.from_json(r.to_json())
    assert again.resources == r.resources


def test_the_report_names_the_heaviest_run():
    from pdverify.report.summary import largest_memory
    light = RunResult("a", "none", {}, "analytic", resources={"peak_rss_gb": 0.1},
                      timings={"total_s": 1.0})
    heavy = RunResult("b", "pddo", {}, "analytic", resources={"peak_rss_gb": 2.5},
                      timings={"total_s": 9.0})
    assert largest_memory([light, heavy]).startswith("largest peak memory of a run: 2.5 GB (b pddo")
    assert largest_memory([RunResult("a", "none", {}, "analytic")]) == ""


def _rss():
    with open("/proc/self/statm") as fh:
        return int(fh.read().split()[1]) * os.sysconf("SC_PAGE_SIZE")


def test_memory_that_earlier_work_freed_is_returned_before_a_run():
    """A run's peak starts from the live memory, not from what earlier runs of the same
    worker freed into the C heaps (budget.release_freed_memory, called by Scene.run): 200
    MB of 64 kB arrays (below glibc's mmap threshold, so heap pages), freed under a
    pinned allocation on top, stay resident until the heap is trimmed."""
    blocks = [np.ones(8192) for _ in range(3200)]     # 3,200 x 64 kB = 210 MB, touched
    pin = np.ones(8192)                               # keeps the heap's top in use
    held = _rss()
    del blocks
    freed = _rss()
    budget.release_freed_memory()
    trimmed = _rss()
    del pin
    # the freed pages stayed (glibc trims only a free top of the heap by itself) unless
    # this allocator returned them at once; the trim returns at least 150 MB of the 210
    # (page granularity and the allocator's own bookkeeping: a safe floor)
    assert held - trimmed >= 150 * MB, (held / MB, freed / MB, trimmed / MB)
