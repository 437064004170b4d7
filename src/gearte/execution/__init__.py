"""One execution layer for sampled and swept work: chunks, seeded streams, progress, backends.

Work is split into chunks whose sizes depend only on the problem (never on the number of
workers); each chunk gets its own random stream from ``SeedSequence(seed).spawn``. So a study
gives identical results for a seed whatever the backend (sequential, local threads, Dask) or the
worker count. Chunk results are small summaries reduced in chunk order (``RunningStats``), so
memory does not grow with the sample count.

Backends
--------
* local threads (default): the machine's cores. gearte's kernels are numba ``nogil`` functions or
  numpy calls that release the GIL, so threads run them in parallel without pickling.
* Dask distributed: pass a scheduler address (``tcp://host:8786``) or a ``distributed.Client``
  as ``scheduler``; needs the ``[cluster]`` extra.
"""

from __future__ import annotations

import math
import os
import sys
from collections.abc import Callable, Sequence
from concurrent.futures import FIRST_COMPLETED, ThreadPoolExecutor, wait
from dataclasses import dataclass, field
from typing import Any, TypeVar

import numpy as np

from gearte.errors import ParameterError, SchedulerError

__all__ = [
    "spawn_generators",
    "spawn_seeds",
    "chunk_sizes",
    "map_chunks",
    "RunningStats",
    "default_workers",
]

T = TypeVar("T")
R = TypeVar("R")


def default_workers() -> int:
    """Worker count of the local backend: the cores this process may use."""
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except AttributeError:  # pragma: no cover - non-Linux
        return max(1, os.cpu_count() or 1)


def spawn_seeds(seed: int | np.random.SeedSequence | None, n: int) -> list[np.random.SeedSequence]:
    """``n`` independent child seed sequences of ``seed`` (picklable, cheap to ship to workers)."""
    if n < 0:
        raise ParameterError("n", n, "number of streams must be ≥ 0")
    ss = seed if isinstance(seed, np.random.SeedSequence) else np.random.SeedSequence(seed)
    return list(ss.spawn(n))


def spawn_generators(
    seed: int | np.random.SeedSequence | None, n: int
) -> list[np.random.Generator]:
    """``n`` independent ``numpy.random.Generator`` objects, one per chunk, from one seed."""
    return [np.random.default_rng(s) for s in spawn_seeds(seed, n)]


def chunk_sizes(total: int, chunk: int) -> list[int]:
    """Split ``total`` samples into chunks of ``chunk`` (the last one smaller).

    >>> chunk_sizes(10, 4)
    [4, 4, 2]
    """
    if total < 0:
        raise ParameterError("samples", total, "must be ≥ 0")
    if chunk <= 0:
        raise ParameterError("chunk_size", chunk, "must be > 0")
    n = math.ceil(total / chunk) if total else 0
    return [min(chunk, total - i * chunk) for i in range(n)]


@dataclass
class RunningStats:
    """Mean, variance, min and max of a stream of samples, merged chunk by chunk.

    Uses Chan et al.'s pairwise update, so merging chunk summaries in a fixed order gives the same
    bits whatever the worker that computed each chunk.
    """

    count: int = 0
    mean: float = 0.0
    m2: float = 0.0
    min: float = math.inf
    max: float = -math.inf
    extra: dict[str, float] = field(default_factory=dict)

    @classmethod
    def of(cls, x: np.ndarray) -> RunningStats:
        """Summary of one chunk of samples."""
        x = np.asarray(x, dtype=float).ravel()
        if x.size == 0:
            return cls()
        mean = float(x.mean())
        return cls(x.size, mean, float(((x - mean) ** 2).sum()), float(x.min()), float(x.max()))

    def merge(self, other: RunningStats) -> RunningStats:
        """Combined summary (returns a new object)."""
        if other.count == 0:
            return RunningStats(**{**vars(self), "extra": dict(self.extra)})
        if self.count == 0:
            return RunningStats(**{**vars(other), "extra": dict(other.extra)})
        n = self.count + other.count
        delta = other.mean - self.mean
        mean = self.mean + delta * other.count / n
        m2 = self.m2 + other.m2 + delta * delta * self.count * other.count / n
        extra = dict(self.extra)
        for k, v in other.extra.items():
            extra[k] = extra.get(k, 0.0) + v
        return RunningStats(n, mean, m2, min(self.min, other.min), max(self.max, other.max), extra)

    @property
    def var(self) -> float:
        """Sample variance (ddof = 1)."""
        return self.m2 / (self.count - 1) if self.count > 1 else math.nan

    @property
    def sd(self) -> float:
        """Sample standard deviation (ddof = 1)."""
        return math.sqrt(self.var) if self.count > 1 else math.nan

    @property
    def standard_error(self) -> float:
        """Standard error of the mean."""
        return self.sd / math.sqrt(self.count) if self.count > 1 else math.nan


