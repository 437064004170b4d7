"""Study kind ``rv_reducer``: a whole RV reducer — load sharing with measured errors, total TE,
catalogue quantities and compensation (Han et al. 2023; Hu et al. 2020 sections 3 and 5).

Case file layout::

    [case]  kind = "rv_reducer"
    [reducer]                  rated_torque_Nm
    [reducer.first_stage]      sun_teeth, planet_teeth, planets, module_mm, pressure_angle_deg,
                               mesh_stiffness_N_per_mm | face_width_mm,
                               sun_support_stiffness_N_per_mm
    [reducer.cranks]           count, circle_radius_mm, eccentricity_mm,
                               cam_bearing = {stiffness_N_per_mm | rollers, roller_length_mm,
                               reference_load_N}, carrier_bearing = {...}
    [reducer.discs]            count, face_width_mm, equidistant_modification_mm,
                               shift_modification_mm, youngs_modulus_MPa, poisson_ratio
    [reducer.pins]             count, pin_radius_mm, circle_radius_mm, *_errors_um (per pin)
    [reducer.supports]         carrier_radial_stiffness_N_per_mm
    [[reducer.errors]]         part, crank, disc, value_um, angle_deg   (one per measured error)
    [analyses.load_sharing]    torque_Nm, positions, compare_without_errors
    [analyses.transmission_error]  torque_Nm, positions, zero_load_fraction
    [analyses.catalogue]       position_deg, torque_sweep, steps_per_segment, lost_motion_fraction
    [analyses.compensation]    torque_Nm, objective, min_backlash_arcmin, positions, bounds_um
"""

from __future__ import annotations

from typing import Literal

import numpy as np
from pydantic import Field, model_validator

from gearte.errors import ConvergenceError, ParameterError
from gearte.geometry.rv import (
    Cranks,
    Discs,
    ErrorEntry,
    FirstStage,
    ManufacturingErrors,
    PinRing,
    RVReducer,
    Supports,
    iso6336_mesh_stiffness,
    palmgren_radial_stiffness,
)
from gearte.io.schema import CaseBase, StrictModel
from gearte.results import AnalysisResult, StudyResult
from gearte.studies._yield import YieldSection
from gearte.units import (
    Nm_to_Nmm,
    arcmin_to_rad,
    deg_to_rad,
    rad_to_arcmin,
    rad_to_arcsec,
    rad_to_deg,
    um_to_mm,
)

KIND = "rv_reducer"
REFERENCES = ["han2023", "hu2020"]
FIGURES = "gearte.plotting.rv_reducer"

__all__ = ["KIND", "REFERENCES", "FIGURES", "Case", "run", "build_reducer"]


# ------------------------------------------------------------------------------------------
# Schema
# ------------------------------------------------------------------------------------------
class Bearing(StrictModel):
    """A roller bearing: a given radial stiffness, or Palmgren data to derive it."""

    stiffness_N_per_mm: float | None = Field(default=None, gt=0, le=1e9, description="[N/mm]")
    rollers: int | None = Field(default=None, ge=3, le=200, description="number of rollers")
    roller_length_mm: float | None = Field(default=None, gt=0, le=200, description="[mm]")
    reference_load_N: float | None = Field(
        default=None, gt=0, le=1e7, description="load of the secant stiffness [N]"
    )
    radial_clearance_um: float = Field(default=0.0, ge=0, le=200, description="[um]")

    @model_validator(mode="after")
    def _one_way(self):
        palm = (self.rollers, self.roller_length_mm, self.reference_load_N)
        if self.stiffness_N_per_mm is not None:
            if any(v is not None for v in palm):
                raise ValueError("give either stiffness_N_per_mm or the Palmgren data, not both")
        elif any(v is None for v in palm):
            raise ValueError(
                "give stiffness_N_per_mm, or all of rollers, roller_length_mm, reference_load_N"
            )
        return self

    def stiffness(self) -> float:
        if self.stiffness_N_per_mm is not None:
            return self.stiffness_N_per_mm
        return palmgren_radial_stiffness(self.rollers, self.roller_length_mm, self.reference_load_N)


