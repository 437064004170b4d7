"""Resource bounds decided before any work starts (issue 13).

Every input that sizes an allocation or a loop has a bound in its schema (``Field(le=...)``);
where the size comes from a combination of inputs (the harmonics of planetary terms, a sweep grid,
a ``--samples`` override) an estimate of memory and time is checked here, at validation time,
against a budget. The budgets are generous for a workstation and can be raised per run through
environment variables (see ``docs/errors.md``):

=========================  =======================  ===========================================
budget                     default                  override
=========================  =======================  ===========================================
memory of one analysis     4 GB                     ``GEARTE_MAX_MEMORY_GB``
time of one analysis       3600 s (estimated)       ``GEARTE_MAX_SECONDS``
points of a sweep          1000                     ``GEARTE_MAX_SWEEP_POINTS``
Dask cluster with no       300 s, then the cluster  ``GEARTE_NO_WORKER_TIMEOUT_S`` (0: forever)
worker                     counts as lost
=========================  =======================  ===========================================

``--samples N`` sets each kind's main sample count (bounded by that field's cap,
``gearte.studies.check_samples_override``) and caps every other count of sampled work — Sobol
base samples, bootstrap, kept worst samples, allocation search and verification, random
assemblies, diagnosis draws, speed-sweep points, quasi-random starts — at ``N``, never below the
field's own minimum (``gearte.studies.sample_cap``; docs/errors.md, "``--samples N``").
"""

from __future__ import annotations

import os
from typing import Any

from gearte.errors import ParameterError

__all__ = [
    "max_memory_bytes",
    "max_seconds",
    "max_sweep_points",
    "check_memory",
    "check_time",
    "check_sweep_points",
    "no_worker_timeout_s",
]

_DEFAULTS = {"GEARTE_MAX_MEMORY_GB": 4.0, "GEARTE_MAX_SECONDS": 3600.0}
_DEFAULT_SWEEP_POINTS = 1000
_DEFAULT_NO_WORKER_S = 300.0


def _env_float(name: str, default: float) -> float:
    text = os.environ.get(name)
    if text is None or not text.strip():
        return default
    try:
        value = float(text)
    except ValueError:
        raise ParameterError(name, text, "must be a positive number") from None
    if not value > 0 or value == float("inf"):
        raise ParameterError(name, text, "must be a positive finite number")
    return value


def max_memory_bytes() -> float:
    """Memory budget of one analysis [bytes] (``GEARTE_MAX_MEMORY_GB``, default 4)."""
    return _env_float("GEARTE_MAX_MEMORY_GB", _DEFAULTS["GEARTE_MAX_MEMORY_GB"]) * 1e9


def max_seconds() -> float:
    """Estimated-time budget of one analysis [s] (``GEARTE_MAX_SECONDS``, default 3600)."""
    return _env_float("GEARTE_MAX_SECONDS", _DEFAULTS["GEARTE_MAX_SECONDS"])


def max_sweep_points() -> int:
    """Largest sweep grid (``GEARTE_MAX_SWEEP_POINTS``, default 1000)."""
    return int(_env_float("GEARTE_MAX_SWEEP_POINTS", _DEFAULT_SWEEP_POINTS))


def no_worker_timeout_s() -> float:
    """Seconds sampled work waits on a Dask cluster without any worker before the cluster counts
    as lost [s] (``GEARTE_NO_WORKER_TIMEOUT_S``, default 300; ``0`` waits forever)."""
    text = os.environ.get("GEARTE_NO_WORKER_TIMEOUT_S", "").strip()
    if text in ("0", "0.0"):
        return 0.0
    return _env_float("GEARTE_NO_WORKER_TIMEOUT_S", _DEFAULT_NO_WORKER_S)


def check_memory(field: str, value: Any, nbytes: float, what: str) -> None:
    """Raise :class:`ParameterError` when ``nbytes`` exceeds the memory budget.

    Parameters
    ----------
    field : str
        The input the budget check is about (named in the error).
    value : Any
        Its value (echoed in the error).
    nbytes : float
        Estimated memory need [bytes].
    what : str
        What needs it, for the message.

    Raises
    ------
    ParameterError
        Over the budget (``GEARTE_MAX_MEMORY_GB``).
    """
    limit = max_memory_bytes()
    if nbytes > limit:
        raise ParameterError(
            field,
            value,
            f"{what} needs about {nbytes / 1e9:.3g} GB of memory, over the budget of "
            f"{limit / 1e9:.3g} GB (raise it with GEARTE_MAX_MEMORY_GB if you mean it)",
        )


def check_time(field: str, value: Any, seconds: float, what: str) -> None:
    """Raise :class:`ParameterError` when an estimated run time exceeds the time budget.

    Parameters
    ----------
    field : str
        The input the budget check is about (named in the error).
    value : Any
        Its value (echoed in the error).
    seconds : float
        Estimated run time [s].
    what : str
        What takes it, for the message.

    Raises
    ------
    ParameterError
        Over the budget (``GEARTE_MAX_SECONDS``).
    """
    limit = max_seconds()
    if seconds > limit:
        raise ParameterError(
            field,
            value,
            f"{what} would take about {seconds:.3g} s, over the budget of {limit:.3g} s "
            "(raise it with GEARTE_MAX_SECONDS if you mean it)",
        )


def check_sweep_points(n: int) -> None:
    """Raise :class:`ParameterError` when a sweep grid has more points than allowed.

    Parameters
    ----------
    n : int
        Number of grid points [-].

    Raises
    ------
    ParameterError
        Over ``GEARTE_MAX_SWEEP_POINTS``.
    """
    limit = max_sweep_points()
    if n > limit:
        raise ParameterError(
            "--vary",
            n,
            f"the grid has {n} points, over the limit of {limit} "
            "(raise it with GEARTE_MAX_SWEEP_POINTS if you mean it)",
        )
