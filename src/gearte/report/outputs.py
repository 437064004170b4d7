"""Write a study's outputs as one set: ``results.json``, ``report.html`` and any extra files.

The output folder belongs to gearte and holds one result set. Everything is computed and rendered
in memory first; the files are then written into a *staging folder* beside the output folder (same
parent, so on the same file system) and the staging folder replaces the output folder in one
atomic rename (Linux ``renameat2(RENAME_EXCHANGE)``; elsewhere two renames). A reader therefore
sees either the whole previous set or the whole new one, never a new ``results.json`` beside an
old ``report.html``. Any failure removes the staging folder; a staging folder left by a killed
process (``SIGKILL`` cannot be caught) is removed by the next write into the same folder.

:func:`check_output_dir` is called by the CLI *before* any computation: a folder that cannot be
written (read-only, under a file, a dangling symlink, holding files gearte did not write) is a
user error (:class:`gearte.errors.OutputError`, exit code 4) instead of a lost computation.
"""

from __future__ import annotations

import contextlib
import errno
import json
import os
import re
import shutil
import sys
import tempfile
from collections.abc import Mapping
from pathlib import Path
from typing import Any

from gearte.errors import OutputError

__all__ = [
    "write_outputs",
    "write_file_set",
    "check_output_dir",
    "check_free_space",
    "expected_output_bytes",
    "safe_label",
    "atomic_write_bytes",
    "atomic_write_text",
    "MARKER",
]

#: Name of the manifest gearte writes into every output folder it owns (JSON: version, files).
MARKER = ".gearte-outputs.json"
#: Files and folders an output folder of an older gearte (before the marker) may hold.
_LEGACY_OUTPUT = re.compile(r"^(results\.json|report\.html|sweep\.(csv|json)|plots|[\w.-]+\.csv)$")
_STAGING = ".gearte-staging-"


def safe_label(name: str, *, default: str = "case") -> str:
    """A case name as a single, harmless folder name: a label, never a path.

    Path separators, ``..``, control characters and anything outside ``[A-Za-z0-9._-]`` become
    ``_``; leading dots are dropped (no hidden or parent folders); at most 100 characters.

    >>> safe_label("../../x")
    '_.._x'

    Parameters
    ----------
    name : str
        The case name.
    default : str
        Used when nothing is left of ``name``.

    Returns
    -------
    str
        The folder name.
    """
    label = re.sub(r"[^A-Za-z0-9._-]+", "_", str(name)).lstrip(".")[:100]
    return label or default


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask


def _public_mode() -> int:
    """Mode of a normally created file (0o666 less the umask); ``mkstemp`` makes 0o600."""
    return 0o666 & ~_umask()


def _describe(exc: OSError) -> str:
    reasons = {
        errno.ENOSPC: "the disk is full",
        errno.EDQUOT: "the disk quota is exceeded",
        errno.EFBIG: "the file-size limit is exceeded",
        errno.EROFS: "the file system is read-only",
        errno.EACCES: "permission denied",
        errno.EPERM: "operation not permitted",
        errno.ENOTDIR: "a part of the path is a file, not a folder",
        errno.ENAMETOOLONG: "the path is too long",
        errno.ELOOP: "too many symbolic links",
    }
    return reasons.get(exc.errno or 0, exc.strerror or str(exc))


def _output_error(path: Path | str, exc: OSError) -> OutputError:
    return OutputError(str(path), f"cannot write: {_describe(exc)} ({exc.strerror or exc})")


def _pid_alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    return True


def _remove_stale_staging(out: Path) -> None:
    """Remove staging folders of ``out`` left by processes that no longer run (killed runs)."""
    prefix = f".{out.name}{_STAGING}"
    with contextlib.suppress(OSError):
        for entry in out.parent.iterdir():
            if not entry.name.startswith(prefix):
                continue
            pid_text = entry.name[len(prefix) :].split("-", 1)[0]
            if pid_text.isdigit() and not _pid_alive(int(pid_text)):
                shutil.rmtree(entry, ignore_errors=True)


