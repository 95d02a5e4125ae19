"""Shared pytest configuration: Agg backend, strict float errors, seeded rng, the two
test tiers (tests marked ``slow`` are skipped unless ``--runslow``; the README's test
command runs the fast tier, ``.ci/run`` then runs the slow one with ``--runslow -m slow``),
and both tiers on every core the process may use (pytest-xdist, one worker a core; ``-n 0``
or ``-p no:xdist`` runs serially)."""
import os

os.environ.setdefault("MPLBACKEND", "Agg")

import numpy as np
import pytest


@pytest.fixture(autouse=True)
def _strict_float_errors():
    old = np.seterr(all="raise", under="ignore")
    yield
    np.seterr(**old)


@pytest.fixture(scope="session", autouse=True)
def fem_cache_dir(tmp_path_factory, request):
    """One cache folder of FEM references (and manufactured loads) for the whole session,
    never the user's: the tests see a cold cache on any machine, as CI does, and each
    reference the session needs is computed once and read by every later test and
    subprocess (issue 32: the references were computed per module, or read from whatever
    the user's cache held). Tests of the cache itself set a folder of their own."""
    from reference_fem.cache import ENV_VAR
    old = os.environ.get(ENV_VAR)
    if hasattr(request.config, "workerinput"):
        # one folder for the run's workers (their temporary folders are the subfolders of
        # the run's own, which is new for each run): a reference one worker computed is
        # read by the others, and two workers needing it at once compute it once (the
        # cache's lock per entry, reference_fem/cache.py)
        path = tmp_path_factory.getbasetemp().parent / "pdverify-cache"
        path.mkdir(exist_ok=True)
    else:
        path = tmp_path_factory.mktemp("pdverify-cache")
    os.environ[ENV_VAR] = str(path)
    yield path
    if old is None:
        os.environ.pop(ENV_VAR, None)
    else:
        os.environ[ENV_VAR] = old


@pytest.fixture(autouse=True)
def _one_blas_thread(request):
    """Every test computes with one BLAS thread, as every run does (pdverify.blas): the
    numbers a test computes beside a run's are made the same way, and the suite does not
    depend on OpenBLAS's threads, which on a busy 2-core machine turned the dense rank
    checks of tests/treatments/test_taylor_3d.py (a 712 x 864 SVD: 0.17 s with one thread)
    into 4.4 s each (issue 32). Tests of the thread setting itself opt out with
    ``@pytest.mark.blas_default_threads`` and see the process's own setting."""
    if request.node.get_closest_marker("blas_default_threads"):
        yield
        return
    from pdverify import blas
    with blas.one_thread():
        yield


#: glibc's ``mallopt`` parameter M_MMAP_THRESHOLD, and the size the test processes give it
#: (``PDVERIFY_TEST_MMAP_THRESHOLD`` bytes; 0: glibc's own, for comparing)
_M_MMAP_THRESHOLD = -3
MMAP_THRESHOLD = int(os.environ.get("PDVERIFY_TEST_MMAP_THRESHOLD", 1 << 20))


def pytest_configure(config):
    """In each test process (the xdist workers, the serial run), allocations of at least
    :data:`MMAP_THRESHOLD` bytes get pages of their own, returned to the system when freed
    (glibc; elsewhere nothing). glibc's default raises that threshold to 32 MB as large
    blocks are freed, after which the arrays of a solve came from the heaps, whose freed
    pages stayed with the process (issue 32: an xdist worker grew from 0.32 GB to 1.2 GB
    over the fast tier, and two such workers in heavy tests at the same time held 2.9 GB,
    over the 2.5 GB budget; tests/pdverify/test_rate_gates.py and
    tests/corrections/test_bond_methods.py in one process: peak 0.62 GB, 0.56 GB left
    resident, against 0.49 and 0.48 GB with 1 MB, at about the same CPU time). Where memory
    comes from changes no computed number (the report is bitwise the same in any worker
    process, tests/pdverify/test_cli.py)."""
    if MMAP_THRESHOLD > 0:
        import ctypes
        try:
            ctypes.CDLL(None).mallopt(_M_MMAP_THRESHOLD, MMAP_THRESHOLD)
        except (OSError, AttributeError):  # not glibc
            pass


