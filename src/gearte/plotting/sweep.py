"""Figures of a parameter sweep: every scalar result against every varied key.

With one varied key each figure is a line; with more, one line per combination of the other keys
(up to :data:`MAX_LINES`, a scatter beyond). matplotlib is imported lazily (via ``new_figure``).
"""

from __future__ import annotations

import math
import re
from typing import Any

from gearte.plotting import PALETTE, Figure, new_figure

__all__ = ["figures", "figure_for", "plot_stem", "MAX_LINES"]

#: Most lines drawn in one figure before falling back to a scatter of all points.
MAX_LINES = 8


def plot_stem(column: str, key: str) -> str:
    """File stem of the figure of ``column`` against ``key`` (safe characters only)."""

    def slug(s: str) -> str:
        return re.sub(r"[^A-Za-z0-9_.-]+", "_", s).strip("_")

    return f"{slug(column)}__vs__{slug(key)}"


def _num(v: Any) -> float:
    if v is None:
        return math.nan
    try:
        return float(v)
    except (TypeError, ValueError):
        return math.nan


def figure_for(result: Any, column: str, key: str) -> Figure:
    """``column`` (a scalar result) against the varied ``key``."""
    fig, ax = new_figure(figsize=(6.0, 3.8))
    y = [_num(v) for v in result.column(column)]
    xs = result.column(key)
    numeric_x = all(isinstance(x, int | float) and not isinstance(x, bool) for x in xs)
    x_pos = [float(x) for x in xs] if numeric_x else None
    if not numeric_x:  # categorical values: positions in order of first appearance
        cats = list(dict.fromkeys(map(str, xs)))
        x_pos = [float(cats.index(str(x))) for x in xs]
        ax.set_xticks(range(len(cats)), cats)
    others = [k for k in result.keys if k != key]
    groups: dict[tuple[Any, ...], list[int]] = {}
    for i, p in enumerate(result.points):
        groups.setdefault(tuple(p[k] for k in others), []).append(i)
    if len(groups) <= MAX_LINES:
        for n, (g, idx) in enumerate(groups.items()):
            label = ", ".join(f"{k} = {v}" for k, v in zip(others, g, strict=True)) or None
            ax.plot(
                [x_pos[i] for i in idx],
                [y[i] for i in idx],
                marker="o",
                color=PALETTE[n % len(PALETTE)],
                label=label,
            )
        if others:
            ax.legend(fontsize="small")
    else:
        ax.scatter(x_pos, y, s=12, color=PALETTE[0])
    failed = [i for i, e in enumerate(result.errors) if e]
    for i in failed:
        ax.axvline(x_pos[i], color="0.8", lw=0.8, ls=":")
    ax.set_xlabel(key)
    ax.set_ylabel(column)
    ax.grid(True, alpha=0.3)
    caption = f"{column} over the sweep of {key}"
    if others:
        caption += f" (lines: {', '.join(others)})" if len(groups) <= MAX_LINES else " (all points)"
    if failed:
        caption += f"; dotted: {len(failed)} point(s) that failed"
    return Figure(f"{column} vs {key}", caption, fig)


def figures(result: Any) -> list[tuple[str, Figure]]:
    """``[(file stem, Figure), ...]``: every scalar result against every varied key."""
    return [
        (plot_stem(col, key), figure_for(result, col, key))
        for col in result.columns
        for key in result.keys
    ]