def _foreign_entries(out: Path) -> list[str]:
    """Entries of an existing folder that show it is not a gearte output folder."""
    names = sorted(e.name for e in out.iterdir())
    if MARKER in names:
        return []
    return [n for n in names if not _LEGACY_OUTPUT.match(n)]


def check_output_dir(out_dir: str | os.PathLike[str]) -> Path:
    """Check that ``out_dir`` can receive a result set, before any computation.

    Returns the folder as an absolute path with symbolic links resolved.

    Raises
    ------
    OutputError
        When the path is empty or holds a NUL byte, is a file or lies under a file, is a dangling
        symbolic link, holds files gearte did not write, contains the current folder, or when
        its parent folder cannot be written (read-only, permissions, full disk).
    """
    text = os.fspath(out_dir)
    if not text.strip() or "\x00" in text:
        raise OutputError(repr(text), "not a usable folder name")
    if os.path.islink(text) and not os.path.exists(text):
        raise OutputError(text, f"is a dangling symbolic link (to {os.readlink(text)!r})")
    out = Path(os.path.realpath(text))
    if out.parent == out:
        raise OutputError(text, "cannot replace the root folder; choose a subfolder")
    if out.exists() and not out.is_dir():
        raise OutputError(text, "is a file, not a folder")
    existing = out.parent  # where the staging folder is made
    while not existing.exists():
        existing = existing.parent
    if not existing.is_dir():
        raise OutputError(text, f"lies under {str(existing)!r}, which is a file")
    if out.exists():
        try:
            foreign = _foreign_entries(out)
        except OSError as exc:
            raise _output_error(text, exc) from None
        if foreign:
            shown = ", ".join(foreign[:3]) + (", ..." if len(foreign) > 3 else "")
            raise OutputError(
                text,
                f"holds files gearte did not write ({shown}); gearte replaces its output folder "
                "as a whole, so choose a new or empty folder (or an earlier gearte output folder)",
            )
        with contextlib.suppress(OSError):
            cwd = Path(os.getcwd()).resolve()
            if cwd == out or out in cwd.parents:
                raise OutputError(text, "contains the current folder; choose a subfolder")
    try:  # a real probe: os.access does not see read-only mounts and answers True for root
        probe = tempfile.mkdtemp(prefix=".gearte-probe-", dir=existing)
        os.rmdir(probe)
    except OSError as exc:
        raise _output_error(existing, exc) from None
    return out


#: Expected size of a result set [bytes]: this much for the set and for each analysis, without
#: and with ``report.html``. Of the order of the bundled cases' sets (0.26 - 1.8 MB with the
#: report, 23 - 280 kB without); the check only has to catch a disk that is (nearly) full.
OUTPUT_BYTES_BASE = 32_000
OUTPUT_BYTES_PER_ANALYSIS = 16_000
REPORT_BYTES_PER_ANALYSIS = 64_000


def expected_output_bytes(case: Any, *, report: bool = True) -> int:
    """A lower estimate of the size of ``case``'s result set [bytes], before computing it.

    Parameters
    ----------
    case : Case
        The validated case; its analyses are counted (the fields set in its ``analyses`` or
        ``analysis`` section; one where it has neither).
    report : bool
        Whether ``report.html`` is written too.
    """
    count = 0
    for name in ("analyses", "analysis"):
        section = getattr(case, name, None)
        if section is None:
            continue
        fields = getattr(type(section), "model_fields", {})
        count += sum(1 for f in fields if getattr(section, f, None) is not None) or 1
    count = max(count, 1)
    per = OUTPUT_BYTES_PER_ANALYSIS + (REPORT_BYTES_PER_ANALYSIS if report else 0)
    return OUTPUT_BYTES_BASE + count * per


