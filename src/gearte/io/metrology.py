"""Readers and writers of measured RV parts (metrology CSV files, issue 16).

Every file is a small optional header of ``# key: value`` lines followed by a comma- (or
semicolon-, tab-) separated table whose column names carry their unit (``deviation [um]``).
Each row names the part's serial number. Formats (details and examples: ``docs/metrology.md``):

==================  ==============================================================  ===========
format              columns                                                          one row per
==================  ==============================================================  ===========
``disc_profile``    ``serial, tooth, profile_parameter [deg|rad],                    point of a
                    deviation [um|mm]``                                              tooth's flank
``disc_pitch``      ``serial, tooth, cumulative_pitch [um|mm]``                      tooth
``pins``            ``serial, pin, diameter [mm|um]`` and optionally                 pin
                    ``slot_radial_deviation [um|mm], slot_tangential_deviation``
``crank_eccentricity``  ``serial, cam, eccentricity [mm|um], phase [deg|rad]``        cam
``disc_bores``      ``serial, bore, x [mm|um], y [mm|um]``                           crank bore
``runout``          ``serial, runout [um|mm], phase [deg|rad]``                      part
``bearing_clearance``  ``serial, bearing, radial_clearance [um|mm]``                  bearing
==================  ==============================================================  ===========

Meaning of the values (the model's conventions, :mod:`gearte.geometry.measured`):

* ``profile_parameter``: the meshing phase ``φ`` of the cycloid tooth space, ``0`` at its root
  (the pin on the eccentric direction), ``φ ∈ [-180°, 180°]``; ``deviation``: normal deviation of
  the measured flank from the design flank, **positive = more material** (less clearance).
* ``cumulative_pitch``: cumulative pitch deviation of each tooth space along the pitch circle,
  positive counter-clockwise (tooth 1 is the reference, usually 0).
* ``pins``: pin diameter; slot deviations of the pin-slot centre from its nominal position,
  radially outward and counter-clockwise.
* ``crank_eccentricity``: measured eccentricity of each cam and the angle of its eccentric
  direction from the nominal one (crank frame).
* ``disc_bores``: crank-bore centre in the disc frame (disc centre at the origin, bore 1 nominally
  on ``+x``, bores counter-clockwise).
* ``runout``: radial run-out (total indicator reading, twice the eccentricity) of a planet or the
  sun and the angle of its high point (planet frame: from the eccentric of disc 1's cam).
* ``bearing_clearance``: ``cam_1`` … ``cam_N`` (needle bearing of cam ``j`` in its disc bore),
  ``carrier`` (the crank's bearings in the carrier).

Metadata keys (all optional): ``format`` (must match the reader), ``instrument``, ``date``,
``operator``, ``lot``, ``note``, ``temperature_C``. Other ``#`` lines are comments.

Every malformed file raises one :class:`gearte.errors.MeasurementFileError` naming file, line and
column; a reader returns a complete mapping ``serial -> part`` or raises — nothing is
half-imported. Everything returned is in gearte's units (mm, rad).
"""

from __future__ import annotations

import difflib
import os
import re
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from gearte.errors import MeasurementFileError
from gearte.io._textfile import read_header, read_text_file
from gearte.units import DEG_PER_RAD, mm_to_um, rad_to_deg

__all__ = [
    "FORMATS",
    "MAX_FILE_BYTES",
    "DiscProfile",
    "PinSet",
    "CrankCams",
    "Runout",
    "read_disc_profiles",
    "read_disc_pitch",
    "read_pins",
    "read_crank_eccentricity",
    "read_disc_bores",
    "read_runout",
    "read_bearing_clearances",
    "write_disc_profiles",
    "write_disc_pitch",
    "write_pins",
    "write_crank_eccentricity",
    "write_disc_bores",
    "write_runout",
    "write_bearing_clearances",
    "DESIGN_DEVIATION",
    "check_against_design",
]

MAX_FILE_BYTES = 64 * 1024 * 1024
"""Largest metrology file read [bytes]."""

_LENGTH = {"um": 1e-3, "µm": 1e-3, "micron": 1e-3, "mm": 1.0}
_ANGLE = {"deg": 1.0 / DEG_PER_RAD, "°": 1.0 / DEG_PER_RAD, "rad": 1.0}
_META = ("format", "instrument", "date", "operator", "lot", "note", "temperature_C")
_KEY = re.compile(r"^#\s*([A-Za-z_][A-Za-z0-9_]*)\s*:\s*(.*?)\s*$")
_HEADER = re.compile(r"^\s*([^\[\]]+?)\s*(?:\[\s*([^\[\]]*?)\s*\])?\s*$")
_SERIAL = re.compile(r"^[A-Za-z0-9][A-Za-z0-9_.\-/]{0,63}$")


