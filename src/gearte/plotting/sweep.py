"""Figures of a parameter sweep: every scalar result against every varied key.

One figure per scalar result that changes over the sweep (results constant at every point are
listed in the table, not drawn), with one panel per varied key. With one varied key a panel is a
line; with more, one line per combination of the other keys (up to :data:`MAX_LINES`, a scatter
beyond). matplotlib is imported lazily (via ``new_figure``).
"""

from __future__ import annotations

import math
import re
from typing import Any

from gearte.plotting import PALETTE, Figure, new_figure

__all__ = ["figures", "figure_for", "plot_stem", "varying_columns", "MAX_LINES"]

#: Most lines drawn in one figure before falling back to a scatter of all points.
MAX_LINES = 8


def plot_stem(column: str) -> str:
    """File stem of the figure of ``column`` (safe characters only)."""
    return re.sub(r"[^A-Za-z0-9_.-]+", "_", column).strip("_")


def _readable(column: str) -> str:
    """``"analysis.value [unit]"`` as people read it (``gearte.labels``), wrapped for an axis."""
    import textwrap

    from gearte.labels import label_with_unit

    analysis, _, rest = column.partition(".")
    text = label_with_unit(rest) if rest and "." not in rest else column
    if rest and "." not in rest:
        text = f"{text} ({analysis})"
    return "\n".join(textwrap.wrap(text, 38)) or column


def _num(v: Any) -> float:
    if v is None:
        return math.nan
    try:
        return float(v)
    except (TypeError, ValueError):
        return math.nan


def varying_columns(result: Any) -> list[str]:
    """Scalar results of a sweep ``result`` that are not the same at every point."""
    out = []
    for col in result.columns:
        vals = result.column(col)
        if len({repr(v) for v in vals}) > 1:
            out.append(col)
    return out


def _panel(ax: Any, result: Any, column: str, key: str) -> str:
    y = [_num(v) for v in result.column(column)]
    xs = result.column(key)
    numeric_x = all(isinstance(x, int | float) and not isinstance(x, bool) for x in xs)
    if numeric_x:
        x_pos = [float(x) for x in xs]
    else:  # categorical values: positions in order of first appearance
        cats = list(dict.fromkeys(map(str, xs)))
        x_pos = [float(cats.index(str(x))) for x in xs]
        ax.set_xticks(range(len(cats)), cats)
    coupled = result.coupled_with(key) if hasattr(result, "coupled_with") else (key,)
    others = [k for k in result.keys if k not in coupled]
    groups: dict[tuple[Any, ...], list[int]] = {}
    for i, p in enumerate(result.points):
        groups.setdefault(tuple(p[k] for k in others), []).append(i)
    if len(groups) <= MAX_LINES:
        for n, (g, idx) in enumerate(groups.items()):
            label = (
                ", ".join(f"{k.rsplit('.', 1)[-1]} = {v}" for k, v in zip(others, g, strict=True))
                or None
            )
            ax.plot(
                [x_pos[i] for i in idx],
                [y[i] for i in idx],
                marker="o",
                ms=4,
                color=PALETTE[n % len(PALETTE)],
                label=label,
            )
        if others:  # moved below the panel, out of the data, by ``polish``
            ax.legend(fontsize="x-small")
        how = f"lines: {', '.join(others)}" if others else ""
    else:
        ax.scatter(x_pos, y, s=12, color=PALETTE[0])
        how = "all points"
    for i, e in enumerate(result.errors):
        if e:  # failed or invalid (skipped) points
            ax.axvline(x_pos[i], color="0.8", lw=0.8, ls=":")
    ax.set_xlabel(key if len(coupled) == 1 else f"{key} (with {', '.join(coupled[1:])})")
    ax.set_ylabel(_readable(column))
    ax.grid(True, alpha=0.3)
    return how


def _axis_keys(result: Any) -> list[str]:
    """One key per axis of the grid: the first of each group of coupled keys."""
    vary = getattr(result, "vary", None)
    if vary is None:
        return list(result.keys)
    return [v.keys[0] for v in vary]


def figure_for(result: Any, column: str) -> Figure:
    """``column`` (a scalar result) against each axis of the grid, one panel per axis (coupled
    keys share one panel, drawn over the first of them)."""
    keys = _axis_keys(result)
    fig, axes = new_figure(1, len(keys), figsize=(5.0 * len(keys), 3.6), squeeze=False)
    hows = [_panel(ax, result, column, key) for ax, key in zip(axes[0], keys, strict=True)]
    caption = f"{column} over the sweep of {', '.join(keys)}"
    extra = [h for h in hows if h]
    if extra:
        caption += f" ({'; '.join(extra)})"
    failed = sum(1 for e in result.errors if e)
    if failed:
        caption += f"; dotted: {failed} point(s) that failed or did not validate"
    from gearte.plotting.display import polish

    polish(fig)  # legends out of the data (below each panel), integer ticks for counts
    lines = 0
    for ax in fig.axes:  # one legend entry per row: panels side by side must not overlap
        leg = ax.get_legend()
        if leg is None:
            continue
        handles, labels = leg.legend_handles, [t.get_text() for t in leg.get_texts()]
        leg.remove()
        ax.legend(
            handles,
            labels,
            loc="upper center",
            bbox_to_anchor=(0.5, -0.16),
            ncols=1,
            fontsize=7,
            frameon=False,
        )
        lines = max(lines, len(labels))
    if lines:
        fig.set_size_inches(fig.get_figwidth(), 3.6 + 0.17 * lines)
    return Figure(f"{column} vs {', '.join(keys)}", caption, fig)


def figures(result: Any) -> list[tuple[str, Figure]]:
    """``[(file stem, Figure), ...]``: every varying scalar result against every varied key."""
    return [(plot_stem(col), figure_for(result, col)) for col in varying_columns(result)]
