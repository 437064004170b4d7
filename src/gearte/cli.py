"""Command-line interface: a thin layer over the Python API.

Only click is imported at start-up; everything else is imported inside the command that needs it,
so ``gearte --help`` answers fast.

Exit codes (docs/errors.md): 0 ok · 1 the analysis failed (non-convergence, divergence) · 2 bad
input · 3 internal error (a bug: please report it, ``--debug`` shows the traceback) · 4 the outputs
cannot be written (read-only, disk full, file-size limit, a path under a file) · 5 the cluster
was lost mid-run (finished chunks written, marked partial) · 130 / 143 stopped by SIGINT (Ctrl-C)
/ SIGTERM: previous outputs kept; an interrupted sweep writes the points that finished, an
interrupted Monte-Carlo its finished chunks, marked partial.
"""

from __future__ import annotations

import contextlib
import os
import sys
from collections.abc import Callable, Iterator
from typing import Any

import click

_T_START = __import__("time").perf_counter()  # fallback clock of the final line's "in all"

EXIT_FAILED = 1
EXIT_BAD_INPUT = 2
EXIT_INTERNAL = 3
EXIT_OUTPUT = 4
EXIT_CLUSTER_LOST = 5
EXIT_SIGINT = 130  # 128 + SIGINT
EXIT_SIGTERM = 143  # 128 + SIGTERM


def _stop_on_sigterm() -> None:
    """SIGTERM stops like Ctrl-C (an exception, so ``finally`` blocks and pools clean up)."""
    import signal

    from gearte.errors import Interrupted

    def handler(signum: int, _frame: Any) -> None:
        raise Interrupted(signum)

    with contextlib.suppress(ValueError):  # not the main thread (embedded use): leave it
        signal.signal(signal.SIGTERM, handler)


#: Output folders of this process's commands whose whole result set was written (a signal that
#: comes after it says so instead of "nothing written").
_COMPLETE: list[str] = []


def _exit_after_stop(code: int) -> None:
    """Exit after a stop. A pool thread still running its chunk (the shutdown does not wait
    for it beyond its time-out, ``gearte.execution.backends._shutdown_pool``) would keep the
    interpreter from exiting until it finishes: then end the process at once, the outputs and
    messages being written and flushed."""
    from gearte.execution.backends import stuck_worker_threads

    if stuck_worker_threads():
        _flushed_exit(code)
    sys.exit(code)


def _flushed_exit(code: int) -> None:
    """Flush stdout and stderr, then end the process with ``code`` at once (``os._exit``: no
    interpreter teardown, no joining of threads)."""
    for stream in (sys.stdout, sys.stderr):
        with contextlib.suppress(Exception):
            stream.flush()
    os._exit(code)


def _error(title: str, message: str) -> None:
    """Print an error without a traceback (rich when available on a terminal)."""
    if sys.stderr.isatty():
        from rich.console import Console
        from rich.panel import Panel

        Console(stderr=True).print(Panel(message, title=title, border_style="red", expand=False))
    else:
        click.echo(f"error ({title}): {message}", err=True)


