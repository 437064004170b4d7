"""gearte's kernel decorators: numba kernels without the wrappers they do not need.

numba compiles every ``@njit`` function with two wrappers besides its machine code: a CPython
wrapper (unboxes each argument from a Python object, boxes the result, turns a raised error
into a Python exception; the larger, the more array and tuple arguments and results) and a
C-callable ``cfunc`` wrapper (for use as a first-class function, which gearte does not do). A
kernel that only other kernels call uses neither: a compiled caller calls its machine code
directly.

* :func:`inner_kernel`: a kernel only other kernels call, compiled without either wrapper
  (numba's ``no_cpython_wrapper`` and ``no_cfunc_wrapper`` options);
* :func:`kernel`: a kernel Python calls, compiled without the cfunc wrapper.

A cold first ``gearte run hu2020_rv80e_initial_reducer``: 10.67 → 9.81 s CPU (medians of six
alternated pairs, every pair 0.8–1.1 s less; ``docs/numba.md``, "The wrappers numba compiles
beside every kernel"). The compiled code, and so every result, is the same.

An inner kernel has no compiled entry for a call from Python (numba would jump to a null
address: a segmentation fault). :func:`inner_kernel` therefore makes it an
:class:`InnerKernel` (a subclass of numba's CPU dispatcher, built the way numba builds its
own; no object's class is swapped), whose call from Python runs the kernel's Python code
(``py_func``, as
:func:`gearte.solvers.twins.plain_twins` does): a Python caller gets the result — at Python
speed — and never a crash. A kernel that Python code calls (a solver's entry point, a function
tested compiled from Python) is a :func:`kernel`.

numba compiles a numpy or builtin overload (``np.empty``, ``max``, …) once per set of compile
flags, and these options are flags: every gearte kernel is a :func:`kernel` or an
:func:`inner_kernel` (or ``inline="always"``, typed inside its callers), so that a run compiles
each overload at most twice (``tests/test_jit.py``). Written for numba 0.68
(``numba.core.registry.CPUDispatcher`` is the class ``njit`` returns).
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
    without the CPython and cfunc wrappers (``no_cpython_wrapper``, ``no_cfunc_wrapper``).

    Parameters
    ----------
    fn : callable
        The kernel's Python function; a call of the result from Python runs it
        (:class:`InnerKernel`).

    Returns
    -------
    InnerKernel
        The numba dispatcher.
    """
    from numba import config

    if getattr(config, "DISABLE_JIT", False):  # as numba's own decorator: the function itself
        return fn
    # made as numba's ``njit`` makes a dispatcher (``numba.core.decorators._jit``), with this
    # subclass of the CPU target's dispatcher class: no object's class is changed afterwards
    dispatcher = InnerKernel(
        py_func=fn,
        locals={},
        targetoptions={"nopython": True, "boundscheck": None, "nogil": True,
                       "no_cpython_wrapper": True, "no_cfunc_wrapper": True},
    )  # fmt: skip
    dispatcher.enable_caching()
    return dispatcher


def kernel(fn: Callable[..., Any] | None = None, /, **options: Any) -> Any:
    """``@njit(cache=True, nogil=True, **options)`` without the cfunc wrapper: a kernel that
    Python code calls (it keeps the CPython wrapper). Every gearte kernel is a :func:`kernel`
    or an :func:`inner_kernel` (or ``inline="always"``): numba compiles a numpy or builtin
    overload once per set of compile flags, so one flag set for all entry points keeps
    ``np.empty``, ``max`` & co. compiled once per run.

    Parameters
    ----------
    fn : callable, optional
        The kernel's Python function (``@kernel``); omitted, a decorator
        (``@kernel(fastmath=...)``).
    **options
        Further ``njit`` options (``fastmath``, ``no_rewrites``).

    Returns
    -------
    numba dispatcher, or a decorator where ``fn`` is omitted.
    """
    jit = _njit(cache=True, nogil=True, no_cfunc_wrapper=True, **options)
    return jit if fn is None else jit(fn)
