"""Tooth-thickness allowances of a gear from its DIN 3967 class, and the backlash of a pair.

A designer states the tooth thickness of a cylindrical gear as a *class* on the drawing, e.g.
``cd25``: the **allowance series** (``a ab b bc c cd d e f g h``, from the largest thinning to
none) fixes the upper tooth-thickness allowance ``A_sne``, the **tolerance series**
(``21 … 30``, fine to coarse) the tooth-thickness tolerance ``T_sn``; the lower allowance is
``A_sni = A_sne − T_sn``. Both tables are stepped in the reference diameter ``d``: a row covers
``d_prev < d ≤ d_upper`` ("over … up to"), the first row ``d ≤ 10 mm``, the last
``6300 < d ≤ 10 000 mm``; outside the tables is an error (a table is not extrapolated).

The allowances are in the normal section on the reference cylinder; for a spur gear that is
the circular tooth thickness on the reference circle, which is what gearte's spur-pair models
call the tooth-thickness deviation (``thickness_upper_um``/``thickness_lower_um``).

Backlash of a spur pair from the allowances of both gears and the centre-distance allowances
``A_ae`` (upper) / ``A_ai`` (lower), with ``α_w`` the working pressure angle (the pressure
angle for a pair at its standard centre distance)::

    j_t,max = −(A_sni,1 + A_sni,2) + 2 A_ae tan α_w      circumferential (on the pitch circle)
    j_t,min = −(A_sne,1 + A_sne,2) + 2 A_ai tan α_w
    j_n     = j_t cos α_w                                  normal

Sources as read (the standard itself is not in gearte's reference corpus):

* Tables 1 (``A_sne``, series a … h) and 2 (``T_sn``, series 21 … 30) of DIN 3967:1978-08 as
  transcribed in a public gear-geometry service's module ``din3967`` (transcribed from the
  norm, its test pinned to the norm's own example §3.1: class ``27cd`` at ``d = 100 mm`` →
  ``A_sne = −70 µm``, ``A_sni = −170 µm``). An independent public gear optimiser quotes the
  ``cd`` column of Table 1 and the ``25`` column of Table 2 for all eleven diameter rows; they
  agree value for value. Every value below was compared with both (the ``cd``/``25`` columns)
  or with the first (the others).
* Backlash: ``j_n = −(A_sne,1 + A_sne,2) cos α_n`` for two gears of one class at the nominal
  centre distance as the same service's test states it; the centre-distance term
  ``Δj_t = 2 A_a tan α_wt``, ``Δj_n = Δj_t cos α_wt`` as a published FVA STplus report prints it
  (``A_Ae = +15 µm`` at ``α_wt = 21.46251°`` → ``Δj_t = 0.012 mm``, ``Δj_n = 0.011 mm``), the
  same ``2 Δa sin α`` as Jiang et al. (2024) eq. 1 (:mod:`gearte.models.backlash`).

Helical pairs (:func:`helical_pair_backlash_limits`): the allowances are normal-section values;
on the reference cylinder a normal circular arc is the transverse one times ``cos β``
(``j_nt = j_tt cos β``), so ``A_st = A_sn / cos β``; the centre-distance term acts in the
transverse plane (``2 A_a tan α_t``); ``j_n = j_t cos α_n cos β`` (``= j_t cos α_t cos β_b``,
``cos β_b = cos β cos α_n / cos α_t``). The backlash relations ``j_nn = j_nt cos α_n``,
``j_nt = j_tt cos β``, ``j_nn = j_tt cos α_n cos β`` are as the Autodesk Inventor help page
"Backlash types (defined for each gear in a gear set)" states them; the same law gives
``j_n = −(A_sn,1 + A_sn,2) cos α_n`` at the nominal centre distance, the form the gear-geometry
service's test above states (with ``α_n``). ISO 21771's own text was not available.

Not implemented: the
conversion of ``A_sn`` to span-measurement or ball-dimension allowances (DIN 3967 Appendix B);
DIN 3967's own recommendation of a class for a given use. See ``docs/tolerance_grades.md``.

References
----------
DIN 3967:1978-08 System of gear fits — Backlash, tooth thickness allowances, tooth thickness
tolerances — Principles. Beuth, Berlin.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from gearte.errors import ParameterError

__all__ = [
    "ALLOWANCE_SERIES",
    "helical_pair_backlash_limits",
    "TOLERANCE_SERIES",
    "DIAMETER_UPPER_BOUNDS_MM",
    "ToothThicknessAllowances",
    "BacklashLimits",
    "parse_thickness_class",
    "upper_allowance_um",
    "thickness_tolerance_um",
    "tooth_thickness_allowances",
    "pair_backlash_limits",
]

#: Allowance series of DIN 3967 Table 1, largest thinning first (``h``: zero allowance).
ALLOWANCE_SERIES: tuple[str, ...] = ("a", "ab", "b", "bc", "c", "cd", "d", "e", "f", "g", "h")
#: Tolerance series of DIN 3967 Table 2, finest first.
TOLERANCE_SERIES: tuple[int, ...] = (21, 22, 23, 24, 25, 26, 27, 28, 29, 30)
#: Upper bound of each reference-diameter row [mm]; row ``i`` covers ``bounds[i−1] < d ≤
#: bounds[i]`` (the first row ``d ≤ 10 mm``).
DIAMETER_UPPER_BOUNDS_MM: tuple[float, ...] = (
    10.0, 50.0, 125.0, 280.0, 560.0, 1000.0, 1600.0, 2500.0, 4000.0, 6300.0, 10_000.0,
)  # fmt: skip

# DIN 3967 Table 1: upper tooth-thickness allowance A_sne [µm]; rows: diameter rows above,
# columns: ALLOWANCE_SERIES.
_TABLE1_A_SNE_UM: tuple[tuple[int, ...], ...] = (
    (-100, -85, -70, -58, -48, -40, -33, -22, -10, -5, 0),
    (-135, -110, -95, -75, -65, -54, -44, -30, -14, -7, 0),
    (-180, -150, -125, -105, -85, -70, -60, -40, -19, -9, 0),
    (-250, -200, -170, -140, -115, -95, -80, -56, -26, -12, 0),
    (-330, -280, -230, -190, -155, -130, -110, -75, -35, -17, 0),
    (-450, -370, -310, -260, -210, -175, -145, -100, -48, -22, 0),
    (-600, -500, -420, -340, -290, -240, -200, -135, -64, -30, 0),
    (-820, -680, -560, -460, -390, -320, -270, -180, -85, -41, 0),
    (-1100, -920, -760, -620, -520, -430, -360, -250, -115, -56, 0),
    (-1500, -1250, -1020, -840, -700, -580, -480, -330, -155, -75, 0),
    (-2000, -1650, -1350, -1150, -940, -780, -640, -450, -210, -100, 0),
)

# DIN 3967 Table 2: tooth-thickness tolerance T_sn [µm]; columns: TOLERANCE_SERIES.
_TABLE2_T_SN_UM: tuple[tuple[int, ...], ...] = (
    (3, 5, 8, 12, 20, 30, 50, 80, 130, 200),
    (5, 8, 12, 20, 30, 50, 80, 130, 200, 300),
    (6, 10, 16, 25, 40, 60, 100, 160, 250, 400),
    (8, 12, 20, 30, 50, 80, 130, 200, 300, 500),
    (10, 16, 25, 40, 60, 100, 160, 250, 400, 600),
    (12, 20, 30, 50, 80, 130, 200, 300, 500, 800),
    (16, 25, 40, 60, 100, 160, 250, 400, 600, 1000),
    (20, 30, 50, 80, 130, 200, 300, 500, 800, 1300),
    (25, 40, 60, 100, 160, 250, 400, 600, 1000, 1600),
    (30, 50, 80, 130, 200, 300, 500, 800, 1300, 2000),
    (40, 60, 100, 160, 250, 400, 600, 1000, 1600, 2400),
)

_CLASS = re.compile(r"^\s*(?:([a-h]{1,2})\s*(\d{2})|(\d{2})\s*([a-h]{1,2}))\s*$")


def _row(field: str, reference_diameter_mm: float) -> int:
    d = float(reference_diameter_mm)
    if not (math.isfinite(d) and 0.0 < d <= DIAMETER_UPPER_BOUNDS_MM[-1]):
        raise ParameterError(
            field,
            reference_diameter_mm,
            "the reference diameter is outside DIN 3967's tables (0 < d <= 10000 mm); "
            "the tables are not extrapolated",
        )
    return next(i for i, hi in enumerate(DIAMETER_UPPER_BOUNDS_MM) if d <= hi)


def parse_thickness_class(text: str, field: str = "tooth_thickness_allowance") -> tuple[str, int]:
    """Split a DIN 3967 tooth-thickness class into its allowance and tolerance series.

    ``"cd25"``, ``"cd 25"`` and the drawing order ``"25cd"`` all give ``("cd", 25)``.

    Parameters
    ----------
    text : str
        The class as written on the drawing or in the case file.
    field : str
        Name of the input (for the error message).

    Returns
    -------
    tuple
        Allowance series (one of :data:`ALLOWANCE_SERIES`) and tolerance series (21 … 30).

    Examples
    --------
    >>> parse_thickness_class("cd25"), parse_thickness_class("27 cd")
    (('cd', 25), ('cd', 27))
    """
    m = _CLASS.match(str(text).lower()) if isinstance(text, str) else None
    series, tol = (m.group(1) or m.group(4), int(m.group(2) or m.group(3))) if m else ("", 0)
    if series not in ALLOWANCE_SERIES or tol not in TOLERANCE_SERIES:
        raise ParameterError(
            field,
            text,
            "not a DIN 3967 tooth-thickness class: an allowance series "
            f"({' '.join(ALLOWANCE_SERIES)}) and a tolerance series (21 to 30), e.g. 'cd25'",
        )
    return series, tol


def upper_allowance_um(
    series: str, reference_diameter_mm: float, field: str = "tooth_thickness_allowance"
) -> float:
    """Upper tooth-thickness allowance ``A_sne`` [µm] of an allowance series (DIN 3967 Table 1).

    Parameters
    ----------
    series : str
        Allowance series ``a`` … ``h``.
    reference_diameter_mm : float
        Reference diameter ``d`` [mm], ``0 < d ≤ 10 000``.
    field : str
        Name of the input (for the error message).

    Returns
    -------
    float
        ``A_sne`` [µm], ≤ 0 (``h``: 0).

    References
    ----------
    DIN 3967:1978-08, Table 1.

    Examples
    --------
    >>> upper_allowance_um("cd", 100.0)
    -70.0
    """
    if series not in ALLOWANCE_SERIES:
        raise ParameterError(field, series, f"allowance series must be one of {ALLOWANCE_SERIES}")
    row = _row(field, reference_diameter_mm)
    return float(_TABLE1_A_SNE_UM[row][ALLOWANCE_SERIES.index(series)])


def thickness_tolerance_um(
    series: int, reference_diameter_mm: float, field: str = "tooth_thickness_allowance"
) -> float:
    """Tooth-thickness tolerance ``T_sn`` [µm] of a tolerance series (DIN 3967 Table 2).

    Parameters
    ----------
    series : int
        Tolerance series 21 … 30.
    reference_diameter_mm : float
        Reference diameter ``d`` [mm], ``0 < d ≤ 10 000``.
    field : str
        Name of the input (for the error message).

    Returns
    -------
    float
        ``T_sn`` [µm], > 0.

    References
    ----------
    DIN 3967:1978-08, Table 2.

    Examples
    --------
    >>> thickness_tolerance_um(27, 100.0)
    100.0
    """
    if isinstance(series, bool) or series not in TOLERANCE_SERIES:
        raise ParameterError(field, series, "tolerance series must be an integer from 21 to 30")
    row = _row(field, reference_diameter_mm)
    return float(_TABLE2_T_SN_UM[row][TOLERANCE_SERIES.index(series)])


@dataclass(frozen=True)
class ToothThicknessAllowances:
    """Tooth-thickness allowances of one gear from its DIN 3967 class [µm]."""

    thickness_class: str
    allowance_series: str
    tolerance_series: int
    reference_diameter_mm: float
    upper_um: float
    lower_um: float
    tolerance_um: float


def tooth_thickness_allowances(
    thickness_class: str, reference_diameter_mm: float, field: str = "tooth_thickness_allowance"
) -> ToothThicknessAllowances:
    """Upper and lower tooth-thickness allowances of a gear from its DIN 3967 class.

    Parameters
    ----------
    thickness_class : str
        Class as on the drawing, e.g. ``"cd25"`` (allowance series ``cd``, tolerance series 25).
    reference_diameter_mm : float
        Reference diameter ``d = m·z`` (spur gear) [mm], ``0 < d ≤ 10 000``.
    field : str
        Name of the input (for the error message).

    Returns
    -------
    ToothThicknessAllowances
        ``upper_um = A_sne`` (Table 1), ``tolerance_um = T_sn`` (Table 2), ``lower_um = A_sni =
        A_sne − T_sn`` [µm].

    References
    ----------
    DIN 3967:1978-08, Tables 1 and 2; example §3.1.

    Examples
    --------
    >>> t = tooth_thickness_allowances("27cd", 100.0)   # the norm's own example
    >>> t.upper_um, t.lower_um
    (-70.0, -170.0)
    """
    series, tol = parse_thickness_class(thickness_class, field)
    upper = upper_allowance_um(series, reference_diameter_mm, field)
    t_sn = thickness_tolerance_um(tol, reference_diameter_mm, field)
    return ToothThicknessAllowances(
        thickness_class=f"{series}{tol}",
        allowance_series=series,
        tolerance_series=tol,
        reference_diameter_mm=float(reference_diameter_mm),
        upper_um=upper,
        lower_um=upper - t_sn,
        tolerance_um=t_sn,
    )


@dataclass(frozen=True)
class BacklashLimits:
    """Backlash limits of a pair [mm] (arrays where the inputs are arrays)."""

    circumferential_min: np.ndarray | float
    circumferential_max: np.ndarray | float
    normal_min: np.ndarray | float
    normal_max: np.ndarray | float


def pair_backlash_limits(
    upper_1: ArrayLike,
    lower_1: ArrayLike,
    upper_2: ArrayLike,
    lower_2: ArrayLike,
    centre_upper: ArrayLike,
    centre_lower: ArrayLike,
    working_pressure_angle: ArrayLike,
) -> BacklashLimits:
    """Circumferential and normal backlash limits of a spur pair from its allowances.

    Parameters
    ----------
    upper_1, lower_1 : array_like
        Tooth-thickness allowances ``A_sne``, ``A_sni`` of gear 1 [mm] (negative: thinner).
    upper_2, lower_2 : array_like
        The same of gear 2 [mm].
    centre_upper, centre_lower : array_like
        Centre-distance allowances ``A_ae`` (≥ 0 for a js field) and ``A_ai`` [mm].
    working_pressure_angle : array_like
        Working pressure angle ``α_w`` [rad] (the pressure angle at the standard centre
        distance).

    Returns
    -------
    BacklashLimits
        ``j_t`` and ``j_n`` minimum and maximum [mm].

    Notes
    -----
    ``j_t,max = −(A_sni,1 + A_sni,2) + 2 A_ae tan α_w``, ``j_t,min = −(A_sne,1 + A_sne,2) + 2 A_ai
    tan α_w``, ``j_n = j_t cos α_w`` (module docstring: sources). The form and run-out
    deviations of the gears and the bearing clearances are not in these limits; the gear_pair
    study adds them through the Jiang et al. (2024) stack.

    References
    ----------
    DIN 3967:1978-08. Jiang J. et al. (2024) J. Zhejiang Univ. (Eng. Sci.) 58(8), 1533–1542,
    eq. 1. doi:10.3785/j.issn.1008-973X.2024.08.001

    Examples
    --------
    >>> b = pair_backlash_limits(-0.054, -0.084, -0.070, -0.110, 0.0, 0.0, 0.3490658504)
    >>> round(float(b.normal_min), 5), round(float(b.normal_max), 5)
    (0.11652, 0.1823)
    """
    tan_a, cos_a = np.tan(working_pressure_angle), np.cos(working_pressure_angle)
    jt_max = -(np.add(lower_1, lower_2)) + 2.0 * np.multiply(centre_upper, tan_a)
    jt_min = -(np.add(upper_1, upper_2)) + 2.0 * np.multiply(centre_lower, tan_a)
    return BacklashLimits(jt_min, jt_max, jt_min * cos_a, jt_max * cos_a)


def helical_pair_backlash_limits(
    upper_1: ArrayLike,
    lower_1: ArrayLike,
    upper_2: ArrayLike,
    lower_2: ArrayLike,
    centre_upper: ArrayLike,
    centre_lower: ArrayLike,
    normal_pressure_angle: float,
    helix_angle: float,
) -> BacklashLimits:
    """Backlash limits of a helical pair at its standard centre distance from the normal-section
    allowances.

    Parameters
    ----------
    upper_1, lower_1, upper_2, lower_2 : array_like
        Normal tooth-thickness allowances ``A_sne``, ``A_sni`` of gears 1 and 2 [mm].
    centre_upper, centre_lower : array_like
        Centre-distance allowances ``A_ae``, ``A_ai`` [mm].
    normal_pressure_angle : float
        ``α_n`` [rad].
    helix_angle : float
        ``β`` on the reference cylinder [rad], ``|β| < 90°``.

    Returns
    -------
    BacklashLimits
        ``circumferential_*``: transverse circumferential backlash ``j_t`` on the reference
        circle; ``normal_*``: normal backlash ``j_n`` [mm].

    Notes
    -----
    ``α_t = atan(tan α_n / cos β)``, ``A_st = A_sn / cos β``,
    ``j_t = −(A_st,1 + A_st,2) + 2 A_a tan α_t``, ``j_n = j_t cos α_n cos β``; ``β = 0`` is
    :func:`pair_backlash_limits` (module docstring: sources).

    References
    ----------
    DIN 3967:1978-08. Autodesk Inventor Help, "Backlash types (defined for each gear in a gear
    set)" (backlash relations of a helical mesh).

    Examples
    --------
    >>> b = helical_pair_backlash_limits(-0.054, -0.084, -0.070, -0.110, 0, 0, 0.3490658504, 0)
    >>> round(float(b.normal_max), 5)
    0.1823
    """
    beta = float(helix_angle)
    if not abs(beta) < 0.5 * math.pi:
        raise ParameterError("helix_angle", beta, "must be within (-90°, 90°) [rad]")
    cos_b = math.cos(beta)
    alpha_t = math.atan(math.tan(float(normal_pressure_angle)) / cos_b)
    t = pair_backlash_limits(
        np.divide(upper_1, cos_b),
        np.divide(lower_1, cos_b),
        np.divide(upper_2, cos_b),
        np.divide(lower_2, cos_b),
        centre_upper,
        centre_lower,
        alpha_t,
    )
    k = math.cos(float(normal_pressure_angle)) * cos_b
    return BacklashLimits(
        t.circumferential_min,
        t.circumferential_max,
        np.multiply(t.circumferential_min, k),
        np.multiply(t.circumferential_max, k),
    )
