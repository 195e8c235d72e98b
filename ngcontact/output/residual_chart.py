"""The solver's residual history of a run as an inline SVG chart for ``report.html``.

Every record of the report's ``solver`` entry that holds a ``residuals`` list is one series; the chart
draws ``log10`` of each residual against its step (non-positive values left out), one colour per solve.
"""
from __future__ import annotations

import html
import math

#: residual series drawn in the solver chart
MAX_SERIES = 40

COLOURS = ("#1f77b4", "#d62728", "#2ca02c", "#9467bd", "#ff7f0e", "#8c564b", "#17becf")


def _e(x) -> str:
    return html.escape(str(x))


def residual_series(solver, label: str = "") -> list[tuple[str, dict]]:
    """Every record of the solver entry holding a ``residuals`` list, labelled by its place."""
    found = []
    if isinstance(solver, dict):
        if isinstance(solver.get("residuals"), list) and solver["residuals"]:
            found.append((label or "all solves", solver))
        for k, v in solver.items():
            if isinstance(v, (dict, list)) and k != "residuals":
                found += residual_series(v, f"{label}.{k}" if label else k)
    elif isinstance(solver, list):
        for i, v in enumerate(solver):
            found += residual_series(v, f"{label}[{i}]")
    return found


def residual_chart(series: list[tuple[str, list[float]]], width: int = 640, height: int = 240) -> str:
    """log10 of each residual series against the step, as an inline SVG (non-positive values left out)."""
    pts = [(name, [(i, math.log10(r)) for i, r in enumerate(res) if isinstance(r, (int, float)) and r > 0])
           for name, res in series[:MAX_SERIES]]
    pts = [(n, p) for n, p in pts if p]
    if not pts:
        return ""
    xmax = max(1, max(i for _, p in pts for i, _ in p))
    ys = [y for _, p in pts for _, y in p]
    ylo, yhi = math.floor(min(ys)), math.ceil(max(ys))
    yhi = yhi if yhi > ylo else ylo + 1
    left, bottom = 50, 30

    def xy(i, y):
        return (left + (width - left - 10) * i / xmax, 10 + (height - bottom - 10) * (yhi - y) / (yhi - ylo))

    out = [f'<svg xmlns="http://www.w3.org/2000/svg" width="{width}" height="{height}" role="img" '
           f'aria-label="residual history"><rect width="100%" height="100%" fill="white"/>']
    step = max(1, (yhi - ylo) // 6)
    for e in range(ylo, yhi + 1, step):
        _, y = xy(0, e)
        out.append(f'<line x1="{left}" x2="{width - 10}" y1="{y:.1f}" y2="{y:.1f}" stroke="#eee"/>'
                   f'<text x="{left - 4}" y="{y + 4:.1f}" font-size="11" text-anchor="end">1e{e}</text>')
    out.append(f'<text x="{(width + left) / 2}" y="{height - 6}" font-size="11" text-anchor="middle">'
               f'step (0 = start)</text>')
    for k, (name, p) in enumerate(pts):
        line = " ".join("%.1f,%.1f" % xy(i, y) for i, y in p)
        out.append(f'<polyline fill="none" stroke="{COLOURS[k % len(COLOURS)]}" stroke-width="1.5" '
                   f'points="{line}"><title>{_e(name)}</title></polyline>')
    legend = "".join(f'<span style="color:{COLOURS[k % len(COLOURS)]}">\u25a0</span> {_e(n)} '
                     for k, (n, _) in enumerate(pts[:8]))
    more = f" \u2026 ({len(pts)} solves; the colours repeat in the order of the table)" if len(pts) > 8 else ""
    return "".join(out) + f'</svg><p class="meta">{legend}{more}</p>'
