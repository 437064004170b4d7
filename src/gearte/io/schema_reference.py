"""The case-file reference, generated from the pydantic schemas of the study kinds.

Every key of every section of every kind (``gearte.io.kinds``), one table per section: the key,
its type, its unit (from the key's unit suffix, ``eccentricity_mm`` → mm, or a ``[unit]`` in its
description), the allowed values (the ``Field`` constraints: ``> 0``, ``≤ 1000``, the choices of a
``Literal``, lengths), the default or *required*, and the meaning (the ``Field`` description; for
a section, the class docstring). Nothing is written by hand, so the reference cannot drift from
what ``gearte validate`` accepts.

``python -m gearte.io.schema_reference [KIND ...]`` prints it as Markdown (the docs site's
"Case-file reference" page is made this way at build time, ``mkdocs.yml`` hooks).
"""

from __future__ import annotations

import inspect
import re
import sys
import types
import typing
from collections.abc import Iterator
from dataclasses import dataclass
from typing import Any

import annotated_types as at
from pydantic import BaseModel
from pydantic.fields import FieldInfo
from pydantic_core import PydanticUndefined

from gearte.io.kinds import available_kinds, get_kind
from gearte.units import unit_text

__all__ = ["KeyDoc", "SectionDoc", "kind_sections", "walk_fields", "unit_of", "reference_markdown"]

#: Unit suffixes of case-file keys (``_mm``), as the last one or three parts of a key.
UNITS: dict[str, str] = {
    "mm": "mm",
    "um": "µm",
    "deg": "°",
    "rad": "rad",
    "arcmin": "arcmin",
    "arcsec": "arcsec",
    "N": "N",
    "Nm": "N·m",
    "Nmm": "N·mm",
    "kNm": "kN·m",
    "MPa": "MPa",
    "GPa": "GPa",
    "s": "s",
    "rpm": "rpm",
    "Hz": "Hz",
    "kg": "kg",
    "kgm2": "kg·m²",
    "m3": "m³",
    "pct": "%",
}


@dataclass
class KeyDoc:
    """One key of a section: name, type, unit, allowed values, default, meaning."""

    key: str
    type: str
    unit: str
    allowed: str
    default: str
    meaning: str
    field: str  # the pydantic field name (the key without an alias)


@dataclass
class SectionDoc:
    """One section (TOML table) of a case file: its path, its model and its keys."""

    path: str  # "stage", "analyses.geometric_te", "chain.stages[]", "…tolerances.<name>"
    model: type[BaseModel]
    meaning: str
    keys: list[KeyDoc]
    array: bool = False  # an array of tables ([[path]])


def unit_of(name: str, description: str = "") -> str:
    """The unit of the case-file key ``name`` for people: from its suffix (``_mm``, ``_Nm``,
    ``_N_per_mm`` → N/mm) or else from a ``[unit]`` in ``description``; ``""`` for none."""
    parts = name.split("_")
    if len(parts) >= 4 and parts[-2] == "per" and parts[-3] in UNITS and parts[-1] in UNITS:
        return f"{UNITS[parts[-3]]}/{UNITS[parts[-1]]}"
    if len(parts) >= 4 and parts[-2] == "per" and parts[-3] in UNITS:
        return f"{UNITS[parts[-3]]}/{parts[-1]}"
    if len(parts) >= 2 and parts[-1] in UNITS:
        return UNITS[parts[-1]]
    for m in re.finditer(r"\[([^\]]+)\]", description):
        parts = re.split(r"[/·*]", m.group(1).strip())
        known = set(UNITS) | set(UNITS.values()) | {"µm", "N·m", "N·mm", "1"}
        if all(p.strip() in known for p in parts):
            return unit_text(m.group(1).strip())
    return ""


