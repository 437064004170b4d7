"""Read and validate case files (TOML).

``load_case`` turns a path, a bundled case name or a dictionary into the validated ``Case`` object
of its study kind. Every problem of a file is reported at once, one line each, as
``path.to.field: reason (got value)``; nothing is coerced or clamped silently.
"""

from __future__ import annotations

import os
import re
import tomllib
from collections.abc import Iterator
from contextlib import contextmanager
from contextvars import ContextVar
from pathlib import Path
from typing import TYPE_CHECKING, Any

from gearte.errors import CaseFileError

if TYPE_CHECKING:  # pragma: no cover
    from gearte.io.schema import CaseBase

__all__ = [
    "load_case",
    "load_case_dict",
    "validate_case",
    "format_validation_errors",
    "MAX_NESTING",
    "MAX_FILE_BYTES",
    "MAX_LINE_CHARS",
    "read_case_toml",
]

#: Deepest nesting of tables/arrays a case file may have (the deepest bundled case has 4).
MAX_NESTING = 32
#: Largest case file read [bytes] (the largest bundled case is < 10 kB).
MAX_FILE_BYTES = 1_000_000
#: Longest line of a case file [characters] (the longest line of a bundled case has 212).
MAX_LINE_CHARS = 20_000

#: One token of a TOML line for :func:`_dotted_depth`: a bare key or number, a quoted string,
#: blanks, or any other single character (linear: no backtracking).
_TOKEN = re.compile(r"[A-Za-z0-9_\-]+|\"(?:[^\"\\\n]|\\.)*\"|'[^'\n]*'|[ \t]+|.")

#: Real paths of the case files being loaded in this thread, outermost first (a case refers to
#: another through ``reducer.case`` or a drive's ``case``): a file met twice is a cycle.
_LOADING: ContextVar[tuple[str, ...]] = ContextVar("gearte_loading_cases", default=())


def _too_deep(data: Any, limit: int = MAX_NESTING) -> str | None:
    """Dotted path of the first value nested deeper than ``limit``, or ``None`` (iterative)."""
    stack: list[tuple[Any, tuple[str, ...]]] = [(data, ())]
    while stack:
        value, path = stack.pop()
        if len(path) > limit:
            return ".".join(path[:4]) + ".…"
        if isinstance(value, dict):
            stack.extend((v, (*path, str(k))) for k, v in value.items())
        elif isinstance(value, list):
            stack.extend((v, (*path, str(i))) for i, v in enumerate(value))
    return None


def _dotted_depth(line: str) -> int:
    """Most segments of one dotted chain (``a.b."c".d`` has 4) on ``line``, in linear time."""
    best = run = 0
    after_segment = after_dot = False
    for m in _TOKEN.finditer(line):
        t = m.group()
        if t[0] in " \t":
            continue
        if t == ".":
            after_dot, after_segment = after_segment, False
            if not after_dot:
                run = 0
            continue
        if t[0].isalnum() or t[0] in "_-\"'":
            run = run + 1 if after_dot else 1
            best = max(best, run)
            after_segment, after_dot = True, False
            continue
        run, after_segment, after_dot = 0, False, False
    return best


def _preparse_problem(text: str) -> str | None:
    """Why ``text`` must not reach the TOML parser, or ``None``: a line over
    :data:`MAX_LINE_CHARS` or a dotted key (``a.b.c = ...``, ``[a.b.c]``) deeper than
    :data:`MAX_NESTING` (the parser's time and memory grow with the square of a key's depth:
    one 80 kB dotted key took over 4 GiB)."""
    for number, line in enumerate(text.splitlines(), start=1):
        if len(line) > MAX_LINE_CHARS:
            return f"line {number} has {len(line)} characters; the limit is {MAX_LINE_CHARS}"
        if line.count(".") >= MAX_NESTING and _dotted_depth(line) > MAX_NESTING:
            return (
                f"line {number} has a dotted key of {_dotted_depth(line)} parts: nested deeper "
                f"than {MAX_NESTING} levels"
            )
    return None


