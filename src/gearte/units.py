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
