"""Make a figure cheap to draw and easy to read before it is rendered: the house style every
report figure gets in one place.

* :func:`decimate` keeps what the eye can resolve of a long signal: the first and last point and
  the minimum and maximum of each of ``max_points/2`` buckets, in order (the envelope drawn at the
  figure's resolution is the same as the full signal's); the full data stay in the results.
* :func:`polish` applies it to every long line of a figure, moves legends out of the data (one
  legend below the axes), and puts integer ticks on axes whose plotted data are all integers
  (pin numbers, counts).
* :func:`distribution` draws samples as a histogram, or as a strip plot (each sample a point)
  below :data:`STRIP_BELOW` samples, where a histogram would be mostly empty bins.
* :func:`one_pass_layout` places the axes of a figure made with constrained layout in one
  measuring pass before it is drawn once (matplotlib's constrained layout measures every label
  twice and ``savefig`` then draws the figure twice): about a third of the drawing work less,
  the same places to a pixel or two.
"""

from __future__ import annotations

import functools
from typing import Any

import numpy as np

__all__ = [
    "decimate",
    "polish",
    "distribution",
    "one_pass_layout",
    "MAX_POINTS",
    "STRIP_BELOW",
]

#: Points kept of a line (a 7-inch axis at 100 dpi is ~600 px wide: 4 points per pixel).
MAX_POINTS = 2400
#: Fewer samples than this are drawn as a strip plot, not a histogram.
STRIP_BELOW = 30


