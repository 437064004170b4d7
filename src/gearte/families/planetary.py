"""Drive family ``planetary``: a 2K-H planetary set and its error terms (Wang et al. 2013).

Description: ``[gearset]`` and ``[errors]`` → the :class:`~gearte.models.planetary_terms`
set, its terms, magnitudes and angles. Wang 2013's model has no backlash: a chain stage gives its
lost motion beside it, so in a chain's yield its lost motion is drawn from those values.
"""

from __future__ import annotations

from typing import Any

from gearte.families import DriveFamily

__all__ = ["FAMILY", "to_object", "drive"]


def to_object(case: Any) -> tuple[Any, Any, dict[str, float], dict[str, float]]:
    """``(set, terms, magnitudes [mm], angles [rad])`` of a validated ``planetary`` case."""
    from gearte.studies.planetary import build_terms

    terms, mags, angs = build_terms(case)
    return case.gearset.build(), terms, mags, angs


def drive(case: Any, name: str) -> Any:
    """The :class:`~gearte.drives.planetary.PlanetaryDrive` of a validated case.

    Parameters
    ----------
    case : Case
        The validated case of the family's kind.
    name : str
        Label of the drive (the chain stage's name).
    """
    from gearte.drives.planetary import PlanetaryDrive

    return PlanetaryDrive(*to_object(case), name=name)


FAMILY = DriveFamily(
    kind="planetary",
    sections=("gearset", "errors"),
    to_object=to_object,
    drive=drive,
    lost_motion=False,
    drive_kinds=("planetary",),
    warm_cases=("wang2013_2kh_eq9",),
    bench_case="wang2013_2kh_eq9",
)
