"""Readers of test-bench measurements: angular TE traces and hysteresis curves (CSV).

A bench file is a small declared header followed by a comma- (or semicolon-, tab-) separated
table whose column names carry their unit::

    # speed_rpm: 15
    # torque_Nm: 0
    # oil_temperature_C: 40
    forward_position [deg],forward_te [arcsec],backward_position [deg],backward_te [arcsec]
    0.0000,1.27,360.0000,-20.4
    ...

* ``# key: value`` lines before the table are metadata. Known keys: ``speed_rpm``, ``torque_Nm``,
  ``oil_temperature_C``, ``serial``, ``sample_rate_Hz``, and ``angle_unit`` / ``te_unit`` /
  ``torque_unit``, which declare the unit of columns written without one. Other ``#`` lines are
  comments; an unknown ``key:`` is an error (a misspelt key would be silently lost otherwise).
* TE trace columns: ``forward_position``, ``forward_te``, ``backward_position``, ``backward_te``
  (either direction alone is accepted; ``position``/``te`` mean the forward direction). Angle
  units: ``deg``, ``arcmin``, ``arcsec``, ``rad``. Positions are the output angle over one output
  revolution (≥ 95 % of 360° covered), strictly monotone in either sense.
* Hysteresis columns: ``torque`` (``N·m``, ``Nm``, ``N·mm``, ``Nmm``, ``kN·m``), ``angle`` (an
  angle unit) and optionally ``branch`` (``ascending``/``descending`` for torque rising/falling,
  or ``loading``/``unloading`` for |torque| rising/falling). Without it the branch is inferred
  (see :func:`gearte.models.catalogue.branch_directions`).

Every malformed file raises one :class:`gearte.errors.BenchFileError` naming file, line and
column; a reader returns a complete object or raises — nothing is half-imported.
Everything returned is in gearte's units (rad, N·mm).
"""

from __future__ import annotations

import difflib
import os
import re
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from gearte.errors import BenchFileError, BenchFileErrors, ParameterError
from gearte.io._textfile import read_header, read_text_file
from gearte.models.bench_data import HysteresisCurve, TETrace
from gearte.units import ARCMIN_PER_RAD, ARCSEC_PER_RAD, DEG_PER_RAD, Nm_to_Nmm, rad_to_deg

__all__ = [
    "TETrace",
    "HysteresisCurve",
    "ImportOptions",
    "TE_COLUMN_ALIASES",
    "HYSTERESIS_COLUMN_ALIASES",
    "metadata_from_name",
    "read_te_trace",
    "read_te_folder",
    "series_problems",
    "TE_CONVENTION",
    "read_hysteresis",
    "write_te_trace",
    "write_hysteresis",
    "MAX_FILE_BYTES",
    "MIN_POINTS",
]

MAX_FILE_BYTES = 256 * 1024 * 1024
"""Largest bench file read [bytes] (a kHz trace of one revolution is a few MB)."""
MIN_POINTS = 16
"""Fewest samples per trace or curve."""

_ANGLE_UNITS = {
    "deg": 1.0 / DEG_PER_RAD,
    "°": 1.0 / DEG_PER_RAD,
    "degree": 1.0 / DEG_PER_RAD,
    "degrees": 1.0 / DEG_PER_RAD,
    "arcmin": 1.0 / ARCMIN_PER_RAD,
    "'": 1.0 / ARCMIN_PER_RAD,
    "arcsec": 1.0 / ARCSEC_PER_RAD,
    '"': 1.0 / ARCSEC_PER_RAD,
    "rad": 1.0,
}
_TORQUE_UNITS = {
    "n·m": float(Nm_to_Nmm(1.0)),
    "nm": float(Nm_to_Nmm(1.0)),
    "n*m": float(Nm_to_Nmm(1.0)),
    "n.m": float(Nm_to_Nmm(1.0)),
    "n m": float(Nm_to_Nmm(1.0)),
    "kn·m": float(Nm_to_Nmm(1000.0)),
    "knm": float(Nm_to_Nmm(1000.0)),
    "n·mm": 1.0,
    "nmm": 1.0,
    "n*mm": 1.0,
    "n.mm": 1.0,
}
_TE_COLUMNS = ("forward_position", "forward_te", "backward_position", "backward_te")
_HYST_COLUMNS = ("torque", "angle", "branch")
_DIRECTION_WORDS = {
    "forward": ("forward", "fwd", "fw", "forw", "cw", "clockwise", "positive", "pos_dir", "plus"),
    "backward": ("backward", "bwd", "bw", "back", "ccw", "counterclockwise", "anticlockwise",
                 "negative", "neg_dir", "minus", "reverse", "rev"),
}  # fmt: skip
_QUANTITY_WORDS = {
    "position": ("position", "pos", "angle", "output_angle", "output_position", "theta", "phi",
                 "angular_position", "rotation_angle", "encoder_angle"),
    "te": ("te", "transmission_error", "angular_te", "ate", "error", "angular_transmission_error",
           "te_angle", "trans_error"),
}  # fmt: skip


