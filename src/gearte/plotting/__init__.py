"""Plotting: one module per study kind with ``figures(result) -> list[Figure]``.

matplotlib is imported only inside functions, and figures are made without pyplot (no global
state, no GUI backend): ``fig, ax = new_figure()``. Nothing here calls ``show()``.
"""

from __future__ import annotations

import importlib
from dataclasses import dataclass
from typing import Any

__all__ = [
    "Figure",
    "new_figure",
    "figures_for",
    "figures_of",
    "others_read_alone",
    "self_contained",
    "for_analysis",
    "PALETTE",
]

#: Colours used consistently across gearte's plots (colour-blind safe, Okabe–Ito).
PALETTE = ["#0072B2", "#D55E00", "#009E73", "#CC79A7", "#E69F00", "#56B4E9", "#F0E442", "#000000"]


@dataclass
class Figure:
    """A figure of a report: its title, a caption saying what to read from it, the figure, and
    the name of the analysis it illustrates (the report places it beside that analysis's table).
    """

    title: str
    caption: str
    fig: Any  # matplotlib.figure.Figure
    analysis: str = ""


def for_analysis(name: str, figs: list[Figure]) -> list[Figure]:
    """Mark the figures ``figs`` as illustrating the analysis ``name`` (the report shows them
    beside it)."""
    for f in figs:
        f.analysis = name
    return figs


def new_figure(
    nrows: int = 1,
    ncols: int = 1,
    *,
    figsize: tuple[float, float] = (7.0, 4.0),
    margins_in: tuple[float, float, float, float] | None = None,
    **subplot_kw: Any,
) -> tuple[Any, Any]:
    """A matplotlib Figure (Agg canvas, no pyplot) and its axes: ``nrows`` × ``ncols`` subplots,
    ``figsize`` [inch]; ``subplot_kw`` passed to ``Figure.subplots``.

    By default matplotlib's constrained layout places the axes (it measures every label: about
    half of a figure's drawing time). A regular grid of like panels may give ``margins_in``
    [inch] = (left, bottom, top, gap): the room left of each panel (tick labels and y label),
    below it (tick labels and x label), above it (title) and to the right edge; the grid is then
    fixed, with no measuring (for a 2 × 4 grid of panels a fifth of the drawing time)."""
    from matplotlib.figure import Figure as MplFigure

    if margins_in is None:
        fig = MplFigure(figsize=figsize, layout="constrained")
        return fig, fig.subplots(nrows, ncols, **subplot_kw)
    left, bottom, top, gap = margins_in
    w, h = figsize
    panel_w = (w - ncols * left - gap) / ncols
    panel_h = (h - nrows * (bottom + top)) / nrows
    if panel_w <= 0 or panel_h <= 0:
        raise ValueError(f"margins_in={margins_in} leave no room for panels in {figsize} inch")
    fig = MplFigure(figsize=figsize)
    fig.subplots_adjust(
        left=left / w,
        right=1.0 - gap / w,
        bottom=bottom / h,
        top=1.0 - top / h,
        wspace=left / panel_w,
        hspace=(bottom + top) / panel_h,
    )
    return fig, fig.subplots(nrows, ncols, **subplot_kw)


def _module(kind: str) -> Any:
    from gearte.studies import get_kind

    module_name = getattr(get_kind(kind), "FIGURES", None)
    return importlib.import_module(module_name) if module_name else None


def figures_for(result: Any) -> list[Figure]:
    """All figures of a study result, from the plotting module its kind names (``FIGURES``)."""
    module = _module(result.kind)
    return list(module.figures(result)) if module is not None else []


def self_contained(kind: str) -> frozenset[str]:
    """The analyses of study kind ``kind`` whose figures read that analysis alone (and the
    case): :func:`figures_of` draws them from the analysis as soon as it is done, the same
    figures as :func:`figures_for` draws from the whole result. A plotting module lists them in
    ``SELF_CONTAINED``; none where it lists none."""
    module = _module(kind)
    return frozenset(getattr(module, "SELF_CONTAINED", ())) if module is not None else frozenset()


def others_read_alone(kind: str) -> bool:
    """Whether no figure of an analysis outside :func:`self_contained` of study kind ``kind``
    reads a self-contained analysis (a plotting module says so with ``OTHERS_READ_ALONE``):
    then the figures of the analyses not drawn early are those :func:`figures_of` draws from
    them alone, and the report process builds only those once the final result comes."""
    return bool(getattr(_module(kind), "OTHERS_READ_ALONE", False))


def figures_of(result: Any, names: Any) -> list[Figure]:
    """The figures of the analyses ``names`` of ``result`` (a
    :class:`~gearte.results.StudyResult`), drawn as if the result held only those analyses.

    For analyses of :func:`self_contained` these are the figures :func:`figures_for` draws of
    them from the whole result, in the same order (the report process draws each finished
    analysis's figures while the next ones run: docs/report.md)."""
    import copy

    names = set(names)
    view = copy.copy(result)
    view.analyses = [a for a in result.analyses if a.name in names]
    try:
        figs = figures_for(view)
    finally:
        result._link()  # reading the view pointed its analyses at it
    return [f for f in figs if f.analysis in names]
