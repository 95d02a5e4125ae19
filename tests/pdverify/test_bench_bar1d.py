"""Timing benchmarks for issue #2's budgets (run with --bench; whole processes, median of 3)."""
import statistics
import subprocess
import sys
import time
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]


def wall(args, repeat=3):
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        proc = subprocess.run([sys.executable, "-m", "pdverify", *args], cwd=ROOT,
                              capture_output=True, text=True, timeout=300)
        times.append(time.perf_counter() - t0)
        assert proc.returncode == 0, proc.stderr
    return statistics.median(times)


@pytest.mark.bench
def test_2000_node_traction_under_2_s():
    # issue #2 Speed: `run bar1d-traction --method taylor-fictitious --set spacing=0.0005`
    # (2000 nodes) in under 2 s on a 2-core machine, interpreter start-up included.
    t = wall(["run", "bar1d-traction", "--method", "taylor-fictitious", "--set", "spacing=0.0005"])
    print(f"\n2000-node traction: median {t:.2f} s (budget 2 s)")
    assert t < 2.0


@pytest.mark.bench
def test_1d_report_under_10_s(tmp_path):
    # issue #2 Speed: the whole 1D part of the report in under 10 s.
    t = wall(["report", "--out", str(tmp_path), "--only", "bar1d-traction", "bar1d-uniform-load",
              "bar1d-linear-load", "bar1d-sine-load", "bar1d-force-flux"])
    print(f"\n1D report: median {t:.2f} s (budget 10 s)")
    assert t < 10.0
