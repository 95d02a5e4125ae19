"""The report's index.html, rendered from the Jinja2 templates in ``templates/``: this
module turns runs into the values a template shows (numbers formatted, colours, the
paper's values), the templates hold the markup, and every value is escaped on output."""
from __future__ import annotations

import hashlib
import math
import re

import jinja2
from markupsafe import Markup

from ..convergence import EXACT, LEVEL_RESULTS
from ..corrections import describe
from ..errors import InputError
from ..papers import PAPERS, seed_of
from ..published import FIGURE, verdict
from ..quotes import resolve
from ..results import CACHED_SETUP
from ..results import cost_s as run_cost_s
from ..results import time_s as run_time_s
from .summary import (configurations, default_run, headline, headline_value, load_note,
                      summarise)

_ENV = jinja2.Environment(
    loader=jinja2.PackageLoader("pdverify.report", "templates"),
    autoescape=True, trim_blocks=True, lstrip_blocks=True,
    undefined=jinja2.StrictUndefined, keep_trailing_newline=False)


def short_caption(caption: str, limit: int = 70) -> str:
    """A figure's short title for a folded list: its caption up to the first colon or
    full stop (at most ``limit`` characters, cut at a word)."""
    text = re.sub(r"<[^>]+>", "", str(caption)).strip()
    head = re.split(r":\s|(?<!Fig)(?<!Figs)(?<!Eq)(?<!Eqs)(?<!e\.g)(?<!i\.e)(?<!\d)\.(?:\s|$)",
                    text, maxsplit=1)[0]
    if len(head) > limit:
        head = head[:limit].rsplit(" ", 1)[0] + "..."
    return head


def short_captions(figures) -> str:
    """The short titles of ``(file, caption)`` pairs for a folded list, each once, with
    how many figures share it (a scene's three FEM references: one title, x 3)."""
    counts = {}
    for _, caption in figures:
        head = short_caption(caption)
        counts[head] = counts.get(head, 0) + 1
    return "; ".join(h + (f" (x {n})" if n > 1 else "") for h, n in counts.items())


_ENV.filters["short_caption"] = short_caption
_ENV.filters["short_captions"] = short_captions


def lead_figures(scene_id: str, figures) -> tuple[list, int]:
    """The scene's figures in the page's order and how many of them it shows unfolded:
    the first figure of the scene's own (a reproduced figure of the paper, an error map)
    leads, the FEM reference's field and force-depth figures (``SCENE-K.png``,
    ``SCENE-K-force.png``) follow it, and the rest is folded (:data:`LEAD_FIGURES`)."""
    fem = re.compile(re.escape(scene_id) + r"-\d+(-force)?\.png")
    own = [f for f in figures if not fem.fullmatch(f[0])]
    ref = [f for f in figures if fem.fullmatch(f[0])]
    return own + ref, min(LEAD_FIGURES, len(figures))


#: figures of a scene shown unfolded: one, so that every scene shows its main picture and
#: the page stays under 50,000 px at 1400 px wide (issue 52; 80,500 px with all 65 of the
#: full report's figures open: record page_height-2026-11-28-lead-figures)
LEAD_FIGURES = 1


def _render(template: str, **context) -> Markup:
    return Markup(_ENV.get_template(template).render(**context))


def _num(v) -> str:
    if isinstance(v, float):
        return f"{v:.4g}"
    return str(v)


def _params(result, scene) -> str:
    """The run's params that differ from the scene's and its method's defaults."""
    try:   # an external run (pdverify score) holds the uncorrected problem's params
        method_params = scene.method("none" if _external(result.method)
                                     else result.method).params
    except InputError:  # a method the scene no longer offers: show everything
        method_params = ()
    defaults = {p.name: p.default for p in tuple(scene.params) + tuple(method_params)}
    shown = {k: v for k, v in result.params.items() if defaults.get(k, object()) != v}
    return ", ".join(f"{k}={_num(v)}" for k, v in shown.items()) or "defaults"


#: at most this many metric columns in a scene's compact table (the rest are folded)
KEY_METRICS = 4


