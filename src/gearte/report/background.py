"""A report renderer that gets ready while the analyses run and draws each analysis's figures
as soon as that analysis is done.

Most of a warm ``gearte run`` of a fast case is not the analyses: importing matplotlib (~0.5 s),
building the figures and drawing them. :class:`ReportWorker` forks, at the command's start
(before the case is loaded), a process that imports the plotting stack, loads the font
and imports the case's study kind and its plotting module
while the parent loads the case, imports numba, loads its kernels and runs the analyses on the
other core. Once the case is loaded the parent sends it, with the names of the gearte modules it
imported: the worker imports them too where the kind's plotting module does not say
``NUMBA_FREE_RESULTS`` (its results hold records of modules that import numba; every bundled
kind says it: unpickling imports what it needs, numba not among it). Each analysis result is
streamed to the worker as soon as the study makes it
(:func:`gearte.results.analysis_listener`); the worker draws the figures of each analysis whose
figures read that analysis alone (:func:`gearte.plotting.self_contained`) while the next
analyses run. The parent then sends the final result; each analysis unchanged since it was
streamed (the same pickled bytes) keeps the figures drawn from it, the worker builds and renders
the rest (forking one helper per further core, :func:`gearte.report.html.render_figures`) and the
HTML, and sends back the page and the stage timings, while the parent writes the CSV tables.

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
import struct
import sys
from typing import Any

__all__ = ["ReportWorker", "warm_up_plotting"]


def warm_up_plotting(case: Any = None) -> Any:
    """Import what building, rendering and the HTML page need and load the font; with ``case``
    (what :func:`gearte.io.case_file.load_case` takes), first import its study kind and plotting
    module (what unpickling its result and drawing its figures need; the case is not validated
    here). A case whose kind cannot be read is ignored here (unpickling imports what it needs).
    No figure needs matplotlib's mathtext parser (log axes get plain-text tick labels,
    :func:`gearte.plotting.display.polish`), so the warm-up does not build it. Returns the
    case's plotting module (``None`` without a case or where it cannot be read)."""
    import jinja2  # noqa: F401
    import matplotlib.figure  # noqa: F401 - what the first figure would import
    import matplotlib.layout_engine  # noqa: F401
    from matplotlib import font_manager
    from matplotlib.backends import backend_agg  # noqa: F401
    from PIL import Image

    import gearte.plotting.display  # noqa: F401
    import gearte.report.html  # noqa: F401
    import gearte.report.summary  # noqa: F401
    import gearte.report.tables  # noqa: F401
    from gearte.report.html import report_template

    report_template()  # compiled now, not after the result
    Image.preinit()  # Pillow's image plugins, imported by the first save
    # the font every figure uses, read and cached (font_manager.get_font): a throw-away figure
    # drawn here (as before) would fill nothing else that a real figure reuses: matplotlib's
    # text-size cache is kept per renderer, and every figure has its own
    font_manager.get_font(font_manager.findfont(font_manager.FontProperties()))
    return _plotting_module(case) if case is not None else None


def _plotting_module(case: Any) -> Any:
    """The plotting module of the case's study kind (imported with the kind: the analyses'
    figures are drawn with it), read without validating the case; ``None`` where the kind
    cannot be read or draws no figures."""
    with contextlib.suppress(Exception):
        kind = _kind_of(case)
        if kind:
            import importlib

            from gearte.io.kinds import get_kind

            figures = getattr(get_kind(kind), "FIGURES", None)
            if figures:
                return importlib.import_module(figures)
    return None


def _kind_of(case: Any) -> str | None:
    """The ``[case] kind`` of a case as :func:`gearte.io.case_file.load_case` takes it (a dict,
    a TOML file or a bundled name), read without validating; ``None`` where it has none."""
    if not isinstance(case, dict):
        from gearte.cases import case_path
        from gearte.io.case_file import read_case_toml

        case = read_case_toml(case_path(case))
    meta = case.get("case") if isinstance(case, dict) else None
    kind = meta.get("kind") if isinstance(meta, dict) else None
    return kind if isinstance(kind, str) else None


