"""What a run keeps when it is stopped mid-way: the chunks that finished (issue 13).

:func:`gearte.studies.run_case` runs a study inside :func:`keep_finished_chunks`. Inside it,
:func:`~gearte.execution.map_chunks` does not throw finished chunks away when the run is stopped
(SIGINT/Ctrl-C, SIGTERM) or its cluster is lost (:class:`~gearte.errors.ClusterLostError`):

* the sampled analysis in flight returns the reduction of its **finished prefix** of chunks
  (chunks ``0 … k-1``; a chunk's stream does not depend on the chunk count, so this is exactly
  the result of a run with those chunks' samples), provided at least one chunk finished;
* every later sampled analysis of the run computes its **first chunk only**, in the calling
  thread (a pool or cluster may be gone), so the study still returns a complete result object;
* the scope records what was cut; ``run_case`` marks the result partial, puts the record in its
  warnings and raises :class:`~gearte.errors.Interrupted` (or the ``ClusterLostError``) with the
  partial result attached, and the CLI writes it marked ``"partial": true``.

A second Ctrl-C while the rest of the study finishes stops at once (nothing is written). Without
a scope (plain :func:`map_chunks` calls) the interrupt propagates unchanged.

**Where a signal may land.** Python runs a signal handler in the main thread between two
bytecodes, wherever that thread is — also inside :mod:`concurrent.futures`, which takes the lock
of every future it waits on one by one: a ``KeyboardInterrupt`` raised there leaves some locks
taken, and the worker that finishes such a chunk then blocks for ever, and the pool shutdown with
it (seen under load: 6 of 20 SIGINTs hung a Monte-Carlo). So the backends wait, submit, collect
and shut down inside :func:`signals_deferred`: there a SIGINT/SIGTERM only records itself, every
wait has a time-out (:data:`POLL_S`), and the recorded signal is delivered — the original
handler called — when the block ends, outside every lock.
"""

from __future__ import annotations

import contextlib
import os
import signal
import threading
from collections.abc import Iterator
from contextvars import ContextVar
from dataclasses import dataclass, field
from typing import Any

__all__ = [
    "StopScope",
    "keep_finished_chunks",
    "current_stop_scope",
    "signals_deferred",
    "POLL_S",
]

#: Longest single wait of a backend inside :func:`signals_deferred` [s]: a recorded signal is
#: acted on at most this long after it came (and as soon as the waited-for chunk finishes).
POLL_S = 0.1


@dataclass
class StopScope:
    """The stop of one run, if any, and what it cut.

    Attributes
    ----------
    cause : BaseException or None
        The ``KeyboardInterrupt`` / :class:`~gearte.errors.Interrupted` or
        :class:`~gearte.errors.ClusterLostError` that stopped the run; ``None`` while running.
    cut : list of str
        One line per sampled analysis computed from fewer chunks than asked for.
    """

    cause: BaseException | None = None
    cut: list[str] = field(default_factory=list)

    @property
    def stopped(self) -> bool:
        """True once the run was stopped (later sampled work runs its first chunk only)."""
        return self.cause is not None

    @property
    def signum(self) -> int | None:
        """The signal number of an interrupt (``SIGINT`` for a plain ``KeyboardInterrupt``), or
        ``None`` when the cause is not a signal."""
        if isinstance(self.cause, KeyboardInterrupt):
            return int(getattr(self.cause, "signum", signal.SIGINT))
        return None

    def summary(self) -> str:
        """One line saying why the run stopped and what each cut analysis used."""
        if self.signum is not None:
            why = f"stopped by {signal.Signals(self.signum).name}"
        else:
            why = f"stopped: {self.cause}"
        return f"PARTIAL result ({why}): " + "; ".join(self.cut)


_SCOPE: ContextVar[StopScope | None] = ContextVar("gearte_stop_scope", default=None)


def current_stop_scope() -> StopScope | None:
    """The innermost active :func:`keep_finished_chunks` scope of this thread, or ``None``."""
    return _SCOPE.get()