def key_metrics(scene, results) -> list[str]:
    """The compact table's metric columns: the headline error, the metrics the paper
    prints for this scene, those the scene names (``table_metrics``), then the scene's
    first metrics; at most :data:`KEY_METRICS`."""
    present = []
    for r in results:
        for k in r.metrics:
            if k not in present:
                present.append(k)
    wanted = ([headline(scene)] + [p.metric for p in scene.published]
              + list(getattr(scene, "table_metrics", ())) + present)
    out = []
    for m in wanted:
        if m in present and m not in out:
            out.append(m)
    return out[:KEY_METRICS]


def _external(method: str) -> bool:
    """A run of another code scored by ``pdverify score`` (``external:NAME``)."""
    return method.startswith("external:")


def _describe(method: str) -> str:
    if _external(method):
        return ("another code's displacements on the exported uncorrected problem, measured "
                "by pdverify score (report --include); its cost is not measured")
    return describe(method)


def _solver(diagnostics) -> dict | None:
    """The linear solver a run used: a short tag for under its solve time and the full
    name (with CG's iteration count in the tag) for on hover."""
    solver = diagnostics.get("solver") if isinstance(diagnostics, dict) else None
    if not isinstance(solver, str):
        return None
    its = diagnostics.get("iterations")
    if solver == "external":
        tag = "external"
    elif solver.startswith("CG"):
        tag = f"CG {its} it" if isinstance(its, int) else "CG"
    elif solver.startswith("dense"):
        tag = "dense LU"
    elif "nested-dissection" in solver:
        tag = "LU, ND"
    else:
        tag = "LU"
    return {"tag": tag, "full": solver}


def _solver_note(diagnostics) -> Markup:
    """The solver tag as the tables show it (under a solve time; empty without a solver)."""
    return _ENV.get_template("macros.html").module.solver_note(_solver(diagnostics))


def _ours(value, paper=None) -> str:
    """Our value with at least one digit more than the paper prints (4.17 -> 4.137,
    1.0125 -> 1.01250), else 4 significant digits."""
    if not isinstance(value, float) or paper is None:
        return _num(value)
    text = str(paper.value).strip()
    if re.fullmatch(r"-?\d+\.\d+", text):
        decimals = len(text.split(".")[1]) + 1
        if f"{value:.{decimals}f}" != f"{value:.4g}" and abs(value) < 1e6:
            return f"{value:.{decimals}f}"
    return _num(value)


def _paper_text(p) -> str:
    """The paper's value as the tables show it: as printed, marked when read off a figure."""
    return _num(p.value) + (" (read off a figure)" if p.kind == FIGURE else "")


def run_anchor(result) -> str:
    """The id of a run's row in its scene's table (the same for the same scene, method
    and params): ``run-`` and a short hash of :func:`~pdverify.results.run_key`."""
    return "run-" + hashlib.sha1("\0".join(result.key).encode()).hexdigest()[:12]


def _row(scene, r, metrics) -> dict:
    """What the compact and the full table show of one run."""
    t = r.timings
    if _external(r.method):   # no cost pdverify measured
        t = {"setup_s": "n/a", "solve_s": "n/a", "total_s": "n/a"}
    paper = scene.published_for(r.method, r.params)
    cached = _num3(t[CACHED_SETUP]) if t.get(CACHED_SETUP) else ""
    return {
        "anchor": run_anchor(r), "ok": r.status == "ok", "method": r.method, "params": _params(r, scene),
        "outcome": r.outcome, "expected": r.expected_failure,
        "message": r.message, "warnings": list(r.warnings),
        "cells": [{"value": _ours(r.metrics.get(m, ""), paper.get(m)),
                   "paper": _paper_text(paper[m]) if m in paper else None,
                   "source": paper[m].source if m in paper else ""} for m in metrics],
        "all_metrics": [(k, _num(v)) for k, v in r.metrics.items()],
        "setup": _num3(t.get('setup_s', 0)), "solve": _num3(t.get('solve_s', 0)),
        # setup read from the cache, at the time it took when computed (results.CACHED_SETUP):
        # named beside the setup, and in the total, so that a warm cache does not make a
        # method look cheap
        "cached": f" (+ {cached} s from the cache)" if cached else "",
        "cached_note": f"incl. {cached} s cached" if cached else "",
        "total": _num3(run_time_s({"total_s": 0, **t})),
        "solver": _solver(r.diagnostics),
        "peak": (f", peak memory {r.resources['peak_rss_gb']:.3g} GB"
                 if r.resources.get("peak_rss_gb") else "") + _load_text(r.resources),
        "size": ", ".join(f"{k} {v}" for k, v in r.size.items()),
    }


