"""Where chunks run: sequentially, on local threads or processes, or on a Dask cluster.

A backend is a :class:`ChunkExecutor`: ``submit`` a chunk, ``next_done`` the ones that finished
(in completion order; :func:`~gearte.execution.map_chunks` restores chunk order), ``close``. One
executor can serve many ``map_chunks`` calls (a sweep, a study with several sampled analyses), so a
pool or a cluster connection is made once: ``with open_executor("tcp://host:8786") as ex: ...``.

``dask.distributed`` is imported only when a Dask backend is asked for; gearte works without it.
"""

from __future__ import annotations

import concurrent.futures as cf
import contextlib
import logging
import math
import multiprocessing
import socket
import threading
import time
import uuid
from collections.abc import Callable, Iterator
from typing import Any
from urllib.parse import urlsplit

from gearte._frames import with_frame_room
from gearte.errors import ClusterLostError, ParameterError, SchedulerError
from gearte.execution.stop import POLL_S, signals_deferred
from gearte.execution.streams import default_workers

__all__ = [
    "ChunkExecutor",
    "Batch",
    "SequentialExecutor",
    "PoolExecutor",
    "DaskExecutor",
    "open_executor",
    "executor_scope",
    "LOCAL_SCHEDULERS",
    "CONNECT_TIMEOUT_S",
]

#: Names accepted as ``scheduler`` that select a local backend instead of a Dask address.
LOCAL_SCHEDULERS = ("sequential", "synchronous", "threads", "processes", "local-cluster")

#: Seconds to wait for a Dask scheduler before giving up with :class:`SchedulerError`.
CONNECT_TIMEOUT_S = 5.0

#: Dask settings of the ``"local-cluster"`` that gearte starts (no dashboard to show profiles).
_LOCAL_CLUSTER_CONFIG = {
    "distributed.worker.profile.enabled": False,
    "distributed.admin.tick.interval": "1s",
}

_CLUSTER_EXTRA = "pip install 'gearte[cluster]' (or: pip install 'dask[distributed]')"


class ChunkExecutor:
    """Runs chunk functions somewhere; the interface :func:`map_chunks` drives.

    Attributes
    ----------
    name : str
        ``"sequential"``, ``"threads"``, ``"processes"`` or ``"dask"``.
    workers : int
        Chunks that can run at once (sizes the submission window).
    """

    name = "base"
    workers = 1

    def batch(self, shared: Any = None, *, has_shared: bool = False) -> Batch:
        """A new set of chunks to submit and collect (one per :func:`map_chunks` call).

        With ``has_shared``, every chunk runs as ``func(task, shared)``; ``shared`` is shipped
        to each worker once (Dask: scattered and broadcast), not with every task.
        """
        raise NotImplementedError

    def close(self) -> None:
        """Release pools, clients and clusters this executor created (idempotent)."""

    def __enter__(self) -> ChunkExecutor:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def __repr__(self) -> str:
        return f"<{type(self).__name__} {self.name} workers={self.workers}>"


class Batch:
    """Chunks of one :func:`map_chunks` call in flight on an executor."""

    def __init__(self, extra: tuple[Any, ...] = ()) -> None:
        self.pending: dict[Any, int] = {}
        self.extra = extra  # further positional arguments of every call: (shared,) or ()

    def __len__(self) -> int:
        return len(self.pending)

    def submit(self, func: Callable[[Any], Any], task: Any, index: int, label: str) -> None:
        """Start ``func(task)`` as chunk ``index``."""
        raise NotImplementedError

    def next_done(self) -> list[tuple[int, Any]]:
        """Block until at least one chunk finished; ``[(index, result), ...]``.

        Raises the exception of a failed chunk.
        """
        raise NotImplementedError

    def cancel(self) -> None:
        """Cancel unfinished chunks (after a failure or an interrupt)."""
        self.pending.clear()

    def finished(self) -> list[tuple[int, Any]]:
        """Chunks already finished but not handed back yet, without waiting (after a stop, to
        keep what is done); ``[]`` where that cannot be known without waiting."""
        return []


