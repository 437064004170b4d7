"""Execution layer (issue 7): determinism across backends, ordered incremental reduction, Dask
fault tolerance, unreachable schedulers.

One Dask ``LocalCluster`` of worker *processes* is shared by this module (start-up costs seconds).
The chunk function shipped to the workers is ``gearte.execution.check.sample_chunk``: a
module-level function of an importable module, as Dask requires.
"""

from __future__ import annotations

import logging
import os
import signal
import socket
import threading
import time
from functools import partial

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from gearte.errors import ParameterError, SchedulerError
from gearte.execution import (
    Chunk,
    RunningStats,
    map_chunks,
    open_executor,
    seeded_chunks,
)
from gearte.execution.check import check_backend, sample_chunk

distributed = pytest.importorskip("distributed")

SAMPLES, CHUNK, SEED = 120_000, 5_000, 7  # 24 chunks


def _stats(**kwargs) -> RunningStats:
    return map_chunks(
        sample_chunk,
        seeded_chunks(SAMPLES, CHUNK, SEED),
        reduce=RunningStats.merge,
        initial=RunningStats(),
        progress=False,
        **kwargs,
    )


@pytest.fixture(scope="module")
def reference() -> RunningStats:
    """The undisturbed, sequential result every backend must reproduce bit for bit."""
    return _stats(workers=1)


@pytest.fixture(scope="module")
def client():
    cluster = distributed.LocalCluster(
        n_workers=3,
        threads_per_worker=1,
        processes=True,
        dashboard_address=None,
        silence_logs=logging.CRITICAL,
    )
    c = distributed.Client(cluster, set_as_default=False)
    yield c
    c.close()
    cluster.close()


def _closed_port() -> int:
    s = socket.socket()
    s.bind(("127.0.0.1", 0))
    port = s.getsockname()[1]
    s.close()
    return port


def test_same_seed_identical_statistics_1_and_2_workers_processes_and_local_cluster(
    reference, client
):
    assert reference.count == SAMPLES and reference.extra["chunks"] == SAMPLES // CHUNK
    runs = {
        "threads, 2 workers": _stats(workers=2),
        "processes, 2 workers": _stats(scheduler="processes", workers=2),
        "dask LocalCluster (client)": _stats(scheduler=client),
        "dask LocalCluster (address)": _stats(scheduler=client.scheduler.address),
    }
    for name, s in runs.items():
        assert s.as_tuple() == reference.as_tuple(), name
        assert s.extra == reference.extra, name


def test_statistics_do_not_depend_on_chunk_size_beyond_rounding(reference):
    """Chunking changes the streams (by design), not the physics: same distribution."""
    other = map_chunks(
        sample_chunk,
        seeded_chunks(SAMPLES, 7_000, SEED),
        reduce=RunningStats.merge,
        workers=2,
        progress=False,
    )
    assert other.count == reference.count
    assert abs(other.mean - reference.mean) < 5 * reference.standard_error


def test_results_come_back_in_task_order_from_a_lazy_iterable():
    def slow_square(i: int) -> int:
        time.sleep(0.02 * ((7 - i) % 4))  # finish out of order
        return i * i

    got = map_chunks(slow_square, (i for i in range(12)), workers=2, progress=False)
    assert got == [i * i for i in range(12)]
    seen: list[int] = []
    out = map_chunks(
        slow_square, range(12), workers=2, progress=False, on_result=lambda i, r: seen.append(i)
    )
    assert out is None and seen == list(range(12))


def test_reduction_holds_a_bounded_window_behind_a_slow_first_chunk():
    events: list[tuple[str, int]] = []
    lock = threading.Lock()

    def task(i: int) -> int:
        with lock:
            events.append(("start", i))
        if i == 0:
            time.sleep(0.3)
        with lock:
            events.append(("end", i))
        return i

    total = map_chunks(
        task,
        range(20),
        workers=2,
        progress=False,
        reduce=lambda a, b: a + b,
        max_in_flight=3,
    )
    assert total == sum(range(20))
    before_first_done = events[: events.index(("end", 0))]
    assert max(i for kind, i in before_first_done if kind == "start") <= 2


