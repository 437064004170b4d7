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
    "to_object",
    "to_sections",
    "drive",
    "chain_yield",
    "RVLostMotion",
]


def to_object(case: Any) -> Any:
    """The :class:`~gearte.models.rv_load_sharing.RVReducer` of a validated ``rv_reducer`` case."""
    from gearte.studies.rv_reducer import build_reducer

    return build_reducer(case.reducer)


def to_sections(red: Any) -> dict[str, Any]:
    """The ``[reducer]`` section (and an empty ``[analyses]``) that describes ``red`` (an
    :class:`~gearte.geometry.rv.RVReducer`): ``to_object`` of a case made of them gives ``red``
    back (:func:`gearte.studies.rv_reducer.reducer_section`: its derived stiffnesses written as
    given keys, what the object does not hold left out).

    Parameters
    ----------
    red : RVReducer
        The reducer [mm, N, N·mm, rad].
    """
    from gearte.studies.rv_reducer import reducer_section

    return {"reducer": reducer_section(red), "analyses": {}}


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
