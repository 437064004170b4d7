"""Study kinds: one module per kind of drive/analysis, the kind name is the module name.

A kind module defines ``KIND``, ``REFERENCES``, ``FIGURES`` (module path of its plotting),
``class Case(CaseBase)`` and ``run(case, options) -> StudyResult`` (see docs/architecture.md).
Kinds are discovered without importing them (:mod:`gearte.io.kinds`), so adding a module is all
it takes.
"""

from __future__ import annotations

import contextlib
import importlib.abc
import importlib.util
import os
import sys
import time
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

from gearte.io.kinds import available_kinds, get_kind, register_kind

if TYPE_CHECKING:  # pragma: no cover
    from gearte.io.schema import CaseBase
    from gearte.results import StudyResult

__all__ = [
    "RunOptions",
    "available_kinds",
    "get_kind",
    "register_kind",
    "preflight",
    "run_case",
    "check_samples_override",
    "check_sample_time",
    "sample_cap",
]


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


def _sample_caps(model: Any, prefix: str = "") -> list[tuple[str, int]]:
    """``(dotted field, upper bound)`` of every sample-count field of a validated case that
    ``--samples`` sets (a Sobol base count or an allocation search count is only capped by it,
    :func:`sample_cap`, so its own bound does not limit ``--samples``)."""
    from pydantic import BaseModel

    caps: list[tuple[str, int]] = []
    for name, info in type(model).model_fields.items():
        value = getattr(model, name, None)
        path = f"{prefix}{name}"
        if isinstance(value, BaseModel):
            caps += _sample_caps(value, path + ".")
        elif name == "sobol_samples" or prefix.endswith("allocation."):
            continue  # only capped by --samples (sample_cap: min(count, N)), never set by it
        elif "samples" in name and isinstance(value, int) and not isinstance(value, bool):
            bounds = [getattr(m, "le", None) for m in info.metadata]
            bounds += [getattr(m, "lt", None) for m in info.metadata]
            caps += [(path, int(b)) for b in bounds if b is not None]
    return caps


def check_samples_override(case: Any, samples: int | None) -> None:
    """``--samples`` obeys the cap of every sample count it overrides (checked before work).

    Raises
    ------
    ParameterError
        Naming ``--samples``, the value and the case field whose cap it exceeds.
    """
    if samples is None:
        check_sample_time(case, None)
        return
    from gearte.errors import ParameterError

    if isinstance(samples, bool) or not isinstance(samples, int) or samples < 0:
        raise ParameterError("--samples", samples, "must be an integer >= 0 (0: skip)")
    for path, cap in _sample_caps(case):
        if samples > cap:
            raise ParameterError("--samples", samples, f"over the cap of {path} (<= {cap})")
    check_sample_time(case, samples)


#: Least time one sample of a sampled analysis takes on one core [s], by ``(kind, field)``: a
#: tenth of what it took on a 2-core machine (the bundled cases' runs with ``--timings``), so
#: the estimate is a lower bound: a count refused by it would take at least that long.
SECONDS_PER_SAMPLE: dict[tuple[str, str], float] = {
    ("gear_pair", "analysis.monte_carlo_samples"): 2e-9,
    ("gear_chain", "analysis.monte_carlo_samples"): 2e-9,
    ("planetary", "analyses.monte_carlo.samples"): 3e-7,
    ("cycloid_stage", "analyses.yield_.samples"): 2e-5,
    ("planetary", "analyses.yield_.samples"): 5e-6,
    ("gear_chain", "analyses.yield_.samples"): 5e-6,
    ("rv_reducer", "analyses.yield_.samples"): 5e-4,
    ("rv_reducer", "analyses.batch.samples"): 1e-2,
}


def check_sample_time(case: Any, samples: int | None, workers: int | None = None) -> None:
    """The sample counts of ``case`` (each replaced by ``--samples`` when given) against the
    time budget (``GEARTE_MAX_SECONDS``, :func:`gearte.limits.check_time`), before any work: a
    lower estimate, ``count × SECONDS_PER_SAMPLE / workers``.

    Raises
    ------
    ParameterError
        Naming ``--samples`` or the case's field, the count and the estimated time.
    """
    from gearte.execution.streams import default_workers
    from gearte.limits import check_time

    cores = max(1, int(workers or default_workers()))
    for path, _cap in _sample_caps(case):
        per = SECONDS_PER_SAMPLE.get((case.case.kind, path))
        if per is None:
            continue
        key = path.replace("yield_", "yield")
        count = int(_get_path(case, path)) if samples is None else samples
        field = key if samples is None else "--samples"
        check_time(field, count, count * per / cores, f"{key} = {count} (on {cores} cores)")


