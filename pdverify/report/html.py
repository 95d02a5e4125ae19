"""The report's index.html: a summary, then per scene a table of runs and its figures."""
from __future__ import annotations

import html
import math

from ..corrections import describe
from ..errors import InputError
from ..papers import PAPERS, seed_of
from .summary import default_run, headline, headline_value, summarise

CSS = """
body{font-family:system-ui,sans-serif;margin:2em auto;max-width:1250px;color:#222}
table{border-collapse:collapse;margin:.6em 0;font-size:13px}
th,td{border:1px solid #ccc;padding:3px 7px;text-align:right;vertical-align:top}
th{background:#f2f2f2} td.l,th.l{text-align:left}
.failed{background:#fde2e2} .warning{color:#8a5a00} .doc{white-space:pre-wrap;font-size:12px;color:#444;
background:#fafafa;border-left:3px solid #ddd;padding:.4em .8em}
figure{margin:1em 0} figcaption{font-size:12px;color:#555} code{font-size:12px}
td.p{max-width:260px;word-break:break-word} td.m{font-size:12px;white-space:nowrap} td.s{max-width:320px;word-break:break-word}
div.wide{overflow-x:auto;max-width:100%} .dev{background:#fff8e5;border-left:3px solid #e0b84d;
padding:.3em .8em;font-size:13px;margin:.5em 0}
"""


def _num(v) -> str:
    if isinstance(v, float):
        return f"{v:.4g}"
    return html.escape(str(v))


def _params(result, scene) -> str:
    """The run's params that differ from the scene's and its method's defaults."""
    try:
        method_params = scene.method(result.method).params
    except InputError:  # a method the scene no longer offers: show everything
        method_params = ()
    defaults = {p.name: p.default for p in tuple(scene.params) + tuple(method_params)}
    shown = {k: v for k, v in result.params.items() if defaults.get(k, object()) != v}
    return ", ".join(f"{k}={_num(v)}" for k, v in shown.items()) or "defaults"


#: at most this many metric columns in a scene's compact table (the rest are folded)
KEY_METRICS = 4


def key_metrics(scene, results) -> list[str]:
    """The compact table's metric columns: the headline error, the metrics the paper
    prints for this scene, then the scene's first metrics; at most :data:`KEY_METRICS`."""
    present = []
    for r in results:
        for k in r.metrics:
            if k not in present:
                present.append(k)
    wanted = [headline(scene)] + [p.metric for p in scene.published] + present
    out = []
    for m in wanted:
        if m in present and m not in out:
            out.append(m)
    return out[:KEY_METRICS]


def _metric_cell(scene, r, m) -> str:
    paper = scene.published_for(r.method, r.params)
    cell = _num(r.metrics.get(m, ""))
    if m in paper:
        cell += (f'<br><small title="{html.escape(paper[m].source)}">paper: '
                 f"{_num(paper[m].value)}</small>")
    return f"<td>{cell}</td>"


def _status(r) -> str:
    status = r.status if r.status == "ok" else f"failed: {html.escape(r.message)}"
    return status + "".join(f'<br><small class="warning">warning: {html.escape(w)}</small>'
                            for w in r.warnings)


def _table(scene, results, metrics, full: bool) -> str:
    """One row per run: method, params that differ, status, then ``metrics`` as columns
    and the total time (setup and solve on hover); ``full``: every metric of the run in
    one wrapped cell, then setup, solve and total time and the size (so that a scene with
    twenty metrics still fits the page)."""
    if full:
        head = ("<tr><th class=l>method</th><th class=l>params</th><th class=l>status</th>"
                "<th class=l>metrics</th><th>setup s</th><th>solve s</th><th>total s</th>"
                "<th class=l>size</th></tr>")
    else:
        head = ("<tr><th class=l>method</th><th class=l>params</th><th class=l>status</th>"
                + "".join(f"<th>{html.escape(m)}</th>" for m in metrics) + "<th>total s</th></tr>")
    rows = []
    for r in results:
        t = r.timings
        if full:
            size = ", ".join(f"{k} {v}" for k, v in r.size.items())
            values = "<br>".join(f"{html.escape(k)} = {_num(v)}" for k, v in r.metrics.items())
            cells = (f'<td class="l m">{values}</td>'
                     f"<td>{t.get('setup_s', 0):.3g}</td><td>{t.get('solve_s', 0):.3g}"
                     f"{_solver_note(r.diagnostics)}</td><td>{t.get('total_s', 0):.3g}</td>"
                     f'<td class="l p">{html.escape(size)}</td>')
        else:
            cells = ("".join(_metric_cell(scene, r, m) for m in metrics)
                     + f'<td title="setup {t.get("setup_s", 0):.3g} s, solve '
                     f'{t.get("solve_s", 0):.3g} s">{t.get("total_s", 0):.3g}'
                     f"{_solver_note(r.diagnostics)}</td>")
        cls = "" if r.status == "ok" else ' class="failed"'
        rows.append(f"<tr{cls}><td class=l>{html.escape(r.method)}</td>"
                    f'<td class="l p">{_params(r, scene)}</td><td class="l s">{_status(r)}</td>'
                    f"{cells}</tr>")
    return f"<table>{head}{''.join(rows)}</table>"