def _guarded(fn: Callable[[], Any], debug: bool) -> Any:
    """Run ``fn`` turning gearte's errors into clean messages and exit codes."""
    from gearte._gc import fewer_collections
    from gearte.errors import (
        BenchFileError,
        CaseFileError,
        ClusterLostError,
        ConvergenceError,
        DivergenceError,
        GearteError,
        OutputError,
        ParameterError,
        SchedulerError,
    )

    _stop_on_sigterm()
    _COMPLETE.clear()
    from gearte.execution.backends import quiet_pool_manager_after_stop

    quiet_pool_manager_after_stop()
    try:
        try:
            with fewer_collections():  # numba's compiler: ~1 s less CPU on a cold cache
                return fn()
        except SystemError as exc:
            # a signal handler raised inside a compiled (numba) kernel: CPython reports the
            # pending KeyboardInterrupt as a SystemError it caused; it is the interrupt
            if isinstance(exc.__cause__, KeyboardInterrupt):
                raise exc.__cause__ from None
            raise
    except KeyboardInterrupt as exc:
        import signal

        signum = int(getattr(exc, "signum", signal.SIGINT))
        name = signal.Signals(signum).name
        written = getattr(exc, "written", None)
        if written is not None:
            _error(
                "interrupted",
                f"stopped by {name}: the finished chunks were written to {written}, marked "
                'partial ("partial": true; its first warning says what was cut)',
            )
        elif _COMPLETE:  # the signal came after the whole result set was written
            _error(
                "interrupted",
                f"stopped by {name} after the complete results were written to {_COMPLETE[-1]}",
            )
        else:
            _error("interrupted", f"stopped by {name}; nothing written, previous outputs kept")
        _exit_after_stop(128 + signum)
    except BrokenPipeError:  # output piped into `head` and closed: not an error of ours
        sys.stderr.close()
        sys.exit(0)
    except CaseFileError as exc:
        _error("invalid case", str(exc))
        sys.exit(EXIT_BAD_INPUT)
    except ParameterError as exc:
        _error("invalid parameter", str(exc))
        sys.exit(EXIT_BAD_INPUT)
    except BenchFileError as exc:  # a malformed bench or metrology file: bad input
        _error("invalid data file", str(exc))
        sys.exit(EXIT_BAD_INPUT)
    except FileNotFoundError as exc:
        _error("not found", str(exc).strip("'\""))
        sys.exit(EXIT_BAD_INPUT)
    except ClusterLostError as exc:
        written = getattr(exc, "written", None)
        kept = (
            f"the finished chunks were written to {written}, marked partial"
            if written is not None
            else "nothing finished was kept; previous outputs kept"
        )
        _error("cluster lost", f"{exc}; {kept}")
        sys.exit(EXIT_CLUSTER_LOST)
    except SchedulerError as exc:
        _error("scheduler", str(exc))
        sys.exit(EXIT_BAD_INPUT)
    except OutputError as exc:
        _error("cannot write outputs", str(exc))
        sys.exit(EXIT_OUTPUT)
    except (ConvergenceError, DivergenceError) as exc:
        _error("analysis failed", str(exc))
        sys.exit(EXIT_FAILED)
    except GearteError as exc:
        _error("error", str(exc))
        sys.exit(EXIT_FAILED)
    except Exception as exc:  # noqa: BLE001 - last line of defence of the CLI
        if debug or os.environ.get("GEARTE_DEBUG"):
            raise
        _error(
            "internal error",
            f"{type(exc).__name__}: {exc}\nThis is a bug in gearte; rerun with --debug for the "
            "traceback and report it.",
        )
        sys.exit(EXIT_INTERNAL)


def _write_partial(exc: BaseException, target: Any) -> None:
    """A run stopped mid-way (signal, lost cluster) with finished chunks: write them as the
    output set, ``results.json`` only, marked ``"partial": true``; say so. The exception then
    propagates to :func:`_guarded` for the exit code."""
    partial = getattr(exc, "partial", None)
    if partial is None:
        return
    from gearte.report.outputs import write_outputs

    paths = write_outputs(partial, target, report=False)
    exc.written = paths["results"]  # type: ignore[attr-defined]


@contextlib.contextmanager
def _executor(scheduler: str | None, workers: int | None) -> Iterator[Any]:
    """The executor of ``--scheduler`` (a Dask cluster is connected once, before any work, and
    released after), or ``None`` for the local default."""
    if scheduler is None:
        yield None
        return
    from gearte.execution import open_executor

    with open_executor(scheduler, workers) as ex:
        yield ex


