"""Progress bar of chunked work (rich, on a terminal only; silent in logs, pipes and tests).

A sampled study's bar counts *samples*: its total is the study's sample count and each finished
chunk advances it by that chunk's own sample count (the last chunk is usually smaller), with the
rate in samples/s and the time remaining. Work that is not sampled (sweep points, reducers of a
lot) counts its own units, one per task. :func:`gearte.execution.map_chunks` advances the bar in
the calling thread as chunks finish, so it reads the same on threads, processes and Dask.
"""

from __future__ import annotations

import sys
from typing import Any

__all__ = ["ChunkProgress", "format_rate"]


def format_rate(speed: float | None, unit: str) -> str:
    """The rate shown beside the bar: ``"12,345 samples/s"`` (``"?"`` before two updates).

    Parameters
    ----------
    speed : float or None
        Units per second [1/s] (rich's estimate); ``None`` while unknown.
    unit : str
        What is counted (``"samples"``, ``"points"`` …).

    >>> format_rate(12345.6, "samples"), format_rate(0.25, "points"), format_rate(None, "samples")
    ('12,346 samples/s', '0.25 points/s', '? samples/s')
    """
    if speed is None:
        return f"? {unit}/s"
    return f"{speed:,.0f} {unit}/s" if speed >= 10 else f"{speed:.2g} {unit}/s"


class ChunkProgress:
    """A transient rich progress bar on stderr, or a no-op when disabled or not on a terminal.

    Parameters
    ----------
    total : int or None
        Units of the whole work (samples of a sampled study, else tasks); ``None`` if unknown.
    description : str
        Label in front of the bar.
    enabled : bool
        ``False``: nothing is shown (also when stderr is not a terminal).
    unit : str
        What the bar counts (``"samples"``, ``"chunks"``, ``"points"`` …), shown after the
        count and in the rate.
    """

    def __init__(
        self, total: int | None, description: str, enabled: bool, unit: str = "chunks"
    ) -> None:
        self._bar: Any = None
        self.unit = unit
        if not enabled or not sys.stderr.isatty():
            return
        from rich.console import Console
        from rich.progress import (
            BarColumn,
            MofNCompleteColumn,
            Progress,
            ProgressColumn,
            TimeElapsedColumn,
            TimeRemainingColumn,
        )
        from rich.text import Text

        class _Rate(ProgressColumn):
            """Units per second (rich's estimate over its last 30 s)."""

            def render(self, task: Any) -> Text:
                return Text(format_rate(task.speed, unit), style="progress.data.speed")

        self._bar = Progress(
            "[progress.description]{task.description}",
            BarColumn(),
            MofNCompleteColumn(),
            unit,
            _Rate(),
            TimeElapsedColumn(),
            "ETA",
            TimeRemainingColumn(),
            console=Console(stderr=True),
            transient=True,
        )
        from gearte.execution.heartbeat import hide_status

        hide_status()  # the bar is the progress now
        self._bar.start()
        self._task = self._bar.add_task(description, total=total)

    @property
    def active(self) -> bool:
        return self._bar is not None

    def advance(self, n: int = 1) -> None:
        """Count ``n`` more units done (a finished chunk's samples, or 1 task)."""
        if self._bar is not None:
            self._bar.advance(self._task, n)

    def close(self) -> None:
        if self._bar is not None:
            from gearte.execution.heartbeat import show_status

            self._bar.stop()
            self._bar = None
            show_status()

    def __enter__(self) -> ChunkProgress:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()
