"""Study kind ``rv_reducer``: every analysis of a whole RV reducer from one description.

One case schema for the whole RV reducer (issue 11): the quasi-static load sharing with measured
errors, total TE, catalogue quantities and compensation (Han et al. 2023; Hu et al. 2020 sections
3 and 5), the cycloid stage's geometric TE with Hu's nine factors, sensitivities, loaded tooth
contact and compensation (Hu et al. 2020 sections 2-4, through the same
:class:`~gearte.geometry.cycloid.CycloidStage` the ``cycloid_stage`` kind builds), and the
dynamics (Li et al. 2023: loaded contact, modes, dynamic TE and its spectrum, speed sweeps, error
batches). Every analysis reads the same :class:`~gearte.geometry.rv.RVReducer` and the same
errors; an analysis whose input the case lacks is an error naming the key.

Case file layout (units in the keys)::

    [case]  kind = "rv_reducer"
    [reducer]                  rated_torque_Nm (catalogue, backlash), contact_law,
                               material = "steel" | density_kg_per_m3 (derived masses)
    [reducer.first_stage]      sun_teeth, planet_teeth, planets, module_mm, pressure_angle_deg,
                               mesh_stiffness_N_per_mm and/or face_width_mm,
                               sun_support_stiffness_N_per_mm; backlash: DIN 3967 classes
                               sun/planet_tooth_thickness_allowance + centre_distance_allowance,
                               or backlash_um (j_t per mesh)
    [reducer.cranks]           count, circle_radius_mm, eccentricity_mm, shaft_diameter_mm,
                               shaft_length_mm, cam_bearing = {stiffness_N_per_mm | rollers,
                               roller_length_mm, reference_load_N, contact_angle_deg, rows;
                               radial_clearance_um}, carrier_bearing = {...}; stiffness chain
                               (docs/rv-stiffness-chain.md): bearing_span_mm |
                               bending_stiffness_N_per_mm, torsion_length_mm |
                               torsional_stiffness_Nm_per_rad
    [reducer.discs]            count, face_width_mm, equidistant_modification_mm,
                               shift_modification_mm, youngs_modulus_MPa, poisson_ratio,
                               crank_bore_diameter_mm, centre_bore_diameter_mm,
                               equidistant_modification_errors_um,
                               shift_modification_errors_um (one per disc)
    [reducer.pins]             count, pin_radius_mm, circle_radius_mm, radius_errors_um,
                               radial_position_errors_um, tangential_position_errors_um (per pin);
                               seat_length_mm | seat_stiffness_N_per_mm, support_span_mm |
                               bending_stiffness_N_per_mm
    [reducer.supports]         carrier_radial_stiffness_N_per_mm | main_bearing = {...},
                               main_bearing_clearance_um, carrier_outer_diameter_mm,
                               carrier_length_mm, output_flange_torsional_stiffness_Nm_per_rad
    [[reducer.errors]]         part, crank, disc, value_um, angle_deg (one per error:
                               sun_eccentricity, sun_assembly, planet_eccentricity, cam,
                               disc_crank_bore,
                               disc_radial_runout, disc_cumulative_pitch, carrier_crank_bore,
                               output_assembly)
    [reducer.cycloid_errors]   the nine factors of Hu 2020 Table 2: {mean_um, tolerance_um}
    [reducer.dynamics]         masses/inertias (derived from geometry when left out), input and
                               crank torsional stiffness, crank bending stiffness, damping ratio
    [operation]                input_speed_rpm, output_torque_Nm (dynamic analyses)
    [analyses.load_sharing]    torque_Nm, positions, compare_without_errors
    [analyses.transmission_error]  torque_Nm, positions, zero_load_fraction
    [analyses.catalogue]       position_deg, torque_sweep, steps_per_segment, lost_motion_fraction,
                               first_stage_backlash = "additive" | "ignored"
    [analyses.compensation]    torque_Nm, objective, min_backlash_arcmin, positions, bounds_um
    [analyses.geometric_te]    reference_factor
    [analyses.tooth_contact]   torque_Nm, disc_share, mesh_positions, start_force_N,
                               clearance_model
    [analyses.cycloid_compensation]  target_te_change_arcmin, factors, rule
    [analyses.contact]         positions, load_sweep_Nm
    [analyses.modal]           speed_min_rpm, speed_max_rpm, resonance_margin
    [analyses.dte]             duration_s, settle_s, method, step_fraction, record_dt_s,
                               record_points
    [analyses.speed_sweep]     speed_min_rpm, speed_max_rpm, count, duration_s, settle_s
    [analyses.batch]           samples, duration_s, settle_s, seed, chunk_size, tolerance_scale
"""

from __future__ import annotations

from typing import Any, Literal, get_args

import numpy as np
from pydantic import Field, field_validator, model_validator

from gearte.errors import ConvergenceError, ParameterError
from gearte.geometry.planetary import SunPlanets
from gearte.geometry.rv import (
    ERROR_PARTS,
    Cranks,
    Discs,
    ErrorEntry,
    FirstStage,
    ManufacturingErrors,
    PinRing,
    RVReducer,
    Supports,
)
from gearte.io.schema import CaseBase, StrictModel, floored
from gearte.models.rv_stiffness import iso6336_mesh_stiffness, roller_bearing_radial_stiffness
from gearte.results import AnalysisResult, StudyResult
from gearte.studies import _rv_dynamics as dyn
from gearte.studies._yield import YieldSection
from gearte.studies.cycloid_stage import CompensationOptions as CycloidCompensationOptions
from gearte.studies.cycloid_stage import Errors as CycloidErrors
from gearte.studies.cycloid_stage import GeometricTEOptions
from gearte.units import (
    NM_PER_RAD_TO_NMM_PER_RAD,
    Nm_to_Nmm,
    Nmm_per_rad_to_Nm_per_arcmin,
    Nmm_to_Nm,
    arcmin_to_rad,
    deg_to_rad,
    mm_to_um,
    rad_to_arcmin,
    rad_to_arcsec,
    rad_to_deg,
    um_to_mm,
)

KIND = "rv_reducer"
REFERENCES = ["han2023", "hu2020", "li2023"]
FIGURES = "gearte.plotting.rv_reducer"

__all__ = [
    "KIND",
    "REFERENCES",
    "FIGURES",
    "Case",
    "run",
    "build_reducer",
    "reducer_section",
    "build_stage_case",
    "load_dynamic_model",
]

#: Densities of the materials a case may name [kg/m³] (physical constants).
MATERIAL_DENSITY_KG_PER_M3 = {"steel": 7850.0}


# ------------------------------------------------------------------------------------------
# Schema
# ------------------------------------------------------------------------------------------
class Bearing(StrictModel):
    """A roller bearing: a given radial stiffness, or Palmgren data to derive it."""

    stiffness_N_per_mm: float | None = floored(
        "linear_stiffness", None, le=1e9, description="[N/mm]"
    )
    rollers: int | None = Field(default=None, ge=3, le=200, description="number of rollers")
    roller_length_mm: float | None = floored("part_length", None, le=200, description="[mm]")
    reference_load_N: float | None = floored(
        "bearing_reference_load", None, le=1e7, description="load of the secant stiffness [N]"
    )
    radial_clearance_um: float = Field(default=0.0, ge=0, le=200, description="[um]")
    contact_angle_deg: float = Field(
        default=0.0, ge=0, lt=90, description="contact angle of the rollers (0: radial) [deg]"
    )
    rows: int = Field(default=1, ge=1, le=8, description="identical rows sharing the load [-]")
    at_rated_torque: bool = Field(
        default=False,
        description="linearise at the bearing's largest load at rated torque (found by a fixed "
        "point of the load sharing) instead of at reference_load_N",
    )

    @model_validator(mode="after")
    def _one_way(self):
        palm = (self.rollers, self.roller_length_mm, self.reference_load_N)
        if self.stiffness_N_per_mm is not None:
            if any(v is not None for v in palm) or self.at_rated_torque:
                raise ValueError("give either stiffness_N_per_mm or the Palmgren data, not both")
        elif self.rollers is None or self.roller_length_mm is None:
            raise ValueError(
                "give stiffness_N_per_mm, or rollers, roller_length_mm and reference_load_N (or "
                "at_rated_torque = true)"
            )
        elif (self.reference_load_N is None) == (not self.at_rated_torque):
            raise ValueError("give reference_load_N or at_rated_torque = true (one)")
        return self

    def stiffness(self, load: float | None = None) -> float:
        """Radial stiffness [N/mm]: the given one, or Palmgren/Stribeck at ``load`` [N]
        (default ``reference_load_N``)."""
        if self.stiffness_N_per_mm is not None:
            return self.stiffness_N_per_mm
        n, length = self.rollers, self.roller_length_mm
        load = self.reference_load_N if load is None else load
        if n is None or length is None or load is None:  # refused by _one_way
            raise ParameterError("stiffness_N_per_mm", None, "no stiffness and no Palmgren data")
        return float(
            roller_bearing_radial_stiffness(
                n, length, load, deg_to_rad(self.contact_angle_deg), self.rows
            )
        )

    def source(self) -> str:
        """How the stiffness was obtained (for the results)."""
        if self.stiffness_N_per_mm is not None:
            return "given"
        at = (
            "its largest load at rated torque"
            if self.at_rated_torque
            else f"{self.reference_load_N} N"
        )
        return (
            f"derived: Palmgren/Stribeck from {self.rollers} rollers x {self.rows} row(s), "
            f"l = {self.roller_length_mm} mm, alpha = {self.contact_angle_deg} deg, secant at {at}"
        )


class FirstStageSection(StrictModel):
    """Involute first stage: sun and planets (an RV first stage has no ring)."""

    sun_teeth: int = Field(ge=6, le=400, description="Teeth of the sun (input) gear [-].")
    planet_teeth: int = Field(ge=6, le=400, description="Teeth of each planet [-].")
    planets: int = Field(ge=2, le=6, description="must equal cranks.count")
    module_mm: float = Field(gt=0, le=20, description="Module m of the first stage [mm].")
    pressure_angle_deg: float = Field(
        gt=0, lt=45, description="Pressure angle α of the first stage [deg]."
    )
    mesh_stiffness_N_per_mm: float | None = floored(
        "linear_stiffness", None, le=1e9, description="mean mesh stiffness; default ISO 6336 from b"
    )
    face_width_mm: float | None = floored(
        "part_length",
        None,
        le=200,
        description="ISO 6336 mesh stiffness c_gamma = 20 N/(mm um) when no mesh stiffness is "
        "given; sun and planet masses",
    )
    sun_support_stiffness_N_per_mm: float = floored(
        "linear_stiffness", le=1e9, description="Radial stiffness of the sun's support [N/mm]."
    )
    sun_tooth_thickness_allowance: str | None = Field(
        default=None,
        description="DIN 3967 tooth-thickness class of the sun, e.g. 'cd25' (with "
        "planet_tooth_thickness_allowance and centre_distance_allowance): the first stage's "
        "backlash limits are reported (analysis first_stage_backlash), its class midpoint is "
        "added to the catalogue test's lost motion and backlash and its tolerances drawn in "
        "the yield (first_stage_backlash = 'additive'); the reducer model's sun–planet mesh "
        "itself has no clearance",
    )
    planet_tooth_thickness_allowance: str | None = Field(
        default=None, description="DIN 3967 tooth-thickness class of the planets, e.g. 'cd25'"
    )
    centre_distance_allowance: str | None = Field(
        default=None,
        description="ISO 286 field js5 … js11 of the sun–planet centre distance m(z1 + z2)/2 "
        "(DIN 3964), e.g. 'js6'",
    )

    backlash_um: float | list[float] | None = Field(
        default=None,
        description="Circumferential backlash j_t of the sun–planet meshes at the pitch circle "
        "[um], measured or specified: one value for every mesh or one per planet (instead of "
        "the classes); added at the output by the catalogue test and the yield",
    )

    @field_validator("backlash_um")
    @classmethod
    def _backlash(cls, v: float | list[float] | None) -> float | list[float] | None:
        vals = [v] if isinstance(v, int | float) else (v or [])
        if any(not (-1000.0 <= float(x) <= 5000.0) for x in vals):
            raise ValueError(f"backlash_um {v} must be within [-1000, 5000] um")
        return v

    @field_validator("sun_tooth_thickness_allowance", "planet_tooth_thickness_allowance")
    @classmethod
    def _thickness_class(cls, v: str | None) -> str | None:
        from gearte.studies.gear_pair import thickness_class_key

        return thickness_class_key(v)

    @field_validator("centre_distance_allowance")
    @classmethod
    def _js_field(cls, v: str | None) -> str | None:
        from gearte.studies.gear_pair import js_field_key

        return js_field_key(v)

    @model_validator(mode="after")
    def _mesh(self):
        if self.mesh_stiffness_N_per_mm is None and self.face_width_mm is None:
            raise ValueError("give mesh_stiffness_N_per_mm or face_width_mm (or both)")
        keys = (
            "sun_tooth_thickness_allowance",
            "planet_tooth_thickness_allowance",
            "centre_distance_allowance",
        )
        if 0 < sum(getattr(self, k) is not None for k in keys) < 3:
            raise ValueError(f"{', '.join(keys)} go together (the first stage's backlash)")
        if self.backlash_um is not None:
            if self.sun_tooth_thickness_allowance is not None:
                raise ValueError("give backlash_um or the tooth-thickness classes, not both")
            if isinstance(self.backlash_um, list) and len(self.backlash_um) != self.planets:
                raise ValueError(
                    f"backlash_um needs one value or one per planet ({self.planets}), got "
                    f"{len(self.backlash_um)}"
                )
        if self.sun_tooth_thickness_allowance is not None:
            first_stage_backlash(self)  # a diameter outside the tables: an error naming the key
        return self


