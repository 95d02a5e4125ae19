"""The figure phase: the report's figure tasks, drawn in forked processes."""
from __future__ import annotations

import os
import time

from ..exchange import is_external
from ..errors import OutputError
from .folder import describe_os_error, storage_failure


def figure_tasks(owned, results, studies, figdir) -> list:
    """The report's figure tasks for :func:`draw_all`, ``(what, draw, args, empty)``:
    the error-against-cost overview, one task per scene of ``owned`` (``(scene, its
    runs)``), then one per scene of the convergence ``studies``.

    The order is the drawing processes' schedule (each takes the next task when it is
    done): the overview, one of the longest tasks, first, and the convergence figures,
    short pieces once split by scene, last, so that the processes end close together
    (record report_cost-2026-11-27-figure-order). :func:`figures_drawn` sorts the results
    back."""
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


def _drawn(what, draw, args, empty, progress):
    """``draw(*args)``, or ``empty`` and a note if the plotting code raises: a broken
    figure must not lose the numbers. A storage failure (disk full, read-only, I/O error;
    :func:`~pdverify.report.folder.storage_failure`) is not a broken figure: it makes the
    report incomplete."""
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
            return "storage", describe_os_error(failure)
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


#: the figure tasks of :func:`draw_all`, read by the forked drawing processes
_TASKS: list = []


def draw_all(tasks, jobs, progress) -> list:
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


def _drawing_process(parent: int) -> None:
    from ..runner import _die_with_parent, _quiet_worker
    _quiet_worker()
    _die_with_parent(parent)


def _draw_task(k: int):
    """One task of :data:`_TASKS`, in a drawing process (:func:`_attempt`)."""
    _, draw, args, _ = _TASKS[k]
    return _attempt(draw, args)