def _te_aliases() -> dict[str, str]:
    out = {"position": "forward_position", "te": "forward_te"}
    for d, dwords in _DIRECTION_WORDS.items():
        for q, qwords in _QUANTITY_WORDS.items():
            for dw in dwords:
                for qw in qwords:
                    for name in (f"{dw}_{qw}", f"{qw}_{dw}"):
                        out.setdefault(name, f"{d}_{q}")
    for q in _QUANTITY_WORDS:
        for qw in _QUANTITY_WORDS[q]:
            out.setdefault(qw, f"forward_{q}")
    return out


TE_COLUMN_ALIASES: dict[str, str] = _te_aliases()
"""Column names of TE traces as rigs write them (normalised: lower case, runs of other
characters as ``_``) → gearte's column: ``TE CW``, ``te_fwd``, ``Angle CCW``, ``backward angle``,
``transmission_error_reverse``, ... (direction words: forward/fwd/cw/positive/...,
backward/bwd/ccw/reverse/...; quantity words: position/angle/theta/..., te/transmission_error/...).
A bare quantity (``angle``, ``te``) is the forward direction."""
HYSTERESIS_COLUMN_ALIASES: dict[str, str] = {
    **{w: "angle" for w in ("output_angle", "torsion_angle", "twist", "torsion", "twist_angle",
                            "angular_displacement", "rotation", "rotation_angle", "position",
                            "output_position", "theta")},
    **{w: "torque" for w in ("output_torque", "load", "load_torque", "moment", "torque_output",
                             "applied_torque", "t_out", "m")},
    **{w: "branch" for w in ("direction", "phase", "segment")},
}  # fmt: skip
"""Column names of hysteresis curves as rigs write them → gearte's column."""
_TE_ALIASES = TE_COLUMN_ALIASES
_HYST_ALIASES = HYSTERESIS_COLUMN_ALIASES
_UNIT_GROUPS = {
    "position": ("forward_position", "backward_position"),
    "te": ("forward_te", "backward_te"),
}
_META_NUMERIC = ("speed_rpm", "torque_Nm", "oil_temperature_C", "sample_rate_Hz")
_META_TEXT = ("serial", "angle_unit", "te_unit", "torque_unit", "kind")
_KEY = re.compile(r"^#\s*([A-Za-z_][A-Za-z0-9_]*)\s*:\s*(.*?)\s*$")
_HEADER = re.compile(r"^\s*([^\[\]]+?)\s*(?:\[\s*([^\[\]]*?)\s*\])?\s*$")
_PAREN_UNIT = re.compile(r"^(.*?)\s*\(\s*([^()]*?)\s*\)\s*$")
_TE_LIMIT = 1.0 / DEG_PER_RAD  # a TE beyond 1° is a unit mistake, not a reducer


_TE_CONVENTIONS = {"nominal_minus_output": 1.0, "output_minus_nominal": -1.0}
TE_CONVENTION = "nominal_minus_output"
"""gearte's TE sign: TE = nominal output angle (input angle / ratio) − measured output angle,
both in the forward sense of rotation. With it a loaded reducer lags in both directions, so the
forward trace lies above the backward one and TE_forward − TE_backward > 0 is the running lost
motion. A rig writing output − nominal is read with ``te_convention = "output_minus_nominal"``
(the TE columns are negated on reading)."""

_NAME_FIELDS = {
    "torque": "torque_Nm",
    "torque_Nm": "torque_Nm",
    "speed": "speed_rpm",
    "speed_rpm": "speed_rpm",
    "temp": "oil_temperature_C",
    "temperature": "oil_temperature_C",
    "oil_temperature_C": "oil_temperature_C",
}
_NUMBER = r"[-+]?\d+(?:[.,p]\d+)?"


def _pattern_regex(pattern: str) -> re.Pattern:
    """``"{torque}Nm_{speed}rpm_{temp}C"`` → a regex with one named group per field."""
    parts = re.split(r"(\{[^{}]*\})", pattern)
    out, seen = [], set()
    for part in parts:
        if part.startswith("{") and part.endswith("}"):
            name = part[1:-1].strip()
            if name == "*":
                out.append(".*?")
                continue
            if name not in _NAME_FIELDS:
                known = ", ".join("{" + k + "}" for k in _NAME_FIELDS)
                raise ParameterError(
                    "data.file_name_pattern", pattern,
                    f"unknown field {{{name}}} (known: {known}, {{*}} for any text)",
                )  # fmt: skip
            key = _NAME_FIELDS[name]
            if key in seen:
                raise ParameterError("data.file_name_pattern", pattern, f"{part} appears twice")
            seen.add(key)
            out.append(f"(?P<{key}>{_NUMBER})")
        else:
            if "{" in part or "}" in part:
                raise ParameterError("data.file_name_pattern", pattern, "unbalanced braces")
            out.append(re.escape(part))
    if not seen:
        raise ParameterError(
            "data.file_name_pattern", pattern, "names no field ({torque}, {speed}, {temp})"
        )
    return re.compile("".join(out), re.IGNORECASE)


