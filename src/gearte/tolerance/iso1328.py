"""Gear accuracy grades → tolerances: ISO 1328-1:2013 flank tolerances, radial composite and
run-out tolerances.

A designer states a gear's accuracy as a *grade* (ISO 1328-1:2013 flank tolerance class
``A = 1 … 11``), not as numbers; these functions turn the grade and the gear's size into the
tolerance values [µm] the Monte-Carlo draws from.

Formulas (class ``A``, step factor ``(√2)^(A−5)``, ``d`` reference diameter [mm], ``m_n``
normal module [mm], ``b`` face width [mm]; ISO 1328-1:2013 clause 5.2, equation numbers of the
standard)::

    f_pT   = (0.001 d + 0.4 m_n + 5)               (√2)^(A−5)          (5)  single pitch
    F_pT   = (0.002 d + 0.55 √d + 0.7 m_n + 12)     (√2)^(A−5)          (6)  cumulative pitch
    f_HαT  = (0.4 m_n + 0.001 d + 4)                (√2)^(A−5)          (7)  profile slope
    f_fαT  = (0.55 m_n + 5)                         (√2)^(A−5)          (8)  profile form
    F_αT   = √(f_HαT² + f_fαT²)                                          (9)  total profile
    f_HβT  = (0.05 √d + 0.35 √b + 4)                (√2)^(A−5)          (10) helix slope
    f_fβT  = (0.07 √d + 0.45 √b + 4)                (√2)^(A−5)          (11) helix form
    F_βT   = √(f_HβT² + f_fβT²)                                          (12) total helix
    F_rT   = 0.9 F_pT                                                         run-out

(9) and (12) take the *unrounded* slope and form values. Rounding (clause 5.2.3): above 10 µm
to the nearest 1 µm, from 5 to 10 µm to the nearest 0.5 µm, below 5 µm to the nearest
0.1 µm; halves round away from zero. Range of application: ``5 ≤ z ≤ 1000``,
``5 ≤ d ≤ 15 000 mm``, ``0.5 ≤ m_n ≤ 70 mm``, ``4 ≤ b ≤ 1200 mm``, ``β ≤ 45°``; the standard
forbids extrapolation, so values outside are errors (``z`` is checked where the caller gives
``teeth``). The standard's scope is "individual cylindrical involute gears", internal gears not
excluded: an internal gear (a planetary ring) is read with ``z`` its tooth count and
``d = m_n z`` its (positive) reference diameter.

Radial composite (double-flank) tolerances, grade ``Q = 4 … 12`` of ISO 1328-2:1997 (the
edition whose formulas gearte's reference corpus holds; ISO 1328-2:2020 replaced them with the
``R`` classes, which are not implemented)::

    F_i″ = (3.2 m_n + 1.01 √d + 6.4)  (√2)^(Q−5)     total radial composite
    f_i″ = (2.96 m_n + 0.01 √d + 0.8) (√2)^(Q−5)     tooth-to-tooth radial composite

rounded as above. Where gearte's models need the radial composite tolerance of a gear given
only a flank class, the same number is used as the radial grade (a designer's usual
convention, stated in the result notes).

Sources as read (the standards themselves are not in the corpus): the 2013 formulas and the
rounding rule as implemented in two independent public calculators that cite the equation
numbers (they agree term by term, including the ``0.001 d`` of (7)), and a worked example in a
third (m_n = 3, z = 40, d = 120, b = 30, class 6: f_pT 8.94 → 9.0, F_pT 28.80 → 29, F_αT 12);
the 1997 radial composite formulas as quoted in a gear tool's design notes. See
``docs/tolerance_grades.md``.

References
----------
ISO 1328-1:2013 Cylindrical gears — ISO system of flank tolerance classification — Part 1:
Definitions and allowable values of deviations relevant to flanks of gear teeth.
ISO 1328-2:1997 Cylindrical gears — ISO system of accuracy — Part 2: Definitions and allowable
values of deviations relevant to radial composite deviations and runout information.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass

from gearte.errors import ParameterError

__all__ = [
    "BEVEL_GRADE_REASON",
    "FlankTolerances",
    "RadialTolerances",
    "iso1328_round",
    "flank_tolerances",
    "radial_composite_tolerances",
    "grade_tolerances_um",
    "runout_tolerance",
]

#: Why a bevel gear takes no ``grade``: ISO 1328 is for cylindrical gears; the bevel accuracy
#: standard, ISO 17485, is not implemented (its formulas are in no source gearte could read), and
#: ISO 1328-1 is not substituted for it.
BEVEL_GRADE_REASON = (
    "bevel gears take no accuracy grade in gearte: ISO 1328-1 is for cylindrical gears only, "
    "and the bevel gear accuracy standard (ISO 17485) is not implemented — its formulas are in "
    "no source gearte could read, and ISO 1328-1 is not substituted for it; give the "
    "tolerances in µm"
)

_SQ2 = math.sqrt(2.0)
_RANGES = {
    "reference_diameter_mm": (5.0, 15_000.0),
    "module_mm": (0.5, 70.0),
    "face_width_mm": (4.0, 1200.0),
    "teeth": (5.0, 1000.0),
}


def iso1328_round(value_um: float) -> float:
    """Round a tolerance ``value_um`` [µm] as ISO 1328-1:2013 §5.2.3 prescribes.

    > 10 µm: nearest 1 µm; 5 … 10 µm: nearest 0.5 µm; < 5 µm: nearest 0.1 µm (halves away from
    zero).

    >>> iso1328_round(8.94), iso1328_round(28.80), iso1328_round(4.94)
    (9.0, 29.0, 4.9)
    """
    v = float(value_um)
    if not math.isfinite(v) or v < 0:
        raise ParameterError("tolerance_um", value_um, "must be a finite number >= 0")
    if v > 10.0:
        step = 1.0
    elif v >= 5.0:
        step = 0.5
    else:
        step = 0.1
    # round half away from zero on the step grid; the small epsilon absorbs binary noise
    # (7.25 stored as 7.2499999...)
    return round(math.floor(v / step + 0.5 + 1e-9) * step, 1)


def _check_grade(field: str, grade: int, lo: int, hi: int) -> int:
    if isinstance(grade, bool) or int(grade) != grade or not lo <= int(grade) <= hi:
        raise ParameterError(field, grade, f"must be an integer class from {lo} to {hi}")
    return int(grade)


def _check_range(field: str, value: float) -> float:
    lo, hi = _RANGES[field]
    v = float(value)
    if not (math.isfinite(v) and lo <= v <= hi):
        raise ParameterError(
            field,
            value,
            f"outside the range of ISO 1328 ({lo:g} to {hi:g}); the standard's formulas must "
            "not be extrapolated",
        )
    return v


@dataclass(frozen=True)
class FlankTolerances:
    """ISO 1328-1:2013 flank tolerances of one gear [µm], rounded; ``unrounded`` keeps the
    formula values."""

    grade: int
    f_pT: float
    F_pT: float
    f_HalphaT: float
    f_falphaT: float
    F_alphaT: float
    f_HbetaT: float
    f_fbetaT: float
    F_betaT: float
    F_rT: float
    unrounded: dict[str, float]

    def as_dict(self) -> dict[str, float]:
        """Rounded values by name [µm] (without ``grade`` and ``unrounded``)."""
        d = asdict(self)
        d.pop("unrounded")
        d.pop("grade")
        return d


@dataclass(frozen=True)
class RadialTolerances:
    """ISO 1328-2:1997 radial composite tolerances [µm] (rounded) and the formula values."""

    grade: int
    F_i2: float
    f_i2: float
    unrounded: dict[str, float]


def flank_tolerances(
    grade: int,
    module_mm: float,
    reference_diameter_mm: float,
    face_width_mm: float,
) -> FlankTolerances:
    """ISO 1328-1:2013 flank tolerances from the flank tolerance class.

    Parameters
    ----------
    grade : int
        Flank tolerance class ``A``, 1 (finest) … 11.
    module_mm : float
        Normal module ``m_n`` [mm], 0.5 … 70.
    reference_diameter_mm : float
        Reference diameter ``d`` [mm], 5 … 15 000.
    face_width_mm : float
        Face width ``b`` [mm], 4 … 1200.

    Returns
    -------
    FlankTolerances
        ``f_pT``, ``F_pT``, ``f_HαT``, ``f_fαT``, ``F_αT``, ``f_HβT``, ``f_fβT``, ``F_βT`` and
        the run-out ``F_rT = 0.9 F_pT`` [µm], rounded per §5.2.3.

    Notes
    -----
    Equations (5)–(12) of ISO 1328-1:2013 (module docstring). Totals (9), (12) and ``F_rT``
    are computed from unrounded values, then rounded.

    References
    ----------
    ISO 1328-1:2013, clause 5.2 and 5.3.

    Examples
    --------
    >>> t = flank_tolerances(6, 3.0, 120.0, 30.0)
    >>> t.f_pT, t.F_pT, t.F_alphaT
    (9.0, 29.0, 12.0)
    """
    a = _check_grade("grade", grade, 1, 11)
    mn = _check_range("module_mm", module_mm)
    d = _check_range("reference_diameter_mm", reference_diameter_mm)
    b = _check_range("face_width_mm", face_width_mm)
    s = _SQ2 ** (a - 5)
    raw = {
        "f_pT": (0.001 * d + 0.4 * mn + 5.0) * s,
        "F_pT": (0.002 * d + 0.55 * math.sqrt(d) + 0.7 * mn + 12.0) * s,
        "f_HalphaT": (0.4 * mn + 0.001 * d + 4.0) * s,
        "f_falphaT": (0.55 * mn + 5.0) * s,
        "f_HbetaT": (0.05 * math.sqrt(d) + 0.35 * math.sqrt(b) + 4.0) * s,
        "f_fbetaT": (0.07 * math.sqrt(d) + 0.45 * math.sqrt(b) + 4.0) * s,
    }
    raw["F_alphaT"] = math.hypot(raw["f_HalphaT"], raw["f_falphaT"])
    raw["F_betaT"] = math.hypot(raw["f_HbetaT"], raw["f_fbetaT"])
    raw["F_rT"] = 0.9 * raw["F_pT"]
    r = {k: iso1328_round(v) for k, v in raw.items()}
    return FlankTolerances(grade=a, unrounded=raw, **r)


def runout_tolerance(
    grade: int, module_mm: float, reference_diameter_mm: float, *, teeth: int | None = None
) -> float:
    """Run-out tolerance ``F_rT = 0.9 F_pT`` [µm], rounded (ISO 1328-1:2013; no face width needed).

    An eccentricity ``e`` of the gear's teeth about its axis gives a run-out of ``2e``, so the
    eccentricity tolerance a grade implies is ``F_rT / 2``. Parameters: ``grade`` (class
    1 … 11), ``module_mm`` [mm], ``reference_diameter_mm`` [mm]; ``teeth`` (optional): the tooth
    count, checked against the range of application ``5 ≤ z ≤ 1000``.

    Examples
    --------
    >>> runout_tolerance(6, 1.5, 60.0)   # F_pT 24.65 → F_rT 22.19
    22.0
    """
    a = _check_grade("grade", grade, 1, 11)
    mn = _check_range("module_mm", module_mm)
    d = _check_range("reference_diameter_mm", reference_diameter_mm)
    if teeth is not None:
        _check_range("teeth", teeth)
    f_pt = (0.002 * d + 0.55 * math.sqrt(d) + 0.7 * mn + 12.0) * _SQ2 ** (a - 5)
    return iso1328_round(0.9 * f_pt)


def radial_composite_tolerances(
    grade: int, module_mm: float, reference_diameter_mm: float
) -> RadialTolerances:
    """ISO 1328-2:1997 radial composite tolerances ``F_i″`` and ``f_i″`` [µm].

    Parameters
    ----------
    grade : int
        Radial composite accuracy grade ``Q``, 4 … 12.
    module_mm : float
        Normal module ``m_n`` [mm], 0.5 … 70 (ISO 1328-2:1997 itself covers 0.2 … 10).
    reference_diameter_mm : float
        Reference diameter ``d`` [mm].

    Notes
    -----
    ``F_i″ = (3.2 m_n + 1.01 √d + 6.4)(√2)^(Q−5)``, ``f_i″ = (2.96 m_n + 0.01 √d + 0.8)
    (√2)^(Q−5)``, rounded as ISO 1328-1 §5.2.3.

    References
    ----------
    ISO 1328-2:1997, clause 5 (grade 5 formulas and the √2 step).

    Examples
    --------
    >>> radial_composite_tolerances(5, 2.0, 40.0).F_i2
    19.0
    """
    q = _check_grade("grade", grade, 4, 12)
    mn = _check_range("module_mm", module_mm)
    d = _check_range("reference_diameter_mm", reference_diameter_mm)
    s = _SQ2 ** (q - 5)
    raw = {
        "F_i2": (3.2 * mn + 1.01 * math.sqrt(d) + 6.4) * s,
        "f_i2": (2.96 * mn + 0.01 * math.sqrt(d) + 0.8) * s,
    }
    return RadialTolerances(grade=q, unrounded=raw, **{k: iso1328_round(v) for k, v in raw.items()})


def grade_tolerances_um(
    grade: int, module_mm: float, reference_diameter_mm: float, face_width_mm: float
) -> dict[str, float]:
    """All tolerances a grade gives one gear [µm], keyed by the names case files use.

    Parameters: ``grade`` (flank class 1 … 11), ``module_mm`` [mm], ``reference_diameter_mm``
    [mm], ``face_width_mm`` [mm].

    ``single_pitch_um`` (f_pT), ``cumulative_pitch_um`` (F_pT), ``profile_total_um`` (F_αT),
    ``helix_total_um`` (F_βT), ``runout_um`` (F_rT), ``radial_composite_um`` (F_i″, same number
    as radial grade), ``radial_composite_tooth_um`` (f_i″).
    """
    f = flank_tolerances(grade, module_mm, reference_diameter_mm, face_width_mm)
    out = {
        "single_pitch_um": f.f_pT,
        "cumulative_pitch_um": f.F_pT,
        "profile_total_um": f.F_alphaT,
        "helix_total_um": f.F_betaT,
        "runout_um": f.F_rT,
    }
    if 4 <= grade <= 12:
        r = radial_composite_tolerances(grade, module_mm, reference_diameter_mm)
        out["radial_composite_um"] = r.F_i2
        out["radial_composite_tooth_um"] = r.f_i2
    return out