def test_a_failing_chunk_propagates_its_error():
    def task(i: int) -> int:
        if i == 5:
            raise ParameterError("x", i, "fails on purpose")
        return i

    for kw in ({"workers": 1}, {"workers": 2}):
        with pytest.raises(ParameterError, match="on purpose"):
            map_chunks(task, range(10), progress=False, **kw)


def test_options_object_and_progress_bar_on_a_terminal(monkeypatch):
    from gearte.studies import RunOptions

    monkeypatch.setattr("sys.stderr.isatty", lambda: True, raising=False)
    out = map_chunks(lambda x: x + 1, range(5), options=RunOptions(workers=1, progress=True))
    assert out == [1, 2, 3, 4, 5]
    assert map_chunks(abs, [], workers=2, reduce=max, progress=False) is None


def test_bad_workers_and_scheduler_values_name_the_field():
    with pytest.raises(ParameterError, match="workers"):
        map_chunks(abs, [1], workers=0)
    with pytest.raises(ParameterError, match="scheduler"):
        open_executor(scheduler=3.5)
    with pytest.raises(SchedulerError, match="tcp://host:port"):
        open_executor("tcp://no-port-here")


def test_worker_lost_mid_study_is_retried_and_result_is_bit_identical(reference, client):
    """Kill one worker process while chunks run: none lost, none counted twice, same bits."""
    pids = client.run(os.getpid)
    killed: list[str] = []

    def kill_a_busy_worker(index: int, _result: RunningStats) -> None:
        # From the third result on, at the first result where the scheduler reports a worker
        # with chunks in hand (under load its view can lag one result behind): kill it.
        if index < 2 or killed:
            return
        busy = [w for w, keys in client.processing().items() if keys and w in pids]
        if busy:
            os.kill(pids[busy[0]], signal.SIGKILL)
            killed.append((busy[0], True))

    stats = map_chunks(
        partial(sample_chunk, delay_s=0.15),
        seeded_chunks(SAMPLES, CHUNK, SEED),
        scheduler=client,
        reduce=RunningStats.merge,
        on_result=kill_a_busy_worker,
        progress=False,
        description="worker loss",
    )
    assert len(killed) == 1, "no busy worker was killed"
    assert stats.extra["chunks"] == SAMPLES // CHUNK  # every chunk exactly once
    assert stats.as_tuple() == reference.as_tuple()
    assert stats.extra == reference.extra


def test_local_process_that_dies_is_replaced_and_its_chunks_rerun(reference, tmp_path):
    from execution_tasks import crash_once
    from gearte.execution import PoolExecutor

    marker = tmp_path / "crashed"
    tasks = [(str(marker), c) for c in seeded_chunks(SAMPLES, CHUNK, SEED)]
    with PoolExecutor("processes", 2) as ex:
        stats = map_chunks(crash_once, tasks, scheduler=ex, reduce=RunningStats.merge)
        assert ex.failures == 1
    assert marker.exists()
    assert stats.extra["chunks"] == SAMPLES // CHUNK
    assert stats.as_tuple() == reference.as_tuple()


def test_shared_data_is_passed_to_every_chunk_on_every_backend(client):
    import numpy as np

    from execution_tasks import weighted_chunk

    shared = {"weights": np.linspace(0.5, 2.0, 200_000)}  # 1.6 MB: shipped once per worker
    chunks = seeded_chunks(60_000, 5_000, 3)
    runs = [
        map_chunks(
            weighted_chunk, chunks, shared=shared, reduce=RunningStats.merge, progress=False, **kw
        ).as_tuple()
        for kw in (
            {"workers": 1},
            {"workers": 2},
            {"scheduler": "processes", "workers": 2},
            {"scheduler": client},
        )
    ]
    assert all(r == runs[0] for r in runs)
    assert runs[0][0] == 60_000


