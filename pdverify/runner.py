"""Running scenes: one run for the CLI, and a batch (optionally in parallel) for the report."""
from __future__ import annotations

import os
import sys

from .errors import InputError
from .results import CACHED_SETUP, RunResult, write_results
from .scenes import get_scene


def format_metrics(metrics: dict, limit: int = 4) -> str:
    items = list(metrics.items())[:limit]
    return " ".join(f"{k}={v:.4g}" if isinstance(v, float) else f"{k}={v}" for k, v in items)


def _paper_value(value) -> str:
    return f"{value:.6g}" if isinstance(value, float) else str(value)


def run_one(scene_id: str, *, method=None, overrides=None, json_path=None, vtu_path=None,
            stream=None, run_timeout=None) -> int:
    """``pdverify run``: resolve (exit 2 on bad input), run, print, optionally write JSON.
    ``run_timeout``: seconds; the run then goes to a supervised worker process that is
    killed past it (a failed run, exit 1)."""
    stream = stream or sys.stdout
    scene = get_scene(scene_id)
    method = method or scene.default_method
    scene.resolve(method, overrides)  # bad input fails here, before any work
    if run_timeout is None and not is_plugin(scene, method):
        result = scene.run(method, overrides)
    else:
        result = run_cases([(scene_id, method, dict(overrides or {}))], jobs=1,
                           run_timeout=run_timeout)[0]
    print(f"{scene.id} --method {method} (reference: {scene.reference}): {result.status}"
          + (f" ({result.message})" if result.message else ""), file=stream)
    paper = scene.published_for(method, result.params)
    for key, value in result.metrics.items():
        text = f"  {key:24s} {value:.10g}" if isinstance(value, float) else f"  {key:24s} {value}"
        if key in paper:  # the paper's value for this method and these params
            text += f"   paper: {_paper_value(paper[key].value)} ({paper[key].source})"
        print(text, file=stream)
    for text in result.warnings:
        print(f"  warning: {text}", file=stream)
    t = result.timings
    peak = result.resources.get("peak_rss_gb")
    cached = (f" (+ {t[CACHED_SETUP]:.4f} s from the cache)" if t.get(CACHED_SETUP)
              else "")
    print(f"  time: setup {t['setup_s']:.4f} s{cached}, solve {t['solve_s']:.4f} s, "
          f"total {t['total_s']:.4f} s" + (f"; peak memory {peak:.3g} GB" if peak else "")
          + f"; size {result.size}", file=stream)
    if vtu_path:
        from .export import write_run_fields
        paths = write_run_fields(result, vtu_path[: -len(".vtu")])
        print("  fields: " + (", ".join(paths) if paths else "none (the run kept no node "
                                                             "fields)"), file=stream)
        result.files = paths
    if json_path:
        write_results(json_path, [result])
    if result.outcome == "expected-failure":
        print(f"(a documented finding: {result.expected_failure})")
    elif result.outcome == "unexpected-pass":
        print(f"unexpected pass: documented to fail ({result.expected_failure}); the finding "
              "is out of date")
    return 1 if result.counts_as_failure else 0


def is_plugin(scene, method: str) -> bool:
    """Whether ``method`` on ``scene`` runs a plugin's code (its run then goes to a
    supervised worker process, where the plugin time limit holds)."""
    t = scene.offered().get(method)
    return t is not None and t.origin != "built-in"


def run_case(case) -> RunResult:
    """One (scene, method, overrides) case; numerical trouble is a failed result."""
    scene_id, method, overrides = case
    return get_scene(scene_id).run(method, overrides)


def died_on_cluster(case, exc) -> RunResult:
    """A failed result for a case whose cluster task raised (e.g. its worker died)."""
    scene_id, method, _ = case
    return _failed(case, f"{scene_id}/{method}: the cluster task failed "
                         f"({type(exc).__name__}: {exc})")


def _failed(case, message) -> RunResult:
    """The failed record of a case that returned no result of its own."""
    scene_id, method, overrides = case
    scene = get_scene(scene_id)
    try:
        params = scene.resolve(method, overrides)
    except InputError:
        params = dict(overrides)
    return RunResult(scene=scene_id, method=method, params=params, reference=scene.reference,
                     status="failed", message=message,
                     timings={"setup_s": 0.0, "solve_s": 0.0, "total_s": 0.0},
                     published=[p.entry(params) for p in
                                scene.published_for(method, params).values()])