def check_free_space(out: Path, nbytes: int) -> None:
    """Refuse, before any computation, an output folder whose file system has less free space
    than ``nbytes`` (:func:`expected_output_bytes`): a full disk was found only after the work,
    when the result set was written (it is still written as one set, so a disk that fills up
    during the run keeps the previous outputs).

    Parameters
    ----------
    out : Path
        The output folder (it need not exist yet: the nearest existing parent is measured).
    nbytes : int
        Expected size of the result set [bytes].

    Raises
    ------
    OutputError
        Naming the folder, the free space and the expected size.
    """
    existing = out
    while not existing.exists() and existing.parent != existing:
        existing = existing.parent
    try:
        free = shutil.disk_usage(existing).free
    except OSError:  # the write will say what is wrong
        return
    if free < nbytes:
        raise OutputError(
            str(out),
            f"the disk has {free / 1e6:.3g} MB free; the results need about "
            f"{nbytes / 1e6:.3g} MB (free some space or choose another --out)",
        )


def _write_file(path: Path, data: bytes) -> None:
    """Write ``data`` to a new file, flushed to the disk (injected faults replace this)."""
    fd = os.open(path, os.O_WRONLY | os.O_CREAT | os.O_EXCL, _public_mode())
    try:
        view = memoryview(data)
        while view:
            view = view[os.write(fd, view) :]
        os.fsync(fd)
    finally:
        os.close(fd)


def _exchange(a: Path, b: Path) -> bool:
    """Swap folders ``a`` and ``b`` atomically; ``False`` where the system cannot."""
    if not sys.platform.startswith("linux"):
        return False
    import ctypes

    try:
        libc = ctypes.CDLL(None, use_errno=True)
        renameat2 = libc.renameat2
    except (OSError, AttributeError):
        return False
    at_fdcwd, rename_exchange = -100, 2
    if renameat2(at_fdcwd, os.fsencode(a), at_fdcwd, os.fsencode(b), rename_exchange) == 0:
        return True
    err = ctypes.get_errno()
    if err in (errno.ENOSYS, errno.EINVAL, errno.ENOTSUP):
        return False
    raise OSError(err, os.strerror(err), str(b))


def _swap(staging: Path, out: Path) -> None:
    """Put the filled ``staging`` folder in place of ``out``; the old set ends in ``staging``."""
    try:
        os.rename(staging, out)  # no previous set (or an empty folder): one rename
        return
    except OSError as exc:
        if exc.errno not in (errno.EEXIST, errno.ENOTEMPTY, errno.EISDIR):
            raise
    if _exchange(staging, out):
        return
    old = staging.with_name(staging.name + "-old")
    os.rename(out, old)
    os.rename(staging, out)
    os.rename(old, staging)


def _check_relative(name: str) -> None:
    parts = Path(name).parts
    if (
        not parts
        or Path(name).is_absolute()
        or any(p in ("..", ".", "") for p in parts)
        or "\x00" in name
        or len(parts) > 2
        or name == MARKER
    ):
        raise ValueError(f"bad output file name {name!r}")


def write_file_set(out_dir: str | os.PathLike[str], files: Mapping[str, bytes]) -> dict[str, Path]:
    """Replace the output folder ``out_dir`` by exactly ``files`` (relative name → content).

    Names are plain file names or ``folder/file``. The set appears at once (see the module
    docstring); on any failure the previous set is left as it was and no temporary remains.

    Raises
    ------
    OutputError
        The folder cannot be written (see :func:`check_output_dir`), or the disk is full, the
        file-size limit is hit, permission is denied while writing.
    """
    for name in files:
        _check_relative(name)
    out = check_output_dir(out_dir)
    from gearte._version import __version__

    manifest = json.dumps({"gearte_version": __version__, "files": sorted(files)}, indent=1)
    staging: Path | None = None
    try:
        out.parent.mkdir(parents=True, exist_ok=True)
        _remove_stale_staging(out)
        staging = Path(
            tempfile.mkdtemp(prefix=f".{out.name}{_STAGING}{os.getpid()}-", dir=out.parent)
        )
        os.chmod(staging, 0o777 & ~_umask())  # mkdtemp makes 0o700
        for name, data in files.items():
            target = staging / name
            target.parent.mkdir(exist_ok=True)
            _write_file(target, data)
        _write_file(staging / MARKER, manifest.encode("utf-8"))
        _swap(staging, out)
    except OSError as exc:
        raise _output_error(out, exc) from None
    finally:
        if staging is not None:
            shutil.rmtree(staging, ignore_errors=True)
    return {name: out / name for name in files}


