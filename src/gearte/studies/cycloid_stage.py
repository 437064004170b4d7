"""Study kind ``cycloid_stage``: geometry, geometric TE, tooth contact and compensation of a
cycloid–pin stage (Hu et al. 2020).

Case file sections (units in the key names)::

    [stage]                  pins, pin_circle_radius_mm, pin_radius_mm, eccentricity_mm,
                             face_width_mm, equidistant_modification_mm, shifted_modification_mm,
                             rotation_modification_arcmin, cycloid_teeth (optional, = pins - 1)
    [errors.<factor>]        mean_um, tolerance_um   for the nine factors of Table 2
    [analyses.geometric_te]  (no options)
    [analyses.tooth_contact] torque_Nm, disc_share, youngs_modulus_MPa, poisson_ratio,
                             mesh_positions, start_force_N
    [analyses.compensation]  target_te_change_arcmin, factors, rule

``run`` returns the analyses ``geometry``, ``geometric_te``, ``tooth_contact`` and
``compensation`` (the last three only when their table is present).
"""

from __future__ import annotations

from typing import Literal

import numpy as np
from pydantic import ConfigDict, Field, model_validator

from gearte.errors import ConvergenceError, ParameterError
from gearte.io.schema import CaseBase, StrictModel, floored
from gearte.results import AnalysisResult, StudyResult
from gearte.studies._yield import YieldSection

KIND = "cycloid_stage"
REFERENCES = ["hu2020"]
FIGURES = "gearte.plotting.cycloid_stage"

__all__ = ["KIND", "REFERENCES", "FIGURES", "Case", "run", "build_stage"]

_FACTOR_HELP = {
    "pin_circle_radius_error": "pin-centre-circle radius error δr_p (Table 2 row a)",
    "pin_radius_error": "pin radius error δr_rp (row b)",
    "pin_groove_clearance": "clearance between pin and pin groove δ_j (row c)",
    "radial_runout": "radial runout of the cycloid disc F_r1 (row d)",
    "pin_housing_position_error": "circumferential position error of the pin housing δt_Σ (row e)",
    "equidistant_modification_error": "error of the equidistant modification δΔr_rp (row f)",
    "shifted_modification_error": "error of the shifted modification δΔr_p (row g)",
    "cumulative_pitch_error": "cumulative pitch error of the disc ΔF_p (row h)",
    "eccentricity_error": "eccentricity error δa (row i)",
}

#: Table 2 rows a–h: the factors with an error coefficient of their own (the eccentricity error,
#: row i, has a derived coefficient of 0 and is neither a reference nor a compensation factor).
_TableFactor = Literal[
    "pin_circle_radius_error",
    "pin_radius_error",
    "pin_groove_clearance",
    "radial_runout",
    "pin_housing_position_error",
    "equidistant_modification_error",
    "shifted_modification_error",
    "cumulative_pitch_error",
]

#: The factors whose error coefficient is negative (Table 2): the default compensation set.
_NEGATIVE_COEFFICIENT_FACTORS: tuple[_TableFactor, ...] = (
    "pin_radius_error",
    "shifted_modification_error",
    "cumulative_pitch_error",
)

_STAGE_FIELD = {
    "z_p": "pins",
    "z_c": "cycloid_teeth",
    "r_p": "pin_circle_radius_mm",
    "r_rp": "pin_radius_mm",
    "a": "eccentricity_mm",
    "b": "face_width_mm",
    "dr_rp": "equidistant_modification_mm",
    "dr_p": "shifted_modification_mm",
    "rotation": "rotation_modification_arcmin",
    "K1": "eccentricity_mm/pins/pin_circle_radius_mm (K1)",
    "dr_rp/dr_p": "equidistant_modification_mm/shifted_modification_mm",
}


class _Section(StrictModel):
    model_config = ConfigDict(strict=True)


