"""Drive family ``rv_reducer``: a whole RV reducer (Han et al. 2023 load sharing, Hu et al. 2020
contact) with its catalogue virtual test.

Description: ``[reducer]`` (:class:`gearte.studies.rv_reducer.ReducerSection`) ↔ the
:class:`~gearte.geometry.rv.RVReducer` (:func:`to_object`, through
:func:`gearte.studies.rv_reducer.build_reducer`, and :func:`to_sections`); ``[analyses]``'s
``catalogue`` options set the drive's virtual test. An RV reducer described with its given
(measured) errors only has no tolerances: in a chain's yield its lost motion is held at its
model's value. One whose case has ``[analyses.yield]`` tolerances draws them in a chain's
yield too (keys ``<stage slug>.<error key>``), each sample one assembled reducer through the
catalogue virtual test (:class:`RVLostMotion`).
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np

from gearte.families import DriveFamily, StageYield

__all__ = [
    "FAMILY",
    "CASE_ONLY_KEYS",
    "to_object",
    "to_sections",
    "with_case_keys",
    "drive",
    "chain_yield",
    "RVLostMotion",
]


def to_object(case: Any) -> Any:
    """The :class:`~gearte.models.rv_load_sharing.RVReducer` of a validated ``rv_reducer`` case."""
    from gearte.studies.rv_reducer import build_reducer

    return build_reducer(case.reducer)


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


def _one_stiffness(field: str, compliances: tuple[float, ...] | None) -> float | None:
    """The one stiffness [N/mm] of a per-disc compliance tuple [mm/N] (``None``: left out).

    Raises
    ------
    ParameterError
        Naming ``field`` when the discs' compliances differ: ``[reducer]`` gives one stiffness
        for every disc.
    """
    from gearte.errors import ParameterError

    if compliances is None:
        return None
    c = np.asarray(compliances, dtype=float)
    if not np.allclose(c, c[0], rtol=1e-12, atol=0.0):
        raise ParameterError(
            field,
            tuple(float(x) for x in c),
            "the discs' compliances differ; [reducer] gives one stiffness for every disc",
        )
    return float(1.0 / c[0])


def _error_entries(errors: Any) -> list[dict[str, Any]]:
    """``[[reducer.errors]]`` of a :class:`~gearte.geometry.rv.ManufacturingErrors`: one entry
    per non-zero error vector, its length [µm] and direction [deg] in the part's frame."""
    from gearte.geometry.planetary import EccentricityError
    from gearte.units import mm_to_um, rad_to_deg

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
        entry["value_um"] = float(mm_to_um(e.amplitude))
        entry["angle_deg"] = float(rad_to_deg(e.phase))
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


def to_sections(red: Any) -> dict[str, Any]:
    """The ``[reducer]`` section (and an empty ``[analyses]``) that describes ``red``:
    ``to_object`` of a case made of them gives ``red`` back (every field and array equal to the
    round-off of the unit conversions: µm ↔ mm, deg ↔ rad, an error vector ↔ its length and
    direction, a stiffness ↔ its compliance).

    Parameters
    ----------
    red : RVReducer
        The reducer [mm, N, N·mm, rad] (:class:`~gearte.geometry.rv.RVReducer`).

    Returns
    -------
    dict
        ``{"reducer": {...}, "analyses": {}}``, JSON-able, units in the keys.

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
    from gearte.errors import ParameterError
    from gearte.units import NM_PER_RAD_TO_NMM_PER_RAD, Nmm_to_Nm, mm_to_um, rad_to_deg

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
        return float(mm_to_um(x))

    def opt(table: dict[str, Any], key: str, value: Any) -> None:
        if value is not None:
            table[key] = float(value)

    def per_item(values: np.ndarray) -> list[float] | None:
        v = np.asarray(values, dtype=float)
        return None if not np.any(v) else [float(x) for x in mm_to_um(v)]

    first: dict[str, Any] = {
        "sun_teeth": int(fs.sun_teeth),
        "planet_teeth": int(fs.planet_teeth),
        "planets": int(red.planets),
        "module_mm": float(fs.module),
        "pressure_angle_deg": float(rad_to_deg(fs.pressure_angle)),
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
        cranks["torsional_stiffness_Nm_per_rad"] = float(
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
        pins["seat_stiffness_N_per_mm"] = float(1.0 / p.seat_compliance)
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
        supports["output_flange_torsional_stiffness_Nm_per_rad"] = float(
            s.output_torsional_stiffness / NM_PER_RAD_TO_NMM_PER_RAD
        )
    reducer: dict[str, Any] = {"contact_law": d.contact_law}
    if red.rated_torque is not None:
        reducer["rated_torque_Nm"] = float(Nmm_to_Nm(red.rated_torque))
    reducer.update(
        first_stage=first,
        cranks=cranks,
        discs=discs,
        pins=pins,
        supports=supports,
        errors=_error_entries(err),
    )
    return {"reducer": reducer, "analyses": {}}


def with_case_keys(reducer: dict[str, Any], case_reducer: Mapping[str, Any]) -> dict[str, Any]:
    """``reducer`` (a ``[reducer]`` table written by :func:`to_sections`) with the keys the
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


