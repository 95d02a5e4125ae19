"""Baseline versus new results.json: per-run metric changes, regressions and the exit code."""
from __future__ import annotations

import json
import math
import sys
from dataclasses import dataclass

from . import published
from .errors import InputError
from .results import load_results, run_key

#: Default thresholds. A metric counts as changed when
#: |new - old| > atol + rtol * |old|. rtol 1e-3 keeps legitimate round-off differences
#: between machines (BLAS, LU pivoting) out while catching any change of substance;
#: atol absorbs metrics that sit at round-off level (e.g. 1e-12 % for an exact method),
#: whose relative change is meaningless. Per-metric overrides below.
#: The schema of ``--summary FILE.json``; it marks the file as pdverify's, so that the next
#: compare may replace it.
SUMMARY_SCHEMA = "pdverify.compare/1"
DEFAULT_RTOL = 1e-3
DEFAULT_ATOL = 1e-9
METRIC_ATOL = {
    "_pct": 1e-6,          # percentages: 1e-6 percentage points
    "rel_l2_error": 1e-10,
    "gap_nonlinearity": 1e-10,
}


def is_error_metric(name: str) -> bool:
    """Error-like metrics regress only when they grow; others regress on any change."""
    return "error" in name or "diff" in name or name.startswith("gap_")


def thresholds(name: str, rtol=None, atol=None) -> tuple[float, float]:
    r = DEFAULT_RTOL if rtol is None else rtol
    a = DEFAULT_ATOL
    for suffix, value in METRIC_ATOL.items():
        if name.endswith(suffix) or name == suffix:
            a = value
    return r, (a if atol is None else atol)


@dataclass
class Change:
    scene: str
    method: str
    params: str
    metric: str
    old: object
    new: object
    verdict: str  # "regression", "improved", "new", "note"

    @property
    def is_regression(self) -> bool:
        return self.verdict == "regression"


def current_defaults(scene: str, method: str) -> dict:
    """Every parameter of (scene, method) at its current default; {} if either is gone.
    An external run (``external:NAME``, pdverify score) has the uncorrected problem's."""
    from .scenes import get_scene
    if method.startswith("external:"):
        method = "none"
    try:
        return get_scene(scene).resolve(method, {})
    except InputError:
        return {}


def compare_docs(base: dict, new: dict, *, rtol=None, atol=None, defaults=current_defaults,
                 matched: list | None = None) -> list[Change]:
    """All differences between two pdverify.results/1 documents that exceed the thresholds.

    A baseline run with no exact match is matched to the new run whose params are the
    baseline's plus parameters added since, each at its current default (``defaults``):
    adding a parameter that keeps the old behaviour as its default does not lose the
    baseline. Such matches are appended to ``matched`` as (scene, method, added keys).
    """
    old_runs = {run_key(r["scene"], r["method"], r["params"]): r for r in base["runs"]}
    new_runs = {run_key(r["scene"], r["method"], r["params"]): r for r in new["runs"]}
    out: list[Change] = []
    used = set()
    for key, old in old_runs.items():
        scene, method, params = key
        cur = new_runs.get(key)
        if cur is None:
            added = {k: v for k, v in defaults(scene, method).items() if k not in old["params"]}
            wider = run_key(scene, method, {**old["params"], **added}) if added else None
            if wider in new_runs and wider not in old_runs:
                cur = new_runs[wider]
                used.add(wider)
                if matched is not None:
                    matched.append((scene, method, tuple(sorted(added))))
        if cur is None:
            out.append(Change(scene, method, params, "(run)", "present", "missing", "regression"))
            continue
        if old["status"] == "ok" and cur["status"] != "ok":
            out.append(Change(scene, method, params, "(status)", "ok",
                              f"failed: {cur.get('message', '')}", "regression"))
            continue
        if old["status"] != "ok" and cur["status"] == "ok":
            out.append(Change(scene, method, params, "(status)", "failed", "ok", "improved"))
        for name, ov in old.get("metrics", {}).items():
            nv = cur.get("metrics", {}).get(name)
            ov, nv = _number(ov), _number(nv)
            if nv is None:
                out.append(Change(scene, method, params, name, ov, "missing", "regression"))
                continue
            if _is_nan(ov) and _is_nan(nv):
                continue  # NaN against NaN is no change (JSON stores it as "nan" or NaN)
            if not isinstance(ov, (int, float)) or not isinstance(nv, (int, float)):
                if ov != nv:
                    out.append(Change(scene, method, params, name, ov, nv, "regression"))
                continue
            if ov == nv:
                continue  # equal, the same infinity included (inf - inf would be NaN)
            r, a = thresholds(name, rtol, atol)
            if math.isfinite(ov) and math.isfinite(nv) and abs(nv - ov) <= a + r * abs(ov):
                continue  # (an infinite baseline would make every threshold infinite)
            if is_error_metric(name) and nv < ov:
                verdict = "improved"
            else:
                verdict = "regression"
            out.append(Change(scene, method, params, name, ov, nv, verdict))
    for key in new_runs.keys() - old_runs.keys() - used:
        scene, method, params = key
        out.append(Change(scene, method, params, "(run)", "absent", "new", "new"))
    return out


