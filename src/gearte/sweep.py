"""Parameter sweeps: a grid over case parameters, run through the execution layer.

``gearte sweep CASE.toml --vary stage.eccentricity_mm=1.0:1.6:7 --vary ...`` or, in Python,

>>> from gearte.sweep import run_sweep, write_sweep                       # doctest: +SKIP
>>> sweep = run_sweep("hu2020_rv80e_initial", {"stage.eccentricity_mm": "1.0:1.6:7"})
>>> write_sweep(sweep, "out/sweep")                                       # doctest: +SKIP

Each key is a dotted path into the case file (``section.field``; list items by index,
``pins.0.radius_mm``). The grid is the full factorial of the varied keys, the first key varying
slowest. Keys that must change together (pins and teeth) are *coupled*: ``--vary a,b=1:2,3:4``
gives the two points (a=1, b=2) and (a=3, b=4) as one axis of the grid, and ``--points
table.csv`` reads such an axis from a table (one column per key, one row per point).

Every point is validated like a case file before anything runs. A point that does not validate
(an out-of-range value, a tooth relation that does not hold) is recorded with the validation
message as its reason and skipped; the others run, and the table, ``sweep.json`` and the index
page list the skipped points. Only when no point validates (a misspelt key) does the sweep stop
with the error. Every point runs with the same seed (common random numbers): differences between
points come from the parameters, not from sampling noise.

Points run through :func:`gearte.execution.map_chunks`: in parallel (one point per worker, each
point's own sampled work sequential) when there are at least as many points as workers, otherwise
one after another with each point's sampled work spread over the workers. Results are identical
either way.
"""

from __future__ import annotations

import csv
import io
import itertools
import math
import os
import re
import time
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from gearte.errors import CaseFileError, GearteError, ParameterError

#: Largest ``--points`` file read [bytes].
MAX_POINTS_FILE_BYTES = 10_000_000

__all__ = [
    "Vary",
    "Coupled",
    "parse_vary",
    "read_points",
    "grid_points",
    "SweepResult",
    "run_sweep",
    "write_sweep",
]

_NUM_RE = re.compile(r"^[+-]?\d+$")


@dataclass(frozen=True)
class Vary:
    """One varied key and its values."""

    key: str
    values: tuple[Any, ...]

    @property
    def keys(self) -> tuple[str, ...]:
        return (self.key,)

    @property
    def rows(self) -> tuple[tuple[Any, ...], ...]:
        return tuple((v,) for v in self.values)


@dataclass(frozen=True)
class Coupled:
    """Keys varied together: one axis of the grid whose points are the ``rows`` (one value per
    key, in the order of ``keys``)."""

    keys: tuple[str, ...]
    rows: tuple[tuple[Any, ...], ...]

    @property
    def key(self) -> str:
        """The keys joined by commas (as written after ``--vary``)."""
        return ",".join(self.keys)

    @property
    def values(self) -> tuple[tuple[Any, ...], ...]:
        return self.rows


def _parse_scalar(text: str) -> Any:
    t = text.strip()
    if _NUM_RE.match(t):
        return int(t)
    try:
        return float(t)
    except ValueError:
        pass
    if t.lower() in ("true", "false"):
        return t.lower() == "true"
    return t


def _tidy(x: float) -> float:
    """Round away linspace noise (``1.3000000000000003`` → ``1.3``): 12 significant digits."""
    return float(f"{x:.12g}")


