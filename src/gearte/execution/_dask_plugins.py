"""Dask worker plugins of gearte's ``local-cluster`` backend (imported only with Dask)."""

from __future__ import annotations

import contextlib
import signal
from typing import Any

from distributed import WorkerPlugin

__all__ = ["IgnoreSigint", "PreloadBlas"]


class IgnoreSigint(WorkerPlugin):
    """The worker process ignores SIGINT: Ctrl-C in a terminal reaches the whole process group,
    and the process that started the cluster stops the work and the cluster itself (no worker
    ``KeyboardInterrupt`` tracebacks). Applies to workers the nannies restart as well."""

    idempotent = True

    def setup(self, worker: Any) -> None:
        with contextlib.suppress(ValueError):  # not the main thread: nothing to do
            signal.signal(signal.SIGINT, signal.SIG_IGN)


class PreloadBlas(WorkerPlugin):
    """The worker loads SciPy's BLAS/LAPACK modules for numba before its first chunk
    (:func:`gearte._blas.preload_scipy_blas`): its first kernel, even one loaded from the cache,
    would otherwise import the whole ``scipy.linalg`` package (~0.3 s CPU per worker). The same
    as local worker processes' initializer (``execution.backends._worker_init``)."""

    idempotent = True

    def setup(self, worker: Any) -> None:
        from gearte._blas import preload_scipy_blas

        preload_scipy_blas()
