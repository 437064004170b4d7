"""``map_chunks``: run chunk functions on a backend, results reduced in chunk order."""

from __future__ import annotations

import re
from collections.abc import Callable, Iterable, Sequence
from typing import Any, TypeVar

from gearte.errors import ClusterLostError, ParameterError
from gearte.execution.backends import ChunkExecutor, SequentialExecutor, open_executor
from gearte.execution.progress import ChunkProgress
from gearte.execution.stop import current_stop_scope
from gearte.execution.streams import Chunk

__all__ = ["map_chunks"]

T = TypeVar("T")
R = TypeVar("R")
A = TypeVar("A")

_NOTHING: Any = object()


def map_chunks(
    func: Callable[..., R],
    tasks: Iterable[T],
    *,
    workers: int | None = None,
    scheduler: Any = None,
    progress: bool | None = None,
    description: str = "working",
    retries: int = 0,
    reduce: Callable[[Any, R], Any] | None = None,
    initial: Any = _NOTHING,
    on_result: Callable[[int, R], None] | None = None,
    options: Any = None,
    max_in_flight: int | None = None,
    shared: Any = _NOTHING,
    sizes: Sequence[int] | None = None,
    unit: str | None = None,
) -> Any:
    """Run ``func(task)`` for every task; hand the results back in task order.

    Parameters
    ----------
    func : callable
        A pure function of one task (e.g. a :class:`~gearte.execution.Chunk`). For processes and
        Dask it must be picklable: a module-level function of an importable module.
    tasks : iterable
        The work items, one per chunk; their number and content must not depend on the backend
        (use :func:`~gearte.execution.seeded_chunks`). Consumed lazily.
    workers : int, optional
        Local threads or processes; default ``options.workers`` or all cores. ``1`` runs
        sequentially in this thread.
    scheduler : str, distributed.Client, cluster or ChunkExecutor, optional
        Where to run (see :func:`~gearte.execution.open_executor`); default ``options.scheduler``
        or local threads. An executor or client passed in is left open; one created here (from an
        address, ``"processes"``, ``"local-cluster"``) is shut down before returning, also on
        errors and Ctrl-C.
    progress : bool, optional
        Progress bar (terminal only; :class:`~gearte.execution.progress.ChunkProgress`): in
        samples when the sample count of every task is known (``sizes``, or tasks that are
        :class:`~gearte.execution.Chunk`), else one unit per task. Default
        ``options.progress`` or ``True``.
    description : str
        Label of the progress bar and of the Dask task keys.
    retries : int
        Dask only: extra attempts of a chunk that raised. A chunk whose worker was lost is re-run
        by the scheduler regardless.
    reduce : callable, optional
        ``acc = reduce(acc, result)``, applied in task order as results arrive; the return value
        is then the final ``acc`` and results are not kept (memory independent of the number of
        chunks). E.g. ``reduce=RunningStats.merge, initial=RunningStats()``.
    initial : any, optional
        Start value of ``reduce``; default: the first result.
    on_result : callable, optional
        ``on_result(index, result)``, called in task order (after ``reduce``).
    options : gearte.studies.RunOptions, optional
        Supplies ``workers``, ``scheduler`` and ``progress`` when those are not given.
    max_in_flight : int, optional
        Chunks submitted ahead of the first unfinished one; bounds the results held while waiting
        for a slow early chunk. Default ``4 × workers`` when reducing, unbounded otherwise.
    shared : any, optional
        Data every chunk needs (a model, a compiled system, tables): each chunk then runs as
        ``func(task, shared)``. On Dask it is sent to every worker once (scattered, broadcast)
        instead of with each task; locally it is passed as is.
    sizes : sequence of int, optional
        Samples of each task, in task order (one per task): the progress bar then counts
        samples — total ``sum(sizes)``, each finished chunk advancing it by its own size. Default:
        the tasks' ``size`` when every task is a :class:`~gearte.execution.Chunk`
        (:func:`~gearte.execution.seeded_chunks`), else none (the bar counts tasks). Progress
        only: results do not depend on it.
    unit : str, optional
        What the bar counts: default ``"samples"`` with sizes, ``"chunks"`` without.

    Returns
    -------
    list or any
        The results in task order; or the reduced value when ``reduce`` is given; or ``None``
        when only ``on_result`` is given.

    Notes
    -----
    Results are combined in task order whatever the order chunks finish in, so floating-point
    reductions give the same bits on every backend and worker count. A failing chunk cancels the
    others and its exception propagates unchanged.

    Inside :func:`gearte.execution.stop.keep_finished_chunks` (every
    :func:`gearte.studies.run_case`), a stop — SIGINT/SIGTERM or
    :class:`~gearte.errors.ClusterLostError` — after at least one chunk finished returns the
    result of the finished prefix of chunks instead of raising, and later calls run their first
    chunk only, in this thread; the scope records both (:mod:`gearte.execution.stop`).
    """
    if options is not None:
        workers = getattr(options, "workers", None) if workers is None else workers
        scheduler = getattr(options, "scheduler", None) if scheduler is None else scheduler
        progress = getattr(options, "progress", True) if progress is None else progress
    if progress is None:
        progress = True
    if max_in_flight is not None and max_in_flight < 1:
        raise ParameterError("max_in_flight", max_in_flight, "must be ≥ 1")
    total = len(tasks) if hasattr(tasks, "__len__") else None  # type: ignore[arg-type]
    if sizes is None and total and isinstance(tasks, Sequence):
        if all(isinstance(t, Chunk) for t in tasks):
            sizes = [t.size for t in tasks]
    if sizes is not None:
        sizes = [int(n) for n in sizes]
        if total is not None and len(sizes) != total:
            raise ParameterError(
                "sizes", len(sizes), f"must give one sample count per task ({total})"
            )
        if any(n < 0 for n in sizes):
            raise ParameterError("sizes", min(sizes), "sample counts must be >= 0")
    bar_total = total if sizes is None else sum(sizes)
    unit = unit or ("chunks" if sizes is None else "samples")
    keep = reduce is None and on_result is None
    label = re.sub(r"[^A-Za-z0-9_.]+", "_", description).strip("_") or "chunk"
    scope = current_stop_scope()
    if scope is not None and scope.stopped:  # the run was stopped: first chunk only, here
        tasks = list(_first(tasks))
        scheduler, progress = SequentialExecutor(), False
        scope.cut.append(f"{description}: first chunk only, of {total or '?'} (after the stop)")

    owned = not isinstance(scheduler, ChunkExecutor)
    executor = open_executor(scheduler, workers, retries=retries)
    results: list[Any] = []
    acc = initial
    try:

        def window() -> int | None:
            if executor.name == "sequential":
                return 1  # computed at submission: hand each result back before the next
            if max_in_flight is not None:
                return max_in_flight
            return None if keep else 4 * max(1, executor.workers)  # follows adaptive clusters

        if shared is _NOTHING:
            batch = executor.batch()
        else:
            batch = executor.batch(shared, has_shared=True)
        buffer: dict[int, Any] = {}
        frontier = 0  # index of the next result to hand back
        submitted = 0
        reducing = False  # an interrupt inside reduce/on_result may leave `acc` half-updated

        def hand_back() -> None:
            """Reduce / keep / report the results that are next in task order."""
            nonlocal frontier, acc, reducing
            while frontier in buffer:
                reducing = True
                result = buffer.pop(frontier)
                if keep:
                    results.append(result)
                if reduce is not None:
                    acc = result if acc is _NOTHING else reduce(acc, result)
                if on_result is not None:
                    on_result(frontier, result)
                frontier += 1
                reducing = False

        it = iter(tasks)
        exhausted = False
        with ChunkProgress(bar_total, description, bool(progress), unit) as bar:
            try:
                while True:
                    w = window()
                    while not exhausted and (w is None or submitted < frontier + w):
                        try:
                            task = next(it)
                        except StopIteration:
                            exhausted = True
                            break
                        if sizes is not None and submitted >= len(sizes):
                            raise ParameterError(
                                "sizes", len(sizes), "gives fewer sample counts than tasks"
                            )
                        batch.submit(func, task, submitted, label)
                        submitted += 1
                    if not len(batch):
                        break
                    for index, result in batch.next_done():
                        buffer[index] = result
                        bar.advance(1 if sizes is None else sizes[index])
                    hand_back()
            except BaseException as caught:
                exc = _signal_in_kernel(caught)
                stop = isinstance(exc, KeyboardInterrupt | ClusterLostError)
                if not (stop and scope is not None and not scope.stopped) or reducing:
                    batch.cancel()  # (an interrupt inside reduce: `acc` may be half-updated)
                    if exc is caught:
                        raise
                    raise exc from None
                for index, result in batch.finished():  # keep what is done, not waited for
                    buffer[index] = result
                batch.cancel()
                hand_back()
                if frontier == 0:  # nothing finished: nothing to keep
                    if exc is caught:
                        raise
                    raise exc from None
                scope.cause = exc
                kept = f"{description}: {frontier} of {total or '?'} chunks finished and kept"
                if sizes is not None:
                    kept += f" ({sum(sizes[:frontier])} of {bar_total} samples)"
                scope.cut.append(kept)
    finally:
        if owned:
            executor.close()
    if keep:
        return results
    if reduce is not None:
        return None if acc is _NOTHING else acc
    return None


def _signal_in_kernel(exc: BaseException) -> BaseException:
    """The ``KeyboardInterrupt`` behind a ``SystemError``: a signal handler that raised while a
    compiled (numba) kernel ran in this thread is reported by CPython as "returned a result with
    an exception set", caused by the interrupt. Any other exception is returned as is."""
    if isinstance(exc, SystemError) and isinstance(exc.__cause__, KeyboardInterrupt):
        return exc.__cause__
    return exc


def _first(tasks: Iterable[T]) -> Iterable[T]:
    for task in tasks:
        yield task
        return
