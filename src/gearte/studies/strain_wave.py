"""Study kind ``strain_wave``: a strain-wave (harmonic) gear — kinematics, the catalogue's
three-segment torsional stiffness, hysteresis loss and lost motion, transmission error with its
once- and twice-per-wave-generator-revolution terms, and the production yield.

The case's sections are the drive family's description (:mod:`gearte.families.strain_wave`:
``[gear]``, ``[errors]``, ``[tolerances]``); ``[analyses]`` sets the figures' resolution and
the optional ``[analyses.yield]``. Models: :mod:`gearte.models.strain_wave`.

Analyses: ``kinematics`` (``ratio``), ``stiffness`` (``torsional_rigidity [N*m/arcmin]``,
``lost_motion [arcmin]``, ``hysteresis_loss [arcmin]``, the K1/K2/K3 model and its torsion
curve), ``transmission_error`` (``te_peak_to_peak [arcsec]`` over one output revolution, the
amplitudes of its once- and twice-per-WG-revolution terms), ``yield``.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from pydantic import Field

from gearte.families.strain_wave import ErrorsSection, GearSection, TolerancesSection
from gearte.io.schema import CaseBase, StrictModel
from gearte.results import AnalysisResult, StudyResult
from gearte.studies._yield import YieldSection

__all__ = ["KIND", "REFERENCES", "FIGURES", "Case", "preflight", "run"]

KIND = "strain_wave"
REFERENCES = ["harmonicdrive2015", "harmonicdrive_csf", "tuttle1992", "jia2021"]
FIGURES = "gearte.plotting.strain_wave"


class StiffnessOptions(StrictModel):
    """``[analyses.stiffness]``: the torsion curve drawn."""

    max_torque_Nm: float | None = Field(
        default=None,
        gt=0,
        le=1e6,
        description="Largest torque of the drawn curve [N·m]; default: 1.5 T2 (derived).",
    )
    points: int = Field(default=241, ge=11, le=100_001, description="Torques of the curve [-].")


class TEOptions(StrictModel):
    """``[analyses.transmission_error]``: the sampled TE trace over one output revolution."""

    positions_per_wg_revolution: int = Field(
        default=32, ge=8, le=4096, description="Samples per wave-generator revolution [-]."
    )


class Analyses(StrictModel):
    """``[analyses]``: stiffness and TE always run; ``[analyses.yield]`` when given."""

    stiffness: StiffnessOptions = StiffnessOptions()
    transmission_error: TEOptions = TEOptions()
    yield_: YieldSection | None = Field(
        default=None, alias="yield", description="production yield (gearte.studies._yield)"
    )


class Case(CaseBase):
    """A ``strain_wave`` case file."""

    gear: GearSection
    errors: ErrorsSection = ErrorsSection()
    tolerances: TolerancesSection = TolerancesSection()
    analyses: Analyses = Analyses()


def _nm_per_arcmin(k: float) -> float:
    from gearte.units import Nmm_per_rad_to_Nm_per_arcmin

    return float(Nmm_per_rad_to_Nm_per_arcmin(k))


def _kinematics(case: Case, gear: Any) -> AnalysisResult:
    h, derived = case.gear.engagement_depth()
    notes = [
        "Circular spline fixed, wave generator input, flexspline output: i = z_f/(z_c − z_f); "
        "the output turns against the wave generator."
    ]
    if derived:
        notes.append(f"engagement_depth derived as 2 m = {h:g} mm (not given).")
    return AnalysisResult(
        name="kinematics",
        title="Kinematics of the strain-wave gear",
        values={
            "ratio": gear.ratio,
            "flexspline_teeth": gear.flexspline_teeth,
            "circular_spline_teeth": gear.circular_spline_teeth,
            "pitch_radius [mm]": gear.pitch_radius,
            "engagement_depth [mm]": h,
            "engagement_depth_derived": derived,
        },
        references=["harmonicdrive_csf", "tuttle1992"],
        notes=notes,
    )


def _stiffness(case: Case, gear: Any) -> AnalysisResult:
    from gearte.drives.strain_wave import StrainWaveDrive
    from gearte.models.strain_wave import hysteresis_branches
    from gearte.units import Nm_to_Nmm, Nmm_to_Nm, rad_to_arcmin

    o = case.analyses.stiffness
    t_max = Nm_to_Nmm(o.max_torque_Nm) if o.max_torque_Nm is not None else 1.5 * gear.T2
    torque = np.linspace(-t_max, t_max, o.points)
    load, unload = hysteresis_branches(
        torque, gear.hysteresis_loss, gear.T1, gear.T2, gear.K1, gear.K2, gear.K3
    )
    lm = gear.lost_motion()
    values: dict[str, Any] = {
        "torsional_rigidity [N*m/arcmin]": _nm_per_arcmin(gear.K3),
        "lost_motion [arcmin]": float(rad_to_arcmin(lm)),
        "hysteresis_loss [arcmin]": float(rad_to_arcmin(gear.hysteresis_loss)),
        "lost_motion_torque [N*m]": float(Nmm_to_Nm(gear.lost_motion_torque)),
        "stiffness_K1 [N*m/arcmin]": _nm_per_arcmin(gear.K1),
        "stiffness_K2 [N*m/arcmin]": _nm_per_arcmin(gear.K2),
        "stiffness_K3 [N*m/arcmin]": _nm_per_arcmin(gear.K3),
        "torsion_at_T1 [arcmin]": float(rad_to_arcmin(gear.torsion(gear.T1))),
        "torsion_at_T2 [arcmin]": float(rad_to_arcmin(gear.torsion(gear.T2))),
    }
    spread = StrainWaveDrive(gear).lost_motion_spread()
    if spread is not None:
        values["lost_motion_sd [arcmin]"] = float(rad_to_arcmin(spread.sd))
    values["torque [N*m]"] = Nmm_to_Nm(torque)
    values["torsion_loading [arcmin]"] = rad_to_arcmin(load)
    values["torsion_unloading [arcmin]"] = rad_to_arcmin(unload)
    return AnalysisResult(
        name="stiffness",
        title="Torsional stiffness, hysteresis and lost motion (catalogue model)",
        values=values,
        references=["harmonicdrive2015", "harmonicdrive_csf"],
        notes=[
            "φ(T) = T/K1 (T ≤ T1), T1/K1 + (T − T1)/K2 (T ≤ T2), T1/K1 + (T2 − T1)/K2 + "
            "(T − T2)/K3 (Harmonic Drive eq. 68.2–68.4), odd in T; torsional_rigidity = K3 "
            "(the catalogue's stiffness above T2).",
            "Lost motion = H + 2 φ(T_L) at the test torque ±T_L (no backlash in the mesh); the "
            "loop is drawn as φ(T) ∓ H/2 (the catalogue gives its width at zero torque only).",
        ],
    )


def _transmission_error(case: Case, gear: Any) -> AnalysisResult:
    from gearte.models.strain_wave import te_harmonics
    from gearte.runners.strain_wave_yield import te_peak_to_peak
    from gearte.units import rad_to_arcsec, rad_to_deg

    e = gear.errors
    n = int(round(gear.ratio * case.analyses.transmission_error.positions_per_wg_revolution))
    out_angle = np.linspace(0.0, 2.0 * np.pi, n, endpoint=False)
    te = gear.transmission_error(-gear.ratio * out_angle)
    ptp = float(
        te_peak_to_peak(
            gear.ratio,
            gear.pitch_radius,
            gear.pressure_angle,
            gear.engagement_depth,
            np.array([e.wave_generator_eccentricity]),
            np.array([e.wave_generator_eccentricity_angle]),
            np.array([e.lobe_height_difference]),
            np.array([e.flexspline_ovality]),
            np.array([e.circular_spline_ovality]),
            np.array([e.circular_spline_ovality_angle]),
        )[0]
    )
    harm = te_harmonics(gear)
    return AnalysisResult(
        name="transmission_error",
        title="Transmission error over one output revolution",
        values={
            "te_peak_to_peak [arcsec]": float(rad_to_arcsec(ptp)),
            "te_once_per_wg_revolution [arcsec]": float(rad_to_arcsec(harm["once"])),
            "te_twice_per_wg_revolution [arcsec]": float(rad_to_arcsec(harm["twice"])),
            "te_twice_per_wg_revolution_flexspline [arcsec]": float(
                rad_to_arcsec(harm["twice_flexspline"])
            ),
            "te_peak_to_peak_sampled [arcsec]": float(rad_to_arcsec(np.ptp(te))),
            "output_angle [deg]": rad_to_deg(out_angle),
            "te [arcsec]": rad_to_arcsec(te - te.mean()),
        },
        references=["tuttle1992", "jia2021"],
        notes=[
            "Two-zone mesh (docs/strain-wave.md): TE = −(tan α/r)[(d/2 + e cos(θ − ψ_e))²/h + "
            "ε_c cos 2(θ − ψ_c) + ε_f cos 2(θ(1 + 1/i) − ψ_f)], θ the wave-generator angle; the "
            "once-per-revolution term (tan α/r) d e/h, the twice-per-revolution terms from e²/2h "
            "and the spline ovalities.",
            "te_peak_to_peak: exact extremes of the trigonometric polynomial, the flexspline "
            "term's slow drift taken through every phase over the output revolution; "
            f"te_peak_to_peak_sampled: the trace of {n} positions drawn.",
        ],
    )


def _yield_setup(case: Case, gear: Any):
    from gearte.families.strain_wave import yield_laws
    from gearte.runners.strain_wave_yield import StrainWaveYield

    laws, units, nominal = yield_laws(gear)
    return StrainWaveYield(gear), laws, units, nominal


def preflight(case: Case) -> None:
    """The checks :func:`run` makes before any analysis: the gear is built (its model's checks)
    and the yield's tolerance keys and spec quantities are checked against its error keys and
    the yield model (:func:`~gearte.studies._yield.yield_inputs`).

    Parameters
    ----------
    case : Case
        The validated case.

    Raises
    ------
    ParameterError
        Naming the key of the first failing check.
    """
    from gearte.families import get_family

    gear = get_family(KIND).to_object(case)
    if case.analyses.yield_ is not None:
        from gearte.studies._yield import yield_inputs

        model, laws, units, nominal = _yield_setup(case, gear)
        yield_inputs(
            case.analyses.yield_, units, nominal, defaults=laws, quantities=model.quantities
        )


def _yield(case: Case, gear: Any, options: Any) -> AnalysisResult:
    """``[analyses.yield]``: each sample one gear of the lot → its lost motion and TE."""
    from dataclasses import replace

    from gearte.families import get_family
    from gearte.studies._yield import yield_analysis
    from gearte.units import arcmin_to_rad, um_to_mm

    model, laws, units, nominal = _yield_setup(case, gear)
    to_sections = get_family(KIND).to_sections
    assert to_sections is not None  # this family writes its description back

    def worst_case(errors: Any) -> dict:
        """The sample's gear written back as a case (the family's ``to_sections``)."""
        v = {k: float(errors.get(k, nominal[k])) for k in nominal}
        g = replace(
            gear,
            hysteresis_loss=float(arcmin_to_rad(v["hysteresis_loss"])),
            K1=gear.T1 / float(arcmin_to_rad(v["torsion_at_T1"])),
        )
        changes: dict[str, float] = {
            "lobe_height_difference": float(um_to_mm(v["lobe_height_difference"]))
        }
        for name in (
            "wave_generator_eccentricity",
            "flexspline_ovality",
            "circular_spline_ovality",
        ):
            changes[name] = abs(float(um_to_mm(v[name])))
            if f"{name}_phase_rad" in errors:
                changes[f"{name}_angle"] = float(np.mod(errors[f"{name}_phase_rad"], 2 * np.pi))
        g = g.with_errors(**changes)
        d = case.model_dump(mode="json", by_alias=True, exclude_none=True)
        d.update(to_sections(g))
        d["tolerances"] = {}
        d["analyses"] = {k: v for k, v in d.get("analyses", {}).items() if k != "yield"}
        return d

    return yield_analysis(
        case.analyses.yield_,  # type: ignore[arg-type]
        model,
        units,
        nominal,
        options=options,
        worst_case=worst_case,
        references=["harmonicdrive2015", "jia2021"],
        defaults=laws,
    )


def run(case: Case, options: Any) -> StudyResult:
    """Run a ``strain_wave`` case: kinematics, stiffness and lost motion, transmission error and
    the optional yield; no I/O, no plotting.

    Parameters
    ----------
    case : Case
        The validated case.
    options : RunOptions
        Execution options (the yield's workers, samples, seed).

    Returns
    -------
    StudyResult
        The analyses.
    """
    from gearte.families import get_family

    gear = get_family(KIND).to_object(case)
    analyses = [
        _kinematics(case, gear),
        _stiffness(case, gear),
        _transmission_error(case, gear),
    ]
    if case.analyses.yield_ is not None:
        analyses.append(_yield(case, gear, options))
    return StudyResult(case=case, analyses=analyses, warnings=[])