def _execution_options(fn: Callable[..., Any]) -> Callable[..., Any]:
    """The options of every command that runs sampled work: --samples, --workers, --scheduler."""
    fn = click.option(
        "--scheduler",
        default=None,
        metavar="ADDRESS",
        help="Run sampled work on a Dask cluster, e.g. tcp://host:8786 (or a local backend: "
        "threads, processes, local-cluster). See docs/cluster.md.",
    )(fn)
    fn = click.option(
        "--workers",
        type=click.IntRange(min=1),
        default=None,
        help="Local worker threads (default: all cores).",
    )(fn)
    return click.option(
        "--samples",
        type=click.IntRange(min=1),
        default=None,
        help="Override Monte-Carlo sample counts.",
    )(fn)


def entry() -> None:
    """The ``gearte`` command (and ``python -m gearte``): :func:`main`, then a quick exit.

    Once a command has finished (its outputs written and flushed), the interpreter's teardown
    (freeing every module: numba's and LLVM's, matplotlib's) took 1–6 s of a warm run's wall
    time on the 2-core machine. The ``atexit`` handlers still run (logging, temporary files,
    multiprocessing, coverage), the output streams are flushed, then the process ends with the
    command's exit code (``os._exit``), unless other threads still run (then the normal exit
    joins them). Embedded use (``main()``, click's test runner) exits normally.
    """
    import atexit
    import signal
    import threading

    from gearte._frames import with_frame_room
    from gearte._gc import set_fewer_collections

    _stop_on_sigterm()  # as early as can be: a SIGTERM during the imports stops cleanly too
    # this process is gearte's own: the collector's setting of _guarded for its whole life, so
    # that leaving _guarded restores the same thresholds, not Python's 700 (that made the next
    # allocation collect every object the command had made: ~0.03 s CPU before the exit)
    set_fewer_collections()
    code: int
    try:
        # the command's frames share one 1 MiB chunk of CPython's frame stack: no loop of it pays
        # CPython 3.11's chunk allocation on every call (gearte._frames)
        with_frame_room(main)
        code = 0
    except SystemExit as exc:
        if exc.code is None or isinstance(exc.code, int):
            code = exc.code or 0
        else:  # sys.exit("message")
            print(exc.code, file=sys.stderr)
            code = 1
    threads_left = threading.active_count() > 1
    if threads_left and code not in (128 + signal.SIGINT, 128 + signal.SIGTERM):
        sys.exit(code)  # the normal exit joins the threads
    # After a stop the outputs are written and flushed, and a thread left is pool machinery: the
    # process pool's manager thread can wait for ever on a worker the signal killed mid-message
    # (seen: interpreter shutdown joining it, 1 of ~20 SIGTERMs to a Monte-Carlo on worker
    # processes), and multiprocessing's exit handlers, run under it, close its pipes and make it
    # print a traceback: end at once, without them, as _exit_after_stop does.
    if not threads_left:
        atexit._run_exitfuncs()
    _flushed_exit(code)


@click.group(context_settings={"help_option_names": ["-h", "--help"]})
@click.version_option(package_name="gearte", message="gearte %(version)s")
def main() -> None:
    """gearte — accuracy of precision robot-joint reducers (RV, cycloid, planetary, gear chains).

    A case file (TOML) describes one drive and the analyses to run; `gearte cases` lists the
    bundled ones. Units inside: mm, N, N·mm, MPa, rad; every result name carries its unit.
    """


def _wall_since_start() -> float:
    """Wall time since this command started [s]: the process's age (interpreter start-up
    included) where the system gives it, else the time since this module was imported. A
    process that a shell ``exec``-ed after other work keeps the shell's start time: an age more
    than :data:`_STARTUP_MAX_S` beyond this module's import is not this command's."""
    import time

    from gearte.execution.heartbeat import process_age

    since_import = time.perf_counter() - _T_START
    age = process_age()
    if age is None or age > since_import + _STARTUP_MAX_S:
        return since_import
    return age


#: The longest plausible interpreter start-up before this module is imported [s].
_STARTUP_MAX_S = 5.0