def read_case_toml(path: str | os.PathLike[str]) -> dict[str, Any]:
    """The parsed TOML of a case file, read only when it is safe to.

    The file must be a regular file of at most :data:`MAX_FILE_BYTES`
    (:func:`gearte.limits.read_input_file`: a device, a FIFO or a folder is refused before any
    byte is read), UTF-8 text whose lines are at most :data:`MAX_LINE_CHARS` long and whose
    dotted keys have at most :data:`MAX_NESTING` parts (checked before the TOML parser sees it).

    Parameters
    ----------
    path : str or os.PathLike
        The case file.

    Raises
    ------
    CaseFileError
        Naming the file and the reason.
    """
    from gearte.limits import read_input_file

    src = str(path)
    try:
        raw = read_input_file(path, MAX_FILE_BYTES)
    except (OSError, ValueError) as exc:
        reason = getattr(exc, "strerror", None) or exc
        raise CaseFileError(src, [("(file)", f"cannot read: {reason}")]) from None
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError as exc:
        line = raw[: exc.start].count(b"\n") + 1
        raise CaseFileError(src, [("(file)", f"line {line}: not UTF-8 text")]) from None
    problem = _preparse_problem(text)
    if problem is not None:
        raise CaseFileError(src, [("(file)", problem)])
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise CaseFileError(src, [("(file)", f"TOML syntax error: {exc}")]) from None
    except RecursionError:
        reason = f"nested deeper than {MAX_NESTING} levels (arrays or inline tables)"
        raise CaseFileError(src, [("(file)", reason)]) from None


@contextmanager
def _loading(path: Path) -> Iterator[None]:
    """Mark ``path`` as being loaded in this thread; a case reference back to a file being
    loaded (itself, or a file that refers to it) is a :class:`CaseFileError` naming the chain."""
    try:
        real = os.path.realpath(path)
    except (OSError, ValueError):
        real = str(path)
    stack = _LOADING.get()
    if real in stack:
        chain = " → ".join([*stack[stack.index(real) :], real])
        raise CaseFileError(
            str(path),
            [
                (
                    "(file)",
                    f"case files refer to each other in a cycle ({chain}): a reducer.case or "
                    "drive case names a file that is already being loaded",
                )
            ],
        )
    token = _LOADING.set((*stack, real))
    try:
        yield
    finally:
        _LOADING.reset(token)


def _short(value: Any, limit: int = 60) -> str:
    text = repr(value)
    return text if len(text) <= limit else text[: limit - 3] + "..."


_UNITS = {
    "mm": "mm",
    "um": "µm",
    "m": "m",
    "Nm": "N·m",
    "Nmm": "N·mm",
    "N": "N",
    "kN": "kN",
    "MPa": "MPa",
    "GPa": "GPa",
    "deg": "degrees",
    "rad": "rad",
    "arcmin": "arcmin",
    "arcsec": "arcsec",
    "rpm": "rpm",
    "s": "s",
    "Hz": "Hz",
}


def _model_classes(annotation: Any) -> list[Any]:
    """The pydantic model classes an annotation may hold (through Optional, lists, dicts)."""
    import typing

    from pydantic import BaseModel

    if isinstance(annotation, type) and issubclass(annotation, BaseModel):
        return [annotation]
    out: list[Any] = []
    for arg in typing.get_args(annotation):
        out += _model_classes(arg)
    return out


def _user_loc(root: Any, loc: tuple[Any, ...]) -> tuple[Any, ...]:
    """``loc`` as the user wrote it: without the tags pydantic adds for tagged unions
    (``pair.spur.module_mm`` → ``pair.module_mm``)."""
    if root is None:
        return loc
    models, out = [root], []
    for i, part in enumerate(loc):
        if isinstance(part, int):
            out.append(part)
            continue
        nxt: list[Any] = []
        for m in models:
            info = m.model_fields.get(part)
            if info is not None:
                nxt += _model_classes(info.annotation)
        if any(part in m.model_fields for m in models):
            out.append(part)
            models = nxt or models
            continue
        tagged = [m for m in models if part in _tags(m)]
        if len(models) > 1 and tagged and i + 1 < len(loc):
            models = tagged  # a union tag: not part of the file's keys
            continue
        out.append(part)  # a dict key (a source name, a pair name): keep
    return tuple(out)


