"""Base models of gearte's case files (pydantic v2).

Every section of a case file is a :class:`StrictModel`: unknown keys, NaN/inf and wrong types are
errors, nothing is coerced silently. A kind of case (``gearte.studies.<kind>``) derives its
``Case`` from :class:`CaseBase`.
"""

from __future__ import annotations

from pydantic import BaseModel, ConfigDict, Field, field_validator

__all__ = ["StrictModel", "CaseMeta", "CaseBase"]


class StrictModel(BaseModel):
    """Base of every case-file section: unknown keys, NaN/inf and lax coercions are errors."""

    model_config = ConfigDict(
        extra="forbid",
        frozen=True,
        allow_inf_nan=False,
        strict=False,
        validate_default=True,
        str_strip_whitespace=True,
    )


class CaseMeta(StrictModel):
    """The ``[case]`` table: what the file describes and which study kind runs it."""

    kind: str = Field(description="Study kind, e.g. 'cycloid_stage' (see `gearte cases --kinds`).")
    name: str | None = Field(
        default=None, description="Case name; defaults to the file name without '.toml'."
    )
    title: str = Field(default="", description="One-line human title.")
    description: str = Field(default="", description="Free text: source, assumptions.")
    references: list[str] = Field(
        default_factory=list, description="Keys of gearte.references.REFERENCES."
    )

    @field_validator("references")
    @classmethod
    def _known_references(cls, v: list[str]) -> list[str]:
        from gearte.references import REFERENCES

        unknown = [k for k in v if k not in REFERENCES]
        if unknown:
            raise ValueError(f"unknown reference key(s) {unknown}; known: {sorted(REFERENCES)}")
        return v


class CaseBase(StrictModel):
    """Root of a case file: the ``[case]`` table plus kind-specific sections."""

    case: CaseMeta