def _load_text(resources: dict) -> str:
    """``, machine load 0.8-3.1``: the 1-minute load average at the run's start and end
    (:func:`pdverify.budget.load_average`), empty when it was not recorded."""
    start, end = resources.get("load_start"), resources.get("load_end")
    if start is None or end is None:
        return ""
    return f", machine load {start:.1f}-{end:.1f} (1-minute average)"


def _num3(v) -> str:
    return v if isinstance(v, str) else f"{v:.3g}"


def _refinement(result) -> dict:
    """The refinement study of a reference run: one row per level, coarsest first."""
    rows = result.fields["refinement"]
    extra = sorted({k for row in rows for k in row.get("extra", {})})
    return {"method": result.method, "quantity": result.fields.get("quantity_name", "quantity"),
            "extra": extra,
            "rows": [[row["level"], row["dofs"], _num(row["h_min"]), f"{row['quantity']:.8g}",
                      _num(row["change_pct"]), _num(row["setup_s"]), _num(row["solve_s"])]
                     + [_num(row.get("extra", {}).get(k, "")) for k in extra] for row in rows]}


def published_rows(scene, results) -> list[dict]:
    """One row per published value of every run that has one: ours beside the paper's,
    the check and its verdict (:mod:`pdverify.published`), the source and any deviation."""
    rows = []
    for r in results:
        for p in scene.published_for(r.method, r.params).values():
            entry = p.entry(r.params)
            ours = r.metrics.get(p.metric)
            check = {"equal": "=", "below": "<", "above": ">", "none": ""}[entry["check"]]
            if entry["check"] != "none":
                check = (f"{check} {entry['target']:.7g}"
                         + (f" &plusmn; {entry['tolerance']:.2g}" if entry["tolerance"] else ""))
                if entry.get("known_difference") and entry.get("reproduced") is not None:
                    # a known difference is bounded by the value we reproduce
                    check += (f"; ours {entry['reproduced']:.7g} &plusmn; "
                              f"{entry['reproduced_tolerance']:.2g}")
            rows.append({"method": r.method, "params": _params(r, scene), "metric": p.metric,
                         "ours": _ours(ours, p) if ours is not None else "(none)",
                         "paper": _num(p.value), "figure": p.kind == FIGURE,
                         "check": Markup(check), "tolerance_source": entry["tolerance_source"],
                         "verdict": verdict(entry, ours), "source": p.source,
                         "deviation": p.deviation, "note": p.note, "role": entry["role"],
                         "entry": entry})
    return rows


def published_counts(rows) -> str:
    """The scene's published rows counted apart by role (:func:`pdverify.published.count_text`):
    values the paper computes, setups it states, claims in words."""
    from ..published import count_text
    return count_text(rows)


def full_report_runs(scene) -> list[tuple[str, dict]]:
    """(method, params) of every run the full report makes of ``scene``."""
    out = []
    for method, overrides in scene.report_cases(quick=False):
        t = scene.offered().get(method)
        if t is not None and t.origin != "built-in":
            continue    # a plugin's runs have no published entries; its code is not called
        try:
            out.append((method, scene.resolve(method, overrides)))
        except InputError:
            continue
    return out


def unmatched_published(scene) -> list[str]:
    """The published values that no run of the full report matches (a ``where`` the
    method's params cannot satisfy): one phrase each, so that the page never says the
    full report runs them."""
    runs = full_report_runs(scene)
    return list(dict.fromkeys(
        f"{p.metric} = {_num(p.value)} ({p.source}; {p.method or 'any method'})"
        for p in scene.published if not any(p.applies(m, q) for m, q in runs)))


