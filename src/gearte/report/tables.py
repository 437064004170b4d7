"""Tables of an analysis's results: the one layout the HTML report and the CSV files share.

An :class:`~gearte.results.AnalysisResult` holds scalars, mappings, records (lists of
mappings), series (numeric arrays) and occasionally CSV text. :func:`analysis_tables` arranges
them as tables people read:

* scalars → a *Results* table (quantity, value with its unit); ``X_dms`` strings join their
  ``X`` row; ``X_before``/``X_after`` pairs form a *Before / after* table with the change;
* mappings with the same keys (contribution, share, index, … of the same factors) → one table,
  one row per key, one column per mapping;
* records (spectrum peaks, load sweeps, mesh-error terms) → a table, one row per record;
* lists of text (assembly instructions) → a list, expanded;
* numeric series → one summary row each (count, min, mean, max, NaN-aware); the full series go to
  CSV only, grouped by length;
* CSV text → parsed into a table (never shown as text in a cell).

:func:`csv_files` writes the same tables (and the full series) as CSV text.
"""

from __future__ import annotations

import csv
import io
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from gearte.labels import label, value_label
from gearte.units import format_number, format_quantity, split_unit, unit_text

__all__ = [
    "Table",
    "RUN_METADATA",
    "analysis_tables",
    "dominant_text",
    "is_run_metadata",
    "run_metadata_table",
    "csv_files",
    "summarise_series",
    "is_series",
    "item_label",
    "relative_change",
]

#: Series up to this length are written inline (``0.168, 0.832``) instead of summarised.
INLINE_MAX = 8
#: Tables with more rows than this are collapsed (``<details>``) in the report.
COLLAPSE_ROWS = 25

#: Result names (without unit) that describe the run, not the drive: solver timings and
#: counters, seeds and sample counts. The report lists them in its "Run metadata" section, apart
#: from the results (results.json and summary.csv keep them with the analysis).
RUN_METADATA: frozenset[str] = frozenset(
    {
        "seed",
        "samples",
        "verified_seed",
        "solver_wall_time",
        "solver_residual_evaluations",
        "rhs_evaluations",
        "model_evaluations",
        "simulated_seconds_per_wall_second",
        "scoring_time",
        "assignment_time",
        "pairings_scored",
    }
)

#: What an empty list or mapping reads as in a table cell.
EMPTY = "none"


@dataclass
class Table:
    """One table: machine key (file stem), title, header and rows of raw values.

    ``units`` gives each column's unit (``""`` for none); cells are formatted by
    :meth:`cell`. ``kind`` is ``"table"`` or ``"list"`` (one column of text).
    """

    key: str
    title: str
    columns: list[str]
    rows: list[list[Any]]
    units: list[str] = field(default_factory=list)
    kind: str = "table"
    csv: bool = True

    def __post_init__(self) -> None:
        if not self.units:
            self.units = [""] * len(self.columns)

    @property
    def header(self) -> list[str]:
        """Column titles for people (label and unit)."""
        return [
            f"{label(c)} [{unit_text(u)}]" if u else label(c)
            for c, u in zip(self.columns, self.units, strict=True)
        ]

    def cell(self, row: list[Any], j: int) -> str:
        v = row[j]
        if isinstance(v, str):
            return value_label(v)
        if isinstance(v, list | tuple | dict) and not v:
            return EMPTY
        if isinstance(v, list | tuple):
            return ", ".join(
                format_number(x) if not isinstance(x, str) else value_label(x) for x in v
            )
        return format_number(v)

    @property
    def formatted(self) -> list[list[str]]:
        return [[self.cell(r, j) for j in range(len(self.columns))] for r in self.rows]

    @property
    def collapsed(self) -> bool:
        return len(self.rows) > COLLAPSE_ROWS

    def to_csv(self) -> str:
        """The table as CSV text with machine column names (unit in brackets)."""
        buf = io.StringIO()
        w = csv.writer(buf, lineterminator="\n")
        w.writerow(
            [f"{c} [{u}]" if u else c for c, u in zip(self.columns, self.units, strict=True)]
        )
        for r in self.rows:
            w.writerow(["" if _isnan(v) else _csv_cell(v) for v in r])
        return buf.getvalue()


def _isnan(v: Any) -> bool:
    if v is None:
        return True
    try:
        return isinstance(v, float | np.floating) and not np.isfinite(v)
    except TypeError:
        return False


def _csv_cell(v: Any) -> Any:
    if isinstance(v, float | np.floating):
        return repr(float(v))
    if isinstance(v, list | tuple):
        return " ".join(str(x) for x in v)
    return v


def _is_scalar(v: Any) -> bool:
    return v is None or isinstance(v, str | bool | int | float | np.generic)