class _SequentialBatch(Batch):
    def submit(self, func: Callable[[Any], Any], task: Any, index: int, label: str) -> None:
        self.pending[object()] = index
        self._result = func(task, *self.extra)

    def next_done(self) -> list[tuple[int, Any]]:
        (index,) = self.pending.values()
        self.pending.clear()
        return [(index, self._result)]


class SequentialExecutor(ChunkExecutor):
    """Runs each chunk in the calling thread when it is submitted (no parallelism, no pickling)."""

    name = "sequential"
    workers = 1

    def batch(self, shared: Any = None, *, has_shared: bool = False) -> Batch:
        return _SequentialBatch((shared,) if has_shared else ())


def _in_frame_room(func: Callable[..., Any], *args: Any) -> Any:
    """``func(*args)`` in a pool worker (thread or process) or a Dask worker, inside one roomy
    frame of CPython's frame stack (:mod:`gearte._frames`): a chunk's loops never allocate a
    stack chunk per call, whatever the worker's frames below."""
    return with_frame_room(lambda: func(*args))


class _PoolBatch(Batch):
    def __init__(self, executor: PoolExecutor, extra: tuple[Any, ...]) -> None:
        super().__init__(extra)
        self._ex = executor
        self._jobs: dict[Any, tuple[Callable[[Any], Any], Any, int]] = {}

    def submit(self, func: Callable[[Any], Any], task: Any, index: int, label: str) -> None:
        with signals_deferred():  # the pool's locks: no interrupt inside (gearte.execution.stop)
            fut = self._ex._pool.submit(_in_frame_room, func, task, *self.extra)
            self.pending[fut] = index
            self._jobs[fut] = (func, task, self._ex._generation)

    def next_done(self) -> list[tuple[int, Any]]:
        from concurrent.futures.process import BrokenProcessPool

        # cf.wait takes every future's lock: a signal is recorded there and acted on between
        # the short waits, outside the locks (gearte.execution.stop.signals_deferred)
        done: set[Any] = set()
        while not done:
            with signals_deferred():
                done, _ = cf.wait(
                    list(self.pending), timeout=POLL_S, return_when=cf.FIRST_COMPLETED
                )
        out: list[tuple[int, Any]] = []
        broken: int | None = None
        for f in done:
            try:
                with signals_deferred():
                    result = f.result()
            except BrokenProcessPool:
                broken = self._jobs[f][2]
                continue
            out.append((self.pending.pop(f), result))
            del self._jobs[f]
        if broken is not None:
            # A worker process died (killed, out of memory, crashed): every chunk still pending
            # in that pool is lost with it. Start a new pool and submit them again (same tasks,
            # same seeds, so the same results).
            self._ex._restart(broken)
            lost = list(self.pending)
            for f in lost:
                func, task, _ = self._jobs.pop(f)
                index = self.pending.pop(f)
                self.submit(func, task, index, "")
        return out

    def cancel(self) -> None:
        with signals_deferred():
            for f in self.pending:
                f.cancel()
        self._jobs.clear()
        super().cancel()

    def finished(self) -> list[tuple[int, Any]]:
        out = []
        with signals_deferred():
            for f, index in list(self.pending.items()):
                if f.done() and not f.cancelled() and f.exception() is None:
                    out.append((index, f.result()))
                    del self.pending[f]
        return out