def _final_line(result: Any, total_s: float) -> str:
    """The last line of a run: the analyses' own time and the command's whole wall time [s]
    (start-up, loading kernels or compiling them on first use, the report), so that the
    time a user waited is the number they read."""
    compile_s = sum(v for k, v in result.timings.items() if k.startswith("numba load/compile"))
    extra = f" (numba kernels {compile_s:.1f} s)" if compile_s >= 0.5 else ""
    return (
        f"{result.name}: {len(result.analyses)} analyses in {result.elapsed_s:.2f} s; "
        f"{total_s:.1f} s in all, with start-up and outputs{extra}"
    )


@contextlib.contextmanager
def _analysis_stages(beat: Any) -> Any:
    """The heartbeat's stage while ``run_case`` runs: "running the analyses", then after each
    finished analysis how many are done and which one finished last."""
    from gearte.results import analysis_listener

    done: list[str] = []

    def finished(a: Any) -> None:
        done.append(a.title or a.name)
        beat.stage(f"running the analyses ({len(done)} done; last: {done[-1]})")

    beat.stage("running the analyses")
    with analysis_listener(finished):
        yield


@main.command()
@click.argument("case")
@click.option(
    "--out",
    "out_dir",
    default=None,
    help="Output folder, replaced as a whole by the new result set (default: out/<case name>).",
)
@click.option("--seed", type=int, default=None, help="Override the case's random seed.")
@_execution_options
@click.option("--no-report", is_flag=True, help="Write results.json only.")
@click.option("--no-progress", is_flag=True, help="Hide progress bars.")
@click.option(
    "--timings",
    is_flag=True,
    help="Print the time of each stage (imports, analyses, figures, writing) as JSON on stderr.",
)
@click.option("--debug", is_flag=True, help="Show tracebacks of internal errors.")
def run(
    case: str,
    out_dir: str | None,
    seed: int | None,
    samples: int | None,
    workers: int | None,
    scheduler: str | None,
    no_report: bool,
    no_progress: bool,
    timings: bool,
    debug: bool,
) -> None:
    """Run CASE (a .toml file or a bundled case name) and write results.json and report.html."""

    def _run() -> None:
        import time

        t0 = time.perf_counter()
        from gearte.execution.heartbeat import Heartbeat

        # quiet since the process started: interpreter start-up and imports count
        beat = Heartbeat(enabled=not no_progress, quiet_since=t0 - _wall_since_start())
        try:
            _run_with(beat, t0)
        finally:
            beat.close()

    def _run_with(beat: Any, t0: float) -> None:
        import time

        beat.stage("loading gearte")
        from gearte.errors import ClusterLostError
        from gearte.io.case_file import load_case
        from gearte.report.outputs import (
            check_free_space,
            check_output_dir,
            expected_output_bytes,
            safe_label,
            write_outputs,
        )
        from gearte.studies import RunOptions, run_case

        t1 = time.perf_counter()
        # the report's process, forked first, imports matplotlib and the case's study kind (its
        # result unpickles there) while this one loads the case and runs the analyses
        renderer = None
        if not no_report:
            from gearte.report.background import ReportWorker

            # (numba imported first, for both processes, where the kind's results need it)
            renderer = ReportWorker.start(case)
        t1b = time.perf_counter()
        try:
            beat.stage("loading the case")
            c = load_case(case)
            t2 = time.perf_counter()
            default = os.path.join("out", safe_label(c.case.name or c.case.kind))
            target = check_output_dir(out_dir if out_dir is not None else default)
            check_free_space(target, expected_output_bytes(c, report=not no_report))
            listening: Any = contextlib.nullcontext()
            if renderer is not None:  # it imports what we did, then draws each analysis's
                from gearte.results import analysis_listener  # figures as soon as it is done

                renderer.preload(c)
                listening = analysis_listener(renderer.stream)
            with _executor(scheduler, workers) as executor, listening:
                opts = RunOptions(
                    progress=not no_progress,
                    seed=seed,
                    samples=samples,
                    scheduler=executor,
                    workers=workers,
                )
                try:
                    with _analysis_stages(beat):
                        result = run_case(c, opts)
                except (KeyboardInterrupt, ClusterLostError) as exc:
                    beat.stage(None)
                    _write_partial(exc, target)
                    raise
            result.timings = {
                "imports: gearte": t1 - t0,
                "imports: before the report process": t1b - t1,
                "load case": t2 - t1b,
                **result.timings,
            }
            beat.stage("writing results.json" + ("" if no_report else " and the report (figures)"))
            paths = write_outputs(result, target, report=not no_report, worker=renderer)
            _COMPLETE.append(str(target))
        finally:
            beat.stage(None)
            if renderer is not None:
                renderer.close()
        beat.close()
        for w in result.warnings:
            click.echo(f"warning: {w}", err=True)
        click.echo(_final_line(result, _wall_since_start()))
        for p in paths.values():
            click.echo(f"  wrote {p}")
        if timings:
            import json

            result.timings["total in gearte"] = time.perf_counter() - t0
            click.echo(f"timings [s]: {json.dumps(result.timings)}", err=True)

    _guarded(_run, debug)


