"""Result objects of gearte's studies and their JSON form.

Names of values carry their unit in brackets (``"max_contact_force [N]"``); dimensionless names
have none (``"K1"``). Arrays become lists in JSON; non-finite numbers become ``null``.
"""

from __future__ import annotations

import json
import math
import time
from dataclasses import dataclass, field
from typing import Any

import numpy as np

__all__ = ["AnalysisResult", "StudyResult", "to_jsonable"]


def to_jsonable(obj: Any) -> Any:
    """Convert numpy scalars/arrays, tuples and nested mappings to plain JSON types."""
    if isinstance(obj, dict):
        return {str(k): to_jsonable(v) for k, v in obj.items()}
    if isinstance(obj, list | tuple):
        return [to_jsonable(v) for v in obj]
    if isinstance(obj, np.ndarray):
        return to_jsonable(obj.tolist())
    if isinstance(obj, np.bool_ | bool):
        return bool(obj)
    if isinstance(obj, np.integer):
        return int(obj)
    if isinstance(obj, np.floating | float):
        f = float(obj)
        return f if math.isfinite(f) else None
    if isinstance(obj, complex | np.complexfloating):
        return {"re": to_jsonable(obj.real), "im": to_jsonable(obj.imag)}
    if obj is None or isinstance(obj, str | int):
        return obj
    if hasattr(obj, "model_dump"):
        return to_jsonable(obj.model_dump(mode="json"))
    return str(obj)


def _count_nonfinite(obj: Any) -> int:
    """Number of NaN/inf numbers in a value (scalars, arrays, lists, mappings)."""
    if isinstance(obj, dict):
        return sum(_count_nonfinite(v) for v in obj.values())
    if isinstance(obj, list | tuple):
        return sum(_count_nonfinite(v) for v in obj)
    if isinstance(obj, np.ndarray):
        if obj.dtype.kind in "fc":
            return int(np.count_nonzero(~np.isfinite(obj)))
        return sum(_count_nonfinite(v) for v in obj.ravel()) if obj.dtype.kind == "O" else 0
    if isinstance(obj, float | np.floating | complex | np.complexfloating):
        return int(not np.isfinite(obj))
    return 0


@dataclass
class AnalysisResult:
    """One analysis of a study.

    Attributes
    ----------
    name : str
        Machine name, key in ``results.json`` (``"tooth_contact"``).
    title : str
        Human title for the report.
    values : dict
        Named results; names carry units (``"max_contact_force [N]"``). Scalars, arrays, lists
        and mappings.
    references : list of str
        Keys of :data:`gearte.references.REFERENCES` this analysis used.
    notes : list of str
        Assumptions and remarks shown in the report and JSON.
    data : dict
        Extra objects for plotting; not serialised.
    files : dict
        Extra output files, plain file name → text (e.g. a compensation table a controller
        loads); written beside ``results.json`` by :func:`gearte.report.write_outputs`.
    created : float
        ``time.perf_counter()`` when the result was made; :func:`gearte.studies.run_case` times
        each analysis as the interval since the previous one's result (or the run's start).
    """

    name: str
    title: str
    values: dict[str, Any] = field(default_factory=dict)
    references: list[str] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)
    data: dict[str, Any] = field(default_factory=dict, repr=False)
    files: dict[str, str] = field(default_factory=dict, repr=False)
    created: float = field(default_factory=time.perf_counter, repr=False, compare=False)

    def __getitem__(self, key: str) -> Any:
        return self.values[key]

    def to_dict(self) -> dict[str, Any]:
        return {
            "title": self.title,
            "values": to_jsonable(self.values),
            "notes": list(self.notes),
            "references": list(self.references),
        }


@dataclass
class StudyResult:
    """All analyses of one case run.

    ``result["tooth_contact"]["pins_in_mesh"]`` reads a value. ``timings`` holds the time of
    each stage of the run in seconds (``"imports"``, ``"numba load/compile"``,
    ``"analysis: <name>"``, ``"figures"``, ``"render"``, ``"write"``, ...), filled
    by :func:`gearte.studies.run_case`, :func:`gearte.report.write_outputs` and the CLI, and
    written to ``results.json`` as ``"timings [s]"``.
    """

    case: Any
    analyses: list[AnalysisResult] = field(default_factory=list)
    warnings: list[str] = field(default_factory=list)
    elapsed_s: float = 0.0
    timings: dict[str, float] = field(default_factory=dict)
    #: True when the run was stopped and sampled analyses used only their finished chunks
    #: (``"partial": true`` in ``results.json``; the first warning says what was cut).
    partial: bool = False

    def __getitem__(self, name: str) -> AnalysisResult:
        for a in self.analyses:
            if a.name == name:
                return a
        raise KeyError(f"no analysis {name!r}; have {[a.name for a in self.analyses]}")

    def __contains__(self, name: object) -> bool:
        return any(a.name == name for a in self.analyses)

    @property
    def kind(self) -> str:
        return str(self.case.case.kind)

    @property
    def name(self) -> str:
        return str(self.case.case.name or self.kind)

    @property
    def references(self) -> list[str]:
        keys: list[str] = list(self.case.case.references)
        for a in self.analyses:
            keys += [k for k in a.references if k not in keys]
        return keys

    def to_dict(self) -> dict[str, Any]:
        from gearte._version import __version__
        from gearte.references import REFERENCES

        return {
            "gearte_version": __version__,
            "case": {
                "name": self.name,
                "kind": self.kind,
                "title": self.case.case.title,
                "input": to_jsonable(self.case.model_dump(mode="json")),
            },
            "references": {k: REFERENCES.get(k, k) for k in self.references},
            "warnings": list(self.warnings) + self._nonfinite_warnings(),
            **({"partial": True} if self.partial else {}),
            "elapsed [s]": round(self.elapsed_s, 4),
            "timings [s]": {k: round(v, 4) for k, v in self.timings.items()},
            "analyses": {a.name: a.to_dict() for a in self.analyses},
        }

    def _nonfinite_warnings(self) -> list[str]:
        """Say where non-finite numbers became ``null`` in JSON (never silently)."""
        out = []
        for a in self.analyses:
            names = [k for k, v in a.values.items() if _count_nonfinite(v)]
            if names:
                n = sum(_count_nonfinite(a.values[k]) for k in names)
                shown = ", ".join(names[:3]) + (", ..." if len(names) > 3 else "")
                out.append(
                    f"{a.name}: {n} non-finite value(s) (NaN/inf) written as null in {shown}"
                )
        return out

    def to_json(self, indent: int | None = 1) -> str:
        return json.dumps(self.to_dict(), indent=indent, ensure_ascii=False, allow_nan=False)
