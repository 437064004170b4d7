"""The one unit system of gearte and the helpers that convert at the edges.

Inside gearte every quantity is in **mm, N, N·mm, MPa, rad, s** (and kg, with mass-spring models
in consistent units stated where they appear). Angles leave the library in arcmin, arcsec or
degrees only through the helpers below; strings that name a quantity carry its unit in brackets,
e.g. ``"geometric_te_mean [arcmin]"``.
"""

from __future__ import annotations

from typing import Any, TypeVar

import numpy as np

Quantity = TypeVar("Quantity", float, np.ndarray)
"""A scalar [float] or an array of them: each converter returns the kind it was given."""

__all__ = [
    "ARCMIN_PER_RAD",
    "ARCSEC_PER_RAD",
    "DEG_PER_RAD",
    "rad_to_arcmin",
    "arcmin_to_rad",
    "rad_to_arcsec",
    "arcsec_to_rad",
    "rad_to_deg",
    "deg_to_rad",
    "um_to_mm",
    "mm_to_um",
    "Nm_to_Nmm",
    "Nmm_to_Nm",
    "format_dms",
    "rpm_to_rad_per_s",
    "N_per_mm_to_N_per_m",
    "Nmm_per_rad_to_Nm_per_arcmin",
    "KG_TO_T",
    "KGM2_TO_TMM2",
    "N_PER_M_TO_N_PER_MM",
    "NM_PER_RAD_TO_NMM_PER_RAD",
    "unit_text",
    "split_unit",
    "format_number",
    "format_quantity",
]

DEG_PER_RAD: float = 180.0 / np.pi
ARCMIN_PER_RAD: float = 10800.0 / np.pi
ARCSEC_PER_RAD: float = 648000.0 / np.pi

# --- mass-spring models in mm, N, s (hence mass in tonne): factors from the papers' SI units ---
KG_TO_T: float = 1e-3
"""Mass [kg] → [t] (1 t·mm/s² = 1 N)."""
KGM2_TO_TMM2: float = 1e3
"""Inertia [kg·m²] → [t·mm²]."""
N_PER_M_TO_N_PER_MM: float = 1e-3
"""Stiffness [N/m] → [N/mm]."""
NM_PER_RAD_TO_NMM_PER_RAD: float = 1e3
"""Torsional stiffness [N·m/rad] → [N·mm/rad]."""


def _scaled(x: Any, factor: float) -> Any:
    """x × factor, an array for array input and a float for a scalar."""
    return np.asarray(x, dtype=float) * factor if np.ndim(x) else float(x) * factor


def _divided(x: Any, factor: float) -> Any:
    """x / factor, an array for array input and a float for a scalar."""
    return np.asarray(x, dtype=float) / factor if np.ndim(x) else float(x) / factor


def rad_to_arcmin(x: Quantity) -> Quantity:
    """Angle ``x`` [rad] → [arcmin]."""
    return _scaled(x, ARCMIN_PER_RAD)


def arcmin_to_rad(x: Quantity) -> Quantity:
    """Angle ``x`` [arcmin] → [rad]."""
    return _divided(x, ARCMIN_PER_RAD)


def rad_to_arcsec(x: Quantity) -> Quantity:
    """Angle ``x`` [rad] → [arcsec]."""
    return _scaled(x, ARCSEC_PER_RAD)


def arcsec_to_rad(x: Quantity) -> Quantity:
    """Angle ``x`` [arcsec] → [rad]."""
    return _divided(x, ARCSEC_PER_RAD)


def rad_to_deg(x: Quantity) -> Quantity:
    """Angle ``x`` [rad] → [deg]."""
    return _scaled(x, DEG_PER_RAD)


def deg_to_rad(x: Quantity) -> Quantity:
    """Angle ``x`` [deg] → [rad]."""
    return _divided(x, DEG_PER_RAD)


def um_to_mm(x: Quantity) -> Quantity:
    """Length ``x`` [µm] → [mm]."""
    return _scaled(x, 1e-3)


def mm_to_um(x: Quantity) -> Quantity:
    """Length ``x`` [mm] → [µm]."""
    return _scaled(x, 1e3)


def Nm_to_Nmm(x: Quantity) -> Quantity:  # noqa: N802 - unit names
    """Torque ``x`` [N·m] → [N·mm]."""
    return _scaled(x, 1e3)


def Nmm_to_Nm(x: Quantity) -> Quantity:  # noqa: N802 - unit names
    """Torque ``x`` [N·mm] → [N·m]."""
    return _scaled(x, 1e-3)


def rpm_to_rad_per_s(x: Quantity) -> Quantity:
    """Speed ``x`` [rpm] → [rad/s]."""
    return _scaled(x, 2.0 * np.pi / 60.0)


def N_per_mm_to_N_per_m(x: Quantity) -> Quantity:  # noqa: N802 - unit names
    """Stiffness ``x`` [N/mm] → [N/m]."""
    return _scaled(x, 1e3)


