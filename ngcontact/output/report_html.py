"""``report.html``: a run's report as one self-contained page for a person to look at.

Built from the report dictionary (:func:`ngcontact.output.report.build_report`) and the files the run
staged beside it: the scene's title and effects, the key figures (picked generically from the report,
plus a few per kind: the law, contact fraction, peak pressure, safety factor), the solver history
(residuals per solve, drawn as an inline SVG), every PNG embedded as a base64 data URI, every CSV table as
an HTML table, the results, timings and the scene itself.  No network, no script: CSS is inline, other
files (VTK, NumPy) are linked relatively.  Every number passes :func:`fmt`, which refuses NaN and infinity
as the report does.
"""
from __future__ import annotations

import base64
import csv
import html
import itertools
import math
import os

from ngcontact.output.residual_chart import MAX_SERIES, residual_chart, residual_series

#: rows of a CSV table shown on the page (the file holds them all)
MAX_TABLE_ROWS = 400
#: a list longer than this is summarized (count, smallest, largest) instead of listed
MAX_INLINE = 12
_PREFIXES = ((1e9, "G"), (1e6, "M"), (1e3, "k"), (1.0, ""), (1e-3, "m"), (1e-6, "\u00b5"), (1e-9, "n"))

#: kind -> (label, dotted path into the report, SI unit or "") shown first when present
HIGHLIGHTS: dict[str, list[tuple[str, str, str]]] = {
    "macro": [
        ("law", "results.law.type", ""),
        ("law from cell", "results.law.cell_scene", ""),
        ("full-contact stiffness K0", "results.law.full_contact_K0", "Pa/m"),
        ("peak pressure", "results.maxima.pressure.pressure", "Pa"),
        ("at s", "results.maxima.pressure.s", "m"),
        ("peak shear", "results.maxima.shear.shear", "Pa"),
        ("contact area share", "results.contact_area", ""),
        ("interface resultant", "results.resultant", "N"),
        ("largest von Mises stress", "results.maxima.von_mises.max.value", "Pa"),
        ("in body", "results.maxima.von_mises.max.body", ""),
        ("safety factor (eq. 78)", "results.strength.safety_factor", ""),
        ("strength holds", "results.strength.holds", ""),
        ("critical body", "results.strength.critical_body", ""),
        ("two-scale converged", "results.two_scale.converged", ""),
        ("two-scale iterations", "results.two_scale.iterations", ""),
        ("cell solves", "results.two_scale.cell_solves", ""),
        ("loop cell method", "results.two_scale.cell.method_choice", ""),
        ("equilibrium error", "results.equilibrium.error", ""),
        ("Newton iterations", "results.newton_iterations", ""),
        ("Coulomb friction solved by", "solver.coulomb.method", ""),
        ("Coulomb passes (fixed point)", "results.coulomb_iterations", ""),
    ],
    "cell": [
        ("cell method", "results.accuracy.method.statement", ""),
        ("cell symmetry", "results.accuracy.symmetry.statement", ""),
        ("method", "results.method.name", ""),
        ("whole-surface k_n", "results.whole_surface.k_n", ""),
        ("whole-surface k_t", "results.whole_surface.k_t", ""),
        ("whole-surface k_nt", "results.whole_surface.k_nt", ""),
        ("whole-surface g_n", "results.whole_surface.g_n", ""),
        ("mu = k_nt / k_n", "results.whole_surface.mu", ""),
        ("|S_C| / |T|", "results.whole_surface.contact_fraction", ""),
    ],
    "manufactured": [
        ("verified", "results.verified", ""),
        ("verdict", "results.verdict", ""),
        ("largest rate deviation", "results.max_rate_deviation", ""),
        ("admissible deviation", "results.rate_tolerance", ""),
    ],
    "direct": [
        ("periods N", "results.periods", ""),
        ("period eps", "results.eps", "m"),
        ("contact fraction", "results.contact_fraction", ""),
        ("contact force", "results.contact_force", "N"),
        ("Newton iterations", "results.newton_iterations", ""),
    ],
    "direct-epsilon-study": [
        (f"{law} law: {err} error < 1 % from eps", f"results.below_1_percent.{law}.{err}.eps", "m")
        for law in ("bundle", "linear", "effective") for err in ("field", "reaction")
    ] + [(f"{law} law: rate of the field error in eps", f"results.rates.{law}.field", "")
         for law in ("bundle", "linear", "effective")],
    "accuracy-study": [
        ("target", "results.target.statement", ""),
        ("distinct runs", "results.distinct_runs", ""),
        ("wall time of every level", "results.seconds_all_levels", "s"),
        ("wall time of the scene's own level", "results.seconds_own_scene", "s"),
    ],
}
#: per-load columns of a cell's law table (the pressure-closure curve and its contact set)
LOAD_COLUMNS = ("mean_pressure", "transmitted_pressure", "max_pressure", "contact_fraction", "mean_closure",
                "max_penetration", "slip_fraction", "newton_iterations", "iterations")