def _import_numba_for(case: Any) -> None:
    """Import numba in this (the parent) process before the report process is forked, unless
    the case's study kind says its results unpickle without it (``NUMBA_FREE_RESULTS`` in its
    plotting module).

    The report process of a kind without the flag (none is bundled: every bundled kind keeps its
    records in numba-free modules, e.g. :mod:`gearte.models.rv_records`) unpickles analyses
    whose result classes live in modules that define kernels, so it imports numba; this process
    imports it anyway for its kernels. Imported once before the fork, the report process
    inherits it (copy-on-write) instead of importing it a second time (~0.15 s CPU). Nothing is
    compiled or started here: importing numba starts no thread, so the fork stays safe."""
    with contextlib.suppress(Exception):
        plotting = _plotting_module(case) if case is not None else None
        if not getattr(plotting, "NUMBA_FREE_RESULTS", False):
            import numba  # noqa: F401


def _fewer_collections() -> None:
    """Move everything imported so far out of the collector's sight (``gc.freeze``) and let the
    young generation grow to :data:`gearte._gc.GC_THRESHOLD0` objects before it is collected.

    Building and drawing matplotlib figures allocates millions of small containers, and the
    collector's passes over them took ~15 % of the report process's figure CPU
    (hu2020_rv80e_initial_reducer's 14 figures, 3 rounds each: 1.15–1.32 s with Python's
    defaults, 1.01–1.04 s with this; ``gc.freeze`` alone: 1.20–1.28 s). The figures' reference
    cycles are then freed later: peak RSS 288 → 387 MB for those 42 figures. The report process
    draws one report and exits."""
    import gc

    from gearte._gc import set_fewer_collections

    gc.freeze()
    set_fewer_collections()


def _die_with_parent() -> None:
    """Linux: this process gets SIGKILL when its parent dies (no orphaned renderer;
    :func:`gearte.execution.backends.die_with_parent`)."""
    from gearte.execution.backends import die_with_parent

    die_with_parent()


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


_HEADER = struct.Struct(">Q")  # the length of the pickled message that follows


def _frame(message: tuple[Any, ...]) -> bytes:
    data = pickle.dumps(message, protocol=pickle.HIGHEST_PROTOCOL)
    return _HEADER.pack(len(data)) + data


def _read_exactly(fd: int, n: int) -> bytes | None:
    chunks: list[bytes] = []
    while n:
        b = os.read(fd, min(n, 1 << 20))
        if not b:
            return None
        chunks.append(b)
        n -= len(b)
    return b"".join(chunks)


def _read_message(fd: int) -> tuple[Any, ...] | None:
    """The next message of the request pipe; ``None`` when the parent closed it."""
    head = _read_exactly(fd, _HEADER.size)
    if head is None:
        return None
    data = _read_exactly(fd, _HEADER.unpack(head)[0])
    return None if data is None else pickle.loads(data)


def _readable(fd: int) -> bool:
    import select

    return bool(select.select([fd], [], [], 0)[0])


