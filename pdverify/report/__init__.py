"""The main job: run every scene and method, write results.json, figures and index.html."""
from __future__ import annotations

import errno
import hashlib
import os
import shutil
import sys
import time
from contextlib import contextmanager

from .. import outputs
from ..outputs import output_lock, swap_in as _swap_in  # noqa: F401 (one lock, one swap)
from ..errors import STOP_REQUESTED, InputError, OutputError
from ..results import atomic_write_text, run_key, umask_mode, write_results
from ..exchange import is_external
from ..runner import plan, run_cases
from ..scenes import get_scene

DEFAULT_OUT = os.path.join("reports", "latest")


def default_out(only=None, quick=False, methods=None) -> str:
    """Where a report goes without ``--out``: the full report in ``reports/latest``, a
    ``--quick`` one in ``reports/quick`` and an ``--only`` one in a folder named after its
    scenes, so that neither ever replaces the full report; ``--method`` adds the methods
    (``reports/only-SCENE-method-M``, ``reports/method-M``)."""
    if methods:
        ids = list(dict.fromkeys(methods))
        tail = "method-" + (ids[0] if len(ids) == 1 else f"{ids[0]}+{len(ids) - 1}-more-"
                            + hashlib.sha1("\0".join(sorted(ids)).encode()).hexdigest()[:6])
        base = default_out(only, quick)
        if not only:
            return os.path.join("reports", ("quick-" if quick else "") + tail)
        return f"{base}-{tail}"
    if only:
        ids = list(dict.fromkeys(only))
        name = ids[0] if len(ids) == 1 else f"{ids[0]}+{len(ids) - 1}-more-" + hashlib.sha1(
            "\0".join(sorted(ids)).encode()).hexdigest()[:6]
        return os.path.join("reports", ("quick-" if quick else "") + "only-" + name)
    return os.path.join("reports", "quick") if quick else DEFAULT_OUT


def build_report(*, out=None, quick=False, only=None, jobs=None, progress=None,
                 scheduler=None, run_timeout=None, methods=None, failed=False,
                 include=None) -> int:
    """Run the report; returns 0, or 1 if any run failed. Bad input raises before work.

    Figures, results.json and index.html are written into a staging folder next to
    ``out`` and swapped in as a whole at the end, under a lock on ``out``: a report that
    is killed or fails leaves the previous one intact (its staging folder is removed now,
    or by the next report into the same folder if the process was killed outright). One
    that cannot be written whole (disk full, ...) raises :class:`OutputError` and keeps
    its staging folder. ``out`` must be new, empty or a previous report, and its disk and
    the cache must take the output (:mod:`pdverify.outputs`; InputError before work).
    ``scheduler``: a Dask scheduler address; the runs then go to that cluster
    (:mod:`pdverify.cluster`), which is reached before any work starts. ``jobs``: local
    worker processes (None: the cores available to this process); ``run_timeout``: the
    seconds after which a run is killed and recorded as failed (None: no limit).
    ``methods``: only the runs of these methods. ``failed``: rerun only the planned runs
    that failed (unexpectedly) or are missing in the previous report in ``out``, and merge
    them into it (:func:`rerun_plan`; InputError if there is none). ``include``: results
    files whose external runs (``pdverify score``) join the report's runs
    (:func:`pdverify.exchange.load_external`; InputError before any work).
    """
    progress = progress or sys.stderr
    out = outputs.check_out_dir(out or default_out(only, quick, methods))  # links resolved
    cases = plan(only=only, quick=quick, methods=methods)  # InputError on unknown names
    included = []
    if include:
        from ..exchange import load_external
        included = load_external(include)
    kept = None
    if failed:
        cases, kept = rerun_plan(cases, out)
        if not cases:
            print(f"report --failed: nothing failed or is missing in {out!r}; it is "
                  "unchanged", file=progress)
            if not included:
                return exit_code(kept)
        print(f"report --failed: rerunning {len(cases)} run(s) that failed or were missing; "
              f"{len(kept)} kept from the previous report", file=progress)
    check_storage(cases, out)
    parent, name = os.path.split(out)
    if scheduler is not None and run_timeout is not None:
        raise InputError("--run-timeout applies to the local worker processes; it cannot be "
                         "combined with --scheduler (or $PDVERIFY_SCHEDULER)")
    client = None
    if scheduler is not None:
        from ..cluster import connect
        client = connect(scheduler)
    try:
        with output_lock(out):
            return _locked(cases, out, parent, name, jobs, progress, client, quick,
                           run_timeout, kept, included)
    finally:
        if client is not None:
            client.close()


