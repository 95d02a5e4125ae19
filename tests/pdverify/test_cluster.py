"""report --scheduler: the cases on a Dask cluster give the same results, bit for bit."""
import json
import subprocess
import sys

import pytest

from pdverify.cluster import scheduler_address
from pdverify.errors import InputError
from pdverify.runner import plan, run_cases

distributed = pytest.importorskip("distributed")


@pytest.mark.slow  # slow tier (issue 32): 68 s of the suite's 3811 s (loaded machine)
def test_local_cluster_results_equal_the_local_pool_bitwise():
    cases = plan(only=["bar1d-traction", "sheet2d-clamped", "wave1d-surface-nodes"], quick=True)
    local = run_cases(cases, jobs=1)
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                  dashboard_address=None) as cluster, \
            distributed.Client(cluster) as client:
        lines = []

        class Sink:
            def write(self, text):
                lines.append(text)

            def flush(self):
                pass

        remote = run_cases(cases, client=client, progress=Sink())
    assert len(remote) == len(local) == len(cases)
    for a, b in zip(local, remote):
        assert (a.scene, a.method, a.status) == (b.scene, b.method, b.status)
        assert json.dumps(a.params, sort_keys=True) == json.dumps(b.params, sort_keys=True)
        # bitwise: the JSON of every float is the shortest repr that round-trips
        assert json.dumps(a.metrics, sort_keys=True) == json.dumps(b.metrics, sort_keys=True)
    assert sum("] " in s for s in lines) == len(cases)  # one progress line per run


@pytest.mark.parametrize("value", ["not an address", "tcp://", "http://x:1", "host:port"])
def test_bad_scheduler_address_is_refused(value):
    with pytest.raises(InputError, match="expected a Dask scheduler address"):
        scheduler_address(value)


def test_scheduler_from_the_environment(monkeypatch):
    monkeypatch.setenv("PDVERIFY_SCHEDULER", "tcp://127.0.0.1:8786")
    assert scheduler_address(None) == "tcp://127.0.0.1:8786"
    monkeypatch.setenv("PDVERIFY_SCHEDULER", "nope")
    with pytest.raises(InputError, match="PDVERIFY_SCHEDULER='nope'"):
        scheduler_address(None)
    monkeypatch.delenv("PDVERIFY_SCHEDULER")
    assert scheduler_address(None) is None


@pytest.mark.slow  # slow tier (issue 32): 12 s: it waits out the 10 s connect timeout (loaded machine)
def test_unreachable_scheduler_exits_2_before_any_work(tmp_path):
    out = tmp_path / "rep"
    p = subprocess.run([sys.executable, "-m", "pdverify", "report", "--out", str(out),
                        "--only", "bar1d-traction", "--scheduler", "tcp://127.0.0.1:9"],
                       capture_output=True, text=True, timeout=120)
    assert p.returncode == 2, p.stderr
    assert "cannot reach a Dask scheduler at tcp://127.0.0.1:9" in p.stderr
    assert len(p.stderr.strip().splitlines()) == 1
    assert not out.exists()