def is_series(v: Any) -> bool:
    """Whether ``v`` is a list/array of numbers (``None``/NaN allowed), any shape."""
    if isinstance(v, np.ndarray):
        return v.dtype.kind in "biuf" or (
            v.dtype == object and all(x is None or _is_number(x) for x in v.ravel())
        )
    if isinstance(v, list | tuple) and v:
        flat = list(_flatten(v))
        return all(x is None or _is_number(x) for x in flat) and any(_is_number(x) for x in flat)
    return False


def _flatten(v: Any) -> Any:
    for x in v:
        if isinstance(x, list | tuple | np.ndarray):
            yield from _flatten(x)
        else:
            yield x


def _is_number(x: Any) -> bool:
    return isinstance(x, int | float | np.integer | np.floating) and not isinstance(x, bool)


def _as_float(v: Any) -> np.ndarray:
    return np.array(
        [np.nan if x is None else float(x) for x in _flatten(np.asarray(v, dtype=object).tolist())]
        if not isinstance(v, np.ndarray) or v.dtype == object
        else np.asarray(v, dtype=float).ravel(),
        dtype=float,
    )


def summarise_series(v: Any) -> dict[str, Any]:
    """Count, NaN count, min, mean, max of the numeric series ``v``, skipping NaN/None."""
    shape = np.shape(np.asarray(v, dtype=object))
    x = _as_float(v)
    ok = x[np.isfinite(x)]
    return {
        "shape": shape,
        "n": int(x.size),
        "missing": int(x.size - ok.size),
        "min": float(ok.min()) if ok.size else None,
        "mean": float(ok.mean()) if ok.size else None,
        "max": float(ok.max()) if ok.size else None,
    }


def _looks_like_csv(s: str) -> bool:
    lines = s.strip().splitlines()
    return len(lines) >= 2 and all("," in ln for ln in lines[:2])


def _csv_table(key: str, text: str) -> Table:
    rows = list(csv.reader(io.StringIO(text.strip())))
    head, body = rows[0], rows[1:]
    width = max(len(r) for r in rows)
    head = head + [""] * (width - len(head))
    parsed = [[_parse_number(c) for c in r] + [""] * (width - len(r)) for r in body if r]
    return Table(key, label(key.removesuffix("_csv")), head, parsed, csv=False)


def _parse_number(s: str) -> Any:
    try:
        return int(s)
    except ValueError:
        pass
    try:
        return float(s)
    except ValueError:
        return s


def _scalar_text(v: Any, unit: str) -> str:
    if isinstance(v, str):
        return value_label(v)
    return format_quantity(v, unit)


def dominant_text(values: dict[str, Any], key: str) -> str | None:
    """The text of a ``dominant_*`` value ``key`` of an analysis's ``values``, or ``None`` when
    it is not one: ``"none (every contribution is zero)"`` when every mapping of numbers that
    holds it as a key (or, for an empty value, every ``contribution*`` mapping) is all zero —
    nothing dominates then; ``"none"`` for another empty value; otherwise the value as people
    read it."""
    if not split_unit(key)[0].startswith("dominant_"):
        return None
    v = values[key]
    if not isinstance(v, str):
        return None
    rankings = [
        m
        for k, m in values.items()
        if isinstance(m, dict)
        and m
        and all(_is_number(x) for x in m.values())
        and (v in m if v else split_unit(k)[0].startswith("contribution"))
    ]
    if rankings and all(not any(m.values()) for m in rankings):
        return "none (every contribution is zero)"
    return value_label(v) if v else "none"


def is_run_metadata(name: str) -> bool:
    """Whether the result ``name`` (with or without unit) describes the run
    (:data:`RUN_METADATA`)."""
    return split_unit(name)[0] in RUN_METADATA


def run_metadata_table(result: Any) -> Table | None:
    """The report's "Run metadata" table: every :data:`RUN_METADATA` value of every analysis
    (analysis, quantity, value) and the run's total analysis time.

    Parameters
    ----------
    result : StudyResult
        The study result whose report it is.

    Returns
    -------
    Table or None
        ``None`` if the result holds no run metadata.
    """
    rows: list[list[Any]] = []
    for a in result.analyses:
        for k, v in a.values.items():
            if is_run_metadata(k) and _is_scalar(v):
                rows.append([a.title, label(k), _scalar_text(v, split_unit(k)[1])])
    if getattr(result, "elapsed_s", 0.0):
        rows.append(["(whole run)", "Time of the analyses", format_quantity(result.elapsed_s, "s")])
    if not rows:
        return None
    return Table("run_metadata", "Run metadata", ["analysis", "quantity", "value"], rows, csv=False)