@main.command()
@click.argument("case")
@click.option(
    "--vary",
    "vary",
    multiple=True,
    metavar="KEY=START:STOP:N",
    help="A case parameter to vary (dotted path, e.g. stage.eccentricity_mm=1.0:1.6:7, or "
    "KEY=V1,V2,...); coupled keys: K1,K2=A1:A2,B1:B2 (the points (A1, A2), (B1, B2)). Repeat "
    "for a full-factorial grid.",
)
@click.option(
    "--points",
    "points_file",
    default=None,
    metavar="TABLE.csv",
    help="Coupled points from a CSV table: a header of keys, one row per point (one axis of "
    "the grid, combined with any --vary).",
)
@click.option(
    "--out",
    "out_dir",
    default=None,
    help="Output folder, replaced as a whole (default: out/sweep_<case name>).",
)
@click.option("--seed", type=int, default=None, help="Override the case's seed (all points).")
@_execution_options
@click.option("--no-plots", is_flag=True, help="Write the table only.")
@click.option("--no-progress", is_flag=True, help="Hide the progress bar.")
@click.option("--debug", is_flag=True, help="Show tracebacks of internal errors.")
def sweep(
    case: str,
    vary: tuple[str, ...],
    points_file: str | None,
    out_dir: str | None,
    seed: int | None,
    samples: int | None,
    workers: int | None,
    scheduler: str | None,
    no_plots: bool,
    no_progress: bool,
    debug: bool,
) -> None:
    """Run CASE over a grid of parameter values; write sweep.csv, sweep.json, index.html and
    plots. Points that do not validate are skipped and listed with the reason."""

    def _sweep() -> None:
        from gearte.errors import ParameterError
        from gearte.io.case_file import load_case
        from gearte.report.outputs import (
            check_free_space,
            check_output_dir,
            expected_output_bytes,
            safe_label,
        )
        from gearte.sweep import Coupled, Vary, parse_vary, read_points, run_sweep, write_sweep

        varies: list[Vary | Coupled] = [parse_vary(v) for v in vary]
        if points_file is not None:
            varies.append(read_points(points_file))
        if not varies:
            raise ParameterError("--vary", "", "give at least one --vary KEY=... or --points")
        c = load_case(case)
        default = os.path.join("out", f"sweep_{safe_label(c.case.name or c.case.kind)}")
        target = check_output_dir(out_dir if out_dir is not None else default)
        check_free_space(target, expected_output_bytes(c, report=False))
        from gearte.errors import Interrupted

        try:
            with _executor(scheduler, workers) as executor:
                result = run_sweep(
                    case,
                    varies,
                    seed=seed,
                    samples=samples,
                    scheduler=executor,
                    workers=workers,
                    progress=not no_progress,
                )
        except Interrupted as exc:
            if exc.partial is not None and exc.partial.points:
                paths = write_sweep(exc.partial, target, plots=False)
                import signal

                name = signal.Signals(exc.signum).name
                _error(
                    "interrupted",
                    f"stopped by {name}: {len(exc.partial.points)} finished point(s) written to "
                    f'{paths["json"].parent} marked partial ("partial": true)',
                )
                sys.exit(128 + exc.signum)
            raise
        paths = write_sweep(result, target, plots=not no_plots, workers=workers)
        click.echo(
            f"{result.name}: {len(result.points)} points × {len(result.columns)} scalar results "
            f"in {result.elapsed_s:.2f} s ({result.backend}); {_wall_since_start():.1f} s in all, "
            "with start-up and outputs"
        )
        statuses = result.statuses
        for what, label in (("invalid", "did not validate (skipped)"), ("failed", "failed")):
            bad = [i for i, st in enumerate(statuses) if st == what]
            if bad:
                click.echo(f"warning: {len(bad)} point(s) {label}:", err=True)
                for i in bad[:10]:
                    where = ", ".join(f"{k}={v!r}" for k, v in result.points[i].items())
                    click.echo(f"  #{i} {where}: {result.errors[i]}", err=True)
                if len(bad) > 10:
                    click.echo(f"  ... {len(bad) - 10} more in {paths['index']}", err=True)
        click.echo(f"  wrote {paths['index']}")
        click.echo(f"  wrote {paths['csv']}")
        click.echo(f"  wrote {paths['json']}")
        if paths["plots"]:
            click.echo(f"  wrote {len(paths['plots'])} plots in {paths['plots'][0].parent}")

    _guarded(_sweep, debug)