CSS = """
body{font-family:system-ui,sans-serif;margin:1.5em auto;max-width:1200px;padding:0 1em;color:#222}
h1{font-size:1.5em;margin-bottom:.2em} h2{border-bottom:1px solid #ccc;margin-top:1.6em}
.meta{color:#555} .chip{display:inline-block;background:#e8eef7;border-radius:1em;padding:.1em .7em;margin:.15em}
.cards{display:grid;grid-template-columns:repeat(auto-fill,minmax(210px,1fr));gap:.6em}
.card{border:1px solid #ddd;border-radius:6px;padding:.5em .7em;background:#fafafa}
.card .label{font-size:.8em;color:#666} .card .value{font-size:1.15em;font-weight:600;word-break:break-word}
.warn{background:#fff3cd;border:1px solid #e0c060;padding:.5em 1em;border-radius:6px}
figure{margin:1em 0;text-align:center} figure img{max-width:100%;border:1px solid #eee}
figcaption{color:#555;font-size:.9em}
table{border-collapse:collapse;font-size:.85em;margin:.4em 0}
td,th{border:1px solid #ddd;padding:.15em .5em;text-align:right;vertical-align:top}
table table{font-size:1em} th{background:#f0f0f0} td.k{text-align:left;font-weight:600;background:#fafafa}
.scroll{max-height:28em;overflow:auto;display:inline-block;max-width:100%}
details{margin:.4em 0} summary{cursor:pointer}
"""


# ------------------------------------------------------------------ values
def fmt(x, unit: str = "") -> str:
    """One value as text: 5 significant digits, SI prefixes for a unit; NaN and infinity are refused."""
    if x is None:
        return "\u2013"
    if isinstance(x, bool):
        return "yes" if x else "no"
    if isinstance(x, int) and not unit:
        return str(x)
    if isinstance(x, (int, float)):
        x = float(x)
        if not math.isfinite(x):
            raise ValueError(f"report.html: non-finite number {x}")
        if unit and x != 0.0:
            for scale, prefix in _PREFIXES:
                if abs(x) >= scale * 0.9999995:
                    return f"{x / scale:.4g} {prefix}{unit}"
        return f"{x:.5g} {unit}".strip()
    if isinstance(x, list):
        if x and all(isinstance(r, list) for r in x):
            return "[" + "; ".join(", ".join(fmt(v) for v in r) for r in x) + "]" + (f" {unit}" if unit else "")
        return "(" + ", ".join(fmt(v, unit) for v in x) + ")"
    if isinstance(x, dict):
        return ", ".join(f"{k} = {fmt(v, unit)}" for k, v in x.items())
    return str(x)


def _cell_text(text: str) -> str:
    """A CSV cell: numbers formatted like the report's, words as they are."""
    try:
        value = float(text)
    except ValueError:
        return text
    return fmt(int(value) if text.strip().lstrip("-").isdigit() else value)


def _get(report: dict, path: str):
    node = report
    for part in path.split("."):
        if not isinstance(node, dict) or part not in node:
            return None
        node = node[part]
    return node


def _is_scalar(x) -> bool:
    return x is None or isinstance(x, (bool, int, float, str))


def _e(x) -> str:
    return html.escape(str(x))


# ------------------------------------------------------------------ blocks
def _cards(items: list[tuple[str, str]]) -> str:
    return '<div class="cards">' + "".join(
        f'<div class="card"><div class="label">{_e(label)}</div><div class="value figure-value">{_e(value)}'
        f"</div></div>" for label, value in items) + "</div>"


