"""Chunking and independent random streams.

Chunk sizes depend only on the problem (total samples, chunk size), never on the number of workers,
and each chunk gets its own child of one ``SeedSequence``: chunk ``i`` draws the same numbers
whichever worker runs it, so a study's result is a function of its seed alone.
"""

from __future__ import annotations

import math
import os
from typing import NamedTuple

import numpy as np

from gearte.errors import ParameterError

__all__ = [
    "default_workers",
    "spawn_seeds",
    "spawn_generators",
    "chunk_sizes",
    "Chunk",
    "seeded_chunks",
]


def default_workers() -> int:
    """Worker count of the local backends: the cores this process may use."""
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except AttributeError:  # pragma: no cover - non-Linux
        return max(1, os.cpu_count() or 1)


def spawn_seeds(seed: int | np.random.SeedSequence | None, n: int) -> list[np.random.SeedSequence]:
    """``n`` independent child seed sequences of ``seed`` (picklable, cheap to ship to workers).

    Parameters
    ----------
    seed : int, SeedSequence or None
        The study's seed. ``None`` draws fresh entropy (results are then not reproducible).
    n : int
        Number of streams (one per chunk), ≥ 0.
    """
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


class Chunk(NamedTuple):
    """One chunk of a sampled study: its position, its sample count and its own random stream."""

    index: int  # type: ignore[assignment]  # the field shadows tuple.index, by design
    size: int
    seed: np.random.SeedSequence

    def rng(self) -> np.random.Generator:
        """The chunk's generator (a fresh one at each call, always drawing the same numbers)."""
        return np.random.default_rng(self.seed)


def seeded_chunks(total: int, chunk: int, seed: int | np.random.SeedSequence | None) -> list[Chunk]:
    """The chunks of a ``total``-sample study: ``Chunk(index, size, seed)`` each.

    The split depends on ``total`` and ``chunk`` only, so pass the result to
    :func:`~gearte.execution.map_chunks` unchanged whatever the backend.

    >>> [c.size for c in seeded_chunks(10, 4, seed=1)]
    [4, 4, 2]
    """
    sizes = chunk_sizes(total, chunk)
    seeds = spawn_seeds(seed, len(sizes))
    return [Chunk(i, n, s) for i, (n, s) in enumerate(zip(sizes, seeds, strict=True))]