class Stage(_Section):
    """The ``[stage]`` table: the cycloid–pin pair and its profile modifications."""

    pins: int = Field(ge=4, le=400, description="Number of pins z_p [-].")
    cycloid_teeth: int | None = Field(
        default=None, ge=3, le=399, description="Cycloid teeth z_c [-]; must be pins - 1."
    )
    pin_circle_radius_mm: float = Field(gt=0, le=5000, description="Pin-centre-circle radius r_p.")
    pin_radius_mm: float = Field(gt=0, le=500, description="Pin radius r_rp.")
    eccentricity_mm: float = floored("eccentricity", le=200, description="Eccentricity a.")
    face_width_mm: float = floored(
        "part_length", ..., le=1000, description="Face width b of one disc."
    )
    equidistant_modification_mm: float = Field(
        default=0.0, ge=-1.0, le=1.0, description="Equidistant modification Δr_rp."
    )
    shifted_modification_mm: float = Field(
        default=0.0, ge=-1.0, le=1.0, description="Shifted modification Δr_p."
    )
    rotation_modification_arcmin: float = Field(
        default=0.0, ge=-60.0, le=60.0, description="Rotation modification δ_rot (thins teeth)."
    )

    @model_validator(mode="after")
    def _physical(self) -> Stage:
        try:
            build_stage(self)
        except ParameterError as exc:
            name = _STAGE_FIELD.get(exc.field, exc.field)
            raise ValueError(f"{name}: {exc.reason} (got {exc.value!r})") from None
        return self


class ErrorSpec(_Section):
    """Mean and tolerance band of one component error."""

    mean_um: float = Field(default=0.0, ge=-1000.0, le=1000.0, description="Mean error [µm].")
    tolerance_um: float = Field(
        default=0.0, ge=0.0, le=1000.0, description="Tolerance band width T (mean ± T/2) [µm]."
    )


class Errors(_Section):
    """The ``[errors]`` table: the nine component errors of Table 2 (all default to zero)."""

    pin_circle_radius_error: ErrorSpec = ErrorSpec()
    pin_radius_error: ErrorSpec = ErrorSpec()
    pin_groove_clearance: ErrorSpec = ErrorSpec()
    radial_runout: ErrorSpec = ErrorSpec()
    pin_housing_position_error: ErrorSpec = ErrorSpec()
    equidistant_modification_error: ErrorSpec = ErrorSpec()
    shifted_modification_error: ErrorSpec = ErrorSpec()
    cumulative_pitch_error: ErrorSpec = ErrorSpec()
    eccentricity_error: ErrorSpec = ErrorSpec()

    def means_mm(self) -> dict[str, float]:
        from gearte.units import um_to_mm

        return {k: float(um_to_mm(getattr(self, k).mean_um)) for k in _FACTOR_HELP}

    def tolerances_mm(self) -> dict[str, float]:
        from gearte.units import um_to_mm

        return {k: float(um_to_mm(getattr(self, k).tolerance_um)) for k in _FACTOR_HELP}


class GeometricTEOptions(_Section):
    """``[analyses.geometric_te]``: geometric TE, error coefficients and sensitivities."""

    reference_factor: _TableFactor = Field(
        default="pin_circle_radius_error", description="g_0 of the sensitivity index."
    )


class ToothContactOptions(_Section):
    """``[analyses.tooth_contact]``: loaded tooth contact analysis (section 4)."""

    torque_Nm: float = floored(
        "load_torque", ..., le=1e6, description="Output torque of the stage T [N·m]."
    )
    disc_share: float = floored(
        "disc_share", le=1, description="Share of T carried by the analysed disc (Hu et al.: 0.55)."
    )
    youngs_modulus_MPa: float = floored(
        "youngs_modulus", ..., le=1e7, description="E of disc and pins [MPa]."
    )
    poisson_ratio: float = Field(ge=0, lt=0.5, description="μ of disc and pins [-].")
    mesh_positions: int = Field(
        default=1, ge=1, le=100000, description="Mesh positions over one tooth pitch (1: paper's)."
    )
    start_force_N: float | None = Field(
        default=None, gt=0, le=1e9, description="Start value of F_max; default eq 45."
    )
    clearance_model: Literal["eq32", "envelope"] = Field(
        default="eq32",
        description="Initial clearance: eq 32 (paper, first order) or the exact envelope.",
    )
    contact_law: Literal["line_contact", "hu2020"] = Field(
        default="line_contact",
        description="Pin contact law: textbook line contact (default) or Hu 2020 eq 38-39 as "
        "printed (docs/contact-law.md).",
    )
    allowable_contact_pressure_MPa: float | None = Field(
        default=None, gt=0, le=1e5, description="Warn when the Hertz pin pressure exceeds it."
    )


