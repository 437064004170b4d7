"""Drive family ``planetary``: a 2K-H planetary set and its error terms (Wang et al. 2013).

Description: ``[gearset]`` and ``[errors]`` ↔ the :class:`~gearte.geometry.planetary.PlanetarySet`,
its :class:`~gearte.models.planetary_terms.TermSet`, magnitudes and angles (:func:`to_object`,
:func:`to_sections`). Wang 2013's model has no backlash: a chain stage gives its
lost motion beside it, so in a chain's yield its lost motion is drawn from those values.
"""

from __future__ import annotations

from typing import Any

from gearte.families import DriveFamily

__all__ = ["FAMILY", "to_object", "to_sections", "drive"]


def to_object(case: Any) -> tuple[Any, Any, dict[str, float], dict[str, float]]:
    """``(set, terms, magnitudes [mm], angles [rad])`` of a validated ``planetary`` case."""
    from gearte.studies.planetary import build_terms

    terms, mags, angs = build_terms(case)
    return case.gearset.build(), terms, mags, angs


def _tidy(x: Any) -> float:
    """``x`` to 15 significant digits: a value that went through a unit conversion (µm → mm →
    µm, deg → rad → deg) is written as it was given; the change is below 1e-15 relative."""
    return float(f"{float(x):.15g}")


def to_sections(obj: tuple[Any, Any, dict[str, float], dict[str, float]]) -> dict[str, Any]:
    """The ``[gearset]`` and ``[errors]`` sections that describe ``obj``: ``to_object`` of a case
    made of them gives ``obj`` back (the unit conversions written to 15 significant digits).

    Parameters
    ----------
    obj : tuple
        ``(set, terms, magnitudes [mm], angles [rad])`` as :func:`to_object` gives it.

    Returns
    -------
    dict
        ``{"gearset": {...}, "errors": {...}}``, JSON-able, units in the keys. Terms that are
        those :func:`gearte.models.planetary_errors.derive_terms` derives from the set (either
        planet model) are written as ``source = "derived"``; any other term set as its table
        (``source = "terms"``).

    Raises
    ------
    ParameterError
        ``terms.scale`` not ± the set's output scale, or a term on an external/internal line
        that is not the derived set's (a table's terms are "given").
    """
    from gearte.errors import ParameterError
    from gearte.models.planetary_errors import derive_terms
    from gearte.units import mm_to_um, rad_to_deg

    pset, terms, mags, angs = obj
    gearset: dict[str, Any] = {
        "z_sun": int(pset.z_sun),
        "z_planet": int(pset.z_planet),
        "z_ring": int(pset.z_ring),
        "module_mm": float(pset.module),
        "pressure_angle_deg": _tidy(rad_to_deg(pset.pressure_angle)),
        "n_planets": int(pset.n_planets),
        "fixed": pset.fixed,
        "input": pset.input,
        "output": pset.output,
        "standard": bool(pset.standard),
    }
    if pset.planet_angles is not None:
        gearset["planet_angles_deg"] = [_tidy(rad_to_deg(a)) for a in pset.planet_angles]
    errors: dict[str, Any] = {
        "magnitudes_um": {k: _tidy(mm_to_um(v)) for k, v in mags.items()},
        "angles_deg": {k: _tidy(rad_to_deg(v)) for k, v in angs.items()},
    }
    model = next((m for m in ("reference", "mean") if derive_terms(pset, m) == terms), None)
    if model is not None:
        errors.update(source="derived", planet_model=model)
        return {"gearset": gearset, "errors": errors}
    sign = terms.scale / pset.output_scale()
    if sign not in (-1.0, 1.0):
        raise ParameterError(
            "terms.scale", terms.scale, f"must be ± the set's output scale {pset.output_scale()}"
        )
    rows = []
    for t in terms.terms:
        if t.line != "given":
            raise ParameterError(
                f"terms.{t.name}.line", t.line, "a term table's terms are 'given' (no mesh line)"
            )
        row: dict[str, Any] = {
            "name": t.name,
            "magnitude": t.magnitude,
            "gain": float(t.gain),
            "frequency": str(t.frequency),
            "phase_deg": _tidy(rad_to_deg(t.phase)),
        }
        if t.angle is not None:
            row.update(angle=t.angle, angle_coeff=int(t.angle_coeff))
        rows.append(row)
    errors.update(source="terms", terms=rows, overall_sign=int(sign))
    if terms.reference_angle is not None:
        errors["reference_angle"] = terms.reference_angle
    return {"gearset": gearset, "errors": errors}


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
    to_sections=to_sections,
    drive=drive,
    lost_motion=False,
    drive_kinds=("planetary",),
    warm_cases=("wang2013_2kh_eq9",),
    bench_case="wang2013_2kh_eq9",
)