def _range_values(key: str, spec: str) -> tuple[Any, ...]:
    parts = spec.split(":")
    if len(parts) != 3:
        raise ParameterError(f"--vary {key}", spec, "expected START:STOP:N, e.g. 1.0:1.6:7")
    start, stop, n_text = (p.strip() for p in parts)
    if not _NUM_RE.match(n_text) or int(n_text) < 1:
        raise ParameterError(f"--vary {key}", spec, f"N = {n_text!r} must be an integer ≥ 1")
    n = int(n_text)
    from gearte.limits import check_sweep_points

    check_sweep_points(n)
    try:
        a, b = float(start), float(stop)
    except ValueError:
        raise ParameterError(f"--vary {key}", spec, "START and STOP must be numbers") from None
    if not (math.isfinite(a) and math.isfinite(b)):
        raise ParameterError(f"--vary {key}", spec, "START and STOP must be finite")
    if n == 1:
        if a != b:
            raise ParameterError(
                f"--vary {key}", spec, "N = 1 gives one point: write KEY=VALUE or START = STOP"
            )
        values = [a]
    else:
        values = [_tidy(a + (b - a) * i / (n - 1)) for i in range(n)]
    if _NUM_RE.match(start) and _NUM_RE.match(stop) and all(v.is_integer() for v in values):
        return tuple(int(v) for v in values)
    return tuple(values)


def parse_vary(spec: str) -> Vary | Coupled:
    """Parse ``KEY=START:STOP:N`` (``N`` evenly spaced values, ends included) or
    ``KEY=V1,V2,...`` (explicit values) or ``KEY=VALUE``; or coupled keys
    ``K1,K2=A1:A2,B1:B2,...`` (the points (K1=A1, K2=A2), (K1=B1, K2=B2), ...).

    Integer ``START``/``STOP`` with integral steps give integers (for counts).

    >>> parse_vary("stage.eccentricity_mm=1.0:1.5:6").values
    (1.0, 1.1, 1.2, 1.3, 1.4, 1.5)
    >>> parse_vary("stage.pins=38,40").values
    (38, 40)
    >>> parse_vary("stage.pins,stage.cycloid_teeth=38:37,40:39").rows
    ((38, 37), (40, 39))

    Parameters
    ----------
    spec : str
        The ``--vary`` text.

    Returns
    -------
    Vary or Coupled
        The key (or coupled keys) and its values.
    """
    key, sep, rhs = spec.partition("=")
    key, rhs = key.strip(), rhs.strip()
    if not sep or not key or not rhs:
        raise ParameterError(
            "--vary", spec, "expected KEY=START:STOP:N or KEY=V1,V2,... (e.g. demo.x_mm=1:2:5)"
        )
    if "," in key:
        return _coupled(key, rhs)
    if ":" in rhs:
        return Vary(key, _range_values(key, rhs))
    values = tuple(_parse_scalar(v) for v in rhs.split(",") if v.strip())
    if not values:
        raise ParameterError(f"--vary {key}", rhs, "no values given")
    return Vary(key, values)


def _coupled(key: str, rhs: str) -> Coupled:
    keys = tuple(k.strip() for k in key.split(","))
    if any(not k for k in keys):
        raise ParameterError("--vary", key, "empty key in the coupled keys K1,K2,...")
    rows = []
    for item in (i for i in rhs.split(",") if i.strip()):
        parts = item.split(":")
        if len(parts) != len(keys):
            raise ParameterError(
                f"--vary {key}",
                item,
                f"a point of {len(keys)} coupled keys needs {len(keys)} values separated by ':' "
                f"(e.g. {key}={':'.join(['1'] * len(keys))},{':'.join(['2'] * len(keys))})",
            )
        rows.append(tuple(_parse_scalar(p) for p in parts))
    if not rows:
        raise ParameterError(f"--vary {key}", rhs, "no points given")
    return Coupled(keys, tuple(rows))


