"""Normal backlash of a spur pair and of a bevel pair from their tolerances (Jiang et al. 2024).

Units: lengths in mm, angles in rad.

Backlash conversions (Jiang et al. 2024, eq. 1), stated once here and used everywhere::

    jn = jt·cos α = 2·jr·sin α

``jt`` circumferential backlash (arc on the pitch circle through which one gear turns with the
other held), ``jn`` normal backlash (shortest distance between the non-working flanks), ``jr``
radial backlash (centre-distance change that closes the backlash), ``α`` pressure angle.

Spur pair (§2.1, eqs. 2–13), five sources, each as a linear term of ``jn``:

=================================  ==========================  ===============================
source                              term of ``jn``              distribution
=================================  ==========================  ===============================
tooth thickness ``ΔEs`` (each gear) ``−ΔEs·cos α``              normal in [Esi, Ess], σ = range/6
centre distance ``Δfa``             ``2Δfa·sin α``              normal in ±fa, σ = fa/3
geometric eccentricity (each gear)  ``2e·sin α·sin φ``          e Rayleigh σx = F″i/6, φ ~ U
bearing radial clearance ``Δb``     ``Δb·sin α``                normal in [bmin, bmax]
reducer output runout ``S``         ``2S·sin α·sin φb``         S Rayleigh σx = S/6, φb ~ U
=================================  ==========================  ===============================

Bevel pair (§3.1, eqs. 15–28): the pair is replaced by the equivalent cylindrical pair on the
back cone (Fig. 5). A displacement of a gear changes that pair's centre distance by its
component normal to the pitch-cone generator: ``cos δ`` of a radial displacement, ``sin δ`` of
an axial one (``√2/2`` for the paper's 45° cones). Six sources: tooth thickness ``−ΔEs cos α``;
shaft distance ``2Δfa sin α sin δ₂`` (our reading, ``√2Δfa sin α`` in the paper); shaft angle
``2ΔEΣ sin α`` (the deviation expressed as an arc at the mean cone distance, a radial backlash);
eccentricity ``2 e sin α cos δ sin φ`` with ``σx = √2 F″iΣ/6``; profile of the four mating
faces ``2ΔP sin α sin δ`` with ``ΔP`` normal in ±P/2; bearing clearance ``Δb sin α cos δ``.

References
----------
Jiang J., Zhong X., Lv L., Lai J., Jin D. (2024) Gear backlash modeling and tolerance simulation
of fully gear-coupled robot. J. Zhejiang Univ. (Eng. Sci.) 58(8), 1533–1542.
doi:10.3785/j.issn.1008-973X.2024.08.001
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from gearte.errors import ParameterError
from gearte.geometry.gears import (
    bevel_mean_diameter,
    bevel_pitch_cone_angles,
    centre_distance,
    gear_ratio,
    pitch_diameter,
)
from gearte.tolerance.distributions import Normal, RadialPhase, Rayleigh
from gearte.tolerance.stackup import Contributor, LinearStack, z_for_confidence

__all__ = [
    "normal_from_circumferential",
    "circumferential_from_normal",
    "normal_from_radial",
    "radial_from_normal",
    "spur_normal_backlash",
    "bevel_normal_backlash",
    "SpurGear",
    "SpurPair",
    "BevelGear",
    "BevelPair",
    "BacklashSummary",
    "summarise_backlash",
    "SPUR_SOURCES",
    "BEVEL_SOURCES",
]

#: Names of the sources (contributors) of the two stacks, as in Tables 3 and 7.
SPUR_SOURCES: tuple[str, ...] = (
    "driving gear tooth thickness",
    "driven gear tooth thickness",
    "centre distance",
    "driven gear eccentricity",
    "bearing radial clearance",
    "driving gear eccentricity",
    "reducer output runout",
)
BEVEL_SOURCES: tuple[str, ...] = (
    "driving gear tooth thickness",
    "driven gear tooth thickness",
    "driving gear eccentricity",
    "driven gear eccentricity",
    "driving gear face profile",
    "driven gear face profile",
    "housing end face profile",
    "end cover face profile",
    "shaft angle",
    "shaft distance",
    "driving bearing radial clearance",
    "driven bearing radial clearance",
)


# ------------------------------------------------------------------------------------------------
# conversions (eq. 1)
# ------------------------------------------------------------------------------------------------
def normal_from_circumferential(jt: ArrayLike, alpha: ArrayLike) -> np.ndarray | float:
    """Normal backlash ``jn = jt·cos α`` [mm] from circumferential ``jt`` [mm] (eq. 1).

    References
    ----------
    Jiang J. et al. (2024) J. Zhejiang Univ. (Eng. Sci.) 58(8), 1533–1542.
    doi:10.3785/j.issn.1008-973X.2024.08.001
    """
    return np.multiply(jt, np.cos(alpha))


def circumferential_from_normal(jn: ArrayLike, alpha: ArrayLike) -> np.ndarray | float:
    """Circumferential backlash ``jt = jn / cos α`` [mm] (eq. 1).

    References
    ----------
    Jiang J. et al. (2024) J. Zhejiang Univ. (Eng. Sci.) 58(8), 1533–1542.
    doi:10.3785/j.issn.1008-973X.2024.08.001
    """
    return np.divide(jn, np.cos(alpha))


def normal_from_radial(jr: ArrayLike, alpha: ArrayLike) -> np.ndarray | float:
    """Normal backlash ``jn = 2·jr·sin α`` [mm] from radial ``jr`` [mm] (eq. 1).

    References
    ----------
    Jiang J. et al. (2024) J. Zhejiang Univ. (Eng. Sci.) 58(8), 1533–1542.
    doi:10.3785/j.issn.1008-973X.2024.08.001
    """
    return np.multiply(2.0 * np.sin(alpha), jr)


def radial_from_normal(jn: ArrayLike, alpha: ArrayLike) -> np.ndarray | float:
    """Radial backlash ``jr = jn / (2 sin α)`` [mm] (eq. 1).

    References
    ----------
    Jiang J. et al. (2024) J. Zhejiang Univ. (Eng. Sci.) 58(8), 1533–1542.
    doi:10.3785/j.issn.1008-973X.2024.08.001
    """
    return np.divide(jn, 2.0 * np.sin(alpha))


# ------------------------------------------------------------------------------------------------
# sample-level models (plain, readable; the stacks below are their linear form)
# ------------------------------------------------------------------------------------------------
def spur_normal_backlash(
    dEs1: ArrayLike,  # noqa: N803 - paper symbols
    dEs2: ArrayLike,  # noqa: N803
    dfa: ArrayLike,
    e1: ArrayLike,
    phi1: ArrayLike,
    e2: ArrayLike,
    phi2: ArrayLike,
    db: ArrayLike,
    S: ArrayLike,  # noqa: N803
    phib: ArrayLike,
    alpha: ArrayLike,
) -> np.ndarray:
    """Normal backlash [mm] of one spur-pair assembly from its individual errors.

    Parameters
    ----------
    dEs1, dEs2 : array_like
        Tooth-thickness deviations ``ΔEs`` of driving and driven gear [mm].
    dfa : array_like
        Centre-distance deviation ``Δfa`` [mm].
    e1, phi1, e2, phi2 : array_like
        Geometric eccentricities [mm] and their phase angles [rad].
    db : array_like
        Bearing radial clearance ``Δb`` [mm].
    S, phib : array_like
        Runout of the reducer output shaft [mm] and its phase [rad].
    alpha : array_like
        Pressure angle [rad].

    Notes
    -----
    Jiang et al. (2024) §2.1, terms of eqs. (2)–(11) summed as in eqs. (12)–(13)::

        jn = −(ΔEs1 + ΔEs2) cos α + 2Δfa sin α + 2(e1 sin φ1 + e2 sin φ2) sin α
             + Δb sin α + 2 S sin φb sin α

    References
    ----------
    Jiang J. et al. (2024) J. Zhejiang Univ. (Eng. Sci.) 58(8), 1533–1542.
    doi:10.3785/j.issn.1008-973X.2024.08.001
    """
    sa, ca = np.sin(alpha), np.cos(alpha)
    return (
        -(np.add(dEs1, dEs2)) * ca
        + 2.0 * np.asarray(dfa) * sa
        + 2.0 * (np.multiply(e1, np.sin(phi1)) + np.multiply(e2, np.sin(phi2))) * sa
        + np.asarray(db) * sa
        + 2.0 * np.multiply(S, np.sin(phib)) * sa
    )


def bevel_normal_backlash(
    dEs1: ArrayLike,  # noqa: N803
    dEs2: ArrayLike,  # noqa: N803
    dfa: ArrayLike,
    dEsigma: ArrayLike,  # noqa: N803
    e1: ArrayLike,
    phi1: ArrayLike,
    e2: ArrayLike,
    phi2: ArrayLike,
    dP: ArrayLike,  # noqa: N803
    db1: ArrayLike,
    db2: ArrayLike,
    alpha: ArrayLike,
    delta1: ArrayLike = np.pi / 4,
    delta2: ArrayLike = np.pi / 4,
) -> np.ndarray:
    """Normal backlash [mm] of one bevel-pair assembly (equivalent cylindrical pair).

    Parameters
    ----------
    dEs1, dEs2 : tooth-thickness deviations [mm]
    dfa : shaft-distance deviation [mm]
    dEsigma : shaft-angle deviation as an arc at the mean cone distance [mm]
    e1, phi1, e2, phi2 : eccentricities [mm] and phases [rad]
    dP : array_like, shape (4, ...)
        Profile deviations of driving-gear face, driven-gear face, housing end face (carries
        the driving gear) and cover face (carries the driven gear) [mm].
    db1, db2 : bearing radial clearances of the driving and driven gear [mm]
    alpha : pressure angle [rad]
    delta1, delta2 : pitch-cone angles [rad] (45° for the paper's pair)

    Notes
    -----
    Jiang et al. (2024) §3.1, eqs. (15)–(28), for general cone angles (see module docstring)::

        jn = −(ΔEs1 + ΔEs2) cos α + 2Δfa sin α sin δ2 + 2ΔEΣ sin α
             + 2 sin α (e1 cos δ1 sin φ1 + e2 cos δ2 sin φ2)
             + 2 sin α (ΔP1 sin δ1 + ΔP2 sin δ2 + ΔP3 sin δ1 + ΔP4 sin δ2)
             + sin α (Δb1 cos δ1 + Δb2 cos δ2)

    References
    ----------
    Jiang J. et al. (2024) J. Zhejiang Univ. (Eng. Sci.) 58(8), 1533–1542.
    doi:10.3785/j.issn.1008-973X.2024.08.001
    """
    sa, ca = np.sin(alpha), np.cos(alpha)
    s1, s2, c1, c2 = np.sin(delta1), np.sin(delta2), np.cos(delta1), np.cos(delta2)
    dP = np.asarray(dP, dtype=float)
    return (
        -(np.add(dEs1, dEs2)) * ca
        + 2.0 * np.asarray(dfa) * sa * s2
        + 2.0 * np.asarray(dEsigma) * sa
        + 2.0 * sa * (np.multiply(e1, np.sin(phi1)) * c1 + np.multiply(e2, np.sin(phi2)) * c2)
        + 2.0 * sa * ((dP[0] + dP[2]) * s1 + (dP[1] + dP[3]) * s2)
        + sa * (np.asarray(db1) * c1 + np.asarray(db2) * c2)
    )


# ------------------------------------------------------------------------------------------------
# objects holding a pair's data → linear stacks
# ------------------------------------------------------------------------------------------------
def _nonneg(field: str, v: float) -> float:
    if not (math.isfinite(v) and v >= 0):
        raise ParameterError(field, v, "must be a finite tolerance >= 0")
    return float(v)


def _pos(field: str, v: float) -> float:
    if not (math.isfinite(v) and v > 0):
        raise ParameterError(field, v, "must be finite and > 0")
    return float(v)


def _limits(field: str, lower: float, upper: float, *, nonneg: bool = False) -> None:
    if upper < lower:
        raise ParameterError(field, (lower, upper), "inverted limits: upper must be >= lower")
    if nonneg and lower < 0:
        raise ParameterError(field, (lower, upper), "a clearance cannot be negative (>= 0)")


def _validate_gear(gear: SpurGear | BevelGear, prefix: str) -> None:
    """The checks every gear of a pair shares: its teeth and its tooth-thickness limits."""
    if gear.teeth < 5:
        raise ParameterError(f"{prefix}.teeth", gear.teeth, "must be >= 5")
    _limits(f"{prefix}.thickness", gear.thickness_lower, gear.thickness_upper)


def _validate_pair(pair: SpurPair | BevelPair) -> None:
    """The checks every pair shares: both gears, the module and the pressure angle."""
    pair.driving.validate("driving")
    pair.driven.validate("driven")
    _pos("module", pair.module)
    if not 0 < pair.pressure_angle < math.pi / 2:
        raise ParameterError("pressure_angle", pair.pressure_angle, "must be in (0, π/2) rad")


def _thickness_contributor(
    gear: SpurGear | BevelGear, prefix: str, cos_alpha: float, group: str | None = None
) -> Contributor:
    """The tooth-thickness contributor of ``gear`` (sensitivity −cos α, eq. 2 / eq. 15)."""
    return Contributor(
        f"{prefix} gear tooth thickness",
        Normal.from_limits(gear.thickness_lower, gear.thickness_upper, field=f"{prefix}.thickness"),
        -cos_alpha,
        group,
    )


@dataclass(frozen=True)
class SpurGear:
    """One spur gear of a pair.

    Parameters
    ----------
    teeth : int
        Number of teeth ``z``.
    thickness_upper : float
        Upper tooth-thickness deviation ``Ess`` [mm] (usually negative).
    thickness_lower : float
        Lower tooth-thickness deviation ``Esi`` [mm], ``≤ Ess``.
    radial_composite_tol : float
        Radial composite tolerance ``F″i`` [mm], ``> 0``; eccentricity scale ``σx = F″i/6``.
    """

    teeth: int
    thickness_upper: float
    thickness_lower: float
    radial_composite_tol: float

    def validate(self, prefix: str) -> None:
        _validate_gear(self, prefix)
        _pos(f"{prefix}.radial_composite_tol", self.radial_composite_tol)


@dataclass(frozen=True)
class SpurPair:
    """A spur pair with its mounting (Jiang et al. 2024, Tables 1–2).

    Parameters
    ----------
    driving, driven : SpurGear
    module : float
        Module ``m`` [mm].
    pressure_angle : float
        ``α`` [rad].
    centre_distance_tol : float
        Centre-distance limit deviation ``fa`` [mm] (``±fa``).
    bearing_clearance : tuple of float
        ``(bmin, bmax)`` radial clearance of the bearing [mm].
    runout : float
        Runout ``S`` of the reducer output shaft carrying the driving gear [mm].
    min_backlash_limit : float
        Minimum limit normal backlash ``jn min`` [mm] the pair must keep.
    """

    driving: SpurGear
    driven: SpurGear
    module: float
    pressure_angle: float
    centre_distance_tol: float
    bearing_clearance: tuple[float, float]
    runout: float
    min_backlash_limit: float = 0.0

    def __post_init__(self) -> None:
        _validate_pair(self)
        _nonneg("centre_distance_tol", self.centre_distance_tol)
        _limits("bearing_clearance", *self.bearing_clearance, nonneg=True)
        _pos("runout", self.runout)
        _nonneg("min_backlash_limit", self.min_backlash_limit)

    @property
    def ratio(self) -> float:
        return float(gear_ratio(self.driving.teeth, self.driven.teeth))

    @property
    def centre_distance(self) -> float:
        """Nominal centre distance [mm]."""
        return float(centre_distance(self.driving.teeth, self.driven.teeth, self.module))

    @property
    def output_diameter(self) -> float:
        """Pitch diameter of the driven gear [mm], the ``d`` of eq. (14)."""
        return float(pitch_diameter(self.driven.teeth, self.module))

    def backlash_stack(self) -> LinearStack:
        """Normal backlash [mm] as a linear stack of the five sources (eqs. 2–13).

        Contributor names follow Table 3.
        """
        a = self.pressure_angle
        sa, ca = math.sin(a), math.cos(a)
        g1, g2 = self.driving, self.driven
        cs = [
            _thickness_contributor(g1, "driving", ca, "tooth thickness"),
            _thickness_contributor(g2, "driven", ca, "tooth thickness"),
            Contributor(
                "centre distance",
                Normal.from_tolerance(self.centre_distance_tol, field="centre_distance_tol"),
                2 * sa,
            ),
            Contributor(
                "driven gear eccentricity",
                RadialPhase(
                    Rayleigh.from_tolerance(
                        g2.radial_composite_tol, field="driven.radial_composite_tol"
                    )
                ),
                2 * sa,
                "eccentricity",
            ),
            Contributor(
                "bearing radial clearance",
                Normal.from_limits(*self.bearing_clearance, field="bearing_clearance"),
                sa,
            ),
            Contributor(
                "driving gear eccentricity",
                RadialPhase(
                    Rayleigh.from_tolerance(
                        g1.radial_composite_tol, field="driving.radial_composite_tol"
                    )
                ),
                2 * sa,
                "eccentricity",
            ),
            Contributor(
                "reducer output runout",
                RadialPhase(Rayleigh.from_tolerance(self.runout, field="runout")),
                2 * sa,
            ),
        ]
        return LinearStack(cs, 0.0, name="spur normal backlash", unit="mm")


@dataclass(frozen=True)
class BevelGear:
    """One bevel gear of a pair with its seat.

    Parameters
    ----------
    teeth : int
    thickness_upper, thickness_lower : float
        Tooth-thickness deviations ``Ess ≥ Esi`` [mm].
    bearing_clearance : tuple of float
        ``(bmin, bmax)`` radial clearance of the bearing carrying the gear [mm].
    face_profile_tol : float
        Profile tolerance ``P`` of the gear's locating face [mm] (zone ``±P/2``).
    seat_profile_tol : float
        Profile tolerance of the housing face the gear is located against [mm] (the paper's
        housing end face for the driving gear, horizontal end cover for the driven gear).
    """

    teeth: int
    thickness_upper: float
    thickness_lower: float
    bearing_clearance: tuple[float, float]
    face_profile_tol: float
    seat_profile_tol: float

    def validate(self, prefix: str) -> None:
        _validate_gear(self, prefix)
        _limits(f"{prefix}.bearing_clearance", *self.bearing_clearance, nonneg=True)
        _nonneg(f"{prefix}.face_profile_tol", self.face_profile_tol)
        _nonneg(f"{prefix}.seat_profile_tol", self.seat_profile_tol)


@dataclass(frozen=True)
class BevelPair:
    """A straight bevel pair with its mounting (Jiang et al. 2024, Tables 5–6).

    Parameters
    ----------
    driving, driven : BevelGear
    module : float
        Outer transverse module [mm].
    pressure_angle : float
        ``α`` [rad].
    face_width : float
        ``B`` [mm].
    shaft_distance_tol : float
        Shaft-distance limit deviation ``fa`` [mm] (``±fa``).
    shaft_angle_tol : float
        Shaft-angle limit deviation ``EΣ`` as an arc at the mean cone distance [mm] (``±EΣ``).
    composite_tol : float
        Shaft-angle composite deviation ``F″iΣ`` [mm]; eccentricity scale ``σx = √2 F″iΣ/6``.
    shaft_angle : float
        ``Σ`` [rad], default π/2.
    min_backlash_limit : float
        ``j″n min`` [mm].
    """

    driving: BevelGear
    driven: BevelGear
    module: float
    pressure_angle: float
    face_width: float
    shaft_distance_tol: float
    shaft_angle_tol: float
    composite_tol: float
    shaft_angle: float = math.pi / 2
    min_backlash_limit: float = 0.0

    def __post_init__(self) -> None:
        _validate_pair(self)
        _pos("face_width", self.face_width)
        _nonneg("shaft_distance_tol", self.shaft_distance_tol)
        _nonneg("shaft_angle_tol", self.shaft_angle_tol)
        _pos("composite_tol", self.composite_tol)
        if not 0 < self.shaft_angle < math.pi:
            raise ParameterError("shaft_angle", self.shaft_angle, "must be in (0, π) rad")
        _nonneg("min_backlash_limit", self.min_backlash_limit)
        d2 = float(pitch_diameter(self.driven.teeth, self.module))
        if self.face_width * math.sin(self.cone_angles[1]) >= d2:
            raise ParameterError("face_width", self.face_width, "too wide for the cone")

    @property
    def ratio(self) -> float:
        return float(gear_ratio(self.driving.teeth, self.driven.teeth))

    @property
    def cone_angles(self) -> tuple[float, float]:
        """Pitch-cone angles ``(δ₁, δ₂)`` [rad]."""
        d1, d2 = bevel_pitch_cone_angles(self.driving.teeth, self.driven.teeth, self.shaft_angle)
        return float(d1), float(d2)

    @property
    def output_diameter(self) -> float:
        """Mean diameter ``dm`` of the driven gear [mm], the ``dm`` of eq. (29)."""
        d2 = float(pitch_diameter(self.driven.teeth, self.module))
        return float(bevel_mean_diameter(d2, self.face_width, self.cone_angles[1]))

    def backlash_stack(self) -> LinearStack:
        """Normal backlash [mm] as a linear stack of the six sources (eqs. 15–28).

        Contributor names and groups follow Table 7.
        """
        a = self.pressure_angle
        sa, ca = math.sin(a), math.cos(a)
        d1, d2 = self.cone_angles
        g1, g2 = self.driving, self.driven
        ecc = Rayleigh.from_tolerance(
            self.composite_tol, factor=math.sqrt(2.0), field="composite_tol"
        )
        cs = [
            _thickness_contributor(g1, "driving", ca),
            _thickness_contributor(g2, "driven", ca),
            Contributor("driving gear eccentricity", RadialPhase(ecc), 2 * sa * math.cos(d1)),
            Contributor("driven gear eccentricity", RadialPhase(ecc), 2 * sa * math.cos(d2)),
        ]
        for name, tol, d, field in (
            ("driving gear face profile", g1.face_profile_tol, d1, "driving.face_profile_tol"),
            ("driven gear face profile", g2.face_profile_tol, d2, "driven.face_profile_tol"),
            ("housing end face profile", g1.seat_profile_tol, d1, "driving.seat_profile_tol"),
            ("end cover face profile", g2.seat_profile_tol, d2, "driven.seat_profile_tol"),
        ):
            cs.append(
                Contributor(
                    name,
                    Normal.from_tolerance(0.5 * tol, field=field),
                    2 * sa * math.sin(d),
                    "face profile",
                )
            )
        cs += [
            Contributor(
                "shaft angle",
                Normal.from_tolerance(self.shaft_angle_tol, field="shaft_angle_tol"),
                2 * sa,
            ),
            Contributor(
                "shaft distance",
                Normal.from_tolerance(self.shaft_distance_tol, field="shaft_distance_tol"),
                2 * sa * math.sin(d2),
            ),
            Contributor(
                "driving bearing radial clearance",
                Normal.from_limits(*g1.bearing_clearance, field="driving.bearing_clearance"),
                sa * math.cos(d1),
                "bearing radial clearance",
            ),
            Contributor(
                "driven bearing radial clearance",
                Normal.from_limits(*g2.bearing_clearance, field="driven.bearing_clearance"),
                sa * math.cos(d2),
                "bearing radial clearance",
            ),
        ]
        return LinearStack(cs, 0.0, name="bevel normal backlash", unit="mm")

    def shim_sensitivity(self) -> float:
        """Normal-backlash change per unit shim thickness under *both* gears [mm/mm].

        ``2 sin α (sin δ₁ + sin δ₂)`` — ``2√2 sin α`` for 45° cones (eq. 32).
        """
        d1, d2 = self.cone_angles
        return 2.0 * math.sin(self.pressure_angle) * (math.sin(d1) + math.sin(d2))


@dataclass(frozen=True)
class BacklashSummary:
    """Analytic statistics of a pair's normal backlash [mm]."""

    mean: float
    sd: float
    min: float
    max: float
    confidence: float
    min_limit: float

    @property
    def meets_min_limit(self) -> bool:
        """Whether the minimum (at the confidence level) stays above the required minimum."""
        return self.min >= self.min_limit


def summarise_backlash(
    stack: LinearStack, *, confidence: float = 0.9973, min_limit: float = 0.0
) -> BacklashSummary:
    """Mean, sd and the ``mean ∓ z·sd`` range [mm] of a backlash ``stack``.

    ``confidence`` [-] sets z (0.9973 ↔ the paper's 6σ); ``min_limit`` [mm] the pair's minimum
    limit normal backlash, compared with the range's lower end.
    """
    z = z_for_confidence(confidence)
    m, s = stack.mean, stack.sd
    return BacklashSummary(m, s, m - z * s, m + z * s, confidence, min_limit)