def first_stage_backlash(fs: FirstStageSection) -> dict[str, float]:
    """Backlash limits of the sun–planet mesh from the DIN 3967 classes and the js field.

    Parameters
    ----------
    fs : FirstStageSection
        The first stage with ``sun_tooth_thickness_allowance``,
        ``planet_tooth_thickness_allowance`` and ``centre_distance_allowance``.

    Returns
    -------
    dict
        ``j_n``/``j_t`` minimum and maximum [µm] (``gearte.tolerance.din3967``), the allowances
        [µm] and the sun's free angle ``j_t / r_sun`` [rad].
    """
    from gearte.tolerance.din3967 import pair_backlash_limits, tooth_thickness_allowances
    from gearte.tolerance.iso286 import js_allowances_um

    f = "reducer.first_stage."
    m = fs.module_mm
    sun = tooth_thickness_allowances(
        fs.sun_tooth_thickness_allowance,  # type: ignore[arg-type]
        m * fs.sun_teeth,
        field=f + "sun_tooth_thickness_allowance",
    )
    planet = tooth_thickness_allowances(
        fs.planet_tooth_thickness_allowance,  # type: ignore[arg-type]
        m * fs.planet_teeth,
        field=f + "planet_tooth_thickness_allowance",
    )
    a_e, a_i = js_allowances_um(
        fs.centre_distance_allowance,  # type: ignore[arg-type]
        0.5 * m * (fs.sun_teeth + fs.planet_teeth),
        field=f + "centre_distance_allowance",
    )
    u1, l1, u2, l2, e, i = (
        float(um_to_mm(v))
        for v in (sun.upper_um, sun.lower_um, planet.upper_um, planet.lower_um, a_e, a_i)
    )
    b = pair_backlash_limits(u1, l1, u2, l2, e, i, float(deg_to_rad(fs.pressure_angle_deg)))
    r_sun = 0.5 * m * fs.sun_teeth
    out = {
        f"{n} [um]": float(mm_to_um(float(getattr(b, n))))
        for n in ("normal_min", "normal_max", "circumferential_min", "circumferential_max")
    }
    out["sun_free_angle_min [rad]"] = float(b.circumferential_min) / r_sun
    out["sun_free_angle_max [rad]"] = float(b.circumferential_max) / r_sun
    out["sun_allowances [um]"] = [sun.upper_um, sun.lower_um]  # type: ignore[assignment]
    out["planet_allowances [um]"] = [planet.upper_um, planet.lower_um]  # type: ignore[assignment]
    out["centre_distance_allowances [um]"] = [a_e, a_i]  # type: ignore[assignment]
    return out


def _first_stage_backlash(case: Case, red: RVReducer) -> AnalysisResult:
    fs = case.reducer.first_stage
    b = first_stage_backlash(fs)
    i = float(red.ratio)
    values: dict[str, Any] = {
        "sun_class": fs.sun_tooth_thickness_allowance,
        "planet_class": fs.planet_tooth_thickness_allowance,
        "centre_distance_field": fs.centre_distance_allowance,
        "sun_allowances [um]": b["sun_allowances [um]"],
        "planet_allowances [um]": b["planet_allowances [um]"],
        "centre_distance_allowances [um]": b["centre_distance_allowances [um]"],
        "first_stage_backlash_normal_min [um]": b["normal_min [um]"],
        "first_stage_backlash_normal_max [um]": b["normal_max [um]"],
        "first_stage_backlash_circumferential_min [um]": b["circumferential_min [um]"],
        "first_stage_backlash_circumferential_max [um]": b["circumferential_max [um]"],
        "first_stage_backlash_at_output_min [arcmin]": rad_to_arcmin(
            b["sun_free_angle_min [rad]"] / i
        ),
        "first_stage_backlash_at_output_max [arcmin]": rad_to_arcmin(
            b["sun_free_angle_max [rad]"] / i
        ),
    }
    return AnalysisResult(
        name="first_stage_backlash",
        title="First-stage backlash from the tooth-thickness classes (DIN 3967)",
        values=values,
        references=[],
        notes=[
            "Sun–planet mesh: j_t = −(A_s,sun + A_s,planet) + 2 A_a tan α, j_n = j_t cos α "
            "(DIN 3967 Tables 1-2 at d = m·z; ISO 286 js field of a = m(z1 + z2)/2). At the "
            "output with the input locked: the sun's free angle j_t / r_sun divided by the ratio "
            f"i = {i:.6g}. One mesh; with several planets the sun stops at the smallest gap.",
            "The reducer model's sun–planet mesh has no clearance; the catalogue test and the "
            "yield add this free angle to lost motion, backlash and hysteresis loss (option "
            "first_stage_backlash = 'additive', the default; the cranks turn together, so the "
            "smallest gap of the planets counts), the TE leaves it out (docs/tolerance_grades.md).",
        ],
    )


FirstStageLaw = Literal["additive", "ignored"]

_FIRST_STAGE_LAW_DOC = (
    "How the first stage's backlash (reducer.first_stage tooth-thickness classes or "
    "backlash_um) enters: 'additive' — its free angle at the output, min_k j_t,k / (r_sun i), "
    "is added to lost motion, backlash and hysteresis loss (docs/tolerance_grades.md); "
    "'ignored' — the second stage alone. Nothing is added when the case gives neither"
)


def first_stage_terms(fs: FirstStageSection) -> dict[str, Any] | None:
    """What the first stage's backlash input gives the catalogue test and the yield.

    Parameters
    ----------
    fs : FirstStageSection

    Returns
    -------
    dict or None
        ``None`` without classes or ``backlash_um``; else ``given_um`` (per mesh [µm]),
        ``nominal_um`` (deviation key → class midpoint [µm]), ``limits_um`` (family →
        (lower, upper) class limits [µm]),
        ``r_sun`` [mm], ``alpha`` [rad] and ``backlash_um`` (per-mesh j_t at the midpoints,
        minimum and maximum [µm]).
    """
    n = fs.planets
    alpha = float(deg_to_rad(fs.pressure_angle_deg))
    r_sun = 0.5 * fs.module_mm * fs.sun_teeth
    if fs.backlash_um is not None:
        raw = fs.backlash_um
        given = [float(x) for x in raw] if isinstance(raw, list) else [float(raw)] * n
        return {
            "given_um": given,
            "nominal_um": {},
            "limits_um": {},
            "r_sun": r_sun,
            "alpha": alpha,
            "backlash_um": {"mid": given, "min": given, "max": given},
        }
    if fs.sun_tooth_thickness_allowance is None:
        return None
    bl: dict[str, Any] = first_stage_backlash(fs)
    sun, planet = bl["sun_allowances [um]"], bl["planet_allowances [um]"]
    a_e, a_i = bl["centre_distance_allowances [um]"]
    limits = {  # per family: a planet's key, each planet's instance
        "first_stage.sun_thickness": (sun[1], sun[0]),
        "first_stage.planet_thickness": (planet[1], planet[0]),
        "first_stage.centre_distance": (a_i, a_e),
    }
    nominal = {"first_stage.sun_thickness": 0.5 * (sun[0] + sun[1])}
    for i in range(1, n + 1):
        nominal[f"first_stage.planet_thickness.c{i}"] = 0.5 * (planet[0] + planet[1])
        nominal[f"first_stage.centre_distance.c{i}"] = 0.5 * (a_e + a_i)
    mid = -0.5 * (sun[0] + sun[1] + planet[0] + planet[1]) + (a_e + a_i) * np.tan(alpha)
    return {
        "given_um": [0.0] * n,
        "nominal_um": nominal,
        "limits_um": limits,
        "r_sun": r_sun,
        "alpha": alpha,
        "backlash_um": {
            "mid": [float(mid)] * n,
            "min": [bl["circumferential_min [um]"]] * n,
            "max": [bl["circumferential_max [um]"]] * n,
        },
    }


class CranksSection(StrictModel):
    count: int = Field(ge=2, le=6, description="Number of crank shafts (= planets) [-].")
    circle_radius_mm: float = Field(
        gt=0, le=1000, description="Radius of the circle of crank centres on the carrier [mm]."
    )
    eccentricity_mm: float = floored(
        "eccentricity", le=50, description="Crank (cam) eccentricity a [mm]."
    )
    cam_bearing: Bearing
    carrier_bearing: Bearing
    shaft_diameter_mm: float | None = Field(
        default=None, gt=0, le=500, description="crank shaft diameter (mass, bending, torsion)"
    )
    shaft_length_mm: float | None = Field(default=None, gt=0, le=2000, description="mass only")
    bearing_span_mm: float | None = Field(
        default=None,
        gt=0,
        le=2000,
        description="distance between a crank's two carrier bearings: crank bending derived "
        "(simply supported, cams centred) [mm]",
    )
    bending_stiffness_N_per_mm: float | None = floored(
        "linear_stiffness", None, le=1e10, description="given crank bending stiffness at a cam"
    )
    torsion_length_mm: float | None = Field(
        default=None,
        gt=0,
        le=2000,
        description="length of crank twisted between planet and cams: torsion derived [mm]",
    )
    torsional_stiffness_Nm_per_rad: float | None = floored(  # noqa: N815
        "torsional_stiffness", None, le=1e10, description="given crank torsional stiffness"
    )

    @model_validator(mode="after")
    def _chain(self):
        for derived, given in (
            ("bearing_span_mm", "bending_stiffness_N_per_mm"),
            ("torsion_length_mm", "torsional_stiffness_Nm_per_rad"),
        ):
            if getattr(self, derived) is not None and getattr(self, given) is not None:
                raise ValueError(f"give {derived} (derived) or {given}, not both")
            if getattr(self, derived) is not None and self.shaft_diameter_mm is None:
                raise ValueError(f"{derived} needs shaft_diameter_mm to derive the stiffness")
        return self


class DiscsSection(StrictModel):
    count: int = Field(ge=1, le=3, description="Number of cycloid discs [-].")
    face_width_mm: float = floored(
        "part_length", ..., le=200, description="Face width of one disc [mm]."
    )
    equidistant_modification_mm: float = Field(
        default=0.0, ge=-0.5, le=0.5, description="Equidistant modification Δr_rp [mm]."
    )
    shift_modification_mm: float = Field(
        default=0.0, ge=-0.5, le=0.5, description="Shifted modification Δr_p [mm]."
    )
    youngs_modulus_MPa: float = floored(  # noqa: N815
        "youngs_modulus", le=1e6, description="Young's modulus E of discs and pins [MPa]."
    )
    poisson_ratio: float = Field(
        ge=0, lt=0.5, description="Poisson's ratio ν of discs and pins [-]."
    )
    crank_bore_diameter_mm: float | None = Field(default=None, gt=0, le=500, description="mass")
    centre_bore_diameter_mm: float | None = Field(default=None, gt=0, le=2000, description="mass")
    equidistant_modification_errors_um: list[float] | None = Field(
        default=None, description="error of each disc's equidistant modification δΔr_rp [um]"
    )
    shift_modification_errors_um: list[float] | None = Field(
        default=None, description="error of each disc's shifted modification δΔr_p [um]"
    )

    @model_validator(mode="after")
    def _per_disc(self):
        for name in ("equidistant_modification_errors_um", "shift_modification_errors_um"):
            v = getattr(self, name)
            if v is not None and (len(v) != self.count or any(abs(x) > 200 for x in v)):
                raise ValueError(
                    f"{name} needs one value per disc ({self.count}) within +-200 um, got {v}"
                )
        return self

    def modification_errors_mm(self) -> np.ndarray:
        """``(N, 2)`` per-disc (δΔr_rp, δΔr_p) [mm]."""
        out = np.zeros((self.count, 2))
        for col, v in enumerate(
            (self.equidistant_modification_errors_um, self.shift_modification_errors_um)
        ):
            if v is not None:
                out[:, col] = um_to_mm(np.asarray(v, dtype=float))
        return out


class PinsSection(StrictModel):
    count: int = Field(ge=8, le=200, description="Number of pins z_p [-].")
    pin_radius_mm: float = Field(gt=0, le=50, description="Pin radius r_rp [mm].")
    circle_radius_mm: float = Field(gt=0, le=2000, description="Pin-centre-circle radius r_p [mm].")
    radius_errors_um: list[float] | None = Field(default=None, description="one per pin [um]")
    radial_position_errors_um: list[float] | None = Field(
        None, description="Radial position error of each pin centre, one per pin [µm]."
    )
    tangential_position_errors_um: list[float] | None = Field(
        None, description="Tangential position error of each pin centre, one per pin [µm]."
    )
    seat_length_mm: float | None = Field(
        default=None,
        gt=0,
        le=2000,
        description="length over which a pin bears on its housing groove: seat stiffness "
        "derived (Palmgren, tangent at the largest ideal pin force at rated torque) [mm]",
    )
    seat_stiffness_N_per_mm: float | None = floored(
        "linear_stiffness", None, le=1e10, description="given pin seat stiffness"
    )
    support_span_mm: float | None = Field(
        default=None,
        gt=0,
        le=2000,
        description="span of a pin held at its ends: bending derived (simply supported, "
        "discs centred) [mm]",
    )
    bending_stiffness_N_per_mm: float | None = floored(
        "linear_stiffness", None, le=1e10, description="given pin bending stiffness at a disc"
    )

    @model_validator(mode="after")
    def _lengths(self):
        names = ("radius_errors_um", "radial_position_errors_um", "tangential_position_errors_um")
        for name in names:
            v = getattr(self, name)
            if v is not None and len(v) != self.count:
                raise ValueError(f"{name} needs one value per pin ({self.count}), got {len(v)}")
        for derived, given in (
            ("seat_length_mm", "seat_stiffness_N_per_mm"),
            ("support_span_mm", "bending_stiffness_N_per_mm"),
        ):
            if getattr(self, derived) is not None and getattr(self, given) is not None:
                raise ValueError(f"give {derived} (derived) or {given}, not both")
        return self