def plan(only=None, quick=False, methods=None) -> list[tuple[str, str, dict]]:
    """The (scene, method, overrides) cases of a report; validates every case up front.
    ``methods``: keep only the cases of these methods (``report --method``); a name that
    no selected scene offers is bad input naming its close matches."""
    from .scenes import all_scenes
    from . import convergence
    from .results import run_key
    scenes = [get_scene(s) for s in only] if only else all_scenes()
    if methods:
        offered = list(dict.fromkeys(m.name for s in scenes for m in s.all_methods))
        for name in methods:
            if name not in offered:
                from .errors import did_you_mean
                raise InputError(f"--method {name!r}{did_you_mean(name, offered)} is not a "
                                 "method of the " + ("scenes of --only" if only else "scenes")
                                 + f"; allowed: {', '.join(offered)}")
    keep = (lambda m: m in methods) if methods else (lambda m: True)
    cases, seen = [], set()
    # only the selected methods' cases are resolved: an unselected plugin is never called
    for scene in scenes:
        for method, overrides in scene.report_cases(quick=quick):
            if keep(method):
                seen.add(run_key(scene.id, method, _params(scene, method, overrides)))
                cases.append((scene.id, method, overrides))
    # the convergence studies' levels, unless a scene case already runs them
    for scene_id, method, overrides in convergence.cases([s.id for s in scenes], quick):
        if not keep(method):
            continue
        key = run_key(scene_id, method, _params(get_scene(scene_id), method, overrides))
        if key not in seen:
            seen.add(key)
            cases.append((scene_id, method, overrides))
    if methods and not cases:
        raise InputError(f"--method {' '.join(methods)}: no run of the report uses "
                         "these methods (an unavailable one is not run)")
    return cases


def _params(scene, method, overrides) -> dict:
    """The resolved params of a report case; a plugin whose check fails (not a refusal)
    keeps its case, which then fails naming the plugin, and the report goes on."""
    from .schedule import case_params
    params = case_params(scene, method, overrides)
    return dict(overrides) if params is None else params


#: A worker process is replaced by a fresh one after this many runs, and after any run
#: whose memory estimate is at least :data:`HEAVY_FRACTION` of the budget. A long-lived
#: process's address space only grows (allocator arenas, fragmentation, module caches):
#: under a 6 GB ``ulimit -v`` one worker that had run all cases failed 21 runs
#: that pass alone (benchmarks/records/worker_recycling-2026-11-27-ulimit-growth.json);
#: the replacement stays for what else a process keeps. A fork of the report process
#: costs milliseconds; the runs' results do not depend on which process ran them
#: (tests/pdverify/test_cli.py: bitwise across jobs).
RUNS_PER_WORKER = 20
HEAVY_FRACTION = 0.125


def retire(runs_done: int, estimate: float, limit: float, next_estimate: float = 0.0) -> bool:
    """Whether a worker that has run ``runs_done`` cases, the last with the memory
    ``estimate`` (bytes) under the budget ``limit``, is replaced by a fresh process; also
    when the next case of the queue (``next_estimate``) is heavy, so that a heavy run
    starts in a fresh process and its peak is its own (benchmarks/records/
    worker_recycling-2026-11-26-heavy-run-peak.json)."""
    heavy = HEAVY_FRACTION * limit
    return runs_done >= RUNS_PER_WORKER or estimate >= heavy or next_estimate >= heavy


def _die_with_parent(parent_pid: int) -> None:
    """Linux: have the kernel kill this worker when the report process dies (SIGKILL
    included), so no orphan keeps computing, or holds the output lock and pipes."""
    import ctypes
    import signal
    try:
        libc = ctypes.CDLL(None, use_errno=True)
        libc.prctl(1, int(signal.SIGKILL))           # PR_SET_PDEATHSIG
    except (OSError, AttributeError):                # not Linux: orphans end at EOF instead
        pass
    if os.getppid() != parent_pid:                   # the parent died before prctl
        os._exit(1)