class _Report:
    """The report process's side: what the parent sent, and the figures drawn so far.

    Messages (each pickled, after its length): ``("preload", modules, case)`` once the parent
    has loaded the case (import the gearte modules it imported, the numba-using models among
    them, which unpickling the analyses would import); ``("analysis", id, data)`` each time the
    parent made an analysis's result; ``("final", study, analyses)``: the study result without
    its analyses, and each analysis as ``("same", id)`` (unchanged since it was streamed) or
    ``("new", data)``.

    While no message waits, the figures of each streamed analysis whose figures read that
    analysis alone (:func:`gearte.plotting.self_contained`) are built, then drawn one at a time
    (one core: the analyses run on the other). When the final result comes, the figures not
    drawn yet are drawn in parallel (:func:`gearte.report.html.render_all`).
    """

    def __init__(self, preload: bool = True) -> None:
        self.preload = preload  # import the parent's modules (False: unpickling imports them)
        self.case: Any = None
        self.streamed: dict[int, Any] = {}
        self.todo: list[int] = []  # streamed analyses whose figures are not built yet
        self.built: dict[int, list[Any]] = {}  # id -> its figures (built, not drawn yet)
        self.drawn: dict[int, list[Any]] = {}  # id -> its figures drawn so far, in order
        self.idle = 0.0  # waiting for the parent [s]
        self.early = 0.0  # building and drawing figures while the analyses ran [s]
        self.taking = 0.0  # importing the parent's modules, unpickling what it sent [s]

    def serve(self, fd: int) -> tuple[Any, ...] | None:
        """Act on the parent's messages until the final one; ``(html, timings)`` from it."""
        import time

        while True:
            if not (self.todo or any(self.built.values())) or _readable(fd):
                t0 = time.perf_counter()
                msg = _read_message(fd)
                self.idle += time.perf_counter() - t0
                if msg is None:
                    return None
                if msg[0] == "final":
                    return self.finish(msg)
                t0 = time.perf_counter()
                self.take(msg)
                self.taking += time.perf_counter() - t0
                continue
            t0 = time.perf_counter()
            self.step()
            self.early += time.perf_counter() - t0

    def take(self, msg: tuple[Any, ...]) -> None:
        import importlib

        if msg[0] == "preload":
            for name in msg[1] if self.preload else ():
                with contextlib.suppress(Exception):
                    importlib.import_module(name)
            self.case = pickle.loads(msg[2])
            with contextlib.suppress(Exception):  # pydantic builds its serialiser on first use
                self.case.model_dump(mode="json")  # (~0.015 s): now, not after the result
        elif msg[0] == "analysis":
            self.streamed[msg[1]] = pickle.loads(msg[2])
            if self.case is not None:
                from gearte.plotting import self_contained

                if self.streamed[msg[1]].name in self_contained(self.case.case.kind):
                    self.todo.append(msg[1])

    def step(self) -> None:
        """One piece of early work: draw the next built figure, else build the figures of the
        next streamed analysis."""
        from gearte.report.html import render_all

        for ref, figs in self.built.items():
            if figs:
                self.drawn[ref] += render_all([figs.pop(0)], workers=1)
                return
        ref = self.todo.pop(0)
        from gearte.plotting import figures_of
        from gearte.results import StudyResult

        a = self.streamed[ref]
        try:
            self.built[ref] = figures_of(StudyResult(case=self.case, analyses=[a]), {a.name})
            self.drawn[ref] = []
        except Exception:  # noqa: BLE001 - built again from the final result
            self.built.pop(ref, None)

    def finish(self, final: tuple[Any, ...]) -> tuple[Any, ...]:
        import time

        from gearte.plotting import figures_for, figures_of, others_read_alone, self_contained
        from gearte.report.html import render_all, render_report

        result = pickle.loads(final[1])
        analyses = []
        early: dict[str, tuple[list[Any], list[Any]]] = {}  # name -> (drawn, built) while streamed
        for how, ref in final[2]:
            if how == "same":
                a = self.streamed[ref]
                if ref in self.built:
                    early[a.name] = (self.drawn[ref], self.built[ref])
            else:
                a = pickle.loads(ref)
            analyses.append(a)
        result.analyses = analyses
        result._link()
        t0 = time.perf_counter()
        names = [a.name for a in analyses]
        rest = [n for n in names if n not in early]
        if not early:
            figs = figures_for(result)
        elif set(rest) <= self_contained(result.kind) or others_read_alone(result.kind):
            figs = figures_of(result, rest)
        else:  # a figure of another analysis may read those built already: build all, skip them
            figs = [f for f in figures_for(result) if f.analysis not in early]
        left = [f for n in names for f in early.get(n, ((), ()))[1]]  # built, not drawn yet
        t1 = time.perf_counter()
        rendered = render_all(left + figs)
        t2 = time.perf_counter()
        now = {id(f): r for f, r in zip(left, rendered, strict=False)}
        drawn = [
            r
            for n in names
            if n in early
            for r in [*early[n][0], *(now[id(f)] for f in early[n][1])]
        ] + rendered[len(left) :]
        html = render_report(result, drawn)
        timings = {
            "report process: waited for the result": self.idle,
            "report process: figures during the analyses": self.early,
            "report process: imports and unpickling": self.taking,
            "figures": t1 - t0,
            "render": t2 - t1,
            "render: slowest figure": max((f.seconds for f in drawn), default=0.0),
            "html": time.perf_counter() - t2,
        }
        return html, timings


