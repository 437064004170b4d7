"""Drives described in case files: the one place that turns a kind's sections into a drive.

A ``gear_chain`` stage (and anything else that composes drives) names a drive by its study kind
and gives it either as a case file of that kind or inline, with the same sections that kind's
case file has (``[reducer]``… for ``rv_reducer``, ``[stage]``/``[errors]`` for
``cycloid_stage``, ``[gearset]``/``[errors]`` for ``planetary``, ``[pair]`` for ``gear_pair``).
Those sections are validated by that kind's own ``Case`` schema, and the drive is built from the
validated case by :func:`drive_from_case` — so a change of a kind's schema touches that kind's
module and, at most, this file.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any, Literal

from pydantic import ConfigDict, Field, PrivateAttr, ValidationInfo, model_validator

from gearte.drives import Drive
from gearte.errors import ParameterError
from gearte.io.schema import StrictModel

__all__ = ["DRIVE_CASE_KINDS", "DriveSpec", "drive_from_case"]

#: Study kinds whose case describes one drive, with the sections that describe it.
DRIVE_CASE_KINDS: dict[str, tuple[str, ...]] = {
    "gear_pair": ("pair",),
    "planetary": ("gearset", "errors"),
    "cycloid_stage": ("stage", "errors"),
    "rv_reducer": ("reducer", "analyses"),
}

DriveKind = Literal["gear_pair", "planetary", "cycloid_stage", "rv_reducer"]


def _lines(exc: Exception) -> str:
    """One-line summary of a nested validation/case-file error."""
    from pydantic import ValidationError

    from gearte.errors import CaseFileError
    from gearte.io.case_file import format_validation_errors

    if isinstance(exc, ValidationError):
        pairs = format_validation_errors(exc)
    elif isinstance(exc, CaseFileError):
        pairs = exc.errors
    else:
        return str(exc)
    return "; ".join(f"{f}: {m}" for f, m in pairs)


def _resolve(path: str, base_dir: str | None) -> Path:
    """A drive's case file: relative to the chain case's folder, else a bundled case name."""
    from gearte.cases import case_path

    p = Path(path)
    if not p.is_absolute() and base_dir is not None:
        try:
            if (Path(base_dir) / p).is_file():
                return Path(base_dir) / p
        except (OSError, ValueError):  # a name too long, a NUL byte: not a file; case_path says
            pass
    return case_path(path)


class DriveSpec(StrictModel):
    """A drive gearte models: ``kind`` and a case file of that kind, or its sections inline."""

    model_config = ConfigDict(**{**StrictModel.model_config, "extra": "allow"})

    kind: DriveKind = Field(description="Study kind of the drive: " + ", ".join(DRIVE_CASE_KINDS))
    case: str | None = Field(
        default=None,
        min_length=1,
        description="Case file of that kind, relative to this case file (or a bundled name).",
    )
    _case: Any = PrivateAttr(default=None)
    _source: str = PrivateAttr(default="inline")

    @model_validator(mode="after")
    def _validate_sections(self, info: ValidationInfo) -> DriveSpec:
        from pydantic import ValidationError

        from gearte.errors import CaseFileError
        from gearte.io.case_file import load_case
        from gearte.studies import get_kind

        extra = dict(self.model_extra or {})
        wanted = DRIVE_CASE_KINDS[self.kind]
        if self.case is not None:
            if extra:
                raise ValueError(
                    f"give either case = '<file>' or the drive's sections inline, not both "
                    f"(got case and {sorted(extra)})"
                )
            base = (info.context or {}).get("case_dir")
            try:
                path = _resolve(self.case, base)
                loaded = load_case(path)
            except FileNotFoundError as exc:
                raise ValueError(f"case = {self.case!r}: {exc}") from None
            except CaseFileError as exc:
                raise ValueError(f"case = {self.case!r} does not validate: {_lines(exc)}") from None
            if loaded.case.kind != self.kind:
                raise ValueError(
                    f"case = {self.case!r} is a {loaded.case.kind!r} case, not {self.kind!r}"
                )
            self._case, self._source = loaded, str(path)
            return self
        unknown = sorted(set(extra) - set(wanted))
        if unknown:
            raise ValueError(
                f"unknown section(s) {unknown} for a {self.kind!r} drive; its sections: "
                f"{list(wanted)} (or case = '<file>')"
            )
        if not extra:
            raise ValueError(
                f"give case = '<file>' or the {self.kind!r} sections {list(wanted)} inline"
            )
        try:
            self._case = get_kind(self.kind).Case.model_validate(
                {"case": {"kind": self.kind}, **extra}, context=info.context
            )
        except ValidationError as exc:
            raise ValueError(f"{self.kind} drive: {_lines(exc)}") from None
        return self

    @property
    def validated_case(self) -> Any:
        """The drive's description validated as a case of its kind."""
        return self._case

    @property
    def source(self) -> str:
        """``"inline"`` or the path of the case file read."""
        return self._source

    def build(self, name: str) -> Drive:
        """The drive object (see :func:`drive_from_case`)."""
        return drive_from_case(self._case, name=name)


def drive_from_case(case: Any, *, name: str | None = None) -> Drive:
    """The :class:`~gearte.drives.Drive` a validated case of a drive kind describes.

    Parameters
    ----------
    case : Case
        A validated ``gear_pair``, ``planetary``, ``cycloid_stage`` or ``rv_reducer`` case.
    name : str, optional
        Label of the drive; default: the case name.
    """
    kind = case.case.kind
    label = name or case.case.name or kind
    if kind == "gear_pair":
        from gearte.drives.gear_pair import GearPairDrive

        spec = case.pair
        return GearPairDrive(
            spec.build(), name=label, face_width=getattr(spec, "face_width_mm", None)
        )
    if kind == "planetary":
        from gearte.drives.planetary import PlanetaryDrive
        from gearte.studies.planetary import build_terms

        terms, mags, angs = build_terms(case)
        return PlanetaryDrive(case.gearset.build(), terms, mags, angs, name=label)
    if kind == "cycloid_stage":
        from gearte.drives.cycloid_stage import CycloidStageDrive
        from gearte.studies.cycloid_stage import build_stage

        return CycloidStageDrive(
            build_stage(case.stage),
            case.errors.means_mm(),
            case.errors.tolerances_mm(),
            name=label,
        )
    if kind == "rv_reducer":
        from gearte.drives.rv_reducer import RVDrive
        from gearte.studies.rv_reducer import build_reducer, first_stage_terms
        from gearte.units import deg_to_rad

        red = build_reducer(case.reducer)
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
            return RVDrive(red, name=label, law=law, first_stage_free_angle=free)
        return RVDrive(
            red,
            name=label,
            position=float(deg_to_rad(cat.position_deg)),
            turning_points=tuple(cat.torque_sweep),
            steps_per_segment=cat.steps_per_segment,
            lost_motion_fraction=cat.lost_motion_fraction,
            law=law,
            first_stage_free_angle=free,
        )
    raise ValueError(
        f"case kind {kind!r} does not describe one drive; drive kinds: {list(DRIVE_CASE_KINDS)}"
    )