@dataclass(frozen=True)
class _Col:
    """A column of a format: kind ``text``, ``int``, ``length`` or ``angle``; plausible range
    of its value in gearte units (mm, rad)."""

    kind: str
    required: bool = True
    lo: float = -np.inf
    hi: float = np.inf


FORMATS: dict[str, dict[str, _Col]] = {
    "disc_profile": {
        "serial": _Col("text"),
        "tooth": _Col("int"),
        "profile_parameter": _Col("angle", lo=-np.pi - 1e-9, hi=np.pi + 1e-9),
        "deviation": _Col("length", lo=-0.5, hi=0.5),
    },
    "disc_pitch": {
        "serial": _Col("text"),
        "tooth": _Col("int"),
        "cumulative_pitch": _Col("length", lo=-0.5, hi=0.5),
    },
    "pins": {
        "serial": _Col("text"),
        "pin": _Col("int"),
        "diameter": _Col("length", lo=0.5, hi=100.0),
        "slot_radial_deviation": _Col("length", False, -0.5, 0.5),
        "slot_tangential_deviation": _Col("length", False, -0.5, 0.5),
    },
    "crank_eccentricity": {
        "serial": _Col("text"),
        "cam": _Col("int"),
        "eccentricity": _Col("length", lo=0.05, hi=50.0),
        "phase": _Col("angle", lo=-2 * np.pi, hi=2 * np.pi),
    },
    "disc_bores": {
        "serial": _Col("text"),
        "bore": _Col("int"),
        "x": _Col("length", lo=-2000.0, hi=2000.0),
        "y": _Col("length", lo=-2000.0, hi=2000.0),
    },
    "runout": {
        "serial": _Col("text"),
        "runout": _Col("length", lo=0.0, hi=1.0),
        "phase": _Col("angle", lo=-2 * np.pi, hi=2 * np.pi),
    },
    "bearing_clearance": {
        "serial": _Col("text"),
        "bearing": _Col("text"),
        "radial_clearance": _Col("length", lo=0.0, hi=0.2),
    },
}
"""Columns of each format (name → kind, required, plausible range in mm / rad)."""


#: Largest plausible deviation of a measured size from the design's nominal, as a fraction of the
#: nominal: ``format -> (column, fraction)``. Manufacturing deviations are micrometres on sizes of
#: millimetres (1e-4 to 1e-3 of the nominal); a value 1000 times off (``x [um]`` written for
#: millimetres) deviates by about the whole nominal. A crank-bore centre is judged against the
#: crank circle radius, a cam eccentricity against the design eccentricity, a pin diameter
#: against the design pin diameter (:func:`check_against_design`).
DESIGN_DEVIATION: dict[str, tuple[tuple[str, ...], float]] = {
    "disc_bores": (("x", "y"), 0.02),
    "crank_eccentricity": (("eccentricity",), 0.2),
    "pins": (("diameter",), 0.1),
}


# ---- data objects ------------------------------------------------------------------------
@dataclass(frozen=True, eq=False)
class DiscProfile:
    """Measured flank deviations of one disc, tooth by tooth.

    Attributes
    ----------
    phase : tuple of numpy.ndarray
        Per tooth space (index 0 = tooth 1), strictly increasing profile parameters ``φ`` [rad].
    deviation : tuple of numpy.ndarray
        Normal deviations at those points [mm] (positive = more material).
    """

    phase: tuple[np.ndarray, ...]
    deviation: tuple[np.ndarray, ...]

    @property
    def teeth(self) -> int:
        """Number of tooth spaces measured [-]."""
        return len(self.phase)


@dataclass(frozen=True, eq=False)
class PinSet:
    """Measured pins of one pin ring: diameters and slot-centre deviations [mm], per pin."""

    diameter: np.ndarray
    slot_radial: np.ndarray
    slot_tangential: np.ndarray


@dataclass(frozen=True, eq=False)
class CrankCams:
    """Measured cams of one crankshaft: eccentricity [mm] and phase [rad] per cam."""

    eccentricity: np.ndarray
    phase: np.ndarray


@dataclass(frozen=True)
class Runout:
    """Measured radial run-out [mm] (total indicator reading) and its high-point angle [rad]."""

    runout: float
    phase: float

    @property
    def eccentricity(self) -> float:
        """Eccentricity = run-out / 2 [mm]."""
        return 0.5 * self.runout


