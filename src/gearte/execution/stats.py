"""Incremental, order-deterministic reductions of chunk summaries."""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

__all__ = ["RunningStats"]


@dataclass
class RunningStats:
    """Mean, variance, min and max of a stream of samples, merged chunk by chunk.

    Uses Chan et al.'s pairwise update, so merging chunk summaries in a fixed order gives the same
    bits whatever the worker that computed each chunk. Memory is constant: pass
    ``reduce=RunningStats.merge, initial=RunningStats()`` to :func:`~gearte.execution.map_chunks`.

    References
    ----------
    T. F. Chan, G. H. Golub, R. J. LeVeque, "Updating formulae and a pairwise algorithm for
    computing sample variances", Stanford CS report STAN-CS-79-773 (1979).
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
        """Combined summary (returns a new object; ``extra`` counters are added)."""
        extra = dict(self.extra)
        for k, v in other.extra.items():
            extra[k] = extra.get(k, 0.0) + v
        if other.count == 0:
            return RunningStats(self.count, self.mean, self.m2, self.min, self.max, extra)
        if self.count == 0:
            return RunningStats(other.count, other.mean, other.m2, other.min, other.max, extra)
        n = self.count + other.count
        delta = other.mean - self.mean
        mean = self.mean + delta * other.count / n
        m2 = self.m2 + other.m2 + delta * delta * self.count * other.count / n
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

    def as_tuple(self) -> tuple[int, float, float, float, float]:
        """``(count, mean, m2, min, max)``: compare two summaries bit for bit."""
        return (self.count, self.mean, self.m2, self.min, self.max)
