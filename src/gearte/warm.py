"""Warm numba's cache: compile every kernel group a study kind uses, once, at install time.

numba caches compiled kernels on disk (``__pycache__`` beside the sources, or ``NUMBA_CACHE_DIR``)
keyed by the source file's path and modification time, so the first ``gearte run`` of each kind
after an install compiles for seconds to tens of seconds. :func:`warm_cache` runs bundled cases
(:data:`WARM_CASES`: per kind, the cases whose analyses together call every kernel of the kind)
with a small sample count and no outputs, and reports the seconds of each; ``gearte warm-cache``
prints them as they finish and ``make demo`` calls it.

Only cases that compile something are run: a case whose kernels another warm-up case already
compiled (same kernels, same argument types) is left out, and so are kinds without kernels of
their own (``gear_chain``: its stages are drives of the other kinds); warming such a kind warms
the kinds whose kernels it uses (:data:`WARM_USES`). ``benchmarks/bench_compile.py --coverage``
checks that after the warm-up no bundled case compiles anything.

In parallel (:func:`warm_cache_parallel`) the cases run in :data:`WARM_CHAINS`: cases that share
kernels run one after the other in the same process (the later ones load what the first one
compiled), chains that share none run side by side, longest first.

Later runs load the kernels from the cache (a fraction of a second per kind). Editing a source
file invalidates its kernels only.
"""

from __future__ import annotations

import importlib
import time
from collections.abc import Callable, Iterator, Sequence
from typing import Any

__all__ = [
    "WARM_ALSO",
    "WARM_CASES",
    "WARM_CHAINS",
    "WARM_USES",
    "BENCH_CASES",
    "warm_cache",
    "warm_cache_parallel",
    "warm_case_names",
]

WARM_CASES: dict[str, tuple[str, ...]] = {
    "gear_chain": (),
    "rv_bench": (),
    "rv_lot": (),
    "rv_serial": ("synthetic_rv110e_serial",),
}
"""Per study kind that is not a drive family (the families add theirs,
:func:`_add_families`), the bundled cases whose analyses together call every kernel of the kind that
no earlier warm-up case compiles (measured with ``bench_compile.py --coverage`` on 2026-11-25:
after these, every other bundled case compiles nothing — e.g. ``rv_bench`` and ``rv_lot`` use
the RV reducer's kernels, ``gear_chain`` those of its stages' kinds)."""

WARM_USES: dict[str, tuple[str, ...]] = {
    "gear_chain": ("gear_pair", "rv_reducer"),
    "rv_bench": ("rv_reducer",),
    "rv_lot": ("rv_reducer",),
}
"""Kinds without warm-up cases of their own and the kinds whose kernels their bundled cases
call (a chain's RV stage: the RV quasi-static solver; its pair stages' yield: the tolerance
Monte-Carlo): ``gearte warm-cache --kind gear_chain`` warms those (it warmed nothing, and the
first ``gear_chain`` run compiled for ~15 s CPU)."""

WARM_ALSO: dict[str, tuple[str, ...]] = {
    "jiang2024_spur_pair": ("gearte.tolerance.montecarlo:compile_general_kernel",),
    "hu2020_rv80e_initial_reducer": ("gearte.models.cycloid_contact:compile_line_contact_kernel",),
}
"""Per warm-up case, ``module:function`` compiles run after it: kernel specialisations that no
bundled case reaches but a user's case may (the Monte-Carlo kernel for a stack with a
non-normal contributor, e.g. a ``[distributions]`` override: the bundled stacks are all
normal and compile a specialisation without those draws); the tooth contact on the
line-contact law (the rv_reducer warm-up case's stage is on Hu 2020's law; ``li2023_rv_errors``
compiled it after the warm-up)."""

WARM_CHAINS: tuple[tuple[str, ...], ...] = (
    ("han2023_rv110e_yield",),  # the batched RV solver (solvers/rv_batch.py)
    # RV equilibrium, dynamics, contact; then the serial's line-contact law
    ("hu2020_rv80e_initial_reducer", "synthetic_rv110e_serial"),
    ("wang2013_2kh_eq9",),  # trig_extremes, planetary errors and assembly
    ("jiang2024_spur_pair", "hu2020_rv80e_initial"),  # tolerance Monte-Carlo; cycloid contact
)
"""The cases of :data:`WARM_CASES` in the order the parallel warm-up runs them: one chain per
process at a time, longest first; a chain's cases share kernels."""

BENCH_CASES: dict[str, str] = {
    "gear_chain": "robot_joint_spur_rv",
    "rv_bench": "synthetic_rv_bench",
    "rv_lot": "synthetic_rv110e_lot",
    "rv_serial": "synthetic_rv110e_serial",
}
"""One bundled case per kind: the first run of a kind that ``bench_compile.py`` measures."""


