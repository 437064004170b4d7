"""One execution layer for sampled and swept work: chunks, seeded streams, progress, backends.

Work is split into chunks whose sizes depend only on the problem (never on the number of
workers); each chunk gets its own random stream from ``SeedSequence(seed).spawn``; chunk results
are small summaries reduced in chunk order (``RunningStats``), so memory does not grow with the
sample count and a study gives identical results for a seed whatever the backend or worker count.

>>> from gearte.execution import RunningStats, map_chunks, seeded_chunks
>>> def chunk_stats(c):                      # a module-level function of one chunk
...     return RunningStats.of(c.rng().normal(size=c.size))
>>> s = map_chunks(chunk_stats, seeded_chunks(100_000, 10_000, seed=1), workers=2,
...                reduce=RunningStats.merge, progress=False)
>>> s.count
100000

Backends (``scheduler=``)
-------------------------
* ``None`` (default): local threads, one per core (sequential when ``workers=1``). gearte's
  kernels are numba ``nogil`` functions or numpy calls that release the GIL, so threads run them in
  parallel without pickling.
* ``"processes"``: a local process pool, for chunk functions that hold the GIL.
* a Dask scheduler address (``tcp://host:8786``), a ``distributed.Client`` or a cluster object,
  or ``"local-cluster"``: Dask distributed (the ``[cluster]`` extra). Lost workers are replaced
  and their chunks re-run by the scheduler.

Reuse one backend across many calls with ``with open_executor(...) as ex: map_chunks(...,
scheduler=ex)``. See docs/cluster.md.
"""

from __future__ import annotations

from gearte.execution.backends import (
    CONNECT_TIMEOUT_S,
    LOCAL_SCHEDULERS,
    ChunkExecutor,
    DaskExecutor,
    PoolExecutor,
    SequentialExecutor,
    executor_scope,
    open_executor,
)
from gearte.execution.mapping import map_chunks
from gearte.execution.stats import RunningStats
from gearte.execution.streams import (
    Chunk,
    chunk_sizes,
    default_workers,
    seeded_chunks,
    spawn_generators,
    spawn_seeds,
)

__all__ = [
    "spawn_generators",
    "spawn_seeds",
    "chunk_sizes",
    "Chunk",
    "seeded_chunks",
    "map_chunks",
    "RunningStats",
    "default_workers",
    "open_executor",
    "executor_scope",
    "ChunkExecutor",
    "SequentialExecutor",
    "PoolExecutor",
    "DaskExecutor",
    "LOCAL_SCHEDULERS",
    "CONNECT_TIMEOUT_S",
]