class SupportsSection(StrictModel):
    carrier_radial_stiffness_N_per_mm: float | None = floored(
        "linear_stiffness",
        None,
        le=1e10,
        description="Radial stiffness of the carrier (output) support [N/mm] (or main_bearing).",
    )
    main_bearing: Bearing | None = Field(
        default=None,
        description="The carrier's main bearings (both rows): roller data or a stiffness.",
    )
    output_flange_torsional_stiffness_Nm_per_rad: float | None = floored(  # noqa: N815
        "torsional_stiffness",
        None,
        le=1e12,
        description="given torsional stiffness of the carrier / output flange [N·m/rad]",
    )
    main_bearing_clearance_um: float = Field(
        default=0.0,
        ge=0,
        le=200,
        description="Radial clearance of the main bearing ε_h [µm] (dynamics only).",
    )
    carrier_outer_diameter_mm: float | None = Field(default=None, gt=0, le=5000, description="mass")
    carrier_length_mm: float | None = Field(default=None, gt=0, le=5000, description="mass")

    @model_validator(mode="after")
    def _main(self):
        if (self.carrier_radial_stiffness_N_per_mm is None) == (self.main_bearing is None):
            raise ValueError("give carrier_radial_stiffness_N_per_mm or main_bearing (one)")
        if self.main_bearing is not None and self.main_bearing.at_rated_torque:
            raise ValueError(
                "main_bearing.at_rated_torque: the output torque puts (almost) no radial load on "
                "the main bearings; give their preload as reference_load_N"
            )
        return self

    def main_stiffness(self) -> float:
        """Radial stiffness of the carrier's main bearings [N/mm]."""
        if self.main_bearing is not None:
            return self.main_bearing.stiffness()
        assert self.carrier_radial_stiffness_N_per_mm is not None  # noqa: S101 - _main
        return self.carrier_radial_stiffness_N_per_mm


_Part = Literal[
    "sun_eccentricity",
    "sun_assembly",
    "planet_eccentricity",
    "cam",
    "disc_crank_bore",
    "disc_radial_runout",
    "disc_cumulative_pitch",
    "carrier_crank_bore",
    "output_assembly",
]
assert set(ERROR_PARTS) == set(get_args(_Part))  # noqa: S101 - one list of parts


class ErrorSection(StrictModel):
    """One eccentricity error: its part, where it sits, magnitude and angle in the part's frame."""

    part: _Part = Field(
        description="The part the error sits on (docs/rv-reducer-description.md, Errors)."
    )
    crank: int | None = Field(default=None, ge=1, description="1-based crank (= planet) index")
    disc: int | None = Field(default=None, ge=1, description="1-based disc index")
    value_um: float = Field(ge=0, le=500, description="Magnitude of the eccentricity error [µm].")
    angle_deg: float = Field(
        ge=-360, le=360, description="Angle of the error in the part's frame [deg]."
    )


class DynamicsSection(StrictModel):
    """What only the dynamics needs; masses and inertias left out are derived from geometry."""

    sun_mass_kg: float | None = Field(
        default=None,
        gt=0,
        le=1e3,
        description="Mass of the sun gear [kg]; default: derived from geometry and density.",
    )
    planet_mass_kg: float | None = Field(
        default=None, gt=0, le=1e3, description="Mass of one planet [kg]; default: derived."
    )
    crank_mass_kg: float | None = Field(
        default=None, gt=0, le=1e3, description="Mass of one crank shaft [kg]; default: derived."
    )
    disc_mass_kg: float | None = Field(
        default=None, gt=0, le=1e3, description="Mass of one cycloid disc [kg]; default: derived."
    )
    output_mass_kg: float | None = Field(
        default=None,
        gt=0,
        le=1e4,
        description="Mass of the output (carrier) [kg]; default: derived.",
    )
    sun_inertia_kgm2: float | None = Field(
        default=None,
        gt=0,
        le=1e3,
        description="Moment of inertia of the sun gear [kg·m²]; default: derived.",
    )
    planet_inertia_kgm2: float | None = Field(
        default=None,
        gt=0,
        le=1e3,
        description="Moment of inertia of one planet [kg·m²]; default: derived.",
    )
    crank_inertia_kgm2: float | None = Field(
        default=None,
        gt=0,
        le=1e3,
        description="Moment of inertia of one crank shaft [kg·m²]; default: derived.",
    )
    disc_inertia_kgm2: float | None = Field(
        default=None,
        gt=0,
        le=1e3,
        description="Moment of inertia of one disc [kg·m²]; default: derived.",
    )
    output_inertia_kgm2: float | None = Field(
        default=None,
        gt=0,
        le=1e4,
        description="Moment of inertia of the output [kg·m²]; default: derived.",
    )
    input_torsional_stiffness_Nm_per_rad: float = floored(  # noqa: N815
        "torsional_stiffness",
        le=1e9,
        description="Torsional stiffness of the input shaft [N·m/rad].",
    )
    crank_torsional_stiffness_Nm_per_rad: float = floored(  # noqa: N815
        "torsional_stiffness",
        le=1e9,
        description="Torsional stiffness of one crank shaft [N·m/rad].",
    )
    crank_bending_stiffness_N_per_mm: float = floored(  # noqa: N815
        "linear_stiffness", le=1e10, description="Bending stiffness of one crank shaft [N/mm]."
    )
    damping_ratio: float = Field(gt=0, lt=1, description="ζ of the lowest elastic mode")
    cycloid_stiffness: Literal["fourier", "mean"] = Field(
        "fourier", description="time-varying k_cr (Fourier) or its mean (as Li 2023 §4.1)"
    )
    cycloid_mesh_stiffness_N_per_mm: float | None = floored(  # noqa: N815
        "linear_stiffness",
        None,
        le=1e10,
        description="override of the mean k_cr from the loaded contact",
    )
    cycloid_pressure_angle_deg: float | None = Field(
        None, ge=0, lt=90, description="override of the equivalent pressure angle β"
    )
    involute_harmonics: int = Field(
        10, ge=1, le=60, description="Fourier harmonics of the involute mesh stiffness [-]."
    )
    cycloid_harmonics: int = Field(
        8, ge=1, le=30, description="Fourier harmonics of the cycloid–pin mesh stiffness [-]."
    )

    def given(self, what: str) -> dict[str, float]:
        """Given masses (``what="mass"``, [kg]) or inertias (``"inertia"``, [kg·m²]) by body."""
        suffix = "_mass_kg" if what == "mass" else "_inertia_kgm2"
        out = {}
        for body in ("sun", "planet", "crank", "disc", "output"):
            v = getattr(self, body + suffix)
            if v is not None:
                out[body] = v
        return out


#: The error of an RV case without ``[reducer] contact_law`` (it had a silent default).
CONTACT_LAW_REQUIRED = (
    "contact_law is required: name the pin-contact law, one of 'line_contact', 'hu2020', "
    "'palmgren' (docs/contact-law.md); contact_law = \"line_contact\" gives the results of a "
    "case written before the key was required"
)


class ReducerSection(StrictModel):
    rated_torque_Nm: float | None = floored(
        "load_torque", None, le=1e6, description="catalogue rated torque (virtual torsion test)"
    )
    contact_law: Literal["line_contact", "hu2020", "palmgren"] | None = Field(
        default=None,
        description="pin-contact law, required: 'line_contact' (Johnson), 'hu2020' (Hu 2020 eq "
        "38-39 as printed) or 'palmgren' (Palmgren's steel line contact) "
        "(gearte.models.contact_law; docs/contact-law.md)",
    )
    allowable_contact_pressure_MPa: float | None = Field(
        default=None, gt=0, le=1e5, description="warn when the Hertz pin pressure exceeds it"
    )
    material: Literal["steel"] | None = Field(
        default=None, description="names the density of derived masses (steel: 7850 kg/m³)"
    )
    density_kg_per_m3: float | None = Field(
        default=None,
        gt=100,
        le=30000,
        description="Density of derived masses [kg/m³] (or give material).",
    )
    first_stage: FirstStageSection
    cranks: CranksSection = Field(description="Crank shafts and their bearings.")
    discs: DiscsSection = Field(
        description="Cycloid discs: width, profile modifications, material."
    )
    pins: PinsSection = Field(description="Pin ring: pins, radii and per-pin errors.")
    supports: SupportsSection = Field(description="Carrier support and main bearing.")
    errors: list[ErrorSection] = Field(default_factory=list)
    cycloid_errors: CycloidErrors | None = None
    dynamics: DynamicsSection | None = None

    @model_validator(mode="after")
    def _build(self):
        problems = []
        if self.contact_law is None:
            raise ValueError(CONTACT_LAW_REQUIRED)
        if self.material is not None and self.density_kg_per_m3 is not None:
            problems.append("give material or density_kg_per_m3, not both")
        if self.contact_law == "palmgren":
            from gearte.models.contact_law import check_palmgren_modulus

            try:
                check_palmgren_modulus(self.discs.youngs_modulus_MPa, "discs.youngs_modulus_MPa")
            except ParameterError as exc:
                problems.append(str(exc))
        if self.first_stage.planets != self.cranks.count:
            problems.append(
                f"first_stage.planets = {self.first_stage.planets}: must equal cranks.count = "
                f"{self.cranks.count} (each planet drives one crank)"
            )
        for k, e in enumerate(self.errors):
            entry = ErrorEntry(e.part, e.crank, e.disc, um_to_mm(e.value_um), 0.0)
            try:
                ManufacturingErrors.from_entries(
                    [entry], self.cranks.count, self.discs.count, field_name="errors"
                )
            except ParameterError as exc:
                problems.append(str(exc).replace("errors[0]", f"errors[{k}]"))
        if not problems:
            try:
                build_reducer(self, operating=False)
            except ParameterError as exc:
                problems.append(str(exc))
        if problems:
            raise ValueError("; ".join(problems))
        return self

    @property
    def density(self) -> float | None:
        """Density of derived masses [kg/m³], from ``density_kg_per_m3`` or ``material``."""
        if self.density_kg_per_m3 is not None:
            return self.density_kg_per_m3
        return None if self.material is None else MATERIAL_DENSITY_KG_PER_M3[self.material]


class OperationSection(StrictModel):
    """Operating point of the dynamic analyses."""

    input_speed_rpm: float = Field(gt=0, le=2e4, description="Input speed [rpm].")
    output_torque_Nm: float = floored(
        "load_torque", ..., le=1e6, description="Output (load) torque [N·m]."
    )  # noqa: N815


class LoadSharingSection(StrictModel):
    torque_Nm: float = floored("load_torque", ..., le=1e6, description="Output torque [N·m].")
    positions: int = Field(
        default=360, ge=8, le=7200, description="Output positions over one revolution [-]."
    )
    compare_without_errors: bool = Field(
        True, description="Also solve without the errors, for comparison."
    )


class TESection(StrictModel):
    torque_Nm: float = floored(
        "load_torque", ..., le=1e6, description="Output torque of the loaded TE [N·m]."
    )
    positions: int = Field(
        default=360, ge=8, le=7200, description="Output positions over one revolution [-]."
    )
    zero_load_fraction: float = Field(
        default=1e-3,
        gt=0,
        lt=0.05,
        description="The geometric part is solved at this fraction × torque [-].",
    )


class CatalogueSection(StrictModel):
    position_deg: float = Field(
        default=0.0,
        ge=0,
        lt=360,
        description="Output angle at which the virtual torsion test runs [deg].",
    )
    torque_sweep: list[float] = Field(
        default=[0.0, 1.0, 0.0, -1.0, 0.0, 1.0],
        description="turning points of the torque sweep, fractions of rated torque",
    )
    steps_per_segment: int = Field(
        default=20, ge=2, le=1000, description="Torque steps per segment of the torque sweep [-]."
    )
    lost_motion_fraction: float = Field(
        default=0.03,
        gt=0,
        lt=0.5,
        description="Lost motion "
        "between ±fraction × rated torque [-] (0.03 or 0.05 in catalogues).",
    )
    first_stage_backlash: FirstStageLaw = Field(
        default="additive", description=_FIRST_STAGE_LAW_DOC + " (class midpoint; limits beside)."
    )

    @model_validator(mode="after")
    def _sweep(self):
        tp = self.torque_sweep
        if len(tp) < 2:
            raise ValueError("torque_sweep needs at least two turning points")
        if not (min(tp) < 0.0 < max(tp)):
            raise ValueError(
                f"torque_sweep {tp} has no zero crossing: it must contain positive and negative "
                "torques (fractions of rated torque) to show backlash and lost motion"
            )
        if max(abs(v) for v in tp) > 1.5:
            raise ValueError("torque_sweep values must be within [-1.5, 1.5] x rated torque")
        return self