_NON_FINITE = {"inf": math.inf, "+inf": math.inf, "infinity": math.inf, "+infinity": math.inf,
               "-inf": -math.inf, "-infinity": -math.inf}


def _number(v):
    """pdverify writes a non-finite metric as the string 'inf' or '-inf' (JSON has no
    infinity); such a string compares as the float, so 'inf' against Infinity is equal."""
    if isinstance(v, str):
        return _NON_FINITE.get(v.strip().lower(), v)
    return v


def _is_nan(v) -> bool:
    if isinstance(v, str):
        return v.strip().lower() == "nan"
    return isinstance(v, float) and math.isnan(v)


def _short_params(params_json: str, scene: str | None = None, method: str | None = None,
                  defaults=current_defaults) -> str:
    """The run's parameters that differ from the current defaults of (scene, method)
    (``defaults``; every parameter when the scene or method is gone), ``defaults`` when
    none differs: the parameter that tells two runs apart stays visible."""
    params = json.loads(params_json)
    if scene is not None:
        base = {k: v for k, v in _plain_defaults(defaults(scene, method)).items()}
        if base:
            params = {k: v for k, v in params.items() if k not in base or base[k] != v}
            if not params:
                return "defaults"
    return ",".join(f"{k}={v:g}" if isinstance(v, float) else f"{k}={v}" for k, v in params.items())


def _plain_defaults(values: dict) -> dict:
    """Defaults as results.json writes them (so that 1e9 compares with 1000000000.0)."""
    from .results import _plain
    return _plain(values)


def format_changes(changes: list[Change], defaults=current_defaults) -> str:
    """The changes as a text table; ``params`` shows each run's parameters that differ
    from the defaults (:func:`_short_params`)."""
    if not changes:
        return "no changes beyond the thresholds"
    rows = [("verdict", "scene", "method", "params (not default)", "metric", "baseline", "new")]
    for c in changes:
        fmt = (lambda v: f"{v:.6g}" if isinstance(v, float) else str(v))
        rows.append((c.verdict, c.scene, c.method,
                     _short_params(c.params, c.scene, c.method, defaults), c.metric,
                     fmt(c.old), fmt(c.new)))
    # the params column is never cut: it shows only what differs from the defaults
    widths = [max(len(r[i]) for r in rows) if i == 3 else min(max(len(r[i]) for r in rows), 90)
              for i in range(len(rows[0]))]
    return "\n".join("  ".join((cell if i == 3 else cell[:90]).ljust(w)
                                for i, (cell, w) in enumerate(zip(row, widths))) for row in rows)