def metadata_from_name(name: str, pattern: str) -> dict[str, float] | None:
    """Operating point written in a file name, read with a pattern.

    Parameters
    ----------
    name : str
        The file name (its folder and extension are ignored).
    pattern : str
        Literal text with fields ``{torque}`` [N·m], ``{speed}`` [rpm], ``{temp}`` [°C] (or
        ``{torque_Nm}``, ``{speed_rpm}``, ``{temperature}``, ``{oil_temperature_C}``) and ``{*}``
        for any text; searched anywhere in the name, case-insensitive. A decimal point may be
        written ``.``, ``,`` or ``p`` (``12p5``).

    Returns
    -------
    dict or None
        ``{"torque_Nm": ..., "speed_rpm": ..., "oil_temperature_C": ...}`` (the fields the
        pattern names), or ``None`` when the name does not match.

    Examples
    --------
    >>> metadata_from_name("RV81_300Nm_15rpm_40C.csv", "{torque}Nm_{speed}rpm_{temp}C")
    {'torque_Nm': 300.0, 'speed_rpm': 15.0, 'oil_temperature_C': 40.0}
    """
    m = _pattern_regex(pattern).search(Path(name).stem)
    if m is None:
        return None
    return {
        k: float(v.replace(",", ".").replace("p", ".").replace("P", "."))
        for k, v in m.groupdict().items()
    }


def _norm(name: str) -> str:
    return re.sub(r"[^0-9a-z]+", "_", name.strip().lower()).strip("_")


@dataclass(frozen=True)
class ImportOptions:
    """How to read a rig's own export without editing it.

    Attributes
    ----------
    columns : mapping
        gearte column → the file's column name, e.g. ``{"forward_te": "TE CW [µrad]"}``; beside the
        built-in aliases (:data:`TE_COLUMN_ALIASES`, :data:`HYSTERESIS_COLUMN_ALIASES`).
    units : mapping
        Unit of columns written without one: per gearte column (``forward_te``), per group
        (``position``, ``te`` for both directions; ``angle``, ``torque`` of hysteresis curves) or
        per file column name. A unit in the header wins; a ``# te_unit:`` line of a file wins
        over this mapping.
    file_name_pattern : str or None
        Operating point in the file names, e.g. ``"{torque}Nm_{speed}rpm_{temp}C"``
        (:func:`metadata_from_name`).
    te_convention : str
        The file's TE sign: ``"nominal_minus_output"`` (gearte's, :data:`TE_CONVENTION`) or
        ``"output_minus_nominal"`` (negated on reading).
    """

    columns: Mapping[str, str] = field(default_factory=dict)
    units: Mapping[str, str] = field(default_factory=dict)
    file_name_pattern: str | None = None
    te_convention: str = TE_CONVENTION

    def __post_init__(self) -> None:
        known = (*_TE_COLUMNS, *_HYST_COLUMNS)
        for k, v in self.columns.items():
            if k not in known:
                raise ParameterError(f"data.columns.{k}", v, f"unknown gearte column (known: "
                                     f"{', '.join(known)})")  # fmt: skip
            if not str(v).strip():
                raise ParameterError(f"data.columns.{k}", v, "empty column name")
        targets = [_norm(_split_unit(v)[0] if "[" in v else v) for v in self.columns.values()]
        for t in set(targets):
            if targets.count(t) > 1:
                raise ParameterError("data.columns", dict(self.columns),
                                     f"the file column {t!r} is mapped twice")  # fmt: skip
        for k, u in self.units.items():
            unit_ok = _unit_key(u, "torque") in _TORQUE_UNITS or u.strip().lower() in _ANGLE_UNITS
            if not unit_ok:
                raise ParameterError(
                    f"data.units.{k}", u,
                    f"not a unit gearte reads (angles: {', '.join(_ANGLE_UNITS)}; torques: "
                    f"{', '.join(_TORQUE_UNITS)})",
                )  # fmt: skip
        if self.te_convention not in _TE_CONVENTIONS:
            raise ParameterError("data.te_convention", self.te_convention,
                                 f"must be one of {', '.join(_TE_CONVENTIONS)}")  # fmt: skip
        if self.file_name_pattern is not None:
            _pattern_regex(self.file_name_pattern)

    @property
    def te_sign(self) -> float:
        """Factor applied to the TE columns on reading (+1 or −1)."""
        return _TE_CONVENTIONS[self.te_convention]

    def unit_for(self, name: str, raw: str) -> str | None:
        """Unit from the mapping for gearte column ``name`` written as ``raw`` in the file."""
        for key in (name, raw, _norm(raw)):
            if key in self.units:
                return self.units[key]
        for group, members in _UNIT_GROUPS.items():
            if name in members and group in self.units:
                return self.units[group]
        return None


_DEFAULT_OPTIONS = ImportOptions()


def _unit_key(unit: str, what: str) -> str:
    key = unit.strip().lower().replace(" ", "") if what == "torque" else unit.strip().lower()
    return "n·m" if key in ("n·m", "n m") else key


# ---- parsing -----------------------------------------------------------------------------
@dataclass
class _Table:
    source: str
    meta: dict
    meta_lines: dict
    names: list[str]
    units: list[str | None]
    data: np.ndarray  # (rows, cols) float; text columns hold NaN
    text: dict  # column index -> list[str]
    data_lines: np.ndarray  # 1-based file line of each row
    header_line: int
    raw_names: list[str] = field(default_factory=list)  # as the file writes them
    options: ImportOptions = _DEFAULT_OPTIONS

    def col_label(self, j: int) -> str:
        unit = f" [{self.units[j]}]" if self.units[j] else ""
        return f"{j + 1} '{self.names[j]}{unit}'"

    def meta_error(self, key: str, reason: str) -> BenchFileError:
        """The error of metadata ``key``, naming the line that declares it."""
        return BenchFileError(self.source, self.meta_lines[key], None, reason)


