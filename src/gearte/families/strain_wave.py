"""Drive family ``strain_wave``: a strain-wave (harmonic) gear, its description in a case file.

Sections (all units in the key names)::

    [gear]        teeth, module, pressure angle, working depth; the catalogue's stiffness model
                  (T1, T2, K1, K2, K3), hysteresis loss and the lost-motion test torque
    [errors]      the errors that make the transmission error: wave-generator eccentricity,
                  lobe-height difference, flexspline and circular-spline ovality (+ directions)
    [tolerances]  production scatter: hysteresis loss and torsion at T1 [arcmin], the errors [µm]

:func:`to_object` turns them into a :class:`~gearte.models.strain_wave.StrainWaveGear` and
:func:`to_sections` writes a gear back as the same sections (one function each way: the worst
Monte-Carlo sample of a yield is written by :func:`to_sections` of that sample's gear). The models
are :mod:`gearte.models.strain_wave`, the drive :class:`gearte.drives.strain_wave.StrainWaveDrive`,
the study kind ``gearte.studies.strain_wave``. In a chain's yield the gear draws its own
tolerances (keys ``<stage slug>.<error>``) and its lost motion follows from them
(:class:`StrainWaveLostMotion`).
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np
from pydantic import Field, model_validator

from gearte.families import DriveFamily, StageYield
from gearte.io.schema import StrictModel

__all__ = [
    "FAMILY",
    "StiffnessSection",
    "GearSection",
    "ErrorsSection",
    "TolerancesSection",
    "TE_ERRORS",
    "LOST_MOTION_KEYS",
    "to_object",
    "to_sections",
    "drive",
    "chain_yield",
    "yield_laws",
    "StrainWaveLostMotion",
]

#: The errors that move the lost motion (drawn in a chain's yield).
LOST_MOTION_KEYS = ("hysteresis_loss", "torsion_at_T1")

#: The TE-making errors: name → (magnitude has a direction, field of its direction).
TE_ERRORS: dict[str, str | None] = {
    "wave_generator_eccentricity": "wave_generator_eccentricity_angle",
    "lobe_height_difference": None,
    "flexspline_ovality": "flexspline_ovality_angle",
    "circular_spline_ovality": "circular_spline_ovality_angle",
}


class StiffnessSection(StrictModel):
    """``[gear.stiffness]``: the catalogue's three-segment torsional stiffness (input locked)."""

    T1_Nm: float = Field(gt=0, le=1e6, description="Limit torque T1 of the K1 segment [N·m].")
    T2_Nm: float = Field(gt=0, le=1e6, description="Limit torque T2 of the K2 segment [N·m].")
    K1_Nm_per_rad: float = Field(gt=0, le=1e10, description="Stiffness K1, 0 to T1 [N·m/rad].")
    K2_Nm_per_rad: float = Field(gt=0, le=1e10, description="Stiffness K2, T1 to T2 [N·m/rad].")
    K3_Nm_per_rad: float = Field(gt=0, le=1e10, description="Stiffness K3, above T2 [N·m/rad].")

    @model_validator(mode="after")
    def _ordered(self) -> StiffnessSection:
        if not self.T1_Nm < self.T2_Nm:
            raise ValueError(f"need T1_Nm < T2_Nm (got {self.T1_Nm} and {self.T2_Nm})")
        return self