class Bounds(StrictModel):
    equidistant_modification: tuple[float, float] | None = Field(
        None, description="[lower, upper] change of the equidistant modification Δr_rp [µm]."
    )
    shift_modification: tuple[float, float] | None = Field(
        None, description="[lower, upper] change of the shifted modification Δr_p [µm]."
    )
    pin_radius: tuple[float, float] | None = Field(
        None, description="[lower, upper] change of the pin radius r_rp [µm]."
    )
    pin_circle_radius: tuple[float, float] | None = Field(
        None, description="[lower, upper] change of the pin-circle radius r_p [µm]."
    )

    @model_validator(mode="after")
    def _order(self):
        given = {k: v for k, v in self.model_dump().items() if v is not None}
        if not given:
            raise ValueError("name at least one design variable with its [lower, upper] in um")
        for k, (lo, hi) in given.items():
            if not lo < hi or max(abs(lo), abs(hi)) > 200:
                raise ValueError(f"{k}: need lower < upper within +-200 um, got [{lo}, {hi}]")
        return self


class CompensationSection(StrictModel):
    torque_Nm: float = floored(
        "load_torque",
        le=1e6,
        description="Output torque at which the objective is evaluated [N·m].",
    )
    objective: Literal["total_te_peak_to_peak", "mean_lag"] = Field(
        "total_te_peak_to_peak",
        description="What the compensation minimises: total TE peak-to-peak or the mean lag.",
    )
    min_backlash_arcmin: float = Field(
        default=0.0,
        ge=0,
        le=30,
        description="Backlash the changed design must keep at least [arcmin].",
    )
    positions: int = Field(
        default=72, ge=8, le=720, description="Output positions per evaluation [-]."
    )
    grid: int = Field(
        default=3,
        ge=2,
        le=7,
        description="Points per design variable of the initial grid search [-].",
    )
    bounds_um: Bounds = Field(
        description="The design variables and their [lower, upper] changes [µm]."
    )


class ToothContactSection(StrictModel):
    """Loaded tooth contact of one disc (Hu 2020 section 4); material from ``[reducer.discs]``."""

    torque_Nm: float = floored(
        "load_torque", ..., le=1e6, description="output torque of the stage T [N·m]"
    )
    disc_share: float = floored(
        "disc_share", ..., le=1, description="share of T carried by the analysed disc"
    )
    mesh_positions: int = Field(
        default=1,
        ge=1,
        le=100000,
        description="Mesh positions over one tooth pitch (1: the paper's).",
    )
    start_force_N: float | None = Field(
        default=None, gt=0, le=1e9, description="Start value of F_max [N]; default eq 45."
    )
    clearance_model: Literal["eq32", "envelope"] = Field(
        "eq32", description="Initial clearance: eq 32 (paper, first order) or the exact envelope."
    )


class RVYieldSection(YieldSection):
    """``[analyses.yield]`` of an RV reducer (gearte.studies._yield): tolerance keys are the
    error families ``planet_base_circle``, ``disc_crank_bore``, ``cam``, ``carrier_crank_bore``,
    ``disc_radial_runout``, ``disc_cumulative_pitch``, ``sun_eccentricity``, ``sun_assembly``,
    ``output_assembly`` (magnitude [µm], ``kind = "rayleigh"``, ``phase = true`` for a uniform
    direction), ``pins.radius_errors``, ``pins.radial_position_errors``,
    ``pins.tangential_position_errors``, ``discs.equidistant_modification_errors``,
    ``discs.shift_modification_errors`` [µm], or one instance (``cam.c1.d2``,
    ``pins.radius_errors.p7``, ``disc_radial_runout.d1``)."""

    positions: int = Field(default=36, ge=2, le=3600, description="TE output positions")
    grid_check_samples: int = Field(
        default=32,
        ge=0,
        le=10**9,  # as samples: --samples caps it, never refused by it (at most the run's)
        description="Samples re-run on a refined grid of output positions to estimate the "
        "grid's error of the TE and pin loads (0: no check).",
    )
    grid_check_factor: int = Field(
        default=10,
        ge=2,
        le=100,
        description="The refined grid: this many times positions (a superset of the grid).",
    )
    te_torque_Nm: float | None = floored(
        "load_torque", None, le=1e6, description="torque of the loaded TE; default rated"
    )
    first_stage_backlash: FirstStageLaw = Field(
        default="additive",
        description=_FIRST_STAGE_LAW_DOC + "; with classes the tooth-thickness and "
        "centre-distance deviations are drawn (truncated normal, 3σ = half the class width, "
        "cut at the class limits) as tolerances first_stage.sun_thickness, "
        "first_stage.planet_thickness, first_stage.centre_distance.",
    )


class Analyses(StrictModel):
    load_sharing: LoadSharingSection | None = Field(
        None, description="Pin load sharing with the errors over one output revolution (Han 2023)."
    )
    transmission_error: TESection | None = Field(
        None, description="Loaded output angle error: geometric and elastic parts, mean lag."
    )
    catalogue: CatalogueSection | None = Field(
        None,
        description="Virtual torsion test: rigidity, "
        "lost motion, backlash (needs rated_torque_Nm).",
    )
    compensation: CompensationSection | None = Field(
        None,
        description="Profile and pin changes that minimise TE while keeping a minimum backlash.",
    )
    geometric_te: GeometricTEOptions | None = None
    tooth_contact: ToothContactSection | None = None
    cycloid_compensation: CycloidCompensationOptions | None = None
    contact: dyn.ContactOptions | None = Field(
        None,
        description="Loaded cycloid–pin contact over one mesh period: mesh stiffness (Li 2023).",
    )
    modal: dyn.ModalOptions | None = Field(
        None, description="Natural frequencies and the Campbell diagram of the dynamic model."
    )
    dte: dyn.DTEOptions | None = Field(
        None, description="Dynamic transmission error and its spectrum (Li 2023)."
    )
    speed_sweep: dyn.SpeedSweepOptions | None = None
    batch: dyn.BatchOptions | None = Field(None, description="DTE over random error realisations.")

    yield_: RVYieldSection | None = Field(default=None, alias="yield")


#: The inputs each analysis needs beyond the reducer's required sections.
_NEEDS = {
    "catalogue": ("reducer.rated_torque_Nm",),
    "compensation": ("reducer.rated_torque_Nm",),
    # every sample's catalogue virtual test (lost motion at ±3 % of the rated torque, rigidity)
    "yield": ("reducer.rated_torque_Nm",),
    "geometric_te": ("reducer.cycloid_errors",),
    "cycloid_compensation": ("reducer.cycloid_errors",),
    **{k: ("reducer.dynamics", "operation") for k in dyn.ANALYSES},
}


class CalibratedParameter(StrictModel):
    """One estimate of a bench calibration (gearte units, named by ``unit``)."""

    value: float = Field(description="The estimate, in the unit named by unit.")
    ci95: float | None = Field(default=None, description="95 % half-width (None: not identified)")
    unit: str = Field(description="Unit of value and ci95 (gearte units).")
    identified: bool = Field(
        description="Whether the bench data determine it (false: confounded or unobserved)."
    )
    note: str = Field(default="", description="Why it is not identified, or how it was found.")


class BenchCalibrationSection(StrictModel):
    """What a bench calibration (kind ``rv_bench``) found for this serial, as values.

    The clearances and the stiffness scale are applied in ``[reducer]`` (the bearing, support
    and mesh stiffnesses and the Young's modulus are the design's times ``stiffness_scale``);
    the friction and the rig's compliance are not parts of the reducer model and are recorded
    here. Informational: the rv_reducer analyses do not read this section.
    """

    source: str = Field(description="The bench case and data it was calibrated from.")
    stiffness_scale: float = Field(gt=0, description="Factor applied to every stiffness [-].")
    contact_stiffness_factor: float | None = Field(
        default=None, description="Reduced model's f on the design's rigidity [-]."
    )
    friction_torque_Nm: float | None = Field(default=None, description="Coulomb friction [N*m].")
    rig_compliance_arcsec_per_kNm: float | None = Field(
        default=None, description="Rig compliance between torque sensor and encoder."
    )
    clearances_identified: bool = Field(
        description="False: the bench sees only the play of both crank bearings together (one "
        "common clearance written) or not even that (the design's clearances kept)."
    )
    parameters: dict[str, CalibratedParameter] = Field(default_factory=dict)
    round_trip: dict[str, dict[str, float | None]] = Field(
        default_factory=dict,
        description="Bench value, this serial through the whole model (+ the rig's twist), "
        "relative difference, per catalogue quantity.",
    )
    not_written: list[str] = Field(
        default_factory=list,
        description="Estimates not applied to [reducer] (unidentifiable or outside the model).",
    )


class Case(CaseBase):
    reducer: ReducerSection
    operation: OperationSection | None = None
    analyses: Analyses
    bench_calibration: BenchCalibrationSection | None = Field(
        default=None, description="A bench calibration's findings (written by rv_bench)."
    )

    @model_validator(mode="after")
    def _inputs(self):
        have = {
            "reducer.rated_torque_Nm": self.reducer.rated_torque_Nm is not None,
            "reducer.cycloid_errors": self.reducer.cycloid_errors is not None,
            "reducer.dynamics": self.reducer.dynamics is not None,
            "operation": self.operation is not None,
        }
        # a section's case key is its field's alias where it has one (``yield`` → ``yield_``)
        attr = {f.alias: n for n, f in Analyses.model_fields.items() if f.alias}
        problems = [
            f"analyses.{name} needs {key}, which the case does not give"
            for name, keys in _NEEDS.items()
            if getattr(self.analyses, attr.get(name, name)) is not None
            for key in keys
            if not have[key]
        ]
        if self.reducer.pins.seat_length_mm is not None and not have["reducer.rated_torque_Nm"]:
            problems.append(
                "reducer.pins.seat_length_mm needs reducer.rated_torque_Nm (the pin seat is "
                "linearised at the largest pin force at rated torque), which the case does not give"
            )
        for name in ("cam_bearing", "carrier_bearing"):
            if (
                getattr(self.reducer.cranks, name).at_rated_torque
                and not have["reducer.rated_torque_Nm"]
            ):
                problems.append(
                    f"reducer.cranks.{name}.at_rated_torque needs reducer.rated_torque_Nm, which "
                    "the case does not give"
                )
        if problems:
            raise ValueError("; ".join(problems))
        return self


# ------------------------------------------------------------------------------------------
# Case -> domain objects
# ------------------------------------------------------------------------------------------
#: ``[reducer.first_stage]`` key of each :class:`SunPlanets` field.
_GEAR_SET_KEYS = {
    "z_sun": "sun_teeth",
    "z_planet": "planet_teeth",
    "module": "module_mm",
    "pressure_angle": "pressure_angle_deg",
    "n_planets": "planets",
}


def build_reducer(
    sec: ReducerSection, *, with_errors: bool = True, operating: bool = True
) -> RVReducer:
    """The :class:`RVReducer` a case's ``[reducer]`` section describes.

    Parameters
    ----------
    sec : ReducerSection
        The validated ``[reducer]`` table.
    with_errors : bool
        Include the ``[[reducer.errors]]`` (``False``: the nominal reducer).
    operating : bool
        Linearise the bearings marked ``at_rated_torque`` at their largest load at rated torque
        (:func:`_at_operating_load`); ``False``: at a first estimate (the case check, which
        needs the geometry only).

    Returns
    -------
    RVReducer
        The description every RV analysis reads.
    """
    fs = sec.first_stage
    if fs.mesh_stiffness_N_per_mm is not None:
        mesh = fs.mesh_stiffness_N_per_mm
    elif fs.face_width_mm is not None:
        mesh = float(iso6336_mesh_stiffness(fs.face_width_mm))
    else:  # refused by FirstStageSection's validator
        raise ParameterError(
            "reducer.first_stage.face_width_mm", None, "give it or mesh_stiffness_N_per_mm"
        )
    try:  # the planetary kind's gear set (its checks, its messages), named by the RV keys
        gears = SunPlanets(
            fs.sun_teeth,
            fs.planet_teeth,
            fs.module_mm,
            float(deg_to_rad(fs.pressure_angle_deg)),
            n_planets=fs.planets,
        )
    except ParameterError as exc:
        key = _GEAR_SET_KEYS.get(exc.field, exc.field)
        raise ParameterError(f"first_stage.{key}", exc.value, exc.reason) from None
    first = FirstStage(gears, mesh, fs.sun_support_stiffness_N_per_mm, fs.face_width_mm)
    c = sec.cranks
    chain = _chain_inputs(sec)
    f0 = _first_bearing_load(sec)
    cranks = Cranks(
        c.count,
        c.circle_radius_mm,
        c.eccentricity_mm,
        c.cam_bearing.stiffness(f0 if c.cam_bearing.at_rated_torque else None),
        c.carrier_bearing.stiffness(f0 if c.carrier_bearing.at_rated_torque else None),
        um_to_mm(c.cam_bearing.radial_clearance_um),
        um_to_mm(c.carrier_bearing.radial_clearance_um),
        c.shaft_diameter_mm,
        c.shaft_length_mm,
        chain["crank_bending"],
        chain["crank_torsion"],
    )
    d = sec.discs
    if sec.contact_law is None:
        raise ParameterError("reducer.contact_law", None, CONTACT_LAW_REQUIRED)
    discs = Discs(
        d.count,
        d.face_width_mm,
        d.equidistant_modification_mm,
        d.shift_modification_mm,
        d.youngs_modulus_MPa,
        d.poisson_ratio,
        d.crank_bore_diameter_mm,
        d.centre_bore_diameter_mm,
        contact_law=sec.contact_law,
    )
    p = sec.pins

    def arr(v):
        return np.zeros(p.count) if v is None else um_to_mm(np.asarray(v, dtype=float))

    pins = PinRing(
        p.count,
        p.pin_radius_mm,
        p.circle_radius_mm,
        arr(p.radius_errors_um),
        arr(p.radial_position_errors_um),
        arr(p.tangential_position_errors_um),
        chain["pin_seat"],
        chain["pin_bending"],
    )
    s = sec.supports
    supports = Supports(
        s.main_stiffness(),
        um_to_mm(s.main_bearing_clearance_um),
        s.carrier_outer_diameter_mm,
        s.carrier_length_mm,
        chain["output_flange"],
    )
    entries = [
        ErrorEntry(e.part, e.crank, e.disc, um_to_mm(e.value_um), deg_to_rad(e.angle_deg))
        for e in sec.errors
    ]
    errors = ManufacturingErrors.from_entries(entries, c.count, d.count, field_name="errors")
    errors = errors.with_disc_modification(d.modification_errors_mm())
    if not with_errors:
        errors = errors.scaled(0.0)
    red = RVReducer(
        first,
        cranks,
        discs,
        pins,
        supports,
        None if sec.rated_torque_Nm is None else Nm_to_Nmm(sec.rated_torque_Nm),
        planets=fs.planets,
        errors=errors,
    )
    from gearte.models.rv_load_sharing import cycloid_stage

    cycloid_stage(red)  # the stage's own validation (undercut, interference, pin fit)
    if operating and (c.cam_bearing.at_rated_torque or c.carrier_bearing.at_rated_torque):
        red = _at_operating_load(red, sec)
    return red