class CompensationOptions(_Section):
    """``[analyses.compensation]``: which errors to change to move the mean TE (eq 24–27)."""

    target_te_change_arcmin: float | None = Field(
        default=None,
        ge=-600,
        le=600,
        description="Wanted change of the mean geometric TE; default: remove the mean.",
    )
    factors: list[_TableFactor] = Field(
        default_factory=lambda: list(_NEGATIVE_COEFFICIENT_FACTORS),
        min_length=1,
        description="Factors allowed to change (default: the negative-coefficient ones).",
    )
    rule: Literal["equal_share", "equal_change", "tolerance_weighted"] = Field(
        "equal_share",
        description="How the TE change is shared among the factors: equal_share (same TE share "
        "each), equal_change (same change each) or tolerance_weighted (least change in units of "
        "each tolerance).",
    )


class Analyses(_Section):
    """``[analyses]``: the analyses to run (a present table runs it)."""

    geometric_te: GeometricTEOptions | None = None
    tooth_contact: ToothContactOptions | None = None
    compensation: CompensationOptions | None = None
    yield_: YieldSection | None = Field(
        default=None, alias="yield", description="production yield (gearte.studies._yield)"
    )


class Case(CaseBase):
    """A ``cycloid_stage`` case file."""

    stage: Stage
    errors: Errors = Errors()
    analyses: Analyses = Analyses()

    @model_validator(mode="after")
    def _combination(self) -> Case:
        comp = self.analyses.compensation
        if comp is not None and comp.rule == "tolerance_weighted":
            tol = self.errors.tolerances_mm()
            zero = [k for k in comp.factors if tol[k] <= 0.0]
            if zero:
                raise ValueError(
                    "analyses.compensation.rule: 'tolerance_weighted' needs tolerance_um > 0 for "
                    f"every factor; zero for {zero}"
                )
        return self


def build_stage(stage: Stage):
    """The :class:`gearte.geometry.cycloid.CycloidStage` of a ``[stage]`` table."""
    from gearte.geometry.cycloid import CycloidStage
    from gearte.units import arcmin_to_rad

    return CycloidStage(
        z_p=stage.pins,
        z_c=stage.pins - 1 if stage.cycloid_teeth is None else stage.cycloid_teeth,
        r_p=stage.pin_circle_radius_mm,
        r_rp=stage.pin_radius_mm,
        a=stage.eccentricity_mm,
        b=stage.face_width_mm,
        dr_rp=stage.equidistant_modification_mm,
        dr_p=stage.shifted_modification_mm,
        rotation=float(arcmin_to_rad(stage.rotation_modification_arcmin)),
    )


def plausibility(case: Case) -> list[tuple[str, float, str]]:
    """``(field, torque [N·m], reason)`` when the tooth contact's torque could not be carried by
    any steel pin contact of this stage (:func:`gearte.io.plausibility.torque_problem`), the
    stage built by :func:`build_stage`.

    Parameters
    ----------
    case : Case
        The validated case (sections may be placeholders: gearte.io.plausibility).
    """
    from gearte.io.plausibility import torque_problem

    tc = case.analyses.tooth_contact
    if tc is None:
        return []
    got = torque_problem(
        "analyses.tooth_contact.torque_Nm",
        tc.torque_Nm,
        build_stage(case.stage),
        tc.disc_share,
        tc.youngs_modulus_MPa,
        tc.poisson_ratio,
    )
    return [got] if got else []