def key_figures(report: dict) -> list[tuple[str, str]]:
    """(label, formatted value) of the figures an engineer looks at first, kind-specific ones first."""
    items = []
    shown = set()
    per_metre = _get(report, "results.setting") == "plane_strain"   # forces of a plane-strain run are per metre
    for label, path, unit in HIGHLIGHTS.get(report.get("kind", ""), []):
        value = _get(report, path)
        unit = "N/m" if unit == "N" and per_metre else unit
        if value is not None and value != []:
            items.append((label, fmt(value, unit)))
            shown.add(path.split(".")[1] if path.startswith("results.") else path)
    counts = _get(report, "results.status_counts")
    if isinstance(counts, dict) and sum(counts.values()) > 0:
        closed = sum(v for k, v in counts.items() if k != "open")
        items.append(("closed interface samples", f"{closed} of {sum(counts.values())} "
                                                  f"({fmt(closed / sum(counts.values()))})"))
    for key, value in (report.get("results") or {}).items():   # every other top-level scalar result
        if key not in shown and _is_scalar(value) and not (isinstance(value, str) and len(value) > 60):
            items.append((key.replace("_", " "), fmt(value)))
    solver = report.get("solver") or {}
    generic = [("unknowns (ndof)", report.get("ndof"), ""), ("solver iterations", solver.get("iterations"), ""),
               ("solver converged", solver.get("converged"), ""),
               ("wall time", (report.get("timings") or {}).get("total"), "s"), ("threads", report.get("threads"), "")]
    return items + [(label, fmt(value, unit)) for label, value, unit in generic if value is not None] + compute_items(
        report.get("compute"))


def compute_items(compute: dict | None) -> list[tuple[str, str]]:
    """Where the run's batches of independent solves ran (nothing when it had none)."""
    if not compute or not compute.get("batches"):
        return []
    where = {"serial": "this process", "local": f"{compute['workers']} local worker processes",
             "dask": f"{compute['workers']} Dask worker threads at {compute.get('scheduler', '?')}"}
    here = {"serial": " (in this process)", "local": " (on the workers)"}
    batches = "; ".join(f"{b['label']}: {b['members']} in {fmt(b['seconds'], 's')}{here.get(b.get('executor'), '')}"
                        for b in compute["batches"])
    items = [("batches ran on", where.get(compute["executor"], str(compute["executor"]))), ("batches", batches)]
    decisions = "; ".join(f"{b['label']}: {b['decision']}" for b in compute["batches"] if b.get("decision"))
    return items + ([("why there", decisions)] if decisions else [])


def html_table(header: list[str], rows: list[list[str]], cls: str = "") -> str:
    """A table of already formatted cells."""
    head = "".join(f"<th>{_e(h)}</th>" for h in header)
    body = "".join("<tr>" + "".join(f"<td>{_e(c)}</td>" for c in r) + "</tr>" for r in rows)
    return f'<div class="scroll"><table class="{cls}"><thead><tr>{head}</tr></thead><tbody>{body}</tbody></table></div>'


def _rows_table(items: list[dict], columns=None) -> str:
    """A list of records as a table of their scalar (or short list) fields."""
    keys: list[str] = []
    for it in items:
        keys += [k for k, v in it.items() if k not in keys and (columns is None or k in columns)
                 and (_is_scalar(v) or (isinstance(v, list) and len(v) <= 3 and all(map(_is_scalar, v))))]
    if columns is not None:
        keys = [c for c in columns if c in keys]
    return html_table(["#"] + keys, [[str(i)] + [fmt(it.get(k)) for k in keys] for i, it in enumerate(items)])


def kind_tables(report: dict) -> str:
    """Tables of the key figures: a cell's law per load (pressure-closure curve, contact set), a two-scale history."""
    loads = _get(report, "results.loads")
    history = _get(report, "results.two_scale.history")
    parts = []
    if report.get("kind") == "cell" and isinstance(loads, list) and loads:
        parts.append("<h3>Law per load</h3>" + _rows_table(loads, LOAD_COLUMNS))
    if report.get("kind") == "accuracy-study":
        parts.append(study_tables(report))
    if report.get("kind") in ("macro", "cell"):
        parts.append(accuracy_table(report))
    if isinstance(history, list) and history:
        parts.append("<h3>Two-scale iterations (max_change: largest pressure change over the interface)</h3>"
                     + _rows_table(history))
    return "".join(parts)


