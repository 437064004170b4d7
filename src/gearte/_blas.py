"""SciPy's BLAS/LAPACK capsules for numba, without importing ``scipy.linalg``.

The first numba kernel a process calls (even one loaded from the cache) initialises numba's CPU
target: among its registries, ``numba.np.arraymath`` checks that BLAS is there with ``import
scipy.linalg.cython_blas``. Importing that submodule runs the ``scipy.linalg`` package first —
every decomposition, ``scipy._lib._array_api`` and its clone of the numpy namespace, which in
turn imports ``numpy.f2py`` and ``numpy.testing`` through numpy's lazy attributes: 0.3–0.4 s of
CPU (quiet machine: ~0.39 s of a warm ``gearte run``'s ~0.7 s "numba load/compile" stage) for
two extension modules that need none of it.

:func:`preload_scipy_blas` loads the two extension modules ``scipy.linalg.cython_blas`` and
``scipy.linalg.cython_lapack`` straight from their files under their full names (~15 ms), so
numba's import finds them in ``sys.modules``; numba's compiled ``np.linalg`` wrappers read the
function pointers from the same modules (their ``__pyx_capi__``), so kernels call the same LAPACK
routines as before. A later ``import scipy.linalg`` imports the package as usual and finds the
two submodules already loaded (one copy of each); a one-shot import hook then sets them as the
package's attributes, as importing them the usual way would have. Where ``scipy.linalg`` is
already imported, the files are not found, or loading fails, nothing is changed (numba then
imports ``scipy.linalg`` itself, as before).
"""

from __future__ import annotations

import importlib.abc
import sys
from typing import Any

__all__ = ["preload_scipy_blas"]

_MODULES = ("cython_blas", "cython_lapack")


def preload_scipy_blas() -> bool:
    """Load ``scipy.linalg.cython_blas`` and ``cython_lapack`` without the ``scipy.linalg``
    package (see the module docstring). Call it before the first numba kernel of a process.

    Returns
    -------
    bool
        True when both modules are in ``sys.modules`` afterwards (loaded here or before).
    """
    names = [f"scipy.linalg.{m}" for m in _MODULES]
    if "scipy.linalg" in sys.modules or all(n in sys.modules for n in names):
        return all(n in sys.modules for n in names)
    try:
        import importlib.machinery
        import importlib.util
        import os

        import scipy

        folder = os.path.join(os.path.dirname(scipy.__file__), "linalg")
        for name in names:
            if name in sys.modules:
                continue
            short = name.rpartition(".")[2]
            path = next(
                (
                    p
                    for p in (
                        os.path.join(folder, short + s)
                        for s in importlib.machinery.EXTENSION_SUFFIXES
                    )
                    if os.path.isfile(p)
                ),
                None,
            )
            if path is None:
                return False
            spec = importlib.util.spec_from_file_location(name, path)
            if spec is None or spec.loader is None:
                return False
            module = importlib.util.module_from_spec(spec)
            sys.modules[name] = module
            try:
                spec.loader.exec_module(module)
            except BaseException:
                del sys.modules[name]
                raise
    except Exception:  # noqa: BLE001 - numba imports scipy.linalg itself, as before
        return False
    sys.meta_path.insert(0, _SetSubmodules("scipy.linalg", _MODULES))
    return True


class _SetSubmodules(importlib.abc.MetaPathFinder):
    """One-shot import hook: once package ``name`` is imported, set its preloaded submodules
    ``subs`` as its attributes (an import of a submodule found in ``sys.modules`` does not)."""

    def __init__(self, name: str, subs: tuple[str, ...]) -> None:
        self.name, self.subs = name, subs

    def find_spec(self, fullname: str, path: Any, target: Any = None) -> Any:
        if fullname != self.name:
            return None
        import importlib.util

        sys.meta_path.remove(self)
        spec = importlib.util.find_spec(fullname)
        if spec is None or spec.loader is None or not hasattr(spec.loader, "exec_module"):
            return spec
        inner = spec.loader.exec_module

        def exec_module(module: Any) -> None:
            inner(module)
            for sub in self.subs:
                got = sys.modules.get(f"{self.name}.{sub}")
                if got is not None and not hasattr(module, sub):
                    setattr(module, sub, got)

        spec.loader.exec_module = exec_module  # type: ignore[method-assign]
        return spec
