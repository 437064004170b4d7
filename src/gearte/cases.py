"""Registry of the bundled example cases (``examples/*.toml``), found by name.

A case name is the file stem, named after its source: ``hu2020_rv80e_initial``.
"""

from __future__ import annotations

import os
from pathlib import Path

__all__ = ["examples_dir", "list_cases", "case_path"]


def examples_dir() -> Path:
    """Folder of the bundled cases.

    Order: ``$GEARTE_EXAMPLES``; the repository's ``examples/`` (source checkout or editable
    install); the copy shipped inside the wheel (``gearte/_examples``).
    """
    env = os.environ.get("GEARTE_EXAMPLES")
    if env:
        return Path(env)
    here = Path(__file__).resolve().parent
    repo = here.parents[1] / "examples"
    if repo.is_dir():
        return repo
    return here / "_examples"


def list_cases() -> dict[str, Path]:
    """Bundled cases, name → path, sorted by name."""
    d = examples_dir()
    if not d.is_dir():
        return {}
    return {p.stem: p for p in sorted(d.glob("*.toml"))}


def case_path(name_or_path: str | os.PathLike[str]) -> Path:
    """Resolve ``name_or_path``, a case file path or a bundled case name, to a path.

    Raises
    ------
    FileNotFoundError
        Naming the bundled cases when neither a file nor a bundled name matches.
    """
    p = Path(name_or_path)
    try:
        if p.is_file():
            return p
    except (OSError, ValueError) as exc:  # a NUL byte, a name too long: not a path at all
        raise FileNotFoundError(f"no case file {str(name_or_path)!r}: {exc}") from None
    cases = list_cases()
    key = p.stem if p.suffix == ".toml" else str(name_or_path)
    if key in cases:
        return cases[key]
    try:
        exists = p.exists()
    except (OSError, ValueError):
        exists = False
    if exists:  # a folder, a device, a FIFO: not a case file (nothing is read)
        raise FileNotFoundError(
            f"{os.fspath(name_or_path)} is not a regular file (a folder, a device or a FIFO), "
            "so not a case file"
        )
    raise FileNotFoundError(
        f"no case file {str(name_or_path)!r} and no bundled case of that name; "
        f"bundled cases: {', '.join(cases) or '(none)'}"
    )