def _add_families() -> None:
    """The drive families' own warm-up and benchmark cases (``FAMILY.warm_cases``,
    ``FAMILY.bench_case``, :mod:`gearte.families`): the kinds above are the studies that are not
    one drive. A family whose warm-up cases share no chain above runs them as a chain of its
    own."""
    from gearte.families import families

    global WARM_CHAINS
    chained = {c for chain in WARM_CHAINS for c in chain}
    for kind, fam in families().items():
        WARM_CASES.setdefault(kind, tuple(fam.warm_cases))
        if fam.warm_uses:
            WARM_USES.setdefault(kind, tuple(fam.warm_uses))
        if fam.bench_case is not None:
            BENCH_CASES.setdefault(kind, fam.bench_case)
        new = tuple(c for c in fam.warm_cases if c not in chained)
        if new:
            WARM_CHAINS = (*WARM_CHAINS, new)
            chained.update(new)


_add_families()

WARM_SAMPLES = 256
"""Monte-Carlo sample count of the warm-up runs (enough to call every kernel once)."""


def _check(kinds: Sequence[str] | None) -> list[str]:
    from gearte.errors import ParameterError

    names = list(WARM_CASES) if kinds is None else list(kinds)
    for k in names:
        if k not in WARM_CASES:
            raise ParameterError("kinds", k, f"must be one of {sorted(WARM_CASES)}")
    return names


def _chains(kinds: Sequence[str] | None) -> list[list[tuple[str, str]]]:
    """:data:`WARM_CHAINS` as (kind, case) pairs, restricted to ``kinds`` and the kinds they use
    (:data:`WARM_USES`); empty chains dropped."""
    names = set(_check(kinds))
    names |= {u for k in list(names) for u in WARM_USES.get(k, ())}
    kind_of = {c: k for k, cases in WARM_CASES.items() for c in cases}
    out = []
    for chain in WARM_CHAINS:
        sel = [(kind_of[c], c) for c in chain if kind_of[c] in names]
        if sel:
            out.append(sel)
    return out


def warm_case_names(kinds: Sequence[str] | None = None) -> list[str]:
    """The warm-up cases that :func:`warm_cache` runs for ``kinds``, in order (for progress)."""
    return [case for chain in _chains(kinds) for _, case in chain]


def _run_one(case: str) -> tuple[float, float]:
    """Run one warm-up case in this process: (wall [s], CPU [s])."""
    from gearte.studies import RunOptions, run_case

    w, c = time.perf_counter(), time.process_time()
    run_case(case, RunOptions(progress=False, samples=WARM_SAMPLES, workers=1))
    for ref in WARM_ALSO.get(case, ()):
        module, name = ref.split(":")
        getattr(importlib.import_module(module), name)()
    return time.perf_counter() - w, time.process_time() - c


def warm_cache(
    kinds: Sequence[str] | None = None,
    *,
    report: Callable[[str, str, float], None] | None = None,
) -> Iterator[tuple[str, str, float]]:
    """Run the warm-up cases of ``kinds`` (default: all of :data:`WARM_CASES`), one by one in
    this process.

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
    for chain in _chains(kinds):
        for k, case in chain:
            if report is not None:
                report(k, case, -1.0)
            dt, _ = _run_one(case)
            if report is not None:
                report(k, case, dt)
            yield k, case, dt


_QUEUE: Any = None


def _init_worker(queue: Any) -> None:
    """Worker: keep the event queue; collect the young generation less often (it compiles,
    :mod:`gearte._gc`)."""
    global _QUEUE
    _QUEUE = queue
    from gearte._gc import set_fewer_collections

    set_fewer_collections()


def _warm_chain(chain: list[tuple[str, str]]) -> None:
    """Worker: run a chain's cases in order, reporting each through the queue."""
    for kind, case in chain:
        wall, cpu = _run_one(case)
        _QUEUE.put((kind, case, wall, cpu))


def warm_cache_parallel(
    kinds: Sequence[str] | None = None, processes: int = 2
) -> Iterator[tuple[str, str, float, float]]:
    """Warm ``kinds`` in ``processes`` worker processes, one chain of :data:`WARM_CHAINS` per
    process at a time (numba writes its cache files atomically, so processes may share the
    cache).

    Yields
    ------
    (kind, case, wall [s], CPU [s])
        As each case finishes.
    """
    import multiprocessing
    import queue as queue_mod
    from concurrent.futures import ProcessPoolExecutor

    chains = _chains(kinds)
    if not chains:
        return
    ctx = multiprocessing.get_context("spawn")
    events = ctx.Queue()
    n = max(1, min(int(processes), len(chains)))
    with ProcessPoolExecutor(
        max_workers=n, mp_context=ctx, initializer=_init_worker, initargs=(events,)
    ) as pool:
        futures = [pool.submit(_warm_chain, ch) for ch in chains]
        left = sum(len(ch) for ch in chains)
        while left:
            try:
                ev = events.get(timeout=0.2)
            except queue_mod.Empty:
                ev = None
            if ev is None:
                for f in futures:
                    if f.done() and f.exception() is not None:
                        f.result()  # raises the worker's error here
                continue
            left -= 1
            yield ev
        for f in futures:
            f.result()