def _analysis_bytes(analysis: Any) -> bytes:
    """An :class:`~gearte.results.AnalysisResult` pickled without the study it belongs to."""
    import copy

    alone = copy.copy(analysis)  # a copy without __init__: no listener hears of it
    alone.study = None
    return pickle.dumps(alone, protocol=pickle.HIGHEST_PROTOCOL)


def _final_frame(result: Any, sent: dict[int, tuple[Any, int, bytes]]) -> bytes:
    """The ``("final", study, analyses)`` message of ``result``; ``sent``: ``id(analysis) ->
    (analysis, id, bytes)`` of the analyses streamed: one unchanged since (the same object, the
    same bytes) is sent as ``("same", id)``, any other as ``("new", bytes)``."""
    import copy

    parts: list[tuple[str, Any]] = []
    for a in result.analyses:
        data = _analysis_bytes(a)
        got = sent.get(id(a))
        if got is not None and got[0] is a and got[2] == data:
            parts.append(("same", got[1]))
        else:
            parts.append(("new", data))
    shell = copy.copy(result)
    shell.analyses = []
    return _frame(("final", pickle.dumps(shell, protocol=pickle.HIGHEST_PROTOCOL), parts))


def _serve(req: int, resp: int, parent: int, case: Any) -> None:
    """The worker's life: warm up, take the parent's messages, send back (html, timings)."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGTERM, signal.SIG_DFL)
    _die_with_parent()
    if os.getppid() != parent:  # the parent died before the death signal was set
        return
    reply: tuple[Any, ...]
    try:
        import time

        t0 = time.perf_counter()
        plotting = warm_up_plotting(case)
        _fewer_collections()
        warm = time.perf_counter() - t0
        # a kind whose results unpickle without numba: not the parent's numba-using modules
        numba_free = bool(getattr(plotting, "NUMBA_FREE_RESULTS", False))
        got = _Report(preload=not numba_free).serve(req)
        if got is None:
            return
        html, timings = got
        # the warm-up is on the run's critical path where the wait is ~0
        reply = ("ok", html, {"report process: warm-up": warm, **timings})
    except BaseException as exc:  # noqa: BLE001 - the parent renders in-process instead
        reply = ("error", f"{type(exc).__name__}: {exc}")
    with contextlib.suppress(OSError):
        _write_all(resp, pickle.dumps(reply, protocol=pickle.HIGHEST_PROTOCOL))


class ReportWorker:
    """A forked process that prepares the report stack while the analyses run, draws each
    finished analysis's figures as it is streamed, then renders the report of the final result
    (see the module docstring).

    Use :meth:`start` (``None`` where it cannot fork), then optionally :meth:`preload` (the
    loaded case) and :meth:`stream` (each analysis as it is made, e.g. through
    :func:`gearte.results.analysis_listener`), then :meth:`render` (or :meth:`submit` and
    :meth:`collect`), and :meth:`close` (also a context manager).
    """

    def __init__(self, pid: int, req: int, resp: int) -> None:
        import threading

        self.pid = pid
        self._req: int | None = req
        self._resp: int | None = resp
        self._feeder: Any = None
        self._queue: Any = None
        self._lock = threading.Lock()
        self._sent: dict[int, tuple[Any, int, bytes]] = {}  # id(analysis) -> (it, id, bytes)
        self._submitted = False

    @classmethod
    def start(cls, case: Any = None) -> ReportWorker | None:
        """Fork the worker; ``None`` where ``os.fork`` is missing or fails. ``case``: the case
        to be run, as :func:`gearte.io.case_file.load_case` takes it (its study kind and
        plotting module are imported while warming up: unpickling the result needs them).

        Call it before any thread or process pool is started (forking copies one thread; with
        other Python threads running it does not fork). ``GEARTE_NO_REPORT_WORKER=1`` in the
        environment turns it off.
        """
        import threading

        if not hasattr(os, "fork") or os.environ.get("GEARTE_NO_REPORT_WORKER"):
            return None
        if threading.active_count() > 1:  # a fork copies one thread: a lock may stay held
            return None
        _import_numba_for(case)
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

    def _send(self, frame: bytes | None) -> bool:
        """Queue ``frame`` for the worker (``None``: the end); a thread feeds the pipe, so this
        returns at once while the worker is busy. ``False`` when the pipe is closed."""
        with self._lock:
            if self._req is None:
                return False
            if frame is None and self._feeder is None:  # nothing was sent: just close
                with contextlib.suppress(OSError):
                    os.close(self._req)
                self._req = None
                return True
            if self._feeder is None:
                import queue
                import threading

                self._queue = queue.SimpleQueue()
                req, q = self._req, self._queue

                def feed() -> None:
                    while (item := q.get()) is not None:
                        try:
                            _write_all(req, item)
                        except OSError:  # the worker is gone: drop the rest
                            break
                    with contextlib.suppress(OSError):
                        os.close(req)

                self._feeder = threading.Thread(target=feed, name="gearte-report-feed", daemon=True)
                self._feeder.start()
            self._queue.put(frame)
            if frame is None:
                self._req = None  # the feeder closes it
            return True

    def preload(self, case: Any) -> None:
        """Send the loaded case (a validated ``Case``) and the names of the gearte modules this
        process has imported (the worker imports them while the analyses run: unpickling the
        analyses needs them, and some import numba)."""
        modules = sorted(
            m for m in sys.modules if m.startswith("gearte.") and m != "gearte.__main__"
        )  # (importing gearte.__main__ runs the command)
        with contextlib.suppress(Exception):
            case_data = pickle.dumps(case, protocol=pickle.HIGHEST_PROTOCOL)
            self._send(_frame(("preload", modules, case_data)))

    def stream(self, analysis: Any) -> None:
        """Send a finished analysis (an :class:`~gearte.results.AnalysisResult`): the worker
        draws its figures while the next analyses run. Any thread may call it; an analysis
        that does not pickle is left to the final result."""
        if self._submitted or self._req is None:
            return
        try:
            data = _analysis_bytes(analysis)
        except Exception:  # noqa: BLE001 - sent with the final result instead
            return
        with self._lock:
            ref = len(self._sent)
            self._sent[id(analysis)] = (analysis, ref, data)
        self._send(_frame(("analysis", ref, data)))

    def submit(self, result: Any) -> bool:
        """Send the final ``result`` (a :class:`~gearte.results.StudyResult`) to be rendered;
        returns at once. Each analysis streamed before and unchanged since (the same pickled
        bytes) is not sent again and keeps the figures drawn from it. ``False`` when it cannot
        be sent (the result does not pickle, the worker is gone)."""
        if self._req is None:
            return False
        try:
            frame = _final_frame(result, self._sent)
        except Exception:  # noqa: BLE001 - something in the result does not pickle
            self.close()
            return False
        self._submitted = True
        return self._send(frame) and self._send(None)

    def collect(self) -> tuple[str, dict[str, float]] | None:
        """Wait for the report of the submitted result.

        Returns
        -------
        (html, timings) or None
            The page and the stage times [s] (``"report process: warm-up"``, ``"report
            process: waited for the result"`` (idle, waiting for the parent), ``"report
            process: figures during the analyses"``, ``"figures"``, ``"render"``, ``"render:
            slowest figure"``, ``"html"``), or ``None`` when the worker could not render it
            (the caller then renders in-process).
        """
        if self._resp is None or not self._submitted:
            self.close()
            return None
        try:
            reply = _read_all(self._resp)
        except OSError:
            reply = b""
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
        self._send(None)  # the feeder closes the request pipe after what is queued
        if self._resp is not None:
            with contextlib.suppress(OSError):
                os.close(self._resp)
            self._resp = None
        if self.pid:
            pid, self.pid = self.pid, 0
            with contextlib.suppress(OSError):
                os.kill(pid, signal.SIGKILL)
            with contextlib.suppress(ChildProcessError, OSError):
                os.waitpid(pid, 0)
        if self._feeder is not None:
            self._feeder.join(timeout=5.0)  # its writes fail once the worker is gone

    def __enter__(self) -> ReportWorker:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()
