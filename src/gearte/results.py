"""Result objects of gearte's studies and their JSON form.

Names of values carry their unit in brackets (``"max_contact_force [N]"``); dimensionless names
have none (``"K1"``). Arrays become lists in JSON; non-finite numbers become ``null``.

In Jupyter both result objects show a summary table (``_repr_html_``), give pandas tables
(``to_pandas()``, extra ``gearte[notebooks]``) and matplotlib figures (``plot()``). That display
belongs to the report layer, above this one (docs/architecture.md, "Layers"): it is found by
name, :data:`DISPLAY_MODULE`, imported when first asked for (as ``gearte.io.kinds`` finds the
study kinds), so this module imports nothing above it.
"""

from __future__ import annotations

import contextlib
import importlib
import json
import math
import threading
import time
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field
from types import ModuleType
from typing import Any

import numpy as np

__all__ = ["AnalysisResult", "StudyResult", "to_jsonable", "DISPLAY_MODULE", "analysis_listener"]

DISPLAY_MODULE = "gearte.report.notebook"
"""The module that displays results in notebooks (HTML summary, pandas tables, figures)."""


def _display() -> ModuleType:
    return importlib.import_module(DISPLAY_MODULE)


_LISTENERS: list[Callable[[AnalysisResult], None]] = []
_LISTENERS_LOCK = threading.Lock()


@contextlib.contextmanager
def analysis_listener(callback: Callable[[AnalysisResult], None]) -> Iterator[None]:
    """Call ``callback(analysis)`` with every :class:`AnalysisResult` made while the block runs
    (in the thread that made it), as soon as it is made: studies make an analysis's result when
    that analysis is done, so ``gearte run`` streams each finished analysis to its report
    process, which draws its figures while the next analyses run. An error of ``callback`` is
    ignored (it must not stop an analysis); a study may still change a result after making it,
    so a listener must not assume it final (the report process checks it against the final
    result).
    """
    with _LISTENERS_LOCK:
        _LISTENERS.append(callback)
    try:
        yield
    finally:
        with _LISTENERS_LOCK:
            _LISTENERS.remove(callback)


def to_jsonable(obj: Any) -> Any:
    """Convert numpy scalars/arrays, tuples and nested mappings to plain JSON types.

    Parameters
    ----------
    obj : Any
        A result value: numbers, numpy scalars or arrays, sequences, mappings.

    Returns
    -------
    Any
        The same structure in plain JSON types (NaN/inf as ``None``).
    """
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
    study : StudyResult or None
        The study result holding this analysis (set by :class:`StudyResult`); :meth:`plot`
        needs it, since figures are drawn from the whole study.
    """

    name: str
    title: str
    values: dict[str, Any] = field(default_factory=dict)
    references: list[str] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)
    data: dict[str, Any] = field(default_factory=dict, repr=False)
    files: dict[str, str] = field(default_factory=dict, repr=False)
    created: float = field(default_factory=time.perf_counter, repr=False, compare=False)
    study: Any = field(default=None, repr=False, compare=False)

    def __post_init__(self) -> None:
        for callback in tuple(_LISTENERS):
            with contextlib.suppress(Exception):
                callback(self)

    def __getitem__(self, key: str) -> Any:
        return self.values[key]

    def _repr_html_(self) -> str:
        """Jupyter's view: the analysis's headline rows and results table."""
        return str(_display().analysis_html(self))

    def to_pandas(self, key: str | None = None) -> Any:
        """The analysis as a pandas DataFrame (needs the extra ``gearte[notebooks]``).

        Parameters
        ----------
        key : str, optional
            ``None``: every scalar value (columns ``quantity``, ``unit``, ``value``). A value's
            name with or without its unit (``"te"`` or ``"te [arcmin]"``): that value as a table
            (records one row each, a mapping one row per item, a 1-D series one column beside
            the other series of its length, a 2-D array one column per row).

        Raises
        ------
        KeyError
            When ``key`` names no value of the analysis (the message lists them).
        ImportError
            When pandas is not installed (the message names the extra).
        """
        return _display().analysis_frame(self, key)

    def plot(self) -> list[Any]:
        """The report's figures of this analysis, as matplotlib figures (none shown; in Jupyter
        ``display(fig)`` or leave one as a cell's last value).

        Raises
        ------
        ValueError
            When the analysis belongs to no :class:`StudyResult` (figures need the study).
        """
        if self.study is None:
            raise ValueError(
                f"analysis {self.name!r} belongs to no StudyResult; plot it with "
                f"study_result.plot({self.name!r})"
            )
        return list(_display().study_figures(self.study, self.name))

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

    def __post_init__(self) -> None:
        self._link()

    def _link(self) -> None:
        for a in self.analyses:
            a.study = self

    def __getitem__(self, name: str) -> AnalysisResult:
        for a in self.analyses:
            if a.name == name:
                a.study = self
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

    def _repr_html_(self) -> str:
        """Jupyter's view: the report's summary block (headlines, spec checks, warnings)."""
        return str(_display().study_html(self))

    def to_pandas(self) -> Any:
        """Every scalar value of every analysis as a pandas DataFrame with the columns
        ``analysis``, ``quantity``, ``unit``, ``value`` (the rows of ``summary.csv``); one
        analysis's series and tables: ``result[name].to_pandas(key)``. Needs the extra
        ``gearte[notebooks]``.

        Raises
        ------
        ImportError
            When pandas is not installed (the message names the extra).
        """
        return _display().study_frame(self)

    def plot(self, analysis: str | None = None) -> list[Any]:
        """The report's figures as matplotlib figures: all of them, or those of the analysis
        named ``analysis``. Nothing is shown (no pyplot); in Jupyter ``display(fig)``.

        Raises
        ------
        KeyError
            When ``analysis`` names no analysis of this result.
        """
        self._link()
        return list(_display().study_figures(self, analysis))

    def to_json(self, indent: int | None = 1) -> str:
        return json.dumps(self.to_dict(), indent=indent, ensure_ascii=False, allow_nan=False)