def _strip_optional(ann: Any) -> tuple[Any, bool]:
    if typing.get_origin(ann) in (typing.Union, types.UnionType):
        args = [a for a in typing.get_args(ann) if a is not type(None)]
        if len(args) < len(typing.get_args(ann)):
            return (args[0] if len(args) == 1 else typing.Union[tuple(args)]), True  # noqa: UP007
    return ann, False


def _unannotated(ann: Any) -> Any:
    while typing.get_origin(ann) is typing.Annotated:
        ann = typing.get_args(ann)[0]
    return ann


def _is_model(ann: Any) -> bool:
    return isinstance(ann, type) and issubclass(ann, BaseModel)


def type_text(ann: Any) -> str:
    """A field annotation in TOML words: ``float``, ``integer``, ``array of float``, one of the
    quoted choices of a ``Literal``, ``table`` for a section."""
    ann = _unannotated(ann)
    ann, optional = _strip_optional(ann)
    ann = _unannotated(ann)
    origin, args = typing.get_origin(ann), typing.get_args(ann)
    if ann is float:
        text = "float"
    elif ann is int:
        text = "integer"
    elif ann is bool:
        text = "boolean"
    elif ann is str:
        text = "string"
    elif origin is typing.Literal:
        text = "one of " + ", ".join(f"`{_toml(a)}`" for a in args)
    elif origin in (list, tuple) or ann in (list, tuple):
        if origin is tuple and args and args[-1] is not Ellipsis:
            inner = {type_text(a) for a in args}
            text = f"array of {len(args)} " + (inner.pop() if len(inner) == 1 else "values")
        else:
            text = f"array of {type_text(args[0]) if args else 'values'}"
        if args and _is_model(_unannotated(args[0])):
            text = "array of tables"
    elif origin is dict:
        inner_ann = _unannotated(args[1]) if len(args) == 2 else Any
        text = "table of tables" if _is_model(inner_ann) else f"table of {type_text(inner_ann)}"
    elif _is_model(ann):
        text = "table"
    elif origin in (typing.Union, types.UnionType):
        arms = [type_text(a) for a in args]
        text = " or ".join(dict.fromkeys(arms))
    elif ann is Any:
        text = "any"
    else:
        text = getattr(ann, "__name__", str(ann))
    return text + (" (optional)" if optional and "optional" not in text else "")


def _toml(v: Any) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, str):
        return f'"{v}"'
    if isinstance(v, float) and v.is_integer() and abs(v) < 1e15:
        return f"{v:.1f}"
    if isinstance(v, list | tuple):
        return "[" + ", ".join(_toml(x) for x in v) + "]"
    if isinstance(v, dict):
        return "{" + ", ".join(f"{k} = {_toml(x)}" for k, x in v.items()) + "}"
    return str(v)


def _number(v: Any) -> str:
    """A bound for people: ``-1000.0`` → ``-1000``, ``1e9`` for 1000000000, ``1e-06`` stays."""
    if isinstance(v, int | float) and abs(v) >= 1e6:
        return f"{v:g}".replace("e+0", "e").replace("e+", "e")
    if isinstance(v, float) and v.is_integer():
        return str(int(v))
    return str(v)


_BOUNDS = [(at.Gt, "gt", ">"), (at.Ge, "ge", "≥"), (at.Lt, "lt", "<"), (at.Le, "le", "≤")]


def allowed_text(f: FieldInfo) -> str:
    """The constraints of a field for people: ``> 0, ≤ 1000``, lengths, a pattern."""
    parts: list[str] = []
    for m in f.metadata:
        for cls, attr, sym in _BOUNDS:
            if isinstance(m, cls):
                parts.append(f"{sym} {_number(getattr(m, attr))}")
        if isinstance(m, at.MultipleOf):
            parts.append(f"multiple of {_toml(m.multiple_of)}")
        what = "characters" if _strip_optional(_unannotated(f.annotation))[0] is str else "items"
        if isinstance(m, at.MinLen):
            parts.append(f"at least {m.min_length} {what}")
        if isinstance(m, at.MaxLen):
            parts.append(f"at most {m.max_length} {what}")
        pattern = getattr(m, "pattern", None)
        if isinstance(pattern, str):
            parts.append("no control characters" if "x00-" in pattern else f"matches `{pattern}`")
    ann, _ = _strip_optional(_unannotated(f.annotation))
    if typing.get_origin(_unannotated(ann)) is typing.Literal and not parts:
        parts.append("the choices listed")
    return ", ".join(parts)


