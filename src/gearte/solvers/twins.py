"""Plain-Python twins of a module's numba kernels, calling one another.

A numba dispatcher carries its Python function as ``py_func``; run on its own, that function
still calls the *compiled* versions of the other kernels it names (it looks them up in its
module's globals). :func:`plain_twins` builds, for a set of kernels of one module, new function
objects from their ``py_func`` code that share one copy of the module's namespace in which
those kernels' names are bound to the twins: the whole call tree then runs as plain Python (a
readable reference the compiled path is tested against), without changing the module or its
kernels, so compiled callers in other threads are unaffected and no lock is needed.
"""

from __future__ import annotations

import types
from collections.abc import Iterable
from typing import Any

__all__ = ["plain_twins"]


def plain_twins(namespace: dict[str, Any], names: Iterable[str]) -> dict[str, Any]:
    """The plain-Python twins of the kernels ``names`` of a module.

    Parameters
    ----------
    namespace : dict
        The module's globals (``globals()`` of the module defining the kernels); not modified.
    names : iterable of str
        Names (in ``namespace``) of the kernels whose calls should run as plain Python; a name
        bound to something without ``py_func`` (a plain function) is kept as it is, and a kernel
        imported from another module becomes its ``py_func`` (which reads that module's globals:
        the kernels it calls in turn run compiled).

    Returns
    -------
    dict
        A copy of ``namespace`` in which each of ``names`` is its plain twin: ``twins[name](*args)``
        runs the kernel's Python code, and every call it makes to another of ``names`` runs that
        one's twin.
    """
    twins = dict(namespace)
    for name in names:
        kernel = namespace[name]
        fn = getattr(kernel, "py_func", None)
        if fn is None:
            continue
        if fn.__globals__ is not namespace:  # imported from another module: its own globals
            twins[name] = fn
            continue
        twin = types.FunctionType(fn.__code__, twins, fn.__name__, fn.__defaults__, fn.__closure__)
        twin.__kwdefaults__ = fn.__kwdefaults__
        twin.__qualname__ = fn.__qualname__
        twin.__doc__ = fn.__doc__
        twins[name] = twin
    return twins