def missing_published(scene, results) -> list[str]:
    """The published values that stand beside no run of this report but beside a run of
    the full report (e.g. at the paper's grid, which the quick report does not run): one
    phrase each, the runs they need. Those no full-report run matches are
    :func:`unmatched_published`'s."""
    out = []
    runs = full_report_runs(scene)
    for p in scene.published:
        if any(p.applies(r.method, r.params) for r in results):
            continue
        if not any(p.applies(m, q) for m, q in runs):
            continue
        mine = [r for r in results if p.method in (None, r.method)]
        where = ", ".join(f"{k}={_num(v)}" for k, v in (p.where or {}).items()
                          if not any(r.params.get(k) == v for r in mine))
        out.append(f"{p.metric} = {_num(p.value)} ({p.source}; {p.method or 'any method'}"
                   + (f" at {where}" if where else "") + ")")
    return list(dict.fromkeys(out))


def scene_section(scene, results, figures, deviations=None, records=None) -> Markup:
    """A scene's section: the deviations box (default: those of
    :mod:`pdverify.deviations`), the docstring folded, the compact table (at most
    :data:`KEY_METRICS` metric columns, the paper's value beneath ours), every metric of
    each run folded (one wrapped cell, so a scene with twenty metrics still fits), the
    reference's refinement studies and the figures. The numbers the deviations and the
    docstring quote (:mod:`pdverify.quotes`) are formatted from ``records`` (default:
    ``results``; the whole report's runs, for a text that quotes another scene's)."""
    records = results if records is None else records
    if deviations is None:
        from ..deviations import for_scene, peer_findings
        deviations = for_scene(scene.id) + peer_findings(scene.id, results)
    deviations = [d.render(records, scene.id) for d in deviations]
    paper = PAPERS.get(seed_of(scene.seed), {})
    metrics = key_metrics(scene, results)
    return _render(
        "scene.html", scene=scene, headline=headline(scene), deviations=deviations,
        cite=f"{paper['authors']} ({paper['year'] or 'n.d.'})" if paper else "",
        doc=resolve((type(scene).__doc__ or "").strip(), getattr(scene, "doc_quotes", {}),
                    records, scene.id), metrics=metrics,
        rows=[_row(scene, r, metrics) for r in results],
        refinements=[_refinement(r) for r in results if r.fields.get("refinement")],
        sources=sorted({p.source for p in scene.published}),
        figures=(lead := lead_figures(scene.id, figures))[0], lead=lead[1],
        published=(pub := published_rows(scene, results)),
        published_counts=published_counts(pub) if pub else "",
        published_fails=sum(p["verdict"] == "fails" for p in pub),
        missing=missing_published(scene, results) if results else [],
        unmatched=unmatched_published(scene))


def convergence_section(studies, figures) -> Markup:
    """A scene's convergence studies: one row per method, its rate in each study (or why
    there is none) and the errors of its levels, the figure beneath."""
    if not studies:
        return Markup("")
    kinds = [k for k in ("delta", "m") if any(s["study"] == k for s in studies)]
    first = {k: next(s for s in studies if s["study"] == k) for k in kinds}
    rows = []
    for method in dict.fromkeys(s["method"] for s in studies):
        cells = []
        for k in kinds:
            e = next((s for s in studies if s["method"] == method and s["study"] == k), None)
            cells.append(None if e is None else {
                "rate": None if e["rate"] is None else f"{e['rate']:.2f}", "note": e["note"],
                "pairs": ", ".join(f"{r:.2f}" for r in e.get("pair_rates", [])),
                "errors": ["failed" if lv["error"] is None else f"{lv['error']:.3g}"
                           for lv in e["levels"]]})
        rows.append((method, cells))
    levels = "; ".join(
        f"{k}: h = {first[k]['h']}: " + ", ".join(
            f"{lv['h']:.4g} (" + ", ".join(f"{p} {v:.4g}" for p, v in lv.items()
                                            if p not in LEVEL_RESULTS) + ")"
            for lv in first[k]["levels"])
        for k in kinds)
    return _render("convergence.html", scene=studies[0]["scene"], metric=studies[0]["metric"],
                   levels=levels, kinds=kinds, fixed={k: first[k]["fixed"] for k in kinds},
                   rows=rows, figures=figures)


