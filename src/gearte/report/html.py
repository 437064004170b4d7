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
import functools
import io
import json
import os
import pickle
import time
from dataclasses import dataclass
from importlib import resources
from typing import Any

__all__ = [
    "render_report",
    "render_figures",
    "render_all",
    "figure_to_png_base64",
    "RenderedFigure",
]

#: Resolution of the embedded PNGs (a 7-inch figure is 700 px wide, as it is shown).
DPI = 100
#: zlib level of the embedded PNGs (see :func:`figure_to_png_base64`).
PNG_COMPRESS_LEVEL = 3


@dataclass
class RenderedFigure:
    """A figure as the report embeds it."""

    title: str
    caption: str
    analysis: str
    png: str  # base64
    width: int
    height: int
    seconds: float = 0.0  # wall time of polishing and drawing it [s]


def figure_to_png_base64(fig: Any, dpi: int = DPI) -> str:
    """PNG of a matplotlib figure, base64 encoded.

    Parameters
    ----------
    fig : matplotlib.figure.Figure
        The figure.
    dpi : int
        Resolution [dots per inch].

    Returns
    -------
    str
        Base64 text of the PNG.
    """
    from gearte.plotting.display import one_pass_layout

    one_pass_layout(fig)  # constrained layout's margins measured once, the figure drawn once
    buf = io.BytesIO()
    # zlib level 3, not Pillow's 6: half the encoding time (~15 of ~30 ms for a 700 x 400 px
    # figure) for ~18 % more bytes
    fig.savefig(buf, format="png", dpi=dpi, pil_kwargs={"compress_level": PNG_COMPRESS_LEVEL})
    return base64.b64encode(buf.getvalue()).decode("ascii")


def _render_one(f: Any, polished: bool = False) -> RenderedFigure:
    from gearte.plotting.display import polish

    t0 = time.perf_counter()
    if not polished:
        polish(f.fig)
    w, h = f.fig.get_size_inches()
    png = figure_to_png_base64(f.fig)
    return RenderedFigure(
        f.title,
        f.caption,
        f.analysis,
        png,
        int(round(w * DPI)),
        int(round(h * DPI)),
        time.perf_counter() - t0,
    )


def render_figures(
    result: Any, timings: dict[str, float] | None = None, *, workers: int | None = None
) -> list[RenderedFigure]:
    """Build every figure of a study result and render it to PNG.

    Rendering (matplotlib drawing text and lines) is most of a report's time and each figure is
    independent: with ``workers`` > 1 (default: the cores this process may use) and ``os.fork``
    available, forked copies of this process render shares of the figures in parallel and send
    the PNGs back (the figures are not pickled: a fork inherits them). ``timings`` (if given)
    receives ``"figures"`` (building the matplotlib figures) and ``"render"`` (drawing them to
    PNG) and ``"render: slowest figure"``, in seconds [s].
    """
    from gearte.plotting import figures_for

    t0 = time.perf_counter()
    figs = figures_for(result)
    t1 = time.perf_counter()
    out = _render_all(figs, _workers() if workers is None else workers)
    t2 = time.perf_counter()
    if timings is not None:
        timings["figures"] = t1 - t0
        timings["render"] = t2 - t1
        timings["render: slowest figure"] = max((f.seconds for f in out), default=0.0)
    return out


def _workers() -> int:
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:  # pragma: no cover - not Linux
        return os.cpu_count() or 1


def _cost(f: Any) -> float:
    """A rough drawing cost of a figure: its axes (ticks, labels) and the points it draws."""
    points = sum(len(line.get_xdata()) for ax in f.fig.axes for line in ax.get_lines())
    return len(f.fig.axes) + min(points, 4 * 2400 * len(f.fig.axes)) / 5000.0


