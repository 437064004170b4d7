"""The report's one-pass layout (``gearte.plotting.display.one_pass_layout``, docs/report.md,
"Drawing a figure once"): a figure made with constrained layout gets margins measured once and
is drawn once, every decoration inside the figure and the axes where constrained layout puts
them to within a few pixels; figures it cannot lay out keep constrained layout."""

from __future__ import annotations

import io
from typing import Any

import numpy as np
import pytest

from gearte.plotting import new_figure
from gearte.plotting.display import one_pass_layout, polish
from gearte.report.html import DPI, figure_to_png_base64


def _line_figure(nrows: int = 1, ncols: int = 1, twin: bool = False) -> tuple[Any, Any]:
    fig, axes = new_figure(nrows, ncols, figsize=(3.5 * ncols + 1.0, 3.0 * nrows), squeeze=False)
    x = np.linspace(0.0, 360.0, 200)
    for k, ax in enumerate(axes.flat):
        ax.plot(x, 1e3 * np.sin(np.radians(x) * (k + 1)), label="a long legend entry [µm]")
        ax.plot(x, 5e2 * np.cos(np.radians(x)), label="another one")
        ax.set_xlabel("output angle [deg]")
        ax.set_ylabel("transmission error [arcsec]")
        ax.set_title(f"panel {k + 1}")
        ax.legend()
    if twin:
        right = axes[0, -1].twinx()
        right.plot(x, 8 + (x > 180), color="C2")
        right.set_ylabel("pins in mesh")
    polish(fig)
    return fig, axes