def _tags(model: Any) -> set[str]:
    """Literal values of the model's fields (candidates for a union's discriminator)."""
    import typing

    tags: set[str] = set()
    for info in model.model_fields.values():
        if typing.get_origin(info.annotation) is typing.Literal:
            tags |= {str(a) for a in typing.get_args(info.annotation)}
    return tags


def _field(model: Any, key: Any) -> Any:
    """The field of ``model`` that the file's ``key`` names (its name, or its alias where it has
    one: ``yield`` is the field ``yield_``), or ``None``."""
    for name, info in model.model_fields.items():
        if key in (name, info.alias):
            return info
    return None


def _models_at(root: Any, loc: tuple[Any, ...]) -> list[Any]:
    """The model classes the section at ``loc`` (a pydantic error location) of ``root`` may
    be."""
    models = [root]
    for part in loc:
        if isinstance(part, int):
            continue
        nxt: list[Any] = []
        for m in models:
            info = _field(m, part)
            if info is not None:
                nxt += _model_classes(info.annotation)
        # a dict key (e.g. a pair name) or a discriminator tag: stay
        models = nxt or models
    return models


def _fields_at(root: Any, loc: tuple[Any, ...]) -> set[str]:
    """Keys of the section at ``loc`` (a pydantic error location) of ``root``, as a file writes
    them (a field's alias where it has one)."""
    return {
        info.alias or name for m in _models_at(root, loc) for name, info in m.model_fields.items()
    }


def _floor_message(root: Any, loc: tuple[Any, ...]) -> str | None:
    """The plausibility-floor message of the field at ``loc`` (``gearte.io.schema.floored``),
    or ``None`` where that field has no floor."""
    if root is None or not loc:
        return None
    for m in _models_at(root, loc[:-1]):
        extra = getattr(_field(m, loc[-1]), "json_schema_extra", None)
        if isinstance(extra, dict) and "plausibility_floor" in extra:
            return str(extra["plausibility_floor"])
    return None


def _in_base_unit(unit: str) -> tuple[str, float] | None:
    """``(dimension, size of one ``unit`` in the dimension's base unit)`` of a key suffix (mm, N·mm,
    N, MPa, rad), or ``None`` for a suffix that is no known unit."""
    from gearte import units as u

    table: dict[str, tuple[str, float]] = {
        "mm": ("length", 1.0),
        "um": ("length", float(u.um_to_mm(1.0))),
        "m": ("length", 1000.0),
        "Nmm": ("torque", 1.0),
        "Nm": ("torque", float(u.Nm_to_Nmm(1.0))),
        "N": ("force", 1.0),
        "kN": ("force", 1000.0),
        "MPa": ("stress", 1.0),
        "GPa": ("stress", 1000.0),
        "rad": ("angle", 1.0),
        "deg": ("angle", float(u.deg_to_rad(1.0))),
        "arcmin": ("angle", float(u.arcmin_to_rad(1.0))),
        "arcsec": ("angle", float(u.arcsec_to_rad(1.0))),
    }
    return table.get(unit)