class PoolExecutor(ChunkExecutor):
    """A local pool of threads (``kind="threads"``) or processes (``kind="processes"``).

    Threads suit gearte's kernels (numba ``nogil`` functions and numpy calls release the GIL):
    nothing is pickled. Processes suit pure-Python chunk functions; ``func`` and the tasks must
    then be picklable (module-level functions) and each process imports gearte once. When a
    process dies, the pool is replaced and its chunks run again, up to
    :attr:`allowed_failures` times.
    """

    #: Pool replacements after dead worker processes before giving up with SchedulerError.
    allowed_failures = 3
    #: Seconds worker processes get to finish at shutdown before they are terminated.
    shutdown_timeout_s = 10.0

    def __init__(self, kind: str = "threads", workers: int | None = None) -> None:
        nw = default_workers() if workers is None else int(workers)
        if nw < 1:
            raise ParameterError("workers", workers, "must be ≥ 1")
        if kind not in ("threads", "processes"):  # pragma: no cover - guarded by open_executor
            raise ParameterError("scheduler", kind, f"must be one of {LOCAL_SCHEDULERS}")
        self.name = kind
        self.workers = nw
        self.failures = 0
        self._generation = 0
        self._lock = threading.Lock()
        self._pool = self._new_pool()

    def _new_pool(self) -> cf.Executor:
        if self.name == "threads":
            return cf.ThreadPoolExecutor(self.workers, thread_name_prefix="gearte")
        methods = multiprocessing.get_all_start_methods()
        ctx = multiprocessing.get_context("forkserver" if "forkserver" in methods else "spawn")
        if ctx.get_start_method() == "forkserver":
            _start_forkserver_ignoring_sigint()
        return cf.ProcessPoolExecutor(self.workers, mp_context=ctx, initializer=_worker_init)

    def _restart(self, generation: int) -> None:
        """Replace the broken pool of ``generation`` (once, whichever batch notices first)."""
        with self._lock:
            if generation != self._generation:
                return
            self.failures += 1
            if self.failures > self.allowed_failures:
                raise SchedulerError(
                    f"local worker processes died {self.failures} times; a chunk likely runs out "
                    "of memory or crashes the interpreter — try a smaller chunk size"
                )
            _shutdown_pool(self._pool, self.shutdown_timeout_s)
            self._pool = self._new_pool()
            self._generation += 1

    def batch(self, shared: Any = None, *, has_shared: bool = False) -> Batch:
        return _PoolBatch(self, (shared,) if has_shared else ())

    def close(self) -> None:
        _shutdown_pool(self._pool, self.shutdown_timeout_s)


def _start_forkserver_ignoring_sigint() -> None:
    """Start multiprocessing's fork server (once per process) with SIGINT ignored. Ctrl-C reaches
    the whole process group: a fork server still importing its modules printed a
    ``KeyboardInterrupt`` traceback (2 of 100 signals of the stress run,
    ``tests/signal_stress.py``). An ignored signal stays ignored across ``exec``, the server then
    ignores it as it means to, and so do the workers it forks until :func:`_worker_init`. Only
    the fork and exec run with SIGINT ignored (milliseconds): a Ctrl-C then is lost, and the
    next one stops the run."""
    import signal
    from multiprocessing import forkserver

    if threading.current_thread() is not threading.main_thread():
        forkserver.ensure_running()
        return
    previous = signal.signal(signal.SIGINT, signal.SIG_IGN)
    try:
        forkserver.ensure_running()
    finally:
        signal.signal(signal.SIGINT, previous)


def die_with_parent() -> None:
    """Linux: this process gets SIGKILL when its parent dies (``PR_SET_PDEATHSIG``), so no
    worker outlives the run. A worker of a process pool is forked by multiprocessing's fork
    server, which ends when the main process does; a worker left behind after a SIGTERM to the
    group (one spawned just after it, or one blocked on the queue lock of a worker killed while
    reading) kept the terminal's pipe open (the stress run counted it as a hang). Where the
    parent is already gone, the process exits at once."""
    import os
    import signal
    import sys

    if not sys.platform.startswith("linux"):
        return
    parent = os.getppid()
    with contextlib.suppress(Exception):
        import ctypes

        pr_set_pdeathsig = 1
        ctypes.CDLL(None, use_errno=True).prctl(pr_set_pdeathsig, int(signal.SIGKILL))
    if os.getppid() != parent:  # the parent died before the request took effect
        os._exit(1)


