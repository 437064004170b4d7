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
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from gearte.errors import BenchFileError
from gearte.io._textfile import read_header, read_text_file
from gearte.models.bench_data import HysteresisCurve, TETrace
from gearte.units import ARCMIN_PER_RAD, ARCSEC_PER_RAD, DEG_PER_RAD, Nm_to_Nmm, rad_to_deg

__all__ = [
    "TETrace",
    "HysteresisCurve",
    "read_te_trace",
    "read_te_folder",
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
_TE_ALIASES = {"position": "forward_position", "te": "forward_te"}
_HYST_COLUMNS = ("torque", "angle", "branch")
_HYST_ALIASES = {"output_angle": "angle", "torsion_angle": "angle", "output_torque": "torque"}
_META_NUMERIC = ("speed_rpm", "torque_Nm", "oil_temperature_C", "sample_rate_Hz")
_META_TEXT = ("serial", "angle_unit", "te_unit", "torque_unit", "kind")
_KEY = re.compile(r"^#\s*([A-Za-z_][A-Za-z0-9_]*)\s*:\s*(.*?)\s*$")
_HEADER = re.compile(r"^\s*([^\[\]]+?)\s*(?:\[\s*([^\[\]]*?)\s*\])?\s*$")
_TE_LIMIT = 1.0 / DEG_PER_RAD  # a TE beyond 1° is a unit mistake, not a reducer


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
    name = re.sub(r"[\s\-]+", "_", m.group(1).strip().lower())
    return name, (m.group(2) if m.group(2) is not None else None)


def _parse(path, allowed, aliases, text_columns=()) -> _Table:
    src, text = read_text_file(path, BenchFileError, MAX_FILE_BYTES)
    lines = text.splitlines()
    if not any(ln.strip() for ln in lines):
        raise BenchFileError(src, 1, None, "is empty (no header, no data)")
    meta: dict = {}
    meta_lines: dict = {}
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
                raise BenchFileError(
                    src, i + 1, None, f"unknown metadata key '{key}' (known: {known}){hint}"
                )
            if key in meta:
                raise BenchFileError(
                    src,
                    i + 1,
                    None,
                    f"metadata key '{key}' repeated (first on line {meta_lines[key]})",
                )
            if key in _META_NUMERIC:
                try:
                    v = float(value)
                except ValueError:
                    v = float("nan")
                if not np.isfinite(v):
                    raise BenchFileError(
                        src, i + 1, None, f"metadata '{key}' must be a finite number, got {value!r}"
                    )
                meta[key] = v
            else:
                meta[key] = value
            meta_lines[key] = i + 1
        i += 1
    header_line, header, delim = read_header(lines, i, src, BenchFileError)
    cells = header.split(delim)
    names: list[str] = []
    units: list[str | None] = []
    for j, c in enumerate(cells):
        name, unit = _split_unit(c)
        name = aliases.get(name, name)
        if not name:
            raise BenchFileError(src, header_line, str(j + 1), "empty column name")
        try:
            float(name)
            is_number = True
        except ValueError:
            is_number = False
        if is_number:
            raise BenchFileError(
                src,
                header_line,
                str(j + 1),
                f"the first line after the metadata must name the columns, got the number {c!r}",
            )
        if name not in allowed:
            close = difflib.get_close_matches(name, allowed, 1)
            hint = f"; did you mean '{close[0]}'?" if close else ""
            raise BenchFileError(
                src,
                header_line,
                f"{j + 1} {c.strip()!r}",
                f"unknown column (known: {', '.join(allowed)}){hint}",
            )
        if name in names:
            raise BenchFileError(
                src,
                header_line,
                f"{j + 1} {c.strip()!r}",
                f"column '{name}' appears twice (first as column {names.index(name) + 1})",
            )
        names.append(name)
        units.append(unit)
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
    return _Table(src, meta, meta_lines, names, units, data, cells_text, lines_arr, header_line)


def _col(names, units, j) -> str:
    unit = f" [{units[j]}]" if units[j] else ""
    return f"{j + 1} '{names[j]}{unit}'"


def _unit_factor(t: _Table, j: int, table: dict, declared_key: str, what: str) -> float:
    unit = t.units[j]
    col = t.col_label(j)
    if unit is None:
        unit = t.meta.get(declared_key)
        if unit is None:
            raise BenchFileError(
                t.source,
                t.header_line,
                col,
                f"no unit: write it in the name ('{t.names[j]} [{next(iter(table))}]') or "
                f"declare '# {declared_key}: ...' (accepted: {', '.join(table)})",
            )
        line = t.meta_lines[declared_key]
    else:
        line = t.header_line
    key = unit.strip().lower().replace(" ", "") if what == "torque" else unit.strip().lower()
    if key in ("n·m", "n m"):
        key = "n·m"
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
def read_te_trace(path: str | os.PathLike) -> TETrace:
    """Read one angular-TE trace (one operating point) from a CSV file.

    Parameters
    ----------
    path : str or path
        CSV file (layout in the module docstring).

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
    t = _parse(path, _TE_COLUMNS, _TE_ALIASES)
    _check_kind(t, "te_trace")
    cols = {n: j for j, n in enumerate(t.names)}
    arrays: dict[str, np.ndarray | None] = {}
    for d in ("forward", "backward"):
        pj, tj = cols.get(f"{d}_position"), cols.get(f"{d}_te")
        if (pj is None) != (tj is None):
            missing = f"{d}_te" if tj is None else f"{d}_position"
            raise BenchFileError(
                t.source,
                t.header_line,
                None,
                f"column '{missing}' is missing (the {d} direction needs position and TE)",
            )
        if pj is None or tj is None:
            arrays[d + "_position"] = arrays[d + "_te"] = None
            continue
        fp = _unit_factor(t, pj, _ANGLE_UNITS, "angle_unit", "angle")
        ft = _unit_factor(t, tj, _ANGLE_UNITS, "te_unit", "angle")
        pos = t.data[:, pj] * fp
        te = t.data[:, tj] * ft
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
        metadata=dict(t.meta),
        **_meta_fields(t),
    )


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


def read_te_folder(path: str | os.PathLike, pattern: str = "*.csv") -> list[TETrace]:
    """Read every TE trace of a folder (one file per operating point), sorted by file name.

    Parameters
    ----------
    path : str or os.PathLike
        The folder.
    pattern : str
        Glob of the trace files in it.

    Returns
    -------
    list of TETrace
        One trace per file, sorted by file name.

    Raises
    ------
    BenchFileError
        For the folder when it holds no matching file, or the first malformed file's error
        (nothing of the folder is returned then).
    """
    p = Path(path)
    if not p.is_dir():
        raise BenchFileError(str(path), None, None, "is not a folder")
    files = sorted(f for f in p.glob(pattern) if f.is_file())
    if not files:
        raise BenchFileError(str(path), None, None, f"holds no file matching {pattern!r}")
    return [read_te_trace(f) for f in files]


# ---- hysteresis --------------------------------------------------------------------------
_BRANCH_WORDS = {"ascending": 1, "descending": -1, "loading": 2, "unloading": -2}


def read_hysteresis(path: str | os.PathLike) -> HysteresisCurve:
    """Read a hysteresis curve (output torque against output torsion angle, input locked).

    Parameters
    ----------
    path : str or os.PathLike
        The CSV file.

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
    t = _parse(path, _HYST_COLUMNS, _HYST_ALIASES, text_columns=("branch",))
    _check_kind(t, "hysteresis")
    cols = {n: j for j, n in enumerate(t.names)}
    for need in ("torque", "angle"):
        if need not in cols:
            raise BenchFileError(
                t.source, t.header_line, None, f"column '{need}' is missing (got {t.names})"
            )
    tj, aj = cols["torque"], cols["angle"]
    torque = t.data[:, tj] * _unit_factor(t, tj, _TORQUE_UNITS, "torque_unit", "torque")
    angle = t.data[:, aj] * _unit_factor(t, aj, _ANGLE_UNITS, "angle_unit", "angle")
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
