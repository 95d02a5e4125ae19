"""What the report's front page and the end-of-run summary say about each scene: its
headline error, the run of each method at its default parameters, the best method."""
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


@dataclass
class SceneSummary:
    scene: str
    metric: str
    best: str | None        # the most accurate method at default params (None: < 2 methods)
    best_error: float | None  # its headline error as a fraction
    best_time_s: float | None
    runs: int
    failed: list            # (method, message) of the failed runs


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
                if r.counts_as_failure])


# -- the end-of-report summary (one row per scene) -----------------------------------------
SUMMARY_COLUMNS = ("scene", "best method", "error", "time", "runs", "failed", "first failure")
#: right-aligned columns: error, time, runs, failed
_NUMERIC = (2, 3, 4, 5)
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
            str(s.runs), str(len(s.failed)), first]


def _columns(summaries) -> int:
    """How many of :data:`SUMMARY_COLUMNS` to show: 'first failure' only if a run failed."""
    n = len(SUMMARY_COLUMNS)
    return n if any(s.failed for s in summaries) else n - 1


def format_summary(summaries) -> str:
    """The summary as fixed-width plain text: a header, then one row per scene: the best
    method at default parameters, its headline error (in %, the metric named unless it is
    ``rel_l2_error``) and total time, the number of runs and of failed runs, and (if any
    run failed) the first failure's message, shortened."""
    n = _columns(summaries)
    rows = [list(SUMMARY_COLUMNS[:n])] + [summary_row(s)[:n] for s in summaries]
    widths = [max(len(r[i]) for r in rows) for i in range(n)]
    lines = []
    for r in rows:
        cells = [c.rjust(w) if i in _NUMERIC else c.ljust(w)
                 for i, (c, w) in enumerate(zip(r, widths))]
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
    for i, name in enumerate(SUMMARY_COLUMNS[:-1]):
        table.add_column(name, justify="right" if i in _NUMERIC else "left",
                         no_wrap=name != "error", min_width=value if name == "error" else None)
    for s, row in zip(summaries, rows):
        table.add_row(*row[:-1], style="red" if s.failed else None)
    failures = [Text(f"  {s.scene}: {row[-1]}", style="red")
                for s, row in zip(summaries, rows) if s.failed]
    if not failures:
        return table
    return Group(table, Text("first failure of each scene with one:"), *failures)


def print_summary(scenes, results, stream) -> None:
    """Print the end-of-report summary of ``scenes`` (Scene objects) from ``results`` to
    ``stream``: a rich table on a terminal, :func:`format_summary` text otherwise. A
    summary that cannot be made costs only itself (a note), never the report."""
    from ..progress import is_terminal
    try:
        summaries = [summarise(scene, [r for r in results if r.scene == scene.id])
                     for scene in scenes]
        if is_terminal(stream):
            from rich.console import Console
            Console(file=stream, force_terminal=True).print(summary_table(summaries))
        else:
            print(format_summary(summaries), file=stream)
    except Exception as exc:  # a display problem must not lose the report
        print(f"summary failed: {type(exc).__name__}: {exc}", file=stream)