def _worker_init() -> None:
    """Runs first in every local worker process: ignore SIGINT, die with the parent
    (:func:`die_with_parent`). Ctrl-C in a terminal reaches
    every process of the group; the main process stops the work and shuts the pool down, and
    workers must not print a ``KeyboardInterrupt`` traceback each (a SIGTERM to the group ends
    them at once, as it should: ignoring it left workers and the fork server running after the
    main process had gone). Then load SciPy's BLAS modules for
    numba (:mod:`gearte._blas`): a worker's first kernel would import all of ``scipy.linalg``
    (~0.3 s CPU per worker), and collect the young generation less often
    (:mod:`gearte._gc`: a worker may compile the kernels on a cold cache)."""
    import signal

    from gearte._blas import preload_scipy_blas
    from gearte._gc import set_fewer_collections

    signal.signal(signal.SIGINT, signal.SIG_IGN)
    die_with_parent()
    preload_scipy_blas()
    set_fewer_collections()


def _shutdown_pool(pool: cf.Executor, timeout_s: float) -> None:
    """Shut a pool down without hanging: queued chunks are cancelled; running ones get
    ``timeout_s`` to finish. Worker processes still alive then are terminated, then killed, and
    always reaped (no orphans). Threads cannot be killed: a thread
    still running its chunk after ``timeout_s`` is left to finish in the background
    (:func:`stuck_worker_threads` lists them; the CLI then ends the process without waiting
    for them). Every wait is in short slices inside
    :func:`~gearte.execution.stop.signals_deferred`, so a signal never lands inside the pool's
    locks."""
    deadline = time.monotonic() + timeout_s
    if not isinstance(pool, cf.ProcessPoolExecutor):
        threads = list(getattr(pool, "_threads", ()) or ())
        with signals_deferred():
            pool.shutdown(wait=False, cancel_futures=True)
        for t in threads:
            while t.is_alive() and time.monotonic() < deadline:
                with signals_deferred():
                    t.join(POLL_S)
        return
    procs = list((getattr(pool, "_processes", None) or {}).values())
    with signals_deferred():
        pool.shutdown(wait=False, cancel_futures=True)
    for p in procs:
        while p.is_alive() and time.monotonic() < deadline:
            with signals_deferred():
                p.join(POLL_S)
    for p in procs:
        if p.is_alive():
            p.terminate()
            with signals_deferred():
                p.join(2.0)
        if p.is_alive():  # pragma: no cover - SIGTERM ignored
            p.kill()
            with signals_deferred():
                p.join(5.0)


def quiet_pool_manager_after_stop() -> None:
    """Silence one known traceback of CPython 3.11's process pool: when a SIGTERM to the process
    group ends the workers while the main process cancels its queued chunks, the pool's manager
    thread marks every chunk it still holds as failed and raises ``InvalidStateError`` on the
    cancelled ones (``terminate_broken``); nothing is lost (the main process has stopped), but
    the traceback reached the terminal. Every other thread exception is reported as before.
    Installed by the CLI."""
    from concurrent.futures.process import _ExecutorManagerThread

    previous = threading.excepthook
    if getattr(previous, "_gearte_quiet", False):  # installed already
        return

    def hook(args: Any) -> None:
        if isinstance(args.thread, _ExecutorManagerThread) and isinstance(
            args.exc_value, cf.InvalidStateError
        ):
            return
        previous(args)

    hook._gearte_quiet = True  # type: ignore[attr-defined]
    threading.excepthook = hook


def stuck_worker_threads() -> list[threading.Thread]:
    """gearte's pool threads still running a chunk (after a stop whose shutdown did not wait
    for them, :func:`_shutdown_pool`)."""
    return [t for t in threading.enumerate() if t.name.startswith("gearte") and t.is_alive()]


