"""What the report's front page and the end-of-run summary say: each scene's headline error,
the run of each method at its default parameters, the best method; the heaviest run; load."""
from __future__ import annotations

from dataclasses import dataclass

from ..errors import InputError
from ..results import time_s
from ..terminal import printable

#: The error each scene is ranked by (a scene may set ``headline``).
HEADLINE_DEFAULT = "rel_l2_error"


def headline(scene) -> str:
    return getattr(scene, "headline", HEADLINE_DEFAULT)


def headline_value(scene, result):
    """The run's headline error as a fraction (``*_pct`` metrics divided by 100), or None
    for a failed run, the FEM reference, or a run without that metric."""
    if result.status != "ok" or result.method == "fem":
        return None
    metric = headline(scene)
    v = result.metrics.get(metric)
    if isinstance(v, bool) or not isinstance(v, (int, float)):
        return None
    return abs(float(v)) / (100.0 if metric.endswith("_pct") else 1.0)


def default_run(scene, method, runs):
    """The run of ``method`` at its default params, else its first run."""
    mine = [r for r in runs if r.method == method]
    if not mine:          # (nothing to resolve: a method that did not run is not called)
        return None
    try:
        defaults = scene.resolve(method, {})
    except InputError:
        defaults = None
    return next((r for r in mine if r.params == defaults), mine[0] if mine else None)


#: Scene parameters that are settings of the model or method (a quadrature rule, an
#: influence function, a micromodulus, a calibration, a solver), not of the problem: the
#: other scene parameters define the problem (geometry, material, load)
SETTINGS = frozenset({"quadrature", "influence", "micromodulus", "complete_m",
                      "end_weight", "calibration", "solver"})
#: Method parameters that define the problem or its discretisation, not a setting of the
#: method: the grid and its refinement (spacing, horizon, m_ratio, nodes, levels, mesh
#: cells and grading, time steps), the lattice's jitter, the kinematics and where the load
#: acts. A run that changes one is another problem or a finer grid
PROBLEM = frozenset({"spacing", "horizon", "horizon_ratio", "m_ratio", "nodes", "levels",
                     "cells", "arc_cells", "radial_cells", "elements", "fine_depth",
                     "fine_half_width", "grading_power", "grading_ratio", "sample_spacing",
                     "dt", "dt_factor", "n_steps", "substeps", "uniform_study", "jitter",
                     "jitter_seed", "kinematics", "load_point", "symmetry"})


def problem_params(scene) -> set:
    """The names of the parameters that define ``scene``'s problem and discretisation
    (every parameter of the scene but :data:`SETTINGS`, and :data:`PROBLEM`)."""
    return {p.name for p in scene.params if p.name not in SETTINGS} | PROBLEM


def configurations(scene, method, runs) -> list:
    """The runs of ``method`` that are configurations of its default run
    (:func:`default_run`): the same problem on the same grid, other settings of the
    method only (:func:`problem_params` equal); the default run among them."""
    default = default_run(scene, method, runs)
    if default is None:
        return []
    fixed = problem_params(scene)
    return [r for r in runs if r.method == method
            and all(r.params.get(k) == default.params.get(k) for k in fixed)]


@dataclass
class SceneSummary:
    scene: str
    metric: str
    best: str | None        # the most accurate method at default params (None: < 2 methods)
    best_error: float | None  # its headline error as a fraction
    best_time_s: float | None
    runs: int
    failed: list            # (method, message) of the runs that count as failures
    expected: int = 0       # documented failures that happened (not failures of the report)


def summarise(scene, runs) -> SceneSummary:
    picked = {m: default_run(scene, m, runs) for m in dict.fromkeys(r.method for r in runs)}
    values = {m: headline_value(scene, r) for m, r in picked.items() if r is not None}
    # an external code's run (report --include) is shown, never pdverify's best method
    values = {m: v for m, v in values.items()
              if v is not None and not m.startswith("external:")}
    best = min(values, key=values.get) if len(values) > 1 else None
    return SceneSummary(
        scene=scene.id, metric=headline(scene), best=best,
        best_error=values.get(best), runs=len(runs),
        best_time_s=time_s(picked[best].timings) if best else None,
        # (shown on the terminal: the names and messages of included records escaped)
        failed=[(printable(r.method), printable(r.message)) for r in runs
                if r.counts_as_failure],
        expected=sum(r.outcome == "expected-failure" for r in runs))


