"""The fuzzing harness (tests/fuzzing.py) at a small size, driven by hypothesis: a mutant of a
bundled case is accepted without silent coercion or rejected with one line per problem naming
the key, never an internal error; accepted mutants run through ``gearte run`` with exit 0, 1 or
2 only; a mutated measurement file is read whole or refused with one line naming the file. The
long job is ``make fuzz``."""

from __future__ import annotations

import random

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import fuzzing
from fuzzing import (
    ForkServer,
    check_measurement,
    check_text,
    corpus,
    measurement_corpus,
    mutant_text,
    mutate_csv,
    run_cli,
    run_subprocess,
    to_toml,
)

CORPUS = corpus()
NAMES = sorted(CORPUS)


def test_every_bundled_case_round_trips_through_the_fuzzer_toml_writer(tmp_path):
    for name in NAMES:
        assert check_text(to_toml(CORPUS[name]), tmp_path).status == "accepted", name


@settings(
    max_examples=60, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture]
)
@given(name=st.sampled_from(NAMES), seed=st.integers(0, 2**32 - 1))
def test_fuzzed_case_file_is_accepted_cleanly_or_rejected_naming_the_key(tmp_path, name, seed):
    text, done = mutant_text(CORPUS[name], random.Random(seed))
    out = check_text(text, tmp_path)
    assert out.status in ("accepted", "rejected"), f"{name}: {done}: {out.status} {out.detail}"


FILES = measurement_corpus()
FILE_NAMES = sorted(FILES)


def test_every_measurement_base_file_is_read_whole(tmp_path):
    for name in FILE_NAMES:
        reader, text = FILES[name]
        assert check_measurement(reader, text, tmp_path).status == "accepted", name


@settings(
    max_examples=150, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture]
)
@given(name=st.sampled_from(FILE_NAMES), seed=st.integers(0, 2**32 - 1))
def test_fuzzed_measurement_file_is_read_whole_or_refused_naming_the_file(tmp_path, name, seed):
    reader, text = FILES[name]
    mutant, done = mutate_csv(text, random.Random(seed))
    out = check_measurement(reader, mutant, tmp_path)
    assert out.status in ("accepted", "rejected"), f"{name}: {done}: {out.status} {out.detail}"


#: Kinds quick enough to run in the suite (``make fuzz`` runs mutants of every bundled case).
FAST = ["jiang2024_spur_pair", "wang2013_2kh_eq9", "jiang2024_bevel_pair", "hu2020_rv80e_initial"]


def test_fuzzed_case_files_run_with_exit_0_1_or_2_and_no_coercion(tmp_path):
    """Accepted mutants of quick bundled cases through ``gearte run`` (in this process, the
    CLI's entry point; --samples 4): never exit 3, no time-out, the recorded input keeps the
    given types."""
    rng = random.Random(2026)
    ran = []
    for i in range(400):
        name = FAST[i % len(FAST)]
        text, done = mutant_text(CORPUS[name], rng)
        if check_text(text, tmp_path).status != "accepted":
            continue
        out = run_cli(text, tmp_path, timeout_s=120)
        assert out.status in ("run_exit_0", "run_exit_1", "run_exit_2"), f"{name}: {done}: {out}"
        ran.append(out.status)
        if len(ran) == 4:
            break
    assert len(ran) == 4


def _accepted(tmp_path, names, n, seed):
    rng = random.Random(seed)
    got = []
    for i in range(100 * n):
        name = names[i % len(names)]
        text, done = mutant_text(CORPUS[name], rng)
        if check_text(text, tmp_path).status == "accepted":
            got.append((i, name, done, text))
            if len(got) == n:
                break
    return got


@pytest.fixture
def forked(monkeypatch):
    """The pids the fork server forks; :func:`_reaped` checks they are all reaped."""
    import os

    pids: list[int] = []
    real_fork = os.fork

    def fork() -> int:
        pid = real_fork()
        if pid:
            pids.append(pid)
        return pid

    monkeypatch.setattr(os, "fork", fork)
    return pids


def _reaped(pids):
    import os

    for pid in pids:
        try:
            os.waitpid(pid, os.WNOHANG)
        except ChildProcessError:
            continue
        return False
    return bool(pids)