class GearSection(StrictModel):
    """``[gear]``: the gear set and its catalogue data (circular spline fixed, WG input)."""

    flexspline_teeth: int = Field(ge=20, le=2000, description="Flexspline teeth z_f [-].")
    circular_spline_teeth: int = Field(
        ge=22, le=2002, description="Circular-spline teeth z_c = z_f + 2 [-]."
    )
    module_mm: float = Field(gt=0, le=10, description="Module m [mm].")
    pressure_angle_deg: float = Field(gt=0, lt=45, description="Pressure angle α [deg].")
    engagement_depth_mm: float | None = Field(
        default=None,
        gt=0,
        le=50,
        description="Nominal working depth h of the mesh [mm]; default: derived as 2 m (a "
        "full-depth tooth's working depth), reported as derived.",
    )
    stiffness: StiffnessSection = Field(description="The catalogue's K1/K2/K3 model.")
    hysteresis_loss_arcmin: float = Field(
        ge=0, le=60, description="Hysteresis loss H at zero torque after ±rated torque [arcmin]."
    )
    lost_motion_torque_Nm: float = Field(
        ge=0, le=1e6, description="Test torque ±T_L of the lost-motion definition [N·m]."
    )

    @model_validator(mode="after")
    def _teeth(self) -> GearSection:
        if self.circular_spline_teeth - self.flexspline_teeth != 2:
            raise ValueError(
                f"circular_spline_teeth must be flexspline_teeth + 2 = "
                f"{self.flexspline_teeth + 2} (a two-lobe wave generator; got "
                f"{self.circular_spline_teeth})"
            )
        return self

    def engagement_depth(self) -> tuple[float, bool]:
        """(h [mm], derived?)."""
        if self.engagement_depth_mm is not None:
            return self.engagement_depth_mm, False
        return 2.0 * self.module_mm, True


class ErrorsSection(StrictModel):
    """``[errors]``: the errors that make the transmission error (all zero by default)."""

    wave_generator_eccentricity_um: float = Field(
        default=0.0, ge=0, le=1000, description="WG axis off the CS axis, e [µm]."
    )
    wave_generator_eccentricity_angle_deg: float = Field(
        default=0.0, ge=-360, le=360, description="Direction ψ_e of the WG eccentricity [deg]."
    )
    lobe_height_difference_um: float = Field(
        default=0.0,
        ge=-1000,
        le=1000,
        description="One major-axis end of the wave deflected d more than the other [µm].",
    )
    flexspline_ovality_um: float = Field(
        default=0.0, ge=0, le=1000, description="Second-harmonic radial error of the FS teeth [µm]."
    )
    flexspline_ovality_angle_deg: float = Field(
        default=0.0, ge=-360, le=360, description="Direction ψ_f of the FS ovality [deg]."
    )
    circular_spline_ovality_um: float = Field(
        default=0.0, ge=0, le=1000, description="Second-harmonic radial error of the CS teeth [µm]."
    )
    circular_spline_ovality_angle_deg: float = Field(
        default=0.0, ge=-360, le=360, description="Direction ψ_c of the CS ovality [deg]."
    )


class TolerancesSection(StrictModel):
    """``[tolerances]``: production scatter of the gear (0: none)."""

    hysteresis_loss_arcmin: float = Field(
        default=0.0, ge=0, le=60, description="± tolerance (3σ, normal) of H [arcmin]."
    )
    torsion_at_T1_arcmin: float = Field(
        default=0.0,
        ge=0,
        le=60,
        description="± tolerance (3σ, normal) of the torsion at T1, θ1 = T1/K1 [arcmin].",
    )
    wave_generator_eccentricity_um: float = Field(
        default=0.0,
        ge=0,
        le=1000,
        description="Tolerance of e [µm]: Rayleigh magnitude, 99.73 % below, uniform direction.",
    )
    lobe_height_difference_um: float = Field(
        default=0.0, ge=0, le=1000, description="± tolerance (3σ, normal) of d [µm]."
    )
    flexspline_ovality_um: float = Field(
        default=0.0, ge=0, le=1000, description="Tolerance of ε_f [µm] (Rayleigh, direction)."
    )
    circular_spline_ovality_um: float = Field(
        default=0.0, ge=0, le=1000, description="Tolerance of ε_c [µm] (Rayleigh, direction)."
    )