def _geometry(st) -> AnalysisResult:
    from gearte.geometry.cycloid import min_convex_curvature_radius
    from gearte.units import rad_to_arcmin, rad_to_deg

    return AnalysisResult(
        name="geometry",
        title="Cycloid–pin geometry (eq 1–4, 32–34, 40)",
        values={
            "K1": st.K1,
            "cycloid_teeth": st.z_c,
            "ratio_i_H": st.i_h,
            "pitch_radius_r_c [mm]": st.r_c,
            "root_radius [mm]": st.root_radius,
            "tip_radius [mm]": st.tip_radius,
            "first_contact_phase [deg]": float(rad_to_deg(st.phi0)),
            "curvature_radius_at_phi0 [mm]": st.rho0,
            "min_convex_curvature_radius [mm]": min_convex_curvature_radius(st.z_p, st.R, st.a),
            "radial_clearance [mm]": st.dr_rp - st.dr_p,
            "backlash_per_flank [arcmin]": float(rad_to_arcmin(st.backlash_per_flank)),
        },
        references=["hu2020"],
        notes=[
            "K1 = a z_p / (r_p + Δr_p) (eq 3); radii R ∓ a − r with R = r_p + Δr_p, "
            "r = r_rp + Δr_rp.",
            "backlash_per_flank is the closing rotation Δ_n(φ0)/r_c + δ_rot; negative means the "
            "nominal design is preloaded and relies on positive errors.",
        ],
        data={"stage": st},
    )


def _geometric_te(st, case: Case, opts: GeometricTEOptions) -> AnalysisResult:
    from gearte.models.cycloid_te import PAPER_SYMBOLS, geometric_te, sensitivity_indices
    from gearte.units import rad_to_arcmin, um_to_mm

    means = case.errors.means_mm()
    tols = case.errors.tolerances_mm()
    te = geometric_te(st, means, tols)
    sens = sensitivity_indices(st, reference=opts.reference_factor)
    arc = {k: float(rad_to_arcmin(v)) for k, v in te.contributions.items()}
    ranked = sorted(arc.items(), key=lambda kv: -abs(kv[1]))
    gain = {k: float(rad_to_arcmin(v) * um_to_mm(1.0)) for k, v in te.gradients.items()}
    return AnalysisResult(
        name="geometric_te",
        title="Geometric transmission error from component errors (eq 5–17, Table 2)",
        values={
            "geometric_te_mean [arcmin]": float(rad_to_arcmin(te.mean)),
            "geometric_te_tolerance [arcmin]": float(rad_to_arcmin(te.tolerance)),
            "geometric_te_min [arcmin]": float(rad_to_arcmin(te.lower)),
            "geometric_te_max [arcmin]": float(rad_to_arcmin(te.upper)),
            "contribution [arcmin]": arc,
            "tolerance_contribution [arcmin]": {
                k: float(rad_to_arcmin(v)) for k, v in te.tolerances.items()
            },
            "tolerance_share": te.tolerance_shares(),
            "error_coefficient": te.coefficients,
            "sensitivity_index": sens,
            "error_gain [arcmin/um]": gain,
            # none when every contribution is zero (no error given): nothing dominates
            "dominant_factor": ranked[0][0] if ranked and ranked[0][1] != 0 else "",
            "paper_symbol": {k: PAPER_SYMBOLS[k] for k in arc},
        },
        references=["hu2020"],
        notes=[
            "TE = mean ± tolerance/2; mean = Σ contributions (eq 16), tolerance = RSS of the "
            "factors' tolerances (eq 17). Positive = more lost motion.",
            "Eccentricity coefficient k_n derived by gearte: the linear effect is exactly zero "
            "(the eccentricity error moves the pin path by δa (K1 − cos φ)/S, zero at φ0); its "
            "second-order effect is evaluated exactly. The paper prints −0.00024.",
            "The nine errors' values are inputs of the case, not from the paper.",
        ],
        data={"te": te},
    )