def scene_section(scene, results, figures, deviations=None) -> str:
    """A scene's section; ``deviations``: default those of :mod:`pdverify.deviations`."""
    if deviations is None:
        from ..deviations import for_scene
        deviations = for_scene(scene.id)
    paper = PAPERS.get(seed_of(scene.seed), {})
    cite = (f"{paper['authors']} ({paper['year'] or 'n.d.'})" if paper else "")
    parts = [f'<h2 id="{scene.id}">{html.escape(scene.id)}: {html.escape(scene.title)}</h2>',
             f"<p>Seed {html.escape(scene.seed)} ({html.escape(cite)}); reference: "
             f"<b>{scene.reference}</b>; headline error <code>{headline(scene)}</code>.</p>"]
    if deviations:
        items = "".join(f"<li><b>{html.escape(d.kind)}</b>: {html.escape(d.text)} "
                        f"<small>({html.escape(d.source)})</small></li>" for d in deviations)
        parts.append(f'<div class="dev"><b>Deviations from the paper</b><ul>{items}</ul></div>')
    parts.append(f'<details><summary>What is implemented and every choice</summary>'
                 f'<div class="doc">{html.escape((type(scene).__doc__ or "").strip())}</div>'
                 "</details>")
    metrics = key_metrics(scene, results)
    parts.append(_table(scene, results, metrics, full=False))
    parts.append("<details><summary>Every metric, setup and solve time and size of each run"
                 f"</summary>{_table(scene, results, (), full=True)}</details>")
    for r in results:
        if r.fields.get("refinement"):
            parts.append(refinement_table(r))
    sources = sorted({p.source for p in scene.published})
    if sources:
        parts.append("<p><small>paper values from: " + "; ".join(map(html.escape, sources))
                     + "</small></p>")
    parts.append(figure_list(figures))
    return "\n".join(parts)


def convergence_section(studies, figures) -> str:
    """A scene's convergence studies: one row per method, its rate in each study, the
    errors of the coarsest and finest levels, the figure beneath."""
    if not studies:
        return ""
    kinds = [k for k in ("delta", "m") if any(s["study"] == k for s in studies)]
    fixed = {k: next(s["fixed"] for s in studies if s["study"] == k) for k in kinds}
    head = ("<tr><th class=l>method</th>" + "".join(
        f"<th>{k}-refinement rate<br><small>fixed {html.escape(fixed[k])}</small></th>"
        f"<th class=l>errors, coarsest &rarr; finest</th>" for k in kinds) + "</tr>")
    rows = []
    for method in dict.fromkeys(s["method"] for s in studies):
        cells = []
        for k in kinds:
            e = next((s for s in studies if s["method"] == method and s["study"] == k), None)
            if e is None:
                cells.append("<td></td><td></td>")
                continue
            rate = (f"{e['rate']:.2f}" if e["rate"] is not None
                    else f"<small>{html.escape(e['note'])}</small>")
            errs = " &rarr; ".join("failed" if lv["error"] is None else f"{lv['error']:.3g}"
                                   for lv in e["levels"])
            cells.append(f"<td>{rate}</td><td class=l><small>{errs}</small></td>")
        rows.append(f"<tr><td class=l>{html.escape(method)}</td>{''.join(cells)}</tr>")
    levels = "; ".join(
        f"{k}: " + ", ".join(f"h={lv['h']:.4g} (spacing {lv['spacing']:.4g}, m {lv['m_ratio']:g})"
                             for lv in next(s for s in studies if s["study"] == k)["levels"])
        for k in kinds)
    figs = figure_list(figures)
    return (f'<h3 id="{studies[0]["scene"]}-convergence">Convergence of every method</h3>'
            f"<p><small>Rate p of {html.escape(studies[0]['metric'])} ~ h^p by least squares "
            f"over the levels ({html.escape(levels)}); h is the horizon for the "
            "delta-refinement and the grid spacing for the m-refinement. The levels are "
            "ordinary runs in results.json; the rates are under <code>convergence</code>."
            f"</small></p><table>{head}{''.join(rows)}</table>{figs}")