# ---- parsing -----------------------------------------------------------------------------
@dataclass
class _Table:
    source: str
    fmt: str
    header_line: int
    names: list[str]
    units: list[str | None]
    values: dict[str, list]  # column name -> parsed values (gearte units)
    lines: list[int]  # 1-based file line of each row

    def col(self, name: str) -> str:
        j = self.names.index(name)
        unit = f" [{self.units[j]}]" if self.units[j] else ""
        return f"{j + 1} '{name}{unit}'"


def _err(src: str, line: int | None, col: str | None, reason: str) -> MeasurementFileError:
    return MeasurementFileError(src, line, col, reason)


def _parse(path: str | os.PathLike, fmt: str) -> _Table:
    spec = FORMATS[fmt]
    src, text = read_text_file(path, MeasurementFileError, MAX_FILE_BYTES)
    lines = text.splitlines()
    if not any(ln.strip() for ln in lines):
        raise _err(src, 1, None, "is empty (no header, no data)")
    seen_meta: dict[str, int] = {}
    i = 0
    while i < len(lines):
        ln = lines[i].strip()
        if ln and not ln.startswith("#"):
            break
        m = _KEY.match(ln) if ln else None
        if m:
            key, value = m.group(1), m.group(2)
            if key not in _META:
                close = difflib.get_close_matches(key, _META, 1)
                hint = f"; did you mean '{close[0]}'?" if close else ""
                raise _err(
                    src,
                    i + 1,
                    None,
                    f"unknown metadata key '{key}' (known: {', '.join(_META)})" + hint,
                )
            if key in seen_meta:
                raise _err(
                    src, i + 1, None, f"metadata '{key}' repeated (first on line {seen_meta[key]})"
                )
            seen_meta[key] = i + 1
            if key == "format" and value != fmt:
                raise _err(
                    src, i + 1, None, f"declares format {value!r}; this reader reads {fmt!r}"
                )
            if key == "temperature_C":
                try:
                    t = float(value)
                except ValueError:
                    t = float("nan")
                if not -60.0 <= t <= 250.0:
                    raise _err(
                        src,
                        i + 1,
                        None,
                        f"temperature_C must be a number in [-60, 250], got {value!r}",
                    )
        i += 1
    header_line, header, delim = read_header(lines, i, src, MeasurementFileError)
    names: list[str] = []
    units: list[str | None] = []
    for j, cell in enumerate(header.split(delim)):
        m = _HEADER.match(cell)
        if m is None:
            raise _err(src, header_line, str(j + 1), f"cannot read the column name {cell!r}")
        name = re.sub(r"[\s\-]+", "_", m.group(1).strip().lower())
        unit = m.group(2)
        shown = f"{j + 1} {cell.strip()!r}"
        if name not in spec:
            close = difflib.get_close_matches(name, list(spec), 1)
            hint = f"; did you mean '{close[0]}'?" if close else ""
            raise _err(
                src, header_line, shown,
                f"unknown column for format '{fmt}' (known: {', '.join(spec)}){hint}",
            )  # fmt: skip
        if name in names:
            raise _err(
                src, header_line, shown,
                f"column '{name}' appears twice (first as column {names.index(name) + 1})",
            )  # fmt: skip
        kind = spec[name].kind
        table = _LENGTH if kind == "length" else _ANGLE if kind == "angle" else None
        if table is None and unit:
            raise _err(src, header_line, shown, f"'{name}' takes no unit, got [{unit}]")
        if table is not None:
            if not unit:
                raise _err(
                    src, header_line, shown,
                    f"no unit: write it in the name ('{name} [{next(iter(table))}]'; accepted: "
                    f"{', '.join(table)})",
                )  # fmt: skip
            if unit.strip().lower() not in table:
                what = "a length" if kind == "length" else "an angle"
                raise _err(
                    src, header_line, shown,
                    f"unit [{unit}] is not {what} unit (accepted: {', '.join(table)})",
                )  # fmt: skip
        names.append(name)
        units.append(unit)
    for name, col in spec.items():
        if col.required and name not in names:
            raise _err(
                src, header_line, f"'{name}'",
                f"required column '{name}' is missing (format '{fmt}' needs "
                f"{', '.join(n for n, c in spec.items() if c.required)})",
            )  # fmt: skip
    values: dict[str, list] = {n: [] for n in names}
    row_lines: list[int] = []
    ncol = len(names)
    for k in range(i + 1, len(lines)):
        ln = lines[k]
        if not ln.strip() or ln.lstrip().startswith("#"):
            continue
        cells = ln.split(delim)
        if len(cells) != ncol:
            raise _err(src, k + 1, None, f"has {len(cells)} cells; the header has {ncol} columns")
        for j, (name, cell) in enumerate(zip(names, cells, strict=True)):
            s = cell.strip()
            col = spec[name]
            where = f"{j + 1} '{name}{f' [{units[j]}]' if units[j] else ''}'"
            if not s:
                raise _err(src, k + 1, where, "empty cell")
            if col.kind == "text":
                if name == "serial" and not _SERIAL.match(s):
                    raise _err(
                        src, k + 1, where,
                        f"serial {s!r} must be 1-64 letters, digits, '_', '.', '-', '/' "
                        "starting with a letter or digit",
                    )  # fmt: skip
                values[name].append(s)
                continue
            if col.kind == "int":
                if s.lower() == name and k + 1 > header_line:
                    raise _err(
                        src,
                        k + 1,
                        where,
                        f"repeats the column header of line {header_line} (two files joined?)",
                    )
                try:
                    v = int(s)
                except ValueError:
                    raise _err(src, k + 1, where, f"{s!r} is not a whole number") from None
                if v < 1 or v > 100000:
                    raise _err(src, k + 1, where, f"{v} is not a valid index (1-based, >= 1)")
                values[name].append(v)
                continue
            try:
                x = float(s)
            except ValueError:
                raise _err(src, k + 1, where, f"{s!r} is not a number") from None
            if not np.isfinite(x):
                raise _err(src, k + 1, where, f"{s!r} is not a finite number (NaN/inf)")
            unit = units[j]
            assert unit is not None  # noqa: S101 - checked on the header
            factor = (_LENGTH if col.kind == "length" else _ANGLE)[unit.strip().lower()]
            val = x * factor
            if not col.lo <= val <= col.hi:
                lo, hi = col.lo / factor, col.hi / factor
                raise _err(
                    src, k + 1, where,
                    f"{s} [{unit}] is outside the plausible range [{lo:.6g}, {hi:.6g}] [{unit}] "
                    "(a unit mistake?)",
                )  # fmt: skip
            values[name].append(val)
        row_lines.append(k + 1)
    if not row_lines:
        raise _err(src, header_line + 1, None, "has column names but no data rows")
    return _Table(src, fmt, header_line, names, units, values, row_lines)


