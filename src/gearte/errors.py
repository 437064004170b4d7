"""Exception hierarchy of gearte.

Every error raised on bad input names the field (as a dotted path into the case file or the
argument name of the API), the offending value and the allowed range or the reason.
"""

from __future__ import annotations

from typing import Any

__all__ = [
    "GearteError",
    "ParameterError",
    "CaseFileError",
    "ConvergenceError",
    "DivergenceError",
    "SchedulerError",
    "ClusterLostError",
    "BenchFileError",
    "BenchFileErrors",
    "bench_problems",
    "MeasurementFileError",
    "OutputError",
    "Interrupted",
]


class GearteError(Exception):
    """Base class of all errors gearte raises on purpose."""


class ParameterError(GearteError, ValueError):
    """A parameter is out of its physical range or parameters contradict each other.

    Parameters
    ----------
    field : str
        Name of the parameter, as the user wrote it (``"stage.eccentricity_mm"``, ``"K1"``).
    value : Any
        The offending value.
    reason : str
        Why it is wrong, ideally with the allowed range (``"must be < 1"``).
    """

    def __init__(self, field: str, value: Any, reason: str) -> None:
        self.field = field
        self.value = value
        self.reason = reason
        super().__init__(f"{field} = {value!r}: {reason}")


class CaseFileError(GearteError):
    """A case file cannot be read or does not validate.

    ``errors`` holds one ``(field, message)`` pair per problem; ``str(err)`` lists them one per
    line, so a user sees every problem of a file at once.
    """

    def __init__(self, source: str, errors: list[tuple[str, str]]) -> None:
        self.source = source
        self.errors = errors
        lines = [f"{source}: {len(errors)} error(s)"]
        lines += [f"  {field}: {msg}" for field, msg in errors]
        super().__init__("\n".join(lines))


class ConvergenceError(GearteError, RuntimeError):
    """An iterative solver did not converge.

    The message names the solver, the iteration count, the last residual and the tolerance.
    """


class DivergenceError(GearteError, RuntimeError):
    """A time integration diverged (non-finite state) or left its stability limit."""


class SchedulerError(GearteError, ConnectionError):
    """A distributed scheduler could not be reached or failed."""


class ClusterLostError(SchedulerError):
    """The cluster running the chunks was lost mid-run: the scheduler connection closed, or no
    worker was left for longer than the no-worker timeout. Not bad input: the CLI writes the
    chunks that finished as a partial result (``partial``) and exits with code 5.

    Parameters
    ----------
    reason : str
        What happened, as seen from this process.
    partial : any, optional
        What finished before the loss, marked partial (set by :func:`gearte.studies.run_case`).
    """

    def __init__(self, reason: str, partial: Any = None) -> None:
        self.reason = reason
        self.partial = partial
        super().__init__(reason)

    def __reduce__(self) -> tuple[Any, ...]:
        return (type(self), (self.reason, self.partial))


class OutputError(GearteError):
    """The output folder cannot receive the results: read-only, full disk, file-size limit, a
    path under a file, a folder holding files gearte did not write. A user error (CLI exit
    code 4), raised before the computation where it can be foreseen.

    Parameters
    ----------
    path : str
        The output path as the user gave it.
    reason : str
        What is wrong and, where possible, what to do.
    """

    def __init__(self, path: str, reason: str) -> None:
        self.path = path
        self.reason = reason
        super().__init__(f"output {path}: {reason}")

    def __reduce__(self) -> tuple[Any, ...]:
        return (type(self), (self.path, self.reason))


class BenchFileError(GearteError, ValueError):
    """A bench measurement file (CSV) is malformed.

    The message names the file, the line (1-based, as an editor shows it) and the column (its
    header name and 1-based number) where the problem was found, and the reason.
    """

    def __init__(self, file: str, line: int | None, column: str | None, reason: str) -> None:
        self.file = file
        self.line = line
        self.column = column
        self.reason = reason
        where = file
        if line is not None:
            where += f", line {line}"
        if column is not None:
            where += f", column {column}"
        super().__init__(f"{where}: {reason}")

    def __reduce__(self) -> tuple[Any, ...]:
        return (type(self), (self.file, self.line, self.column, self.reason))


class BenchFileErrors(BenchFileError):
    """Several problems of bench files, reported together (``gearte validate`` lists them all).

    ``errors`` holds one :class:`BenchFileError` per problem; the message lists them one per line.
    The first problem's file, line, column and reason are this exception's own.
    """

    errors: list[BenchFileError]

    def __init__(self, errors: list[BenchFileError]) -> None:
        flat: list[BenchFileError] = []
        for e in errors:
            flat.extend(e.errors if isinstance(e, BenchFileErrors) else [e])
        if not flat:
            raise ValueError("BenchFileErrors needs at least one error")
        self.errors = flat
        first = flat[0]
        super().__init__(first.file, first.line, first.column, first.reason)
        if len(flat) > 1:
            self.args = (f"{len(flat)} problems:\n" + "\n".join(f"  {e}" for e in flat),)

    def __reduce__(self) -> tuple[Any, ...]:
        return (type(self), (self.errors,))


def bench_problems(exc: BenchFileError) -> list[BenchFileError]:
    """Every problem an exception carries: its ``errors`` (:class:`BenchFileErrors`) or itself.

    Parameters
    ----------
    exc : BenchFileError
        The exception raised by a bench or metrology reader.

    Returns
    -------
    list of BenchFileError
        One per problem.
    """
    return list(exc.errors) if isinstance(exc, BenchFileErrors) else [exc]


class Interrupted(KeyboardInterrupt):
    """A run was stopped by SIGINT (Ctrl-C) or SIGTERM.

    A ``KeyboardInterrupt``, so code that does not know it stops as on Ctrl-C. ``partial`` holds
    what finished before the signal where the work is made of independent parts (the points of a
    sweep), marked partial; the CLI writes it and exits with 128 + the signal number (130 for
    SIGINT, 143 for SIGTERM).
    """

    def __init__(self, signum: int, partial: Any = None) -> None:
        self.signum = signum
        self.partial = partial
        super().__init__(f"interrupted by signal {signum}")


class MeasurementFileError(BenchFileError):
    """A metrology file (measured parts: disc profiles, pitch, pins, cranks, bores, run-outs,
    bearing clearances; :mod:`gearte.io.metrology`) is malformed.

    Same fields as :class:`BenchFileError`: file, line (1-based), column (number and header
    name) and the reason.
    """