def figure_list(figures) -> str:
    """``(file, caption)`` pairs of ``figures/`` as HTML figures."""
    return "".join(f'<figure><img src="figures/{name}" style="max-width:100%">'
                   f"<figcaption>{html.escape(caption)}</figcaption></figure>"
                   for name, caption in figures)


def _solver_note(diagnostics) -> str:
    """The linear solver a run used, as a short tag under its solve time (the full name,
    and CG's iteration count, on hover)."""
    solver = diagnostics.get("solver") if isinstance(diagnostics, dict) else None
    if not isinstance(solver, str):
        return ""
    its = diagnostics.get("iterations")
    if solver.startswith("CG"):
        tag = f"CG {its} it" if isinstance(its, int) else "CG"
    elif solver.startswith("dense"):
        tag = "dense LU"
    elif "nested-dissection" in solver:
        tag = "LU, ND"
    else:
        tag = "LU"
    return f'<br><small title="{html.escape(solver)}">{tag}</small>'


def refinement_table(result) -> str:
    """The refinement study of a reference run: one row per level, coarsest first."""
    rows = result.fields["refinement"]
    extra = sorted({k for row in rows for k in row.get("extra", {})})
    head = ("<tr><th>level</th><th>dofs</th><th>h_min</th>"
            f"<th>{html.escape(result.fields.get('quantity_name', 'quantity'))}</th>"
            "<th>change %</th><th>setup s</th><th>solve s</th>"
            + "".join(f"<th>{html.escape(k)}</th>" for k in extra) + "</tr>")
    body = "".join(
        f"<tr><td>{row['level']}</td><td>{row['dofs']}</td><td>{_num(row['h_min'])}</td>"
        f"<td>{row['quantity']:.8g}</td><td>{_num(row['change_pct'])}</td>"
        f"<td>{_num(row['setup_s'])}</td><td>{_num(row['solve_s'])}</td>"
        + "".join(f"<td>{_num(row.get('extra', {}).get(k, ''))}</td>" for k in extra) + "</tr>"
        for row in rows)
    return (f"<p><b>Refinement study</b> ({html.escape(result.method)}):</p>"
            f'<div class="wide"><table>{head}{body}</table></div>')


_LOG_RANGE = (-8.0, 0.0)  # colour scale of the overview: 1e-8 (green) .. 1 (red)


def _colour(value: float) -> str:
    """Green (1e-8 or less) to red (1 or more), on a log scale of ``abs(value)``."""
    lo, hi = _LOG_RANGE
    v = abs(value)
    bad = 0.0 if v == 0 else (min(max(math.log10(v), lo), hi) - lo) / (hi - lo)
    return f"rgb({int(150 + 100 * bad)},{int(235 - 85 * bad)},150)"