def read_points(path: str | os.PathLike[str]) -> Coupled:
    """Read coupled points from a CSV table (``--points``): a header of keys, one row per point,
    e.g.::

        stage.pins,stage.cycloid_teeth
        38,37
        40,39

    Values are read as in ``--vary`` (integers, floats, ``true``/``false``, text).

    Parameters
    ----------
    path : path
        The CSV file.

    Raises
    ------
    ParameterError
        The file cannot be read, has no row, an empty key, or a row with a wrong number of
        values (its line is named).
    """
    from gearte.limits import check_sweep_points

    where = f"--points {os.fspath(path)}"
    from gearte.limits import read_input_file

    try:
        text = read_input_file(path, MAX_POINTS_FILE_BYTES).decode("utf-8")
    except (OSError, ValueError) as exc:  # (UnicodeDecodeError is a ValueError)
        reason = getattr(exc, "strerror", None) or exc
        raise ParameterError("--points", os.fspath(path), f"cannot read: {reason}") from None
    lines = [row for row in csv.reader(io.StringIO(text)) if any(c.strip() for c in row)]
    if len(lines) < 2:
        raise ParameterError(where, len(lines), "needs a header of keys and at least one row")
    keys = tuple(k.strip() for k in lines[0])
    if any(not k for k in keys):
        raise ParameterError(where, lines[0], "empty key in the header")
    check_sweep_points(len(lines) - 1)
    rows = []
    for n, row in enumerate(lines[1:], start=2):
        if len(row) != len(keys):
            raise ParameterError(
                f"{where} line {n}", row, f"has {len(row)} values for {len(keys)} keys"
            )
        rows.append(tuple(_parse_scalar(c) for c in row))
    return Coupled(keys, tuple(rows))


def _as_vary(key: str, spec: Any) -> Vary | Coupled:
    if isinstance(spec, Vary | Coupled):
        return spec
    if isinstance(spec, str):
        return parse_vary(f"{key}={spec}")
    if "," in key:
        keys = tuple(k.strip() for k in key.split(","))
        rows = tuple(tuple(r) for r in spec)
        bad = [r for r in rows if len(r) != len(keys)]
        if bad or not rows:
            raise ParameterError(f"vary[{key!r}]", spec, f"give rows of {len(keys)} values")
        return Coupled(keys, rows)
    try:
        values = tuple(v.item() if hasattr(v, "item") else v for v in spec)
    except TypeError:
        values = (spec,)
    if not values:
        raise ParameterError(f"vary[{key!r}]", spec, "no values given")
    return Vary(key, values)


def grid_points(vary: Sequence[Vary | Coupled]) -> list[dict[str, Any]]:
    """Full-factorial grid, first key varying slowest: ``[{key: value, ...}, ...]``; coupled
    keys form one axis (their rows).

    Parameters
    ----------
    vary : sequence of Vary or Coupled
        The varied keys with their values (:func:`parse_vary`).

    Returns
    -------
    list of dict
        One ``{key: value}`` per grid point.
    """
    axes = [[dict(zip(v.keys, row, strict=True)) for row in v.rows] for v in vary]
    return [{k: x for d in combo for k, x in d.items()} for combo in itertools.product(*axes)]


def _set_path(data: dict[str, Any], key: str, value: Any) -> None:
    """Set ``data[a][b][c] = value`` for ``key = "a.b.c"`` (creating missing tables)."""
    parts = key.split(".")
    if any(not p for p in parts):
        raise ParameterError("vary", key, "empty part in the dotted key")
    if parts[0] == "case":
        raise ParameterError("vary", key, "the [case] table (kind, title, ...) cannot be varied")
    node: Any = data
    for i, part in enumerate(parts):
        last = i == len(parts) - 1
        where = ".".join(parts[:i]) or "(top level)"
        if isinstance(node, dict):
            if last:
                node[part] = value
            else:
                if part not in node:
                    node[part] = {}
                node = node[part]
        elif isinstance(node, list) and part.isdigit():
            idx = int(part)
            if idx >= len(node):
                raise ParameterError(
                    "vary", key, f"{where} has {len(node)} items; index {idx} is out of range"
                )
            if last:
                node[idx] = value
            else:
                node = node[idx]
        else:
            raise ParameterError(
                "vary", key, f"{where} is a value ({node!r}), not a table: cannot set {part!r}"
            )


def _deep_copy(data: Any) -> Any:
    if isinstance(data, dict):
        return {k: _deep_copy(v) for k, v in data.items()}
    if isinstance(data, list):
        return [_deep_copy(v) for v in data]
    return data


