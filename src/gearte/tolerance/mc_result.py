"""The record of a tolerance Monte-Carlo run (:class:`MCResult`), apart from its kernels.

:func:`gearte.tolerance.montecarlo.monte_carlo` makes it; it lives here, in a module that imports
no numba, so that a result holding it unpickles without numba (the report process of the gear
pair and gear chain kinds, ``NUMBA_FREE_RESULTS`` in :mod:`gearte.plotting.gear_chain`). It is
still importable from :mod:`gearte.tolerance.montecarlo`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

__all__ = ["MCResult"]


@dataclass
class MCResult:
    """Statistics of a Monte-Carlo run.

    Attributes are in the unit of the stacked quantity. ``percentiles`` maps the percent level
    (e.g. ``0.135``) to the value, read off the histogram (``hist_edges``, ``hist_counts``; the
    first and last counts are the under- and overflow). ``samples`` holds the first ``keep``
    samples for plots.
    """

    n: int
    mean: float
    sd: float
    min: float
    max: float
    percentiles: dict[float, float]
    lower_spec: float | None
    upper_spec: float | None
    below_fraction: float
    above_fraction: float
    cp: float | None
    cpk: float | None
    hist_edges: np.ndarray
    hist_counts: np.ndarray
    samples: np.ndarray
    seed: int
    chunk_size: int
    engine: str
    extra: dict[str, Any] = field(default_factory=dict)

    @property
    def std_error(self) -> float:
        """Standard error of the mean, ``sd/√n``."""
        return self.sd / math.sqrt(self.n)

    @property
    def out_of_spec_fraction(self) -> float:
        return self.below_fraction + self.above_fraction