def _split_unit(cell: str) -> tuple[str, str | None]:
    m = _HEADER.match(cell)
    if m is None:
        return cell.strip(), None
    raw, unit = m.group(1).strip(), m.group(2)
    if unit is None:  # "TE (arcsec)": a unit in parentheses, where it is one gearte knows
        pm = _PAREN_UNIT.match(raw)
        if pm and (pm.group(2).lower() in _ANGLE_UNITS or _unit_key(pm.group(2), "torque")
                   in _TORQUE_UNITS):  # fmt: skip
            raw, unit = pm.group(1), pm.group(2)
    name = re.sub(r"[\s\-]+", "_", raw.strip().lower())
    return name, unit


def _raise(problems: list[BenchFileError]) -> None:
    if len(problems) == 1:
        raise problems[0]
    if problems:
        raise BenchFileErrors(problems)


def _parse(path, allowed, aliases, text_columns=(), options=_DEFAULT_OPTIONS) -> _Table:
    src, text = read_text_file(path, BenchFileError, MAX_FILE_BYTES)
    lines = text.splitlines()
    if not any(ln.strip() for ln in lines):
        raise BenchFileError(src, 1, None, "is empty (no header, no data)")
    meta: dict = {}
    meta_lines: dict = {}
    problems: list[BenchFileError] = []  # header and metadata problems, reported together
    mapped = {_norm(_split_unit(v)[0]): k for k, v in options.columns.items() if k in allowed}
    i = 0
    while i < len(lines):
        ln = lines[i].strip()
        if not ln:
            i += 1
            continue
        if not ln.startswith("#"):
            break
        m = _KEY.match(ln)
        if m:
            key, value = m.group(1), m.group(2)
            if key not in _META_NUMERIC and key not in _META_TEXT:
                close = difflib.get_close_matches(key, _META_NUMERIC + _META_TEXT, 1)
                hint = f"; did you mean '{close[0]}'?" if close else ""
                known = ", ".join(_META_NUMERIC + _META_TEXT)
                problems.append(BenchFileError(
                    src, i + 1, None, f"unknown metadata key '{key}' (known: {known}){hint}"
                ))  # fmt: skip
                i += 1
                continue
            if key in meta:
                problems.append(BenchFileError(
                    src, i + 1, None,
                    f"metadata key '{key}' repeated (first on line {meta_lines[key]})",
                ))  # fmt: skip
                i += 1
                continue
            if key in _META_NUMERIC:
                try:
                    v = float(value)
                except ValueError:
                    v = float("nan")
                if not np.isfinite(v):
                    problems.append(BenchFileError(
                        src, i + 1, None, f"metadata '{key}' must be a finite number, got {value!r}"
                    ))  # fmt: skip
                    i += 1
                    continue
                meta[key] = v
            else:
                meta[key] = value
            meta_lines[key] = i + 1
        i += 1
    try:
        header_line, header, delim = read_header(lines, i, src, BenchFileError)
    except BenchFileError as exc:
        _raise([*problems, exc])
        raise
    cells = header.split(delim)
    names: list[str] = []
    raw_names: list[str] = []
    units: list[str | None] = []
    for j, c in enumerate(cells):
        raw, unit = _split_unit(c)
        name = mapped.get(_norm(raw)) or aliases.get(raw) or aliases.get(_norm(raw)) or raw
        if not name:
            problems.append(BenchFileError(src, header_line, str(j + 1), "empty column name"))
            continue
        try:
            float(name)
            is_number = True
        except ValueError:
            is_number = False
        if is_number:
            _raise([*problems, BenchFileError(
                src,
                header_line,
                str(j + 1),
                f"the first line after the metadata must name the columns, got the number {c!r}",
            )])  # fmt: skip
        if name not in allowed:
            close = difflib.get_close_matches(name, allowed, 1)
            hint = f"; did you mean '{close[0]}'?" if close else ""
            problems.append(BenchFileError(
                src,
                header_line,
                f"{j + 1} {c.strip()!r}",
                f"unknown column (known: {', '.join(allowed)}, their aliases, or map it with "
                f"columns = {{...}}){hint}",
            ))  # fmt: skip
        elif name in names:
            problems.append(BenchFileError(
                src,
                header_line,
                f"{j + 1} {c.strip()!r}",
                f"column '{name}' appears twice (first as column {names.index(name) + 1})",
            ))  # fmt: skip
        names.append(name)
        raw_names.append(c.strip())
        units.append(unit)
    _raise(problems)
    body_idx = [k for k in range(i + 1, len(lines)) if lines[k].strip()]
    rows = len(body_idx)
    ncol = len(names)
    if rows == 0:
        raise BenchFileError(src, header_line + 1, None, "has column names but no data rows")
    text_cols = [j for j, n in enumerate(names) if n in text_columns]
    data = None
    if not text_cols:
        body = "\n".join(lines[k] for k in body_idx)
        flat = body.replace("\n", delim).split(delim)
        if len(flat) == rows * ncol:
            try:
                data = np.array(flat, dtype=float).reshape(rows, ncol)
            except ValueError:
                data = None
    cells_text: dict = {j: [] for j in text_cols}
    if data is None:  # slow path: find the offending line and cell
        data = np.full((rows, ncol), np.nan)
        header_norm = [s.strip() for s in cells]
        for r, k in enumerate(body_idx):
            parts = lines[k].split(delim)
            if [s.strip() for s in parts] == header_norm:
                raise BenchFileError(
                    src,
                    k + 1,
                    None,
                    f"repeats the column header of line {header_line} (two files joined?)",
                )
            if len(parts) != ncol:
                raise BenchFileError(
                    src, k + 1, None, f"has {len(parts)} cells; the header has {ncol} columns"
                )
            for j, cell in enumerate(parts):
                if j in cells_text:
                    cells_text[j].append(cell.strip().lower())
                    continue
                s = cell.strip()
                if not s:
                    raise BenchFileError(src, k + 1, _col(names, units, j), "empty cell")
                try:
                    data[r, j] = float(s)
                except ValueError:
                    raise BenchFileError(
                        src, k + 1, _col(names, units, j), f"{s!r} is not a number"
                    ) from None
    lines_arr = np.asarray(body_idx, dtype=np.int64) + 1
    num_cols = [j for j in range(ncol) if j not in cells_text]
    bad = ~np.isfinite(data[:, num_cols]) if num_cols else np.zeros((rows, 0), bool)
    if bad.any():
        r, jj = np.argwhere(bad)[0]
        j = num_cols[jj]
        raise BenchFileError(
            src,
            int(lines_arr[r]),
            _col(names, units, j),
            f"{data[r, j]!r} is not a finite number (NaN/inf: a dropout of the encoder?)",
        )
    return _Table(
        src, meta, meta_lines, names, units, data, cells_text, lines_arr, header_line, raw_names,
        options,
    )  # fmt: skip