@main.command()
@click.argument("case")
@click.option(
    "--format",
    "formats",
    multiple=True,
    type=click.Choice(["dxf", "csv"], case_sensitive=False),
    default=("dxf", "csv"),
    show_default=True,
    help="Profile format; repeat for several.",
)
@click.option(
    "--chordal-tolerance-um",
    type=float,
    default=1.0,
    show_default=True,
    help="Largest distance between a chord of the polyline and the profile [µm].",
)
@click.option(
    "--out",
    "out_dir",
    default=None,
    help="Output folder, replaced as a whole (default: out/export_<case name>).",
)
@click.option("--no-compensation", is_flag=True, help="Skip the compensation tables.")
@click.option("--debug", is_flag=True, help="Show tracebacks of internal errors.")
def export(
    case: str,
    formats: tuple[str, ...],
    chordal_tolerance_um: float,
    out_dir: str | None,
    no_compensation: bool,
    debug: bool,
) -> None:
    """Write the modified cycloid profile of CASE (DXF, CSV) and its compensation tables (CSV).

    Works for cycloid_stage and rv_reducer cases; see docs/export.md.
    """

    def _export() -> None:
        from gearte.export import export_case
        from gearte.io.case_file import load_case
        from gearte.report.outputs import check_output_dir, safe_label

        c = load_case(case)
        default = os.path.join("out", f"export_{safe_label(c.case.name or c.case.kind)}")
        target = check_output_dir(out_dir if out_dir is not None else default)
        paths = export_case(
            c,
            target,
            formats=formats,
            chordal_tolerance_um=chordal_tolerance_um,
            compensation=not no_compensation,
        )
        for p in paths.values():
            click.echo(f"  wrote {p}")

    _guarded(_export, debug)


