"""Read and validate case files (TOML).

``load_case`` turns a path, a bundled case name or a dictionary into the validated ``Case`` object
of its study kind. Every problem of a file is reported at once, one line each, as
``path.to.field: reason (got value)``; nothing is coerced or clamped silently.
"""

from __future__ import annotations

import os
import tomllib
from pathlib import Path
from typing import Any

from gearte.errors import CaseFileError

__all__ = ["load_case", "load_case_dict", "validate_case", "format_validation_errors"]


def _short(value: Any, limit: int = 60) -> str:
    text = repr(value)
    return text if len(text) <= limit else text[: limit - 3] + "..."


def format_validation_errors(exc: Any) -> list[tuple[str, str]]:
    """Turn a pydantic ``ValidationError`` into ``(field, message)`` pairs, one per problem."""
    out: list[tuple[str, str]] = []
    for err in exc.errors(include_url=False):
        loc = ".".join(str(p) for p in err.get("loc", ())) or "(case)"
        msg = str(err.get("msg", "invalid"))
        for prefix in ("Value error, ", "Assertion failed, "):
            if msg.startswith(prefix):
                msg = msg[len(prefix) :]
        kind = err.get("type", "")
        if kind == "missing":
            msg = "required field is missing"
        elif kind == "extra_forbidden":
            msg = "unknown key (not allowed here; check spelling and section)"
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
    try:
        return module.Case.model_validate(data, context={"case_dir": base_dir})
    except ValidationError as exc:
        raise CaseFileError(source, format_validation_errors(exc)) from None


def load_case(case: str | os.PathLike[str] | dict[str, Any]) -> Any:
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
    try:
        text = Path(path).read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        raise CaseFileError(str(path), [("(file)", f"cannot read: {exc}")]) from None
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise CaseFileError(str(path), [("(file)", f"TOML syntax error: {exc}")]) from None
    return load_case_dict(
        data, source=str(path), name=Path(path).stem, base_dir=str(Path(path).parent)
    )


def validate_case(case: str | os.PathLike[str] | dict[str, Any]) -> Any:
    """Validate a case without running it; returns the ``Case`` or raises ``CaseFileError``."""
    return load_case(case)