def rerun_plan(cases, out: str):
    """``report --failed``: (the cases to run again, the previous runs to keep).

    Rerun: the planned cases whose run failed unexpectedly (outcome ``failed``, not a
    documented finding) or is missing in ``out/results.json``; kept: every other run of
    that file, as it was (a run of the previous report outside today's plan included).
    No readable results file there is bad input (exit 2), before any work."""
    from ..results import RunResult, load_results
    path = os.path.join(out, "results.json")
    if outputs.folder_state(out)[0] != "report" or not os.path.isfile(path):
        raise InputError(f"--failed: {out!r} holds no previous pdverify report (no "
                         "results.json); run the report without --failed first")
    try:
        doc = load_results(path)
    except (OSError, ValueError) as exc:
        raise InputError(f"--failed: the previous report's results cannot be read "
                         f"({exc})") from None
    previous = {}
    for k, run in enumerate(doc["runs"]):
        outputs.check_listed(out, run.get("files", []),
                             f"--failed: the previous report's results.json runs[{k}].files")
        r = RunResult.from_json(run)
        previous.setdefault(r.key, r)
    again = []
    for case in cases:
        scene_id, method, overrides = case
        from ..runner import _params
        key = run_key(scene_id, method, _params(get_scene(scene_id), method, overrides))
        prev = previous.get(key)
        if prev is None or prev.outcome == "failed":
            again.append(case)
            previous.pop(key, None)
    return again, list(previous.values())


#: Bytes a report needs on disk, per run and once (figures of the overview, pages), from
#: the largest --quick --only SCENE report per run measured: see "Storage" in docs/command-line.md.
REPORT_BYTES_PER_RUN = 256_000
REPORT_BYTES_FIXED = 2_000_000


def estimate_bytes(cases) -> int:
    """A generous estimate of a report's size on disk (see :data:`REPORT_BYTES_PER_RUN`)."""
    return REPORT_BYTES_FIXED + REPORT_BYTES_PER_RUN * len(cases)


def check_storage(cases, out: str) -> None:
    """Before any work: the cache takes files, and ``out``'s disk has room for the new
    report next to the previous one (which stays until the new one is complete)."""
    outputs.check_cache()
    outputs.check_target(out)
    outputs.check_free(os.path.dirname(out), estimate_bytes(cases),
                       f"--out {out!r} (a report of {len(cases)} runs)")


def _locked(cases, out, parent, name, jobs, progress, client, quick=False,
            run_timeout=None, kept=None, included=()) -> int:
    """The report's body, under the output lock: stage, build, swap in.

    A report that could not be written whole (:class:`OutputError`: a figure, a VTU file,
    a page or results.json failed to write) is not swapped in: the previous report stays,
    the partial one stays in its staging folder, and OutputError names both."""
    staging = outputs.new_staging(parent, name, outputs.is_own_leftover, "report",
                                  "nothing was run")
    keep = False
    try:
        try:
            os.chmod(staging, umask_mode(0o777))  # mkdtemp gives 0700
            outputs.write_marker(staging, complete=False)
        except OSError as exc:
            raise OutputError(f"report: cannot write into its staging folder {staging!r} "
                              f"({exc.strerror or exc}); nothing was run") from None
        try:
            code = _build(cases, staging, out, jobs, progress, client, quick, run_timeout,
                          kept, included)
            _write_marker(staging)
        except OutputError as exc:
            keep = True
            previous = ("the previous report in " + repr(out) + " is unchanged"
                        if os.path.exists(out) else "nothing was published at " + repr(out))
            raise OutputError(f"report incomplete: {exc}; {previous}; the partial report is "
                              f"in {staging!r}") from None
        if STOP_REQUESTED["flag"]:  # an interrupt some library swallowed: publish nothing
            raise KeyboardInterrupt
        state, why = outputs.folder_state(out)
        if state == "foreign":  # someone put files there while the report ran
            keep = True
            raise OutputError(f"report: {out!r} changed while the report ran ({why}); it was "
                              f"left as it is; the new report is in {staging!r}")
        _swap_in(staging, out)
    finally:
        if not keep and os.path.exists(staging):
            shutil.rmtree(staging, ignore_errors=True)
    return code