def accuracy_table(report: dict) -> str:
    """A run's accuracy verdict as a table: per quantity (a cell's per load) its value, estimated relative error
    (or that it is mesh dependent), whether the verdict counts it, where a macro run attains it, and beside it
    the estimator's statement that the estimate may exceed the error by more than ten times (``loose``); the
    balls the maxima away from the singular points are taken outside of."""
    acc = _get(report, "results.accuracy") or {}
    quantities = [q for q in acc.get("quantities", []) if isinstance(q, dict)] if isinstance(acc, dict) else []
    if not quantities:
        return ""
    macro, loose = report.get("kind") == "macro", any(q.get("loose") for q in quantities)
    rows = [[(f"load {q['load']}, " if q.get("load") is not None else "") + str(q.get("name")), fmt(q.get("value")),
             "mesh dependent, singular at " + fmt(q["singular_at"]) if q.get("singular_at") is not None
             else fmt(q.get("relative_error")), fmt(q.get("counted", True))]
            + [fmt(q.get("location"))] * macro + [q.get("loose") or ""] * loose for q in quantities]
    ex = acc.get("exclusion") or {}
    note = (f"<p>*_away: outside {fmt(ex.get('radius'), 'm')} of the singular points {fmt(ex.get('points'))} "
            f"({_e(', '.join(ex.get('why', [])))}); the mesh-dependent maxima are listed, not counted.</p>"
            if ex.get("points") else "") + _edges_note(ex)
    return ("<h3>Accuracy (met: " + fmt(acc.get("met")) + ")</h3>" + note
            + html_table(["quantity", "value", "relative error", "counted"] + ["at"] * macro
                         + ["loose: may exceed the error by more than 10 times"] * loose, rows))


def _edges_note(ex: dict) -> str:
    """The singular edges of a 3D run's verdict (``accuracy.exclusion.edges``): per curve why, length, ends."""
    curves = [c for c in ex.get("edges") or [] if isinstance(c, dict)]
    if not curves:
        return ""
    rows = [[str(c.get("why")), fmt(c.get("length")), fmt(c.get("segments")), fmt(c.get("ends"))] for c in curves]
    return (f"<p>*_away: outside a tube of radius {fmt(ex.get('radius'), 'm')} around the singular edges; the "
            "mesh-dependent maxima are listed, not counted.</p>"
            + html_table(["singular edge", "length [m]", "segments", "ends"], rows))


def nested(value, depth: int = 0) -> str:
    """Any report value as HTML: dicts as key tables, records as tables, long arrays summarized."""
    if _is_scalar(value):
        return _e(fmt(value))
    if isinstance(value, dict):
        if not value:
            return "\u2013"
        rows = "".join(f'<tr><td class="k">{_e(k)}</td><td style="text-align:left">{nested(v, depth + 1)}</td></tr>'
                       for k, v in value.items())
        return f"<table>{rows}</table>"
    if not value:
        return "(none)"
    if all(isinstance(v, dict) for v in value):
        extra = [v for v in value if any(not _is_scalar(x) for x in v.values())]
        parts = [_rows_table(value)]
        if extra and depth < 4:
            parts.append(f"<details><summary>all fields of the {len(value)} entries</summary>"
                         + "".join(f"<details><summary>[{i}]</summary>{nested(v, depth + 1)}</details>"
                                   for i, v in enumerate(value)) + "</details>")
        return "".join(parts)
    if all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in value) and len(value) > MAX_INLINE:
        return _e(f"{len(value)} values from {fmt(min(value))} to {fmt(max(value))}")
    if all(isinstance(v, str) for v in value) and len(value) > MAX_INLINE:
        counts: dict[str, int] = {}
        for v in value:
            counts[v] = counts.get(v, 0) + 1
        return _e(f"{len(value)} entries: " + ", ".join(f"{k} \u00d7 {n}" for k, n in counts.items()))
    if all(isinstance(v, list) for v in value) and len(value) > MAX_INLINE:
        return _e(f"{len(value)} entries of {min(map(len, value))} to {max(map(len, value))} values")
    if all(_is_scalar(v) for v in value) or all(isinstance(v, list) and len(v) <= MAX_INLINE for v in value):
        return _e(fmt(value))
    return "<ol start=0>" + "".join(f"<li>{nested(v, depth + 1)}</li>" for v in value) + "</ol>"


