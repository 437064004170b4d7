"""Reading a measurement file's text, shared by the bench and the metrology readers.

Private to :mod:`gearte.io`: :mod:`gearte.io.bench` and :mod:`gearte.io.metrology` read their
CSV files through :func:`read_text_file`, each with its own error class and size limit.
"""

from __future__ import annotations

import errno
import os

from gearte.errors import BenchFileError


def read_text_file(
    path: str | os.PathLike, error: type[BenchFileError], max_bytes: int
) -> tuple[str, str]:
    """``(source, text)`` of a UTF-8 text file (a BOM is dropped), or ``error`` naming the file.

    Parameters
    ----------
    path : str or os.PathLike
        The file.
    error : type
        :class:`gearte.errors.BenchFileError` or a subclass, raised as
        ``error(file, line, None, reason)``.
    max_bytes : int
        Largest file read [bytes].

    Raises
    ------
    BenchFileError
        (of the class ``error``) for a folder, a missing or unreadable file, a device, FIFO or
        socket (refused before reading: :func:`gearte.limits.read_input_file`), a path the
        system cannot take (a NUL byte), a file over ``max_bytes``, text that is not UTF-8 or
        holds a NUL byte (the line is named).
    """
    from gearte.limits import read_input_file

    src = str(path)
    try:
        raw = read_input_file(path, max_bytes)
    except IsADirectoryError:
        raise error(src, None, None, "is a folder, expected a CSV file") from None
    except (OSError, ValueError) as exc:  # ValueError: a NUL byte in the path
        reason = getattr(exc, "strerror", None) or exc
        if getattr(exc, "errno", None) in (errno.EINVAL, errno.EFBIG):
            raise error(src, None, None, str(reason)) from None
        raise error(src, None, None, f"cannot read: {reason}") from None
    try:
        text = raw.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        line = raw[: exc.start].count(b"\n") + 1
        raise error(src, line, None, "is not UTF-8 text (a binary file?)") from None
    if "\x00" in text:
        line = text[: text.index("\x00")].count("\n") + 1
        raise error(src, line, None, "contains a NUL byte (a binary file?)")
    return src, text


def read_header(
    lines: list[str], i: int, src: str, error: type[BenchFileError]
) -> tuple[int, str, str]:
    """The header row ``lines[i]`` (the first line after the metadata) and its delimiter.

    Parameters
    ----------
    lines : list of str
        The file's lines.
    i : int
        Index of the first line that is neither blank nor a ``#`` line [-].
    src : str
        The file, as errors name it.
    error : type
        The reader's error class, as in :func:`read_text_file`.

    Returns
    -------
    (int, str, str)
        The header's 1-based line number, its text and its delimiter: ``,``, else a tab, else
        ``;`` (``,`` if it has none).

    Raises
    ------
    BenchFileError
        (of the class ``error``) when the file ends before a header.
    """
    if i >= len(lines):
        raise error(src, len(lines), None, "has a header but no column names and no data")
    header = lines[i]
    delim = "," if "," in header else ("\t" if "\t" in header else (";" if ";" in header else ","))
    return i + 1, header, delim