def _import_distributed() -> Any:
    try:
        import distributed
    except ImportError:
        raise SchedulerError(
            "a Dask scheduler was asked for but dask.distributed is not installed: "
            + _CLUSTER_EXTRA
        ) from None
    return distributed


def _probe_tcp(address: str, timeout_s: float) -> None:
    """Fail fast (milliseconds, not the full timeout) when nothing listens at a tcp address."""
    parts = urlsplit(address if "://" in address else f"tcp://{address}")
    if parts.scheme not in ("tcp", "tls"):
        return
    try:
        host, port = parts.hostname, parts.port
    except ValueError as exc:
        raise SchedulerError(f"invalid Dask scheduler address {address!r}: {exc}") from None
    if not host or port is None:
        raise SchedulerError(
            f"invalid Dask scheduler address {address!r}: expected tcp://host:port "
            "(the scheduler's default port is 8786)"
        )
    try:
        with socket.create_connection((host, port), timeout=timeout_s) as sock:
            if parts.scheme == "tcp":
                # A Dask server speaks first (its handshake): silence means something else.
                sock.settimeout(timeout_s)
                if not sock.recv(1, socket.MSG_PEEK):
                    raise ConnectionResetError(0, "closed the connection at once")
    except TimeoutError:
        raise SchedulerError(
            f"no answer from a Dask scheduler at {address!r} within {timeout_s:g} s; check the "
            "address and port (the scheduler's default port is 8786)"
        ) from None
    except OSError as exc:
        reason = exc.strerror or type(exc).__name__
        raise SchedulerError(
            f"cannot reach the Dask scheduler at {address!r} ({reason}); check the address and "
            "that `dask scheduler` is running there and the port is open"
        ) from None


def _connect(distributed: Any, address: str, timeout_s: float) -> Any:
    """``distributed.Client(address)``, given up after ``timeout_s`` (plus a grace second).

    The client's own timeout does not cover every stage of the handshake, so it is built in a
    watchdog thread; a client that never answers is abandoned rather than waited for.
    """
    box: dict[str, Any] = {}

    def target() -> None:
        try:
            box["client"] = distributed.Client(
                address, timeout=f"{timeout_s}s", set_as_default=False
            )
        except BaseException as exc:  # noqa: BLE001 - handed to the calling thread
            box["error"] = exc

    th = threading.Thread(target=target, name="gearte-dask-connect", daemon=True)
    th.start()
    th.join(timeout_s + 1.0)
    if th.is_alive():
        raise SchedulerError(
            f"the Dask scheduler at {address!r} did not complete the connection within "
            f"{timeout_s:g} s; check the address, the port and the network"
        )
    exc = box.get("error")
    if isinstance(exc, OSError | TimeoutError):
        raise SchedulerError(
            f"cannot connect to the Dask scheduler at {address!r} within {timeout_s:g} s "
            f"({exc}); check the address (tcp://host:8786) and that the scheduler is running"
        ) from None
    if exc is not None:
        raise SchedulerError(
            f"{address!r} does not answer as a Dask scheduler ({type(exc).__name__}: {exc}); "
            "check the address and port"
        ) from None
    return box["client"]


def _worker_gearte_version() -> str:
    """Runs on each Dask worker: the gearte version it imports."""
    from gearte._version import __version__

    return __version__