def analysis_tables(analysis: Any) -> list[Table]:
    """The tables of one analysis, in reading order (see the module docstring)."""
    values: dict[str, Any] = dict(analysis.values)
    name = analysis.name
    tables: list[Table] = []
    bases = {split_unit(k)[0]: k for k in values}

    # before/after pairs
    pairs: list[tuple[str, str, str]] = []
    for k in values:
        base, unit = split_unit(k)
        if base.endswith("_before"):
            stem = base[: -len("_before")]
            after = f"{stem}_after [{unit}]" if unit else f"{stem}_after"
            if after in values and _is_scalar(values[k]) and _is_scalar(values[after]):
                pairs.append((stem, k, after))
    paired = {k for _, b, a in pairs for k in (b, a)}

    results: list[list[Any]] = []
    series: list[list[Any]] = []
    mappings: dict[tuple[str, ...], list[str]] = {}
    for k, v in values.items():
        if k in paired or is_run_metadata(k):
            continue
        base, unit = split_unit(k)
        if base.endswith("_dms") and base[:-4] in bases:
            continue  # shown beside its value in arcmin
        if isinstance(v, str) and _looks_like_csv(v):
            tables.append(_csv_table(f"{name}_{base}", v))
            continue
        if _is_scalar(v):
            text = dominant_text(values, k) or _scalar_text(v, unit)
            dms = values.get(f"{base}_dms")
            if isinstance(dms, str):
                text += f" ({dms})"
            results.append([label(k), text])
        elif isinstance(v, dict):
            if v and all(_is_scalar(x) for x in v.values()):
                mappings.setdefault(tuple(map(str, v)), []).append(k)
            else:
                tables += _nested_tables(f"{name}_{base}", k, v)
        elif isinstance(v, list | tuple) and v and all(isinstance(x, dict) for x in v):
            tables.append(_records_table(f"{name}_{base}", k, v))
        elif isinstance(v, list | tuple | dict) and not v:
            results.append([label(k), EMPTY])
        elif isinstance(v, list | tuple) and all(isinstance(x, str) for x in v):
            if len(v) <= INLINE_MAX and sum(len(x) for x in v) < 120:
                results.append([label(k), ", ".join(value_label(x) for x in v)])
            else:
                tables.append(
                    Table(f"{name}_{base}", label(k), [base], [[x] for x in v], kind="list")
                )
        elif is_series(v):
            n = int(np.size(np.asarray(v, dtype=object)))
            if n <= INLINE_MAX and np.ndim(np.asarray(v, dtype=object)) == 1:
                results.append(
                    [label(k), ", ".join(format_quantity(x, unit) for x in _as_float(v))]
                )
            else:
                s = summarise_series(v)
                size = "×".join(str(d) for d in s["shape"])
                series.append([label(k), unit_text(unit), size, s["min"], s["mean"], s["max"]])
                if s["missing"]:
                    series[-1][2] += f" ({s['missing']} missing)"
        else:
            results.append([label(k), str(v)])
    out: list[Table] = []
    if results:
        out.append(Table(f"{name}_results", "Results", ["quantity", "value"], results, csv=False))
    if pairs:
        rows = []
        for stem, b, a in pairs:
            unit = split_unit(b)[1]
            vb, va = values[b], values[a]
            change = ""
            if _is_number(vb) and _is_number(va) and np.isfinite(vb) and np.isfinite(va):
                change = format_quantity(va - vb, unit)
                change += relative_change(vb, va)
            rows.append(
                [label(stem), _scalar_text(vb, unit), _scalar_text(va, unit), change or "—"]
            )
        out.append(
            Table(
                f"{name}_before_after",
                "Before and after",
                ["quantity", "before", "after", "change"],
                rows,
                csv=False,
            )
        )
    for keys, ks in mappings.items():
        units = [split_unit(k)[1] for k in ks]
        rows = [[item_label(key)] + [values[k][key] for k in ks] for key in keys]
        title = ", ".join(label(k) for k in ks[:3]) + (" …" if len(ks) > 3 else "")
        out.append(
            Table(
                f"{name}_{split_unit(ks[0])[0]}",
                f"{title} by item",
                ["item"] + [split_unit(k)[0] for k in ks],
                rows,
                units=[""] + units,
            )
        )
    out += tables
    if series:
        out.append(
            Table(
                f"{name}_series",
                "Series (full values in results.json and CSV)",
                ["series", "unit", "values", "min", "mean", "max"],
                series,
                csv=False,
            )
        )
    return out


def item_label(key: str) -> str:
    """``key``, an item of a mapping (a factor, a stage), for people: identifiers get
    :func:`label`."""
    return label(key) if "_" in key and " " not in key else key


def relative_change(before: float, after: float) -> str:
    """The relative change from ``before`` [any unit] to ``after`` [same unit] for people:
    `` (+17 %)``; `` (×3110)`` over 1000 %; ``""`` from 0."""
    if not before:
        return ""
    r = 100 * (after - before) / abs(before)
    if abs(r) >= 1000:
        return f" (×{format_number(after / before, 3)})"
    return f" ({'+' if r > 0 else ''}{format_number(r, 2)} %)"