def decimate(x: np.ndarray, y: np.ndarray, max_points: int = MAX_POINTS) -> np.ndarray:
    """Indices of the points of ``x`` [any unit], ``y`` [any unit] to draw (``max_points``
    [-]): all of them if there are at most ``max_points``; else the first, the last, and in
    each of ``max_points // 4`` buckets of consecutive points the ones with the smallest and
    largest ``x`` and ``y`` (in order).

    Works for signals (``x`` increasing: the min/max envelope of ``y`` is kept exactly) and for
    curves such as trajectories and phase portraits (their extent in both directions is kept).
    NaN points are kept where they are the bucket's extreme only (a break in a line may close).
    """
    n = len(y)
    if n <= max_points:
        return np.arange(n)
    buckets = max(1, max_points // 4)
    edges = np.linspace(0, n, buckets + 1).astype(np.int64)
    width = int(np.max(np.diff(edges)))
    # pad the last buckets so every bucket has `width` points (padding repeats a bucket's last)
    idx = np.minimum(edges[:-1, None] + np.arange(width)[None, :], edges[1:, None] - 1)
    keep = [idx[:, 0], idx[:, -1]]
    for v in (np.asarray(x, dtype=float), np.asarray(y, dtype=float)):
        vb = v[idx]
        finite = np.isfinite(vb)
        if not finite.any():
            continue
        lo = np.where(finite, vb, np.inf).argmin(axis=1)
        hi = np.where(finite, vb, -np.inf).argmax(axis=1)
        rows = np.arange(len(idx))
        keep += [idx[rows, lo], idx[rows, hi]]
    return np.unique(np.concatenate([*keep, [0, n - 1]]))


def _decimate_lines(fig: Any) -> None:
    for ax in fig.axes:
        for line in ax.get_lines():
            x, y = line.get_xdata(orig=True), line.get_ydata(orig=True)
            if np.ndim(x) != 1 or np.ndim(y) != 1 or len(x) != len(y) or len(y) <= MAX_POINTS:
                continue
            if np.asarray(x).dtype.kind not in "biuf" or np.asarray(y).dtype.kind not in "biuf":
                continue
            keep = decimate(np.asarray(x), np.asarray(y))
            line.set_data(np.asarray(x)[keep], np.asarray(y)[keep])
            if line.get_marker() not in (None, "None", "", " "):
                line.set_markevery(None)


def _all_integer(values: list[np.ndarray]) -> bool:
    vals = [np.asarray(v, dtype=float).ravel() for v in values if np.size(v)]
    if not vals:
        return False
    v = np.concatenate(vals)
    v = v[np.isfinite(v)]
    return v.size > 0 and bool(np.all(v == np.round(v))) and np.ptp(v) >= 1


def _integer_ticks(fig: Any) -> None:
    from matplotlib.container import BarContainer
    from matplotlib.ticker import AutoLocator, MaxNLocator

    for ax in fig.axes:
        if ax.name != "rectilinear":
            continue
        xs: list[np.ndarray] = []
        ys: list[np.ndarray] = []
        other = False
        for line in ax.get_lines():
            x, y = line.get_xdata(), line.get_ydata()
            if np.size(x) == 0 or np.size(y) == 0:
                continue  # legend proxies
            try:
                xf, yf = np.asarray(x, dtype=float), np.asarray(y, dtype=float)
            except (TypeError, ValueError):  # dates, categories: leave the axis alone
                other = True
                break
            if len(xf) <= 2 and (np.ptp(yf) == 0 or np.ptp(xf) == 0):
                continue  # reference lines (axhline/axvline)
            xs.append(xf)
            ys.append(yf)
        for c in ax.containers:
            if isinstance(c, BarContainer):
                xs.append(np.array([r.get_x() + r.get_width() / 2 for r in c]))
                ys.append(np.array([r.get_height() for r in c]))
        other = (
            other
            or bool(ax.images)
            or any(type(c).__name__ not in ("LineCollection",) for c in ax.collections)
        )
        if other or not (xs or ys):
            continue
        if isinstance(ax.xaxis.get_major_locator(), AutoLocator) and _all_integer(xs):
            ax.xaxis.set_major_locator(MaxNLocator(integer=True))
        if isinstance(ax.yaxis.get_major_locator(), AutoLocator) and _all_integer(ys):
            ax.yaxis.set_major_locator(MaxNLocator(integer=True))


def _legends_outside(fig: Any) -> None:
    """Each axes legend moves below its axes (out of the data), in up to three columns."""
    for ax in fig.axes:
        leg = ax.get_legend()
        if leg is None:
            continue
        handles, labels = leg.legend_handles, [t.get_text() for t in leg.get_texts()]
        fontsize = leg.get_texts()[0].get_fontsize() if labels else 8
        leg.remove()
        if not labels:
            continue
        ncols = 1 if max(len(s) for s in labels) > 45 else min(3, len(labels))
        ax.legend(
            handles,
            labels,
            loc="upper center",
            bbox_to_anchor=(0.5, -0.16 if ax.get_xlabel() else -0.08),
            ncols=ncols,
            fontsize=min(fontsize, 8),
            frameon=False,
        )


def _tight_pads(engine: Any) -> dict[str, float]:
    """The pads of a constrained-layout ``engine`` (``w_pad``, ``h_pad`` [inch]) as tight layout
    takes them (``pad``, ``w_pad``, ``h_pad`` [fractions of the font size], ``pad`` the larger),
    for :func:`one_pass_layout`."""
    import matplotlib as mpl

    pads = engine.get()
    fontsize = mpl.font_manager.FontProperties(size=mpl.rcParams["font.size"]).get_size_in_points()
    w_pad, h_pad = 72.0 * pads["w_pad"] / fontsize, 72.0 * pads["h_pad"] / fontsize
    return {"pad": max(w_pad, h_pad), "w_pad": w_pad, "h_pad": h_pad}


def _drop_layout_engine(fig: Any) -> None:
    """Leave ``fig`` without a layout engine (not the one the rc parameters would give it)."""
    import matplotlib as mpl

    with mpl.rc_context({"figure.autolayout": False, "figure.constrained_layout.use": False}):
        fig.set_layout_engine(None)


def one_pass_layout(fig: Any) -> bool:
    """Replace the constrained layout of ``fig`` (a matplotlib figure) by margins measured once,
    where that gives the same picture; True where it did, False where the figure is left as it
    was.

    matplotlib's constrained layout measures the decorations of every axes (tick labels, axis
    labels, titles, legends) twice, and ``savefig`` draws a figure with a layout engine twice
    (once without rendering, to run the layout, then for real): on gearte's report figures that
    is about a third of the Python calls of drawing one (``docs/report.md``, "Drawing a figure
    once"). Here the decorations are measured once by matplotlib's tight layout
    (:meth:`matplotlib.figure.Figure.tight_layout`, one pass: each axes' tight box, the
    room it needs on each side, the margins shared by a row or column of the grid, set with
    ``subplots_adjust``), with the pads of constrained layout, and the layout engine removed, so
    ``savefig`` draws once.

    Left to constrained layout (False): a figure with a figure legend (``loc="outside ..."``
    is constrained layout's own placement), with axes outside the subplot grid (a colorbar made
    by constrained layout, an inset), with subfigures, with the "compressed" variant, and one
    whose margins cannot be found (the labels need more room than the figure has: tight layout
    warns and sets nothing).
    """
    import warnings

    from matplotlib.layout_engine import ConstrainedLayoutEngine

    engine = fig.get_layout_engine()
    # "compressed" is ConstrainedLayoutEngine(compress=True); read where the engine keeps it
    if not isinstance(engine, ConstrainedLayoutEngine) or getattr(engine, "_compress", False):
        return False
    if not fig.axes or fig.legends or fig.subfigs:
        return False
    if any(ax.get_subplotspec() is None for ax in fig.axes):
        return False
    _drop_layout_engine(fig)  # (subplots_adjust is refused under constrained layout)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        # Figure.tight_layout without a rect: one measuring pass (TightLayoutEngine's own
        # default rect, the whole figure, makes tight layout measure every label a second
        # time to fit the same margins into it); it leaves a place-holder engine behind, which
        # would make savefig draw twice: dropped below
        fig.tight_layout(**_tight_pads(engine))
    _drop_layout_engine(fig)
    if caught:  # tight layout found no margins and set nothing: constrained layout again
        fig.set_layout_engine(engine)
        return False
    return True


def polish(fig: Any) -> Any:
    """Decimate long lines of ``fig`` (a matplotlib figure), put legends outside the data,
    integer ticks on integer data and plain-text labels on logarithmic axes."""
    _decimate_lines(fig)
    _integer_ticks(fig)
    _legends_outside(fig)
    _plain_log_labels(fig)
    return fig


_SUPERSCRIPT = str.maketrans("-0123456789", "⁻⁰¹²³⁴⁵⁶⁷⁸⁹")


@functools.cache
def _plain_log_formatter() -> Any:
    """matplotlib's base-10 log tick formatter with the labels as plain text: ``10⁻³``,
    ``2×10⁻³`` (Unicode superscripts) instead of mathtext (``$\\mathdefault{10^{-3}}$``);
    the class is made on first use (matplotlib is imported lazily).

    Which ticks are labelled (decades, and minor ticks where the axis spans less than a decade
    or so) is matplotlib's :class:`~matplotlib.ticker.LogFormatter` logic, unchanged; only the
    text differs. Mathtext needs its parser, built on the first such label of a process
    (~0.15-0.3 s CPU), and lays out each label in pieces."""
    import math

    from matplotlib.ticker import LogFormatter

    class PlainLogFormatter(LogFormatter):
        def _num_to_string(self, x: float, vmin: float, vmax: float) -> str:
            fx = math.log10(x)
            exponent = round(fx)
            if abs(fx - exponent) < 1e-10:  # matplotlib's _is_close_to_int
                return "10" + str(exponent).translate(_SUPERSCRIPT)
            exponent = math.floor(fx)
            coeff = round(10.0 ** (fx - exponent))
            return f"{coeff}×10" + str(exponent).translate(_SUPERSCRIPT)

    return PlainLogFormatter


def _plain_log_labels(fig: Any) -> None:
    """Give every base-10 logarithmic axis of ``fig`` whose tick formatters are matplotlib's
    defaults (:class:`~matplotlib.ticker.LogFormatterSciNotation`) the same formatters with
    plain-text labels (:func:`_plain_log_formatter`)."""
    from matplotlib.ticker import LogFormatterSciNotation

    for ax in fig.axes:
        for axis in (ax.xaxis, ax.yaxis):
            if axis.get_scale() != "log":
                continue
            for which in ("major", "minor"):
                old = getattr(axis, f"get_{which}_formatter")()
                # (its base and symlog threshold are private attributes: read with defaults)
                if type(old) is not LogFormatterSciNotation or getattr(old, "_base", 0) != 10:
                    continue
                new = _plain_log_formatter()(
                    base=10.0,
                    labelOnlyBase=old.labelOnlyBase,
                    minor_thresholds=old.minor_thresholds,
                    linthresh=getattr(old, "_linthresh", None),
                )
                getattr(axis, f"set_{which}_formatter")(new)


def distribution(ax: Any, samples: Any, *, color: str, label: str = "", density: bool = False,
                 bins: int | None = None) -> str:  # fmt: skip
    """Samples on ``ax`` along x: a histogram, or a strip plot below :data:`STRIP_BELOW` samples,
    in ``color``, named ``label``; ``density`` and ``bins`` as in ``Axes.hist``.

    Returns ``"histogram"`` or ``"strip"`` (the y label to use differs)."""
    s = np.asarray(samples, dtype=float)
    s = s[np.isfinite(s)]
    if s.size < STRIP_BELOW:
        rng = np.random.default_rng(0)  # fixed jitter: the same picture every time
        ax.plot(s, rng.uniform(-0.3, 0.3, s.size), "o", color=color, ms=5, alpha=0.8,
                label=label or None)  # fmt: skip
        if s.size:
            ax.axvline(float(s.mean()), color=color, lw=1.2, ls="--")
        ax.set_ylim(-1, 1)
        ax.set_yticks([])
        return "strip"
    ax.hist(s, bins=bins or max(5, int(np.sqrt(s.size))), density=density, color=color,
            alpha=0.7, label=label or None)  # fmt: skip
    return "histogram"