# -- the end-of-report summary (one row per scene) -----------------------------------------
SUMMARY_COLUMNS = ("scene", "best method", "error", "time", "runs", "failed",
                   "failed as expected", "first failure")
#: right-aligned columns: error, time, runs, failed, failed as expected
_NUMERIC = (2, 3, 4, 5, 6)
#: a failure message is cut to this many characters in the summary
FAILURE_WIDTH = 60


def _shorten(text: str, width: int = FAILURE_WIDTH) -> str:
    text = " ".join(str(text).split())
    return text if len(text) <= width else text[: width - 3].rstrip() + "..."


def summary_row(s: SceneSummary) -> list[str]:
    """The summary's cells of one scene (see :data:`SUMMARY_COLUMNS`): the error is the
    best method's headline error in %, named when it is not :data:`HEADLINE_DEFAULT`;
    ``-`` where there is nothing to say (a best method needs two methods with a headline
    error)."""
    error = "-"
    if s.best_error is not None:
        error = f"{100 * s.best_error:.3g} %"
        if s.metric != HEADLINE_DEFAULT:
            error += f" {s.metric}"
    first = _shorten(f"{s.failed[0][0]}: {s.failed[0][1]}") if s.failed else ""
    return [s.scene, s.best or "-", error,
            "-" if s.best_time_s is None else f"{s.best_time_s:.2f} s",
            str(s.runs), str(len(s.failed)), str(s.expected), first]


def _columns(summaries) -> list[int]:
    """Which of :data:`SUMMARY_COLUMNS` to show: 'failed as expected' only if a documented
    failure happened, 'first failure' only if a run failed."""
    shown = list(range(len(SUMMARY_COLUMNS)))
    if not any(s.failed for s in summaries):
        shown.remove(SUMMARY_COLUMNS.index("first failure"))
    if not any(s.expected for s in summaries):
        shown.remove(SUMMARY_COLUMNS.index("failed as expected"))
    return shown


def format_summary(summaries) -> str:
    """The summary as fixed-width plain text: a header, then one row per scene: the best
    method at default parameters, its headline error (in %, the metric named unless it is
    ``rel_l2_error``) and total time, the number of runs and of failed runs (those that
    count: documented failures are apart, in 'failed as expected', shown when one
    happened), and (if any run failed) the first failure's message, shortened."""
    shown = _columns(summaries)
    rows = [[SUMMARY_COLUMNS[i] for i in shown]] + [[summary_row(s)[i] for i in shown]
                                                     for s in summaries]
    widths = [max(len(r[j]) for r in rows) for j in range(len(shown))]
    lines = []
    for r in rows:
        cells = [c.rjust(w) if i in _NUMERIC else c.ljust(w)
                 for i, c, w in zip(shown, r, widths)]
        lines.append("  ".join(cells).rstrip())
    return "\n".join(lines)