def did_you_mean(key: str, known: set[str], value: Any = None) -> str:
    """A hint for an unknown key: the field with another unit suffix (with ``value``, a number,
    converted to that unit), or a close spelling."""
    import difflib

    known = known - {key}  # (a union's other branch may have the key: no "did you mean" itself)
    stem, _, unit = key.rpartition("_")
    if stem:
        same_stem = sorted(k for k in known if k.rpartition("_")[0] == stem and k != key)
        if same_stem:
            k = same_stem[0]
            target = k.rpartition("_")[2]
            given = _UNITS.get(target, target)
            hint = f"did you mean {k!r}? (this field is given in {given}, not {unit}"
            a, b = _in_base_unit(unit), _in_base_unit(target)
            number = isinstance(value, int | float) and not isinstance(value, bool)
            if number and a is not None and b is not None and a[0] == b[0]:
                hint += f": write {k} = {float(value) * a[1] / b[1]:.6g}"
            return hint + ")"
    close = difflib.get_close_matches(key, sorted(known), n=1, cutoff=0.6)
    return f"did you mean {close[0]!r}?" if close else ""


def format_validation_errors(exc: Any, root: Any = None) -> list[tuple[str, str]]:
    """Turn a pydantic ``ValidationError`` into ``(field, message)`` pairs, one per problem;
    with ``root`` (the ``Case`` class), unknown keys get a "did you mean" hint.

    Parameters
    ----------
    exc : pydantic.ValidationError
        The validation error.
    root : type, optional
        The ``Case`` class the input was validated against (for "did you mean" hints).

    Returns
    -------
    list of (str, str)
        ``(dotted field, message)`` pairs.
    """
    out: list[tuple[str, str]] = []
    for err in exc.errors(include_url=False):
        loc = ".".join(str(p) for p in _user_loc(root, tuple(err.get("loc", ())))) or "(case)"
        msg = str(err.get("msg", "invalid"))
        for prefix in ("Value error, ", "Assertion failed, "):
            if msg.startswith(prefix):
                msg = msg[len(prefix) :]
        kind = err.get("type", "")
        if kind == "missing":
            msg = "required field is missing"
        elif kind == "extra_forbidden":
            msg = "unknown key (not allowed here; check spelling and section)"
            loc_t = _user_loc(root, tuple(err.get("loc", ())))
            if root is not None and loc_t:
                hint = did_you_mean(str(loc_t[-1]), _fields_at(root, loc_t[:-1]), err.get("input"))
                if hint:
                    msg = f"unknown key; {hint}"
        elif kind == "greater_than_equal":
            floor = _floor_message(root, tuple(err.get("loc", ())))
            if floor is not None:
                msg = floor
        if "input" in err and kind not in ("missing",) and not isinstance(err["input"], dict):
            msg = f"{msg} (got {_short(err['input'])})"
        out.append((loc, msg))
    return out


def load_case_dict(
    data: Any, *, source: str = "<dict>", name: str | None = None, base_dir: str | None = None
) -> Any:
    """Validate a case given as a dictionary (the parsed TOML).

    Parameters
    ----------
    data : Mapping
        The case, with a ``case`` table holding at least ``kind``.
    source : str
        Where it came from, for messages.
    name : str, optional
        Default for ``case.name`` (the file stem).
    base_dir : str, optional
        Folder that relative paths inside the case (a chain stage's drive ``case``) are read
        from; default: the working directory.

    Returns
    -------
    Case
        The validated ``Case`` object of the study kind.

    Raises
    ------
    CaseFileError
        Listing every problem, each with its dotted field path.
    """
    from pydantic import ValidationError

    from gearte.io.kinds import available_kinds, get_kind

    if not isinstance(data, dict):
        got = type(data).__name__
        raise CaseFileError(source, [("(case)", f"a case must be a table, got {got}")])
    deep = _too_deep(data)
    if deep is not None:
        raise CaseFileError(
            source, [(deep, f"nested deeper than {MAX_NESTING} levels (tables or arrays)")]
        )
    meta = data.get("case")
    if not isinstance(meta, dict):
        raise CaseFileError(
            source, [("case", "required table [case] with at least kind = '...' is missing")]
        )
    kind = meta.get("kind")
    kinds = available_kinds()
    if not isinstance(kind, str) or kind not in kinds:
        raise CaseFileError(
            source, [("case.kind", f"unknown study kind {_short(kind)}; known: {', '.join(kinds)}")]
        )
    module = get_kind(kind)
    if name is not None and "name" not in meta:
        data = {**data, "case": {**meta, "name": name}}
    context = {"case_dir": base_dir}
    try:
        case = module.Case.model_validate(data, context=context)
    except ValidationError as exc:
        errors = format_validation_errors(exc, module.Case)
        errors += _checks_beside_errors(module.Case, kind, data, context, exc)
        raise CaseFileError(source, errors) from None
    from gearte.io.plausibility import plausibility_problems

    problems = plausibility_problems(kind, case)
    if problems:
        raise CaseFileError(source, problems)
    return case