def _release_freed_memory():
    """Hand the memory that freed objects left in the C allocator's heap back to the
    system (glibc's ``malloc_trim``; elsewhere nothing). A test file's arrays, freed at its
    end, stayed resident in the process that ran it: an xdist worker grew by every file it
    ran (0.32 GB after collection to 1.2 GB over the fast tier), and two such workers,
    each in a heavy test at the same time, held 2.9 GB (issue 32's 2.5 GB budget). Only
    pages no object uses are given back, so no computed number changes."""
    import gc
    from pdverify.budget import release_freed_memory
    gc.collect()
    release_freed_memory()


@pytest.hookimpl(wrapper=True)
def pytest_runtest_teardown(item, nextitem):
    """After a test file's last test (its module fixtures torn down), the memory it freed
    goes back to the system (:func:`_release_freed_memory`)."""
    try:
        return (yield)
    finally:
        if nextitem is None or nextitem.path != item.path:
            _release_freed_memory()


@pytest.fixture
def rng():
    return np.random.default_rng(20211121)


@pytest.hookimpl(tryfirst=True)
def pytest_cmdline_main(config):
    """Both tiers run on every core the process may use (issue 32: the fast tier took
    5:35 on one core of a 2-core machine): one pytest-xdist worker a core, unless the
    command line chose (``-n N``, ``-n 0`` or ``-p no:xdist`` for a serial run, ``--pdb``),
    the process has one core, or this is a worker itself. ``--bench`` runs serially: the
    timing benchmarks measure against their budgets with no other test beside them. Each
    test file goes to one worker as a whole (``--dist loadfile``), so the module-scoped
    fixtures, which share their runs among a file's tests, are computed once, as in a
    serial run."""
    if not config.pluginmanager.hasplugin("xdist") or hasattr(config, "workerinput"):
        return
    if os.environ.get("PYTEST_XDIST_WORKER") or config.option.numprocesses is not None:
        return
    if config.getoption("usepdb") or config.getoption("collectonly") \
            or config.getoption("--bench"):
        return
    cores = len(os.sched_getaffinity(0))
    if cores > 1:
        config.option.numprocesses = cores
        if config.option.dist == "no":
            config.option.dist = "loadfile"


#: ``PDVERIFY_TEST_TRACE=DIR``: each test process appends to ``DIR/<pid>.log`` a line
#: ``start|end MONOTONIC_SECONDS RSS_BYTES PEAK_BYTES NODEID`` as each test starts and ends
#: (CLOCK_MONOTONIC, the same clock in every process; the process's own resident set, and
#: at ``end`` its largest resident set since the test's start, setup and teardown
#: included: Linux's VmHWM, reset at each start through /proc/self/clear_refs; at
#: ``start`` the RSS again), so benchmarks/tiers.py --trace can name the test each xdist
#: worker ran when the tree's memory peaked, what each file left resident, and each
#: test's own peak. Unset (the default): nothing.
_TRACE = os.environ.get("PDVERIFY_TEST_TRACE")


def _trace(what, nodeid):
    import time
    with open("/proc/self/statm") as fh:
        rss = int(fh.read().split()[1]) * os.sysconf("SC_PAGE_SIZE")
    from pdverify.budget import peak_rss, reset_peak_rss
    peak = rss
    if what == "start":
        reset_peak_rss()
    else:
        peak = int(peak_rss() or rss)
    with open(os.path.join(_TRACE, f"{os.getpid()}.log"), "a") as fh:
        fh.write(f"{what} {time.monotonic():.3f} {rss} {peak} {nodeid}\n")


if _TRACE:
    def pytest_runtest_logstart(nodeid, location):
        _trace("start", nodeid)

    def pytest_runtest_logfinish(nodeid, location):
        _trace("end", nodeid)


def pytest_addoption(parser):
    parser.addoption("--bench", action="store_true", default=False,
                     help="run the timing benchmarks (marked 'bench') against the issues' budgets")
    parser.addoption("--runslow", action="store_true", default=False,
                     help="also run the tests marked 'slow' (CI's second tier)")


def pytest_collection_modifyitems(config, items):
    bench = config.getoption("--bench")
    slow = config.getoption("--runslow")
    skip_bench = pytest.mark.skip(reason="timing benchmark: run with --bench")
    skip_slow = pytest.mark.skip(reason="slow tier: run with --runslow")
    for item in items:
        if "bench" in item.keywords and not bench:
            item.add_marker(skip_bench)
        if "slow" in item.keywords and not slow:
            item.add_marker(skip_slow)


_SHARED_RUNS = {}