def _col(names, units, j) -> str:
    unit = f" [{units[j]}]" if units[j] else ""
    return f"{j + 1} '{names[j]}{unit}'"


def _unit_factor(t: _Table, j: int, table: dict, declared_key: str, what: str) -> float:
    unit = t.units[j]
    col = t.col_label(j)
    line = t.header_line
    if unit is None:
        unit = t.meta.get(declared_key)
        if unit is not None:
            line = t.meta_lines[declared_key]
        else:
            raw = _split_unit(t.raw_names[j])[0] if t.raw_names else t.names[j]
            unit = t.options.unit_for(t.names[j], raw)
        if unit is None:
            raise BenchFileError(
                t.source,
                t.header_line,
                col,
                f"no unit: write it in the name ('{t.names[j]} [{next(iter(table))}]'), "
                f"declare '# {declared_key}: ...' or give units = {{{t.names[j]} = ...}} in the "
                f"case (accepted: {', '.join(table)})",
            )
    key = _unit_key(unit, what)
    if key not in table:
        raise BenchFileError(
            t.source,
            line,
            col,
            f"unit {unit!r} is not {'a torque' if what == 'torque' else 'an angle'} unit "
            f"(accepted: {', '.join(table)})",
        )
    return table[key]


def _meta_fields(t: _Table) -> dict:
    out: dict = {}
    m = t.meta
    if "speed_rpm" in m:
        if m["speed_rpm"] <= 0:
            raise t.meta_error("speed_rpm", f"speed_rpm must be > 0, got {m['speed_rpm']}")
        out["speed_rpm"] = m["speed_rpm"]
    if "oil_temperature_C" in m:
        if not -60.0 <= m["oil_temperature_C"] <= 250.0:
            raise t.meta_error(
                "oil_temperature_C",
                f"oil_temperature_C must be in [-60, 250] °C, got {m['oil_temperature_C']}",
            )
        out["oil_temperature"] = m["oil_temperature_C"]
    if "torque_Nm" in m:
        out["torque"] = float(Nm_to_Nmm(m["torque_Nm"]))
    if "sample_rate_Hz" in m and m["sample_rate_Hz"] <= 0:
        raise t.meta_error(
            "sample_rate_Hz", f"sample_rate_Hz must be > 0, got {m['sample_rate_Hz']}"
        )
    return out


def _check_kind(t: _Table, want: str) -> None:
    kind = t.meta.get("kind")
    if kind is not None and kind != want:
        raise t.meta_error("kind", f"declares kind {kind!r}; expected {want!r}")