def render_all(
    figs: list[Any], workers: int | None = None, *, polished: bool = False
) -> list[RenderedFigure]:
    """Render the :class:`~gearte.plotting.Figure` objects ``figs`` to PNG, in order, in
    ``workers`` forked processes (default: the cores this process may use) where that can help.

    Parameters
    ----------
    figs : list of Figure
        The figures.
    workers : int, optional
        Processes to render in (1: in this process).
    polished : bool
        The figures are already polished (:func:`gearte.plotting.display.polish`); by default
        each is polished before it is drawn.
    """
    return _render_all(figs, _workers() if workers is None else workers, polished=polished)


def _render_all(figs: list[Any], workers: int, *, polished: bool = False) -> list[RenderedFigure]:
    """Render ``figs`` in order, in ``workers`` processes (forked) where that can help."""
    workers = min(workers, len(figs))
    if workers < 2 or not hasattr(os, "fork"):
        return [_render_one(f, polished) for f in figs]
    # share the figures out, largest first, to the least loaded worker
    load = [0.0] * workers
    share: list[list[int]] = [[] for _ in range(workers)]
    for i in sorted(range(len(figs)), key=lambda i: -_cost(figs[i])):
        w = load.index(min(load))
        share[w].append(i)
        load[w] += _cost(figs[i])
    children: list[tuple[int, int, list[int]]] = []
    for idx in share[1:]:
        r, w = os.pipe()
        pid = os.fork()
        if pid == 0:  # child: render its share, send it, leave without cleanup handlers
            code = 0
            try:
                os.close(r)
                data = pickle.dumps([_render_one(figs[i], polished) for i in idx])
                with os.fdopen(w, "wb") as fh:
                    fh.write(data)
            except BaseException:  # noqa: BLE001 - the parent renders what a child could not
                code = 1
            finally:
                os._exit(code)
        os.close(w)
        children.append((pid, r, idx))
    done: dict[int, RenderedFigure] = {i: _render_one(figs[i], polished) for i in share[0]}
    for pid, r, idx in children:
        with os.fdopen(r, "rb") as fh:
            data = fh.read()
        _, status = os.waitpid(pid, 0)
        got = pickle.loads(data) if status == 0 and data else None
        for k, i in enumerate(idx):
            done[i] = got[k] if got else _render_one(figs[i], polished)
    return [done[i] for i in range(len(figs))]


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


#: Tables with more columns than this leave the column beside the figures and span the
#: section's width below them (their first column stays in view when they scroll sideways).
WIDE_COLUMNS = 5


@functools.cache
def report_template() -> Any:
    """The report's jinja2 template (``report.html.j2``), compiled once per process (~0.02 s
    CPU; the report process of ``gearte run`` compiles it while it warms up)."""
    import jinja2

    env = jinja2.Environment(autoescape=True, undefined=jinja2.StrictUndefined)
    text = resources.files("gearte.report").joinpath("report.html.j2").read_text("utf-8")
    return env.from_string(text)


def render_report(result: Any, figures: list[RenderedFigure] | None = None) -> str:
    """HTML text of the report of a :class:`~gearte.results.StudyResult`.

    ``figures``: already rendered figures (:func:`render_figures`); rendered here if ``None``.

    Parameters
    ----------
    result : StudyResult
        The result to report.
    figures : list of RenderedFigure, optional
        Already rendered figures (:func:`render_figures`); rendered here if ``None``.

    Returns
    -------
    str
        The self-contained HTML page.
    """
    from gearte._version import __version__
    from gearte.references import REFERENCES
    from gearte.report.summary import headlines, tradeoff_warnings
    from gearte.report.tables import analysis_tables, run_metadata_table

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
    return report_template().render(
        title=result.case.case.title or result.name,
        name=result.name,
        kind=result.kind,
        version=__version__,
        date=_dt.datetime.now(_dt.UTC).strftime("%Y-%m-%d %H:%M UTC"),
        description=result.case.case.description,
        warnings=list(result.warnings) + tradeoff_warnings(result),
        headline_groups=_grouped(headlines(result)),
        analyses=analyses,
        references=[(k, REFERENCES.get(k, k)) for k in result.references],
        case_json=_case_json(result),
        run_metadata=run_metadata_table(result),
        wide_columns=WIDE_COLUMNS,
    )
