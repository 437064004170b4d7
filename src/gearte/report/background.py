"""A report renderer that gets ready while the analyses run.

Most of a warm ``gearte run`` of a fast case is not the analyses: importing matplotlib (~0.5 s),
building the figures and drawing them. :class:`ReportWorker` forks, at the command's start
(before the case is loaded), a process that imports the plotting stack, draws one throw-away
figure (fonts, text layout caches) and imports the case's study kind while the parent loads the
case, imports numba, loads its kernels and runs the analyses on the other core. The parent then
sends it the result (pickled); the worker builds the figures, renders them (itself forking one
helper per further core, :func:`gearte.report.html.render_figures`) and the HTML, and sends back
the page and the stage timings, while the parent writes the CSV tables.

Nothing depends on it: where ``os.fork`` is missing, the worker died, the result does not
pickle, or anything in the worker fails, the parent renders in-process as before (an error of a
plotting function then surfaces there, with its traceback under ``--debug``). The worker ignores
SIGINT (the parent, interrupted, ends it), dies with its parent (Linux ``PR_SET_PDEATHSIG``) and
exits when its request pipe closes.
"""

from __future__ import annotations

import contextlib
import os
import pickle
import signal
import sys
from typing import Any

__all__ = ["ReportWorker", "warm_up_plotting"]


def warm_up_plotting(case: Any = None) -> None:
    """Import what building, rendering and the HTML page need, and draw one small figure with
    text to PNG (loads the font and fills matplotlib's text caches); with ``case`` (what
    :func:`gearte.io.case_file.load_case` takes), also import its study kind (what unpickling
    its result needs; the case is not validated here). A case whose kind cannot be read is
    ignored here (unpickling imports what it needs)."""
    import io

    import jinja2  # noqa: F401
    from matplotlib.backends import backend_agg  # noqa: F401

    import gearte.plotting.display  # noqa: F401
    import gearte.report.html  # noqa: F401
    import gearte.report.summary  # noqa: F401
    import gearte.report.tables  # noqa: F401
    from gearte.plotting import new_figure

    fig, ax = new_figure(figsize=(2.0, 1.5))
    ax.plot([1.0, 2.0], [1.0, 100.0], label="x")
    ax.set_yscale("log")  # builds the mathtext parser of log tick labels (~0.1 s once)
    ax.set_xlabel("0123456789 [mm]")
    ax.set_ylabel("−.,e+ [arcmin]")
    ax.set_title("Warm-up")
    ax.legend()
    fig.savefig(io.BytesIO(), format="png", dpi=50)
    if case is not None:
        with contextlib.suppress(Exception):
            kind = _kind_of(case)
            if kind:
                from gearte.io.kinds import get_kind

                get_kind(kind)


def _kind_of(case: Any) -> str | None:
    """The ``[case] kind`` of a case as :func:`gearte.io.case_file.load_case` takes it (a dict,
    a TOML file or a bundled name), read without validating; ``None`` where it has none."""
    if not isinstance(case, dict):
        import tomllib

        from gearte.cases import case_path

        with open(case_path(case), "rb") as fh:
            case = tomllib.load(fh)
    meta = case.get("case") if isinstance(case, dict) else None
    kind = meta.get("kind") if isinstance(meta, dict) else None
    return kind if isinstance(kind, str) else None


def _no_setter_docstrings() -> None:
    """Skip the docstrings matplotlib writes for each artist class's ``set`` method as it imports
    (``matplotlib.artist.kwdoc``: every setter of every artist listed, ~0.15 s of importing the
    plotting stack). Only in the report process, which never reads a docstring; call it before
    matplotlib's artists are imported. The figures and the PNGs are unchanged."""
    with contextlib.suppress(Exception):
        import matplotlib.artist

        matplotlib.artist.kwdoc = lambda artist: ""


def _die_with_parent() -> None:
    """Linux: this process gets SIGKILL when its parent dies (no orphaned renderer)."""
    if not sys.platform.startswith("linux"):
        return
    with contextlib.suppress(Exception):
        import ctypes

        pr_set_pdeathsig = 1
        ctypes.CDLL(None, use_errno=True).prctl(pr_set_pdeathsig, int(signal.SIGKILL))


def _read_all(fd: int) -> bytes:
    chunks: list[bytes] = []
    while True:
        b = os.read(fd, 1 << 20)
        if not b:
            return b"".join(chunks)
        chunks.append(b)


def _write_all(fd: int, data: bytes) -> None:
    view = memoryview(data)
    while view:
        view = view[os.write(fd, view) :]