class FirstStageSection(StrictModel):
    sun_teeth: int = Field(ge=6, le=400)
    planet_teeth: int = Field(ge=6, le=400)
    planets: int = Field(ge=2, le=6, description="must equal cranks.count")
    module_mm: float = Field(gt=0, le=20)
    pressure_angle_deg: float = Field(default=20.0, gt=0, lt=45)
    mesh_stiffness_N_per_mm: float | None = Field(default=None, gt=0, le=1e9)
    face_width_mm: float | None = Field(
        default=None, gt=0, le=200, description="ISO 6336 mesh stiffness c_gamma = 20 N/(mm um)"
    )
    sun_support_stiffness_N_per_mm: float = Field(default=1e4, gt=0, le=1e9)

    @model_validator(mode="after")
    def _mesh(self):
        if (self.mesh_stiffness_N_per_mm is None) == (self.face_width_mm is None):
            raise ValueError("give exactly one of mesh_stiffness_N_per_mm and face_width_mm")
        return self


class CranksSection(StrictModel):
    count: int = Field(ge=2, le=6)
    circle_radius_mm: float = Field(gt=0, le=1000)
    eccentricity_mm: float = Field(gt=0, le=50)
    cam_bearing: Bearing
    carrier_bearing: Bearing


class DiscsSection(StrictModel):
    count: int = Field(default=2, ge=1, le=3)
    face_width_mm: float = Field(gt=0, le=200)
    equidistant_modification_mm: float = Field(default=0.0, ge=-0.5, le=0.5)
    shift_modification_mm: float = Field(default=0.0, ge=-0.5, le=0.5)
    youngs_modulus_MPa: float = Field(default=2.06e5, gt=0, le=1e6)
    poisson_ratio: float = Field(default=0.3, ge=0, lt=0.5)


class PinsSection(StrictModel):
    count: int = Field(ge=8, le=200)
    pin_radius_mm: float = Field(gt=0, le=50)
    circle_radius_mm: float = Field(gt=0, le=2000)
    radius_errors_um: list[float] | None = Field(default=None, description="one per pin [um]")
    radial_position_errors_um: list[float] | None = None
    tangential_position_errors_um: list[float] | None = None

    @model_validator(mode="after")
    def _lengths(self):
        names = ("radius_errors_um", "radial_position_errors_um", "tangential_position_errors_um")
        for name in names:
            v = getattr(self, name)
            if v is not None and len(v) != self.count:
                raise ValueError(f"{name} needs one value per pin ({self.count}), got {len(v)}")
        return self


class SupportsSection(StrictModel):
    carrier_radial_stiffness_N_per_mm: float = Field(gt=0, le=1e10)


class ErrorSection(StrictModel):
    part: Literal["planet_base_circle", "disc_crank_bore", "cam", "carrier_crank_bore"]
    crank: int = Field(ge=1, description="1-based crank (= planet) index")
    disc: int | None = Field(default=None, ge=1, description="1-based disc index")
    value_um: float = Field(ge=0, le=500)
    angle_deg: float = Field(ge=-360, le=360)


class ReducerSection(StrictModel):
    rated_torque_Nm: float = Field(gt=0, le=1e6)
    contact_law: Literal["line_contact", "hu2020"] = Field(
        default="line_contact",
        description="pin-contact law (gearte.models.contact_law; docs/contact-law.md)",
    )
    allowable_contact_pressure_MPa: float | None = Field(
        default=None, gt=0, le=1e5, description="warn when the Hertz pin pressure exceeds it"
    )
    first_stage: FirstStageSection
    cranks: CranksSection
    discs: DiscsSection
    pins: PinsSection
    supports: SupportsSection
    errors: list[ErrorSection] = Field(default_factory=list)

    @model_validator(mode="after")
    def _build(self):
        problems = []
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
                build_reducer(self)
            except ParameterError as exc:
                problems.append(str(exc))
        if problems:
            raise ValueError("; ".join(problems))
        return self


class LoadSharingSection(StrictModel):
    torque_Nm: float = Field(gt=0, le=1e6)
    positions: int = Field(default=360, ge=8, le=7200)
    compare_without_errors: bool = True


class TESection(StrictModel):
    torque_Nm: float = Field(gt=0, le=1e6)
    positions: int = Field(default=360, ge=8, le=7200)
    zero_load_fraction: float = Field(default=1e-3, gt=0, lt=0.05)