def _groups(t: _Table, index: str | None) -> dict[str, list[int]]:
    """Row numbers by serial, checking that ``(serial, index)`` appears once."""
    out: dict[str, list[int]] = {}
    seen: dict[tuple, int] = {}
    for r, serial in enumerate(t.values["serial"]):
        key = (serial, None if index is None else t.values[index][r])
        if key in seen:
            what = f"serial {serial!r}" + ("" if index is None else f", {index} {key[1]}")
            raise _err(
                t.source, t.lines[r], t.col("serial" if index is None else index),
                f"duplicate: {what} already given on line {seen[key]}",
            )  # fmt: skip
        seen[key] = t.lines[r]
        out.setdefault(serial, []).append(r)
    return out


def _complete(t: _Table, serial: str, rows: list[int], index: str, count: int | None) -> None:
    """The indices of one serial are exactly ``1..count`` (``count`` None: ``1..max``)."""
    got = sorted({t.values[index][r] for r in rows})
    n = count if count is not None else got[-1]
    over = [r for r in rows if t.values[index][r] > n]
    if over:
        r = over[0]
        raise _err(
            t.source, t.lines[r], t.col(index),
            f"{index} {t.values[index][r]} of serial {serial!r} does not exist: the part has "
            f"{n} {_plural(index)}",
        )  # fmt: skip
    missing = sorted(set(range(1, n + 1)) - set(got))
    if missing:
        shown = ", ".join(str(m) for m in missing[:8]) + (" ..." if len(missing) > 8 else "")
        raise _err(
            t.source, t.lines[rows[-1]], t.col(index),
            f"serial {serial!r} has {len(got)} {_plural(index)}; expected {n} (missing {index} "
            f"{shown})",
        )  # fmt: skip


def _plural(index: str) -> str:
    return "teeth" if index == "tooth" else index + "s"


def _expect(t: _Table, serials: dict[str, list[int]], index: str, count: int | None) -> int:
    """All serials of ``t`` have the same number of ``index`` entries (``count`` if given)."""
    n = count
    for serial, rows in serials.items():
        if n is None:
            n = max(t.values[index][r] for r in rows)
        _complete(t, serial, rows, index, n)
    assert n is not None  # noqa: S101 - a table has rows
    return n