#: ``[reducer]`` keys (by sub-table, ``""`` the table itself) that the
#: :class:`~gearte.geometry.rv.RVReducer` does not hold: the first stage's backlash input (added
#: by the catalogue test and the yield beside the reducer model), the dynamics' and the tooth
#: contact's own inputs, the pressure warning and the density of derived masses.
CASE_ONLY_KEYS: dict[str, tuple[str, ...]] = {
    "": (
        "allowable_contact_pressure_MPa",
        "material",
        "density_kg_per_m3",
        "cycloid_errors",
        "dynamics",
    ),
    "first_stage": (
        "sun_tooth_thickness_allowance",
        "planet_tooth_thickness_allowance",
        "centre_distance_allowance",
        "backlash_um",
    ),
}


def _tidy(x: Any) -> float:
    """``x`` to 15 significant digits: a value that went through a unit conversion (µm → mm →
    µm, N·m → N·mm → N·m) is written as it was given (``12.0``, not ``12.000000000000002``);
    the change is below 1e-15 relative."""
    return float(f"{float(x):.15g}")


def _one_stiffness(field: str, compliances: tuple[float, ...] | None) -> float | None:
    """The one stiffness [N/mm] of a per-disc compliance tuple [mm/N] (``None``: left out).

    Raises
    ------
    ParameterError
        Naming ``field`` when the discs' compliances differ: ``[reducer]`` gives one stiffness
        for every disc.
    """
    if compliances is None:
        return None
    c = np.asarray(compliances, dtype=float)
    if not np.allclose(c, c[0], rtol=1e-12, atol=0.0):
        raise ParameterError(
            field,
            tuple(float(x) for x in c),
            "the discs' compliances differ; [reducer] gives one stiffness for every disc",
        )
    return _tidy(1.0 / c[0])


def _error_entries(errors: ManufacturingErrors) -> list[dict[str, Any]]:
    """``[[reducer.errors]]`` of a :class:`~gearte.geometry.rv.ManufacturingErrors`: one entry
    per non-zero error vector, its length [µm] and direction [deg] in the part's frame."""
    from gearte.geometry.planetary import EccentricityError

    out: list[dict[str, Any]] = []

    def add(part: str, vec: np.ndarray, crank: int | None = None, disc: int | None = None):
        if not np.any(vec):
            return
        e = EccentricityError.from_vector(vec, f"errors.{part}")
        entry: dict[str, Any] = {"part": part}
        if crank is not None:
            entry["crank"] = crank
        if disc is not None:
            entry["disc"] = disc
        entry["value_um"] = _tidy(mm_to_um(e.amplitude))
        entry["angle_deg"] = _tidy(rad_to_deg(e.phase))
        out.append(entry)

    m, n = errors.planet.shape[0], errors.disc_bore.shape[0]
    add("sun_eccentricity", errors.sun)
    add("sun_assembly", errors.sun_seat)
    for i in range(m):
        add("planet_eccentricity", errors.planet[i], crank=i + 1)
    for i in range(m):
        for j in range(n):
            add("cam", errors.cam[i, j], crank=i + 1, disc=j + 1)
    for j in range(n):
        for i in range(m):
            add("disc_crank_bore", errors.disc_bore[j, i], crank=i + 1, disc=j + 1)
    for j in range(n):
        add("disc_radial_runout", errors.disc_runout[j], disc=j + 1)
        add("disc_cumulative_pitch", errors.disc_pitch[j], disc=j + 1)
    for i in range(m):
        add("carrier_crank_bore", errors.carrier_bore[i], crank=i + 1)
    add("output_assembly", errors.output_seat)
    return out


def reducer_section(red: RVReducer) -> dict[str, Any]:
    """The ``[reducer]`` table that describes ``red``, the inverse of :func:`build_reducer`:
    ``build_reducer`` of it gives ``red`` back (every field and array equal to the
    round-off of the unit conversions: µm ↔ mm, deg ↔ rad, an error vector ↔ its length and
    direction, a stiffness ↔ its compliance; converted values are written to 15 significant
    digits).

    Parameters
    ----------
    red : RVReducer
        The reducer [mm, N, N·mm, rad] (:class:`~gearte.geometry.rv.RVReducer`).

    Returns
    -------
    dict
        The ``[reducer]`` table, JSON-able, units in the keys.

    Raises
    ------
    ParameterError
        Naming the field the section cannot hold: measured discs or measured bearing
        clearances (a serial's metrology, ``rv_serial``), planets not equally spaced, or
        per-disc bending compliances that differ.

    Notes
    -----
    The object holds the stiffnesses, not how they were obtained, so every stiffness is written
    as a **given** key, whatever the case it came from derived it from:

    * crank bearings and the main bearing from Palmgren/Stribeck data (linearised at a reference
      load or, ``at_rated_torque``, at the design's largest load at rated torque) →
      ``stiffness_N_per_mm`` / ``carrier_radial_stiffness_N_per_mm``;
    * the stiffness chain derived from dimensions (``bearing_span_mm``, ``torsion_length_mm``,
      ``seat_length_mm`` at the ideal peak pin force, ``support_span_mm``) →
      ``bending_stiffness_N_per_mm``, ``torsional_stiffness_Nm_per_rad``,
      ``seat_stiffness_N_per_mm``;
    * the ISO 6336 mesh stiffness from ``face_width_mm`` → ``mesh_stiffness_N_per_mm`` (the face
      width is written too: the masses read it).

    The errors are written as ``[[reducer.errors]]`` entries (non-zero vectors only, direction
    in (−180, 180] deg), the per-pin and per-disc errors as lists. What the object does not hold
    (:data:`CASE_ONLY_KEYS`: the first stage's backlash, ``dynamics``, ``cycloid_errors``,
    density) is not written: :func:`with_case_keys` takes it from the case the object came from.
    """
    fs, c, d, p, s = red.first_stage, red.cranks, red.discs, red.pins, red.supports
    err = red.error_set
    if err.measured_discs is not None and any(x is not None for x in err.measured_discs):
        raise ParameterError(
            "errors.measured_discs", "measured", "a measured disc (rv_serial) has no [reducer] key"
        )
    for name in ("cam_clearance", "carrier_clearance"):
        if getattr(err, name) is not None:
            raise ParameterError(
                f"errors.{name}",
                "measured",
                "measured per-bearing clearances (rv_serial) have no [reducer] key",
            )
    if fs.gears.planet_angles is not None:
        eta = np.asarray(fs.gears.planet_angles, dtype=float)
        n = len(eta)
        if not np.allclose(eta, 2.0 * np.pi * np.arange(n) / n, rtol=0.0, atol=1e-12):
            raise ParameterError(
                "first_stage.planet_angles",
                fs.gears.planet_angles,
                "[reducer] describes equally spaced planets only",
            )

    def um(x: float) -> float:
        return _tidy(mm_to_um(x))

    def opt(table: dict[str, Any], key: str, value: Any) -> None:
        if value is not None:
            table[key] = float(value)

    def per_item(values: np.ndarray) -> list[float] | None:
        v = np.asarray(values, dtype=float)
        return None if not np.any(v) else [_tidy(x) for x in mm_to_um(v)]

    first: dict[str, Any] = {
        "sun_teeth": int(fs.sun_teeth),
        "planet_teeth": int(fs.planet_teeth),
        "planets": int(fs.gears.n_planets),
        "module_mm": float(fs.module),
        "pressure_angle_deg": _tidy(rad_to_deg(fs.pressure_angle)),
        "mesh_stiffness_N_per_mm": float(fs.mesh_stiffness),
        "sun_support_stiffness_N_per_mm": float(fs.sun_support_stiffness),
    }
    opt(first, "face_width_mm", fs.face_width)
    cranks: dict[str, Any] = {
        "count": int(c.count),
        "circle_radius_mm": float(c.circle_radius),
        "eccentricity_mm": float(c.eccentricity),
        "cam_bearing": {
            "stiffness_N_per_mm": float(c.cam_bearing_stiffness),
            "radial_clearance_um": um(c.cam_bearing_clearance),
        },
        "carrier_bearing": {
            "stiffness_N_per_mm": float(c.carrier_bearing_stiffness),
            "radial_clearance_um": um(c.carrier_bearing_clearance),
        },
    }
    opt(cranks, "shaft_diameter_mm", c.shaft_diameter)
    opt(cranks, "shaft_length_mm", c.shaft_length)
    opt(
        cranks,
        "bending_stiffness_N_per_mm",
        _one_stiffness("cranks.bending_compliance", c.bending_compliance),
    )
    if c.torsional_stiffness is not None:
        cranks["torsional_stiffness_Nm_per_rad"] = _tidy(
            c.torsional_stiffness / NM_PER_RAD_TO_NMM_PER_RAD
        )
    discs: dict[str, Any] = {
        "count": int(d.count),
        "face_width_mm": float(d.face_width),
        "equidistant_modification_mm": float(d.equidistant_modification),
        "shift_modification_mm": float(d.shift_modification),
        "youngs_modulus_MPa": float(d.youngs_modulus),
        "poisson_ratio": float(d.poisson_ratio),
    }
    opt(discs, "crank_bore_diameter_mm", d.crank_bore_diameter)
    opt(discs, "centre_bore_diameter_mm", d.centre_bore_diameter)
    for col, key in enumerate(
        ("equidistant_modification_errors_um", "shift_modification_errors_um")
    ):
        if (v := per_item(err.disc_modification[:, col])) is not None:
            discs[key] = v
    pins: dict[str, Any] = {
        "count": int(p.count),
        "pin_radius_mm": float(p.pin_radius),
        "circle_radius_mm": float(p.circle_radius),
    }
    for name in ("radius_errors", "radial_position_errors", "tangential_position_errors"):
        if (v := per_item(getattr(p, name))) is not None:
            pins[f"{name}_um"] = v
    if p.seat_compliance is not None:
        pins["seat_stiffness_N_per_mm"] = _tidy(1.0 / p.seat_compliance)
    opt(
        pins,
        "bending_stiffness_N_per_mm",
        _one_stiffness("pins.bending_compliance", p.bending_compliance),
    )
    supports: dict[str, Any] = {
        "carrier_radial_stiffness_N_per_mm": float(s.carrier_radial_stiffness),
        "main_bearing_clearance_um": um(s.main_bearing_clearance),
    }
    opt(supports, "carrier_outer_diameter_mm", s.carrier_outer_diameter)
    opt(supports, "carrier_length_mm", s.carrier_length)
    if s.output_torsional_stiffness is not None:
        supports["output_flange_torsional_stiffness_Nm_per_rad"] = _tidy(
            s.output_torsional_stiffness / NM_PER_RAD_TO_NMM_PER_RAD
        )
    reducer: dict[str, Any] = {"contact_law": d.contact_law}
    if red.rated_torque is not None:
        reducer["rated_torque_Nm"] = _tidy(Nmm_to_Nm(red.rated_torque))
    reducer.update(
        first_stage=first,
        cranks=cranks,
        discs=discs,
        pins=pins,
        supports=supports,
        errors=_error_entries(err),
    )
    return reducer


def with_case_keys(reducer: dict[str, Any], case_reducer: dict[str, Any]) -> dict[str, Any]:
    """``reducer`` (a ``[reducer]`` table written by :func:`reducer_section`) with the keys the
    object does not hold (:data:`CASE_ONLY_KEYS`) taken from ``case_reducer`` (the JSON dump of
    the ``[reducer]`` the object came from); a new dict."""
    out = {**reducer, "first_stage": dict(reducer["first_stage"])}
    for sub, keys in CASE_ONLY_KEYS.items():
        src = case_reducer if not sub else case_reducer.get(sub, {})
        dst = out if not sub else out[sub]
        for k in keys:
            if src.get(k) is not None:
                dst[k] = src[k]
    return out