def figure_list(figures) -> Markup:
    """``(file, caption)`` pairs of ``figures/`` as HTML figures."""
    return _ENV.get_template("macros.html").module.figure_list(figures)


#: A headline error (as a fraction) at or below this is round-off, shown as "exact" apart
#: from the colour scale: :data:`pdverify.convergence.EXACT` (1e-10, i.e. 1e-8 %), the bound
#: the convergence studies use (direct solves' residuals are ~1e-13 relative).
EXACT_FRACTION = EXACT


def headline_pct(scene, result) -> float | None:
    """The run's headline error in per cent (``*_pct`` metrics as they are, fractions
    times 100), its sign kept; None where :func:`headline_value` has none."""
    if headline_value(scene, result) is None:
        return None
    v = float(result.metrics[headline(scene)])
    return v if headline(scene).endswith("_pct") else 100.0 * v


def is_exact(pct) -> bool:
    """A headline error (per cent) at round-off level (:data:`EXACT_FRACTION`)."""
    return abs(pct) <= 100.0 * EXACT_FRACTION


def cost_s(result) -> float:
    """A run's cost on the front page: :func:`pdverify.results.cost_s` of its timings."""
    return run_cost_s(result.timings)


def colour_scale(pcts) -> tuple[float, float] | None:
    """The overview's log colour scale, fitted to the errors present: from the smallest
    error that is not exact to the largest (per cent, absolute values); None if every
    error is exact or there is none. A single value gets one decade around it."""
    vals = [abs(v) for v in pcts if v is not None and not is_exact(v)]
    if not vals:
        return None
    lo, hi = min(vals), max(vals)
    if hi <= lo * 1.0001:
        lo, hi = lo / 10 ** 0.5, hi * 10 ** 0.5
    return lo, hi


def _colour(pct: float, scale) -> str:
    """Green (the scale's low end) to red (its high end) on a log scale of ``|pct|``."""
    lo, hi = scale
    v = min(max(abs(pct), lo), hi)
    bad = (math.log10(v) - math.log10(lo)) / (math.log10(hi) - math.log10(lo))
    return f"rgb({int(150 + 100 * bad)},{int(235 - 85 * bad)},150)"


def _pct_text(pct: float) -> str:
    return f"{pct:.3g} %"


def best_run(scene, method, runs):
    """The best configuration of ``method``: among its runs on the default run's problem
    and grid (:func:`~pdverify.report.summary.configurations`: jitter, geometry and
    refinement are not configurations), the one with the lowest headline error (ties: the
    cheaper one), or None when none has a headline error."""
    mine = [(abs(headline_pct(scene, r)), cost_s(r), k, r)
            for k, r in enumerate(configurations(scene, method, runs))
            if headline_pct(scene, r) is not None]
    return min(mine)[3] if mine else None


def _value(scene, r, scale) -> dict:
    pct = headline_pct(scene, r)
    exact = is_exact(pct)
    return {"text": _pct_text(pct), "exact": exact, "params": _params(r, scene),
            "colour": "" if exact or scale is None else _colour(pct, scale),
            "cost": ("not measured" if _external(r.method)
                     else f"{cost_s(r):.2g}")}


def _overview_cell(scene, m, runs, best, scale) -> dict | None:
    r = default_run(scene, m, runs)
    if r is None:
        t = scene.offered().get(m)
        if t is not None and t.unavailable:
            return {"kind": "unavailable", "message": t.unavailable}
        if any(x.name == m for x in scene.all_methods):
            return {"kind": "not-run"}
        return None
    if r.outcome == "expected-failure":
        return {"kind": "expected", "message": f"expected ({r.expected_failure}): {r.message}"}
    if r.status != "ok":
        return {"kind": "failed", "message": r.message}
    if m == "fem":
        return {"kind": "fem", "time": f"{cost_s(r):.2g}"}
    if headline_value(scene, r) is None:
        return {"kind": "none"}
    cell = {"kind": "value", "default": _value(scene, r, scale), "best": m == best,
            "better": None}
    top = best_run(scene, m, runs)
    if top is not None and top is not r and abs(headline_pct(scene, top)) < abs(
            headline_pct(scene, r)):
        better = _value(scene, top, scale)
        # better to the digits shown (a difference in the fourth digit is not a finding)
        if (better["text"], better["exact"]) != (cell["default"]["text"],
                                                 cell["default"]["exact"]):
            cell["better"] = better
    return cell