class CatalogueSection(StrictModel):
    position_deg: float = Field(default=0.0, ge=0, lt=360)
    torque_sweep: list[float] = Field(
        default=[0.0, 1.0, 0.0, -1.0, 0.0, 1.0],
        description="turning points of the torque sweep, fractions of rated torque",
    )
    steps_per_segment: int = Field(default=20, ge=2, le=1000)
    lost_motion_fraction: float = Field(default=0.03, gt=0, lt=0.5)

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
    equidistant_modification: tuple[float, float] | None = None
    shift_modification: tuple[float, float] | None = None
    pin_radius: tuple[float, float] | None = None
    pin_circle_radius: tuple[float, float] | None = None

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
    torque_Nm: float = Field(gt=0, le=1e6)
    objective: Literal["total_te_peak_to_peak", "mean_lag"] = "total_te_peak_to_peak"
    min_backlash_arcmin: float = Field(default=0.0, ge=0, le=30)
    positions: int = Field(default=72, ge=8, le=720)
    grid: int = Field(default=3, ge=2, le=7)
    bounds_um: Bounds


class RVYieldSection(YieldSection):
    """``[analyses.yield]`` of an RV reducer (gearte.studies._yield): tolerance keys are the
    error families ``planet_base_circle``, ``disc_crank_bore``, ``cam``, ``carrier_crank_bore``
    (magnitude [µm], ``kind = "rayleigh"``, ``phase = true`` for a uniform direction),
    ``pins.radius_errors``, ``pins.radial_position_errors``, ``pins.tangential_position_errors``
    [µm], or one instance (``cam.c1.d2``, ``pins.radius_errors.p7``)."""

    positions: int = Field(default=36, ge=2, le=3600, description="TE output positions")
    te_torque_Nm: float | None = Field(
        default=None, gt=0, le=1e6, description="torque of the loaded TE; default rated"
    )


class Analyses(StrictModel):
    load_sharing: LoadSharingSection | None = None
    transmission_error: TESection | None = None
    catalogue: CatalogueSection | None = None
    compensation: CompensationSection | None = None
    yield_: RVYieldSection | None = Field(default=None, alias="yield")


class Case(CaseBase):
    reducer: ReducerSection
    analyses: Analyses


# ------------------------------------------------------------------------------------------
# Case -> domain objects
# ------------------------------------------------------------------------------------------
def build_reducer(sec: ReducerSection, *, with_errors: bool = True) -> RVReducer:
    """The :class:`RVReducer` a case's ``[reducer]`` section describes."""
    fs = sec.first_stage
    mesh = (
        fs.mesh_stiffness_N_per_mm
        if fs.mesh_stiffness_N_per_mm is not None
        else iso6336_mesh_stiffness(fs.face_width_mm)
    )
    first = FirstStage(
        fs.sun_teeth,
        fs.planet_teeth,
        fs.module_mm,
        deg_to_rad(fs.pressure_angle_deg),
        mesh,
        fs.sun_support_stiffness_N_per_mm,
    )
    c = sec.cranks
    cranks = Cranks(
        c.count,
        c.circle_radius_mm,
        c.eccentricity_mm,
        c.cam_bearing.stiffness(),
        c.carrier_bearing.stiffness(),
        um_to_mm(c.cam_bearing.radial_clearance_um),
        um_to_mm(c.carrier_bearing.radial_clearance_um),
    )
    d = sec.discs
    discs = Discs(
        d.count,
        d.face_width_mm,
        d.equidistant_modification_mm,
        d.shift_modification_mm,
        d.youngs_modulus_MPa,
        d.poisson_ratio,
        sec.contact_law,
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
    )
    entries = [
        ErrorEntry(e.part, e.crank, e.disc, um_to_mm(e.value_um), deg_to_rad(e.angle_deg))
        for e in sec.errors
    ]
    errors = ManufacturingErrors.from_entries(entries, c.count, d.count, field_name="errors")
    if not with_errors:
        errors = errors.scaled(0.0)
    red = RVReducer(
        first,
        cranks,
        discs,
        pins,
        Supports(sec.supports.carrier_radial_stiffness_N_per_mm),
        Nm_to_Nmm(sec.rated_torque_Nm),
        planets=fs.planets,
        errors=errors,
    )
    from gearte.models.rv_load_sharing import cycloid_stage

    cycloid_stage(red)  # the stage's own validation (undercut, interference, pin fit)
    return red