def stage_section(sec: ReducerSection):
    """The ``cycloid_stage`` kind's ``[stage]`` section of the reducer's cycloid–pin stage: the
    one mapping of the RV description to the stage, built by that kind's one builder
    (:func:`gearte.studies.cycloid_stage.build_stage`; the reducer object's own stage,
    :func:`gearte.models.rv_load_sharing.cycloid_stage`, is the same:
    tests/test_families.py).

    Parameters
    ----------
    sec : ReducerSection
        The validated ``[reducer]`` table.
    """
    from gearte.studies import cycloid_stage as cs

    return cs.Stage(
        pins=sec.pins.count,
        cycloid_teeth=sec.pins.count - 1,
        pin_circle_radius_mm=sec.pins.circle_radius_mm,
        pin_radius_mm=sec.pins.pin_radius_mm,
        eccentricity_mm=sec.cranks.eccentricity_mm,
        face_width_mm=sec.discs.face_width_mm,
        equidistant_modification_mm=sec.discs.equidistant_modification_mm,
        shifted_modification_mm=sec.discs.shift_modification_mm,
    )


def plausibility(case: Case) -> list[tuple[str, float, str]]:
    """``(field, torque [N·m], reason)`` for each torque of the case (rated, operation, an
    analysis's ``torque_Nm``) that no steel pin contact of this stage could carry
    (:func:`gearte.io.plausibility.torque_problem`), the stage built by the one builder
    (:func:`stage_section`).

    Parameters
    ----------
    case : Case
        The validated case (sections may be placeholders: gearte.io.plausibility).
    """
    from gearte.io.plausibility import torque_problem
    from gearte.studies.cycloid_stage import build_stage

    r = case.reducer
    stage = build_stage(stage_section(r))
    E, nu, share = r.discs.youngs_modulus_MPa, r.discs.poisson_ratio, 1.0 / r.discs.count
    torques: list[tuple[str, float, float]] = []
    if r.rated_torque_Nm is not None:
        torques.append(("reducer.rated_torque_Nm", r.rated_torque_Nm, share))
    if case.operation is not None:
        torques.append(("operation.output_torque_Nm", case.operation.output_torque_Nm, share))
    for name in type(case.analyses).model_fields:
        sec = getattr(case.analyses, name)
        value = getattr(sec, "torque_Nm", None)
        if isinstance(value, int | float) and not isinstance(value, bool):
            key = type(case.analyses).model_fields[name].alias or name
            torques.append(
                (f"analyses.{key}.torque_Nm", float(value), getattr(sec, "disc_share", share))
            )
    out = []
    for field, value, s in torques:
        got = torque_problem(field, value, stage, s, E, nu)
        if got:
            out.append(got)
    return out


def _first_bearing_load(sec: ReducerSection) -> float:
    """First estimate of a crank bearing's load at rated torque [N]: ``T / (M R_dc)``, the
    tangential force one crank passes to the carrier (1 kN without a rated torque: the case
    check refuses ``at_rated_torque`` then)."""
    if sec.rated_torque_Nm is None:
        return 1.0e3
    return float(Nm_to_Nmm(sec.rated_torque_Nm)) / (sec.cranks.count * sec.cranks.circle_radius_mm)


def _at_operating_load(red: RVReducer, sec: ReducerSection, tol: float = 1e-4) -> RVReducer:
    """``red`` with the ``at_rated_torque`` crank bearings linearised at their largest radial
    load at rated torque over 36 output positions of the error-free design (a property of the
    design: the measured errors of one reducer do not change its bearings' stiffness): a fixed
    point (the load sharing depends on the stiffnesses it sets; Palmgren's stiffness grows as
    ``F^0.1``, so it contracts in a few steps), to a relative load change below ``tol``.

    Raises
    ------
    ParameterError
        No rated torque (``reducer.rated_torque_Nm``).
    """
    import dataclasses

    from gearte.models.rv_load_sharing import load_sharing, output_positions

    if red.rated_torque is None:
        raise ParameterError(
            "reducer.rated_torque_Nm", None, "needed by a bearing linearised at_rated_torque"
        )
    torque = float(red.rated_torque)
    c = sec.cranks
    theta = output_positions(36)
    f0 = _first_bearing_load(sec)
    loads = {"cam": f0, "carrier": f0}
    for _ in range(30):
        cranks = dataclasses.replace(
            red.cranks,
            cam_bearing_stiffness=c.cam_bearing.stiffness(
                loads["cam"] if c.cam_bearing.at_rated_torque else None
            ),
            carrier_bearing_stiffness=c.carrier_bearing.stiffness(
                loads["carrier"] if c.carrier_bearing.at_rated_torque else None
            ),
        )
        red = red.replace(cranks=cranks)
        nominal = red.replace(  # no errors of any kind: the design
            pins=dataclasses.replace(
                red.pins,
                radius_errors=np.zeros(0),
                radial_position_errors=np.zeros(0),
                tangential_position_errors=np.zeros(0),
            ),
            errors=ManufacturingErrors.none(c.count, sec.discs.count),
        )
        ls = load_sharing(nominal, torque, theta)
        new = {
            "cam": float(ls.cam_bearing_load.max()),
            "carrier": float(ls.carrier_bearing_load.max()),
        }
        if all(abs(new[k] - loads[k]) <= tol * loads[k] for k in loads):
            return red
        loads = new
    raise ConvergenceError(
        f"bearing loads at rated torque did not settle: {loads} N (at_rated_torque bearings)"
    )


def _chain_inputs(sec: ReducerSection) -> dict[str, Any]:
    """The stiffness-chain elements of the description, given or derived (None: left out).

    Returns the crank bending compliance per disc [mm/N], the crank torsional stiffness
    [N·mm/rad], the pin seat compliance [mm/N], the pin bending compliance per disc [mm/N] and
    the output flange's torsional stiffness [N·mm/rad] (:mod:`gearte.models.rv_stiffness`).
    """
    from gearte.models.rv_stiffness import (
        beam_point_compliance,
        disc_load_positions,
        ideal_peak_pin_force,
        pin_seat_stiffness,
        shaft_torsional_stiffness,
    )

    c, d, p, s = sec.cranks, sec.discs, sec.pins, sec.supports
    E, nu = d.youngs_modulus_MPa, d.poisson_ratio
    shaft = float("nan") if c.shaft_diameter_mm is None else c.shaft_diameter_mm  # checked
    out: dict[str, Any] = dict.fromkeys(
        ("crank_bending", "crank_torsion", "pin_seat", "pin_bending", "output_flange")
    )

    def span_positions(key: str, span: float) -> np.ndarray:
        try:
            return disc_load_positions(span, d.count, d.face_width_mm)
        except ParameterError as exc:
            raise ParameterError(key, span, exc.reason) from None

    if c.bearing_span_mm is not None:
        a = span_positions("reducer.cranks.bearing_span_mm", c.bearing_span_mm)
        cb = beam_point_compliance(c.bearing_span_mm, a, shaft, E, nu)
        out["crank_bending"] = tuple(float(x) for x in cb)
    elif c.bending_stiffness_N_per_mm is not None:
        out["crank_bending"] = (1.0 / c.bending_stiffness_N_per_mm,) * d.count
    if c.torsion_length_mm is not None:
        out["crank_torsion"] = float(shaft_torsional_stiffness(shaft, c.torsion_length_mm, E, nu))
    elif c.torsional_stiffness_Nm_per_rad is not None:
        out["crank_torsion"] = c.torsional_stiffness_Nm_per_rad * NM_PER_RAD_TO_NMM_PER_RAD
    if p.seat_length_mm is not None:
        if sec.rated_torque_Nm is None:  # refused by Case._inputs, naming both keys
            return out
        k1 = c.eccentricity_mm * p.count / (p.circle_radius_mm + d.shift_modification_mm)
        if not 0.0 < k1 < 1.0:  # RVReducer refuses it next, naming cranks.eccentricity
            return out
        force = ideal_peak_pin_force(
            Nm_to_Nmm(sec.rated_torque_Nm), 1.0 / d.count, k1, p.count - 1, p.circle_radius_mm
        )
        out["pin_seat"] = 1.0 / float(pin_seat_stiffness(force, p.seat_length_mm))
    elif p.seat_stiffness_N_per_mm is not None:
        out["pin_seat"] = 1.0 / p.seat_stiffness_N_per_mm
    if p.support_span_mm is not None:
        a = span_positions("reducer.pins.support_span_mm", p.support_span_mm)
        pb = beam_point_compliance(p.support_span_mm, a, 2.0 * p.pin_radius_mm, E, nu)
        out["pin_bending"] = tuple(float(x) for x in pb)
    elif p.bending_stiffness_N_per_mm is not None:
        out["pin_bending"] = (1.0 / p.bending_stiffness_N_per_mm,) * d.count
    if s.output_flange_torsional_stiffness_Nm_per_rad is not None:
        out["output_flange"] = (
            s.output_flange_torsional_stiffness_Nm_per_rad * NM_PER_RAD_TO_NMM_PER_RAD
        )
    return out


def chain_sources(sec: ReducerSection) -> dict[str, str]:
    """Element of the stiffness chain → ``"given"``, ``"derived: <how>"`` or ``"left out"``."""
    c, p, s, fs = sec.cranks, sec.pins, sec.supports, sec.first_stage

    def pick(derived: Any, how: str, given: Any) -> str:
        if derived is not None:
            return f"derived: {how}"
        return "given" if given is not None else "left out"

    return {
        "output_flange": "given"
        if s.output_flange_torsional_stiffness_Nm_per_rad is not None
        else "left out",
        "main_bearing": "given" if s.main_bearing is None else s.main_bearing.source(),
        "carrier_bearing": c.carrier_bearing.source(),
        "crank_bending": pick(
            c.bearing_span_mm,
            "simply supported crank (Roark, bending + shear), cams centred in bearing_span_mm",
            c.bending_stiffness_N_per_mm,
        ),
        "cam_bearing": c.cam_bearing.source(),
        "pin_contact": f"contact law '{sec.contact_law}'",
        "pin_seat": pick(
            p.seat_length_mm,
            "Palmgren line contact in the groove, tangent at the largest ideal pin force at "
            "rated torque (Hu 2020 eq 30)",
            p.seat_stiffness_N_per_mm,
        ),
        "pin_bending": pick(
            p.support_span_mm,
            "simply supported pin (Roark, bending + shear), discs centred in support_span_mm",
            p.bending_stiffness_N_per_mm,
        ),
        "crank_torsion": pick(
            c.torsion_length_mm, "G J / L over torsion_length_mm", c.torsional_stiffness_Nm_per_rad
        ),
        "first_stage_mesh": "given"
        if fs.mesh_stiffness_N_per_mm is not None
        else "derived: ISO 6336 c_gamma b",
        "sun_support": "given",
    }


def build_stage_case(case: Case):
    """The ``cycloid_stage`` case of the reducer's cycloid–pin stage (same geometry, same errors).

    The reducer's cycloid analyses (geometric TE, sensitivity, tooth contact, compensation) run
    through the ``cycloid_stage`` kind on this case, so both kinds build the same
    :class:`~gearte.geometry.cycloid.CycloidStage` from the same numbers.
    """
    from gearte.studies import cycloid_stage as cs

    r, a = case.reducer, case.analyses
    stage = stage_section(r)
    tc = None
    if a.tooth_contact is not None:
        t = a.tooth_contact
        if r.contact_law not in ("line_contact", "hu2020"):
            raise ParameterError(
                "reducer.contact_law",
                r.contact_law,
                "analyses.tooth_contact (the cycloid-stage tooth contact) solves 'line_contact' "
                "and 'hu2020' only; select one of them or drop [analyses.tooth_contact]",
            )
        tc = cs.ToothContactOptions(
            torque_Nm=t.torque_Nm,
            disc_share=t.disc_share,
            youngs_modulus_MPa=r.discs.youngs_modulus_MPa,
            poisson_ratio=r.discs.poisson_ratio,
            mesh_positions=t.mesh_positions,
            start_force_N=t.start_force_N,
            clearance_model=t.clearance_model,
            contact_law=r.contact_law,
            allowable_contact_pressure_MPa=r.allowable_contact_pressure_MPa,
        )
    return cs.Case(
        case=case.case.model_copy(update={"kind": "cycloid_stage"}),
        stage=stage,
        errors=r.cycloid_errors if r.cycloid_errors is not None else cs.Errors(),
        analyses=cs.Analyses(
            geometric_te=a.geometric_te,
            tooth_contact=tc,
            compensation=a.cycloid_compensation,
        ),
    )