def test_fork_server_runs_accepted_mutants_as_gearte_run_and_records_each(tmp_path, forked):
    """The long job's path: a forked child per accepted mutant runs the CLI entry point; each
    run is recorded with its exit code, message, peak RSS and CPU time, and every child is
    reaped."""
    server = ForkServer(tmp_path, workers=2, timeout_s=120)
    assert server.warm(FAST[:1]) == {FAST[0]: "run_exit_0"}  # the parent: imports and kernels
    jobs = _accepted(tmp_path, FAST[:1], 2, 7)
    for job in jobs:
        server.submit(*job)
    records = server.drain()
    assert [r.index for r in sorted(records, key=lambda r: r.index)] == [j[0] for j in jobs]
    for r in records:
        assert r.status in ("run_exit_0", "run_exit_1", "run_exit_2"), r
        assert r.code in (0, 1, 2) and r.peak_rss_mb > 0 and r.cpu_s > 0 and r.wall_s > 0
    assert _reaped(forked)
    assert [p.name for p in tmp_path.iterdir() if p.name.startswith("run")] == []


def test_fork_server_kills_and_reaps_a_run_past_its_time_out(tmp_path, monkeypatch, forked):
    import time

    monkeypatch.setattr(fuzzing, "_cli_exit_code", lambda args: time.sleep(60) or 0)
    server = ForkServer(tmp_path, workers=1, timeout_s=1.0)
    server.submit(0, "jiang2024_spur_pair", "none", to_toml(CORPUS["jiang2024_spur_pair"]))
    (r,) = server.drain()
    assert r.status == "run_timeout" and r.code is None and r.wall_s < 30
    assert _reaped(forked)


def test_fork_server_counts_a_run_past_the_memory_bound(tmp_path, monkeypatch):
    """A child that allocates past the address-space limit (the memory bound) fails to
    allocate and is counted as ``run_memory`` — a failure of the harness."""

    def hog(args):  # reserved, never touched: fails at the limit without using memory
        import numpy as np

        blocks = [np.empty(2**30, np.uint8) for _ in range(fuzzing.RUN_MEMORY_LIMIT // 2**30 + 1)]
        return len(blocks)

    monkeypatch.setattr(fuzzing, "_cli_exit_code", hog)
    server = ForkServer(tmp_path, workers=1, timeout_s=60)
    server.submit(0, "jiang2024_spur_pair", "none", to_toml(CORPUS["jiang2024_spur_pair"]))
    (r,) = server.drain()
    assert r.status == "run_memory" and r.status in fuzzing.BAD_RUN
    assert r.peak_rss_mb < fuzzing.RUN_MEMORY_LIMIT / 2**20


@pytest.mark.slow
def test_fork_server_and_real_gearte_run_processes_agree(tmp_path):
    """The same accepted mutants as real ``gearte run`` processes and through the fork server:
    same outcome and message."""
    server = ForkServer(tmp_path, workers=2, timeout_s=120)
    jobs = _accepted(tmp_path, ["jiang2024_spur_pair", "wang2013_2kh_eq9"], 2, 11)
    for job in jobs:
        server.submit(*job)
    forked = {r.index: r for r in server.drain()}
    for i, name, done, text in jobs:
        ref = run_subprocess(text, tmp_path / f"sub{i}", 120)
        assert ref.status == forked[i].status, (name, done, ref, forked[i])
        if ref.status != "run_exit_0":
            assert ref.detail.splitlines()[0][:200] == forked[i].message


def test_fork_server_stops_a_run_past_its_cpu_time_limit(tmp_path, monkeypatch, forked):
    """On a shared machine the limit is CPU time (RLIMIT_CPU), the wall time-out a backstop."""

    def spin(args):
        while True:
            pass

    monkeypatch.setattr(fuzzing, "_cli_exit_code", spin)
    server = ForkServer(tmp_path, workers=1, timeout_s=120, cpu_limit_s=1)
    server.submit(0, "jiang2024_spur_pair", "none", to_toml(CORPUS["jiang2024_spur_pair"]))
    (r,) = server.drain()
    assert r.status == "run_timeout" and "CPU" in r.message and r.cpu_s > 0.5
    assert _reaped(forked)
