"""Check a backend: does it give the same bits as a sequential run here?

Run ``python -m gearte.execution.check tcp://host:8786`` (or ``threads``, ``processes``,
``local-cluster``) before a long study on a new cluster: it runs a small Monte-Carlo both
sequentially in this process and on the backend, compares the statistics bit for bit and reports
the workers. The chunk function is also what gearte's own tests of the execution layer ship to
Dask workers (it must be importable there, so it lives in the package).
"""

from __future__ import annotations

import argparse
import math
import sys
import time
from functools import partial
from typing import Any

import numpy as np

from gearte.execution.backends import executor_scope
from gearte.execution.mapping import map_chunks
from gearte.execution.stats import RunningStats
from gearte.execution.streams import Chunk, seeded_chunks

__all__ = ["sample_chunk", "check_backend"]


def sample_chunk(chunk: Chunk, delay_s: float = 0.0) -> RunningStats:
    """Statistics of one chunk of a small stack-up: ``e = n + u·cos φ`` [dimensionless].

    ``n ~ N(0, 1)``, ``u ~ U(-1, 1)``, ``φ ~ U(0, 2π)``; ``extra["above_3"]`` counts ``e > 3``.
    ``delay_s`` [s] sleeps first, standing in for the cost of a physics model in the loop (used
    to test fault tolerance and scheduling overhead).
    """
    if delay_s > 0:
        time.sleep(delay_s)
    rng = chunk.rng()
    e = rng.normal(size=chunk.size) + rng.uniform(-1.0, 1.0, chunk.size) * np.cos(
        rng.uniform(0.0, 2.0 * math.pi, chunk.size)
    )
    stats = RunningStats.of(e)
    stats.extra["above_3"] = float(np.count_nonzero(e > 3.0))
    stats.extra["chunks"] = 1.0
    return stats


def check_backend(
    scheduler: Any = None,
    workers: int | None = None,
    *,
    samples: int = 200_000,
    chunk_size: int = 10_000,
    seed: int = 20260101,
    delay_s: float = 0.0,
) -> dict[str, Any]:
    """Run the same seeded study sequentially and on ``scheduler``; compare the results.

    ``samples`` draws in chunks of ``chunk_size`` from ``seed``; ``delay_s`` [s] of sleep per
    chunk (to watch a cluster work); ``workers`` local threads.

    Returns
    -------
    dict
        ``identical`` (bool), ``backend``, ``workers``, ``local`` and ``remote`` statistics
        ``(count, mean, m2, min, max)``, ``elapsed [s]`` of the backend run.
    """
    chunks = seeded_chunks(samples, chunk_size, seed)
    func = partial(sample_chunk, delay_s=delay_s)
    local = map_chunks(
        func, chunks, scheduler="sequential", reduce=RunningStats.merge, progress=False
    )
    with executor_scope(scheduler, workers) as ex:
        t0 = time.perf_counter()
        remote = map_chunks(
            func, chunks, scheduler=ex, reduce=RunningStats.merge, description="check"
        )
        elapsed = time.perf_counter() - t0
        backend, nw = ex.name, ex.workers
    return {
        "identical": local.as_tuple() == remote.as_tuple() and local.extra == remote.extra,
        "backend": backend,
        "workers": nw,
        "local": local.as_tuple(),
        "remote": remote.as_tuple(),
        "elapsed [s]": elapsed,
    }


def main(argv: list[str] | None = None) -> int:
    """``python -m gearte.execution.check [SCHEDULER] [--workers N]``; exit 0 when identical."""
    from gearte.errors import GearteError

    p = argparse.ArgumentParser(prog="python -m gearte.execution.check", description=__doc__)
    p.add_argument("scheduler", nargs="?", default=None, help="address or local backend name")
    p.add_argument("--workers", type=int, default=None)
    p.add_argument("--samples", type=int, default=200_000)
    a = p.parse_args(argv)
    try:
        r = check_backend(a.scheduler, a.workers, samples=a.samples)
    except GearteError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    verdict = "identical to" if r["identical"] else "DIFFERENT from"
    print(
        f"{r['backend']} backend, {r['workers']} worker(s): {r['remote'][0]} samples in "
        f"{r['elapsed [s]']:.2f} s, statistics {verdict} the sequential run"
    )
    return 0 if r["identical"] else 1


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