def _worker(conn, inherited, parent_pid, watch=None) -> None:
    """Worker process: run the cases it receives, send back each result; None ends it.

    ``inherited``: the supervisor's ends of the pipes, copied by fork; closed at once so
    that each pipe reaches EOF when the supervisor's own end closes.
    """
    _quiet_worker()
    _die_with_parent(parent_pid)
    for c in inherited:
        c.close()
    if watch is not None:
        from .corrections import containment
        containment.WATCH = watch
    while True:
        try:
            case = conn.recv()
        except (EOFError, OSError):      # the report process is gone: end quietly
            return
        if case is None:
            return
        result = run_case(case)
        try:
            conn.send(result)
        except (BrokenPipeError, EOFError, OSError):
            return


def _quiet_worker() -> None:
    """A worker ignores Ctrl-C (the terminal sends SIGINT to the whole process group: the
    report process alone handles it, prints "pdverify: interrupted" and ends its workers)
    and dies of SIGTERM without the CLI's handler, which would unwind it with a
    traceback. SIGINT was blocked across the fork (:func:`_forked`); it is unblocked here,
    once ignored."""
    import signal
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGTERM, signal.SIG_DFL)
    signal.signal(signal.SIGALRM, signal.SIG_DFL)
    signal.pthread_sigmask(signal.SIG_UNBLOCK, {signal.SIGINT})


def _forked(proc) -> None:
    """Start ``proc`` with SIGINT blocked across the fork, so that a Ctrl-C before the
    worker ignores it cannot unwind the worker (the report process gets it right after)."""
    import signal
    old = signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT})
    try:
        proc.start()
    finally:
        signal.pthread_sigmask(signal.SIG_SETMASK, old)


def _died(case, exitcode, plugin_call=None) -> RunResult:
    """The failed record of a case whose worker process died in native code, or inside
    the plugin call ``plugin_call`` (``"plugin method NAME (ENTRY POINT): its closure"``,
    :mod:`~pdverify.corrections.containment`)."""
    import signal
    if exitcode is not None and exitcode < 0:
        try:
            how = f"signal {signal.Signals(-exitcode).name}"
        except ValueError:
            how = f"signal {-exitcode}"
    else:
        how = f"exit code {exitcode}"
    if plugin_call:
        return _failed(case, f"{case[0]}/{case[1]}: {plugin_call} ended the run's process "
                             f"({how})")
    return _failed(case, f"the run's process died ({how}) in native code (e.g. a crash in "
                         "a linear-algebra library, or killed for lack of memory)")


def _plugin_hung(case, plugin_call, seconds) -> RunResult:
    """The failed record of a case whose plugin call outlasted the plugin time limit."""
    from .corrections.containment import ENV
    res = _failed(case, f"{case[0]}/{case[1]}: {plugin_call} did not return within "
                        f"{seconds:g} s (the plugin time limit, ${ENV}); the supervisor "
                        "killed the run's process")
    res.timings = {"setup_s": 0.0, "solve_s": float(seconds), "total_s": float(seconds)}
    return res


def run_line(case, res) -> str:
    """A finished run's progress line (after ``[done/total] ``): ``scene method params ...
    status (seconds) metrics``; the status by the run's outcome: ``ok``, ``FAILED:
    message``, ``failed as expected: message`` (a documented finding: not a failure of the
    report) or ``ok, UNEXPECTED PASS: ...`` (a documented failure that did not happen)."""
    from .progress import format_overrides
    params = format_overrides(case[2])
    status = {"ok": "ok", "expected-failure": f"failed as expected: {res.message}",
              "unexpected-pass": f"ok, UNEXPECTED PASS: documented to fail "
                                 f"({res.expected_failure})"}.get(res.outcome,
                                                                  f"FAILED: {res.message}")
    if res.warnings:
        status += f" ({len(res.warnings)} warning)"
    from .terminal import printable
    return printable(f"{res.scene} {res.method} {params} ... {status} "
                     f"({res.timings.get('total_s', 0):.2f} s) "
                     f"{format_metrics(res.metrics, 2)}")


