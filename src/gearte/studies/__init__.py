"""Study kinds: one module per kind of drive/analysis, the kind name is the module name.

A kind module defines ``KIND``, ``REFERENCES``, ``FIGURES`` (module path of its plotting),
``class Case(CaseBase)`` and ``run(case, options) -> StudyResult`` (see docs/architecture.md).
Kinds are discovered without importing them (:mod:`gearte.io.kinds`), so adding a module is all
it takes.
"""

from __future__ import annotations

import os
import time
from dataclasses import dataclass
from typing import Any

from gearte.io.kinds import available_kinds, get_kind, register_kind

__all__ = [
    "RunOptions",
    "available_kinds",
    "get_kind",
    "register_kind",
    "run_case",
    "check_samples_override",
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
    """``(dotted field, upper bound)`` of every sample-count field of a validated case."""
    from pydantic import BaseModel

    caps: list[tuple[str, int]] = []
    for name, info in type(model).model_fields.items():
        value = getattr(model, name, None)
        path = f"{prefix}{name}"
        if isinstance(value, BaseModel):
            caps += _sample_caps(value, path + ".")
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
        return
    from gearte.errors import ParameterError

    if isinstance(samples, bool) or not isinstance(samples, int) or samples < 0:
        raise ParameterError("--samples", samples, "must be an integer >= 0 (0: skip)")
    for path, cap in _sample_caps(case):
        if samples > cap:
            raise ParameterError("--samples", samples, f"over the cap of {path} (<= {cap})")


def run_case(case: Any, options: RunOptions | None = None) -> Any:
    """Run a case: a validated ``Case``, a path to a TOML file, a bundled name or a dict.

    Returns
    -------
    gearte.results.StudyResult
    """
    if isinstance(case, str | os.PathLike | dict):
        from gearte.io.case_file import load_case

        case = load_case(case)
    module = get_kind(case.case.kind)
    check_samples_override(case, (options or RunOptions()).samples)
    t0 = time.perf_counter()
    result = module.run(case, options or RunOptions())
    result.elapsed_s = time.perf_counter() - t0
    return result