def atomic_write_bytes(path: Path, data: bytes) -> None:
    """Write one file ``path`` atomically (temporary file in the same folder + rename), with the
    mode of a normally created file; creates the folder. For single files outside a result set.

    Parameters
    ----------
    path : Path
        The file.
    data : bytes
        Its content.
    """
    path = Path(path)
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
    except OSError as exc:
        raise _output_error(path, exc) from None
    os.close(fd)
    try:
        os.unlink(tmp)
        _write_file(Path(tmp), data)
        os.replace(tmp, path)
    except OSError as exc:
        raise _output_error(path, exc) from None
    finally:
        if os.path.exists(tmp):
            os.unlink(tmp)


def atomic_write_text(path: Path, text: str) -> None:
    """:func:`atomic_write_bytes` of ``text`` encoded as UTF-8.

    Parameters
    ----------
    path : Path
        The file.
    text : str
        Its content.
    """
    atomic_write_bytes(path, text.encode("utf-8"))


def write_outputs(
    result: Any, out_dir: str | os.PathLike[str], *, report: bool = True, worker: Any = None
) -> dict[str, Path]:
    """Write ``results.json`` (and ``report.html`` unless ``report=False``), the analyses' extra
    files and the tabular results as CSV (:func:`gearte.report.tables.csv_files`) into
    ``out_dir`` as one set, replacing the previous set.

    The time of each stage (``"figures"``, ``"render"``, ``"html"``, ``"csv"``) is added to
    ``result.timings`` before ``results.json`` is serialised; ``"write"`` (the file set) is added
    after, so it is in ``result.timings`` but not in ``results.json``.

    ``worker``: a :class:`gearte.report.background.ReportWorker` started before the analyses;
    it renders the report while this process writes the CSV tables (in-process where it cannot).

    Returns
    -------
    dict
        ``{"results": path, "report": path, <extra file name>: path}`` of the files written.

    Raises
    ------
    OutputError
        The folder cannot be written (exit code 4 in the CLI); the previous set is kept.
    """
    import time

    from gearte.report.tables import csv_files

    timings = result.timings
    texts: dict[str, str] = {}
    sent = report and worker is not None and worker.submit(result)
    t0 = time.perf_counter()
    csv_texts = csv_files(result)
    t_csv = time.perf_counter() - t0
    got = worker.collect() if sent else None
    if worker is not None:
        worker.close()
    if got is not None:
        texts["report.html"], report_timings = got
        timings.update(report_timings)
    elif report:
        from gearte.report.html import render_figures, render_report

        if worker is not None:  # say so: the run took the slow path
            timings["report process failed: rendered in-process"] = 0.0

        figures = render_figures(result, timings)
        t0 = time.perf_counter()
        texts["report.html"] = render_report(result, figures)
        timings["html"] = time.perf_counter() - t0
    keys = {"results.json": "results", "report.html": "report"}
    for analysis in result.analyses:
        for fname, text in analysis.files.items():
            if Path(fname).name != fname or fname in keys or fname == MARKER:
                raise ValueError(f"analysis {analysis.name!r}: bad output file name {fname!r}")
            texts[fname] = text
    for fname, text in csv_texts.items():
        texts.setdefault(fname, text)
    timings["csv"] = t_csv
    texts = {"results.json": result.to_json(), **texts}
    # Every document exists in memory: only now touch the disk.
    t0 = time.perf_counter()
    written = write_file_set(out_dir, {k: v.encode("utf-8") for k, v in texts.items()})
    timings["write"] = time.perf_counter() - t0
    return {keys.get(k, k): p for k, p in written.items()}