def summary_text(changes: list[Change], path: str, baseline: str, new: str) -> str:
    """The changes as JSON (``path`` ending in .json) or a Markdown table (else), for CI."""
    n_reg = sum(c.is_regression for c in changes)
    if path.endswith(".json"):
        return json.dumps({"schema": SUMMARY_SCHEMA, "baseline": baseline, "new": new,
                           "regressions": n_reg,
                           "changes": [{"verdict": c.verdict, "scene": c.scene,
                                        "method": c.method, "params": json.loads(c.params),
                                        "metric": c.metric, "baseline": c.old, "new": c.new}
                                       for c in changes]}, indent=1, default=str) + "\n"
    lines = [f"# pdverify compare: {n_reg} regression(s), {len(changes) - n_reg} other change(s)",
             "", f"baseline `{baseline}`, new `{new}`", ""]
    if changes:
        lines += ["| verdict | scene | method | params (not default) | metric | baseline | new |",
                  "|---|---|---|---|---|---|---|"]
        for c in changes:
            fmt = (lambda v: f"{v:.6g}" if isinstance(v, float) else str(v))
            lines.append(f"| {c.verdict} | {c.scene} | {c.method} "
                         f"| {_short_params(c.params, c.scene, c.method)} "
                         f"| {c.metric} | {fmt(c.old)} | {fmt(c.new)} |")
    return "\n".join(lines) + "\n"


def compare_files(baseline: str, new: str, *, rtol=None, atol=None, stream=None,
                  summary: str | None = None) -> int:
    """``pdverify compare``: print the table of changes; 1 on any regression, else 0.

    Both files are checked against the schema first (exit 2 naming the file and the
    first bad field); ``summary`` also writes the changes as JSON or Markdown.
    """
    stream = stream or sys.stdout
    for value, flag in ((rtol, "--rtol"), (atol, "--atol")):
        if value is not None and not (value >= 0 and math.isfinite(value)):
            raise InputError(f"{flag}={value} must be a finite number >= 0")
    docs = [_load_checked(path, what)
            for path, what in ((baseline, "baseline"), (new, "new results"))]
    matched: list = []
    changes = compare_docs(docs[0], docs[1], rtol=rtol, atol=atol, matched=matched)
    print(format_changes(changes), file=stream)
    if matched:
        keys = sorted({k for *_, added in matched for k in added})
        print(f"compare: {len(matched)} baseline run(s) matched with parameters added since, "
              f"at their defaults: {', '.join(keys)}", file=stream)
    n_reg = sum(c.is_regression for c in changes)
    print(f"compare: {n_reg} regression(s), {len(changes) - n_reg} other change(s)", file=stream)
    if summary is not None:
        from .errors import OutputError
        from .results import atomic_write_text
        try:
            atomic_write_text(summary, summary_text(changes, summary, baseline, new))
        except OSError as exc:
            raise OutputError(f"--summary {summary!r}: cannot write it ({exc.strerror or exc})"
                              "; the comparison above is complete") from None
    return 1 if n_reg else 0


def check_unique(doc: dict, path: str, what: str) -> None:
    """InputError naming the first (scene, method, params) that ``doc`` holds twice: two
    copies would collapse into one and the comparison would silently use the last."""
    first = {}
    for k, r in enumerate(doc["runs"]):
        key = run_key(r["scene"], r["method"], r["params"])
        if key in first:
            raise InputError(f"{what} {path!r}: runs[{k}] repeats runs[{first[key]}] (scene "
                             f"{r['scene']!r}, method {r['method']!r}, params {key[2]}); a "
                             "results file holds each run once")
        first[key] = k


def _pub_fmt(v) -> str:
    if isinstance(v, bool) or v is None:
        return "-" if v is None else str(v)
    if isinstance(v, float):
        return f"{v:.6g}"
    return str(v)


def _pub_params(params: dict) -> str:
    return ",".join(f"{k}={v:g}" if isinstance(v, float) else f"{k}={v}"
                    for k, v in params.items())


def format_published(rows: list[dict]) -> str:
    """The checked entries as a fixed-width table, one line per entry."""
    table = [("verdict", "role", "scene", "method", "metric", "ours", "paper", "check",
              "tolerance", "source", "params")]
    for r in rows:
        e = r["entry"]
        check = {"equal": "=", "below": "<", "above": ">", "none": "-"}[e["check"]]
        if e["check"] != "none" and e.get("target") is not None and "deviation" in e \
                and not e.get("known_difference"):
            check += f" {_pub_fmt(e['target'])} ({e['deviation']})"
        elif e.get("known_difference"):
            check += f" (known: {e['deviation']})"
        table.append((r["verdict"], published.role_of(e), r["scene"], r["method"], e["metric"],
                      _pub_fmt(r["ours"]),
                      _pub_fmt(e["value"])
                      + (" [figure]" if e["kind"] == published.FIGURE else ""),
                      check, _pub_fmt(e.get("tolerance")), e["source"][:50],
                      _pub_params(r["params"])[:70]))
    widths = [max(len(row[i]) for row in table) for i in range(len(table[0]))]
    return "\n".join("  ".join(c.ljust(w) for c, w in zip(row, widths)).rstrip()
                     for row in table)


