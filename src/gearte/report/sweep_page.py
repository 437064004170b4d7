"""The index page of a parameter sweep (``index.html`` beside ``sweep.csv``).

One self-contained HTML page: what was swept, how many points ran, failed or were skipped as
invalid (each with its reason), every figure (linked to its PNG under ``plots/``), the results
that vary as a table and the ones that are the same at every point as a list.
"""

from __future__ import annotations

import html
import math
from collections.abc import Sequence
from typing import Any

__all__ = ["sweep_index_html"]

_CSS = """
body{font-family:system-ui,-apple-system,"Segoe UI",sans-serif;margin:1.5rem auto;max-width:1200px;
padding:0 1rem;color:#1a1a1a;line-height:1.4}
h1{font-size:1.5rem;margin-bottom:.2rem}h3{font-size:1rem;margin:1rem 0 .3rem}
h2{font-size:1.15rem;margin-top:1.8rem;
border-bottom:1px solid #ddd}
.meta{color:#555}.warn{background:#fff4e5;border-left:4px solid #e69500;padding:.5rem .8rem}
table{border-collapse:collapse;font-size:.85rem;margin:.5rem 0}
th,td{border:1px solid #ddd;padding:.2rem .5rem;text-align:right;vertical-align:top}
th{background:#f3f3f3}td.text,th.text{text-align:left}
tr.invalid td{background:#fdecea}tr.failed td{background:#fff4e5}
figure{display:inline-block;margin:.5rem;vertical-align:top;max-width:100%}
figure img{max-width:100%;border:1px solid #eee}figcaption{font-size:.8rem;color:#444;
max-width:700px}
nav a{margin-right:1rem}
@media print{nav{display:none}figure{break-inside:avoid}}
"""


def _e(x: Any) -> str:
    return html.escape(str(x), quote=True)


def _num(v: Any) -> str:
    if v is None:
        return ""
    if isinstance(v, bool):
        return str(v).lower()
    if isinstance(v, float):
        return "" if math.isnan(v) else f"{v:.6g}"
    if isinstance(v, str):
        from gearte.labels import value_label

        return value_label(v)  # an option or factor name as people read it
    return str(v)