def Nmm_per_rad_to_Nm_per_arcmin(x: Quantity) -> Quantity:  # noqa: N802 - unit names
    """Torsional stiffness ``x`` [N·mm/rad] → [N·m/arcmin] (catalogue torsional rigidity)."""
    return _scaled(x, 1e-3 / ARCMIN_PER_RAD)


def format_dms(angle_rad: float, *, arcsec_decimals: int = 0) -> str:
    """Format an angle ``angle_rad`` [rad] as the papers print it: ``9′59″`` (degrees shown only
    if ≥ 1°), seconds rounded to ``arcsec_decimals`` decimals [-].

    >>> format_dms(arcmin_to_rad(9 + 59 / 60))
    "9′59″"
    """
    sign = "-" if angle_rad < 0 else ""
    total = abs(angle_rad) * ARCSEC_PER_RAD
    total = round(total, arcsec_decimals)
    deg = int(total // 3600)
    rest = total - 3600 * deg
    minutes = int(rest // 60)
    sec = rest - 60 * minutes
    sec_s = f"{sec:.{arcsec_decimals}f}" if arcsec_decimals else f"{int(round(sec))}"
    head = f"{deg}°" if deg else ""
    return f"{sign}{head}{minutes}′{sec_s}″"


# --- the one formatter of quantities for people (reports, figure labels, CLI) ------------------

#: Spelling of units for people; keys are the spellings found in result names.
_UNIT_SPELLING: dict[str, str] = {
    "um": "µm",
    "µm": "µm",
    "um2": "µm²",
    "mm2": "mm²",
    "N*m": "N·m",
    "Nm": "N·m",
    "N.m": "N·m",
    "N*mm": "N·mm",
    "Nmm": "N·mm",
    "N.mm": "N·mm",
    "deg": "°",
    "arcmin": "arcmin",
    "arcsec": "arcsec",
    "x input": "× input",
}
_SUPERSCRIPT = str.maketrans("-0123456789", "⁻⁰¹²³⁴⁵⁶⁷⁸⁹")
#: Units written as a symbol right after the number (``1.03′``, ``71.6″``, ``14°``).
_ATTACHED = {"arcmin": "′", "arcsec": "″", "deg": "°", "%": " %"}


def unit_text(unit: str) -> str:
    """A unit as people read it: ``um`` → ``µm``, ``N*m/arcmin`` → ``N·m/arcmin``, ``deg`` → ``°``.

    Compound units are spelled part by part (``arcsec/um`` → ``arcsec/µm``)."""
    unit = unit.strip()
    if unit in _UNIT_SPELLING:
        return _UNIT_SPELLING[unit]
    if "/" in unit:
        return "/".join(unit_text(p) for p in unit.split("/"))
    return unit.replace("*", "·")


def split_unit(name: str) -> tuple[str, str]:
    """``"peak_pin_load [N]"`` → ``("peak_pin_load", "N")``; without a unit → ``(name, "")``."""
    name = str(name)
    if name.endswith("]") and " [" in name:
        base, _, unit = name[:-1].rpartition(" [")
        return base, unit
    return name, ""


def format_number(x: object, digits: int = 4) -> str:
    """The number ``x`` for people: ``digits`` significant digits, no exponent between 1e-3 and 1e6,
    integers as integers, booleans as yes/no; NaN, infinities and ``None`` as an em dash."""
    if x is None:
        return "—"
    if isinstance(x, bool | np.bool_):
        return "yes" if x else "no"
    if isinstance(x, int | np.integer):
        return f"{int(x):,}".replace(",", "\u2009") if abs(int(x)) >= 10000 else str(int(x))
    try:
        f = float(x)  # type: ignore[arg-type]
    except (TypeError, ValueError):
        return str(x)
    if not np.isfinite(f):
        return "—"
    if f == 0:
        return "0"
    a = abs(f)
    if 1e-3 <= a < 1e6:
        decimals = max(0, digits - 1 - int(np.floor(np.log10(a))))
        text = f"{f:.{decimals}f}"
        if "." in text:
            text = text.rstrip("0").rstrip(".")
        return "0" if text in ("-0", "") else text
    mant, _, exp = f"{f:.{digits - 1}e}".partition("e")
    if "." in mant:
        mant = mant.rstrip("0").rstrip(".")
    return f"{mant}×10{str(int(exp)).translate(_SUPERSCRIPT)}"


def format_quantity(x: object, unit: str = "", digits: int = 4) -> str:
    """The value ``x`` with its ``unit`` for people (``digits`` significant digits):
    ``(1.0339, "arcmin")`` → ``1.034′``, ``(1904.6, "N")`` → ``1905 N``, ``(17.19, "um")`` →
    ``17.19 µm``, NaN → ``—`` (no unit)."""
    text = format_number(x, digits)
    if not unit or text == "—":
        return text
    if unit in _ATTACHED:
        return text + _ATTACHED[unit]
    return f"{text} {unit_text(unit)}"