# ------------------------------------------------------------------------------------------
# Run
# ------------------------------------------------------------------------------------------
def _load_sharing(red, red0, sec: LoadSharingSection, law) -> AnalysisResult:
    from gearte.models.cycloid_contact import tooth_contact
    from gearte.models.rv_load_sharing import (
        cycloid_stage,
        load_sharing,
        output_positions,
        peak_pin,
    )

    th = output_positions(sec.positions)
    T = Nm_to_Nmm(sec.torque_Nm)
    ls = load_sharing(red, T, th, law=law)
    has_errors = red0 is not None
    p_peak = np.unravel_index(np.argmax(ls.pin_force), ls.pin_force.shape)
    pk = peak_pin(red, ls)
    values = {
        "peak_pin_load [N]": ls.peak_pin_load,
        "max_contact_pressure [MPa]": ls.max_contact_pressure,
        "contact_law": ls.contact_law,
        "contact_law_form": law.describe() if hasattr(law, "describe") else ls.contact_law,
        "peak_pin": f"disc {pk.disc}, pin {pk.pin}",
        "peak_pin_angle_from_line_of_centres [deg]": abs(float(rad_to_deg(pk.phase))),
        "peak_pin_force_angle_from_radial [deg]": float(rad_to_deg(pk.force_angle_from_radial)),
        "pairs_in_mesh_min": int(ls.pairs_in_mesh.min()),
        "pairs_in_mesh_max": int(ls.pairs_in_mesh.max()),
        "pairs_in_mesh_at_peak": int(ls.pairs_in_mesh[p_peak[0], p_peak[1]]),
        "output_angle_at_peak [deg]": float(rad_to_deg(th[p_peak[0]])),
        "max_cam_bearing_load [N]": float(ls.cam_bearing_load.max()),
        "max_carrier_bearing_load [N]": float(ls.carrier_bearing_load.max()),
        "max_mesh_force [N]": float(np.abs(ls.mesh_force).max()),
        "disc_torque_share_range": [
            float((ls.disc_torque / ls.disc_torque.sum(axis=1, keepdims=True)).min()),
            float((ls.disc_torque / ls.disc_torque.sum(axis=1, keepdims=True)).max()),
        ],
    }
    if pk.root_squeeze:
        values["root_squeeze_warning"] = (
            f"the peak pin load is a radial squeeze at the tooth root, near the line of centres "
            f"({pk.describe()}; less than half of its force turns the disc): the load there "
            "depends on the root geometry and on the pin-contact law more than on the torque path"
        )
    from gearte.models.rv_stiffness_chain import left_out_elements

    left_out = left_out_elements(red)
    values["stiffness_chain_left_out"] = ", ".join(e.replace("_", " ") for e in left_out) or "none"
    data = {"load": ls}
    notes = [
        "Pin loads from the quasi-static equilibrium of all parts (springs + unilateral pin "
        f"contacts with the '{ls.contact_law}' load-dependent stiffness), one output revolution; "
        "max_contact_pressure: Hertz line-contact pressure of each pin with its own flank "
        "curvature. Pin seat and pin bending are in series with each pin contact, crank bending "
        "with the cam bearings, crank torsion with the mesh (docs/rv-stiffness-chain.md)"
        + (
            f"; left out (rigid: the case describes neither): {', '.join(left_out)}."
            if left_out
            else "."
        ),
    ]
    if has_errors and sec.compare_without_errors:
        ls0 = load_sharing(red0, T, th, law=law)
        values.update(
            {
                "peak_pin_load_without_errors [N]": ls0.peak_pin_load,
                "peak_pin_load_increase [%]": 100.0 * (ls.peak_pin_load / ls0.peak_pin_load - 1),
                "pairs_in_mesh_without_errors_min": int(ls0.pairs_in_mesh.min()),
                "pairs_in_mesh_without_errors_max": int(ls0.pairs_in_mesh.max()),
            }
        )
        data["load_without_errors"] = ls0
    # the cycloid-stage contact analysis (issue 2) of one disc with the same law and torque share
    st = cycloid_stage(red)
    share = (1.0 - 1.0 / red.ratio) * red.cycloid_teeth / red.pins.count / red.discs.count
    try:
        tc = tooth_contact(
            st,
            T,
            disc_share=share,
            mesh_angle=np.linspace(0, 2 * np.pi / red.pins.count, 9),
            E=red.discs.youngs_modulus,
            mu=red.discs.poisson_ratio,
            contact_law=ls.contact_law,
        )
        values["peak_pin_load_cycloid_stage_analysis [N]"] = float(tc.force.max())
        notes.append(
            "peak_pin_load_cycloid_stage_analysis: one disc alone (centre fixed, rigid "
            "supports, no errors, moment T (1 - 1/i) z_c/(z_p N)) — the cycloid_stage contact law."
        )
    except (ParameterError, ConvergenceError) as exc:  # pragma: no cover - reported, not fatal
        notes.append(f"cycloid-stage comparison not available: {exc}")
    return AnalysisResult(
        name="load_sharing",
        title="Pin load sharing over one output revolution",
        values=values,
        references=["han2023", "hu2020"],
        notes=notes + ["pin_loads.csv: the load of every pin on every disc at every position."],
        data=data,
        files={"pin_loads.csv": _pin_csv(ls)},
    )


def _pin_csv(ls) -> str:
    """Pin-load table: one row per output angle and disc, one column per pin [N]."""
    zp = ls.pin_force.shape[2]
    lines = ["output_angle [deg],disc," + ",".join(f"pin_{k + 1} [N]" for k in range(zp))]
    for p, th in enumerate(rad_to_deg(ls.theta)):
        for j in range(ls.pin_force.shape[1]):
            vals = ",".join(f"{v:.3f}" for v in ls.pin_force[p, j])
            lines.append(f"{th:.4f},{j + 1},{vals}")
    return "\n".join(lines) + "\n"


def _transmission_error(red, sec: TESection, law) -> AnalysisResult:
    from gearte.models.rv_load_sharing import output_positions, transmission_error

    th = output_positions(sec.positions)
    te = transmission_error(
        red, Nm_to_Nmm(sec.torque_Nm), th, zero_load_fraction=sec.zero_load_fraction, law=law
    )
    pp = te.peak_to_peak
    values = {
        "total_te_peak_to_peak [arcsec]": rad_to_arcsec(te.total_pp),
        "geometric_te_peak_to_peak [arcsec]": rad_to_arcsec(te.geometric_pp),
        "elastic_te_peak_to_peak [arcsec]": rad_to_arcsec(te.elastic_pp),
        "total_te_peak_to_peak_sampled [arcsec]": rad_to_arcsec(pp(te.total)),
        "mean_output_lag [arcmin]": rad_to_arcmin(-float(te.total.mean())),
        "mean_geometric_lag [arcmin]": rad_to_arcmin(-float(te.geometric.mean())),
        "mean_elastic_lag [arcmin]": rad_to_arcmin(-float(te.elastic.mean())),
        "output_angle [deg]": rad_to_deg(th),
        "total_te [arcsec]": rad_to_arcsec(te.total),
        "geometric_te [arcsec]": rad_to_arcsec(te.geometric),
        "contact_law": red.discs.contact_law,
    }
    return AnalysisResult(
        name="transmission_error",
        title="Loaded output angle error (total TE) and its geometric and elastic parts",
        values=values,
        references=["hu2020", "han2023"],
        notes=[
            "TE = actual − nominal output angle with the input held at its kinematic position; "
            "negative = output lags. Geometric part: solved at zero_load_fraction × torque "
            "(clearances closed, errors and the preload they cause included); elastic = total − "
            "geometric. Peak-to-peak over one output revolution: the sampled positions plus one "
            "finely resolved mesh period (2π/(z_p z_c)) around each extreme, because the mesh "
            "ripple has z_p z_c cycles per revolution and is aliased by uniform sampling.",
        ],
        data={"te": te},
        files={"transmission_error.csv": _te_csv(te)},
    )


def _te_csv(te) -> str:
    rows = ["output_angle [deg],total_te [arcsec],geometric_te [arcsec],elastic_te [arcsec]"]
    for th, t, g, e in zip(
        rad_to_deg(te.theta),
        rad_to_arcsec(te.total),
        rad_to_arcsec(te.geometric),
        rad_to_arcsec(te.elastic),
        strict=True,
    ):
        rows.append(f"{th:.4f},{t:.6f},{g:.6f},{e:.6f}")
    return "\n".join(rows) + "\n"


def _catalogue(red, sec: CatalogueSection, law, fs_terms=None, sources=None) -> AnalysisResult:
    from gearte.models.rv_catalogue import catalogue_values
    from gearte.models.rv_first_stage import catalogue_with_free_angle, output_free_angle
    from gearte.models.rv_stiffness_chain import stiffness_chain

    cat = catalogue_values(
        red,
        theta=deg_to_rad(sec.position_deg),
        turning_points=sec.torque_sweep,
        steps_per_segment=sec.steps_per_segment,
        lost_motion_fraction=sec.lost_motion_fraction,
        law=law,
    )
    fs_values: dict[str, Any] = {"first_stage_backlash": sec.first_stage_backlash}
    fs_notes = []
    if fs_terms is not None and sec.first_stage_backlash == "additive":
        r, i = fs_terms["r_sun"], float(red.ratio)
        free = {
            k: float(output_free_angle(um_to_mm(np.asarray(v)), r, i))
            for k, v in fs_terms["backlash_um"].items()
        }
        base = cat
        cat = catalogue_with_free_angle(
            base, free["mid"], float(red.rated_torque), sec.lost_motion_fraction
        )
        fs_values["first_stage_backlash_at_output [arcmin]"] = rad_to_arcmin(free["mid"])
        if free["min"] != free["max"]:
            for tag in ("min", "max"):
                c = catalogue_with_free_angle(
                    base, free[tag], float(red.rated_torque), sec.lost_motion_fraction
                )
                fs_values[f"first_stage_backlash_at_output_{tag} [arcmin]"] = rad_to_arcmin(
                    free[tag]
                )
                fs_values[f"lost_motion_{tag} [arcmin]"] = rad_to_arcmin(c.lost_motion)
                fs_values[f"backlash_{tag} [arcmin]"] = rad_to_arcmin(c.backlash)
        fs_notes.append(
            "First-stage backlash added (first_stage_backlash = 'additive'): the output turns "
            "freely by min_k j_t,k / (r_sun i) (the cranks turn together, the smallest sun–planet "
            "gap stops them; gaps centred on the model's contact), a dead zone of the torsion "
            "curve: lost motion, backlash and hysteresis loss grow by it, rigidity does not. With "
            "tooth-thickness classes the values are at the class midpoints, _min/_max at the "
            "limits (docs/tolerance_grades.md)."
        )
    elif fs_terms is None:
        fs_notes.append(
            "The first stage's backlash is not in these values: the case gives no first-stage "
            "tooth-thickness classes or backlash_um (the model's sun–planet mesh has no "
            "clearance)."
        )
    values = {
        "torsional_rigidity [N*m/arcmin]": Nmm_per_rad_to_Nm_per_arcmin(cat.torsional_rigidity),
        "lost_motion [arcmin]": rad_to_arcmin(cat.lost_motion),
        "backlash [arcmin]": rad_to_arcmin(cat.backlash),
        "hysteresis_loss [arcmin]": rad_to_arcmin(cat.hysteresis_loss),
        "rated_torque [N*m]": None if red.rated_torque is None else Nmm_to_Nm(red.rated_torque),
        **fs_values,
        "contact_law": red.discs.contact_law,
    }
    chain = stiffness_chain(red, theta=deg_to_rad(sec.position_deg), law=law)
    values["tangent_rigidity_at_rated [N*m/arcmin]"] = Nmm_per_rad_to_Nm_per_arcmin(chain.rigidity)
    values["compliance_shares"] = chain.shares
    values["stiffness_chain_left_out"] = (
        ", ".join(e.replace("_", " ") for e in chain.left_out) or "none"
    )
    values["cam_bearing_load_at_rated [N]"] = chain.cam_bearing_load
    values["carrier_bearing_load_at_rated [N]"] = chain.carrier_bearing_load
    if sources is not None:
        values["stiffness_sources"] = sources
    chain_notes = [
        "compliance_shares: each element's share of the tangent output torsional compliance at "
        "rated torque (its share of the strain energy of a torque increment; sum 1), "
        "tangent_rigidity_at_rated its inverse (docs/rv-stiffness-chain.md). Pin seat and pin "
        "bending act in series with each pin contact, crank bending with each cam bearing, "
        "crank torsion with the sun–planet mesh, the output flange with the output rotation: "
        "all in the load-sharing solve and in the torsion test."
    ]
    if chain.left_out:
        chain_notes.append(
            "Left out of the stiffness chain (rigid: the case gives neither the element's data "
            "nor its stiffness): " + ", ".join(chain.left_out) + "."
        )
    return AnalysisResult(
        name="catalogue",
        title="Catalogue quantities from a virtual torsion test (input locked)",
        values=values,
        references=[],
        data={"catalogue": cat, "stiffness_chain": chain},
        notes=[
            *chain_notes,
            "Definitions as in the Nabtesco RV catalogue: rigidity = (T_r/2)/(θ(T_r) − θ(T_r/2)) "
            "averaged over both directions; lost motion = θ(+3% T_r) − θ(−3% T_r) at the "
            "curve midpoints; backlash = θ(0+) − θ(0−).",
            "The model is frictionless: loading and unloading branches coincide outside the "
            "backlash, so hysteresis loss = backlash.",
            *fs_notes,
        ],
    )


def _compensation(red, sec: CompensationSection) -> AnalysisResult:
    from gearte.models.rv_compensation import compensate

    bounds = {
        k: (um_to_mm(v[0]), um_to_mm(v[1]))
        for k, v in sec.bounds_um.model_dump().items()
        if v is not None
    }
    comp = compensate(
        red,
        Nm_to_Nmm(sec.torque_Nm),
        bounds,
        min_backlash=arcmin_to_rad(sec.min_backlash_arcmin),
        objective=sec.objective,
        positions=sec.positions,
        grid=sec.grid,
    )
    values: dict[str, Any] = {
        "changes [um]": {k: mm_to_um(v) for k, v in comp.after.changes.items()}
    }
    for tag, dp in (("before", comp.before), ("after", comp.after)):
        values.update(
            {
                f"total_te_peak_to_peak_{tag} [arcsec]": rad_to_arcsec(dp.total_te_peak_to_peak),
                f"mean_output_lag_{tag} [arcmin]": rad_to_arcmin(dp.mean_lag),
                f"backlash_{tag} [arcmin]": rad_to_arcmin(dp.backlash),
                f"peak_pin_load_{tag} [N]": dp.peak_pin_load,
                f"pairs_in_mesh_min_{tag}": dp.pairs_in_mesh_min,
                f"pairs_in_mesh_max_{tag}": dp.pairs_in_mesh_max,
            }
        )
    values["model_evaluations"] = comp.evaluations
    values["contact_law"] = red.discs.contact_law
    return AnalysisResult(
        name="compensation",
        title="Compensation of the total TE through the model",
        values=values,
        references=["hu2020"],
        notes=[
            f"Minimises {sec.objective} at {sec.torque_Nm} N·m subject to backlash >= "
            f"{sec.min_backlash_arcmin} arcmin over the given ranges (grid + compass search).",
        ],
        data={"compensation": comp},
    )