# ------------------------------------------------------------------------------------------
# Run
# ------------------------------------------------------------------------------------------
def _load_sharing(red, red0, sec: LoadSharingSection) -> AnalysisResult:
    from gearte.models.cycloid_contact import tooth_contact
    from gearte.models.rv_load_sharing import cycloid_stage, load_sharing, output_positions

    th = output_positions(sec.positions)
    T = Nm_to_Nmm(sec.torque_Nm)
    ls = load_sharing(red, T, th)
    has_errors = red0 is not None
    p_peak = np.unravel_index(np.argmax(ls.pin_force), ls.pin_force.shape)
    values = {
        "peak_pin_load [N]": ls.peak_pin_load,
        "max_contact_pressure [MPa]": ls.max_contact_pressure,
        "contact_law": ls.contact_law,
        "pairs_in_mesh_min": int(ls.pairs_in_mesh.min()),
        "pairs_in_mesh_max": int(ls.pairs_in_mesh.max()),
        "pairs_in_mesh_at_peak": int(ls.pairs_in_mesh[p_peak[0], p_peak[1]]),
        "output_angle_at_peak [deg]": float(np.degrees(th[p_peak[0]])),
        "max_cam_bearing_load [N]": float(ls.cam_bearing_load.max()),
        "max_carrier_bearing_load [N]": float(ls.carrier_bearing_load.max()),
        "max_mesh_force [N]": float(np.abs(ls.mesh_force).max()),
        "disc_torque_share_range": [
            float((ls.disc_torque / ls.disc_torque.sum(axis=1, keepdims=True)).min()),
            float((ls.disc_torque / ls.disc_torque.sum(axis=1, keepdims=True)).max()),
        ],
    }
    data = {"load": ls}
    notes = [
        "Pin loads from the quasi-static equilibrium of all parts (springs + unilateral pin "
        f"contacts with the '{ls.contact_law}' load-dependent stiffness), one output revolution; "
        "max_contact_pressure: Hertz line-contact pressure of each pin with its own flank "
        "curvature.",
    ]
    if has_errors and sec.compare_without_errors:
        ls0 = load_sharing(red0, T, th)
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
            mesh_angle=np.linspace(0, 2 * np.pi / 40, 9),
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
    for p, th in enumerate(np.degrees(ls.theta)):
        for j in range(ls.pin_force.shape[1]):
            vals = ",".join(f"{v:.3f}" for v in ls.pin_force[p, j])
            lines.append(f"{th:.4f},{j + 1},{vals}")
    return "\n".join(lines) + "\n"


def _transmission_error(red, sec: TESection) -> AnalysisResult:
    from gearte.models.rv_load_sharing import output_positions, transmission_error

    th = output_positions(sec.positions)
    te = transmission_error(
        red, Nm_to_Nmm(sec.torque_Nm), th, zero_load_fraction=sec.zero_load_fraction
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
        "output_angle [deg]": np.degrees(th),
        "total_te [arcsec]": rad_to_arcsec(te.total),
        "geometric_te [arcsec]": rad_to_arcsec(te.geometric),
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
        np.degrees(te.theta),
        rad_to_arcsec(te.total),
        rad_to_arcsec(te.geometric),
        rad_to_arcsec(te.elastic),
        strict=True,
    ):
        rows.append(f"{th:.4f},{t:.6f},{g:.6f},{e:.6f}")
    return "\n".join(rows) + "\n"