def _get_path(model: Any, path: str) -> Any:
    for part in path.split("."):
        model = getattr(model, part)
    return model


def sample_cap(section: Any, name: str, options: Any, low: int | None = None) -> Any:
    """The count ``section.<name>`` of a sampled analysis under ``--samples N``
    (``options.samples``): ``min(count, N)``, never below the field's own lower bound (so a
    quasi-random search keeps its fewest starts); the count itself without an override.

    ``--samples`` sets the main sample count of each kind (yield, Monte-Carlo, batch) and caps
    every other count of sampled work with this (Sobol base samples, bootstrap resamples, kept
    worst samples, allocation and verification samples, random assemblies, diagnosis draws,
    speed-sweep points, quasi-random starts): docs/errors.md, "Resource bounds". ``low``
    replaces the field's lower bound where the analysis needs more than the schema says (a
    Sobol estimate needs a minimum of base samples unless its count is 0: none).
    """
    value = getattr(section, name)
    n = getattr(options, "samples", None)
    if n is None or value is None:
        return value
    if low is None:
        low = 0
        for m in type(section).model_fields[name].metadata:
            if getattr(m, "ge", None) is not None:
                low = int(m.ge)
            elif getattr(m, "gt", None) is not None:
                low = int(m.gt) + 1
    return max(low, min(int(value), int(n)))


def preflight(case: Any) -> None:
    """Every check a run of ``case`` (a validated ``Case``) makes on the built drive, made before
    any analysis: the kind module's ``preflight(case)`` where it has one (it builds the drive and
    model objects and calls the same check functions the analyses call). ``gearte validate`` and
    :func:`run_case` call it, so a run refuses such an input before doing any work and validate
    gives the same message (docs/errors.md, "Limits").

    Raises
    ------
    gearte.errors.ParameterError
        Naming the key of the first failing check.
    """
    check_sample_time(case, None)
    fn = getattr(get_kind(case.case.kind), "preflight", None)
    if fn is not None:
        fn(case)


def run_case(
    case: CaseBase | str | os.PathLike[str] | dict[str, Any], options: RunOptions | None = None
) -> StudyResult:
    """Run a case: a validated ``Case``, a path to a TOML file, a bundled name or a dict.

    Parameters
    ----------
    case : Case, str, os.PathLike or dict
        What to run.
    options : RunOptions, optional
        Execution options; default :class:`RunOptions` ().

    Returns
    -------
    gearte.results.StudyResult

    Raises
    ------
    gearte.errors.Interrupted, gearte.errors.ClusterLostError
        The run was stopped (SIGINT/SIGTERM) or lost its cluster during sampled work after
        chunks had finished: ``exc.partial`` is the result computed from the finished chunks,
        marked partial (``result.partial``, first warning), see :mod:`gearte.execution.stop`.

    Notes
    -----
    The run happens inside :func:`gearte._frames.with_frame_room`: its loops never pay CPython
    3.11's frame-stack chunk allocation per call, wherever the caller's frames end.
    """
    from gearte._frames import with_frame_room

    return with_frame_room(lambda: _run_case(case, options))


def _run_case(
    case: CaseBase | str | os.PathLike[str] | dict[str, Any], options: RunOptions | None
) -> StudyResult:
    if isinstance(case, str | os.PathLike | dict):
        from gearte.io.case_file import load_case

        case = load_case(case)
    t_imp = time.perf_counter()
    module = get_kind(case.case.kind)
    check_samples_override(case, (options or RunOptions()).samples)
    t_pre = time.perf_counter()
    with _numba_timer() as numba_pre:  # a preflight may build a model that calls kernels
        preflight(case)
    t0 = time.perf_counter()
    from gearte.execution.stop import keep_finished_chunks

    with _numba_timer() as numba, keep_finished_chunks() as stop:
        try:
            result = module.run(case, options or RunOptions())
        except Exception:
            if not stop.stopped:
                raise
            # the study could not be completed from the finished chunks (a caller needing
            # every chunk's result): stop as before, keeping nothing
            raise _stopped(stop, None) from None
    t_end = time.perf_counter()
    for a in result.analyses:  # a sampled analysis' statistics it could not vouch for
        result.warnings += [f"{a.name}: {w}" for w in a.values.get("statistics_warnings") or ()]
    result.elapsed_s = t_end - t0
    result.timings["imports: study kind"] = t_pre - t_imp
    result.timings["preflight"] = t0 - t_pre
    result.timings.update({f"{k}: preflight": v for k, v in numba_pre.items()})
    result.timings.update(numba)
    result.timings.update(analysis_timings(result.analyses, t0, t_end))
    if stop.stopped:
        result.partial = True
        result.warnings.insert(0, stop.summary())
        raise _stopped(stop, result) from None
    return result