def _serve(req: int, resp: int, parent: int, case: Any) -> None:
    """The worker's life: warm up, wait for one result, send back (html, timings)."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGTERM, signal.SIG_DFL)
    _die_with_parent()
    if os.getppid() != parent:  # the parent died before the death signal was set
        return
    reply: tuple[Any, ...]
    try:
        import time

        t0 = time.perf_counter()
        _no_setter_docstrings()
        warm_up_plotting(case)
        t1 = time.perf_counter()
        data = _read_all(req)
        if not data:
            return
        t2 = time.perf_counter()
        result = pickle.loads(data)
        from gearte.report.html import render_figures, render_report

        # the warm-up is on the run's critical path where the wait is ~0
        timings: dict[str, float] = {
            "report process: warm-up": t1 - t0,
            "report process: waited for the result": t2 - t1,
        }
        figures = render_figures(result, timings)
        t0 = time.perf_counter()
        html = render_report(result, figures)
        timings["html"] = time.perf_counter() - t0
        reply = ("ok", html, timings)
    except BaseException as exc:  # noqa: BLE001 - the parent renders in-process instead
        reply = ("error", f"{type(exc).__name__}: {exc}")
    with contextlib.suppress(OSError):
        _write_all(resp, pickle.dumps(reply, protocol=pickle.HIGHEST_PROTOCOL))


class ReportWorker:
    """A forked process that prepares the report stack while the analyses run, then renders the
    report of the result it is sent (see the module docstring).

    Use :meth:`start` (``None`` where it cannot fork), :meth:`render`, and :meth:`close` (also a
    context manager).
    """

    def __init__(self, pid: int, req: int, resp: int) -> None:
        self.pid = pid
        self._req: int | None = req
        self._resp: int | None = resp
        self._feeder: Any = None

    @classmethod
    def start(cls, case: Any = None) -> ReportWorker | None:
        """Fork the worker; ``None`` where ``os.fork`` is missing or fails. ``case``: the case
        to be run, as :func:`gearte.io.case_file.load_case` takes it (loaded while warming up:
        it imports the study kind that unpickling the result needs).

        Call it before any thread or process pool is started (forking copies one thread; with
        other Python threads running it does not fork). ``GEARTE_NO_REPORT_WORKER=1`` in the
        environment turns it off.
        """
        import threading

        if not hasattr(os, "fork") or os.environ.get("GEARTE_NO_REPORT_WORKER"):
            return None
        if threading.active_count() > 1:  # a fork copies one thread: a lock may stay held
            return None
        parent = os.getpid()
        req_r, req_w = os.pipe()
        resp_r, resp_w = os.pipe()
        try:
            pid = os.fork()
        except OSError:
            for fd in (req_r, req_w, resp_r, resp_w):
                os.close(fd)
            return None
        if pid == 0:  # the worker: never returns into the caller's code
            code = 0
            try:
                os.close(req_w)
                os.close(resp_r)
                _serve(req_r, resp_w, parent, case)
            except BaseException:  # noqa: BLE001
                code = 1
            finally:
                os._exit(code)
        os.close(req_r)
        os.close(resp_w)
        return cls(pid, req_w, resp_r)

    def submit(self, result: Any) -> bool:
        """Send ``result`` (a :class:`~gearte.results.StudyResult`) to be rendered; returns at
        once (a thread feeds the pipe while the worker may still be warming up). ``False`` when
        it cannot be sent (the result does not pickle, the worker is gone)."""
        if self._req is None:
            return False
        try:
            data = pickle.dumps(result, protocol=pickle.HIGHEST_PROTOCOL)
        except Exception:  # noqa: BLE001 - something in the result does not pickle
            self.close()
            return False
        import threading

        req, self._req = self._req, None

        def feed() -> None:
            with contextlib.suppress(OSError):
                _write_all(req, data)
            with contextlib.suppress(OSError):
                os.close(req)

        self._feeder = threading.Thread(target=feed, name="gearte-report-feed", daemon=True)
        self._feeder.start()
        return True

    def collect(self) -> tuple[str, dict[str, float]] | None:
        """Wait for the report of the submitted result.

        Returns
        -------
        (html, timings) or None
            The page and the stage times [s] (``"report process: warm-up"``, ``"report
            process: waited for the result"``, ``"figures"``, ``"render"``, ``"render: slowest
            figure"``, ``"html"``), or ``None`` when the worker could not render it (the caller
            then renders in-process).
        """
        if self._resp is None or self._feeder is None:
            self.close()
            return None
        try:
            reply = _read_all(self._resp)
        except OSError:
            reply = b""
        self._feeder.join()
        self.close()
        try:
            got = pickle.loads(reply) if reply else None
        except Exception:  # noqa: BLE001
            got = None
        if not got or got[0] != "ok":
            return None
        return got[1], got[2]

    def render(self, result: Any) -> tuple[str, dict[str, float]] | None:
        """:meth:`submit` then :meth:`collect`."""
        if not self.submit(result):
            return None
        return self.collect()

    def close(self) -> None:
        """End the worker (if it still runs) and reap it; idempotent."""
        for name in ("_req", "_resp"):
            fd = getattr(self, name)
            if fd is not None:
                with contextlib.suppress(OSError):
                    os.close(fd)
                setattr(self, name, None)
        if self.pid:
            pid, self.pid = self.pid, 0
            with contextlib.suppress(OSError):
                os.kill(pid, signal.SIGKILL)
            with contextlib.suppress(ChildProcessError, OSError):
                os.waitpid(pid, 0)

    def __enter__(self) -> ReportWorker:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()
