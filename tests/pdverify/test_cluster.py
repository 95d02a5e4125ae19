"""report --scheduler: the cases on a Dask cluster give the same results, bit for bit."""
import json
import os
import re
import signal
import socket
import subprocess
import sys
import time
from pathlib import Path

import pytest

from pdverify.cluster import scheduler_address
from pdverify.errors import InputError
from pdverify.runner import plan, run_cases

distributed = pytest.importorskip("distributed")

ROOT = Path(__file__).resolve().parents[2]
#: seconds for the scheduler and both workers to come up, and for any report of one small
#: scene on them (bounds, not expectations: each takes a few seconds on a loaded machine)
START_S = 60
REPORT_S = 300


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


def _free_port() -> int:
    """A free loopback port: bind port 0 and take what the kernel chose."""
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def _dask(role: str) -> list[str]:
    """The command that starts a Dask ``role`` (scheduler or worker): the ``dask``
    executable next to this Python, else the module behind it."""
    exe = Path(sys.executable).with_name("dask")
    if exe.exists():
        return [str(exe), role]
    return [sys.executable, "-m", f"distributed.cli.dask_{role}"]


@pytest.fixture()
def dask_cluster(tmp_path):
    """A scheduler and two one-thread workers started as separate processes with Dask's
    command line, on loopback; yields (address, env, the scheduler's process, the
    workers' processes). Each runs
    in its own session, so killing one kills its nanny and its worker process together;
    all are killed at the end."""
    path = [str(ROOT)] + [p for p in os.environ.get("PYTHONPATH", "").split(os.pathsep) if p]
    env = dict(os.environ, PDVERIFY_CACHE_DIR=str(tmp_path / "cache"),
               PYTHONPATH=os.pathsep.join(path))  # the workers import this pdverify
    port = _free_port()
    address = f"tcp://127.0.0.1:{port}"
    procs = []

    def start(cmd, log):
        procs.append(subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=open(log, "w"),
                                      env=env, start_new_session=True, cwd=tmp_path))
        return procs[-1]

    try:
        scheduler = start(_dask("scheduler") + ["--host", "127.0.0.1", "--port", str(port),
                                    "--dashboard-address", "127.0.0.1:0"], tmp_path / "s.log")
        workers = [start(_dask("worker") + [address, "--nworkers", "1", "--nthreads", "1",
                                            "--host", "127.0.0.1"], tmp_path / f"w{k}.log")
                   for k in range(2)]
        with distributed.Client(address, timeout=f"{START_S}s") as client:
            client.wait_for_workers(2, timeout=START_S)
        yield address, env, scheduler, workers
    finally:
        for p in procs:
            try:
                os.killpg(p.pid, signal.SIGKILL)
            except ProcessLookupError:
                pass
        for p in procs:
            p.wait(timeout=30)


def _comparable(doc):
    """results.json without what differs between two runs of the same numbers: the
    machine's costs (test_report_safety's _strip) and whether a reference came from the
    cache (the first report computed it, the second read it)."""
    doc = dict(doc)
    for key in ("created", "machine", "report_phases"):
        doc.pop(key)
    runs = []
    for r in doc["runs"]:
        r = {k: v for k, v in r.items() if k not in ("timings", "resources")}
        r["diagnostics"] = {k: v for k, v in r.get("diagnostics", {}).items()
                            if k not in ("from_cache", "perifit_weights")}
        runs.append(r)
    doc["runs"] = runs
    doc["convergence"] = [{**e, "levels": [{k: v for k, v in lv.items() if k != "total_s"}
                                           for lv in e["levels"]]}
                          for e in doc["convergence"]]
    return doc


def _report(out, env, *extra):
    return subprocess.Popen([sys.executable, "-m", "pdverify", "report", "--out", str(out),
                             *extra], stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            text=True, env=env, cwd=out.parent)