def _write_marker(folder: str) -> None:
    try:
        outputs.write_marker(folder, complete=True)
    except OSError as exc:
        raise OutputError(f"writing its marker {outputs.MARKER} failed "
                          f"({exc.strerror or exc})") from None


def export_fields(results, out) -> None:
    """Every run's fields as VTU files in ``out/fields`` (:mod:`pdverify.export`), named
    by the run's place in ``results.json``; each run lists its files under ``files``."""
    from ..export import write_run_fields
    for k, r in enumerate(results):
        if not r.fields:
            continue
        stem = os.path.join(out, "fields", f"{k:03d}-{r.scene}-{r.method}")
        r.files = [os.path.relpath(p, out) for p in write_run_fields(r, stem)]


class _Phases(dict):
    """Wall time of each phase of the report, seconds by name (summed over re-entries).

    A write that fails in a writing phase (an OSError: disk full, read-only, ...) becomes
    an :class:`OutputError` naming the phase and the file."""

    WRITES = {"figures_s": "figures", "fields_s": "the VTU fields",
              "pages_s": "the pages (index.html, results.json)"}

    @contextmanager
    def __call__(self, name):
        t0 = time.perf_counter()
        try:
            yield
        except OSError as exc:
            if name not in self.WRITES:
                raise
            raise OutputError(f"writing {self.WRITES[name]} failed ({_describe(exc)})") from exc
        finally:
            self[name] = self.get(name, 0.0) + time.perf_counter() - t0


#: errno values of a storage failure: the disk, not the plotting code, is at fault
STORAGE_ERRNOS = {errno.ENOSPC, errno.EDQUOT, errno.EFBIG, errno.EROFS, errno.EIO}


def storage_failure(exc: BaseException) -> OSError | None:
    """The OSError of a storage failure (:data:`STORAGE_ERRNOS`) in ``exc`` or the
    exceptions it was raised from or during, if any."""
    seen = set()
    while exc is not None and id(exc) not in seen:
        seen.add(id(exc))
        if isinstance(exc, OSError) and exc.errno in STORAGE_ERRNOS:
            return exc
        exc = exc.__cause__ or exc.__context__
    return None


def _describe(exc: OSError) -> str:
    text = exc.strerror or str(exc) or type(exc).__name__
    return f"{text}: {exc.filename!r}" if exc.filename else text


def _drawn(what, draw, args, empty, progress):
    """``draw(*args)``, or ``empty`` and a note if the plotting code raises: a broken
    figure must not lose the numbers. A storage failure (disk full, read-only, I/O error;
    :func:`storage_failure`) is not a broken figure: it makes the report incomplete."""
    return _settled(what, *_attempt(draw, args), empty, progress)


def _attempt(draw, args):
    """``("ok", draw(*args))``, or what went wrong as plain data (a drawing process sends
    it back; the exception itself may not pickle): ``("storage", description)`` for a
    storage failure, ``("failed", message)`` for any other."""
    try:
        return "ok", draw(*args)
    except Exception as exc:
        failure = storage_failure(exc)
        if failure is not None:
            return "storage", _describe(failure)
        return "failed", f"{type(exc).__name__}: {exc}"


def _settled(what, status, value, empty, progress):
    """The figures of an :func:`_attempt`: a storage failure raises
    :class:`OutputError`, a broken figure is a note and ``empty``."""
    if status == "storage":
        raise OutputError(f"writing the {what} failed ({value})")
    if status == "failed":
        print(f"{what} failed: {value}", file=progress)
        return empty
    return value