def _base_case(case: Any) -> tuple[dict[str, Any], str, str]:
    """The case as a plain dict, where it came from and its name."""
    if isinstance(case, Mapping):
        data = _deep_copy(dict(case))
        name = str(data.get("case", {}).get("name") or data.get("case", {}).get("kind", "case"))
        return data, "<dict>", name
    if hasattr(case, "model_dump"):  # a validated Case
        data = case.model_dump(mode="json")
        return data, f"<{case.case.kind} case>", str(case.case.name or case.case.kind)
    from gearte.cases import case_path

    path = case_path(case)
    from gearte.io.case_file import read_case_toml

    data = read_case_toml(path)
    meta = data.get("case")
    if isinstance(meta, dict) and "name" not in meta:
        meta["name"] = Path(path).stem
    return data, str(path), Path(path).stem


def _scalars(result: Any) -> dict[str, Any]:
    """Every scalar value of a StudyResult: ``"analysis.value name"`` → number (mappings
    flattened with dots; arrays, lists and strings left out)."""
    import numpy as np

    out: dict[str, Any] = {}

    def visit(prefix: str, value: Any) -> None:
        if isinstance(value, Mapping):
            for k, v in value.items():
                visit(f"{prefix}.{k}", v)
        elif isinstance(value, bool | np.bool_):
            out[prefix] = bool(value)
        elif isinstance(value, int | np.integer):
            out[prefix] = int(value)
        elif isinstance(value, float | np.floating):
            out[prefix] = float(value)
        elif isinstance(value, np.ndarray) and value.ndim == 0 and value.dtype.kind in "biuf":
            visit(prefix, value.item())

    for a in result.analyses:
        for name, value in a.values.items():
            visit(f"{a.name}.{name}", value)
    return out


def _run_point(task: tuple[int, dict[str, Any], str, str, dict[str, Any]]) -> dict[str, Any]:
    """Run one grid point (module-level: shipped to Dask workers). Returns its scalars or the
    error that stopped it (non-convergence and the like; bugs propagate)."""
    index, data, kind, kind_module, opts = task
    from gearte.studies import RunOptions, available_kinds, register_kind, run_case

    if kind not in available_kinds():  # a plugin kind on a fresh worker
        register_kind(kind, kind_module)
    t0 = time.perf_counter()
    try:
        result = run_case(data, RunOptions(**opts))
    except CaseFileError:
        raise
    except GearteError as exc:
        out: dict[str, Any] = {
            "index": index,
            "values": {},
            "error": f"{type(exc).__name__}: {exc}",
            "warnings": [],
            "elapsed": time.perf_counter() - t0,
        }
    else:
        out = {
            "index": index,
            "values": _scalars(result),
            "error": None,
            "warnings": list(result.warnings),
            "elapsed": time.perf_counter() - t0,
        }
        _unlink(result)
    return out


def _unlink(result: Any) -> None:
    """Break the reference cycle of a finished point's result (each analysis refers back to its
    study result, which holds the analyses), so that the point's arrays are freed as soon as the
    point is done, by reference counting.

    gearte's own processes collect the older generations rarely (:mod:`gearte._gc`: every ~10^8
    allocations), so left to the collector the cycle of every point of a sweep was kept to the
    end of the sweep (~2 MB per hu2020_rv80e_initial point); with it unlinked the memory stays
    flat (``tests/test_sweep.py``). No explicit ``gc.collect`` here: points run in parallel
    threads, and a collection in one of them while another first imports numba could stall both.
    """
    for a in getattr(result, "analyses", ()):
        a.study = None
    result.analyses = []