# ---- readers -----------------------------------------------------------------------------
def read_disc_profiles(
    path: str | os.PathLike, teeth: int | None = None, min_points: int = 3
) -> dict[str, DiscProfile]:
    """Read measured disc flank deviations (format ``disc_profile``).

    Parameters
    ----------
    path : str or path
        CSV file: ``serial, tooth, profile_parameter [deg], deviation [um]``.
    teeth : int, optional
        Tooth count ``z_c`` [-] of the design: every serial must give exactly teeth 1..z_c.
    min_points : int
        Fewest points per tooth [-].

    Returns
    -------
    dict
        ``serial -> DiscProfile`` (profile parameter [rad], deviation [mm]).

    Raises
    ------
    MeasurementFileError
        Naming file, line and column (module docstring), also for a profile parameter that is not
        strictly increasing within a tooth, a tooth with fewer than ``min_points`` points, a
        wrong tooth count.
    """
    t = _parse(path, "disc_profile")
    serials = _groups_multi(t, "tooth", "profile_parameter")
    traces: dict[str, dict[int, tuple[np.ndarray, np.ndarray]]] = {}
    for serial, rows in serials.items():
        by_tooth: dict[int, list[int]] = {}
        for r in rows:
            by_tooth.setdefault(t.values["tooth"][r], []).append(r)
        for tooth, rr in by_tooth.items():
            ph = np.array([t.values["profile_parameter"][r] for r in rr])
            if len(rr) < min_points:
                raise _err(
                    t.source, t.lines[rr[-1]], t.col("tooth"),
                    f"serial {serial!r} tooth {tooth} has {len(rr)} points; at least "
                    f"{min_points} are needed",
                )  # fmt: skip
            bad = np.flatnonzero(np.diff(ph) <= 0.0)
            if bad.size:
                r = rr[bad[0] + 1]
                raise _err(
                    t.source, t.lines[r], t.col("profile_parameter"),
                    f"profile_parameter of serial {serial!r} tooth {tooth} is not strictly "
                    f"increasing ({rad_to_deg(ph[bad[0]]):.6g} deg then "
                    f"{rad_to_deg(ph[bad[0] + 1]):.6g} deg)",
                )  # fmt: skip
            dv = np.array([t.values["deviation"][r] for r in rr])
            traces.setdefault(serial, {})[tooth] = (ph, dv)
    n = _expect(t, serials, "tooth", teeth)
    out = {}
    for serial, tr in traces.items():
        out[serial] = DiscProfile(
            tuple(tr[k][0] for k in range(1, n + 1)), tuple(tr[k][1] for k in range(1, n + 1))
        )
    return out


def _groups_multi(t: _Table, index: str, within: str) -> dict[str, list[int]]:
    """Rows by serial where ``(serial, index, within)`` must be unique."""
    out: dict[str, list[int]] = {}
    seen: dict[tuple, int] = {}
    for r, serial in enumerate(t.values["serial"]):
        key = (serial, t.values[index][r], t.values[within][r])
        if key in seen:
            raise _err(
                t.source, t.lines[r], t.col(within),
                f"duplicate point: serial {serial!r} {index} {key[1]} at this {within} already "
                f"given on line {seen[key]}",
            )  # fmt: skip
        seen[key] = t.lines[r]
        out.setdefault(serial, []).append(r)
    return out


def read_disc_pitch(path: str | os.PathLike, teeth: int | None = None) -> dict[str, np.ndarray]:
    """Read measured cumulative pitch deviations (format ``disc_pitch``).

    Parameters
    ----------
    path : str or path
        CSV file: ``serial, tooth, cumulative_pitch [um]``.
    teeth : int, optional
        Tooth count ``z_c`` [-]: every serial must give teeth 1..z_c once each.

    Returns
    -------
    dict
        ``serial -> (z_c,)`` cumulative pitch deviation per tooth space [mm].
    """
    t = _parse(path, "disc_pitch")
    serials = _groups(t, "tooth")
    n = _expect(t, serials, "tooth", teeth)
    out = {}
    for serial, rows in serials.items():
        v = np.zeros(n)
        for r in rows:
            v[t.values["tooth"][r] - 1] = t.values["cumulative_pitch"][r]
        out[serial] = v
    return out


