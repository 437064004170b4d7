"""Registry of the study kinds, found by name.

Loading a case file needs the schema of its kind, and the kinds (``gearte.studies.<kind>``) are
built on this package's schema. The registry breaks that circle the way plugin systems do: it
knows the kinds by *name* only, lists the modules of the ``gearte.studies`` package without
importing them and imports one when it is asked for (``importlib``), so ``gearte.io`` imports
nothing from the layers above it (docs/architecture.md, "Layers"). Kinds implemented outside
gearte are added with :func:`register_kind`.
"""

from __future__ import annotations

import importlib
import importlib.util
import pkgutil
from types import ModuleType

__all__ = ["STUDIES_PACKAGE", "available_kinds", "get_kind", "register_kind"]

STUDIES_PACKAGE = "gearte.studies"
"""The package whose modules are the built-in study kinds (the kind name is the module name)."""

_EXTRA_KINDS: dict[str, str] = {}


def _builtin_kinds() -> set[str]:
    spec = importlib.util.find_spec(STUDIES_PACKAGE)
    paths = list(spec.submodule_search_locations or []) if spec else []
    return {m.name for m in pkgutil.iter_modules(paths) if not m.name.startswith("_")}


def available_kinds() -> list[str]:
    """Names of all study kinds (modules of ``gearte.studies`` plus registered ones)."""
    return sorted(_builtin_kinds() | set(_EXTRA_KINDS))


def register_kind(kind: str, module: str) -> None:
    """Register a study kind implemented outside gearte (plugins, tests).

    Parameters
    ----------
    kind : str
        The name a case file gives as ``case.kind``.
    module : str
        Importable module path that defines ``Case`` and ``run`` (docs/architecture.md).
    """
    _EXTRA_KINDS[kind] = module


def get_kind(kind: str) -> ModuleType:
    """Import the module of a study kind.

    Raises
    ------
    KeyError
        Naming the known kinds when ``kind`` is none of them.
    """
    if kind in _EXTRA_KINDS:
        return importlib.import_module(_EXTRA_KINDS[kind])
    if kind not in available_kinds():
        raise KeyError(f"unknown study kind {kind!r}; known: {available_kinds()}")
    return importlib.import_module(f"{STUDIES_PACKAGE}.{kind}")
