"""A status line for the stretches of a command that print nothing else.

``gearte run`` and ``gearte warm-cache`` spend seconds on work that has no progress bar of its own:
importing, compiling numba kernels on their first use, the analyses between two progress bars,
waiting for the report's figures. Once the command has printed nothing for :data:`AFTER_S`
seconds, :class:`Heartbeat` names the stage it is in, with the stage's elapsed time and the numba
kernel being compiled right then (numba's ``numba:compile`` event fires only when a kernel is not
in its cache). On a terminal it is one line of stderr rewritten in place, kept up to date through
the stages that follow and cleared before the command's own output; a chunk progress bar
(:class:`~gearte.execution.progress.ChunkProgress`) hides it while the bar shows. Elsewhere (a
log, a pipe) it is off unless ``GEARTE_HEARTBEAT=1``, and then prints one plain line per stage
reached in a quiet stretch, and again every :data:`LOG_EVERY_S` while a stage lasts.
"""

from __future__ import annotations

import os
import sys
import threading
import time
from typing import IO, Any

__all__ = [
    "AFTER_S",
    "LOG_EVERY_S",
    "Heartbeat",
    "hide_status",
    "numba_ready",
    "process_age",
    "show_status",
]

#: A stage is named once it has lasted this long [s].
AFTER_S = 2.0
#: Off a terminal, a running stage is named again this often [s].
LOG_EVERY_S = 15.0

_LOCK = threading.RLock()
_ACTIVE: list[Heartbeat] = []
_HIDDEN = [0]  # progress bars showing


def numba_ready() -> None:
    """numba is imported (called in the importing thread): every running status line names the
    kernels it compiles from now on."""
    with _LOCK:
        for hb in _ACTIVE:
            hb._listen_to_numba()


def hide_status() -> None:
    """Clear the status line and keep it hidden (a progress bar is about to show)."""
    with _LOCK:
        _HIDDEN[0] += 1
        for hb in _ACTIVE:
            hb._clear()


def show_status() -> None:
    """Let the status line show again (the progress bar is gone; it counts as output, so the
    line waits for the next quiet stretch)."""
    with _LOCK:
        _HIDDEN[0] = max(0, _HIDDEN[0] - 1)
        for hb in _ACTIVE:
            hb._quiet = time.perf_counter()


class _CompileListener:
    """numba ``numba:compile`` events → the heartbeat's detail (the kernel being compiled)."""

    def __init__(self, hb: Heartbeat) -> None:
        from numba.core import event

        class Listener(event.Listener):
            def on_start(self, ev: Any) -> None:
                hb._compiling_start(_kernel_name(ev))

            def on_end(self, ev: Any) -> None:
                hb._compiling_end()

        self.listener = Listener()
        event.register("numba:compile", self.listener)

    def close(self) -> None:
        from numba.core import event

        event.unregister("numba:compile", self.listener)


def _kernel_name(ev: Any) -> str:
    d = getattr(ev, "data", None) or {}
    f = getattr(d.get("dispatcher"), "py_func", None)
    return getattr(f, "__name__", "a kernel")