def drive(case: Any, name: str) -> Any:
    """The :class:`~gearte.drives.rv_reducer.RVDrive` of a validated case: its pin-contact law,
    its first stage's backlash at the output (when additive) and the case's catalogue options.

    Parameters
    ----------
    case : Case
        The validated ``rv_reducer`` case.
    name : str
        Label of the drive (the chain stage's name).

    Raises
    ------
    ParameterError
        ``reducer.rated_torque_Nm`` missing (the catalogue virtual test needs it).
    """
    from gearte.drives.rv_reducer import RVDrive
    from gearte.errors import ParameterError
    from gearte.studies.rv_reducer import first_stage_terms
    from gearte.units import deg_to_rad

    red = to_object(case)
    if getattr(red, "rated_torque", None) is None:
        raise ParameterError(
            "reducer.rated_torque_Nm",
            None,
            "an RV drive's lost motion and stiffness come from the catalogue virtual test, "
            "which needs the rated torque",
        )
    law_name = getattr(case.reducer, "contact_law", None)  # the case's pin-contact law
    law = None
    if law_name is not None:
        from gearte.models.rv_load_sharing import contact_law

        law = contact_law(red, law_name)
    cat = getattr(case.analyses, "catalogue", None)
    free = 0.0  # the first stage's backlash at the output (first_stage_backlash = additive)
    fs_terms = first_stage_terms(case.reducer.first_stage)
    if fs_terms is not None and getattr(cat, "first_stage_backlash", "additive") == "additive":
        import numpy as np

        from gearte.models.rv_first_stage import output_free_angle
        from gearte.units import um_to_mm

        mid = um_to_mm(np.asarray(fs_terms["backlash_um"]["mid"], dtype=float))
        free = float(output_free_angle(mid, fs_terms["r_sun"], float(red.ratio)))
    if cat is None:
        return RVDrive(red, name=name, law=law, first_stage_free_angle=free)
    return RVDrive(
        red,
        name=name,
        position=float(deg_to_rad(cat.position_deg)),
        turning_points=tuple(cat.torque_sweep),
        steps_per_segment=cat.steps_per_segment,
        lost_motion_fraction=cat.lost_motion_fraction,
        law=law,
        first_stage_free_angle=free,
    )


class RVLostMotion:
    """A chain stage's lost motion [rad] from its reducer's drawn errors (picklable).

    Parameters
    ----------
    model : RVReducerYield or FirstStageBacklashYield
        The reducer's own yield model (:func:`gearte.studies.rv_reducer._yield_model`).
    prefix : str
        ``"<stage slug>."``.
    """

    def __init__(self, model: Any, prefix: str) -> None:
        self.model, self.prefix = model, prefix

    def __call__(self, errors: Mapping[str, np.ndarray], n: int) -> np.ndarray:
        from gearte.units import arcmin_to_rad

        p = self.prefix
        drawn = {k[len(p) :]: np.asarray(errors[k]) for k in errors if k.startswith(p)}
        out = np.asarray(self.model(drawn)["lost_motion [arcmin]"], dtype=float)
        if out.shape != (n,):  # nothing drawn: the reducer as described, every sample
            out = np.full(n, float(out.reshape(-1)[0]))
        return np.asarray(arcmin_to_rad(out), dtype=float)


def chain_yield(case: Any, slug: str) -> StageYield | None:
    """The reducer's own tolerances (its case's ``[analyses.yield]``, with the first stage's
    backlash classes when additive) in a chain's yield; ``None`` without that section.

    Parameters
    ----------
    case : Case
        The validated ``rv_reducer`` case.
    slug : str
        The chain stage's key prefix.
    """
    sec = getattr(case.analyses, "yield_", None)
    if sec is None:
        return None
    from gearte.studies.rv_reducer import _grade_um, _yield_keys, _yield_model

    red = to_object(case)
    model, _ = _yield_model(case, red, sec)
    families, defaults, units = _yield_keys(case, red, sec)
    laws = {**defaults, **sec.tolerances}
    if not laws:
        return None
    p = f"{slug}."
    grade = _grade_um(case)
    return StageYield(
        laws={p + k: v for k, v in laws.items()},
        units={p + k: u for k, u in units.items()},
        nominal={},
        model=RVLostMotion(model, p),
        grade_um=lambda key, g: grade(key[len(p) :], g),
        families={p + k: [p + i for i in v] for k, v in families.items()},
    )


FAMILY = DriveFamily(
    kind="rv_reducer",
    sections=("reducer", "analyses"),
    to_object=to_object,
    to_sections=to_sections,
    drive=drive,
    chain_yield=chain_yield,
    drive_kinds=("rv_reducer",),
    warm_cases=("hu2020_rv80e_initial_reducer", "han2023_rv110e_yield"),
    bench_case="hu2020_rv80e_initial_reducer",
)