class DaskExecutor(ChunkExecutor):
    """Chunks as Dask futures on a distributed cluster.

    Parameters
    ----------
    scheduler : str or distributed.Client or distributed.deploy.Cluster
        A scheduler address (``tcp://host:8786``), a connected ``Client`` (left open on
        :meth:`close`), a cluster object (``LocalCluster``, dask-jobqueue, dask-kubernetes; left
        running), or ``"local-cluster"`` to start a ``LocalCluster`` of ``workers`` processes here
        (shut down on :meth:`close`).
    workers : int, optional
        Worker processes of a ``"local-cluster"``.
    retries : int
        Extra attempts of a chunk that *raised*. A chunk whose worker died is re-run by the
        scheduler regardless (up to ``distributed.scheduler.allowed-failures`` times).
    connect_timeout_s : float
        How long to wait for the scheduler.
    no_worker_timeout_s : float, optional
        Seconds chunks may wait on a cluster without any worker before the cluster counts as
        lost (:class:`~gearte.errors.ClusterLostError`; finished chunks are kept inside
        :func:`gearte.studies.run_case`); ``0`` waits forever. Default: the environment
        variable ``GEARTE_NO_WORKER_TIMEOUT_S`` or 300 s (queued HPC workers may need more).
    check_versions : bool
        Check that every worker imports the same gearte version as this process.

    Notes
    -----
    Each chunk becomes one future with a unique key; its result is fetched once and released, and
    :func:`map_chunks` reduces results in chunk order. A lost worker only makes the scheduler run
    its chunks again elsewhere — from the same task (same seed), so with the same result — hence
    nothing is lost or counted twice.
    """

    name = "dask"

    def __init__(
        self,
        scheduler: Any,
        workers: int | None = None,
        *,
        retries: int = 0,
        connect_timeout_s: float = CONNECT_TIMEOUT_S,
        no_worker_timeout_s: float | None = None,
        check_versions: bool = True,
    ) -> None:
        if no_worker_timeout_s is None:
            from gearte.limits import no_worker_timeout_s as _default

            no_worker_timeout_s = _default()
        self.no_worker_timeout_s = float(no_worker_timeout_s)
        distributed = _import_distributed()
        self._owned: list[Any] = []
        self._workers, self._workers_at = 1, -math.inf
        self.retries = int(retries)
        self._token = uuid.uuid4().hex[:8]
        try:
            if isinstance(scheduler, distributed.Client):
                self.client = scheduler
            elif scheduler == "local-cluster":
                nw = default_workers() if workers is None else int(workers)
                if nw < 1:
                    raise ParameterError("workers", workers, "must be ≥ 1")
                # No dashboard, so no use for the workers' statistical profiler (it samples the
                # running chunk's stack every 10 ms and keeps an hour of profiles) nor for a
                # 20 ms event-loop watchdog tick: both cost CPU per second of wall time, not per
                # chunk (an idle worker: 35–41 → 9–12 ms CPU per s; docs/cluster.md).
                import dask

                with dask.config.set(_LOCAL_CLUSTER_CONFIG):
                    cluster = distributed.LocalCluster(
                        n_workers=nw,
                        threads_per_worker=1,
                        processes=True,
                        dashboard_address=None,
                        # the scheduler's HTTP server (health and metrics routes; no dashboard)
                        # on a free port: on 8787, Dask's default, a second local cluster on the
                        # machine (another gearte run) printed "Port 8787 is already in use"
                        scheduler_kwargs={"dashboard_address": ":0"},
                        silence_logs=logging.ERROR,
                    )
                self._owned.append(cluster)
                self.client = distributed.Client(cluster, set_as_default=False)
                self._owned.insert(0, self.client)
                # Ctrl-C in a terminal reaches the local workers too: they ignore it (also
                # workers the nannies restart), this process stops the work and the cluster.
                # And they load numba's BLAS modules without scipy.linalg (gearte._blas).
                from gearte.execution._dask_plugins import IgnoreSigint, PreloadBlas

                self.client.register_plugin(IgnoreSigint(), name="gearte-ignore-sigint")
                self.client.register_plugin(PreloadBlas(), name="gearte-preload-blas")
            elif isinstance(scheduler, str):
                _probe_tcp(scheduler, connect_timeout_s)
                self.client = _connect(distributed, scheduler, connect_timeout_s)
                self._owned.append(self.client)
            elif hasattr(scheduler, "scheduler_address"):  # a Cluster object
                self.client = distributed.Client(scheduler, set_as_default=False)
                self._owned.append(self.client)
            else:
                raise ParameterError(
                    "scheduler",
                    scheduler,
                    "must be a Dask address (tcp://host:8786), a distributed.Client, a cluster, "
                    f"a gearte ChunkExecutor or one of {LOCAL_SCHEDULERS}",
                )
            if check_versions:
                self._check_versions()
        except BaseException:
            self.close()
            raise

    @property
    def workers(self) -> int:  # type: ignore[override]
        """Worker threads of the cluster now (asked at most once a second: clusters adapt)."""
        now = time.monotonic()
        if now - self._workers_at > 1.0:
            try:
                self._workers = max(1, sum(self.client.nthreads().values()))
            except Exception:  # noqa: BLE001 - a sizing hint only
                self._workers = 1
            self._workers_at = now
        return self._workers

    def _check_versions(self) -> None:
        from gearte._version import __version__

        try:
            versions = self.client.run(_worker_gearte_version)
        except Exception as exc:  # noqa: BLE001 - unpickling fails where gearte is missing
            raise SchedulerError(
                f"the Dask workers cannot run gearte ({type(exc).__name__}: {exc}); install "
                f"gearte {__version__} in the workers' environment"
            ) from None
        wrong = {w: v for w, v in versions.items() if v != __version__}
        if wrong:
            listed = ", ".join(f"{w} has {v}" for w, v in sorted(wrong.items()))
            raise SchedulerError(
                f"Dask workers run another gearte version than this process "
                f"({__version__}): {listed}; install the same version everywhere"
            )

    def batch(self, shared: Any = None, *, has_shared: bool = False) -> Batch:
        extra: tuple[Any, ...] = ()
        if has_shared:  # shipped once to every worker, not with each of the tasks
            extra = (self.client.scatter(shared, broadcast=True, hash=False),)
        return _DaskBatch(self, extra)

    def close(self) -> None:
        for obj in getattr(self, "_owned", []):
            with contextlib.suppress(Exception):
                obj.close()
        self._owned = []

    def __repr__(self) -> str:
        return f"<DaskExecutor {getattr(self.client, 'scheduler', None)}>"