@pytest.mark.slow  # slow tier (issue 32): 7 s, separate scheduler and worker processes
def test_separate_scheduler_and_workers_give_the_local_results_bitwise(tmp_path, dask_cluster):
    """The issue 52 bug: against a scheduler started with `dask scheduler`, the report
    ended in a traceback ("No clients found"); the in-process LocalCluster test above
    could not see it (its Client is the default one)."""
    address, env, _, _ = dask_cluster
    scene = ["--only", "bar1d-traction"]
    remote = _report(tmp_path / "remote", env, *scene, "--scheduler", address)
    _, err = remote.communicate(timeout=REPORT_S)
    assert remote.returncode == 0, err
    assert "Traceback" not in err
    local = _report(tmp_path / "local", env, *scene, "--jobs", "1")
    _, err = local.communicate(timeout=REPORT_S)
    assert local.returncode == 0, err
    docs = [json.loads((tmp_path / d / "results.json").read_text()) for d in ("remote", "local")]
    assert len(docs[0]["runs"]) == len(docs[1]["runs"]) > 0
    # bitwise: the JSON of every float is the shortest repr that round-trips
    assert json.dumps(_comparable(docs[0])) == json.dumps(_comparable(docs[1]))


@pytest.mark.slow  # slow tier (issue 32): 21 s, separate scheduler and worker processes
def test_a_worker_killed_mid_report_leaves_a_complete_report_or_one_line(tmp_path,
                                                                         dask_cluster):
    """The scheduler gives a dead worker's task to the other one (or, past Dask's
    allowed-failures, it comes back as a failed run naming it): every case is in
    results.json; else one line and a nonzero exit, never a traceback."""
    address, env, _, workers = dask_cluster
    scene = ["--only", "sheet2d-clamped", "--quick"]
    expected = len(plan(only=["sheet2d-clamped"], quick=True))
    p = _report(tmp_path / "rep", env, *scene, "--scheduler", address)
    try:
        first = p.stderr.readline()  # the first finished run's progress line
        assert re.match(r"\[1/\d+\]", first), first
        os.killpg(workers[0].pid, signal.SIGKILL)
        killed_at = time.monotonic()
        out, rest = p.communicate(timeout=REPORT_S)
    finally:
        if p.poll() is None:
            p.kill()
            p.wait(timeout=30)
    err = first + rest
    assert "Traceback" not in err, err
    assert workers[0].wait(timeout=30) is not None
    if p.returncode == 0:
        runs = json.loads((tmp_path / "rep" / "results.json").read_text())["runs"]
        assert len(runs) == expected
        for r in runs:
            assert r["status"] == "ok" or "the cluster task failed" in r["message"], r
    else:
        lines = [s for s in err.splitlines() if s.startswith("pdverify: error:")]
        assert p.returncode == 1 and len(lines) == 1, err
    assert time.monotonic() - killed_at < REPORT_S


@pytest.mark.slow  # slow tier (issue 32): 14 s, separate scheduler and worker processes
def test_a_scheduler_killed_mid_report_is_one_line_and_exit_1(tmp_path, dask_cluster):
    """The client cancels every future when it loses its scheduler: the report (17 runs)
    stops with one line naming the scheduler (ClusterError, exit 1) and publishes nothing."""
    address, env, scheduler, _ = dask_cluster
    p = _report(tmp_path / "rep", env, "--only", "sheet2d-clamped", "--quick",
                "--scheduler", address)
    try:
        first = p.stderr.readline()
        assert re.match(r"\[1/\d+\]", first), first
        os.killpg(scheduler.pid, signal.SIGKILL)
        out, rest = p.communicate(timeout=REPORT_S)
    finally:
        if p.poll() is None:
            p.kill()
            p.wait(timeout=30)
    assert "Traceback" not in rest, rest
    # 16 runs were still out when the scheduler died: they cannot all have finished
    assert p.returncode == 1, rest
    others = [s for s in rest.splitlines() if s.strip() and not s.startswith("[")]
    assert len(others) == 1, rest
    assert others[0].startswith(f"pdverify: error: --scheduler: lost the Dask scheduler at "
                                f"{address} after "), rest
    assert not (tmp_path / "rep" / "results.json").exists()
