"""gearte — accuracy of precision robot-joint reducers.

Units inside gearte: mm, N, N·mm, MPa, rad, s (see :mod:`gearte.units`).

The top-level API is imported lazily so that ``import gearte`` and the CLI's ``--help`` stay fast.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from gearte._version import __version__

__all__ = [
    "__version__",
    "load_case",
    "validate_case",
    "run_case",
    "write_outputs",
    "list_cases",
]

_LAZY = {
    "load_case": "gearte.io.case_file",
    "validate_case": "gearte.io.case_file",
    "run_case": "gearte.studies",
    "write_outputs": "gearte.report.outputs",
    "list_cases": "gearte.cases",
}

if TYPE_CHECKING:  # pragma: no cover
    from gearte.cases import list_cases
    from gearte.io.case_file import load_case, validate_case
    from gearte.report.outputs import write_outputs
    from gearte.studies import run_case


def __getattr__(name: str) -> Any:
    if name in _LAZY:
        import importlib

        return getattr(importlib.import_module(_LAZY[name]), name)
    raise AttributeError(f"module 'gearte' has no attribute {name!r}")