class _DaskBatch(Batch):
    def __init__(self, executor: DaskExecutor, extra: tuple[Any, ...]) -> None:
        super().__init__(extra)
        self._ex = executor
        self._ac: Any = None

    def submit(self, func: Callable[[Any], Any], task: Any, index: int, label: str) -> None:
        ex = self._ex
        key = f"gearte-{label}-{ex._token}-{index}"
        fut = ex.client.submit(
            _in_frame_room, func, task, *self.extra, key=key, retries=ex.retries, pure=False
        )
        self.pending[fut] = index
        if self._ac is None:
            self._ac = _import_distributed().as_completed([fut], loop=ex.client.loop)
        else:
            self._ac.add(fut)

    def _wait_ready(self) -> None:
        """Wait for a finished chunk, watching the cluster: no worker for longer than
        ``no_worker_timeout_s`` (or no scheduler) is a lost cluster, not an endless wait."""
        ex, ac = self._ex, self._ac
        checked, alone_since = time.monotonic(), None
        cond = getattr(ac, "thread_condition", None)
        while not ac.has_ready() and not ac.is_empty():
            if cond is not None:
                with signals_deferred(), cond:  # no interrupt while the lock is held
                    cond.wait(timeout=POLL_S)
            else:  # pragma: no cover - other distributed versions
                time.sleep(0.1)
            now = time.monotonic()
            if ex.no_worker_timeout_s <= 0 or now - checked < 1.0:
                continue
            checked = now
            if ex.client.nthreads():
                alone_since = None
                continue
            alone_since = now if alone_since is None else alone_since
            if now - alone_since > ex.no_worker_timeout_s:
                raise ClusterLostError(
                    f"the Dask cluster has had no worker for {ex.no_worker_timeout_s:g} s "
                    f"with {len(self.pending)} chunk(s) waiting (workers killed or gone; "
                    "GEARTE_NO_WORKER_TIMEOUT_S sets the wait, 0 waits forever)"
                )

    def next_done(self) -> list[tuple[int, Any]]:
        distributed = _import_distributed()
        from distributed.comm import CommClosedError

        try:
            self._wait_ready()
            batch = self._ac.next_batch(block=True)
            results = self._ex.client.gather(batch)
        except distributed.KilledWorker as exc:
            raise SchedulerError(
                f"a chunk killed its Dask workers repeatedly ({exc}); it likely runs out of "
                "memory or crashes the interpreter — try a smaller chunk size"
            ) from None
        except (CommClosedError, OSError) as exc:
            raise ClusterLostError(f"lost the connection to the Dask scheduler ({exc})") from None
        except distributed.client.FutureCancelledError as exc:
            raise SchedulerError(f"the Dask scheduler cancelled a chunk ({exc})") from None
        out = [(self.pending.pop(f), r) for f, r in zip(batch, results, strict=True)]
        for fut in batch:
            fut.release()
        return out

    def finished(self) -> list[tuple[int, Any]]:
        out = []
        for f, index in list(self.pending.items()):
            if f.status == "finished":
                with contextlib.suppress(Exception):  # a lost cluster: keep what can be had
                    out.append((index, f.result(timeout=2.0)))
                    del self.pending[f]
        return out

    def cancel(self) -> None:
        with contextlib.suppress(Exception):
            self._ex.client.cancel(list(self.pending))
        if self._ac is not None:
            with contextlib.suppress(Exception):
                self._ac.clear()
        super().cancel()