def default_text(f: FieldInfo) -> str:
    """``required``, or the default as TOML (``unset`` for None: the key may be left out)."""
    if f.is_required():
        return "required"
    if f.default_factory is not None:
        try:
            v = f.default_factory()  # type: ignore[call-arg]  # factories of schemas take none
        except TypeError:
            return "computed"
    else:
        v = f.default
    if v is None or v is PydanticUndefined:
        return "unset"
    if isinstance(v, list | dict | tuple) and not v:
        return "empty"
    if isinstance(v, BaseModel):
        return "its keys' defaults"
    text = _toml(v)
    return f"`{text}`" if len(text) <= 40 else f"`{text[:37]}…`"


def _doc(cls: type) -> str:
    doc = inspect.getdoc(cls) or ""
    if doc and cls.__doc__ is None:
        return ""
    if doc.startswith(("A base class for creating Pydantic models", "Usage docs:")):
        return ""
    return " ".join(doc.split("\n\n")[0].split())


def _models_in(ann: Any) -> list[tuple[type[BaseModel], str]]:
    """(model, how) of the sections a field holds: ``table``, ``array`` or ``map``."""
    ann = _unannotated(ann)
    ann, _ = _strip_optional(ann)
    ann = _unannotated(ann)
    origin, args = typing.get_origin(ann), typing.get_args(ann)
    if _is_model(ann):
        return [(ann, "table")]
    if origin in (typing.Union, types.UnionType):
        return [m for a in args for m in _models_in(a)]
    if origin in (list, tuple) and args and _is_model(_unannotated(args[0])):
        return [(_unannotated(args[0]), "array")]
    if origin is dict and len(args) == 2 and _is_model(_unannotated(args[1])):
        return [(_unannotated(args[1]), "map")]
    return []


def _tag(model: type[BaseModel]) -> str:
    """``type = "spur"``: the discriminating Literal of an arm of a union of sections."""
    for name, f in model.model_fields.items():
        ann = _unannotated(f.annotation)
        if typing.get_origin(ann) is typing.Literal and len(typing.get_args(ann)) == 1:
            return f"{f.alias or name} = {_toml(typing.get_args(ann)[0])}"
    return model.__name__


def walk_fields(model: type[BaseModel], path: str = "") -> Iterator[tuple[str, str, FieldInfo]]:
    """Every (section path, key, field) under ``model``, depth first; paths are spelled as in
    :class:`SectionDoc` (``analyses.yield.tolerances.<name>``; an array of tables by its own
    path, ``chain.stages``). Independent of :func:`kind_sections`, which tests compare with it.
    """
    for name, f in model.model_fields.items():
        key = f.alias or name
        yield path, key, f
        subs = _models_in(f.annotation)
        for sub, how in subs:
            sub_path = f"{path}.{key}" if path else key
            if how == "map":
                sub_path += ".<name>"
            if len(subs) > 1:
                sub_path += f" ({_tag(sub)})"
            yield from walk_fields(sub, sub_path)


