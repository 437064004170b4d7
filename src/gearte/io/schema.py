"""Base models of gearte's case files (pydantic v2).

Every section of a case file is a :class:`StrictModel`: unknown keys, NaN/inf and wrong types are
errors, nothing is coerced silently. A kind of case (``gearte.studies.<kind>``) derives its
``Case`` from :class:`CaseBase`.
"""

from __future__ import annotations

import types
import typing
from typing import Any

from pydantic import BaseModel, BeforeValidator, ConfigDict, Field, field_validator, model_validator

__all__ = ["StrictModel", "CaseMeta", "CaseBase", "Sign", "floored"]


def _not_bool(v: Any) -> Any:
    if isinstance(v, bool):  # True == 1 would pass a Literal[-1, 1] even in strict mode
        raise ValueError("must be the number -1 or 1, not a boolean")
    return v


#: A sign, -1 or 1 (a ``true`` is refused: it would equal 1).
Sign = typing.Annotated[typing.Literal[-1, 1], BeforeValidator(_not_bool)]


def floored(quantity: str, default: Any = ..., **kwargs: Any) -> Any:
    """A ``Field`` whose smallest value is the plausibility floor of ``quantity``.

    ``quantity`` names an entry of :data:`gearte.limits.FLOORS` (``"linear_stiffness"``,
    ``"load_torque"``, ...): the field gets ``ge=`` that floor, and a value below it is refused
    at validation with the floor, its unit and the reason (``gearte.io.case_file``; the wording
    of :func:`gearte.limits.floor_reason`, which the model functions use too), e.g.
    ``reducer.cranks.cam_bearing.stiffness_N_per_mm: must be >= 1 N/mm: no part of a reducer is
    that soft ... (got 1e-300)``.

    Parameters
    ----------
    quantity : str
        Key of :data:`gearte.limits.FLOORS`.
    default : Any
        The field's default (``...``: required).
    **kwargs
        Passed on to ``pydantic.Field`` (``le``, ``description``, ...).

    Returns
    -------
    pydantic.fields.FieldInfo
        The field, ``ge`` its floor, the message in ``json_schema_extra["plausibility_floor"]``.
    """
    from gearte.limits import FLOORS, floor_reason

    extra: dict[str, Any] = {"plausibility_floor": floor_reason(quantity)}
    return Field(default, ge=FLOORS[quantity][0], json_schema_extra=extra, **kwargs)


def _arrays_as_tuples(annotation: Any, value: Any) -> Any:
    """TOML has arrays, not tuples: turn the lists of ``value`` that ``annotation`` types as
    tuples into tuples (recursively), touching nothing else. Strict mode then checks the items."""
    origin = typing.get_origin(annotation)
    args = typing.get_args(annotation)
    if origin is typing.Annotated:
        return _arrays_as_tuples(args[0], value)
    if origin in (typing.Union, types.UnionType):
        for arm in args:
            converted = _arrays_as_tuples(arm, value)
            if converted is not value:
                return converted
        return value
    if isinstance(value, list):
        if origin is tuple:
            if len(args) == 2 and args[1] is Ellipsis:
                return tuple(_arrays_as_tuples(args[0], v) for v in value)
            if len(args) == len(value):
                return tuple(_arrays_as_tuples(a, v) for a, v in zip(args, value, strict=True))
            return tuple(value)
        if origin is list and args:
            new = [_arrays_as_tuples(args[0], v) for v in value]
            return new if any(n is not v for n, v in zip(new, value, strict=True)) else value
    if isinstance(value, dict) and origin is dict and len(args) == 2:
        new_d = {k: _arrays_as_tuples(args[1], v) for k, v in value.items()}
        return new_d if any(new_d[k] is not value[k] for k in value) else value
    return value


class StrictModel(BaseModel):
    """Base of every case-file section: unknown keys, NaN/inf and lax coercions are errors.

    Strict mode: ``true`` is not a number, ``"1.3"`` is not a float, ``2.0`` is not an integer;
    an integer is accepted where a float is expected (``2`` for 2.0 changes no type category).
    TOML arrays are accepted where a tuple is expected.
    """

    model_config = ConfigDict(
        extra="forbid",
        frozen=True,
        allow_inf_nan=False,
        strict=True,
        validate_default=True,
        str_strip_whitespace=True,
        # validators are built on first use, not at import: importing a study kind (the report
        # process does only that) took ~0.25 s CPU building every section's schema; importing and
        # validating a case 0.65-0.80 -> 0.36-0.62 s (issue 12, docs/report.md)
        defer_build=True,
    )

    @model_validator(mode="before")
    @classmethod
    def _toml_arrays_as_tuples(cls, data: Any) -> Any:
        if not isinstance(data, dict):
            return data
        fixed: dict[str, Any] | None = None
        for name, info in cls.model_fields.items():
            key = info.alias or name
            if key in data:
                new = _arrays_as_tuples(info.annotation, data[key])
                if new is not data[key]:
                    fixed = fixed if fixed is not None else dict(data)
                    fixed[key] = new
        return fixed if fixed is not None else data


class CaseMeta(StrictModel):
    """The ``[case]`` table: what the file describes and which study kind runs it."""

    kind: str = Field(description="Study kind, e.g. 'cycloid_stage' (see `gearte cases --kinds`).")
    name: str | None = Field(
        default=None,
        max_length=200,
        pattern=r"^[^\x00-\x1f\x7f]*$",
        description="Case name, a label (no control characters); defaults to the file name "
        "without '.toml'. The default output folder is out/<name> with unsafe characters "
        "replaced.",
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