class Heartbeat:
    """The status line of one command (see the module docstring).

    Parameters
    ----------
    enabled : bool
        ``False``: nothing is shown (``--no-progress``).
    stream : file, optional
        Where the line goes; default ``sys.stderr``.
    after : float
        Seconds a stage lasts before it is named [s].
    interval : float
        How often the line is redrawn [s].
    quiet_since : float, optional
        ``time.perf_counter()`` of the command's last output before this (e.g. the process's
        start, :func:`process_age`); default now.
    """

    def __init__(
        self,
        enabled: bool = True,
        stream: IO[str] | None = None,
        *,
        after: float = AFTER_S,
        interval: float = 0.25,
        quiet_since: float | None = None,
    ) -> None:
        self.stream = stream if stream is not None else sys.stderr
        self.tty = bool(getattr(self.stream, "isatty", lambda: False)())
        forced = os.environ.get("GEARTE_HEARTBEAT", "") == "1"
        self.enabled = enabled and (self.tty or forced)
        self.after = after
        self.interval = interval
        self.compile_s = 0.0  # time numba spent compiling (cache misses) while this ran [s]
        self._stage: str | None = None
        self._since = 0.0  # when the current stage started
        # when the command last showed something (its own output, a progress bar, a status
        # line printed to a log): a status line shows once the command has been quiet for
        # ``after`` seconds, whichever stages the quiet stretch went through
        self._quiet = time.perf_counter() if quiet_since is None else quiet_since
        self._logged: str | None = None  # the stage last printed (off a terminal)
        self._logged_at = 0.0
        self._shown = False
        self._compiling: list[tuple[str, float]] = []
        self._numba: _CompileListener | None = None
        self._stop = threading.Event()
        self._thread: threading.Thread | None = None
        if self.enabled:
            with _LOCK:
                _ACTIVE.append(self)
            self._thread = threading.Thread(target=self._loop, name="gearte-heartbeat", daemon=True)
            self._thread.start()

    # -- the command's side ---------------------------------------------------------------------
    def stage(self, text: str | None) -> None:
        """Start a stage named ``text`` (``None``: none, the line is cleared); its clock starts
        now. A line already showing goes on showing, with the new stage."""
        with _LOCK:
            if text is None:
                self._clear()
            self._stage = text
            self._since = time.perf_counter()
        self._listen_to_numba()

    def echo(self, text: str, file: IO[str] | None = None) -> None:
        """Print a line of the command's own output to ``file`` (default stdout); the status
        line steps aside."""
        with _LOCK:
            self._clear()
            print(text, file=file if file is not None else sys.stdout, flush=True)
            self._quiet = time.perf_counter()

    def close(self) -> None:
        """Clear the line and stop."""
        self._stop.set()
        if self._thread is not None:
            self._thread.join(timeout=2.0)
        with _LOCK:
            self._clear()
            if self in _ACTIVE:
                _ACTIVE.remove(self)
        if self._numba is not None:
            self._numba.close()
            self._numba = None

    def __enter__(self) -> Heartbeat:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    # -- numba ----------------------------------------------------------------------------------
    def _listen_to_numba(self) -> None:
        """Listen to numba's compile events (from the thread that imported numba or runs the
        command, never the status thread: an import racing numba's own is unsafe)."""
        numba = sys.modules.get("numba")
        spec = getattr(numba, "__spec__", None)
        if numba is None or getattr(spec, "_initializing", False):
            return  # not imported, or being imported: numba_ready() comes after
        if self.enabled and self._numba is None:
            try:
                self._numba = _CompileListener(self)
            except Exception:  # an unexpected numba: no kernel names, the stage still shows
                self._numba = None

    def _compiling_start(self, name: str) -> None:
        with _LOCK:
            self._compiling.append((name, time.perf_counter()))

    def _compiling_end(self) -> None:
        with _LOCK:
            if self._compiling:
                _, t = self._compiling.pop()
                if not self._compiling:
                    self.compile_s += time.perf_counter() - t

    # -- the line -------------------------------------------------------------------------------
    def text(self, now: float | None = None) -> str | None:
        """The status text now, or ``None`` while nothing needs naming."""
        now = time.perf_counter() if now is None else now
        with _LOCK:
            if self._stage is None or (not self._shown and now - self._quiet < self.after):
                return None
            text = f"… {self._stage} ({now - self._since:.0f} s)"
            if self._compiling:
                name, t = self._compiling[0]
                text += (
                    f" — compiling numba kernel {name} ({now - t:.0f} s; first use, "
                    "cached for later runs)"
                )
            return text

    def _loop(self) -> None:
        while not self._stop.wait(self.interval):
            self._tick()

    def _tick(self) -> None:
        now = time.perf_counter()
        with _LOCK:
            if _HIDDEN[0]:
                return
            text = self.text(now)
            if text is None:
                return
            try:
                if self.tty:
                    width = max(20, _columns() - 1)
                    self.stream.write("\r\033[K" + text[:width])
                    self.stream.flush()
                    self._shown = True
                elif self._logged != self._stage or now - self._logged_at >= LOG_EVERY_S:
                    print(text, file=self.stream, flush=True)
                    self._logged, self._logged_at = self._stage, now
            except (OSError, ValueError):  # the stream went away: stop showing
                self._stop.set()

    def _clear(self) -> None:
        if self._shown:
            try:
                self.stream.write("\r\033[K")
                self.stream.flush()
            except (OSError, ValueError):
                pass
            self._shown = False


def process_age() -> float | None:
    """Wall time since this process started [s], or ``None`` where the system does not say
    (read from ``/proc`` on Linux)."""
    try:
        with open("/proc/self/stat", encoding="ascii") as fh:
            start_ticks = int(fh.read().rsplit(")", 1)[1].split()[19])
        with open("/proc/uptime", encoding="ascii") as fh:
            uptime = float(fh.read().split()[0])
        return max(0.0, uptime - start_ticks / os.sysconf("SC_CLK_TCK"))
    except (OSError, ValueError, IndexError, AttributeError):
        return None


def _columns() -> int:
    """The terminal's width in characters (100 when it does not say)."""
    try:
        cols = os.get_terminal_size(sys.stderr.fileno()).columns
    except (OSError, ValueError):
        return 100
    return cols if cols >= 40 else 100