def kind_sections(kind: str) -> list[SectionDoc]:
    """The sections of a case file of the study kind ``kind``, in reading order."""
    root: type[BaseModel] = get_kind(kind).Case
    sections: dict[str, SectionDoc] = {}

    def visit(model: type[BaseModel], path: str, meaning: str, array: bool) -> None:
        sec = SectionDoc(path, model, meaning or _doc(model), [], array)
        sections[path] = sec
        for name, f in model.model_fields.items():
            key = f.alias or name
            desc = " ".join((f.description or "").split())
            subs = _models_in(f.annotation)
            if subs and not desc:
                desc = _doc(subs[0][0]) if len(subs) == 1 else ""
            sec.keys.append(
                KeyDoc(
                    key=key,
                    type=type_text(f.annotation),
                    unit=unit_of(key, desc),
                    allowed=allowed_text(f),
                    default=default_text(f),
                    meaning=desc,
                    field=name,
                )
            )
            for sub, how in subs:
                sub_path = f"{path}.{key}" if path else key
                if how == "map":
                    sub_path += ".<name>"
                if len(subs) > 1:
                    sub_path += f" ({_tag(sub)})"
                visit(sub, sub_path, _doc(sub), how == "array")

    visit(root, "", "top-level keys (outside any table)", False)
    top = sections.pop("")
    top.keys = [k for k in top.keys if not _models_in(root.model_fields[k.field].annotation)]
    return ([top] if top.keys else []) + list(sections.values())


def _cell(text: str) -> str:
    return text.replace("|", "\\|").replace("\n", " ") if text else ""


def _heading(sec: SectionDoc) -> str:
    """``[stage]``, ``[[chain.stages]]`` or ``top level``."""
    if not sec.path:
        return "top level"
    return f"[[{sec.path}]]" if sec.array else f"[{sec.path}]"


def _section_md(sec: SectionDoc) -> list[str]:
    out = [f"### `{_heading(sec)}`", ""]
    if sec.meaning:
        out += [sec.meaning, ""]
    out += [
        "| key | type | unit | allowed | default | meaning |",
        "|---|---|---|---|---|---|",
    ]
    for k in sec.keys:
        out.append(
            f"| `{k.key}` | {_cell(k.type)} | {_cell(k.unit)} | {_cell(k.allowed)} | "
            f"{_cell(k.default)} | {_cell(k.meaning)} |"
        )
    return out + [""]


def kind_markdown(kind: str) -> str:
    """The reference of one study kind as Markdown (a level-2 heading, a table per section)."""
    module = get_kind(kind)
    summary = " ".join((inspect.getdoc(module) or "").split("\n\n")[0].split())
    out = [f"## `{kind}`", ""]
    if summary:
        out += [summary, ""]
    first: dict[type[BaseModel], str] = {}
    for sec in kind_sections(kind):
        if sec.model in first and sec.path:
            # the same section model again (one per error, per arm): say so, do not repeat
            out += [f"### `{_heading(sec)}`", "", f"Same keys as `{first[sec.model]}`.", ""]
            continue
        first.setdefault(sec.model, _heading(sec))
        out += _section_md(sec)
    return "\n".join(out)


def reference_markdown(kinds: list[str] | None = None) -> str:
    """The whole case-file reference as Markdown: an introduction, then every kind's sections
    (``kinds``: the study kinds to include; all of them by default)."""
    kinds = kinds or available_kinds()
    intro = [
        "# Case-file reference",
        "",
        "Generated from the case-file schemas (`gearte.io.schema_reference`); it lists every "
        "key `gearte validate` accepts. A case file is TOML: a `[case]` table naming the "
        "`kind`, then the kind's sections. Keys carry their unit (`eccentricity_mm`); "
        "*required* keys have no default; *unset* optional keys may be left out; unknown keys "
        'are errors (with a "did you mean"). `[a.<name>]` is a table whose keys you choose '
        "(e.g. one per error); `[[a]]` an array of tables.",
        "",
        "Kinds: " + ", ".join(f"[`{k}`](#{k})" for k in kinds) + ".",
        "",
    ]
    return "\n".join(intro + [kind_markdown(k) for k in kinds])


def main(argv: list[str] | None = None) -> int:
    """Print the reference of the kinds named in ``argv`` (all when none) as Markdown."""
    args = sys.argv[1:] if argv is None else argv
    sys.stdout.write(reference_markdown(args or None) + "\n")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