class FigureProgress:
    """The figure phase's progress on the report's stream: a line when it starts, then a
    line as each task is drawn (``figures 3/41: figure for plate-l | elapsed 0:12``), so
    that a minute of drawing is not a silent one; plain lines on any stream (a few dozen,
    one per scene and the overview)."""

    def __init__(self, tasks, jobs, stream):
        self.total, self.count, self.stream = len(tasks), 0, stream
        self.t0 = time.monotonic()
        if stream is not None and tasks:
            print(f"figures: drawing {self.total} figure tasks in {max(1, jobs)} "
                  f"process{'es' if jobs > 1 else ''}", file=stream, flush=True)

    def done(self, what: str) -> None:
        from ..progress import clock
        self.count += 1
        if self.stream is not None:
            print(f"figures {self.count}/{self.total}: {what} | elapsed "
                  f"{clock(time.monotonic() - self.t0)}", file=self.stream, flush=True)


#: the figure tasks of :func:`_draw_all`, read by the forked drawing processes
_TASKS: list = []


def _draw_all(tasks, jobs, progress) -> list:
    """Each ``(what, draw, args, empty)`` of ``tasks`` drawn as by :func:`_drawn`, their
    results in order. With ``jobs`` > 1 (and fork) the tasks are shared out among that
    many forked processes (the scenes' figures are independent files). The processes
    ignore Ctrl-C and die with the report, as the run workers do; should one die (a crash
    in a rendering library), the tasks it leaves are drawn in the report process."""
    import multiprocessing as mp
    from concurrent.futures import ProcessPoolExecutor
    from ..schedule import default_jobs
    jobs = min(default_jobs() if jobs is None else jobs, len(tasks))
    shown = FigureProgress(tasks, jobs, progress)
    if jobs <= 1 or "fork" not in mp.get_all_start_methods():
        out = []
        for what, draw, args, empty in tasks:
            out.append(_drawn(what, draw, args, empty, progress))
            shown.done(what)
        return out
    import signal
    global _TASKS
    _TASKS = tasks
    old = signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT})
    try:
        pool = ProcessPoolExecutor(jobs, mp_context=mp.get_context("fork"),
                                   initializer=_drawing_process, initargs=(os.getpid(),))
        pending = [pool.submit(_draw_task, k) for k in range(len(tasks))]
    finally:
        signal.pthread_sigmask(signal.SIG_SETMASK, old)
    try:
        from concurrent.futures import as_completed
        index = {job: k for k, job in enumerate(pending)}
        out = [None] * len(tasks)
        for job in as_completed(pending):
            k = index[job]
            what, draw, args, empty = tasks[k]
            try:
                status, value = job.result()
            except Exception as exc:       # the drawing process died: draw it here
                print(f"{what}: its drawing process failed ({type(exc).__name__}); drawn "
                      "in the report process", file=progress)
                status, value = _attempt(draw, args)
            out[k] = _settled(what, status, value, empty, progress)
            shown.done(what)
        return out
    finally:
        pool.shutdown(wait=True, cancel_futures=True)
        _TASKS = []


def figure_tasks(owned, results, studies, figdir) -> list:
    """The report's figure tasks for :func:`_draw_all`, ``(what, draw, args, empty)``:
    the error-against-cost overview, one task per scene of ``owned`` (``(scene, its
    runs)``), then one per scene of the convergence ``studies``.

    The order is the drawing processes' schedule (each takes the next task when it is
    done): the overview, one of the longest tasks, first, and the convergence figures,
    short pieces once split by scene, last, so that the processes end close together
    (the overview and all convergence figures, 2-3 s each, were the last two tasks).
    :func:`figures_drawn` sorts the results back."""
    from . import figures
    from .figures import convergence, overview
    scenes = [scene for scene, _ in owned]
    return ([("error-against-cost figures", overview.pareto, (scenes, results, figdir), [])]
            + [(f"figure for {scene.id}", figures.draw,
                (scene, [r for r in mine if not is_external(r.method)], figdir), [])
               for scene, mine in owned]
            + [(f"convergence figures of {name}", convergence.draw,
                ([s for s in studies if s["scene"] == name], figdir), {})
               for name in dict.fromkeys(s["scene"] for s in studies)])


def figures_drawn(owned, drawn) -> tuple:
    """The results of :func:`figure_tasks`' tasks as ``(figures of each scene of owned,
    the overview's figures, {scene: convergence figures})``."""
    conv = {}
    for part in drawn[1 + len(owned):]:
        conv.update(part)
    return drawn[1:1 + len(owned)], drawn[0], conv


def _drawing_process(parent: int) -> None:
    from ..runner import _die_with_parent, _quiet_worker
    _quiet_worker()
    _die_with_parent(parent)