def summary_table(summaries):
    """The same summary for a terminal: a ``rich`` table without the failure column,
    then the first failure of each scene that has one, below the table (so the table stays
    narrow; on a narrow terminal only the error cell wraps, between value and metric)."""
    from rich.console import Group
    from rich.table import Table
    from rich.text import Text
    table = Table(title=f"best method at default parameters; error: {HEADLINE_DEFAULT} "
                        "unless named", title_justify="left", title_style="italic",
                  header_style="bold underline", box=None, padding=(0, 1), pad_edge=False)
    rows = [summary_row(s) for s in summaries]
    value = max([len(r[2].split(" %")[0]) + 2 for r in rows] + [5])  # '1.2e-13 %'
    shown = [i for i in _columns(summaries) if SUMMARY_COLUMNS[i] != "first failure"]
    for i in shown:
        name = SUMMARY_COLUMNS[i]
        table.add_column(name, justify="right" if i in _NUMERIC else "left",
                         no_wrap=name != "error", min_width=value if name == "error" else None)
    for s, row in zip(summaries, rows):
        # red for failures that count; a documented failure is expected (pytest's yellow)
        table.add_row(*[row[i] for i in shown],
                      style="red" if s.failed else "yellow" if s.expected else None)
    failures = [Text(f"  {s.scene}: {row[-1]}", style="red")
                for s, row in zip(summaries, rows) if s.failed]
    if not failures:
        return table
    return Group(table, Text("first failure of each scene with one:"), *failures)


def print_summary(scenes, results, stream) -> None:
    """Print the end-of-report summary of ``scenes`` (Scene objects) from ``results`` to
    ``stream``: a rich table on a terminal, :func:`format_summary` text otherwise (and
    always in the report's log, when ``stream`` is a :class:`~pdverify.progress.Tee`). A
    summary that cannot be made costs only itself (a note), never the report."""
    from ..progress import is_terminal, screen_and_log
    try:
        summaries = [summarise(scene, [r for r in results if r.scene == scene.id])
                     for scene in scenes]
        screen, log = screen_and_log(stream)
        if is_terminal(screen):
            from rich.console import Console
            Console(file=screen, force_terminal=True).print(summary_table(summaries))
            if log is not None:
                print(format_summary(summaries), file=log)
        else:
            print(format_summary(summaries), file=stream)
    except Exception as exc:  # a display problem must not lose the report
        print(f"summary failed: {type(exc).__name__}: {exc}", file=stream)


def largest_memory(results) -> str:
    """The run with the largest peak memory (``resources.peak_rss_gb``), as a line; empty
    where no run measured one."""
    measured = [r for r in results if r.resources.get("peak_rss_gb")]
    if not measured:
        return ""
    r = max(measured, key=lambda r: r.resources["peak_rss_gb"])
    return (f"largest peak memory of a run: {r.resources['peak_rss_gb']:.3g} GB "
            f"({r.scene} {r.method}, {r.timings.get('total_s', 0.0):.3g} s)")


# -- the machine's load over the runs ------------------------------------------------------
#: A report notes the machine's load when the runs' shares of a core differ by more than
#: this factor: each run records the 1-minute load average at its start and end
#: (``resources.load_start``, ``load_end``: :func:`pdverify.budget.load_average`), and
#: above the CPU count the runnable processes share the cores, so a run can take up to
#: max(1, load / CPUs) times its time on an idle machine. 1.5: a run time half again as long
#: is more than the run-to-run spread of a run at one load (a few %, the quick report's
#: repeats in benchmarks/report_cost.py)
LOAD_FACTOR = 1.5


def load_note(results, cpus) -> str:
    """A sentence saying how the machine's load varied over the runs of ``results`` on
    ``cpus`` CPUs, when it varied by more than :data:`LOAD_FACTOR` in shares of a core;
    empty otherwise, or when no run recorded its load."""
    loads = [v for r in results for v in (r.resources.get("load_start"),
                                            r.resources.get("load_end"))
             if isinstance(v, (int, float)) and not isinstance(v, bool)]
    if not loads or not cpus or cpus < 1:
        return ""
    low, high = min(loads), max(loads)
    factor = max(1.0, high / cpus) / max(1.0, low / cpus)
    if factor <= LOAD_FACTOR:
        return ""
    return (f"The machine's load varied while the runs ran: the 1-minute load average was "
            f"{low:.1f} to {high:.1f} on {cpus} CPUs. Above the CPU count the runs share "
            f"the cores, so a run's time may be up to {factor:.1f} times what it would be "
            f"at the lowest load: compare run times at similar loads (each run's load is "
            f"in its time's hover text and in results.json, resources.load_start and "
            f"load_end).")