def run_cases(cases, *, jobs: int | None = None, progress=None, client=None,
              run_timeout: float | None = None, known=None, schedule=None) -> list[RunResult]:
    """Run ``cases`` in ``jobs`` supervised worker processes (default: the cores available
    to this process), showing their progress on the stream ``progress``
    (:class:`pdverify.progress.RunProgress`: a live display on a terminal, one line per
    finished run otherwise; None: silent).

    With a Dask ``client`` (``report --scheduler``), the cases run as tasks on its
    cluster instead (:mod:`pdverify.cluster`); ``jobs`` is then unused.

    Every case runs in a worker process, so a run that dies in native code (segfault,
    abort, out-of-memory kill) becomes a failed run naming the signal, a new worker takes
    over, and the other runs go on; so does a run that takes longer than ``run_timeout``
    seconds (killed by the supervisor; None: no limit). The cases start longest first and
    only while the memory estimates of the runs in flight fit the budget
    (:mod:`pdverify.schedule`; ``known``: earlier run times by run key). ``schedule``: a
    list that receives each worker's :class:`~pdverify.schedule.Slot`. Results come back
    in the order of ``cases``, the same numbers whatever ``jobs`` and the order they ran in.
    """
    from .progress import RunProgress
    from .schedule import case_costs, default_jobs

    jobs = default_jobs() if jobs is None else jobs
    if jobs < 1:
        raise InputError(f"--jobs={jobs} must be >= 1")
    if run_timeout is not None and not run_timeout > 0:
        raise InputError(f"--run-timeout={run_timeout} must be a positive number of seconds")

    def line(k, res):
        return run_line(cases[k], res)

    costs = case_costs(cases, known) if progress is not None else None

    if client is not None:
        from .cluster import run_cases_on
        try:
            workers = sum(client.nthreads().values())
        except Exception:  # the count only scales the ETA
            workers = 1
        with RunProgress(cases, workers, progress, auto_refresh=True, line=line,
                         costs=costs) as shown:
            for k in range(len(cases)):
                shown.started(k, timed=False)   # queued on the cluster
            return run_cases_on(client, cases, shown.finished, run_case, died_on_cluster)

    with RunProgress(cases, min(jobs, len(cases)), progress, line=line,
                     costs=costs) as shown:
        return _run_local(cases, jobs, shown, run_timeout, known,
                          schedule if schedule is not None else [])


def _timed_out(case, seconds) -> RunResult:
    """The failed record of a case its supervisor killed for taking too long."""
    res = _failed(case, f"timed out after {seconds:g} s (--run-timeout); the supervisor "
                        "killed the run's process")
    res.timings = {"setup_s": 0.0, "solve_s": float(seconds), "total_s": float(seconds)}
    return res