# ---- TE traces ---------------------------------------------------------------------------
def read_te_trace(path: str | os.PathLike, options: ImportOptions | None = None) -> TETrace:
    """Read one angular-TE trace (one operating point) from a CSV file.

    Parameters
    ----------
    path : str or path
        CSV file (layout in the module docstring).
    options : ImportOptions, optional
        Column mapping, units, file-name pattern and TE sign convention of the rig's export.

    Returns
    -------
    TETrace
        Positions and TE in [rad], torque in [N·mm].

    Raises
    ------
    BenchFileError
        Naming file, line and column: unknown/duplicate/missing columns, missing or wrong units,
        non-numeric or non-finite cells, ragged rows, too few points, positions not strictly
        monotone or not covering one output revolution, implausible TE (a unit mistake), bad
        metadata.
    """
    opts = options or _DEFAULT_OPTIONS
    t = _parse(path, _TE_COLUMNS, _TE_ALIASES, options=opts)
    _check_kind(t, "te_trace")
    _name_metadata(t, opts)
    cols = {n: j for j, n in enumerate(t.names)}
    arrays: dict[str, np.ndarray | None] = {}
    problems: list[BenchFileError] = []
    factors: dict[str, tuple[float, float]] = {}
    for d in ("forward", "backward"):
        pj, tj = cols.get(f"{d}_position"), cols.get(f"{d}_te")
        if (pj is None) != (tj is None):
            missing = f"{d}_te" if tj is None else f"{d}_position"
            problems.append(BenchFileError(
                t.source,
                t.header_line,
                None,
                f"column '{missing}' is missing (the {d} direction needs position and TE)",
            ))  # fmt: skip
        if pj is None or tj is None:
            continue
        got = []
        for j, key in ((pj, "angle_unit"), (tj, "te_unit")):
            try:
                got.append(_unit_factor(t, j, _ANGLE_UNITS, key, "angle"))
            except BenchFileError as exc:
                problems.append(exc)
        if len(got) == 2:
            factors[d] = (got[0], got[1])
    _raise(problems)
    for d in ("forward", "backward"):
        pj, tj = cols.get(f"{d}_position"), cols.get(f"{d}_te")
        if d not in factors or pj is None or tj is None:
            arrays[d + "_position"] = arrays[d + "_te"] = None
            continue
        fp, ft = factors[d]
        pos = t.data[:, pj] * fp
        te = t.data[:, tj] * (ft * opts.te_sign)
        _check_positions(t, pj, pos)
        big = np.abs(te - np.median(te)) > _TE_LIMIT
        if big.any():
            r = int(np.argmax(big))
            raise BenchFileError(
                t.source,
                int(t.data_lines[r]),
                t.col_label(tj),
                f"TE of {t.data[r, tj]!r} {t.units[tj] or t.meta.get('te_unit')} departs more "
                "than 1° from the trace's median: wrong unit (arcsec written as deg?) or a glitch",
            )
        arrays[d + "_position"], arrays[d + "_te"] = pos, te
    if arrays["forward_position"] is None and arrays["backward_position"] is None:
        raise BenchFileError(
            t.source,
            t.header_line,
            None,
            "no TE columns: needs forward_position + forward_te and/or backward_position + "
            "backward_te",
        )
    return TETrace(
        source=t.source,
        forward_position=arrays["forward_position"],
        forward_te=arrays["forward_te"],
        backward_position=arrays["backward_position"],
        backward_te=arrays["backward_te"],
        serial=t.meta.get("serial"),
        metadata={**t.meta, "te_convention": opts.te_convention},
        **_meta_fields(t),
    )


def _name_metadata(t: _Table, opts: ImportOptions) -> None:
    """Merge the operating point written in the file name (``opts.file_name_pattern``) into
    the metadata; a name that does not match, or disagrees with a ``#`` line, is an error."""
    if opts.file_name_pattern is None:
        return
    got = metadata_from_name(t.source, opts.file_name_pattern)
    if got is None:
        raise BenchFileError(
            t.source, None, None,
            f"the file name does not match file_name_pattern {opts.file_name_pattern!r}",
        )  # fmt: skip
    for key, v in got.items():
        if key in t.meta and not np.isclose(t.meta[key], v, rtol=1e-9, atol=1e-9):
            raise t.meta_error(key, f"'{key}: {t.meta[key]:g}' contradicts the file name ({v:g})")
        if key not in t.meta:
            t.meta[key] = v
            t.meta_lines[key] = None


def _check_positions(t: _Table, j: int, pos: np.ndarray) -> None:
    if pos.size < MIN_POINTS:
        raise BenchFileError(
            t.source,
            int(t.data_lines[-1]),
            t.col_label(j),
            f"only {pos.size} samples; at least {MIN_POINTS} are needed",
        )
    step = np.diff(pos)
    sense = 1.0 if pos[-1] >= pos[0] else -1.0
    bad = step * sense <= 0.0
    if bad.any():
        r = int(np.argmax(bad)) + 1
        raise BenchFileError(
            t.source,
            int(t.data_lines[r]),
            t.col_label(j),
            f"position {t.data[r, j]!r} does not continue the strictly "
            f"{'increasing' if sense > 0 else 'decreasing'} sequence of the previous line "
            f"({t.data[r - 1, j]!r}); positions must be monotone",
        )
    span = abs(pos[-1] - pos[0])
    gap = np.max(np.abs(step))
    if span + gap < 0.95 * 2 * np.pi:
        raise BenchFileError(
            t.source,
            int(t.data_lines[-1]),
            t.col_label(j),
            f"positions cover {rad_to_deg(span):.4g}°; one output revolution (>= 342°) is "
            "needed (wrong unit, e.g. rad declared as deg?)",
        )
    if span > 2 * np.pi * 1.01:
        raise BenchFileError(
            t.source,
            int(t.data_lines[-1]),
            t.col_label(j),
            f"positions cover {rad_to_deg(span):.6g}°, more than one output revolution "
            "(split the trace per revolution, or wrong unit, e.g. arcmin declared as deg?)",
        )


