"""Drives described in case files: the one place that turns a kind's sections into a drive.

A ``gear_chain`` stage (and anything else that composes drives) names a drive by its family
(:mod:`gearte.families`, the family's study kind) and gives it either as a case file of that kind
or inline, with the sections its family declares (``FAMILY.sections``: ``[reducer]``… for
``rv_reducer``, ``[pair]`` for ``gear_pair``, ...). Those sections are validated by that kind's
own ``Case`` schema, and the drive is built from the validated case by its family's ``drive``
(:func:`drive_from_case`) — nothing here names a family.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from pydantic import (
    ConfigDict,
    Field,
    PrivateAttr,
    ValidationInfo,
    field_validator,
    model_validator,
)

from gearte.drives import Drive
from gearte.families import family_kinds, get_family
from gearte.io.schema import StrictModel

__all__ = ["DriveSpec", "drive_from_case"]


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

    kind: str = Field(
        description="Study kind of the drive, a registered drive family (gearte.families): "
        + ", ".join(family_kinds())
    )
    case: str | None = Field(
        default=None,
        min_length=1,
        description="Case file of that kind, relative to this case file (or a bundled name).",
    )
    _case: Any = PrivateAttr(default=None)
    _source: str = PrivateAttr(default="inline")

    @field_validator("kind")
    @classmethod
    def _registered(cls, v: str) -> str:
        if v not in family_kinds():
            raise ValueError(f"unknown drive kind {v!r}; drive families: {list(family_kinds())}")
        return v

    @model_validator(mode="after")
    def _validate_sections(self, info: ValidationInfo) -> DriveSpec:
        from pydantic import ValidationError

        from gearte.errors import CaseFileError
        from gearte.io.case_file import load_case
        from gearte.studies import get_kind

        extra = dict(self.model_extra or {})
        wanted = get_family(self.kind).sections
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
    """The :class:`~gearte.drives.Drive` a validated case of a drive family describes (its
    family's ``drive``, :mod:`gearte.families`).

    Parameters
    ----------
    case : Case
        A validated case of a registered drive family (``gear_pair``, ``rv_reducer``, ...).
    name : str, optional
        Label of the drive; default: the case name.
    """
    kind = case.case.kind
    if kind not in family_kinds():
        raise ValueError(
            f"case kind {kind!r} does not describe one drive; drive kinds: {list(family_kinds())}"
        )
    return get_family(kind).drive(case, name or case.case.name or kind)