def _run_local(cases, jobs, shown, run_timeout=None, known=None, slots=None):
    """The supervised local pool of :func:`run_cases`; ``shown`` (a
    :class:`~pdverify.progress.RunProgress`) hears of every start and finish here, in the
    main process, and is redrawn every ``shown.tick_s`` while no run finishes."""
    import multiprocessing as mp
    import time
    from multiprocessing.connection import wait

    from .budget import memory_limit
    from .corrections import containment
    from .schedule import Slot, longest_first, memory_estimates, next_case

    total = len(cases)
    results: list[RunResult | None] = [None] * total
    done = 0
    ctx = mp.get_context("fork")
    memory = memory_estimates(cases)
    limit = memory_limit()[0]
    pending = longest_first(cases, known)
    workers = {}          # connection -> [process, case index or None, slot, start time]
    slots = slots if slots is not None else []
    slots.extend(Slot() for _ in range(min(jobs, total)))
    t0 = time.monotonic()
    plugin_limit = containment.limit_s()
    watches = {}          # connection -> the worker's plugin-call buffers
    #: a plugin call starts unseen by the supervisor: it looks this often while a worker
    #: runs a plugin's case (a small fraction of the limit)
    look_s = min(1.0, plugin_limit / 10)
    plugin_cases = {k for k, (scene_id, method, _) in enumerate(cases)
                    if is_plugin(get_scene(scene_id), method)}

    def start(slot):
        parent, child = ctx.Pipe()
        watch = containment.watch_buffers(ctx)
        proc = ctx.Process(target=_worker, args=(child, [parent, *workers], os.getpid(),
                                                  watch), daemon=True)
        _forked(proc)
        child.close()
        watches[parent] = watch
        workers[parent] = [proc, None, slot, None, 0]
        slots[slot].processes += 1
        return parent

    def in_flight_memory():
        return sum(memory[w[1]] for w in workers.values() if w[1] is not None)

    def give_all():
        """Idle workers take the next case (:func:`~pdverify.schedule.next_case`: the head
        of the queue, unless it would wait on a reference in flight) while it fits the
        memory budget."""
        for conn, w in workers.items():
            if w[1] is not None or not pending:
                continue
            running = [x[1] for x in workers.values() if x[1] is not None]
            i = next_case(pending, cases, running)
            if running and in_flight_memory() + memory[pending[i]] > limit:
                return                   # the case waits for memory; nothing overtakes it
            k = pending.pop(i)
            w[1], w[3] = k, time.monotonic()
            conn.send(cases[k])
            shown.started(k)

    def finish(conn, k, res):
        nonlocal done
        proc, _, slot, began, _ = workers[conn]
        slots[slot].runs.append((k, began - t0, time.monotonic() - t0))
        workers[conn][1] = None
        results[k] = res
        done += 1
        shown.finished(k, res)

    def replace(conn):
        """The worker of ``conn`` is dead or killed: a new one takes its slot."""
        proc, _, slot, _, _ = workers.pop(conn)
        watches.pop(conn, None)
        conn.close()
        start(slot)

    def recycle(conn, k):
        """After a normal finish: a worker due for retirement (:func:`retire`) ends and
        a fresh process takes its slot."""
        w = workers[conn]
        w[4] += 1
        if not retire(w[4], memory[k], limit, memory[pending[0]] if pending else 0.0):
            return
        try:
            conn.send(None)
        except OSError:  # already gone
            pass
        w[0].join(timeout=5)
        if w[0].is_alive():
            w[0].kill()
            w[0].join()
        replace(conn)

    try:
        for slot in range(min(jobs, total)):
            start(slot)
        give_all()
        while done < total:
            busy = {c: w for c, w in workers.items() if w[1] is not None}
            timeout = shown.tick_s
            if run_timeout is not None:
                left = min(w[3] + run_timeout for w in busy.values()) - time.monotonic()
                timeout = max(0.0, left) if timeout is None else min(timeout, max(0.0, left))
            if any(w[1] in plugin_cases for w in busy.values()):
                timeout = look_s if timeout is None else min(timeout, look_s)
            ready = wait(list(busy) + [w[0].sentinel for w in busy.values()],
                         timeout=timeout)
            for conn, (proc, k, slot, began, _) in list(busy.items()):
                res = None
                if conn in ready or proc.sentinel in ready:
                    try:
                        if conn.poll():
                            res = conn.recv()
                    except (EOFError, OSError):
                        res = None
                    if res is None and not proc.is_alive():   # died: record, replace
                        proc.join()
                        inside = containment.watched(watches[conn])
                        finish(conn, k, _died(cases[k], proc.exitcode,
                                              inside[1] if inside else None))
                        replace(conn)
                        continue
                inside = containment.watched(watches[conn]) if res is None else None
                if res is not None:
                    finish(conn, k, res)
                    recycle(conn, k)
                elif inside and time.monotonic() - inside[0] > plugin_limit:
                    proc.kill()
                    proc.join()
                    finish(conn, k, _plugin_hung(cases[k], inside[1], plugin_limit))
                    replace(conn)
                elif run_timeout is not None and time.monotonic() - began > run_timeout:
                    proc.kill()
                    proc.join()
                    finish(conn, k, _timed_out(cases[k], run_timeout))
                    replace(conn)
            give_all()
            shown.tick()
    finally:
        for conn, (proc, *_) in workers.items():
            try:
                conn.send(None)
            except OSError:  # the worker is gone (BrokenPipeError)
                pass
            conn.close()
        for conn, (proc, *_) in workers.items():
            proc.join(timeout=1)
            if proc.is_alive():
                proc.kill()
                proc.join()
    return results