def overview_scale(scenes, results):
    """The colour scale of :func:`overview` (see :func:`colour_scale`): fitted to the
    headline errors the matrix shows (each method's default and best run)."""
    pcts = []
    for scene in scenes:
        runs = [r for r in results if r.scene == scene.id]
        for m in dict.fromkeys(r.method for r in runs):
            for r in (default_run(scene, m, runs), best_run(scene, m, runs)):
                if r is not None and r.status == "ok":
                    pcts.append(headline_pct(scene, r))
    return colour_scale(pcts)


def overview(scenes, results) -> Markup:
    """Scene x method matrix: each cell the headline error in per cent of the method's
    run at its default parameters and, when another of its runs is more accurate, that
    best configuration (its parameters and cost beneath); coloured on a log scale fitted
    to the errors present (:func:`overview_scale`), round-off marked "exact" apart from
    the scale; the best method per scene (at default parameters) starred; failed runs
    red with the reason on hover; a method that cannot run here says why; FEM cells
    marked as the reference. Method names break at their hyphens so that ~15 columns
    fit a 1400 px screen."""
    from ..listing import method_columns
    methods = method_columns(scenes)
    # external codes' runs (pdverify score, report --include): a column each, last
    methods += sorted({r.method for r in results if _external(r.method)})
    scale = overview_scale(scenes, results)
    rows = []
    for scene in scenes:
        runs = [r for r in results if r.scene == scene.id]
        best = summarise(scene, runs).best
        rows.append({"scene": scene.id, "metric": headline(scene),
                     "cells": [_overview_cell(scene, m, runs, best, scale) for m in methods]})
    return _render("overview.html", methods=methods, rows=rows, exact=100 * EXACT_FRACTION,
                   scale=None if scale is None else [_pct_text(v) for v in scale],
                   low=None if scale is None else _colour(scale[0], scale),
                   high=None if scale is None else _colour(scale[1], scale))


def papers(scenes) -> Markup:
    """The seed papers the report's scenes come from, with the scenes of each."""
    items = []
    for key, p in PAPERS.items():
        ids = [s.id for s in scenes if seed_of(s.seed) == key]
        if ids:
            items.append({**p, "key": key, "year": p["year"] or "n.d.", "scenes": ids})
    return _render("papers.html", items=items)


def failed_runs(results, tabled=None) -> list[dict]:
    """The runs that count as failures (:attr:`RunResult.counts_as_failure`), each with
    the anchor the header's failure count links to: its row in the scene's table, or the
    scene's convergence section for a level that has no row (``tabled``: the keys of the
    runs in the tables; None: all)."""
    out = []
    for r in results or ():
        if not r.counts_as_failure:
            continue
        in_table = tabled is None or r.key in tabled
        out.append({"scene": r.scene, "method": r.method,
                    "params": ", ".join(f"{k}={_num(v)}" for k, v in r.params.items()),
                    "message": r.message or "ok, but documented to fail: the finding is "
                                            "out of date",
                    "anchor": run_anchor(r) if in_table else f"{r.scene}-convergence"})
    return out


def page(doc: dict, sections: list[tuple], total_time: float, results=None,
         front_figures=(), tabled=None) -> str:
    runs = doc["runs"]
    scenes = [s for s, _ in sections]
    return _render(
        "page.html", doc=doc, n_runs=len(runs),
        n_failed=sum(1 for r in runs if r["status"] != "ok" and not r.get("expected_failure")),
        n_expected=sum(1 for r in runs if r["status"] != "ok" and r.get("expected_failure")),
        n_warned=sum(1 for r in runs if r.get("warnings")), total_time=total_time,
        load_note=(load_note(results, doc.get("machine", {}).get("cpus"))
                   if results is not None else ""),
        overview=overview(scenes, results) if results is not None else "",
        failed=failed_runs(results, tabled),
        front_figures=front_figures, papers=papers(scenes),
        methods=[(m, _describe(m)) for m in sorted({r["method"] for r in runs})],
        sections=sections) + "\n"