def sweep_index_html(
    result: Any,
    figures: Sequence[tuple[str, str, str]],
    *,
    varying: Sequence[str] | None = None,
    plots: bool = True,
) -> str:
    """The index page of a sweep.

    Parameters
    ----------
    result : SweepResult
        The sweep.
    figures : sequence of (href, title, caption)
        The figures written, ``href`` relative to the page (``plots/x.png``).
    varying : sequence of str, optional
        The results that change over the sweep (table columns); default: every result.
    plots : bool
        Whether figures were asked for (the page says so when they were not).

    Returns
    -------
    str
        The HTML text.
    """
    statuses = result.statuses
    n = len(result.points)
    n_invalid = statuses.count("invalid")
    n_failed = statuses.count("failed")
    cols = list(varying) if varying is not None else list(result.columns)
    constant = [c for c in result.columns if c not in cols]
    out: list[str] = [
        "<!DOCTYPE html><html lang='en'><head><meta charset='utf-8'>",
        f"<title>Sweep: {_e(result.title or result.name)}</title>",
        f"<style>{_CSS}</style></head><body>",
        f"<h1>Sweep of {_e(result.title or result.name)}</h1>",
        f"<p class='meta'>case <code>{_e(result.name)}</code> ({_e(result.kind)}) from "
        f"<code>{_e(result.source)}</code>; varied: "
        + ", ".join(f"<code>{_e(v.key)}</code> ({len(v.values)})" for v in result.vary)
        + f"; {n} points: {statuses.count('ok')} ran, {n_failed} failed, {n_invalid} invalid "
        f"(skipped); {result.elapsed_s:.2f} s on {_e(result.backend)}; seed "
        f"{_e(result.seed if result.seed is not None else 'of the case')}.</p>",
        "<nav><a href='#figures'>Figures</a><a href='#skipped'>Points not run</a>"
        "<a href='#table'>Table</a><a href='#constant'>Constant results</a>"
        "<a href='sweep.csv'>sweep.csv</a><a href='sweep.json'>sweep.json</a></nav>",
    ]
    if result.partial:
        out.append(
            "<p class='warn'>Interrupted: only the points that finished are listed "
            '(<code>"partial": true</code>).</p>'
        )
    if n_invalid or n_failed:
        out.append(
            f"<p class='warn'>{n_invalid} point(s) did not validate and were skipped, "
            f"{n_failed} failed while running: see <a href='#skipped'>Points not run</a>.</p>"
        )

    out.append("<h2 id='figures'>Figures</h2>")
    if figures:
        groups: dict[str, list[tuple[str, str, str]]] = {}
        for fig in figures:  # by analysis: the part of the result name before the first dot
            groups.setdefault(fig[1].split(".", 1)[0], []).append(fig)
        if len(groups) > 1:
            out.append(
                "<p>"
                + " · ".join(
                    f"<a href='#fig-{_e(g)}'>{_e(g)}</a> ({len(v)})" for g, v in groups.items()
                )
                + "</p>"
            )
        for g, figs in groups.items():
            if len(groups) > 1:
                out.append(f"<h3 id='fig-{_e(g)}'>{_e(g)}</h3>")
            for href, title, caption in figs:
                out.append(
                    f"<figure><a href='{_e(href)}'><img src='{_e(href)}' alt='{_e(title)}' "
                    f"loading='lazy'></a><figcaption><b>{_e(title)}</b>. {_e(caption)}"
                    "</figcaption></figure>"
                )
    elif not plots:
        out.append("<p>No figures (written with <code>--no-plots</code>).</p>")
    else:
        out.append("<p>No figures: no result changes over the points that ran.</p>")

    out.append("<h2 id='skipped'>Points not run</h2>")
    bad = [i for i, s in enumerate(statuses) if s != "ok"]
    if bad:
        out.append("<table><tr><th>#</th>")
        out += [f"<th class='text'>{_e(k)}</th>" for k in result.keys]
        out.append("<th class='text'>status</th><th class='text'>reason</th></tr>")
        for i in bad:
            p = result.points[i]
            out.append(f"<tr class='{statuses[i]}'><td>{i}</td>")
            out += [f"<td>{_e(_num(p[k]))}</td>" for k in result.keys]
            out.append(
                f"<td class='text'>{statuses[i]}</td><td class='text'>{_e(result.errors[i])}</td>"
                "</tr>"
            )
        out.append("</table>")
    else:
        out.append("<p>Every point ran.</p>")

    out.append("<h2 id='table'>Results that vary</h2><table><tr><th>#</th>")
    out += [f"<th class='text'>{_e(k)}</th>" for k in result.keys]
    out += [f"<th>{_e(c)}</th>" for c in cols]
    out.append("<th class='text'>status</th></tr>")
    for i, (p, v) in enumerate(zip(result.points, result.values, strict=True)):
        out.append(f"<tr class='{statuses[i]}'><td>{i}</td>")
        out += [f"<td>{_e(_num(p[k]))}</td>" for k in result.keys]
        out += [f"<td>{_e(_num(v.get(c)))}</td>" for c in cols]
        out.append(f"<td class='text'>{statuses[i]}</td></tr>")
    out.append("</table>")

    out.append("<h2 id='constant'>Results the same at every point</h2>")
    if constant:
        first: dict[str, Any] = next((v for v in result.values if v), {})
        out.append("<table><tr><th class='text'>result</th><th>value</th></tr>")
        out += [
            f"<tr><td class='text'>{_e(c)}</td><td>{_e(_num(first.get(c)))}</td></tr>"
            for c in constant
        ]
        out.append("</table>")
    else:
        out.append("<p>None.</p>")
    out.append("</body></html>")
    return "\n".join(out)