def overview(scenes, results) -> str:
    """Scene x method matrix: each cell the headline error of the method's default run
    (coloured on a log scale, total time beneath), the best method per scene starred,
    failed runs red with the reason on hover, FEM cells marked as the reference."""
    from ..listing import method_columns
    methods = method_columns(scenes)
    # method names break at their hyphens so that ~15 columns fit a 1400 px screen
    head = "<tr><th class=l>scene<br><small>headline error</small></th>" + "".join(
        f"<th>{html.escape(m).replace('-', '-<wbr>')}</th>" for m in methods) + "</tr>"
    rows = []
    for scene in scenes:
        runs = [r for r in results if r.scene == scene.id]
        metric = headline(scene)
        picked = {m: default_run(scene, m, runs) for m in methods}
        values = {m: r.metrics[metric] for m, r in picked.items()
                  if r is not None and headline_value(scene, r) is not None}
        best = summarise(scene, runs).best
        cells = []
        for m in methods:
            r = picked[m]
            if r is None:
                cells.append("<td></td>")
            elif r.status != "ok":
                cells.append(f'<td class="failed" title="{html.escape(r.message)}">failed</td>')
            elif m == "fem":
                cells.append(f'<td title="the scene\'s FEM reference">ref.<br><small>'
                             f"{r.timings.get('total_s', 0):.2g} s"
                             "</small></td>")
            elif m in values:
                star = " &#9733;" if m == best else ""
                pct = metric.endswith("_pct")      # a percentage: coloured as a fraction
                cells.append(f'<td style="background:{_colour(values[m] / (100 if pct else 1))}" '
                             f'title="{html.escape(_params(r, scene))}">'
                             f"{float(values[m]):.3g}{' %' if pct else ''}{star}<br><small>"
                             f"{r.timings.get('total_s', 0):.2g} s</small></td>")
            else:
                cells.append("<td>&ndash;</td>")
        rows.append(f'<tr><td class=l><a href="#{scene.id}">{html.escape(scene.id)}</a><br>'
                    f"<small><code>{html.escape(metric)}</code></small></td>{''.join(cells)}</tr>")
    return ("<h3>Overview: error and cost of each method at its default parameters</h3>"
            "<p><small>Each cell: the scene's headline error for the method's run at its "
            "default parameters (green 1e-8 to red 1, log scale), the total time beneath; "
            "&#9733; the most accurate method of the scene; hover a cell for its parameters "
            "or a failure's reason. Sweeps and variants are in each scene's table.</small>"
            f'</p><div class="wide"><table>{head}{"".join(rows)}</table></div>')


def papers(scenes) -> str:
    """The seed papers the report's scenes come from, with the scenes of each."""
    items = []
    for key, p in PAPERS.items():
        ids = [s.id for s in scenes if seed_of(s.seed) == key]
        if not ids:
            continue
        doi = (f'<a href="https://doi.org/{html.escape(p["doi"])}">doi:{html.escape(p["doi"])}'
               "</a>" if p["doi"] else "DOI not printed in the seed text")
        venue = f", <i>{html.escape(p['venue'])}</i>" if p["venue"] else ""
        items.append(f"<li>[{key}] {html.escape(p['authors'])} ({p['year'] or 'n.d.'}). "
                     f"{html.escape(p['title'])}{venue}. {doi}. <small>Scenes: "
                     + ", ".join(f'<a href="#{i}">{i}</a>' for i in ids) + "</small></li>")
    return f"<h3>Papers</h3><ol>{''.join(items)}</ol>" if items else ""


def page(doc: dict, sections: list[tuple], total_time: float, results=None,
         front_figures=()) -> str:
    runs = doc["runs"]
    failed = [r for r in runs if r["status"] != "ok"]
    warned = sum(1 for r in runs if r.get("warnings"))
    methods = sorted({r["method"] for r in runs})
    toc = "".join(f'<li><a href="#{s.id}">{html.escape(s.id)}</a> — {html.escape(s.title)}</li>'
                  for s, _ in sections)
    legend = "".join(f"<li><code>{html.escape(m)}</code>: {html.escape(describe(m))}</li>"
                     for m in methods)
    body = "\n".join(text for _, text in sections)
    figs = figure_list(front_figures)
    return f"""<!doctype html><html><head><meta charset="utf-8"><title>pdverify report</title>
<style>{CSS}</style></head><body>
<h1>pdverify report</h1>
<p>pdverify {html.escape(doc['pdverify_version'])}, created {html.escape(doc['created'])},
Python {html.escape(str(doc['machine']['python']))} on {doc['machine']['cpus']} CPUs.
{len(runs)} runs, {len(failed)} failed, {warned} ok with a warning, {total_time:.1f} s in all. Machine-readable:
<a href="results.json">results.json</a> (schema <code>{html.escape(doc['schema'])}</code>).</p>
<p>Each scene's table lists one run per row: the method, the parameters that differ from
the scene's defaults (the paper's values), the status, the headline error and the metrics
the paper prints (the paper's number beneath), and the total time (setup and solve on
hover). Every metric, time and size of every run is in the folded table beneath it.</p>
{overview([s for s, _ in sections], results) if results is not None else ""}
{figs}
{papers([s for s, _ in sections])}
<h3>Methods</h3><ul>{legend}</ul>
<h3>Scenes</h3><ul>{toc}</ul>
{body}
</body></html>
"""