@dataclass
class SweepResult:
    """Results of a sweep: one row per grid point.

    Attributes
    ----------
    name, kind, title, source : str
        The base case.
    vary : list of Vary
        The varied keys and their values.
    points : list of dict
        ``{key: value}`` of each grid point.
    values : list of dict
        Scalar results of each point (``"analysis.value [unit]"`` → number).
    errors : list of str or None
        Why a point failed (non-convergence, ...) or was skipped (``"invalid case: ..."``, the
        validation messages), ``None`` where it ran.
    skipped : list of bool
        Points that did not validate and were not run.
    """

    name: str
    kind: str
    title: str
    source: str
    vary: list[Vary | Coupled]
    points: list[dict[str, Any]]
    values: list[dict[str, Any]]
    errors: list[str | None]
    warnings: list[list[str]] = field(default_factory=list)
    seed: int | None = None
    samples: int | None = None
    elapsed_s: float = 0.0
    point_elapsed_s: list[float] = field(default_factory=list)
    #: True when the sweep was interrupted: only the points that finished are here.
    partial: bool = False
    backend: str = ""
    skipped: list[bool] = field(default_factory=list)

    def __post_init__(self) -> None:
        if not self.skipped:
            self.skipped = [False] * len(self.points)

    @property
    def keys(self) -> list[str]:
        return [k for v in self.vary for k in v.keys]

    def coupled_with(self, key: str) -> tuple[str, ...]:
        """The keys varied together with ``key`` (itself included)."""
        for v in self.vary:
            if key in v.keys:
                return v.keys
        return (key,)

    @property
    def statuses(self) -> list[str]:
        """``"ok"``, ``"failed"`` (the run stopped: the error says why) or ``"invalid"`` (did not
        validate, not run) for each point."""
        return [
            "invalid" if s else ("failed" if e else "ok")
            for s, e in zip(self.skipped, self.errors, strict=True)
        ]

    @property
    def columns(self) -> list[str]:
        """Names of the scalar results, in order of first appearance."""
        cols: dict[str, None] = {}
        for row in self.values:
            cols.update(dict.fromkeys(row))
        return list(cols)

    def column(self, name: str) -> list[Any]:
        """Values of one result (or varied key) over the points; NaN where missing."""
        if name in self.keys:
            return [p[name] for p in self.points]
        if name not in self.columns:
            raise KeyError(f"no result {name!r}; have {self.columns}")
        return [row.get(name, math.nan) for row in self.values]

    def rows(self) -> list[dict[str, Any]]:
        """The table: varied keys, every scalar result, ``error``."""
        cols = self.columns
        return [
            {**p, **{c: v.get(c) for c in cols}, "status": st, "error": e or ""}
            for p, v, e, st in zip(
                self.points, self.values, self.errors, self.statuses, strict=True
            )
        ]

    def to_csv(self) -> str:
        buf = io.StringIO()
        w = csv.DictWriter(
            buf, fieldnames=[*self.keys, *self.columns, "status", "error"], lineterminator="\n"
        )
        w.writeheader()
        for row in self.rows():
            w.writerow(
                {
                    k: ("" if v is None else repr(v) if isinstance(v, float) else v)
                    for k, v in row.items()
                }
            )
        return buf.getvalue()

    def to_dict(self) -> dict[str, Any]:
        from gearte._version import __version__
        from gearte.results import to_jsonable

        return {
            "gearte_version": __version__,
            "case": {
                "name": self.name,
                "kind": self.kind,
                "title": self.title,
                "source": self.source,
            },
            "vary": {
                v.key: [list(r) for r in v.rows] if isinstance(v, Coupled) else list(v.values)
                for v in self.vary
            },
            "partial": self.partial,
            "seed": self.seed,
            "samples": self.samples,
            "backend": self.backend,
            "elapsed [s]": round(self.elapsed_s, 4),
            "columns": self.columns,
            "constant_columns": [
                c for c in self.columns if len({repr(v) for v in self.column(c)}) == 1
            ],
            "invalid_points": sum(self.skipped),
            "failed_points": sum(1 for s in self.statuses if s == "failed"),
            "points": [
                {
                    "params": p,
                    "values": to_jsonable(v),
                    "status": st,
                    "error": e,
                    "warnings": w,
                    "elapsed [s]": round(t, 4),
                }
                for p, v, e, w, t, st in zip(
                    self.points,
                    self.values,
                    self.errors,
                    self.warnings,
                    self.point_elapsed_s,
                    self.statuses,
                    strict=True,
                )
            ],
        }

    def to_json(self, indent: int | None = 1) -> str:
        import json

        return json.dumps(self.to_dict(), indent=indent, ensure_ascii=False, allow_nan=False)