def test_client_passed_in_stays_open_and_internal_ones_are_closed(client):
    r = check_backend(client, samples=20_000, chunk_size=5_000)
    assert r["identical"] and r["backend"] == "dask"
    assert client.status == "running"
    with open_executor(client.scheduler.address) as ex:
        assert ex.workers >= 1
        out = map_chunks(
            sample_chunk, [Chunk(0, 10, seeded_chunks(10, 10, 1)[0].seed)], scheduler=ex
        )
        assert out[0].count == 10
    assert ex.client.status == "closed"
    assert client.status == "running"


def test_workers_with_another_gearte_version_are_refused(client, monkeypatch):
    import gearte._version

    monkeypatch.setattr(gearte._version, "__version__", "0.0.0+other")
    with pytest.raises(SchedulerError, match="same version"):
        open_executor(client)


def test_unreachable_scheduler_fails_fast_with_a_clear_error():
    port = _closed_port()
    t0 = time.perf_counter()
    with pytest.raises(SchedulerError, match=f"127.0.0.1:{port}"):
        map_chunks(abs, [1, 2], scheduler=f"tcp://127.0.0.1:{port}", progress=False)
    assert time.perf_counter() - t0 < 5.0


def test_silent_listener_is_not_waited_for():
    """Something accepts the connection but never speaks Dask: give up after the timeout."""
    with socket.socket() as server:
        server.bind(("127.0.0.1", 0))
        server.listen(1)
        address = f"tcp://127.0.0.1:{server.getsockname()[1]}"
        t0 = time.perf_counter()
        with pytest.raises(SchedulerError, match="no answer"):
            open_executor(address, connect_timeout_s=0.5)
        assert time.perf_counter() - t0 < 3.0


def test_missing_dask_names_the_cluster_extra(monkeypatch):
    import sys

    monkeypatch.setitem(sys.modules, "distributed", None)
    with pytest.raises(SchedulerError, match=r"gearte\[cluster\]"):
        open_executor("tcp://127.0.0.1:8786")
    # the local backends do not need it
    assert map_chunks(abs, [-1, -2], workers=2, progress=False) == [1, 2]


def test_cli_prints_an_unreachable_scheduler_without_traceback(tmp_path):
    from click.testing import CliRunner

    from gearte.cli import main

    case = tmp_path / "c.toml"
    case.write_text('[case]\nkind = "foundation_test"\n[demo]\nlength_mm = 4.0\n')
    port = _closed_port()
    r = CliRunner().invoke(
        main,
        ["run", str(case), "--scheduler", f"tcp://127.0.0.1:{port}", "--out", str(tmp_path / "o")],
    )
    assert r.exit_code == 2, r.output
    assert "scheduler" in r.output and f"127.0.0.1:{port}" in r.output
    assert "Traceback" not in r.output


@settings(max_examples=25, deadline=None)
@given(
    durations=st.lists(st.integers(0, 3), min_size=0, max_size=25),
    workers=st.integers(1, 3),
    window=st.one_of(st.none(), st.integers(1, 5)),
)
def test_results_are_handed_back_in_task_order_whatever_the_timing(durations, workers, window):
    def task(i: int) -> float:
        time.sleep(0.001 * durations[i])
        return 0.1 * i + 1e-17 * i * i  # order-sensitive floating-point sum

    order: list[int] = []
    total = map_chunks(
        task,
        range(len(durations)),
        workers=workers,
        max_in_flight=window,
        reduce=lambda a, b: a + b,
        initial=0.0,
        on_result=lambda i, r: order.append(i),
        progress=False,
    )
    expected = 0.0
    for i in range(len(durations)):
        expected += 0.1 * i + 1e-17 * i * i
    assert order == list(range(len(durations)))
    assert total == expected


