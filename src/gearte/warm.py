"""Warm numba's cache: compile every kernel group a study kind uses, once, at install time.

numba caches compiled kernels on disk (``__pycache__`` beside the sources, or ``NUMBA_CACHE_DIR``)
keyed by the source file's path and modification time, so the first ``gearte run`` of each kind
after an install compiles for seconds to tens of seconds. :func:`warm_cache` runs one bundled
case per kind (the group of kernels that kind uses: the cases are chosen so that their analyses
call every kernel of the kind) with a small sample count and no outputs, and reports the seconds
of each; ``gearte warm-cache`` prints them as they finish and ``make demo`` calls it.

Later runs load the kernels from the cache (a fraction of a second per kind). Editing a source
file invalidates its kernels only.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Iterator, Sequence

__all__ = ["WARM_CASES", "warm_cache", "warm_cache_parallel"]

WARM_CASES: dict[str, tuple[str, ...]] = {
    "cycloid_stage": ("hu2020_rv80e_initial", "hu2020_rv80e_yield"),
    "gear_pair": ("jiang2024_spur_pair", "jiang2024_bevel_pair"),
    "gear_chain": ("jiang2024_shoulder_swing",),
    "planetary": ("wang2013_2kh_eq9", "wang2013_2kh_eq9_yield"),
    "rv_reducer": ("hu2020_rv80e_initial_reducer", "li2023_rv", "han2023_rv110e_yield"),
    "rv_bench": ("synthetic_rv_bench",),
    "rv_lot": ("synthetic_rv110e_lot",),
    "rv_serial": ("synthetic_rv110e_serial",),
}
_LONGEST_FIRST = ("rv_reducer", "rv_lot", "planetary", "cycloid_stage", "gear_pair")
"""Per study kind, the bundled cases whose analyses together call every kernel of the kind."""

WARM_SAMPLES = 256
"""Monte-Carlo sample count of the warm-up runs (enough to call every kernel once)."""


def warm_cache(
    kinds: Sequence[str] | None = None,
    *,
    report: Callable[[str, str, float], None] | None = None,
) -> Iterator[tuple[str, str, float]]:
    """Run the warm-up cases of ``kinds`` (default: all of :data:`WARM_CASES`), one by one.

    Parameters
    ----------
    kinds : sequence of str, optional
        Study kinds to warm; unknown names raise :class:`~gearte.errors.ParameterError`.
    report : callable, optional
        Called as ``report(kind, case, seconds)`` with ``seconds`` [s] = -1 before each case
        starts and its wall time after it ends, for progress output.

    Yields
    ------
    (kind, case, seconds)
        Wall seconds of each warm-up run [s] (compile + the small run).
    """
    from gearte.studies import RunOptions, run_case

    names = _check(kinds)
    opts = RunOptions(progress=False, samples=WARM_SAMPLES, workers=1)
    for k in names:
        for case in WARM_CASES[k]:
            if report is not None:
                report(k, case, -1.0)
            t0 = time.perf_counter()
            run_case(case, opts)
            dt = time.perf_counter() - t0
            if report is not None:
                report(k, case, dt)
            yield k, case, dt


def _check(kinds: Sequence[str] | None) -> list[str]:
    from gearte.errors import ParameterError

    names = list(WARM_CASES) if kinds is None else list(kinds)
    for k in names:
        if k not in WARM_CASES:
            raise ParameterError("kinds", k, f"must be one of {sorted(WARM_CASES)}")
    return names


def _warm_kind(kind: str) -> list[tuple[str, float, float]]:
    """Warm one kind in this process: (case, wall [s], CPU [s]) per case."""
    from gearte.studies import RunOptions, run_case

    out = []
    for case in WARM_CASES[kind]:
        w, c = time.perf_counter(), time.process_time()
        run_case(case, RunOptions(progress=False, samples=WARM_SAMPLES, workers=1))
        out.append((case, time.perf_counter() - w, time.process_time() - c))
    return out


def warm_cache_parallel(
    kinds: Sequence[str] | None = None, processes: int = 2
) -> Iterator[tuple[str, list[tuple[str, float, float]]]]:
    """Warm ``kinds`` in ``processes`` worker processes (numba's cache files are written
    atomically, so processes may share the cache), longest kinds first.

    Yields
    ------
    (kind, [(case, wall [s], CPU [s]), ...])
        As each kind finishes.
    """
    import multiprocessing
    from concurrent.futures import ProcessPoolExecutor, as_completed

    names = _check(kinds)
    names.sort(key=lambda k: _LONGEST_FIRST.index(k) if k in _LONGEST_FIRST else 99)
    ctx = multiprocessing.get_context("spawn")
    with ProcessPoolExecutor(max_workers=max(1, int(processes)), mp_context=ctx) as pool:
        futures = {pool.submit(_warm_kind, k): k for k in names}
        for f in as_completed(futures):
            yield futures[f], f.result()