def run_sweep(
    case: Any,
    vary: Mapping[str, Any] | Sequence[Vary | Coupled | str],
    *,
    seed: int | None = None,
    samples: int | None = None,
    scheduler: Any = None,
    workers: int | None = None,
    progress: bool = True,
) -> SweepResult:
    """Run ``case`` at every point of a grid over its parameters.

    Parameters
    ----------
    case : path, bundled case name, dict or validated Case
        The base case.
    vary : mapping or sequence
        ``{"section.field": spec}`` where ``spec`` is ``"START:STOP:N"``, ``"V1,V2,..."`` or a
        sequence of values, or ``{"k1,k2": [(a1, a2), (b1, b2)]}`` / ``{"k1,k2": "a1:a2,b1:b2"}``
        for coupled keys; or a sequence of ``"KEY=..."`` strings / :class:`Vary` /
        :class:`Coupled` (:func:`read_points`).
    seed, samples : int, optional
        Override the case's seed and Monte-Carlo sample counts (the same for every point).
    scheduler, workers :
        Where to run, as for :func:`gearte.execution.map_chunks` (a Dask address or ``Client``
        runs the points on the cluster).
    progress : bool
        Progress bar over points (terminal only).

    Raises
    ------
    ParameterError
        A malformed ``vary`` entry, or a key that cannot be set.
    CaseFileError
        No point validates: the message names the field, the value and the first point. (Points
        that do not validate beside others that do are recorded and skipped.)
    """
    from gearte.execution import executor_scope, map_chunks
    from gearte.io.case_file import load_case_dict
    from gearte.studies import get_kind

    varies: list[Vary | Coupled]
    if isinstance(vary, Mapping):
        varies = [_as_vary(k, s) for k, s in vary.items()]
    else:
        varies = [v if isinstance(v, Vary | Coupled) else parse_vary(v) for v in vary]
    if not varies:
        raise ParameterError("vary", vary, "give at least one key to vary")
    dup = [k for k, n in _count([k for v in varies for k in v.keys]).items() if n > 1]
    if dup:
        raise ParameterError("vary", dup[0], "key given more than once")

    from gearte.limits import check_sweep_points

    check_sweep_points(math.prod(len(v.values) for v in varies))
    base, source, name = _base_case(case)
    points = grid_points(varies)
    cases: dict[int, dict[str, Any]] = {}
    invalid: dict[int, CaseFileError] = {}
    validated = None
    for i, p in enumerate(points):
        data = _deep_copy(base)
        for k, v in p.items():
            _set_path(data, k, v)
        where = ", ".join(f"{k}={v!r}" for k, v in p.items())
        try:
            validated = load_case_dict(data, source=f"{source} at {where}")
        except CaseFileError as exc:  # recorded and skipped (issue 15.5)
            invalid[i] = exc
            continue
        cases[i] = data
    if validated is None:  # nothing to run: a wrong key, or every value out of range
        raise invalid[0]
    from gearte.studies import check_samples_override

    check_samples_override(validated, samples)
    kind = str(validated.case.kind)
    kind_module = get_kind(kind).__name__
    title = str(validated.case.title)

    t0 = time.perf_counter()
    done: dict[int, dict[str, Any]] = {}
    interrupted: KeyboardInterrupt | None = None
    by_points, backend = False, "?"
    try:
        with executor_scope(scheduler, workers) as ex:
            backend = ex.name
            by_points = len(cases) >= ex.workers or ex.workers == 1
            inner: dict[str, Any] = {"progress": False, "seed": seed, "samples": samples}
            if by_points:
                inner |= {"scheduler": None, "workers": 1}
                tasks = [(i, c, kind, kind_module, inner) for i, c in cases.items()]
                map_chunks(
                    _run_point,
                    tasks,
                    scheduler=ex,
                    progress=progress,
                    description=f"sweep {name}",
                    unit="points",
                    on_result=done.__setitem__,
                )
            else:  # few points: one after another, each spreading its samples over the workers
                inner |= {"scheduler": ex, "workers": workers}
                for i, c in cases.items():
                    done[i] = _run_point((i, c, kind, kind_module, inner))
    except KeyboardInterrupt as exc:  # keep what finished, marked partial
        interrupted = exc
    for i, bad in invalid.items():
        reason = "; ".join(f"{f}: {m}" for f, m in bad.errors)
        done[i] = {
            "index": i,
            "values": {},
            "error": f"invalid case: {reason}",
            "warnings": [],
            "elapsed": 0.0,
        }
    order = sorted(done)
    out = [done[i] for i in order]
    result = SweepResult(
        name=name,
        kind=kind,
        title=title,
        source=source,
        vary=varies,
        points=[points[i] for i in order],
        values=[o["values"] for o in out],
        errors=[o["error"] for o in out],
        warnings=[o["warnings"] for o in out],
        seed=seed,
        samples=samples,
        elapsed_s=time.perf_counter() - t0,
        point_elapsed_s=[o["elapsed"] for o in out],
        backend=f"{backend} ({'points' if by_points else 'samples'} in parallel)",
        partial=interrupted is not None,
        skipped=[i in invalid for i in order],
    )
    if interrupted is not None:
        from gearte.errors import Interrupted

        signum = getattr(interrupted, "signum", 2)
        raise Interrupted(signum, partial=result) from None
    return result