def _canvas(fig: Any) -> Any:
    """An Agg canvas of ``fig`` at the report's resolution (gearte makes figures without
    pyplot, so they have no canvas that draws until ``savefig`` lends one)."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    fig.set_dpi(DPI)
    return FigureCanvasAgg(fig)


def _boxes(fig: Any) -> list[Any]:
    """Window extents [px] of every decoration: tick labels, axis labels, titles, legends."""
    renderer = _canvas(fig).get_renderer()
    out = []
    for ax in fig.axes:
        out.append(ax.get_tightbbox(renderer))
        for text in (ax.title, ax.xaxis.label, ax.yaxis.label):
            if text.get_text():
                out.append(text.get_window_extent(renderer))
    return out


def _draw(fig: Any) -> None:
    fig.savefig(io.BytesIO(), format="png", dpi=DPI)


@pytest.mark.parametrize(
    "nrows,ncols,twin", [(1, 1, False), (1, 1, True), (2, 2, False), (1, 3, True)]
)
def test_every_decoration_inside_the_figure_and_axes_near_constrained_places(nrows, ncols, twin):
    ref, ref_axes = _line_figure(nrows, ncols, twin)
    _draw(ref)  # constrained layout places the axes
    fig, axes = _line_figure(nrows, ncols, twin)
    assert one_pass_layout(fig) is True
    assert fig.get_layout_engine() is None
    _draw(fig)
    width, height = _canvas(fig).get_width_height()
    for box in _boxes(fig):
        assert box.x0 >= -0.5 and box.y0 >= -0.5, box
        assert box.x1 <= width + 0.5 and box.y1 <= height + 0.5, box
    for a, b in zip(axes.flat, ref_axes.flat, strict=True):
        pa, pb = a.get_position(), b.get_position()  # figure fractions
        # within 4 % of the figure's size of constrained layout's place, on every side
        assert abs(pa.x0 - pb.x0) < 0.04 and abs(pa.x1 - pb.x1) < 0.04, (pa, pb)
        assert abs(pa.y0 - pb.y0) < 0.04 and abs(pa.y1 - pb.y1) < 0.04, (pa, pb)


def test_the_panels_of_a_grid_do_not_overlap_each_others_labels():
    fig, axes = _line_figure(2, 2)
    assert one_pass_layout(fig)
    _draw(fig)
    renderer = _canvas(fig).get_renderer()
    boxes = [ax.get_tightbbox(renderer) for ax in axes.flat]
    for i, a in enumerate(boxes):
        for b in boxes[i + 1 :]:
            overlap_w = min(a.x1, b.x1) - max(a.x0, b.x0)
            overlap_h = min(a.y1, b.y1) - max(a.y0, b.y0)
            assert overlap_w <= 1.0 or overlap_h <= 1.0, (a, b)


def test_the_report_draws_a_figure_once(monkeypatch):
    """savefig draws a figure with a layout engine twice (once to run the layout); after the
    one-pass layout it draws it once."""
    from matplotlib.figure import Figure as MplFigure

    calls = []
    draw = MplFigure.draw

    def counting(self: Any, renderer: Any) -> Any:
        calls.append(self)
        return draw(self, renderer)

    monkeypatch.setattr(MplFigure, "draw", counting)
    fig, _ = _line_figure()
    _draw(fig)
    assert len(calls) == 2  # constrained layout: a draw without rendering, then the PNG
    calls.clear()
    fig, _ = _line_figure()
    figure_to_png_base64(fig)
    assert len(calls) == 1


def test_figures_it_cannot_lay_out_keep_constrained_layout():
    from matplotlib.layout_engine import ConstrainedLayoutEngine

    fig, ax = new_figure()
    ax.plot([0, 1], [0, 1], label="x")
    fig.legend(loc="outside lower center")  # constrained layout's own placement
    assert one_pass_layout(fig) is False
    assert isinstance(fig.get_layout_engine(), ConstrainedLayoutEngine)

    fig, ax = new_figure()
    im = ax.imshow(np.arange(12.0).reshape(3, 4))
    fig.colorbar(im, ax=ax)  # an axes outside the subplot grid
    assert one_pass_layout(fig) is False
    assert isinstance(fig.get_layout_engine(), ConstrainedLayoutEngine)

    fig, axes = new_figure(1, 2, margins_in=(0.8, 0.6, 0.3, 0.2))  # a fixed grid: no engine
    assert one_pass_layout(fig) is False
    assert fig.get_layout_engine() is None


def test_a_user_figure_keeps_constrained_layout_until_the_report_draws_it():
    """``new_figure`` still makes constrained-layout figures (what an API user saving a figure
    gets); only the report's rendering replaces the layout."""
    from matplotlib.layout_engine import ConstrainedLayoutEngine

    fig, _ = _line_figure()
    assert isinstance(fig.get_layout_engine(), ConstrainedLayoutEngine)


def test_the_margins_are_measured_in_one_pass_with_the_places_of_two(monkeypatch):
    """Tight layout with a ``rect`` (its default, the whole figure) measures every label a
    second time to fit the margins into the rect; the one-pass layout asks for none (one
    measuring pass) and gets the same margins to 1e-9 of the figure."""
    import warnings

    from matplotlib.layout_engine import TightLayoutEngine
    from matplotlib.text import Text

    from gearte.plotting.display import _tight_pads

    calls = []
    layout = Text._get_layout

    def counting(self: Any, renderer: Any) -> Any:
        calls.append(1)
        return layout(self, renderer)

    monkeypatch.setattr(Text, "_get_layout", counting)
    fig, _ = _line_figure(2, 2, twin=True)
    assert one_pass_layout(fig)
    once = len(calls)
    calls.clear()
    other, _ = _line_figure(2, 2, twin=True)
    two = TightLayoutEngine(**_tight_pads(other.get_layout_engine()))  # rect (0, 0, 1, 1)
    other.set_layout_engine(None)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        two.execute(other)
    assert len(calls) > 1.8 * once
    for name in ("left", "right", "top", "bottom", "wspace", "hspace"):
        a, b = getattr(fig.subplotpars, name), getattr(other.subplotpars, name)
        assert abs(a - b) < 1e-9, name