def to_object(case: Any) -> Any:
    """The :class:`~gearte.models.strain_wave.StrainWaveGear` of a validated ``strain_wave``
    case (its ``[gear]``, ``[errors]``, ``[tolerances]``).

    Parameters
    ----------
    case : Case
        The validated case.
    """
    from gearte.models.strain_wave import StrainWaveErrors, StrainWaveGear, StrainWaveTolerances
    from gearte.units import Nm_to_Nmm, arcmin_to_rad, deg_to_rad, um_to_mm

    g, e, t = case.gear, case.errors, case.tolerances
    s = g.stiffness
    errors = StrainWaveErrors(
        **{name: float(um_to_mm(getattr(e, f"{name}_um"))) for name in TE_ERRORS},
        **{
            angle: float(deg_to_rad(getattr(e, f"{angle}_deg")))
            for angle in TE_ERRORS.values()
            if angle is not None
        },
    )
    tols = StrainWaveTolerances(
        hysteresis_loss=float(arcmin_to_rad(t.hysteresis_loss_arcmin)),
        torsion_at_T1=float(arcmin_to_rad(t.torsion_at_T1_arcmin)),
        errors={n: float(um_to_mm(getattr(t, f"{n}_um"))) for n in TE_ERRORS},
    )
    return StrainWaveGear(
        flexspline_teeth=g.flexspline_teeth,
        circular_spline_teeth=g.circular_spline_teeth,
        module=g.module_mm,
        pressure_angle=float(deg_to_rad(g.pressure_angle_deg)),
        engagement_depth=g.engagement_depth()[0],
        T1=float(Nm_to_Nmm(s.T1_Nm)),
        T2=float(Nm_to_Nmm(s.T2_Nm)),
        K1=float(Nm_to_Nmm(s.K1_Nm_per_rad)),
        K2=float(Nm_to_Nmm(s.K2_Nm_per_rad)),
        K3=float(Nm_to_Nmm(s.K3_Nm_per_rad)),
        hysteresis_loss=float(arcmin_to_rad(g.hysteresis_loss_arcmin)),
        lost_motion_torque=float(Nm_to_Nmm(g.lost_motion_torque_Nm)),
        errors=errors,
        tolerances=tols,
    )


def to_sections(gear: Any) -> dict[str, Any]:
    """The ``[gear]``, ``[errors]`` and ``[tolerances]`` sections that describe ``gear``:
    :func:`to_object` of a case made of them gives ``gear`` back.

    Parameters
    ----------
    gear : StrainWaveGear
        The gear [mm, N·mm, rad].
    """
    from gearte.units import Nmm_to_Nm, mm_to_um, rad_to_arcmin, rad_to_deg

    e, t = gear.errors, gear.tolerances
    errors: dict[str, float] = {}
    for name, angle in TE_ERRORS.items():
        errors[f"{name}_um"] = float(mm_to_um(getattr(e, name)))
        if angle is not None:
            errors[f"{angle}_deg"] = float(rad_to_deg(getattr(e, angle)))
    return {
        "gear": {
            "flexspline_teeth": int(gear.flexspline_teeth),
            "circular_spline_teeth": int(gear.circular_spline_teeth),
            "module_mm": float(gear.module),
            "pressure_angle_deg": float(rad_to_deg(gear.pressure_angle)),
            "engagement_depth_mm": float(gear.engagement_depth),
            "stiffness": {
                "T1_Nm": float(Nmm_to_Nm(gear.T1)),
                "T2_Nm": float(Nmm_to_Nm(gear.T2)),
                "K1_Nm_per_rad": float(Nmm_to_Nm(gear.K1)),
                "K2_Nm_per_rad": float(Nmm_to_Nm(gear.K2)),
                "K3_Nm_per_rad": float(Nmm_to_Nm(gear.K3)),
            },
            "hysteresis_loss_arcmin": float(rad_to_arcmin(gear.hysteresis_loss)),
            "lost_motion_torque_Nm": float(Nmm_to_Nm(gear.lost_motion_torque)),
        },
        "errors": errors,
        "tolerances": {
            "hysteresis_loss_arcmin": float(rad_to_arcmin(t.hysteresis_loss)),
            "torsion_at_T1_arcmin": float(rad_to_arcmin(t.torsion_at_T1)),
            **{f"{n}_um": float(mm_to_um(t.errors.get(n, 0.0))) for n in TE_ERRORS},
        },
    }


def drive(case: Any, name: str) -> Any:
    """The :class:`~gearte.drives.strain_wave.StrainWaveDrive` of a validated case.

    Parameters
    ----------
    case : Case
        The validated ``strain_wave`` case.
    name : str
        Label of the drive (the chain stage's name).
    """
    from gearte.drives.strain_wave import StrainWaveDrive

    return StrainWaveDrive(to_object(case), name=name)


