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
"""

from __future__ import annotations

import contextlib
import signal
from collections.abc import Iterator
from contextvars import ContextVar
from dataclasses import dataclass, field

__all__ = ["StopScope", "keep_finished_chunks", "current_stop_scope"]


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