def _contact_solver(st, o: ToothContactOptions):
    """``mesh_angle [rad] → ToothContact`` of ``[analyses.tooth_contact]``
    (:func:`gearte.models.cycloid_contact.tooth_contact`). A torque the contact model refuses
    once solved (a pin loaded beyond the elastic law's range, a normal deformation beyond its
    range) is bad input naming ``analyses.tooth_contact.torque_Nm``, whichever mesh position
    found it."""
    from gearte.models.cycloid_contact import tooth_contact
    from gearte.units import Nm_to_Nmm

    T = float(Nm_to_Nmm(o.torque_Nm))

    def contact(mesh_angle):
        try:
            return tooth_contact(
                st,
                T,
                disc_share=o.disc_share,
                E=o.youngs_modulus_MPa,
                mu=o.poisson_ratio,
                mesh_angle=mesh_angle,
                F_start=o.start_force_N,
                clearance_model=o.clearance_model,
                contact_law=o.contact_law,
            )
        except ParameterError as exc:
            if exc.field != "torque":
                raise
            raise ParameterError(
                "analyses.tooth_contact.torque_Nm",
                o.torque_Nm,
                f"{exc.reason.removeprefix('[N·mm] ')} (with youngs_modulus_MPa = "
                f"{o.youngs_modulus_MPa:g}, disc_share = {o.disc_share:g}, "
                f"contact_law = {o.contact_law!r})",
            ) from None

    return contact


def _tooth_contact(st, o: ToothContactOptions) -> tuple[AnalysisResult, list[str]]:
    from gearte.units import rad_to_deg

    contact = _contact_solver(st, o)
    tc = contact(0.0)
    values = {
        "contact_law": o.contact_law,
        "pins_in_mesh": int(tc.pins_in_mesh[0]),
        "max_contact_force [N]": float(tc.F_max[0]),
        "max_normal_deformation [mm]": float(tc.delta_max[0]),
        "max_pin_force [N]": float(tc.max_pin_force[0]),
        "torque_on_disc [N·mm]": tc.T_c,
        "curvature_radius_at_phi0 [mm]": tc.rho,
        "pins_in_mesh_index": (np.nonzero(tc.in_mesh[0])[0] + 1).tolist(),
        "pin_index": np.arange(1, st.z_p + 1),
        "meshing_phase [deg]": rad_to_deg(tc.phase[0]),
        "initial_clearance [mm]": tc.clearance[0],
        "normal_deformation [mm]": tc.approach[0],
        "contact_force [N]": tc.force[0],
        "max_contact_pressure [MPa]": float(tc.max_contact_pressure[0]),
        "contact_pressure [MPa]": tc.pressure[0],
        "flank_curvature_radius [mm]": tc.curvature[0],
        "solver_residual_evaluations": int(tc.n_eval[0]),
    }
    warnings: list[str] = []
    sweep = None
    if o.mesh_positions > 1:
        theta = np.arange(o.mesh_positions) * (2.0 * np.pi / st.z_p) / o.mesh_positions
        sweep = contact(theta)
        values.update(
            {
                "mesh_angle [deg]": rad_to_deg(theta),
                "max_contact_force_over_pitch [N]": sweep.F_max,
                "max_normal_deformation_over_pitch [mm]": sweep.delta_max,
                "pins_in_mesh_over_pitch": sweep.pins_in_mesh,
                "max_pin_force_over_pitch [N]": sweep.max_pin_force,
                "peak_contact_force [N]": float(sweep.F_max.max()),
                "peak_pin_force [N]": float(sweep.max_pin_force.max()),
                "pins_in_mesh_min": int(sweep.pins_in_mesh.min()),
                "pins_in_mesh_max": int(sweep.pins_in_mesh.max()),
                "max_contact_pressure_over_pitch [MPa]": sweep.max_contact_pressure,
            }
        )
        values["max_contact_pressure [MPa]"] = float(sweep.max_contact_pressure.max())
    allowable = o.allowable_contact_pressure_MPa
    if allowable is not None:
        values["allowable_contact_pressure [MPa]"] = allowable  # the report checks it
    if allowable is not None and values["max_contact_pressure [MPa]"] > allowable:
        warnings.append(
            f"tooth_contact: max_contact_pressure {values['max_contact_pressure [MPa]']:.0f} MPa "
            f"exceeds analyses.tooth_contact.allowable_contact_pressure_MPa = {allowable:g} MPa"
        )
    if values["pins_in_mesh"] <= 2:
        warnings.append(
            f"tooth_contact: only {values['pins_in_mesh']} pin(s) carry the load; the "
            "modification leaves large clearances for this torque"
        )
    res = AnalysisResult(
        name="tooth_contact",
        title="Loaded tooth contact analysis (section 4, eq 28–47)",
        values=values,
        references=["hu2020"],
        notes=[
            f"T = {o.torque_Nm:g} N·m, disc share {o.disc_share:g} (T_c = {tc.T_c / 1e3:.4g} N·m), "
            f"b = {st.b:g} mm, E = {o.youngs_modulus_MPa:g} MPa, μ = {o.poisson_ratio:g}.",
            "Mesh position 0: pin 1 on the line of centres, pin i at φ_i = 2π(i−1)/z_p; loaded "
            "flank sin φ > 0. max_contact_force is F_max of eq 44 (force at the largest arm).",
            "Solved as the unique root of the moment balance (independent of the start value); "
            "the paper's Picard iteration oscillates (Table 4).",
            f"Initial clearances: {o.clearance_model} "
            + (
                "(Hu et al. eq 32, first order in the modifications)."
                if o.clearance_model == "eq32"
                else "(exact envelope of the modified profile, closed at φ0)."
            ),
        ],
        data={"contact": tc, "sweep": sweep},
    )
    return res, warnings


