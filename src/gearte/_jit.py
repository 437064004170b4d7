"""Compiled helper kernels without a Python entry point (a cheaper first compile).

numba compiles every ``@njit`` function with two wrappers besides its machine code: a CPython
wrapper (unboxes each argument from a Python object, boxes the result, turns a raised error
into a Python exception; the larger, the more array and tuple arguments and results) and a
C-callable ``cfunc`` wrapper (for use as a first-class function). A kernel that only other
kernels call uses neither: a compiled caller calls the machine code directly. Compiling a
helper without them (numba's ``no_cpython_wrapper`` and ``no_cfunc_wrapper`` options) saves
~30–60 ms of typing, lowering and LLVM work per helper — ~1.1 s of a cold first
``gearte run hu2020_rv80e_initial_reducer`` (12.0 → 10.9 s CPU, four paired runs,
``docs/numba.md``, "Wrappers"). The compiled code, and so every result, is the same.

Such a dispatcher has no compiled entry for a call from Python (numba would jump to a null
address). :func:`inner_kernel` therefore gives it the class :class:`InnerKernel`, whose call
from Python runs the kernel's Python code (``py_func``, as :func:`gearte.solvers.twins.
plain_twins` does), so a Python caller gets the right result — at Python speed — and never a
crash. Use it only for a kernel that is called from compiled kernels; a kernel that Python
code calls (a solver's entry point, a function tested compiled from Python) stays
``@njit(cache=True, nogil=True)``.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from numba import njit
from numba.core.registry import CPUDispatcher

__all__ = ["InnerKernel", "inner_kernel", "kernel"]

#: ``numba.njit`` untyped: its type stubs do not list the ``no_cpython_wrapper`` and
#: ``no_cfunc_wrapper`` target options (numba accepts them: ``numba.core.cpu``'s option list)
_njit: Any = njit


class InnerKernel(CPUDispatcher):
    """A numba dispatcher compiled without the CPython and cfunc wrappers (:func:`inner_kernel`).

    Compiled callers call its machine code; a call from Python runs its Python code
    (``py_func``)."""

    def __call__(self, *args: Any, **kwargs: Any) -> Any:
        return self.py_func(*args, **kwargs)


def inner_kernel(fn: Callable[..., Any]) -> Any:
    """``@njit(cache=True, nogil=True)`` for a kernel called only from other kernels: compiled
    without the CPython and cfunc wrappers (``no_cpython_wrapper``, ``no_cfunc_wrapper``), a
    call from Python runs ``fn`` itself (:class:`InnerKernel`)."""
    dispatcher = _njit(cache=True, nogil=True, no_cpython_wrapper=True, no_cfunc_wrapper=True)(fn)
    dispatcher.__class__ = InnerKernel
    return dispatcher


def kernel(fn: Callable[..., Any] | None = None, /, **options: Any) -> Any:
    """``@njit(cache=True, nogil=True, **options)`` without the cfunc wrapper: a kernel that
    Python code calls (it keeps the CPython wrapper). Every gearte kernel is a :func:`kernel`
    or an :func:`inner_kernel` (or ``inline="always"``): numba compiles a numpy or builtin
    overload once per set of compile flags, so one flag set for all entry points keeps
    ``np.empty``, ``max`` & co. compiled once per run."""
    jit = _njit(cache=True, nogil=True, no_cfunc_wrapper=True, **options)
    return jit if fn is None else jit(fn)