@contextlib.contextmanager
def keep_finished_chunks() -> Iterator[StopScope]:
    """``with keep_finished_chunks() as scope:`` — inside it, a stopped :func:`map_chunks` keeps
    its finished chunks (see the module docstring); ``scope.stopped`` tells afterwards."""
    scope = StopScope()
    token = _SCOPE.set(scope)
    try:
        yield scope
    finally:
        _SCOPE.reset(token)


_DEFERRED = (signal.SIGINT, signal.SIGTERM)
#: Handlers replaced by :func:`signals_deferred` (outermost block only), and the signals recorded.
_saved: dict[int, Any] = {}
_recorded: list[int] = []
_depth = 0
#: Signals inside one :func:`signals_deferred` block past which the process ends at once
#: (``os._exit(128 + signal)``): a user pressing Ctrl-C again and again while a wait would not
#: end.
FORCE_AFTER = 3
_received = 0


def _record(signum: int, _frame: object) -> None:
    """The handler inside :func:`signals_deferred`: note the signal, raise nothing."""
    global _received
    _received += 1
    if _received >= FORCE_AFTER:
        name = signal.Signals(signum).name
        os.write(2, f"gearte: {name} {_received} times: ending at once\n".encode())
        os._exit(128 + signum)
    _recorded.append(signum)


@contextlib.contextmanager
def signals_deferred() -> Iterator[None]:
    """``with signals_deferred(): ...`` — SIGINT and SIGTERM arriving inside the block are
    recorded, not raised; when the (outermost) block ends, the handlers are put back and the
    first recorded signal is delivered to its handler (a ``KeyboardInterrupt`` for Python's
    default SIGINT handler, :class:`~gearte.errors.Interrupted` for the CLI's), outside any lock
    the block took. Code inside must not block for long: wait with a time-out
    (:data:`POLL_S`) and leave the block between waits so that a recorded signal is acted on.

    Only the main thread's handlers are replaced (signals are handled there); in other threads,
    and for a signal that is ignored or left to the system (``SIG_IGN``, ``SIG_DFL``), the block
    changes nothing.
    """
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    _enter()
    try:
        yield
    finally:
        _leave()


def _enter() -> None:
    """Start a deferred section of the main thread (nested sections count)."""
    global _depth, _received
    if _depth == 0:
        _received = 0
        for sig in _DEFERRED:
            handler = signal.getsignal(sig)
            if callable(handler) and handler is not _record:
                _saved[sig] = handler
                signal.signal(sig, _record)
    _depth += 1


def _leave() -> None:
    """End a deferred section; the outermost puts the handlers back and delivers the first
    recorded signal (which may raise)."""
    global _depth
    _depth -= 1
    if _depth > 0:
        return
    saved = dict(_saved)
    _saved.clear()
    for signum, previous in saved.items():
        signal.signal(signum, previous)
    if _recorded:
        first = _recorded[0]
        _recorded.clear()
        deliver = saved.get(first)
        if callable(deliver):
            deliver(first, None)


_COMPILE_LISTENER: list[Any] = []


def defer_signals_while_compiling() -> None:
    """Make numba's compiler a deferred section (:func:`signals_deferred`) in the main thread:
    a signal that arrives while the main thread holds numba's compiler lock is delivered when
    the lock is released. Raised inside the compiler, the interrupt left a half-built library
    behind, and the run's later kernels failed with "RuntimeError: no compiled object yet"
    (exit 3; seen in the signal stress run). Call it once numba is imported (idempotent)."""
    if _COMPILE_LISTENER:
        return
    from numba.core import event

    class _Listener(event.Listener):
        def on_start(self, _event: Any) -> None:
            if threading.current_thread() is threading.main_thread():
                _enter()

        def on_end(self, _event: Any) -> None:
            if threading.current_thread() is threading.main_thread():
                _leave()

    listener = _Listener()
    event.register("numba:compiler_lock", listener)
    _COMPILE_LISTENER.append(listener)
