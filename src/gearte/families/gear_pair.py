"""Drive family ``gear_pair``: a spur or bevel pair (Jiang et al. 2024) and its backlash stack.

Description: the ``[pair]`` section (:class:`gearte.studies.gear_pair.PairSpec`) → the
:class:`~gearte.models.backlash.SpurPair` / :class:`~gearte.models.backlash.BevelPair`. In a
chain's yield each contributor of the pair's backlash stack is drawn (keys
``<slug>.<contributor>`` [µm], :func:`gearte.runners.chain_yield.stack_terms`).
"""

from __future__ import annotations

from typing import Any

from gearte.families import DriveFamily, StageYield

__all__ = ["FAMILY", "to_object", "to_sections", "drive", "chain_yield", "pair_stage_yield"]


def to_object(case: Any) -> Any:
    """The pair a validated ``gear_pair`` case's ``[pair]`` describes."""
    return case.pair.build()


def to_sections(pair: Any) -> dict[str, Any]:
    """The ``[pair]`` section that describes ``pair`` (a
    :class:`~gearte.models.backlash.SpurPair` or :class:`~gearte.models.backlash.BevelPair`):
    :func:`to_object` of it gives the pair back. Tolerances derived from grades or allowance
    classes are written as the µm values they gave.

    Parameters
    ----------
    pair : SpurPair or BevelPair
        The pair [mm, rad].
    """
    from gearte.models.backlash import BevelPair
    from gearte.units import mm_to_um, rad_to_deg

    def um(x: float) -> float:
        return float(mm_to_um(x))

    def gear(g: Any) -> dict[str, Any]:
        out: dict[str, Any] = {
            "teeth": int(g.teeth),
            "thickness_upper_um": um(g.thickness_upper),
            "thickness_lower_um": um(g.thickness_lower),
        }
        if isinstance(pair, BevelPair):
            out.update(
                bearing_clearance_min_um=um(g.bearing_clearance[0]),
                bearing_clearance_max_um=um(g.bearing_clearance[1]),
                face_profile_tol_um=um(g.face_profile_tol),
                seat_profile_tol_um=um(g.seat_profile_tol),
            )
        else:
            out["radial_composite_tol_um"] = um(g.radial_composite_tol)
        return out

    sec: dict[str, Any] = {
        "module_mm": float(pair.module),
        "pressure_angle_deg": float(rad_to_deg(pair.pressure_angle)),
        "min_backlash_limit_um": um(pair.min_backlash_limit),
        "driving": gear(pair.driving),
        "driven": gear(pair.driven),
    }
    if isinstance(pair, BevelPair):
        sec.update(
            type="bevel",
            face_width_mm=float(pair.face_width),
            shaft_angle_deg=float(rad_to_deg(pair.shaft_angle)),
            shaft_distance_tol_um=um(pair.shaft_distance_tol),
            shaft_angle_tol_um=um(pair.shaft_angle_tol),
            composite_tol_um=um(pair.composite_tol),
        )
    else:
        sec.update(
            type="spur",
            centre_distance_tol_um=um(pair.centre_distance_tol),
            runout_um=um(pair.runout),
            bearing_clearance_min_um=um(pair.bearing_clearance[0]),
            bearing_clearance_max_um=um(pair.bearing_clearance[1]),
        )
    return {"pair": sec}


def drive(case: Any, name: str) -> Any:
    """The :class:`~gearte.drives.gear_pair.GearPairDrive` of a validated case.

    Parameters
    ----------
    case : Case
        The validated case of the family's kind.
    name : str
        Label of the drive (the chain stage's name).
    """
    from gearte.drives.gear_pair import GearPairDrive

    return GearPairDrive(
        to_object(case), name=name, face_width=getattr(case.pair, "face_width_mm", None)
    )


def pair_stage_yield(spec: Any, slug: str) -> StageYield:
    """A pair's own tolerances in a chain's yield: every contributor of its backlash stack.

    Parameters
    ----------
    spec : PairSpec
        The validated ``[pair]`` table (a ``[pair]`` stage's or a ``gear_pair`` drive's).
    slug : str
        The stage's key prefix.
    """
    from gearte.runners.chain_yield import PairLostMotion, stack_terms
    from gearte.studies._yield import ToleranceEntry

    pair = spec.build()
    terms, laws = stack_terms(slug, spec.backlash_stack())
    entries = {
        key: ToleranceEntry(
            kind=kind,
            tolerance_um=tol,
            nominal_um=mu,
            sigmas=6.0 if kind == "rayleigh" else None,
            phase=kind == "rayleigh",
        )
        for key, (kind, tol, mu) in laws.items()
    }
    return StageYield(
        laws=entries,
        units={k: "um" for k in laws},
        nominal={k: mu for k, (_, _, mu) in laws.items()},
        model=PairLostMotion(terms, pair.output_diameter, pair.pressure_angle),
        radial=frozenset(t.key for t in terms if t.radial),
        grade_um=_grades(pair),
    )


def _grades(pair: Any):
    """``grade_um(key, grade)``: a spur gear's eccentricity from its ISO 1328-2 total radial
    composite tolerance F_i″; refused for a bevel gear (no grade)."""

    def grade_um(key: str, grade: int):
        from gearte.models.backlash import BevelPair, SpurPair
        from gearte.studies._yield import GradeTolerance
        from gearte.tolerance.iso1328 import radial_composite_tolerances

        if not key.endswith("_gear_eccentricity"):
            return None
        if isinstance(pair, BevelPair):
            from gearte.errors import ParameterError
            from gearte.tolerance.iso1328 import BEVEL_GRADE_REASON

            raise ParameterError(
                f"analyses.yield.tolerances.{key}.grade", grade, BEVEL_GRADE_REASON
            )
        if not isinstance(pair, SpurPair):
            return None
        which = "driving" if ".driving_gear" in key else "driven"
        teeth = getattr(pair, which).teeth
        f_i2 = radial_composite_tolerances(grade, pair.module, pair.module * teeth).F_i2
        return GradeTolerance(
            f_i2,
            f"ISO 1328-2:1997 radial composite, grade {grade}, {which} gear: z = {teeth}, "
            f"m = {pair.module:g} mm, d = {pair.module * teeth:g} mm: F_i″ = {f_i2:g} µm",
        )

    return grade_um


def chain_yield(case: Any, slug: str) -> StageYield:
    """The pair's backlash-stack contributors (:func:`pair_stage_yield`).

    Parameters
    ----------
    case : Case
        The validated case of the family's kind.
    slug : str
        The chain stage's key prefix (its errors are ``<slug>.<error>``).
    """
    return pair_stage_yield(case.pair, slug)


FAMILY = DriveFamily(
    kind="gear_pair",
    sections=("pair",),
    to_object=to_object,
    to_sections=to_sections,
    drive=drive,
    chain_yield=chain_yield,
    drive_kinds=("spur_pair", "bevel_pair"),
    warm_cases=("jiang2024_spur_pair",),
    bench_case="jiang2024_spur_pair",
)