def _catalogue(red, sec: CatalogueSection) -> AnalysisResult:
    from gearte.models.rv_catalogue import catalogue_values

    cat = catalogue_values(
        red,
        theta=deg_to_rad(sec.position_deg),
        turning_points=sec.torque_sweep,
        steps_per_segment=sec.steps_per_segment,
        lost_motion_fraction=sec.lost_motion_fraction,
    )
    values = {
        "torsional_rigidity [N*m/arcmin]": cat.torsional_rigidity / 1e3 / rad_to_arcmin(1.0),
        "lost_motion [arcmin]": rad_to_arcmin(cat.lost_motion),
        "backlash [arcmin]": rad_to_arcmin(cat.backlash),
        "hysteresis_loss [arcmin]": rad_to_arcmin(cat.hysteresis_loss),
        "rated_torque [N*m]": red.rated_torque / 1e3,
    }
    return AnalysisResult(
        name="catalogue",
        title="Catalogue quantities from a virtual torsion test (input locked)",
        values=values,
        references=[],
        notes=[
            "Definitions as in the Nabtesco RV catalogue: rigidity = (T_r/2)/(θ(T_r) − θ(T_r/2)) "
            "averaged over both directions; lost motion = θ(+3% T_r) − θ(−3% T_r) at the "
            "curve midpoints; backlash = θ(0+) − θ(0−).",
            "The model is frictionless: loading and unloading branches coincide outside the "
            "backlash, so hysteresis loss = backlash.",
        ],
        data={"catalogue": cat},
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
    values = {"changes [um]": {k: v * 1e3 for k, v in comp.after.changes.items()}}
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


def run(case: Case, options=None) -> StudyResult:
    """Run the analyses a case asks for."""
    red = build_reducer(case.reducer)
    has_errors = len(case.reducer.errors) > 0
    red0 = build_reducer(case.reducer, with_errors=False) if has_errors else None
    a = case.analyses
    out: list[AnalysisResult] = []
    if a.load_sharing is not None:
        out.append(_load_sharing(red, red0, a.load_sharing))
    if a.transmission_error is not None:
        out.append(_transmission_error(red, a.transmission_error))
    if a.catalogue is not None:
        out.append(_catalogue(red, a.catalogue))
    if a.compensation is not None:
        out.append(_compensation(red, a.compensation))
    if a.yield_ is not None:
        out.append(_yield(case, red0 if red0 is not None else red, a.yield_, options))
    warnings = []
    if not out:
        warnings.append("no analyses requested: add [analyses.load_sharing] etc.")
    allowable = case.reducer.allowable_contact_pressure_MPa
    for r in out:
        p = r.values.get("max_contact_pressure [MPa]")
        if allowable is not None and p is not None and p > allowable:
            warnings.append(
                f"{r.name}: max_contact_pressure {p:.0f} MPa exceeds "
                f"reducer.allowable_contact_pressure_MPa = {allowable:g} MPa"
            )
    return StudyResult(case=case, analyses=out, warnings=warnings)


def _yield(case: Case, red, sec: RVYieldSection, options) -> AnalysisResult:
    """``[analyses.yield]``: each sample one assembled reducer (errors drawn from the
    tolerances; errors without a tolerance keep the case's values) → catalogue test, angular TE
    over one output revolution, peak pin load; yield against ``[analyses.yield.spec]``."""
    from gearte.runners.yield_models import RV_PIN_FAMILIES, RVReducerYield, rv_error_keys
    from gearte.studies._yield import yield_analysis

    model = RVReducerYield(
        build_reducer(case.reducer),
        positions=sec.positions,
        te_torque=None if sec.te_torque_Nm is None else float(Nm_to_Nmm(sec.te_torque_Nm)),
    )
    families = rv_error_keys(red)
    units = {k: "um" for k in families} | {k: "um" for v in families.values() for k in v}

    def worst_case(errors):
        d = case.model_dump(mode="json", by_alias=True, exclude_none=True)
        entries = {(e["part"], e["crank"], e.get("disc")): e for e in d["reducer"]["errors"]}
        for part in ("planet_base_circle", "disc_crank_bore", "cam", "carrier_crank_bore"):
            for key in families[part]:
                if key not in errors:
                    continue
                idx = key.split(".")[1:]
                crank = int(idx[0][1:])
                disc = int(idx[1][1:]) if len(idx) > 1 else None
                entry = {"part": part, "crank": crank, "value_um": float(errors[key])}
                if disc is not None:
                    entry["disc"] = disc
                phase = float(errors.get(f"{key}_phase_rad", 0.0))
                entry["angle_deg"] = float(np.mod(rad_to_deg(phase) + 180.0, 360.0) - 180.0)
                entries[(part, crank, disc)] = entry
        d["reducer"]["errors"] = list(entries.values())
        pins = d["reducer"]["pins"]
        for f in RV_PIN_FAMILIES:
            keys = families[f"pins.{f}"]
            if any(k in errors for k in keys):
                old = pins.get(f"{f}_um") or [0.0] * len(keys)
                pins[f"{f}_um"] = [float(errors.get(k, old[i])) for i, k in enumerate(keys)]
        te_torque = sec.te_torque_Nm or case.reducer.rated_torque_Nm
        d["analyses"] = {
            "catalogue": {"lost_motion_fraction": 0.03},
            "transmission_error": {"torque_Nm": te_torque, "positions": max(8, sec.positions)},
        }
        return d

    def grade_um(key: str, grade: int) -> float | None:
        """planet_base_circle: eccentricity tolerance F_rT/2 of the planet (ISO 1328-1:2013)."""
        from gearte.tolerance.iso1328 import runout_tolerance

        fs = case.reducer.first_stage
        if key.split(".")[0] != "planet_base_circle":
            return None
        return 0.5 * runout_tolerance(grade, fs.module_mm, fs.module_mm * fs.planet_teeth)

    return yield_analysis(
        sec,
        model,
        units,
        {},
        options=options,
        worst_case=worst_case,
        references=["han2023", "hu2020"],
        families=families,
        grade_um=grade_um,
    )
