"""Signals never block: a SIGINT/SIGTERM is only recorded while a backend holds the pool's locks
(``gearte.execution.stop.signals_deferred``) and acted on outside them, every wait has a
time-out, and an interrupted yield run with an allocation search keeps what finished.

The end-to-end stress harness is ``tests/signal_stress.py`` (real ``gearte run`` processes
signalled at random times); a short run of it is a test here, the full 50 + 50 trials are marked
slow (docs/errors.md, "Signals")."""

from __future__ import annotations

import os
import signal
import sys
import threading
from pathlib import Path

import pytest

from gearte.execution.stop import keep_finished_chunks, signals_deferred

TESTS = Path(__file__).resolve().parent
sys.path.insert(0, str(TESTS))
import signal_stress  # noqa: E402

posix_only = pytest.mark.skipif(sys.platform == "win32", reason="POSIX signals")


@posix_only
def test_signal_inside_the_deferred_block_is_delivered_when_it_ends():
    old = signal.signal(signal.SIGINT, signal.default_int_handler)
    try:
        reached = False
        with pytest.raises(KeyboardInterrupt), signals_deferred():
            os.kill(os.getpid(), signal.SIGINT)
            threading.Event().wait(0.05)  # the handler has run: it only recorded the signal
            reached = True
        assert reached
        assert signal.getsignal(signal.SIGINT) is signal.default_int_handler  # put back
    finally:
        signal.signal(signal.SIGINT, old)


@posix_only
def test_deferred_block_keeps_the_clis_sigterm_handler_and_its_exception():
    from gearte.errors import Interrupted

    def handler(signum, _frame):
        raise Interrupted(signum)

    old = signal.signal(signal.SIGTERM, handler)
    try:
        with pytest.raises(Interrupted) as info, signals_deferred(), signals_deferred():
            os.kill(os.getpid(), signal.SIGTERM)
            threading.Event().wait(0.05)
        assert info.value.signum == signal.SIGTERM
        assert signal.getsignal(signal.SIGTERM) is handler
    finally:
        signal.signal(signal.SIGTERM, old)


def test_deferred_block_changes_nothing_outside_the_main_thread():
    seen = []

    def body():
        before = signal.getsignal(signal.SIGINT)
        with signals_deferred():
            seen.append(signal.getsignal(signal.SIGINT) is before)

    t = threading.Thread(target=body)
    t.start()
    t.join()
    assert seen == [True]


def test_allocation_search_stopped_keeps_the_run_and_reports_no_allocation(monkeypatch):
    """A stop inside the allocation search (here: the interrupt raised in its first Monte-Carlo
    call, before any chunk finished) gives the search up, records it in the stop scope and lets
    the yield study return what it computed before."""
    import gearte.tolerance.allocation as allocation
    from gearte.tolerance.allocation import SearchStopped

    def interrupted(*_a, **_k):
        raise KeyboardInterrupt

    monkeypatch.setattr(allocation, "map_chunks", interrupted)
    with keep_finished_chunks() as scope:
        with pytest.raises(SearchStopped):
            allocation.allocate(None, _FakeTolerances(), [_Spec()], {"a": _Cost()}, 0.9, n=10)
    assert scope.stopped and scope.signum == signal.SIGINT
    assert scope.cut == ["allocation search: stopped after 0 evaluations, not reported"]
    with pytest.raises(KeyboardInterrupt):  # without a scope: the interrupt goes through
        allocation.allocate(None, _FakeTolerances(), [_Spec()], {"a": _Cost()}, 0.9, n=10)


class _Tol:
    tolerance = 1.0


class _FakeTolerances:
    families = {"a": ["a"]}
    tolerances = {"a": _Tol()}


class _Spec:
    quantity = "q"


class _Cost:
    def ladder(self, t0):
        return [t0 / 2, t0, 2 * t0]


@posix_only
@pytest.mark.parametrize(
    ("case_index", "sig", "scheduler"),
    [
        (0, signal.SIGINT, "threads"),
        (1, signal.SIGTERM, "processes"),
        (2, signal.SIGINT, "threads"),
    ],
)
def test_a_signal_at_a_random_time_never_hangs(tmp_path, case_index, sig, scheduler):
    """One trial of the stress harness per case (random delay, seeded): the run stops with
    128 + signal (finished chunks kept, marked partial, or nothing written) or had finished;
    never a hang, a traceback or another exit code."""
    import random

    name, case, extra, max_delay = signal_stress.CASES[case_index]
    delay = random.Random(case_index).uniform(0.5, min(max_delay, 4.0))
    rec = signal_stress.trial(name, case, extra, scheduler, sig, delay, 120.0, tmp_path)
    assert rec["outcome"] in ("stopped", "finished"), rec


@pytest.mark.slow
@posix_only
def test_fifty_sigint_and_fifty_sigterm_under_load_never_hang(tmp_path):
    """The full stress run (about 20 min): 50 SIGINT + 50 SIGTERM at random times to the three
    cases on threads and processes, two busy processes beside them."""
    tally = signal_stress.run(50, 2, 120.0, 33, tmp_path / "signals.jsonl")
    bad = {k: n for k, n in tally.items() if k[1] not in ("stopped", "finished")}
    assert not bad, tally


@posix_only
def test_signal_inside_numbas_compiler_waits_for_the_lock_to_be_released():
    """Raised inside numba's compiler, the interrupt left a half-built library and the run's
    later kernels failed ("no compiled object yet", exit 3): it is now delivered when the main
    thread releases the compiler lock."""
    from numba.core import event

    from gearte.execution.stop import defer_signals_while_compiling

    defer_signals_while_compiling()
    old = signal.signal(signal.SIGINT, signal.default_int_handler)
    try:
        reached = False
        with pytest.raises(KeyboardInterrupt):
            event.start_event("numba:compiler_lock")
            try:
                os.kill(os.getpid(), signal.SIGINT)
                threading.Event().wait(0.05)
                reached = True
            finally:
                event.end_event("numba:compiler_lock")
        assert reached
        assert signal.getsignal(signal.SIGINT) is signal.default_int_handler
    finally:
        signal.signal(signal.SIGINT, old)