def _worker_dask_settings() -> tuple[bool, str]:
    import dask

    return (
        bool(dask.config.get("distributed.worker.profile.enabled")),
        str(dask.config.get("distributed.admin.tick.interval")),
    )


def test_local_cluster_workers_run_without_profiler_and_with_a_slow_tick(reference):
    """Issue 14: the ``"local-cluster"`` gearte starts serves no dashboard, so its workers run
    without Dask's statistical profiler and with a 1 s event-loop tick (both cost worker CPU per
    second of wall time); this process's Dask settings are left as they were; same bits."""
    before = _worker_dask_settings()
    with open_executor("local-cluster", 1) as ex:
        settings = set(ex.client.run(_worker_dask_settings).values())
        assert settings == {(False, "1s")}
        assert _stats(scheduler=ex).as_tuple() == reference.as_tuple()
    assert _worker_dask_settings() == before


def test_local_cluster_with_port_8787_taken_warns_nothing(reference):
    """A second ``"local-cluster"`` on the machine (another gearte run, which Dask's default
    scheduler HTTP port 8787 would make print "Port 8787 is already in use") starts silently
    on a free port and gives the same bits."""
    import warnings

    holder = socket.socket()
    try:
        holder.bind(("127.0.0.1", 8787))
        holder.listen(1)
    except OSError:
        pass  # already taken (by another cluster on this machine): the case under test
    try:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            with open_executor("local-cluster", 1) as ex:
                assert _stats(scheduler=ex).as_tuple() == reference.as_tuple()
        assert not [w for w in caught if "8787" in str(w.message)], [str(w.message) for w in caught]
    finally:
        holder.close()


def test_progress_on_dask_counts_samples_with_the_uneven_last_chunk(client, monkeypatch):
    """Issue 14: on a Dask cluster too the bar's total is the samples (10 500) and each finished
    chunk advances it by its own size (4000, 4000, 2500); the result equals the sequential one.
    (Threads and processes: tests/test_progress_samples.py.)"""
    import gearte.execution.mapping as mapping

    seen: list = []

    class Recorder:
        def __init__(self, total, description, enabled, unit="chunks"):
            seen.append([total, unit])

        def advance(self, n=1):
            seen[-1].append(n)

        def __enter__(self):
            return self

        def __exit__(self, *exc):
            return None

    monkeypatch.setattr(mapping, "ChunkProgress", Recorder)
    kw = dict(reduce=RunningStats.merge, progress=True)
    on_dask = map_chunks(sample_chunk, seeded_chunks(10_500, 4_000, 3), scheduler=client, **kw)
    here = map_chunks(sample_chunk, seeded_chunks(10_500, 4_000, 3), workers=1, **kw)
    assert on_dask.as_tuple() == here.as_tuple()
    for total, unit, *advances in seen:
        assert (total, unit, sorted(advances)) == (10_500, "samples", [2500, 4000, 4000])


def test_local_process_workers_call_kernels_without_importing_scipy_linalg():
    """A worker process's first kernel initialises numba's CPU target, whose BLAS check imports
    the whole ``scipy.linalg`` package (~0.3 s CPU per worker) unless the worker's initializer
    preloaded the two modules it needs (:mod:`gearte._blas`, issue 12)."""
    from execution_tasks import kernel_modules
    from gearte.execution import PoolExecutor

    with PoolExecutor("processes", 1) as ex:
        assert map_chunks(kernel_modules, [0], scheduler=ex, progress=False) == [False]


def test_local_cluster_workers_call_kernels_without_importing_scipy_linalg():
    """The same for the workers of gearte's ``"local-cluster"``: a worker plugin preloads the
    two BLAS modules (:class:`gearte.execution._dask_plugins.PreloadBlas`, issue 12)."""
    from execution_tasks import kernel_modules

    with open_executor("local-cluster", 1) as ex:
        assert map_chunks(kernel_modules, [0], scheduler=ex, progress=False) == [False]