# ------------------------------------------------------------------ solver history
def solver_section(solver: dict) -> str:
    """Summary of the solver entry, its residual history as a chart and a table per solve."""
    if not solver:
        return ""
    summary = {k: v for k, v in solver.items() if _is_scalar(v) or (isinstance(v, dict) and
                                                                    all(map(_is_scalar, v.values())))}
    parts = ["<h2>Solver</h2>", nested(summary)]
    series = residual_series(solver)
    if series:
        parts.append(residual_chart([(n, s["residuals"]) for n, s in series]))
        rows = [[name, fmt(s.get("iterations", len(s["residuals"]) - 1)), fmt(s.get("converged")),
                 fmt(s["residuals"][0]), fmt(s["residuals"][-1]), str(len(s["residuals"]))] for name, s in series]
        parts.append(html_table(["solve", "iterations", "converged", "first residual", "last residual",
                                 "residuals"], rows))
        if len(series) > MAX_SERIES:
            parts.append(f"<p>The chart draws the first {MAX_SERIES} of {len(series)} solves.</p>")
    for key in ("coulomb_changes",):
        if isinstance(solver.get(key), list) and solver[key]:
            parts.append(f"<p><b>{_e(key)}</b>: {_e(fmt(solver[key]))}</p>")
    return "".join(parts)


def study_tables(report: dict) -> str:
    """An accuracy study's section: per level its largest error, time and unknowns; per knob its rates."""
    levels = _get(report, "results.levels") or []
    rows = []
    for r in levels:
        qs = r.get("quantities") or {}
        worst = max(((q.get("error") or 0.0) + (q.get("error_other_knobs") or 0.0) for q in qs.values()),
                    default=None)
        rows.append([r.get("knob"), r.get("setting"), "reference" if r.get("reference") else
                     ("the scene" if r.get("own_scene") else ""), fmt(r.get("seconds"), "s"), fmt(r.get("ndof")),
                     r.get("failed") or fmt(worst)])
    rates = _get(report, "results.rates") or {}
    rate_rows = [[k, v.get("variable"), name, fmt(rate)] for k, v in rates.items()
                 for name, rate in (v.get("rates") or {}).items()]
    return ("<h2>Accuracy study</h2><p>" + _e(_get(report, "results.reference") or "") + "</p>"
            + html_table(["knob", "level", "", "wall time", "unknowns", "largest error (all knobs)"], rows)
            + "<h3>Observed rates (error ~ x^rate)</h3>" + html_table(["knob", "x", "quantity", "rate"], rate_rows))


# ------------------------------------------------------------------ files
def figure(directory: str, name: str) -> str:
    """One PNG of the run, embedded."""
    with open(os.path.join(directory, name), "rb") as fh:
        data = base64.b64encode(fh.read()).decode("ascii")
    return (f'<figure id="fig-{_e(name)}"><img alt="{_e(name)}" src="data:image/png;base64,{data}">'
            f"<figcaption>{_e(name)}</figcaption></figure>")


def csv_table(directory: str, name: str) -> str:
    """One CSV table of the run as HTML (the first :data:`MAX_TABLE_ROWS` rows; the others only counted)."""
    with open(os.path.join(directory, name), newline="") as fh:
        reader = csv.reader(fh)
        rows = list(itertools.islice(reader, MAX_TABLE_ROWS + 1))
        count = len(rows) - 1 + sum(1 for _ in reader)
    if not rows:
        return ""
    header, body = rows[0], rows[1:]
    note = (f" (the first {MAX_TABLE_ROWS} of {count} rows; all in "
            f'<a href="{_e(name)}">{_e(name)}</a>)' if count > MAX_TABLE_ROWS else
            f' (<a href="{_e(name)}">{_e(name)}</a>, {count} rows)')
    return (f'<h3 id="table-{_e(name)}">{_e(name)}</h3><p>{note}</p>'
            + html_table(header, [[_cell_text(c) for c in r] for r in body[:MAX_TABLE_ROWS]], "csv"))