def read_te_folder(
    path: str | os.PathLike, pattern: str = "*.csv", options: ImportOptions | None = None
) -> list[TETrace]:
    """Read every TE trace of a folder (one file per operating point: a series).

    Parameters
    ----------
    path : str or os.PathLike
        The folder.
    pattern : str
        Glob of the trace files in it.
    options : ImportOptions, optional
        As :func:`read_te_trace`.

    Returns
    -------
    list of TETrace
        One trace per file, sorted by file name (the order carries no meaning: analyses pick
        files by their operating point).

    Raises
    ------
    BenchFileError
        For the folder when it holds no matching file; else :class:`BenchFileErrors` with the
        problems of *every* malformed file (nothing of the folder is returned then), and of
        the series (:func:`check_series`).
    """
    p = Path(path)
    if not p.is_dir():
        raise BenchFileError(str(path), None, None, "is not a folder")
    files = sorted(f for f in p.glob(pattern) if f.is_file())
    if not files:
        raise BenchFileError(str(path), None, None, f"holds no file matching {pattern!r}")
    traces, problems = [], []
    for f in files:
        try:
            traces.append(read_te_trace(f, options))
        except BenchFileErrors as exc:
            problems.extend(exc.errors)
        except BenchFileError as exc:
            problems.append(exc)
    if not problems:
        problems = series_problems(traces)
    _raise(problems)
    return traces


def series_problems(traces: list[TETrace]) -> list[BenchFileError]:
    """What a series of operating points lacks: every file needs its torque, and speed and oil
    temperature are given for every file or for none (a file without them cannot be placed
    in the series). A single trace is not a series (no requirement).

    Parameters
    ----------
    traces : list of TETrace
        The traces of one folder.

    Returns
    -------
    list of BenchFileError
        One error per file and missing key, naming the file; empty when the series is complete.
    """
    if len(traces) < 2:
        return []
    out = []
    how = ("write '# {key}: ...' in the file or give file_name_pattern "
           "(e.g. \"{{torque}}Nm_{{speed}}rpm_{{temp}}C\") in [data]")  # fmt: skip
    for attr, key, always in (("torque", "torque_Nm", True), ("speed_rpm", "speed_rpm", False),
                              ("oil_temperature", "oil_temperature_C", False)):  # fmt: skip
        have = [getattr(t, attr) is not None for t in traces]
        if not always and not any(have):
            continue
        for t, h in zip(traces, have, strict=True):
            if not h:
                why = "" if always else " (other files of the series give it)"
                out.append(BenchFileError(
                    t.source, None, None,
                    f"no {key}{why}: a series needs it for every file; " + how.format(key=key),
                ))  # fmt: skip
    return out


# ---- hysteresis --------------------------------------------------------------------------
_BRANCH_WORDS = {"ascending": 1, "descending": -1, "loading": 2, "unloading": -2}


def read_hysteresis(
    path: str | os.PathLike, options: ImportOptions | None = None
) -> HysteresisCurve:
    """Read a hysteresis curve (output torque against output torsion angle, input locked).

    Parameters
    ----------
    path : str or os.PathLike
        The CSV file.
    options : ImportOptions, optional
        Column mapping and units (the file-name pattern and TE convention do not apply).

    Returns
    -------
    HysteresisCurve
        Torque [N·mm], angle [rad] in recording order; ``branch`` +1 where the torque rises,
        −1 where it falls (from a ``branch`` column), or ``None`` to be inferred.

    Raises
    ------
    BenchFileError
        As :func:`read_te_trace`, plus: a curve that does not cross zero torque, and unknown
        branch marks.
    """
    opts = options or _DEFAULT_OPTIONS
    t = _parse(path, _HYST_COLUMNS, _HYST_ALIASES, text_columns=("branch",), options=opts)
    _check_kind(t, "hysteresis")
    cols = {n: j for j, n in enumerate(t.names)}
    _raise([
        BenchFileError(t.source, t.header_line, None, f"column '{need}' is missing (got {t.names})")
        for need in ("torque", "angle") if need not in cols
    ])  # fmt: skip
    tj, aj = cols["torque"], cols["angle"]
    problems, got = [], []
    for j, table, key, what in ((tj, _TORQUE_UNITS, "torque_unit", "torque"),
                                (aj, _ANGLE_UNITS, "angle_unit", "angle")):  # fmt: skip
        try:
            got.append(_unit_factor(t, j, table, key, what))
        except BenchFileError as exc:
            problems.append(exc)
    _raise(problems)
    torque = t.data[:, tj] * got[0]
    angle = t.data[:, aj] * got[1]
    if torque.size < MIN_POINTS:
        raise BenchFileError(
            t.source,
            int(t.data_lines[-1]),
            None,
            f"only {torque.size} samples; at least {MIN_POINTS} are needed",
        )
    if not (torque.min() < 0.0 < torque.max()):
        raise BenchFileError(
            t.source,
            int(t.data_lines[0]),
            t.col_label(tj),
            "torque never changes sign: a hysteresis curve loads both directions",
        )
    if np.ptp(angle) > _TE_LIMIT:
        r = int(np.argmax(np.abs(angle - angle[0])))
        raise BenchFileError(
            t.source,
            int(t.data_lines[r]),
            t.col_label(aj),
            f"torsion angle spans {rad_to_deg(np.ptp(angle)):.4g}°: wrong unit (arcmin "
            "declared as deg?)",
        )
    branch = None
    if "branch" in cols:
        bj = cols["branch"]
        marks = t.text[bj]
        branch = np.empty(len(marks), dtype=np.int64)
        for r, w in enumerate(marks):
            code = _BRANCH_WORDS.get(w)
            if code is None:
                raise BenchFileError(
                    t.source,
                    int(t.data_lines[r]),
                    t.col_label(bj),
                    f"branch mark {w!r} is not one of {', '.join(_BRANCH_WORDS)}",
                )
            branch[r] = code
        branch = _branch_to_direction(branch, torque)
    return HysteresisCurve(
        source=t.source,
        torque=torque,
        angle=angle,
        branch=branch,
        serial=t.meta.get("serial"),
        metadata=dict(t.meta),
    )