@pytest.fixture(scope="session")
def run_once():
    """``run_once(scene, method, **over)``: the scene's run, made once per test session and
    shared by every test that asks for the same scene, method and parameters (issue 32:
    several files re-ran the same default case). The runs are deterministic (the report is
    bitwise reproducible), so a shared result is the one each test would have made; tests
    read it and must not change it. A test that patches pdverify must call the scene
    itself."""
    from pdverify.scenes import get_scene

    def run(scene, method=None, **over):
        key = (scene, method, repr(sorted(over.items())))
        if key not in _SHARED_RUNS:
            _SHARED_RUNS[key] = get_scene(scene).run(method, dict(over))
        return _SHARED_RUNS[key]
    return run


#: the program behind ``cli_concurrently``: one interpreter imports the modules every
#: ``python -m pdverify run`` imports (the command line, the runner, the scene modules), then
#: forks one process per argv, at most one per core at a time. Each child runs
#: ``python -m pdverify ARGV`` as the interpreter would (``runpy``, ``sys.argv``, an
#: uncaught exception printed by ``sys.excepthook`` with exit status 1, ``SystemExit``'s
#: code) with its stdout and stderr on files of its own; the parent reports each child's
#: exit status as ``subprocess`` does (-N for a signal) and the two texts, as JSON.
_FORK_SERVER = r"""
import json, os, runpy, sys, tempfile
import pdverify.cli, pdverify.runner, pdverify.scenes
pdverify.scenes.all_scenes()        # the scene modules, which every run imports first
argvs, cores = json.loads(sys.argv[1]), int(sys.argv[2])
tmp = tempfile.mkdtemp(prefix="pdverify-cli-")
files = [(os.path.join(tmp, f"{k}.out"), os.path.join(tmp, f"{k}.err")) for k in range(len(argvs))]
sys.stdout.flush(); sys.stderr.flush()

def child(k):
    code = 1
    try:
        for fd, path in ((1, files[k][0]), (2, files[k][1])):
            os.dup2(os.open(path, os.O_WRONLY | os.O_CREAT | os.O_TRUNC, 0o600), fd)
        sys.argv = ["pdverify", *argvs[k]]
        try:
            runpy.run_module("pdverify", run_name="__main__", alter_sys=True)
            code = 0
        except SystemExit as exc:
            if exc.code is None:
                code = 0
            elif isinstance(exc.code, int):
                code = exc.code
            else:
                print(exc.code, file=sys.stderr)
                code = 1
        except BaseException:
            sys.excepthook(*sys.exc_info())
            code = 1
        sys.stdout.flush(); sys.stderr.flush()
    finally:
        os._exit(code & 0xFF)

status, running, todo = {}, {}, list(range(len(argvs)))
while todo or running:
    while todo and len(running) < cores:
        k = todo.pop(0)
        pid = os.fork()
        if pid == 0:
            child(k)
        running[pid] = k
    pid, st = os.wait()
    status[running.pop(pid)] = os.waitstatus_to_exitcode(st)
out = []
for k in range(len(argvs)):
    texts = []
    for path in files[k]:
        with open(path) as fh:
            texts.append(fh.read())
        os.remove(path)
    out.append([status[k], *texts])
os.rmdir(tmp)
print(json.dumps(out))
"""


@pytest.fixture(scope="session")
def cli_concurrently():
    """``cli_concurrently(argvs, env=None, cwd=None)``: each argv run as
    ``python -m pdverify ARGV`` in a process of its own, as many at a time as the process
    has cores; returns ``{tuple(argv): CompletedProcess}`` with each process's exit
    status and its stdout and stderr. For the tables of bad-input cases, whose cost was
    each interpreter's start (issue 32): the processes are forked from one interpreter
    that has imported what ``run`` imports before reading its arguments (as the report's
    workers are forked), so the cases no longer pay numpy's and scipy's import each
    (0.8 s of CPU a case); what a case prints and its exit status are its own."""
    import json
    import subprocess
    import sys

    def run_all(argvs, env=None, cwd=None, timeout=120):
        argvs = [tuple(a) for a in argvs]
        cores = len(os.sched_getaffinity(0))
        server = subprocess.run([sys.executable, "-c", _FORK_SERVER, json.dumps(argvs),
                                 str(cores)], capture_output=True, text=True, env=env,
                                cwd=cwd, timeout=timeout * max(1, len(argvs) // cores))
        assert server.returncode == 0, server.stderr
        done = json.loads(server.stdout.splitlines()[-1])
        return {argv: subprocess.CompletedProcess([sys.executable, "-m", "pdverify", *argv],
                                                  code, out, err)
                for argv, (code, out, err) in zip(argvs, done)}
    return run_all
