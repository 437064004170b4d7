"""The cyclic garbage collector in gearte's own processes: fewer young-generation passes.

numba's compiler and matplotlib's figures allocate millions of small containers (numba's IR,
type and LLVM-wrapper objects; artists, paths, transforms). With Python's default threshold
(700 allocations between two young-generation collections) the collector's passes over them
take a measurable share of the CPU:

* a first ``gearte run hu2020_rv80e_initial_reducer`` with an empty numba cache (31 kernels to
  compile): 11.23–11.38 s CPU with the defaults, 10.26–10.48 s with a young generation of
  :data:`GC_THRESHOLD0` objects (2 runs each, 2026-11-26); peak RSS 286 → 304 MB;
* the report process's figures: ~15 % of their CPU (:mod:`gearte.report.background`).

The reference cycles are still freed, only later: memory grows by the young
generation's size, not with the run. This is a setting of gearte's *own* processes — the CLI
(:func:`gearte.cli._guarded`, restored when the command returns, so an embedding process keeps
its own), its local worker processes and the report process — never of a process that imports
gearte as a library.
"""

from __future__ import annotations

import contextlib
import gc
from collections.abc import Iterator

__all__ = ["GC_THRESHOLD0", "fewer_collections", "set_fewer_collections"]

#: Allocations between two young-generation collections in gearte's processes (Python: 700).
GC_THRESHOLD0 = 50_000


def set_fewer_collections() -> None:
    """Young generation of :data:`GC_THRESHOLD0` objects, older generations collected every 20
    and 100 younger collections; for the rest of the process (worker processes)."""
    gc.set_threshold(GC_THRESHOLD0, 20, 100)


@contextlib.contextmanager
def fewer_collections() -> Iterator[None]:
    """:func:`set_fewer_collections` while the block runs, the previous thresholds after."""
    old = gc.get_threshold()
    set_fewer_collections()
    try:
        yield
    finally:
        gc.set_threshold(*old)
