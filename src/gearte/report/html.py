"""Render a study result as one self-contained HTML page (jinja2, figures embedded as PNG).

Layout (summary first): title and run facts; a *Summary* block with every warning (the study's
and the trade-off warnings of :func:`gearte.report.summary.tradeoff_warnings`) and the headline
quantities of each analysis with their spec and pass/fail; a table of contents; one section per
analysis with its tables (:mod:`gearte.report.tables`) beside its figures; references; the case
input. A print stylesheet puts each analysis on its own page.
"""

from __future__ import annotations

import base64
import datetime as _dt
import io
import json
import time
from dataclasses import dataclass
from importlib import resources
from typing import Any

__all__ = ["render_report", "render_figures", "figure_to_png_base64", "RenderedFigure"]

#: Resolution of the embedded PNGs (a 7-inch figure is 700 px wide, as it is shown).
DPI = 100


@dataclass
class RenderedFigure:
    """A figure as the report embeds it."""

    title: str
    caption: str
    analysis: str
    png: str  # base64
    width: int
    height: int


def figure_to_png_base64(fig: Any, dpi: int = DPI) -> str:
    """PNG of a matplotlib figure, base64 encoded."""
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=dpi)
    return base64.b64encode(buf.getvalue()).decode("ascii")


def _render_one(f: Any) -> RenderedFigure:
    from gearte.plotting.display import polish

    polish(f.fig)
    w, h = f.fig.get_size_inches()
    png = figure_to_png_base64(f.fig)
    return RenderedFigure(
        f.title, f.caption, f.analysis, png, int(round(w * DPI)), int(round(h * DPI))
    )


def render_figures(result: Any, timings: dict[str, float] | None = None) -> list[RenderedFigure]:
    """Build every figure of a study result and render it to PNG.

    ``timings`` (if given) receives ``"figures"`` (building the matplotlib figures) and
    ``"render"`` (drawing them to PNG), in seconds.
    """
    from gearte.plotting import figures_for

    t0 = time.perf_counter()
    figs = figures_for(result)
    t1 = time.perf_counter()
    out = [_render_one(f) for f in figs]
    t2 = time.perf_counter()
    if timings is not None:
        timings["figures"] = t1 - t0
        timings["render"] = t2 - t1
    return out


def _grouped(rows: list[Any]) -> list[list[Any]]:
    """Consecutive summary rows of the same analysis, together (one title cell each)."""
    groups: list[list[Any]] = []
    for r in rows:
        if groups and groups[-1][0].analysis == r.analysis:
            groups[-1].append(r)
        else:
            groups.append([r])
    return groups


def _case_json(result: Any) -> str:
    from gearte.results import to_jsonable

    return json.dumps(
        to_jsonable(result.case.model_dump(mode="json")), indent=1, ensure_ascii=False
    )


def render_report(result: Any, figures: list[RenderedFigure] | None = None) -> str:
    """HTML text of the report of a :class:`~gearte.results.StudyResult`.

    ``figures``: already rendered figures (:func:`render_figures`); rendered here if ``None``.
    """
    import jinja2

    from gearte._version import __version__
    from gearte.references import REFERENCES
    from gearte.report.summary import headlines, tradeoff_warnings
    from gearte.report.tables import analysis_tables

    if figures is None:
        figures = render_figures(result)
    names = [a.name for a in result.analyses]
    by_analysis: dict[str, list[RenderedFigure]] = {n: [] for n in names}
    for f in figures:
        # a figure that names no (known) analysis goes with the first one
        key = f.analysis if f.analysis in by_analysis else (names[0] if names else "")
        if key:
            by_analysis[key].append(f)
    analyses = [
        {
            "name": a.name,
            "title": a.title,
            "notes": a.notes,
            "tables": analysis_tables(a),
            "figures": by_analysis.get(a.name, []),
        }
        for a in result.analyses
    ]
    env = jinja2.Environment(autoescape=True, undefined=jinja2.StrictUndefined)
    template = resources.files("gearte.report").joinpath("report.html.j2").read_text("utf-8")
    return env.from_string(template).render(
        title=result.case.case.title or result.name,
        name=result.name,
        kind=result.kind,
        version=__version__,
        date=_dt.datetime.now(_dt.UTC).strftime("%Y-%m-%d %H:%M UTC"),
        elapsed=f"{result.elapsed_s:.2f}",
        description=result.case.case.description,
        warnings=list(result.warnings) + tradeoff_warnings(result),
        headline_groups=_grouped(headlines(result)),
        analyses=analyses,
        references=[(k, REFERENCES.get(k, k)) for k in result.references],
        case_json=_case_json(result),
    )