# ------------------------------------------------------------------ the page
def accuracy_warnings(report: dict) -> list[str]:
    """One line per failed check of the report's accuracy verdict (``results.accuracy``), for the page's top
    (a quantity reported without being held to the tolerance, ``counted = false``, is no failed check)."""
    acc = _get(report, "results.accuracy") or {}
    if not isinstance(acc, dict) or acc.get("met", True):
        return []
    head = f"Accuracy not met (tolerance {fmt(acc.get('tolerance'))}): "
    checks = [f"{head}load {c.get('load')}, {c.get('name')} = {fmt(c.get('value'))} > {fmt(c.get('limit'))}"
              for c in acc.get("checks", []) if isinstance(c, dict) and not c.get("ok", True)]
    shortfall = [head + acc["shortfall"]] if isinstance(acc.get("shortfall"), str) else []
    return checks + [head + quantity_line(q) for q in acc.get("quantities", [])
                     if isinstance(q, dict) and not q.get("met", True) and q.get("counted", True)] + shortfall


def quantity_line(q: dict) -> str:
    """One estimated quantity of an accuracy verdict: its value and relative error, or why it has none."""
    where, rel = (f"load {q['load']}, " if q.get("load") is not None else ""), q.get("relative_error")
    if rel is None:
        return f"{where}{q.get('name')} = {fmt(q.get('value'))} has no error estimate: {q.get('how', '')}"
    return f"{where}{q.get('name')} = {fmt(q.get('value'))}, estimated relative error {fmt(rel)}"


def render(report: dict, directory: str, names: list[str]) -> str:
    """The page of ``report``; ``names`` are the run's files in ``directory`` (PNGs embedded, CSVs tabulated)."""
    title = report.get("title") or "(untitled scene)"
    kind = report.get("kind", "")
    pngs = sorted(n for n in names if n.endswith(".png"))
    csvs = sorted(n for n in names if n.endswith(".csv"))
    effects = "".join(f'<span class="chip">{_e(e)}</span>' for e in report.get("effects", []))
    warnings = list(_get(report, "results.warnings") or []) + accuracy_warnings(report)
    parts = [
        f'<!DOCTYPE html><html lang="en"><head><meta charset="utf-8"><title>{_e(title)}</title>'
        f"<style>{CSS}</style></head><body>",
        f"<h1>{_e(title)}</h1>",
        f'<p class="meta">kind <b>{_e(kind)}</b> \u00b7 ngcontact {_e(report.get("version", ""))} \u00b7 '
        f'{_e(report.get("schema", ""))} \u00b7 <a href="report.json">report.json</a></p>',
        f"<p>Effects: {effects or '(none)'}</p>",
        "".join(f'<p class="warn">{_e(w)}</p>' for w in warnings if isinstance(w, str)),
        "<h2>Key figures</h2>", _cards(key_figures(report)), kind_tables(report),
    ]
    if pngs:
        parts += ["<h2>Figures</h2>"] + [figure(directory, n) for n in pngs]
    parts.append(solver_section(report.get("solver") or {}))
    if csvs:
        parts += ["<h2>Tables</h2>"] + [csv_table(directory, n) for n in csvs]
    parts += ["<h2>Results</h2>", nested(report.get("results") or {}),
              "<h2>Timings</h2>", html_table(["stage", "seconds"], [[k, fmt(v)] for k, v in
                                                                    (report.get("timings") or {}).items()]),
              "<h2>Files</h2><ul>"
              + "".join(f'<li><a href="{_e(n)}">{_e(n)}</a></li>' for n in ["report.json"] + sorted(names))
              + "</ul>",
              "<h2>Scene</h2><details><summary>the validated scene, every default filled in</summary>"
              + nested(report.get("scene") or {}) + "</details>",
              "</body></html>\n"]
    return "\n".join(p for p in parts if p)


def write_html(path: str, report: dict, directory: str, names: list[str]) -> None:
    """Write :func:`render` of ``report`` to ``path`` (UTF-8)."""
    text = render(report, directory, names)
    with open(path, "w", encoding="utf-8") as fh:
        fh.write(text)
