"""Study kinds: one module per kind of drive/analysis, the kind name is the module name.

A kind module defines ``KIND``, ``REFERENCES``, ``FIGURES`` (module path of its plotting),
``class Case(CaseBase)`` and ``run(case, options) -> StudyResult`` (see docs/architecture.md).
Kinds are discovered without importing them (:mod:`gearte.io.kinds`), so adding a module is all
it takes.
"""

from __future__ import annotations

import contextlib
import os
import sys
import time
from collections.abc import Iterator
from dataclasses import dataclass
from typing import Any

from gearte.io.kinds import available_kinds, get_kind, register_kind

__all__ = ["RunOptions", "available_kinds", "get_kind", "register_kind", "run_case"]


@dataclass(frozen=True)
class RunOptions:
    """Options of a run that are not part of the drive's description.

    Attributes
    ----------
    progress : bool
        Show progress bars for chunked work (only on a terminal).
    seed : int, optional
        Overrides the case's random seed.
    samples : int, optional
        Overrides Monte-Carlo sample counts.
    scheduler : str, distributed.Client or executor, optional
        Where sampled work runs: ``None`` or ``"threads"`` (local cores, the default),
        ``"sequential"``, ``"processes"``, ``"local-cluster"``, a Dask scheduler address
        (``tcp://host:8786``), a ``distributed.Client``, or an executor from
        :func:`gearte.execution.open_executor`. Results are identical for a seed on every one.
    workers : int, optional
        Local worker threads; default: the machine's cores.
    """

    progress: bool = True
    seed: int | None = None
    samples: int | None = None
    scheduler: Any = None
    workers: int | None = None


def run_case(case: Any, options: RunOptions | None = None) -> Any:
    """Run a case: a validated ``Case``, a path to a TOML file, a bundled name or a dict.

    Returns
    -------
    gearte.results.StudyResult
    """
    if isinstance(case, str | os.PathLike | dict):
        from gearte.io.case_file import load_case

        case = load_case(case)
    t_imp = time.perf_counter()
    module = get_kind(case.case.kind)
    t0 = time.perf_counter()
    with _numba_timer() as numba_s:
        result = module.run(case, options or RunOptions())
    t_end = time.perf_counter()
    result.elapsed_s = t_end - t0
    result.timings["imports: study kind"] = t0 - t_imp
    if numba_s:
        result.timings["numba load/compile"] = numba_s[0]
    result.timings.update(analysis_timings(result.analyses, t0, t_end))
    return result


def analysis_timings(analyses: list[Any], start: float, end: float) -> dict[str, float]:
    """Time of each analysis [s]: the interval from the previous analysis's result (or ``start``)
    to its own (:attr:`AnalysisResult.created`); work after the last result is ``"analysis:
    (after the last result)"``. Studies make each result as soon as its analysis is done, so the
    intervals are the analyses' times (shared set-up falls to the first analysis)."""
    out: dict[str, float] = {}
    prev = start
    for a in sorted(analyses, key=lambda a: a.created):
        t = min(max(a.created, prev), end)
        out[f"analysis: {a.name}"] = t - prev
        prev = t
    if end - prev > 1e-3:
        out["analysis: (after the last result)"] = end - prev
    return out


@contextlib.contextmanager
def _numba_timer() -> Iterator[list[float]]:
    """Seconds numba spends loading kernels from its cache or compiling them (its
    ``numba:compile`` event, outermost calls only), as a one-element list once the block ends;
    empty if the study kind does not use numba (numba is not imported just to time it)."""
    out: list[float] = []
    if "numba" not in sys.modules:
        yield out
        return
    from numba.core import event

    timer = event.TimingListener()
    with event.install_listener("numba:compile", timer):
        yield out
    out.append(timer.duration if timer.done else 0.0)