def read_pins(path: str | os.PathLike, pins: int | None = None) -> dict[str, PinSet]:
    """Read measured pin diameters and pin-slot positions (format ``pins``).

    Parameters
    ----------
    path : str or path
        CSV file: ``serial, pin, diameter [mm]`` (+ optional ``slot_radial_deviation [um]``,
        ``slot_tangential_deviation [um]``).
    pins : int, optional
        Pin count ``z_p`` [-]: every serial must give pins 1..z_p once each.

    Returns
    -------
    dict
        ``serial -> PinSet`` [mm].
    """
    t = _parse(path, "pins")
    serials = _groups(t, "pin")
    n = _expect(t, serials, "pin", pins)
    out = {}
    for serial, rows in serials.items():
        arrs = {c: np.zeros(n) for c in ("diameter", "rad", "tan")}
        for r in rows:
            k = t.values["pin"][r] - 1
            arrs["diameter"][k] = t.values["diameter"][r]
            if "slot_radial_deviation" in t.values:
                arrs["rad"][k] = t.values["slot_radial_deviation"][r]
            if "slot_tangential_deviation" in t.values:
                arrs["tan"][k] = t.values["slot_tangential_deviation"][r]
        out[serial] = PinSet(arrs["diameter"], arrs["rad"], arrs["tan"])
    return out


def read_crank_eccentricity(
    path: str | os.PathLike, cams: int | None = None
) -> dict[str, CrankCams]:
    """Read measured cam eccentricities and phases per crankshaft (format ``crank_eccentricity``).

    Parameters
    ----------
    path : str or path
        CSV file: ``serial, cam, eccentricity [mm], phase [deg]``.
    cams : int, optional
        Cams per crank (= discs) [-]: every serial must give cams 1..cams once each.

    Returns
    -------
    dict
        ``serial -> CrankCams`` (eccentricity [mm], phase [rad] from the nominal direction).
    """
    t = _parse(path, "crank_eccentricity")
    serials = _groups(t, "cam")
    n = _expect(t, serials, "cam", cams)
    out = {}
    for serial, rows in serials.items():
        e, ph = np.zeros(n), np.zeros(n)
        for r in rows:
            k = t.values["cam"][r] - 1
            e[k], ph[k] = t.values["eccentricity"][r], t.values["phase"][r]
        out[serial] = CrankCams(e, ph)
    return out


def read_disc_bores(path: str | os.PathLike, bores: int | None = None) -> dict[str, np.ndarray]:
    """Read measured crank-bore positions per disc (format ``disc_bores``).

    Parameters
    ----------
    path : str or path
        CSV file: ``serial, bore, x [mm], y [mm]`` in the disc frame.
    bores : int, optional
        Crank bores per disc (= cranks) [-].

    Returns
    -------
    dict
        ``serial -> (bores, 2)`` bore centres [mm].
    """
    t = _parse(path, "disc_bores")
    serials = _groups(t, "bore")
    n = _expect(t, serials, "bore", bores)
    out = {}
    for serial, rows in serials.items():
        xy = np.zeros((n, 2))
        for r in rows:
            xy[t.values["bore"][r] - 1] = (t.values["x"][r], t.values["y"][r])
        out[serial] = xy
    return out


def read_runout(path: str | os.PathLike) -> dict[str, Runout]:
    """Read measured radial run-outs of planets or suns (format ``runout``), one row per part.

    Parameters
    ----------
    path : str or path
        CSV file: ``serial, runout [um], phase [deg]``.

    Returns
    -------
    dict
        ``serial -> Runout`` [mm, rad].
    """
    t = _parse(path, "runout")
    serials = _groups(t, None)
    return {
        s: Runout(float(t.values["runout"][r[0]]), float(t.values["phase"][r[0]]))
        for s, r in serials.items()
    }


def read_bearing_clearances(
    path: str | os.PathLike, cams: int | None = None
) -> dict[str, dict[str, float]]:
    """Read measured radial clearances of a crank's bearings (format ``bearing_clearance``).

    Parameters
    ----------
    path : str or path
        CSV file: ``serial, bearing, radial_clearance [um]``; bearing ``cam_1`` … ``cam_N`` or
        ``carrier``.
    cams : int, optional
        Cams per crank [-]: every serial must name ``cam_1..cam_<cams>`` and ``carrier``.

    Returns
    -------
    dict
        ``serial -> {bearing: clearance [mm]}``.
    """
    t = _parse(path, "bearing_clearance")
    serials = _groups(t, "bearing")
    out: dict[str, dict[str, float]] = {}
    for serial, rows in serials.items():
        d: dict[str, float] = {}
        for r in rows:
            b = t.values["bearing"][r].lower()
            m = re.fullmatch(r"cam_(\d+)", b)
            ok = b == "carrier" or (m is not None and 1 <= int(m.group(1)) <= (cams or 99))
            if not ok:
                raise _err(
                    t.source, t.lines[r], t.col("bearing"),
                    f"bearing {t.values['bearing'][r]!r} is not 'carrier' or 'cam_<j>'"
                    + (f" with j in 1..{cams}" if cams else ""),
                )  # fmt: skip
            d[b] = t.values["radial_clearance"][r]
        if cams is not None:
            want = {f"cam_{j}" for j in range(1, cams + 1)} | {"carrier"}
            missing = sorted(want - set(d))
            if missing:
                raise _err(
                    t.source, t.lines[rows[-1]], t.col("bearing"),
                    f"serial {serial!r} lacks bearing(s) {', '.join(missing)}",
                )  # fmt: skip
        out[serial] = d
    return out