def _count(items: Sequence[str]) -> dict[str, int]:
    counts: dict[str, int] = {}
    for i in items:
        counts[i] = counts.get(i, 0) + 1
    return counts


def write_sweep(
    result: SweepResult,
    out_dir: str | os.PathLike[str],
    *,
    plots: bool = True,
    workers: int | None = None,
) -> dict[str, Any]:
    """Write ``sweep.csv``, ``sweep.json``, ``index.html`` and (unless ``plots=False``) under
    ``plots/`` one PNG per scalar result that varies over the sweep, with one panel per varied
    key. The index page links every figure and lists the points that were skipped as invalid or
    failed, with their reasons. Figures are rendered before any file is written, in ``workers``
    forked processes (default: the cores this process may use).

    Parameters
    ----------
    result : SweepResult
        The sweep.
    out_dir : str or os.PathLike
        Output folder (created).
    plots : bool
        Also write the PNG figures.

    Returns
    -------
    dict
        ``{"csv": path, "json": path, "index": path, "plots": [paths]}``.
    """
    from gearte.plotting.sweep import varying_columns
    from gearte.report.sweep_page import sweep_index_html

    rendered: dict[str, bytes] = {}
    listed: list[tuple[str, str, str]] = []
    if plots:
        import base64

        from gearte.plotting.sweep import figures
        from gearte.report.html import render_all

        figs = figures(result)
        # drawn in parallel (forked processes), the way the report draws its figures
        pngs = render_all([f for _, f in figs], workers, polished=True)
        for (stem, fig), png in zip(figs, pngs, strict=True):
            name, n = f"plots/{stem}.png", 1
            while name in rendered:  # two results with the same safe file name
                n += 1
                name = f"plots/{stem}_{n}.png"
            rendered[name] = base64.b64decode(png.png)
            listed.append((name, fig.title, fig.caption))
    from gearte.report.outputs import write_file_set

    page = sweep_index_html(result, listed, varying=varying_columns(result), plots=plots)
    files = {
        "sweep.csv": result.to_csv().encode(),
        "sweep.json": result.to_json().encode(),
        "index.html": page.encode(),
    }
    written = write_file_set(out_dir, {**files, **rendered})
    return {
        "csv": written["sweep.csv"],
        "json": written["sweep.json"],
        "index": written["index.html"],
        "plots": [written[k] for k in rendered],
    }