class _NotValidated(Exception):
    """A cross-field check used a section that did not validate (the check is skipped)."""


class _Placeholder:
    """Stands for a section that did not validate: any use of it stops the check using it."""

    __slots__ = ("_key",)

    def __init__(self, key: str) -> None:
        object.__setattr__(self, "_key", key)

    def __getattr__(self, name: str) -> Any:
        raise _NotValidated(object.__getattribute__(self, "_key"))


def _checks_beside_errors(
    root: Any, kind: str, data: dict[str, Any], context: dict[str, Any], exc: Any
) -> list[tuple[str, str]]:
    """The case-level cross-field checks (``root``'s "after" model validators) and the
    plausibility checks, run on the sections that did validate when others did not.

    pydantic runs a model's after-validators only when all its fields are valid, so a
    contradiction between sections (a rule that needs tolerances, an analysis that needs a
    section) would be reported only after the field errors are fixed. Here each top-level section
    is validated on its own; the sections with errors become placeholders, and a check that
    touches a placeholder is skipped (it cannot be judged), every other check runs.
    """
    from pydantic import TypeAdapter, ValidationError

    errs = exc.errors(include_url=False)
    if any(not e.get("loc") for e in errs):  # the case-level checks ran (and failed)
        return []
    failed = {str(e["loc"][0]) for e in errs}
    values: dict[str, Any] = {}
    for name, info in root.model_fields.items():
        key = info.alias or name
        if key in failed or (key not in data and info.is_required()):
            values[name] = _Placeholder(key)
        elif key not in data:
            values[name] = info.get_default(call_default_factory=True)
        else:
            try:
                adapter: TypeAdapter[Any] = TypeAdapter(info.annotation)
                values[name] = adapter.validate_python(data[key], context=context)
            except (ValidationError, TypeError):
                values[name] = _Placeholder(key)
    case = root.model_construct(**values)
    out: list[tuple[str, str]] = []
    for dec in root.__pydantic_decorators__.model_validators.values():
        if dec.info.mode != "after":
            continue
        try:
            dec.func(case)
        except (_NotValidated, TypeError, AttributeError):
            continue
        except (ValueError, AssertionError) as err:
            out.append(("(case)", str(err)))
    from gearte.io.plausibility import plausibility_problems

    try:
        out += plausibility_problems(kind, case)
    except (_NotValidated, TypeError, AttributeError):
        pass
    return out


def load_case(case: str | os.PathLike[str] | dict[str, Any]) -> CaseBase:
    """Load and validate a case from a TOML file, a bundled case name, or a dictionary.

    Examples
    --------
    >>> case = load_case("hu2020_rv80e_initial")      # doctest: +SKIP
    >>> case.case.kind                                # doctest: +SKIP
    'cycloid_stage'
    """
    if isinstance(case, dict):
        return load_case_dict(case)
    from gearte.cases import case_path

    path = case_path(case)
    with _loading(path):
        data = read_case_toml(path)
        return load_case_dict(
            data, source=str(path), name=Path(path).stem, base_dir=str(Path(path).parent)
        )


def validate_case(case: str | os.PathLike[str] | dict[str, Any]) -> CaseBase:
    """Validate a case without running it; returns the ``Case`` or raises ``CaseFileError``."""
    return load_case(case)