# ---- writers (exact: shortest round-trip repr of every float) -----------------------------
def _write(path: str | os.PathLike, fmt: str, header: list[str], rows: list[list]) -> None:
    lines = [f"# format: {fmt}", ",".join(header)]
    lines += [",".join(v if isinstance(v, str) else repr(v) for v in row) for row in rows]
    Path(path).write_text("\n".join(lines) + "\n", encoding="utf-8")


def _f(x: float) -> float:
    return float(x)


def write_disc_profiles(path: str | os.PathLike, profiles: Mapping[str, DiscProfile]) -> None:
    """Write disc profiles (format ``disc_profile``; profile parameter [deg], deviation [um]).

    Parameters
    ----------
    path : str or path
        File to write.
    profiles : mapping
        ``serial -> DiscProfile`` [rad, mm].
    """
    rows = []
    for serial, p in profiles.items():
        for tooth, (ph, dv) in enumerate(zip(p.phase, p.deviation, strict=True), start=1):
            for a, d in zip(rad_to_deg(ph), mm_to_um(dv), strict=True):
                rows.append([serial, str(tooth), _f(a), _f(d)])
    header = ["serial", "tooth", "profile_parameter [deg]", "deviation [um]"]
    _write(path, "disc_profile", header, rows)


def write_disc_pitch(path: str | os.PathLike, pitch: Mapping[str, np.ndarray]) -> None:
    """Write cumulative pitch deviations (format ``disc_pitch``, [um]).

    Parameters
    ----------
    path : str or path
        File to write.
    pitch : mapping
        ``serial -> (z_c,)`` deviation per tooth [mm].
    """
    rows = [[s, str(k + 1), _f(v)] for s, arr in pitch.items() for k, v in enumerate(mm_to_um(arr))]
    _write(path, "disc_pitch", ["serial", "tooth", "cumulative_pitch [um]"], rows)


def write_pins(path: str | os.PathLike, pins: Mapping[str, PinSet]) -> None:
    """Write pin diameters [mm] and slot deviations [um] (format ``pins``).

    Parameters
    ----------
    path : str or path
        File to write.
    pins : mapping
        ``serial -> PinSet`` [mm].
    """
    rows = []
    for s, p in pins.items():
        for k in range(p.diameter.size):
            rows.append(
                [
                    s,
                    str(k + 1),
                    _f(p.diameter[k]),
                    _f(mm_to_um(p.slot_radial[k])),
                    _f(mm_to_um(p.slot_tangential[k])),
                ]
            )
    header = [
        "serial",
        "pin",
        "diameter [mm]",
        "slot_radial_deviation [um]",
        "slot_tangential_deviation [um]",
    ]
    _write(path, "pins", header, rows)


def write_crank_eccentricity(path: str | os.PathLike, cranks: Mapping[str, CrankCams]) -> None:
    """Write cam eccentricities [mm] and phases [deg] (format ``crank_eccentricity``).

    Parameters
    ----------
    path : str or path
        File to write.
    cranks : mapping
        ``serial -> CrankCams`` [mm, rad].
    """
    rows = [
        [s, str(k + 1), _f(c.eccentricity[k]), _f(rad_to_deg(c.phase[k]))]
        for s, c in cranks.items()
        for k in range(c.eccentricity.size)
    ]
    header = ["serial", "cam", "eccentricity [mm]", "phase [deg]"]
    _write(path, "crank_eccentricity", header, rows)


def write_disc_bores(path: str | os.PathLike, bores: Mapping[str, np.ndarray]) -> None:
    """Write crank-bore positions [mm] (format ``disc_bores``).

    Parameters
    ----------
    path : str or path
        File to write.
    bores : mapping
        ``serial -> (bores, 2)`` [mm].
    """
    rows = [
        [s, str(k + 1), _f(xy[k, 0]), _f(xy[k, 1])]
        for s, xy in bores.items()
        for k in range(len(xy))
    ]
    _write(path, "disc_bores", ["serial", "bore", "x [mm]", "y [mm]"], rows)