def _compensation(st, case: Case, o: CompensationOptions) -> AnalysisResult:
    from gearte.models.cycloid_te import compensate, geometric_te
    from gearte.units import arcmin_to_rad, mm_to_um, rad_to_arcmin

    means = case.errors.means_mm()
    tols = case.errors.tolerances_mm()
    before = geometric_te(st, means, tols)
    target = (
        -before.mean
        if o.target_te_change_arcmin is None
        else float(arcmin_to_rad(o.target_te_change_arcmin))
    )
    comp = compensate(st, target, factors=o.factors, rule=o.rule, tolerances=tols)
    new_means = dict(means)
    for k, d in comp.changes.items():
        new_means[k] += d
    after = geometric_te(st, new_means, tols)
    extra = []
    if after.mean < 0:
        extra.append(
            "The compensated mean geometric TE is negative (nominal preload). That is what the "
            "paper intends when it compensates the total TE (geometric + elastic, 1.4559′ from "
            "Adams) with geometric factors: the preload offsets the elastic part."
        )
    return AnalysisResult(
        name="compensation",
        title="Error compensation (eq 24–27, explicit allocation rule)",
        values={
            "rule": comp.rule,
            "target_te_change [arcmin]": float(rad_to_arcmin(target)),
            "change [um]": {k: float(mm_to_um(v)) for k, v in comp.changes.items()},
            "te_change [arcmin]": {k: float(rad_to_arcmin(v)) for k, v in comp.te_changes.items()},
            "new_mean_error [um]": {k: float(mm_to_um(new_means[k])) for k in comp.changes},
            "geometric_te_mean_before [arcmin]": float(rad_to_arcmin(before.mean)),
            "geometric_te_mean_after [arcmin]": float(rad_to_arcmin(after.mean)),
        },
        references=["hu2020"],
        notes=[
            {
                "equal_share": "equal_share: each factor takes target/n of the TE change, then "
                "eq 27 (diagonal A⁻¹) gives its error change.",
                "equal_change": "equal_change: the same magnitude of change for every factor, "
                "signed by its coefficient.",
                "tolerance_weighted": "tolerance_weighted: least change measured in each "
                "factor's tolerance, min Σ(Δδ_j/T_j)² with Σ g_j Δδ_j = target.",
            }[comp.rule],
            "The paper's Table 6 is not reproduced by any split through eq 27 (see "
            "docs/validation/hu2020.md).",
            *extra,
        ],
        data={"compensation": comp, "before": before, "after": after},
    )


