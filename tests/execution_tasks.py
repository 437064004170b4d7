"""Chunk functions for tests/test_execution.py that must be importable in worker processes."""

from __future__ import annotations

import os
from pathlib import Path

from gearte.execution.check import sample_chunk


def crash_once(task):
    """``sample_chunk`` of the chunk, but the first process to run chunk 3 dies abruptly
    (as if killed or out of memory); a marker file makes the rerun succeed."""
    marker, chunk = task
    if chunk.index == 3 and not Path(marker).exists():
        Path(marker).write_text("crashed")
        os._exit(1)
    return sample_chunk(chunk)


def weighted_chunk(chunk, shared):
    """Statistics of ``weights[k] * z`` for a shared weight table (``map_chunks(shared=...)``)."""
    import numpy as np

    from gearte.execution import RunningStats

    weights = shared["weights"]
    z = chunk.rng().standard_normal(chunk.size)
    return RunningStats.of(weights[np.arange(chunk.size) % weights.size] * z)


def kernel_modules(_task):
    """Call one cached numba kernel in this worker; whether ``scipy.linalg`` got imported (numba's
    BLAS check imports it unless :mod:`gearte._blas` preloaded its two modules)."""
    import sys

    from gearte.models.contact_law import max_contact_pressure_scalar

    max_contact_pressure_scalar(1000.0, -40.0, 3.0, 1.1e5, 10.0)
    return "scipy.linalg" in sys.modules