def _records_table(key: str, name: str, records: Any) -> Table:
    cols: list[str] = []
    for r in records:
        cols += [c for c in map(str, r) if c not in cols]
    rows = [[_plain_cell(r.get(c)) for c in cols] for r in records]
    units = [split_unit(c)[1] for c in cols]
    return Table(key, label(name), [split_unit(c)[0] for c in cols], rows, units=units)


def _plain_cell(v: Any) -> Any:
    if isinstance(v, dict):
        if not v:
            return EMPTY
        return "; ".join(f"{label(a)}: {_plain_text(b)}" for a, b in v.items())
    if isinstance(v, np.ndarray):
        return v.tolist()
    return v


def _plain_text(v: Any) -> str:
    if isinstance(v, str):
        return value_label(v)
    if isinstance(v, list | tuple):
        return ", ".join(_plain_text(x) for x in v) if v else EMPTY
    return format_number(v)


def _nested_tables(key: str, name: str, mapping: dict[str, Any]) -> list[Table]:
    """A mapping holding lists or mappings: its scalars as one table, its parts as tables."""
    scalars = [
        [label(a), _scalar_text(b, split_unit(a)[1])] for a, b in mapping.items() if _is_scalar(b)
    ]
    out = []
    if scalars:
        out.append(Table(key, label(name), ["quantity", "value"], scalars))
    for a, b in mapping.items():
        if _is_scalar(b):
            continue
        sub = f"{key}_{split_unit(a)[0]}"
        if isinstance(b, list | tuple) and b and all(isinstance(x, dict) for x in b):
            out.append(_records_table(sub, f"{label(name)}: {label(a)}", b))
        elif isinstance(b, dict) and all(isinstance(x, dict) for x in b.values()):
            recs = [{"item": k2, **v2} for k2, v2 in b.items()]
            out.append(_records_table(sub, f"{label(name)}: {label(a)}", recs))
        elif isinstance(b, dict):
            rows = [[label(k2), _plain_cell(v2)] for k2, v2 in b.items()]
            out.append(Table(sub, f"{label(name)}: {label(a)}", ["item", "value"], rows))
        else:
            out.append(Table(sub, f"{label(name)}: {label(a)}", ["value"], [[_plain_cell(b)]]))
    return out


def csv_files(result: Any) -> dict[str, str]:
    """CSV text of every tabular result of a study, file name → text.

    * ``summary.csv``: every scalar of every analysis (analysis, quantity, unit, value);
    * ``<analysis>_<first series>.csv``: the analysis's numeric series of one length, side by
      side (one file per length);
    * ``<analysis>_<key>.csv``: each multi-column table (mappings by item, records).

    Names an analysis already writes itself (``analysis.files``) are left to it.
    """
    out: dict[str, str] = {}
    taken = {f for a in result.analyses for f in a.files} | {"results.json", "report.html"}
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(["analysis", "quantity", "unit", "value"])
    for a in result.analyses:
        for k, v in a.values.items():
            if _is_scalar(v) and not (isinstance(v, str) and "\n" in v):
                base, unit = split_unit(k)
                w.writerow([a.name, base, unit, "" if _isnan(v) else _csv_cell(v)])
    out["summary.csv"] = buf.getvalue()
    for a in result.analyses:
        groups: dict[int, list[str]] = {}
        for k, v in a.values.items():
            if is_series(v) and np.ndim(np.asarray(v, dtype=object)) == 1 and len(v) > 1:
                groups.setdefault(len(v), []).append(k)
        for _, ks in groups.items():
            t = Table(
                f"{a.name}_{split_unit(ks[0])[0]}",
                "",
                [split_unit(k)[0] for k in ks],
                [list(r) for r in zip(*[_as_float(a.values[k]) for k in ks], strict=True)],
                units=[split_unit(k)[1] for k in ks],
            )
            out.setdefault(_file_name(t.key), t.to_csv())
        for t in analysis_tables(a):
            if t.csv and t.kind == "table":
                out.setdefault(_file_name(t.key), t.to_csv())
    return {k: v for k, v in out.items() if k not in taken}


def _file_name(key: str) -> str:
    safe = "".join(c if c.isalnum() or c in "-_" else "_" for c in key)
    if len(safe.encode()) > 120:  # a table named after a long label: a file name must fit in 255
        import hashlib

        digest = hashlib.sha1(key.encode("utf-8", "surrogatepass")).hexdigest()[:12]
        safe = safe.encode()[:100].decode("utf-8", "ignore") + "_" + digest
    return f"{safe}.csv"