@main.command()
@click.argument("cases", nargs=-1, required=True)
def validate(cases: tuple[str, ...]) -> None:
    """Check case files without running them; print every problem, one per line."""
    from gearte.errors import BenchFileError, CaseFileError, ParameterError, bench_problems

    def _validate() -> None:
        from gearte.io.case_file import load_case
        from gearte.studies import preflight

        bad = 0
        for c in cases:
            try:
                case = load_case(c)
            except CaseFileError as exc:
                bad += 1
                click.echo(str(exc), err=True)
                continue
            except FileNotFoundError as exc:  # report it and go on with the next file
                bad += 1
                click.echo(
                    f"{c}: 1 error(s)\n  (file): {str(exc).strip(chr(39) + chr(34))}", err=True
                )
                continue
            try:  # the checks `run` makes on the built drive before any analysis
                preflight(case)
            except BenchFileError as exc:  # every problem of every data file, one per line
                bad += 1
                found = bench_problems(exc)
                click.echo(f"{c}: {len(found)} error(s)", err=True)
                for e in found:
                    click.echo(f"  {e}", err=True)
                continue
            except ParameterError as exc:
                bad += 1
                click.echo(f"{c}: 1 error(s)\n  {exc}", err=True)
                continue
            except CaseFileError as exc:  # a case file the pre-flight loads (a drive's case)
                bad += 1
                click.echo(str(exc), err=True)
                continue
            click.echo(f"{c}: ok ({case.case.kind})")
        if bad:
            sys.exit(EXIT_BAD_INPUT)

    _guarded(_validate, False)


@main.command("warm-cache")
@click.option("--kind", "kinds", multiple=True, help="Warm this study kind only (repeatable).")
@click.option(
    "--processes",
    type=click.IntRange(min=1),
    default=None,
    help="Case groups compiled side by side (default: the machine's cores, at most 4).",
)
@click.option("--debug", is_flag=True, help="Show tracebacks of internal errors.")
def warm_cache_cmd(kinds: tuple[str, ...], processes: int | None, debug: bool) -> None:
    """Compile the numba kernels of every study kind now (make demo runs this once), so that the
    first `gearte run` of a kind loads them from the cache instead of compiling."""

    def _warm() -> None:
        import time

        from gearte.execution.heartbeat import Heartbeat
        from gearte.warm import warm_cache, warm_cache_parallel, warm_case_names

        n = processes if processes is not None else min(4, os.cpu_count() or 1)
        t0 = time.perf_counter()
        total = len(warm_case_names(list(kinds) or None))
        click.echo(f"==> compiling gearte's numba kernels, one line per case ({n} at a time)")
        with Heartbeat(quiet_since=time.perf_counter()) as beat:
            done = [0]

            def line(kind: str, case: str, wall: float, cpu_s: float) -> None:
                done[0] += 1
                beat.echo(f"  {kind:14s} {case:32s} {wall:6.1f} s ({cpu_s:.1f} s CPU)")
                beat.stage(f"compiling numba kernels ({done[0]} of {total} cases done)")

            beat.stage(f"compiling numba kernels (0 of {total} cases done)")
            if n == 1:
                cpu = [0.0]

                def report(kind: str, case: str, seconds: float) -> None:
                    if seconds < 0:
                        cpu[0] = time.process_time()
                        beat.stage(f"compiling numba kernels: {case} ({done[0]} of {total} done)")
                    else:
                        line(kind, case, seconds, time.process_time() - cpu[0])

                list(warm_cache(list(kinds) or None, report=report))
            else:
                for ev in warm_cache_parallel(list(kinds) or None, processes=n):
                    line(*ev)
            beat.stage("stopping the compile workers")
        click.echo(f"==> numba cache warm ({time.perf_counter() - t0:.1f} s)")

    _guarded(_warm, debug)


@main.command("cases")
@click.option("--kinds", is_flag=True, help="List the study kinds instead.")
def cases_cmd(kinds: bool) -> None:
    """List the bundled example cases (run one with `gearte run NAME`)."""
    if kinds:
        from gearte.studies import available_kinds

        for k in available_kinds():
            click.echo(k)
        return
    import tomllib

    from gearte.cases import list_cases

    for name, path in list_cases().items():
        try:
            meta = tomllib.loads(path.read_text(encoding="utf-8")).get("case", {})
        except (OSError, tomllib.TOMLDecodeError):
            meta = {}
        click.echo(f"{name:40s} {meta.get('kind', '?'):16s} {meta.get('title', '')}")


if __name__ == "__main__":  # pragma: no cover
    main()
