"""Drive family ``cycloid_stage``: a cycloid–pin stage and its nine component errors (Hu et al.
2020).

Description: ``[stage]`` ↔ :class:`~gearte.geometry.cycloid.CycloidStage` (:func:`to_object`,
:func:`to_sections`), ``[errors]`` the means and tolerance bands of Hu 2020 Table 2's nine
component errors. In a chain's yield the stage draws those nine errors (keys
``<stage slug>.<factor>`` [µm], mean ± T/2 read as normal with σ = T/6, as the kind's own yield)
and its lost motion is the geometric TE they give (eq 5–16, clipped at 0:
:class:`CycloidLostMotion`).
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np

from gearte.families import DriveFamily, StageYield

__all__ = ["FAMILY", "to_object", "to_sections", "drive", "chain_yield", "CycloidLostMotion"]


def to_object(case: Any) -> Any:
    """The :class:`~gearte.geometry.cycloid.CycloidStage` of a validated ``cycloid_stage`` case
    (its ``[stage]``)."""
    from gearte.studies.cycloid_stage import build_stage

    return build_stage(case.stage)


def to_sections(stage: Any) -> dict[str, Any]:
    """The ``[stage]`` section that describes ``stage`` (a
    :class:`~gearte.geometry.cycloid.CycloidStage`): ``to_object`` of it gives ``stage`` back.

    Parameters
    ----------
    stage : CycloidStage
        The stage [mm, rad].
    """
    from gearte.units import rad_to_arcmin

    return {
        "stage": {
            "pins": int(stage.z_p),
            "cycloid_teeth": int(stage.z_c),
            "pin_circle_radius_mm": float(stage.r_p),
            "pin_radius_mm": float(stage.r_rp),
            "eccentricity_mm": float(stage.a),
            "face_width_mm": float(stage.b),
            "equidistant_modification_mm": float(stage.dr_rp),
            "shifted_modification_mm": float(stage.dr_p),
            "rotation_modification_arcmin": float(rad_to_arcmin(stage.rotation)),
        }
    }


def drive(case: Any, name: str) -> Any:
    """The :class:`~gearte.drives.cycloid_stage.CycloidStageDrive` of a validated case.

    Parameters
    ----------
    case : Case
        The validated case of the family's kind.
    name : str
        Label of the drive (the chain stage's name).
    """
    from gearte.drives.cycloid_stage import CycloidStageDrive

    return CycloidStageDrive(
        to_object(case), case.errors.means_mm(), case.errors.tolerances_mm(), name=name
    )


class CycloidLostMotion:
    """A cycloid stage's lost motion from its drawn component errors (picklable).

    Parameters
    ----------
    stage : CycloidStage
        The nominal stage.
    slug : str
        The chain stage's key prefix (keys ``<slug>.<factor>`` [µm]).
    nominal_um : mapping
        Factor → mean [µm].

    Notes
    -----
    Hu et al. (2020) eq 5–16 through :class:`gearte.runners.yield_models.CycloidGeometricTE`; a
    negative geometric TE (preload) loses no motion: ``max(TE, 0)`` [rad].
    """

    def __init__(self, stage: Any, slug: str, nominal_um: Mapping[str, float]) -> None:
        from gearte.runners.yield_models import CycloidGeometricTE

        self.slug = slug
        self.te = CycloidGeometricTE(stage, nominal_um)

    def __call__(self, errors: Mapping[str, np.ndarray], n: int) -> np.ndarray:
        from gearte.units import arcmin_to_rad

        te = self.te({k: errors[f"{self.slug}.{k}"] for k in self.te.factors})
        return np.maximum(arcmin_to_rad(te[self.te.quantities[0]]), 0.0)


def chain_yield(case: Any, slug: str) -> StageYield | None:
    """The stage's nine component errors with a tolerance band (``None`` when none has one).

    Parameters
    ----------
    case : Case
        The validated case of the family's kind.
    slug : str
        The chain stage's key prefix (its errors are ``<slug>.<error>``).
    """
    from gearte.models.cycloid_te import ERROR_FACTORS
    from gearte.studies._yield import ToleranceEntry

    means = {k: float(getattr(case.errors, k).mean_um) for k in ERROR_FACTORS}
    bands = {k: getattr(case.errors, k).tolerance_um for k in ERROR_FACTORS}
    if not any(t > 0 for t in bands.values()):
        return None
    laws = {
        f"{slug}.{k}": ToleranceEntry(tolerance_um=0.5 * t, nominal_um=means[k])
        for k, t in bands.items()
        if t > 0
    }
    return StageYield(
        laws=laws,
        units={f"{slug}.{k}": "um" for k in ERROR_FACTORS},
        nominal={f"{slug}.{k}": means[k] for k in ERROR_FACTORS},
        model=CycloidLostMotion(to_object(case), slug, means),
    )


FAMILY = DriveFamily(
    kind="cycloid_stage",
    sections=("stage", "errors"),
    to_object=to_object,
    to_sections=to_sections,
    drive=drive,
    chain_yield=chain_yield,
    drive_kinds=("cycloid_stage",),
    warm_cases=("hu2020_rv80e_initial",),
    bench_case="hu2020_rv80e_initial",
)