def _draw_task(k: int):
    """One task of :data:`_TASKS`, in a drawing process (:func:`_attempt`)."""
    _, draw, args, _ = _TASKS[k]
    return _attempt(draw, args)


LOG = "report.log"


def _build(cases, out, final, jobs, progress, client=None, quick=False,
           run_timeout=None, kept=None, included=()) -> int:
    """The report's work into the staging folder ``out``; the progress lines also go to
    ``out/report.log`` (:data:`LOG`)."""
    from ..progress import Tee
    try:
        log = open(os.path.join(out, LOG), "w", encoding="utf-8")
    except OSError as exc:
        raise OutputError(f"cannot write its log {LOG} ({_describe(exc)})") from None
    with log:
        return _build_logged(cases, out, final, jobs, Tee(progress, log), client, quick,
                             run_timeout, kept, included)


def _build_logged(cases, out, final, jobs, progress, client=None, quick=False,
                  run_timeout=None, kept=None, included=()) -> int:
    from ..schedule import critical_path, previous_times
    t0 = time.perf_counter()
    phase = _Phases()
    slots = []
    with phase("runs_s"):
        # the previous report in this folder times each run, for the longest-first order
        known = previous_times(os.path.join(final, "results.json"))
        results = (run_cases(cases, jobs=jobs, progress=progress, client=client,
                             run_timeout=run_timeout, known=known, schedule=slots)
                   if cases else [])   # report --failed --include: only runs to add
    if kept is not None:     # report --failed: the new runs merged into the previous ones
        results = _merged(kept, results)
    if included:             # report --include: external runs (pdverify score) join them,
        new = {r.key for r in included}         # replacing a kept copy of the same run
        results = _merged([r for r in results if r.key not in new], included)
    figdir = os.path.join(out, "figures")
    with phase("figures_s"):
        os.makedirs(figdir, exist_ok=True)
    from . import figures, html
    from ..runner import _params
    sections = []
    tabled = set()   # the runs in the scenes' tables (the failure list links to their rows)
    order = []
    for scene_id in [c[0] for c in cases] + [r.scene for r in results]:
        if scene_id not in order:
            order.append(scene_id)
    owned = []
    for scene_id in order:
        scene = get_scene(scene_id)
        # the scene's own cases; the convergence studies' extra levels have their section
        # (of the methods that ran: an unselected plugin's check is never called)
        ran = {r.method for r in results if r.scene == scene_id}
        own = {run_key(scene_id, m, _params(scene, m, o))
               for m, o in scene.report_cases(quick) if m in ran}
        mine = [r for r in results if r.scene == scene_id
                and (r.key in own or is_external(r.method))]
        tabled.update(r.key for r in mine)
        owned.append((scene, mine))
    scenes = [scene for scene, _ in owned]
    from ..convergence import collect
    studies = collect([r for r in results if not is_external(r.method)], quick)
    with phase("figures_s"), figures.quick_figures(quick):
        tasks = figure_tasks(owned, results, studies, figdir)
        figs, front, conv = figures_drawn(owned, _draw_all(tasks, jobs, progress))
    with phase("pages_s"):
        for (scene, mine), mine_figs in zip(owned, figs):
            sections.append((scene, html.scene_section(scene, mine, mine_figs, records=results)))
    with phase("fields_s"):
        export_fields(results, out)
        if kept is not None:
            _keep_fields(results, final, out)
    with phase("pages_s"):
        write_tables(results, out)
    with phase("pages_s"):
        sections = [(scene, text + html.convergence_section(
            [s for s in studies if s["scene"] == scene.id], conv.get(scene.id, [])))
            for scene, text in sections]
        # the phases so far; the page and results.json themselves take a few ms
        phases = {**phase, "total_s": time.perf_counter() - t0}
        doc = write_results(os.path.join(out, "results.json"), results,
                            {"convergence": studies, "report_phases": phases})
        atomic_write_text(os.path.join(out, "index.html"),
                          html.page(doc, sections, time.perf_counter() - t0, results, front,
                                    tabled))
    outcomes = [r.outcome for r in results]
    failed = outcomes.count("failed")
    expected = outcomes.count("expected-failure")
    passed = [r for r in results if r.outcome == "unexpected-pass"]
    from .summary import load_note, print_summary
    print_summary(scenes, results, progress)  # one row per scene, before the last line
    if slots:                                 # the local pool (not a Dask cluster)
        print(critical_path(slots, cases), file=progress)
    heaviest = largest_memory(results)
    if heaviest:
        print(heaviest, file=progress)
    loads = load_note(results, doc.get("machine", {}).get("cpus"))
    if loads:
        print(loads, file=progress)
    for r in passed:   # strict: a documented failure that no longer happens
        print(f"unexpected pass: {r.scene}/{r.method} is ok, but it is documented to fail "
              f"({r.expected_failure}); update the finding", file=progress)
    print(f"report: {len(results)} runs, {failed} failed, {expected} failed as expected "
          f"(documented findings), {len(passed)} passed unexpectedly, "
          f"{time.perf_counter() - t0:.1f} s -> {os.path.join(final, 'index.html')}",
          file=progress)
    return exit_code(results)