def _load_checked(path: str, what: str) -> dict:
    """A results file read and checked (unique run keys), every failure one line of bad
    input naming the file."""
    try:
        doc = load_results(path)
    except FileNotFoundError:
        raise InputError(f"results file {path!r} does not exist") from None
    except IsADirectoryError:
        raise InputError(f"results file {path!r} is a folder") from None
    except PermissionError:
        raise InputError(f"results file {path!r} cannot be read (permission denied)") from None
    except ValueError as exc:
        raise InputError(str(exc)) from None
    check_unique(doc, path, what)
    return doc


def compare_published(path: str, *, stream=None) -> int:
    """``pdverify compare --against-published RESULTS.json``: check every run of the file
    against the published entries pdverify's own catalogue holds for its scene, method
    and params (:func:`pdverify.published.catalogue_rows`: the target, tolerance, check
    and reproduced value of a known difference come from the package; the file supplies
    our values only, and its own ``published`` entries are not used); 0 when all hold
    (known differences and statements without a number are listed, not failed), 1 when
    one fails (listed again at the end), bad input (exit 2,
    :class:`~pdverify.errors.InputError`): a file that is not a results file (a NaN or
    negative tolerance, a number beyond the doubles), a run of a scene this pdverify does
    not know that claims published entries, a value of ours that is not a finite
    number, or no run the catalogue holds an entry for."""
    from .scenes import all_scenes
    stream = stream or sys.stdout
    doc = _load_checked(path, "results file")
    known = {s.id: s for s in all_scenes()}
    rows = []
    for k, run in enumerate(doc["runs"]):
        scene = known.get(run["scene"])
        if scene is None:
            if run.get("published"):
                raise InputError(f"--against-published {path!r}: runs[{k}] is of scene "
                                 f"{run['scene']!r}, which this pdverify does not know, so "
                                 "its published entries cannot be checked against the "
                                 "package's own")
            continue
        for row in published.catalogue_rows(run, scene):
            ours = row["ours"]
            if (isinstance(ours, (int, float)) and not isinstance(ours, bool)
                    and not published.finite_number(ours)):
                what = (repr(ours) if isinstance(ours, float)
                        else f"an integer of {len(str(abs(ours)))} digits")
                raise InputError(f"--against-published {path!r}: runs[{k}].metrics."
                                 f"{row['entry']['metric']} is {what}; a finite number is "
                                 "allowed")
            rows.append(row)
    if not rows:
        raise InputError(f"--against-published {path!r}: no run has a published entry in "
                         "pdverify's catalogue (runs the papers print nothing for, or of "
                         "scenes or params they do not cover)")
    print(format_published(rows), file=stream)
    counts = {v: sum(r["verdict"] == v for r in rows)
              for v in ("holds", "known difference", "not numeric", "fails")}
    failed = [r for r in rows if r["verdict"] == "fails"]
    for r in failed:
        e = r["entry"]
        print(f"fails: {r['scene']} {r['method']} {_pub_params(r['params'])}: {e['metric']} "
              f"= {_pub_fmt(r['ours'])}, paper {_pub_fmt(e['value'])} ({e['source']}; check "
              f"{e['check']} {_pub_fmt(e['target'])} within {_pub_fmt(e['tolerance'])}: "
              f"{e['tolerance_source']})"
              + (f"; known difference {e['deviation']}: ours reproduces "
                 f"{_pub_fmt(e.get('reproduced'))} within "
                 f"{_pub_fmt(e.get('reproduced_tolerance'))} ({e.get('reproduced_source')})"
                 if e.get("known_difference") else ""), file=stream)
    print(f"compare --against-published: {len(rows)} entries, {counts['holds']} hold, "
          f"{counts['known difference']} known differences, {counts['not numeric']} not "
          f"numeric, {counts['fails']} fail; {published.count_text(rows)}", file=stream)
    return 1 if failed else 0