def yield_laws(gear: Any, prefix: str = "") -> tuple[dict, dict, dict]:
    """``(laws, units, nominal)`` of the gear's tolerances: each toleranced error key (with
    ``prefix``) → its :class:`~gearte.studies._yield.ToleranceEntry`, every error key → its unit
    and nominal value (:data:`gearte.runners.strain_wave_yield.ERROR_KEYS`).

    Parameters
    ----------
    gear : StrainWaveGear
        The gear with its tolerances.
    prefix : str
        Key prefix (``"<stage slug>."`` in a chain).
    """
    from gearte.runners.strain_wave_yield import ERROR_KEYS, StrainWaveYield
    from gearte.studies._yield import ToleranceEntry
    from gearte.units import mm_to_um, rad_to_arcmin

    nominal = StrainWaveYield(gear).nominal()
    t = gear.tolerances
    laws: dict[str, Any] = {}
    for key, tol in (("hysteresis_loss", t.hysteresis_loss), ("torsion_at_T1", t.torsion_at_T1)):
        if tol > 0:
            laws[prefix + key] = ToleranceEntry(
                tolerance_arcmin=float(rad_to_arcmin(tol)), nominal_arcmin=nominal[key]
            )
    for name, angle in TE_ERRORS.items():
        tol = float(t.errors.get(name, 0.0))
        if tol <= 0:
            continue
        if angle is None:
            laws[prefix + name] = ToleranceEntry(
                tolerance_um=float(mm_to_um(tol)), nominal_um=nominal[name]
            )
        else:
            laws[prefix + name] = ToleranceEntry(
                kind="rayleigh", tolerance_um=float(mm_to_um(tol)), nominal_um=0.0, phase=True
            )
    units = {prefix + k: u for k, u in ERROR_KEYS.items()}
    return laws, units, {prefix + k: v for k, v in nominal.items()}


class StrainWaveLostMotion:
    """A chain stage's lost motion [rad] from the gear's drawn errors (picklable).

    Parameters
    ----------
    gear : StrainWaveGear
        The nominal gear.
    prefix : str
        ``"<stage slug>."``.
    """

    def __init__(self, gear: Any, prefix: str) -> None:
        from gearte.runners.strain_wave_yield import StrainWaveYield

        self.model = StrainWaveYield(gear, prefix)

    def __call__(self, errors: Mapping[str, np.ndarray], n: int) -> np.ndarray:
        return self.model.lost_motion(errors, n)


def chain_yield(case: Any, slug: str) -> StageYield | None:
    """The gear's own tolerances that move its lost motion, in a chain's yield: its hysteresis
    loss and torsion at T1 (keys ``<slug>.hysteresis_loss``, ``<slug>.torsion_at_T1``
    [arcmin]); ``None`` when neither has a tolerance. (The TE-making errors do not change the
    lost motion: they are not drawn there.)

    Parameters
    ----------
    case : Case
        The validated ``strain_wave`` case.
    slug : str
        The chain stage's key prefix.
    """
    gear = to_object(case)
    laws, units, nominal = yield_laws(gear, f"{slug}.")
    keep = [f"{slug}.{k}" for k in LOST_MOTION_KEYS]
    laws = {k: v for k, v in laws.items() if k in keep}
    if not laws:
        return None
    return StageYield(
        laws=laws,
        units={k: units[k] for k in keep},
        nominal={k: nominal[k] for k in keep},
        model=StrainWaveLostMotion(gear, f"{slug}."),
    )


FAMILY = DriveFamily(
    kind="strain_wave",
    sections=("gear", "errors", "tolerances"),
    to_object=to_object,
    to_sections=to_sections,
    drive=drive,
    chain_yield=chain_yield,
    drive_kinds=("strain_wave",),
    # its TE peak-to-peak calls trig_extremes' batch kernel, which no other kind's warm-up case
    # compiles (the planetary kind's TE kernel has the extremes search written in)
    warm_cases=("harmonicdrive_csf32_100",),
    bench_case="harmonicdrive_csf32_100",
    labels={
        "te_once_per_wg_revolution": "TE once per wave-generator revolution",
        "te_twice_per_wg_revolution": "TE twice per wave-generator revolution",
        "te_twice_per_wg_revolution_flexspline": "TE of the flexspline ovality (≈ twice per WG "
        "revolution)",
    },
)