def largest_memory(results) -> str:
    """The run with the largest peak memory (``resources.peak_rss_gb``), as a line; empty
    where no run measured one."""
    measured = [r for r in results if r.resources.get("peak_rss_gb")]
    if not measured:
        return ""
    r = max(measured, key=lambda r: r.resources["peak_rss_gb"])
    return (f"largest peak memory of a run: {r.resources['peak_rss_gb']:.3g} GB "
            f"({r.scene} {r.method}, {r.timings.get('total_s', 0.0):.3g} s)")


def _merged(kept, new) -> list:
    """``report --failed``: the previous runs kept and the runs made now, grouped by scene
    in the order of the scene registry (a report's order), each group's runs in order."""
    from ..scenes import all_scenes
    rank = {s.id: k for k, s in enumerate(all_scenes())}
    return sorted(list(kept) + list(new), key=lambda r: rank.get(r.scene, len(rank)))


def _keep_fields(results, final, out) -> None:
    """``report --failed``: the VTU files of the runs kept from the previous report in
    ``final``, copied into ``out`` under their run's new place in results.json."""
    for k, r in enumerate(results):
        if r.fields or not r.files:
            continue
        files = []
        for rel in r.files:
            head, name = os.path.split(rel)
            new = os.path.join(head, f"{k:03d}-" + name.split("-", 1)[-1])
            src = os.path.join(final, rel)
            if outputs.outside(final, rel) or outputs.outside(out, new):
                continue     # never read or write outside the two reports (checked before)
            if os.path.isfile(src):
                os.makedirs(os.path.join(out, head), exist_ok=True)
                shutil.copyfile(src, os.path.join(out, new))
                files.append(new)
        r.files = files


def write_tables(results, out) -> list[str]:
    """One CSV per scene, ``out/tables/<scene>.csv``: a row per run (method, outcome,
    message, every parameter, every metric, the run's time), for a spreadsheet or pandas.
    Returns the files written, relative to ``out``."""
    import csv
    import io
    from ..results import _plain
    by_scene: dict[str, list] = {}
    for r in results:
        by_scene.setdefault(r.scene, []).append(r)
    written = []
    for scene_id, runs in by_scene.items():
        params = list(dict.fromkeys(k for r in runs for k in r.params))
        metrics = list(dict.fromkeys(k for r in runs for k in r.metrics))
        buf = io.StringIO()
        w = csv.writer(buf, lineterminator="\n")
        w.writerow(["scene", "method", "outcome", "status", "message"] + params + metrics
                   + ["total_s"])
        for r in runs:
            p, m = _plain(r.params), _plain(r.metrics)
            w.writerow([r.scene, r.method, r.outcome, r.status, r.message]
                       + [p.get(k, "") for k in params] + [m.get(k, "") for k in metrics]
                       + [_plain(r.timings.get("total_s", ""))])
        rel = os.path.join("tables", f"{scene_id}.csv")
        atomic_write_text(os.path.join(out, rel), buf.getvalue())
        written.append(rel)
    return written


def exit_code(results) -> int:
    """1 when a run failed unexpectedly or a documented failure did not happen (strict,
    like pytest's xfail), else 0: the documented findings do not fail a healthy install."""
    return 1 if any(r.counts_as_failure for r in results) else 0


__all__ = ["build_report", "exit_code"]