def write_runout(path: str | os.PathLike, parts: Mapping[str, Runout]) -> None:
    """Write run-outs [um] and phases [deg] (format ``runout``).

    Parameters
    ----------
    path : str or path
        File to write.
    parts : mapping
        ``serial -> Runout`` [mm, rad].
    """
    rows = [[s, _f(mm_to_um(r.runout)), _f(rad_to_deg(r.phase))] for s, r in parts.items()]
    _write(path, "runout", ["serial", "runout [um]", "phase [deg]"], rows)


def write_bearing_clearances(
    path: str | os.PathLike, clearances: Mapping[str, Mapping[str, float]]
) -> None:
    """Write bearing clearances [um] (format ``bearing_clearance``).

    Parameters
    ----------
    path : str or path
        File to write.
    clearances : mapping
        ``serial -> {bearing: clearance [mm]}``.
    """
    rows = [[s, b, _f(mm_to_um(c))] for s, d in clearances.items() for b, c in d.items()]
    _write(path, "bearing_clearance", ["serial", "bearing", "radial_clearance [um]"], rows)


def check_against_design(
    path: str | os.PathLike,
    fmt: str,
    rows: Mapping[str, np.ndarray],
    nominal: np.ndarray,
    scale_mm: float,
) -> None:
    """Refuse measured values far from the design: a unit slip in a header (``x [um]`` for
    millimetres), a file of another reducer.

    Parameters
    ----------
    path : str or path
        The file the values were read from (named in the error).
    fmt : str
        Its format, a key of :data:`DESIGN_DEVIATION`.
    rows : mapping
        ``serial -> measured values`` in gearte units [mm], as the reader returned them: shape
        ``(count,)`` (eccentricity per cam, diameter per pin) or ``(count, 2)`` (bore centres).
    nominal : numpy.ndarray
        The design's values, broadcastable to each serial's array [mm].
    scale_mm : float
        Size the deviation is judged against [mm] (crank circle radius, design eccentricity,
        design pin diameter); the limit is ``DESIGN_DEVIATION[fmt][1] * scale_mm``.

    Raises
    ------
    MeasurementFileError
        Naming file, line, column and its unit, the value, the design's value and the limit,
        and the unit that would make the value plausible where one does.
    """
    columns, fraction = DESIGN_DEVIATION[fmt]
    limit = fraction * scale_mm
    nom = np.asarray(nominal, dtype=float)
    for serial, values in rows.items():
        v = np.asarray(values, dtype=float)
        if nom.ndim and len(v) != len(nom):  # another count: the reader's count check says so
            k = min(len(v), len(nom))
            v, nom_s = v[:k], nom[:k]
        else:
            nom_s = nom
        dev = np.abs(v - np.broadcast_to(nom_s, v.shape))
        if v.ndim == 2:  # bore centres: the distance from the nominal centre
            dev = np.hypot(dev[:, 0], dev[:, 1])
        bad = np.flatnonzero(~(dev <= limit))
        if bad.size:
            _design_error(path, fmt, columns, serial, int(bad[0]), v, nom_s, limit)


def _design_error(
    path: str | os.PathLike,
    fmt: str,
    columns: tuple[str, ...],
    serial: str,
    k: int,
    values: np.ndarray,
    nominal: np.ndarray,
    limit: float,
) -> None:
    """Raise the error of :func:`check_against_design` for entry ``k`` of ``serial``: the file is
    read again to name its line, column and unit."""
    t = _parse(path, fmt)
    index = {"disc_bores": "bore", "crank_eccentricity": "cam", "pins": "pin"}[fmt]
    r = next(
        r
        for r in range(len(t.lines))
        if t.values["serial"][r] == serial and t.values[index][r] == k + 1
    )
    nom = np.broadcast_to(nominal, values.shape)[k]
    val = values[k]
    if values.ndim == 2:  # the coordinate farther from its nominal
        c = int(np.argmax(np.abs(val - nom)))
        column, got, want = columns[c], float(val[c]), float(nom[c])
    else:
        column, got, want = columns[0], float(val), float(nom)
    j = t.names.index(column)
    unit = (t.units[j] or "").strip()
    factor = _LENGTH[unit.lower()]
    hint = ""
    for other, f in _LENGTH.items():
        if other in ("µm", "micron") or f == factor:
            continue
        if abs(got / factor * f - want) <= limit:
            hint = f"; read as [{other}] it would fit: is the header's unit [{unit}] a mistake?"
    raise _err(
        t.source, t.lines[r], t.col(column),
        f"{got / factor:.6g} [{unit}] ({index} {k + 1} of serial {serial!r}) is "
        f"{abs(got - want):.4g} mm from the design's {want:.6g} mm; a measured part deviates "
        f"from its design by at most {limit:.4g} mm here{hint or ' (a unit mistake?)'}",
    )  # fmt: skip
