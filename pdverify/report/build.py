"""The main job: run the planned scenes and methods, then build the report from their runs."""
from __future__ import annotations

import os
import sys
import time
from contextlib import contextmanager

from .. import outputs
from ..errors import InputError, OutputError
from ..exchange import is_external
from ..outputs import output_lock
from ..results import atomic_write_text, run_key, write_results
from ..runner import plan, run_cases
from ..scenes import get_scene
from .drawing import draw_all, figure_tasks, figures_drawn
from .files import export_fields, keep_fields, write_tables
from .folder import check_storage, default_out, describe_os_error, publish
from .rerun import merged, rerun_plan


def build_report(*, out=None, quick=False, only=None, jobs=None, progress=None,
                 scheduler=None, run_timeout=None, methods=None, failed=False,
                 include=None) -> int:
    """Run the report; returns 0, or 1 if any run failed. Bad input raises before work.

    Figures, results.json and index.html are written into a staging folder next to
    ``out`` and swapped in as a whole at the end, under a lock on ``out``: a report that
    is killed or fails leaves the previous one intact (its staging folder is removed now,
    or by the next report into the same folder if the process was killed outright). One
    that cannot be written whole (disk full, ...) raises :class:`OutputError` and keeps
    its staging folder (:func:`~pdverify.report.folder.publish`). ``out`` must be new,
    empty or a previous report, and its disk and the cache must take the output
    (:mod:`pdverify.outputs`; InputError before work).
    ``scheduler``: a Dask scheduler address; the runs then go to that cluster
    (:mod:`pdverify.cluster`), which is reached before any work starts. ``jobs``: local
    worker processes (None: the cores available to this process); ``run_timeout``: the
    seconds after which a run is killed and recorded as failed (None: no limit).
    ``methods``: only the runs of these methods. ``failed``: rerun only the planned runs
    that failed (unexpectedly) or are missing in the previous report in ``out``, and merge
    them into it (:func:`~pdverify.report.rerun.rerun_plan`; InputError if there is
    none). ``include``: results files whose external runs (``pdverify score``) join the
    report's runs (:func:`pdverify.exchange.load_external`; InputError before any work).
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
    if scheduler is not None and run_timeout is not None:
        raise InputError("--run-timeout applies to the local worker processes; it cannot be "
                         "combined with --scheduler (or $PDVERIFY_SCHEDULER)")
    client = None
    if scheduler is not None:
        from ..cluster import connect
        client = connect(scheduler)
    try:
        with output_lock(out):
            return publish(out, lambda staging: _build(
                cases, staging, out, jobs, progress, client, quick, run_timeout, kept,
                included))
    finally:
        if client is not None:
            client.close()


def exit_code(results) -> int:
    """1 when a run failed unexpectedly or a documented failure did not happen (strict,
    like pytest's xfail), else 0: the documented findings do not fail a healthy install."""
    return 1 if any(r.counts_as_failure for r in results) else 0


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
            raise OutputError(f"writing {self.WRITES[name]} failed "
                              f"({describe_os_error(exc)})") from exc
        finally:
            self[name] = self.get(name, 0.0) + time.perf_counter() - t0


LOG = "report.log"


def _build(cases, out, final, jobs, progress, client=None, quick=False,
           run_timeout=None, kept=None, included=()) -> int:
    """The report's work into the staging folder ``out``; the progress lines also go to
    ``out/report.log`` (:data:`LOG`)."""
    from ..progress import Tee
    try:
        log = open(os.path.join(out, LOG), "w", encoding="utf-8")
    except OSError as exc:
        raise OutputError(f"cannot write its log {LOG} ({describe_os_error(exc)})") from None
    with log:
        return _build_logged(cases, out, final, jobs, Tee(progress, log), client, quick,
                             run_timeout, kept, included)


def _build_logged(cases, out, final, jobs, progress, client=None, quick=False,
                  run_timeout=None, kept=None, included=()) -> int:
    """Run ``cases`` (merged with the ``kept`` and ``included`` runs), then write into
    ``out`` the figures, the VTU fields, the CSV tables, results.json and index.html;
    print the closing summary; return the exit code."""
    from ..schedule import previous_times
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
        results = merged(kept, results)
    if included:             # report --include: external runs (pdverify score) join them,
        new = {r.key for r in included}         # replacing a kept copy of the same run
        results = merged([r for r in results if r.key not in new], included)
    figdir = os.path.join(out, "figures")
    with phase("figures_s"):
        os.makedirs(figdir, exist_ok=True)
    from . import figures, html
    owned = _scene_runs(cases, results, quick)
    # the runs in the scenes' tables (the failure list links to their rows)
    tabled = {r.key for _, mine in owned for r in mine}
    from ..convergence import collect
    studies = collect([r for r in results if not is_external(r.method)], quick)
    with phase("figures_s"), figures.quick_figures(quick):
        tasks = figure_tasks(owned, results, studies, figdir)
        figs, front, conv = figures_drawn(owned, draw_all(tasks, jobs, progress))
    sections = []
    with phase("pages_s"):
        for (scene, mine), mine_figs in zip(owned, figs):
            sections.append((scene, html.scene_section(scene, mine, mine_figs, records=results)))
    with phase("fields_s"):
        export_fields(results, out)
        if kept is not None:
            keep_fields(results, final, out)
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
    _print_end([scene for scene, _ in owned], cases, results, slots, doc, progress)
    print(f"report: {len(results)} runs, {_count(results, 'failed')} failed, "
          f"{_count(results, 'expected-failure')} failed as expected "
          f"(documented findings), {_count(results, 'unexpected-pass')} passed "
          f"unexpectedly, {time.perf_counter() - t0:.1f} s -> "
          f"{os.path.join(final, 'index.html')}", file=progress)
    return exit_code(results)


def _scene_runs(cases, results, quick) -> list:
    """``(scene, its runs)`` for each scene of ``cases`` and ``results``, in that order:
    a scene's own report cases (of the methods that ran: an unselected plugin's check is
    never called) and its external runs; the convergence studies' extra levels have
    their own section."""
    from ..runner import _params
    owned = []
    for scene_id in dict.fromkeys([c[0] for c in cases] + [r.scene for r in results]):
        scene = get_scene(scene_id)
        ran = {r.method for r in results if r.scene == scene_id}
        own = {run_key(scene_id, m, _params(scene, m, o))
               for m, o in scene.report_cases(quick) if m in ran}
        owned.append((scene, [r for r in results if r.scene == scene_id
                              and (r.key in own or is_external(r.method))]))
    return owned


def _count(results, outcome: str) -> int:
    return sum(r.outcome == outcome for r in results)


def _print_end(scenes, cases, results, slots, doc, progress) -> None:
    """The lines before the report's last one: a summary row per scene, the critical path
    of the local pool (not a Dask cluster), the heaviest run, the machine's load, and each
    documented failure that no longer happens (strict)."""
    from ..schedule import critical_path
    from .summary import largest_memory, load_note, print_summary
    print_summary(scenes, results, progress)
    if slots:
        print(critical_path(slots, cases), file=progress)
    heaviest = largest_memory(results)
    if heaviest:
        print(heaviest, file=progress)
    loads = load_note(results, doc.get("machine", {}).get("cpus"))
    if loads:
        print(loads, file=progress)
    for r in results:
        if r.outcome == "unexpected-pass":
            print(f"unexpected pass: {r.scene}/{r.method} is ok, but it is documented to "
                  f"fail ({r.expected_failure}); update the finding", file=progress)
