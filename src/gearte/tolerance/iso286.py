"""Standard tolerance grades of ISO 286-1 and the symmetric ``js`` fields of a centre distance.

A gear pair's centre-distance allowance is given, in DIN 3964's system, as an ISO 286
tolerance field of the centre distance: ``js7`` means ``A_ae = +IT7/2``, ``A_ai = −IT7/2``
with IT7 the standard tolerance of grade 7 for the nominal centre distance. Grades
IT5 … IT11, nominal sizes up to 3150 mm; a size row covers ``previous < size ≤ upper``.

Sources as read (the standards are not in gearte's reference corpus): ISO 286-1:2010 Table 1
as tabulated in a public tolerance knowledge base (sizes to 3150 mm, IT01 … IT18) and, for
sizes up to 500 mm and IT5 … IT8, in two independent public fits calculators; they agree
value for value where they overlap. ``tests/test_din3967.py`` checks every value up to 500 mm
against the standard's formula ``IT = k·i``, ``i = 0.45 ∛D + 0.001 D`` (``D`` the geometric
mean of the row's bounds; ``k`` = 7, 10, 16, 25, 40, 64, 100 for IT5 … IT11). A js7 centre
distance of 52 mm gives ±15 µm, as a published FVA STplus report prints for DIN 3964 field JS7
(``A_Ae = +0.015``, ``A_Ai = −0.015`` mm).

``±IT/2`` is returned unrounded (an odd IT gives half micrometres); ISO 286-2's tables of
``js`` limit deviations were not available to check whether they round it.

References
----------
ISO 286-1:2010 Geometrical product specifications (GPS) — ISO code system for tolerances on
linear sizes — Part 1: Basis of tolerances, deviations and fits, Table 1.
DIN 3964:1980-11 Deviations of shaft centre distances and shaft position tolerances of
casings for cylindrical gears.
"""

from __future__ import annotations

import math
import re

from gearte.errors import ParameterError

__all__ = [
    "SIZE_UPPER_BOUNDS_MM",
    "IT_GRADES",
    "standard_tolerance_um",
    "parse_js_field",
    "js_allowances_um",
]

#: Upper bound of each nominal-size row [mm]; row ``i`` covers ``bounds[i−1] < size ≤ bounds[i]``
#: (the first row ``size ≤ 3 mm``).
SIZE_UPPER_BOUNDS_MM: tuple[float, ...] = (
    3, 6, 10, 18, 30, 50, 80, 120, 180, 250, 315, 400, 500,
    630, 800, 1000, 1250, 1600, 2000, 2500, 3150,
)  # fmt: skip

# ISO 286-1:2010 Table 1, standard tolerance values IT5 … IT11 [µm], one value per size row.
_IT_UM: dict[int, tuple[int, ...]] = {
    5: (4, 5, 6, 8, 9, 11, 13, 15, 18, 20, 23, 25, 27, 32, 36, 40, 47, 55, 65, 78, 96),
    6: (6, 8, 9, 11, 13, 16, 19, 22, 25, 29, 32, 36, 40, 44, 50, 56, 66, 78, 92, 110, 135),
    7: (10, 12, 15, 18, 21, 25, 30, 35, 40, 46, 52, 57, 63, 70, 80, 90, 105, 125, 150, 175, 210),
    8: (14, 18, 22, 27, 33, 39, 46, 54, 63, 72, 81, 89, 97, 110, 125, 140, 165, 195, 230, 280,
        330),
    9: (25, 30, 36, 43, 52, 62, 74, 87, 100, 115, 130, 140, 155, 175, 200, 230, 260, 310, 370,
        440, 540),
    10: (40, 48, 58, 70, 84, 100, 120, 140, 160, 185, 210, 230, 250, 280, 320, 360, 420, 500,
         600, 700, 860),
    11: (60, 75, 90, 110, 130, 160, 190, 220, 250, 290, 320, 360, 400, 440, 500, 560, 660, 780,
         920, 1100, 1350),
}  # fmt: skip

#: The grades gearte tabulates.
IT_GRADES: tuple[int, ...] = tuple(_IT_UM)

_JS = re.compile(r"^\s*js\s*(\d{1,2})\s*$")


def standard_tolerance_um(grade: int, nominal_size_mm: float, field: str = "grade") -> float:
    """Standard tolerance ``IT<grade>`` [µm] of a nominal size (ISO 286-1:2010 Table 1).

    Parameters
    ----------
    grade : int
        Standard tolerance grade, 5 … 11.
    nominal_size_mm : float
        Nominal size [mm], ``0 < size ≤ 3150``.
    field : str
        Name of the input (for the error message).

    Returns
    -------
    float
        IT value [µm].

    References
    ----------
    ISO 286-1:2010, Table 1.

    Examples
    --------
    >>> standard_tolerance_um(7, 52.0)
    30.0
    """
    if isinstance(grade, bool) or grade not in _IT_UM:
        raise ParameterError(field, grade, f"ISO 286 grade must be one of {IT_GRADES}")
    s = float(nominal_size_mm)
    if not (math.isfinite(s) and 0.0 < s <= SIZE_UPPER_BOUNDS_MM[-1]):
        raise ParameterError(
            field,
            nominal_size_mm,
            "nominal size outside ISO 286-1 Table 1 (0 < size <= 3150 mm); not extrapolated",
        )
    row = next(i for i, hi in enumerate(SIZE_UPPER_BOUNDS_MM) if s <= hi)
    return float(_IT_UM[grade][row])


def parse_js_field(tolerance_field: str, field: str = "centre_distance_allowance") -> int:
    """The grade of a symmetric ISO 286 field: ``"js7"`` (or ``"JS 7"``) → 7.

    Parameters
    ----------
    tolerance_field : str
        ``"js5"`` … ``"js11"``.
    field : str
        Name of the input (for the error message).

    Returns
    -------
    int
        The standard tolerance grade.

    Examples
    --------
    >>> parse_js_field("JS 7")
    7
    """
    m = _JS.match(tolerance_field.lower()) if isinstance(tolerance_field, str) else None
    grade = int(m.group(1)) if m else -1
    if grade not in _IT_UM:
        raise ParameterError(
            field,
            tolerance_field,
            f"must be a symmetric ISO 286 field js{IT_GRADES[0]} … js{IT_GRADES[-1]} (DIN 3964), "
            "e.g. 'js7'",
        )
    return grade


def js_allowances_um(
    tolerance_field: str, nominal_size_mm: float, field: str = "centre_distance_allowance"
) -> tuple[float, float]:
    """Upper and lower allowance [µm] of a symmetric ISO 286 field ``js<grade>``.

    Parameters
    ----------
    tolerance_field : str
        ``"js5"`` … ``"js11"`` (DIN 3964's centre-distance allowance fields).
    nominal_size_mm : float
        Nominal size, here the centre distance ``a`` [mm].
    field : str
        Name of the input (for the error message).

    Returns
    -------
    tuple of float
        ``(+IT/2, −IT/2)`` [µm].

    References
    ----------
    ISO 286-1:2010, Table 1; DIN 3964:1980-11.

    Examples
    --------
    >>> js_allowances_um("js7", 52.0)   # STplus: A_Ae = +0.015, A_Ai = -0.015 mm
    (15.0, -15.0)
    """
    half = 0.5 * standard_tolerance_um(
        parse_js_field(tolerance_field, field), nominal_size_mm, field
    )
    return half, -half