def load_dynamic_model(name: str):
    """The dynamic model and the reducer of a bundled or given ``rv_reducer`` case (benchmarks,
    tests): ``(RVDynamicModel, RVReducer)``.

    Parameters
    ----------
    name : str
        A bundled case name or a path to a case file.
    """
    from gearte.io.case_file import load_case

    case: Any = load_case(name)  # an rv_reducer Case
    red = build_reducer(case.reducer)
    return dyn.build_dynamic_model(case, red)[0], red


def _cycloid_analyses(case: Case, options) -> tuple[list[AnalysisResult], list[str]]:
    """Geometry, geometric TE, tooth contact and compensation of the cycloid stage.

    Run by the ``cycloid_stage`` kind on :func:`build_stage_case`; the stage's compensation is
    reported as ``cycloid_compensation`` beside the whole reducer's ``compensation``.
    """
    from dataclasses import replace

    from gearte.studies import cycloid_stage as cs

    res = cs.run(build_stage_case(case), options)
    out = []
    for a in res.analyses:
        if a.name == "compensation":
            a = replace(a, name="cycloid_compensation")
        out.append(a)
    return out, list(res.warnings)


def preflight(case: Case) -> None:
    """The checks :func:`run` makes on the built reducer, before any analysis (called by
    ``gearte validate`` and by :func:`gearte.studies.run_case`): the dynamic model's derived
    masses (density), its elastic modes and RK4 step budgets
    (:func:`_rv_dynamics.preflight_dynamics`); the tooth contact at the paper's mesh position
    (:func:`gearte.studies.cycloid_stage.preflight` of :func:`build_stage_case`, which the
    cycloid analyses run on); the yield's tolerance and cost keys against the
    reducer's error keys (:func:`~gearte.studies._yield.yield_inputs`).

    Raises
    ------
    ParameterError
        Naming the key of the first failing check.
    """
    a = case.analyses
    if a.yield_ is not None:
        from gearte.studies._yield import yield_inputs

        # the reducer the yield reads: the design without the case's errors
        red0 = build_reducer(case.reducer, with_errors=not case.reducer.errors)
        families, defaults, units = _yield_keys(case, red0, a.yield_)
        model, _ = _yield_model(case, red0, a.yield_)
        yield_inputs(a.yield_, units, {}, defaults, families, _grade_um(case), model.quantities)
    if any(getattr(a, k) is not None for k in dyn.ANALYSES):
        dyn.preflight_dynamics(case, build_reducer(case.reducer))
    if a.tooth_contact is not None:  # the cycloid analyses run as a cycloid_stage case
        from gearte.studies import cycloid_stage as cs

        cs.preflight(build_stage_case(case))


def run(case: Case, options=None, *, reducer: RVReducer | None = None) -> StudyResult:
    """Run the analyses a case asks for; every one reads the same :class:`RVReducer`.

    ``reducer`` replaces the one the case describes (a measured serial, ``rv_serial``); its
    errors are compared with the design's errors removed.

    Parameters
    ----------
    case : Case
        The validated case.
    options : RunOptions, optional
        Execution options (workers, scheduler, progress).

    Returns
    -------
    StudyResult
        The analyses and warnings.
    """
    from gearte.models.rv_load_sharing import contact_law

    red = build_reducer(case.reducer) if reducer is None else reducer
    has_errors = bool(case.reducer.errors) or reducer is not None
    red0 = build_reducer(case.reducer, with_errors=False) if has_errors else None
    law = contact_law(red)  # the reducer's own law (reducer.contact_law of the case)
    a = case.analyses
    out: list[AnalysisResult] = []
    warnings: list[str] = []
    # the dynamics and the cycloid analyses run first and are reported last: their figures (the
    # DTE, its spectrum, the trajectories; the profile, the sensitivities, the tooth contact)
    # are the costliest to draw, and the report process of `gearte run` draws each analysis's
    # figures while the next analyses run (gearte.report.background), here the quasi-static
    # ones (the compensation: tenths of a second)
    dynamics: tuple[list[AnalysisResult], list[str]] = ([], [])
    if any(getattr(a, k) is not None for k in dyn.ANALYSES):
        dynamics = dyn.run_dynamics(case, red, options)
    cycloid: tuple[list[AnalysisResult], list[str]] = ([], [])
    if any(getattr(a, k) is not None for k in ("geometric_te", "tooth_contact")) or (
        a.cycloid_compensation is not None
    ):
        cycloid = _cycloid_analyses(case, options)
    if a.load_sharing is not None:
        out.append(_load_sharing(red, red0, a.load_sharing, law))
    if a.transmission_error is not None:
        out.append(_transmission_error(red, a.transmission_error, law))
    if a.catalogue is not None:
        out.append(
            _catalogue(
                red,
                a.catalogue,
                law,
                first_stage_terms(case.reducer.first_stage),
                chain_sources(case.reducer),
            )
        )
    if a.compensation is not None:
        out.append(_compensation(red, a.compensation))
    if a.yield_ is not None:
        out.append(_yield(case, red0 if red0 is not None else red, a.yield_, options))
    if case.reducer.first_stage.sun_tooth_thickness_allowance is not None:
        out.append(_first_stage_backlash(case, red))
    out += cycloid[0] + dynamics[0]
    warnings += cycloid[1] + dynamics[1]
    for r in out:  # each says its law when it is made (a result is streamed to the report then)
        if r.name in ("load_sharing", "transmission_error", "catalogue", "compensation"):
            if r.values.get("contact_law") != case.reducer.contact_law:
                r.values["contact_law"] = case.reducer.contact_law
            r.values.setdefault("contact_law_form", law.describe())
    for r in out:
        if r.name == "load_sharing" and r.values.get("root_squeeze_warning"):
            warnings.append(f"load_sharing: {r.values['root_squeeze_warning']}")
    if not out:
        warnings.append("no analyses requested: add [analyses.load_sharing] etc.")
    allowable = case.reducer.allowable_contact_pressure_MPa
    for r in out:
        p = r.values.get("max_contact_pressure [MPa]")
        if allowable is not None and p is not None:
            r.values["allowable_contact_pressure [MPa]"] = allowable  # the report checks it
        if allowable is not None and p is not None and p > allowable:
            warnings.append(
                f"{r.name}: max_contact_pressure {p:.0f} MPa exceeds "
                f"reducer.allowable_contact_pressure_MPa = {allowable:g} MPa"
            )
    return StudyResult(case=case, analyses=out, warnings=warnings)


def _yield_keys(case: Case, red, sec: RVYieldSection) -> tuple[dict, dict, dict]:
    """``(families, defaults, units)`` of the reducer's yield: the error keys of ``red`` (and of
    the first stage's backlash when it is additive), the tolerances its classes imply, µm each."""
    from gearte.runners.yield_models import rv_error_keys

    families = rv_error_keys(red)
    fs_terms = first_stage_terms(case.reducer.first_stage)
    defaults: dict[str, Any] = {}
    if fs_terms is not None and sec.first_stage_backlash == "additive":
        from gearte.runners.rv_first_stage_yield import first_stage_error_keys
        from gearte.studies._yield import ToleranceEntry

        fs_keys = first_stage_error_keys(case.reducer.first_stage.planets)
        families = {**families, **fs_keys}
        for key, (lo, hi) in fs_terms["limits_um"].items():
            # a class is a drawing limit: truncated normal, 3σ = half its width, cut there
            defaults[key] = ToleranceEntry(
                kind="truncated_normal", tolerance_um=0.5 * (hi - lo), nominal_um=0.5 * (lo + hi)
            )
    units = {k: "um" for k in families} | {k: "um" for v in families.values() for k in v}
    return families, defaults, units


def _grade_um(case: Case):
    """The ``grade_um(key, grade)`` argument of the reducer's yield
    (:func:`~gearte.studies._yield.yield_analysis`)."""

    def grade_um(key: str, grade: int):
        """planet_base_circle / sun_eccentricity: eccentricity tolerance F_rT/2 of the planet /
        sun gear (ISO 1328-1:2013), reported with its derivation."""
        from gearte.studies._yield import eccentricity_grade_tolerance

        fs = case.reducer.first_stage
        gear = {"planet_base_circle": ("planet", fs.planet_teeth)}
        gear["sun_eccentricity"] = ("sun", fs.sun_teeth)
        if key.split(".")[0] not in gear:
            return None
        name, z = gear[key.split(".")[0]]
        field = f"analyses.yield.tolerances.{key}.grade"
        return eccentricity_grade_tolerance(field, grade, name, z, fs.module_mm, "first stage's ")

    return grade_um


def _yield_model(case: Case, red, sec: RVYieldSection):
    """The yield model of ``[analyses.yield]`` (:class:`RVReducerYield`, wrapped in a
    :class:`FirstStageBacklashYield` when the first stage's backlash is added) and that wrapper
    (or ``None``); nothing is evaluated."""
    from gearte.runners.yield_models import RVReducerYield

    model = RVReducerYield(
        build_reducer(case.reducer),
        positions=sec.positions,
        te_torque=None if sec.te_torque_Nm is None else float(Nm_to_Nmm(sec.te_torque_Nm)),
    )
    fs_terms = first_stage_terms(case.reducer.first_stage)
    if fs_terms is not None and sec.first_stage_backlash == "additive":
        from gearte.runners.rv_first_stage_yield import FirstStageBacklashYield

        fs_model = FirstStageBacklashYield(
            model,
            fs_terms["given_um"],
            fs_terms["r_sun"],
            float(red.ratio),
            fs_terms["alpha"],
            nominal_um=fs_terms["nominal_um"],
        )
        return fs_model, fs_model
    return model, None


def _grid_check(case: Case, red, sec: RVYieldSection):
    """The grid check of the TE's output positions: the same yield model at
    ``grid_check_factor × positions`` (:class:`~gearte.studies._yield.GridCheck`), or ``None``."""
    from gearte.runners.yield_models import RVReducerYield
    from gearte.studies._yield import GridCheck

    fine = sec.positions * sec.grid_check_factor
    if sec.grid_check_samples == 0 or sec.grid_check_factor < 2:
        return None
    finer = sec.model_copy(update={"positions": fine})
    return GridCheck(
        refined=lambda: _yield_model(case, red, finer)[0],
        positions=sec.positions,
        refined_positions=fine,
        samples=sec.grid_check_samples,
        quantities=RVReducerYield.grid_quantities,
        te="angular_te [arcmin]",
    )


def _yield(case: Case, red, sec: RVYieldSection, options) -> AnalysisResult:
    """``[analyses.yield]``: each sample one assembled reducer (errors drawn from the
    tolerances; errors without a tolerance keep the case's values) → catalogue test, angular TE
    over one output revolution, peak pin load; yield against ``[analyses.yield.spec]``."""
    from gearte.studies._yield import yield_analysis

    model, fs_model = _yield_model(case, red, sec)
    families, defaults, units = _yield_keys(case, red, sec)

    def worst_case(errors):
        """The worst sample's case: its reducer (the yield model's, built for the drawn errors)
        written back by :func:`reducer_section` (the family's ``to_sections``), the keys the
        reducer object does not hold taken from the case, the first stage's drawn backlash as
        ``backlash_um``."""
        d = case.model_dump(mode="json", by_alias=True, exclude_none=True)
        inner = model if fs_model is None else fs_model.inner
        d["reducer"] = with_case_keys(reducer_section(inner.reducer_for(errors)), d["reducer"])
        te_torque = sec.te_torque_Nm or case.reducer.rated_torque_Nm
        if fs_model is not None and any(k.startswith("first_stage.") for k in errors):
            fsd = d["reducer"]["first_stage"]
            for k in (
                "sun_tooth_thickness_allowance",
                "planet_tooth_thickness_allowance",
                "centre_distance_allowance",
            ):
                fsd.pop(k, None)
            fsd["backlash_um"] = fs_model.mesh_backlash_um(errors)
        d["analyses"] = {
            "catalogue": {"lost_motion_fraction": 0.03},
            "transmission_error": {"torque_Nm": te_torque, "positions": max(8, sec.positions)},
        }
        return d

    res = yield_analysis(
        sec,
        model,
        units,
        {},
        options=options,
        worst_case=worst_case,
        references=["han2023", "hu2020"],
        defaults=defaults,
        families=families,
        grade_um=_grade_um(case),
        grid=_grid_check(case, red, sec),
    )
    res.values["first_stage_backlash"] = sec.first_stage_backlash
    if fs_model is not None:
        res.notes.append(
            "First-stage backlash added to lost motion, backlash and hysteresis loss: "
            "min_k j_t,k / (r_sun i) per sample, j_t,k = j_k − (E_sun + E_planet,k) + "
            "2 A_a,k tan α (first_stage_backlash_at_output [arcmin]); with classes the "
            "tooth-thickness and centre-distance deviations are drawn truncated normal within "
            "the class limits (3σ = half the width) unless [analyses.yield.tolerances] gives "
            "them (docs/tolerance_grades.md)."
        )
    return res
