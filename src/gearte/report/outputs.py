"""Write a study's outputs atomically: ``results.json`` and ``report.html``.

Everything is computed and rendered in memory first; files are then written to temporary names in
the output folder and moved into place with ``os.replace``, so a failed run never leaves a
half-written report.
"""

from __future__ import annotations

import os
import tempfile
from pathlib import Path
from typing import Any

__all__ = ["write_outputs", "atomic_write_bytes", "atomic_write_text"]


def _public_mode() -> int:
    """Mode of a normally created file (0o666 less the umask); ``mkstemp`` makes 0o600."""
    mask = os.umask(0)
    os.umask(mask)
    return 0o666 & ~mask


def atomic_write_bytes(path: Path, data: bytes) -> None:
    """Write ``data`` to ``path`` atomically (temporary file in the same folder + rename), with
    the mode of a normally created file; creates the folder."""
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
    try:
        with os.fdopen(fd, "wb") as fh:
            fh.write(data)
        os.chmod(tmp, _public_mode())
        os.replace(tmp, path)
    except BaseException:
        if os.path.exists(tmp):
            os.unlink(tmp)
        raise


def atomic_write_text(path: Path, text: str) -> None:
    """:func:`atomic_write_bytes` of ``text`` encoded as UTF-8."""
    atomic_write_bytes(path, text.encode("utf-8"))


def write_outputs(
    result: Any, out_dir: str | os.PathLike[str], *, report: bool = True
) -> dict[str, Path]:
    """Write ``results.json`` (and ``report.html`` unless ``report=False``) into ``out_dir``,
    with the tabular results as CSV beside them (:func:`gearte.report.tables.csv_files`).

    The time of each stage (``"figures"``, ``"render"``, ``"html"``, ``"csv"``, ``"write"``) is
    added to ``result.timings``; ``"write"`` in ``results.json`` covers every file but
    ``results.json`` itself (written last, it cannot time itself).

    Returns
    -------
    dict
        ``{"results": path, "report": path, <extra file name>: path}`` of the files written.
    """
    import time

    from gearte.report.tables import csv_files

    out = Path(out_dir)
    timings = result.timings
    html_text = None
    if report:
        from gearte.report.html import render_figures, render_report

        figures = render_figures(result, timings)
        t0 = time.perf_counter()
        html_text = render_report(result, figures)
        timings["html"] = time.perf_counter() - t0
    t0 = time.perf_counter()
    texts: dict[str, str] = {}
    paths: dict[str, Path] = {}
    if html_text is not None:
        paths["report"] = out / "report.html"
        texts["report"] = html_text
    for analysis in result.analyses:
        for fname, text in analysis.files.items():
            if Path(fname).name != fname or fname in ("results.json", "report.html"):
                raise ValueError(f"analysis {analysis.name!r}: bad output file name {fname!r}")
            paths[fname] = out / fname
            texts[fname] = text
    for fname, text in csv_files(result).items():
        if fname not in paths:
            paths[fname] = out / fname
            texts[fname] = text
    timings["csv"] = time.perf_counter() - t0
    # Every document exists in memory: only now touch the disk; results.json last, with the time
    # the other files took to write.
    t_write = time.perf_counter()
    tmp_files: list[tuple[str, Path]] = []
    out.mkdir(parents=True, exist_ok=True)

    def stage(key: str, text: str) -> None:
        fd, tmp = tempfile.mkstemp(prefix=f".{key}.", suffix=".tmp", dir=out)
        tmp_files.append((tmp, paths[key]))
        with os.fdopen(fd, "w", encoding="utf-8") as fh:
            fh.write(text)
        os.chmod(tmp, _public_mode())

    try:
        for key, text in texts.items():
            stage(key, text)
        timings["write"] = time.perf_counter() - t_write
        paths = {"results": out / "results.json", **paths}
        stage("results", result.to_json())
        for tmp, final in tmp_files:
            os.replace(tmp, final)
    finally:
        for tmp, _ in tmp_files:
            if os.path.exists(tmp):
                os.unlink(tmp)
    return paths