def open_executor(
    scheduler: Any = None,
    workers: int | None = None,
    *,
    retries: int = 0,
    connect_timeout_s: float = CONNECT_TIMEOUT_S,
) -> ChunkExecutor:
    """The executor for a ``scheduler`` / ``workers`` pair (use it as a context manager).

    Parameters
    ----------
    scheduler : None, str, distributed.Client, cluster or ChunkExecutor
        ``None``: local threads (sequential when ``workers == 1``). ``"sequential"``
        (alias ``"synchronous"``), ``"threads"``, ``"processes"``: local backends.
        ``"local-cluster"``: a Dask ``LocalCluster`` of ``workers`` processes started here.
        Any other string: a Dask scheduler address. A ``Client`` or a cluster object: use it.
        A ``ChunkExecutor``: returned as is.
    workers : int, optional
        Local threads or processes; default: the cores this process may use.
    retries : int
        Dask only: extra attempts of a chunk that raised.
    connect_timeout_s : float
        Dask only: time to wait for the scheduler before :class:`SchedulerError` [s].

    Raises
    ------
    SchedulerError
        The scheduler cannot be reached, dask.distributed is missing, or the workers run another
        gearte version.
    """
    if isinstance(scheduler, ChunkExecutor):
        return scheduler
    if workers is not None and int(workers) < 1:
        raise ParameterError("workers", workers, "must be ≥ 1")
    if scheduler is None:
        if workers is not None and int(workers) == 1:
            return SequentialExecutor()
        return PoolExecutor("threads", workers)
    if isinstance(scheduler, str):
        s = scheduler.strip()
        if s in ("sequential", "synchronous"):
            return SequentialExecutor()
        if s in ("threads", "processes"):
            return PoolExecutor(s, workers)
        if not s:
            raise ParameterError("scheduler", scheduler, "empty scheduler address")
        scheduler = s
    return DaskExecutor(scheduler, workers, retries=retries, connect_timeout_s=connect_timeout_s)


@contextlib.contextmanager
def executor_scope(
    scheduler: Any = None, workers: int | None = None, **kwargs: Any
) -> Iterator[ChunkExecutor]:
    """``with executor_scope(scheduler, workers) as ex:`` — :func:`open_executor`, closed at the
    end only if it was opened here (an executor passed in stays open for its owner)."""
    ex = open_executor(scheduler, workers, **kwargs)
    try:
        yield ex
    finally:
        if ex is not scheduler:
            ex.close()