def _branch_to_direction(code: np.ndarray, torque: np.ndarray) -> np.ndarray:
    """Map loading/unloading marks to rising (+1) / falling (−1) torque using its sign."""
    out = code.copy()
    lu = np.abs(code) == 2
    if lu.any():
        sgn = np.sign(torque)
        # at exactly zero torque a loading sample belongs to where it goes, unloading to
        # where it comes from
        nxt = np.concatenate([sgn[1:], sgn[-1:]])
        prv = np.concatenate([sgn[:1], sgn[:-1]])
        s = np.where(sgn != 0, sgn, np.where(code > 0, nxt, prv))
        out[lu] = np.where(code[lu] > 0, 1, -1) * np.where(s[lu] >= 0, 1, -1)
    return out


# ---- writers (for synthetic benches and round trips) -------------------------------------
def _fmt(a: np.ndarray) -> np.ndarray:
    return np.char.mod("%.17g", np.asarray(a, dtype=float))


def write_te_trace(
    path: str | os.PathLike, trace: TETrace, *, unit_position: str = "deg", unit_te: str = "arcsec"
) -> None:
    """Write a :class:`TETrace` in the layout :func:`read_te_trace` reads (round-trip exact).

    Parameters
    ----------
    path : str or os.PathLike
        The CSV file to write.
    trace : TETrace
        Positions [rad] and TE [rad] (written in the units below).
    unit_position : str
        Unit of the position column (e.g. ``"deg"``).
    unit_te : str
        Unit of the TE column (e.g. ``"arcsec"``).
    """
    fp, ft = _ANGLE_UNITS[unit_position], _ANGLE_UNITS[unit_te]
    head = []
    if trace.serial:
        head.append(f"# serial: {trace.serial}")
    if trace.speed_rpm is not None:
        head.append(f"# speed_rpm: {trace.speed_rpm!r}")
    if trace.torque is not None:
        head.append(f"# torque_Nm: {trace.torque / float(Nm_to_Nmm(1.0))!r}")
    if trace.oil_temperature is not None:
        head.append(f"# oil_temperature_C: {trace.oil_temperature!r}")
    cols, names = [], []
    for d, (pos, te) in trace.directions().items():
        cols += [_fmt(pos / fp), _fmt(te / ft)]
        names += [f"{d}_position [{unit_position}]", f"{d}_te [{unit_te}]"]
    n = max(c.size for c in cols)
    if any(c.size != n for c in cols):
        raise ValueError("both directions must have the same number of samples to share a file")
    rows = [",".join(r) for r in zip(*cols, strict=True)]
    _write(path, "\n".join([*head, ",".join(names), *rows]) + "\n")


def write_hysteresis(
    path: str | os.PathLike,
    curve: HysteresisCurve,
    *,
    unit_angle: str = "arcmin",
    with_branch: bool = True,
) -> None:
    """Write a :class:`HysteresisCurve` (torque in N·m) in the layout :func:`read_hysteresis`
    reads.

    Parameters
    ----------
    path : str or os.PathLike
        The CSV file to write.
    curve : HysteresisCurve
        Torque [N·mm] and angle [rad] (written as N·m and ``unit_angle``).
    unit_angle : str
        Unit of the angle column (a unit :func:`read_hysteresis` reads, e.g. ``"arcmin"``).
    with_branch : bool
        Write the ``branch`` column (+1 / −1) when the curve has one.
    """
    fa = _ANGLE_UNITS[unit_angle]
    names = ["torque [N·m]", f"angle [{unit_angle}]"]
    cols = [_fmt(curve.torque / float(Nm_to_Nmm(1.0))), _fmt(curve.angle / fa)]
    if with_branch and curve.branch is not None:
        names.append("branch")
        cols.append(np.where(np.asarray(curve.branch) > 0, "ascending", "descending"))
    head = [f"# serial: {curve.serial}"] if curve.serial else []
    rows = [",".join(r) for r in zip(*cols, strict=True)]
    _write(path, "\n".join([*head, ",".join(names), *rows]) + "\n")


def _write(path, text: str) -> None:
    p = Path(path)
    tmp = p.with_name(p.name + ".tmp")
    tmp.write_text(text, encoding="utf-8")
    os.replace(tmp, p)