def _stopped(stop: Any, partial: Any) -> BaseException:
    """The exception that ends a stopped run: :class:`~gearte.errors.Interrupted` for a signal,
    :class:`~gearte.errors.ClusterLostError` for a lost cluster, carrying ``partial``."""
    from gearte.errors import ClusterLostError, Interrupted

    if stop.signum is not None:
        return Interrupted(stop.signum, partial=partial)
    return ClusterLostError(str(stop.cause), partial=partial)


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
def _numba_timer() -> Iterator[dict[str, float]]:
    """Seconds numba spends loading kernels from its cache or compiling them (it holds its
    compiler lock for both: the ``numba:compiler_lock`` event, outermost holds only) and, if the
    block imports numba, the import.

    numba is not imported just to time it: if it is not imported yet, a one-shot import hook
    starts the timer as soon as the study imports it. Starting it also loads SciPy's BLAS/LAPACK
    modules for numba without the ``scipy.linalg`` package (:mod:`gearte._blas`). The mapping is
    filled when the block ends: ``{"numba load/compile": s, "imports: numba": s}`` (keys absent
    where nothing happened). :func:`run_case` times the preflight and the analyses apart (the
    preflight's keys end in ``": preflight"``).
    """
    out: dict[str, float] = {}
    timer: list[Any] = []

    def start() -> None:
        from numba.core import event

        from gearte._blas import preload_scipy_blas

        preload_scipy_blas()  # numba's first kernel would import all of scipy.linalg (~0.35 s)

        timer.append(event.TimingListener())
        event.register("numba:compiler_lock", timer[0])
        from gearte.execution.heartbeat import numba_ready

        numba_ready()  # a status line names the kernels numba compiles from now on

        from gearte.execution.stop import defer_signals_while_compiling

        defer_signals_while_compiling()  # after the timer: a signal it delivers may raise

    hook = None
    if "numba" in sys.modules:
        # another thread (a sweep's or a yield's other point) may still be importing numba:
        # wait for that import to finish before importing its submodules here. start() importing
        # numba.core.event while the other thread was inside numba/__init__ made the import
        # system hand one of them a partially initialised module ("numba.core.event has no
        # attribute 'start_event'", or a stalled sweep)
        import numba  # noqa: F401

        start()
    else:
        hook = _AfterImport("numba", out, start)
        sys.meta_path.insert(0, hook)
    try:
        yield out
    finally:
        if hook is not None and hook in sys.meta_path:
            sys.meta_path.remove(hook)
        if timer:
            from numba.core import event

            event.unregister("numba:compiler_lock", timer[0])
            if timer[0].done:
                out["numba load/compile"] = timer[0].duration


class _AfterImport(importlib.abc.MetaPathFinder):
    """Times the first import of module ``name`` (into ``out["imports: <name>"]``) and calls
    ``then()`` right after it; removes itself from ``sys.meta_path`` on first use."""

    def __init__(self, name: str, out: dict[str, float], then: Callable[[], None]) -> None:
        self.name, self.out, self.then = name, out, then

    def find_spec(self, fullname: str, path: Any, target: Any = None) -> Any:
        if fullname != self.name:
            return None
        sys.meta_path.remove(self)
        spec = importlib.util.find_spec(fullname)
        if spec is None or spec.loader is None or not hasattr(spec.loader, "exec_module"):
            return spec
        loader = spec.loader
        inner = loader.exec_module

        def exec_module(module: Any) -> None:
            t0 = time.perf_counter()
            inner(module)
            self.out[f"imports: {self.name}"] = time.perf_counter() - t0
            self.then()

        loader.exec_module = exec_module  # type: ignore[method-assign]
        return spec