def run(case: Case, options) -> StudyResult:
    """Run a ``cycloid_stage`` case; no I/O, no plotting.

    Parameters
    ----------
    case : Case
        The validated case.
    options : RunOptions
        Execution options (workers, scheduler, progress); the runner passes them.

    Returns
    -------
    StudyResult
        Geometry and the analyses whose table is present.
    """
    st = build_stage(case.stage)
    analyses = [_geometry(st)]
    warnings: list[str] = []
    if st.backlash_per_flank < 0:
        from gearte.units import rad_to_arcmin

        warnings.append(
            "geometry: the nominal modification leaves no backlash (closing rotation "
            f"{rad_to_arcmin(st.backlash_per_flank):.3f} arcmin < 0): the disc is preloaded "
            "unless the errors open it"
        )
    if case.analyses.geometric_te is not None:
        a = _geometric_te(st, case, case.analyses.geometric_te)
        analyses.append(a)
        if a.values["geometric_te_min [arcmin]"] < 0:
            warnings.append(
                "geometric_te: the lower TE limit is negative: part of the tolerance range "
                "interferes (no lost motion left)"
            )
    if case.analyses.tooth_contact is not None:
        a, w = _tooth_contact(st, case.analyses.tooth_contact)
        analyses.append(a)
        warnings += w
    if case.analyses.compensation is not None:
        analyses.append(_compensation(st, case, case.analyses.compensation))
    if case.analyses.yield_ is not None:
        analyses.append(_yield(st, case, options))
    return StudyResult(case=case, analyses=analyses, warnings=warnings)


def _yield_keys(case: Case) -> tuple[dict, dict, dict]:
    """The yield's error keys (all in µm), their means [µm] and the tolerances the ``[errors]``
    bands imply (mean ± T/2 as normal laws with σ = T/6, unless the section says else)."""
    from gearte.models.cycloid_te import ERROR_FACTORS
    from gearte.studies._yield import ToleranceEntry

    means = {k: getattr(case.errors, k).mean_um for k in ERROR_FACTORS}
    bands = {
        k: ToleranceEntry(tolerance_um=0.5 * getattr(case.errors, k).tolerance_um)
        for k in ERROR_FACTORS
        if getattr(case.errors, k).tolerance_um > 0
    }
    return {k: "um" for k in ERROR_FACTORS}, means, bands


def preflight(case: Case) -> None:
    """The checks :func:`run` makes before any analysis that the schema cannot make alone
    (``gearte validate``, :func:`gearte.studies.run_case`): the tooth contact's solve at the
    paper's mesh position (a torque that loads a pin beyond the elastic contact model's range;
    the other mesh positions are checked when the analysis solves them), the yield's tolerance
    and cost keys against the stage's error keys and its spec against the yield model's
    quantities (:func:`~gearte.studies._yield.yield_inputs`).

    Raises
    ------
    ParameterError
        Naming ``analyses.tooth_contact.torque_Nm``, ``analyses.yield.tolerances.<key>``,
        ``analyses.yield.allocation.costs.<key>`` or ``analyses.yield.spec.<quantity>``.
    """
    if case.analyses.tooth_contact is not None:
        # the paper's mesh position, the analysis's first solve (one position: milliseconds);
        # the other positions are solved and checked when the analysis runs
        try:
            _contact_solver(build_stage(case.stage), case.analyses.tooth_contact)(0.0)
        except ConvergenceError:
            pass  # not a check of the input: the analysis reports it (exit 1)
    if case.analyses.yield_ is not None:
        from gearte.runners.yield_models import CycloidGeometricTE
        from gearte.studies._yield import yield_inputs

        units, means, bands = _yield_keys(case)
        yield_inputs(
            case.analyses.yield_,
            units,
            means,
            defaults=bands,
            quantities=CycloidGeometricTE.quantities,
        )


def _yield(st, case: Case, options) -> AnalysisResult:
    """``[analyses.yield]``: the nine component errors [µm] drawn from their laws → the
    distribution of the geometric TE (not only eq 17's RSS band) and its yield."""
    from gearte.models.cycloid_te import ERROR_FACTORS
    from gearte.runners.yield_models import CycloidGeometricTE
    from gearte.studies._yield import yield_analysis

    units, means, bands = _yield_keys(case)

    def worst_case(errors):
        d = case.model_dump(mode="json", by_alias=True, exclude_none=True)
        d["errors"] = {k: {"mean_um": float(errors.get(k, means[k]))} for k in ERROR_FACTORS}
        d["analyses"] = {"geometric_te": {}}
        return d

    return yield_analysis(
        case.analyses.yield_,  # type: ignore[arg-type]
        CycloidGeometricTE(st, means),
        units,
        means,
        options=options,
        worst_case=worst_case,
        references=["hu2020"],
        defaults=bands,
    )