def _progress(total: int, description: str, enabled: bool) -> Any:
    """A rich progress bar, or a no-op when disabled or not on a terminal."""
    if not enabled or not sys.stderr.isatty():
        return None
    from rich.console import Console
    from rich.progress import BarColumn, MofNCompleteColumn, Progress, TimeRemainingColumn

    prog = Progress(
        "[progress.description]{task.description}",
        BarColumn(),
        MofNCompleteColumn(),
        TimeRemainingColumn(),
        console=Console(stderr=True),
        transient=True,
    )
    prog.start()
    prog.add_task(description, total=total)
    return prog


def _dask_client(scheduler: Any, timeout_s: float = 5.0) -> Any:
    try:
        from distributed import Client
    except ImportError:  # pragma: no cover - depends on extras
        raise SchedulerError(
            "a Dask scheduler was given but dask.distributed is not installed: "
            "pip install 'gearte[cluster]'"
        ) from None
    if isinstance(scheduler, Client):
        return scheduler
    try:
        return Client(scheduler, timeout=f"{timeout_s}s", set_as_default=False)
    except (OSError, TimeoutError, ValueError) as exc:
        raise SchedulerError(
            f"cannot reach the Dask scheduler at {scheduler!r} within {timeout_s:g} s ({exc}); "
            "check the address (tcp://host:8786) and that the scheduler is running"
        ) from None


def map_chunks(
    func: Callable[[T], R],
    tasks: Sequence[T],
    *,
    workers: int | None = None,
    scheduler: Any = None,
    progress: bool = True,
    description: str = "working",
    retries: int = 2,
) -> list[R]:
    """Run ``func(task)`` for every task and return the results in task order.

    Parameters
    ----------
    func : callable
        A pure function of one task (e.g. ``(chunk_size, seed_sequence)``); for Dask it must be
        picklable (a module-level function).
    tasks : sequence
        The work items, one per chunk.
    workers : int, optional
        Local threads; default :func:`default_workers`. ``1`` runs sequentially.
    scheduler : str or distributed.Client, optional
        Run on Dask instead of locally.
    progress : bool
        Progress bar over chunks (terminal only).
    description : str
        Label of the progress bar.
    retries : int
        Dask retries of a chunk whose worker was lost.
    """
    tasks = list(tasks)
    n = len(tasks)
    results: list[Any] = [None] * n
    bar = _progress(n, description, progress)
    try:
        if scheduler is not None:
            from distributed import as_completed

            client = _dask_client(scheduler)
            futures = client.map(func, tasks, pure=False, retries=retries)
            index = {f.key: i for i, f in enumerate(futures)}
            for fut in as_completed(futures):
                results[index[fut.key]] = fut.result()
                if bar is not None:
                    bar.advance(0)
            return results
        nw = default_workers() if workers is None else int(workers)
        if nw < 1:
            raise ParameterError("workers", workers, "must be ≥ 1")
        if nw == 1 or n <= 1:
            for i, t in enumerate(tasks):
                results[i] = func(t)
                if bar is not None:
                    bar.advance(0)
            return results
        with ThreadPoolExecutor(max_workers=min(nw, n)) as pool:
            pending = {pool.submit(func, t): i for i, t in enumerate(tasks)}
            while pending:
                done, _ = wait(pending, return_when=FIRST_COMPLETED)
                for fut in done:
                    results[pending.pop(fut)] = fut.result()
                    if bar is not None:
                        bar.advance(0)
        return results
    finally:
        if bar is not None:
            bar.stop()
