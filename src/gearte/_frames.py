"""Room on the interpreter's frame stack for one command: a workaround for CPython's data-stack
chunk churn (python/cpython issue gh-142183).

Since CPython 3.11 the frames of Python functions live on a per-thread stack made of 16 KiB
chunks. A call whose frame does not fit in the current chunk allocates a new one (``mmap``) and
frees it (``munmap``) as soon as the call returns; a loop that calls across a chunk boundary
pays both, plus the first-touch page faults, on every iteration. Where the boundaries fall
depends on the size of every frame below: adding one local variable to a function on the
stack moves them all. Measured with ``strace`` on a warm ``gearte run`` (2-core machine,
CPython 3.11.7):

* ``han2023_rv110e``: 3 457 chunk allocations in the main process; after adding ``import numpy``
  (one local variable) to the ``run`` command's function, 51 492 — about a second of CPU spent
  in ``mmap``/``munmap`` and page faults, with identical results;
* ``wang2013_2kh_eq9``: 566 at commit ac29b7a, 2 022 after unrelated changes to the CLI
  (importing numpy two frames deeper put ``numpy._typing``'s module bodies on a boundary):
  +0.035 s of a 0.9 s run.

CPython fixed this in 3.13 and 3.14 (one chunk kept per thread, merged March 2026); 3.11 and
3.12 are not fixed. :func:`with_frame_room` runs a callable inside a frame whose evaluation
stack is declared :data:`ROOM_SLOTS` slots deep (``CodeType.replace(co_stacksize=...)``,
public API): entering it allocates one chunk of 1 MiB, of which ~0.5 MiB is free for every
frame below it, so a command's frames (recursion included, up to ~1 000 frames) share one
chunk and no boundary is crossed in its loops. The unused slots are never touched (no page
is faulted in for them) and are not scanned by the garbage collector; results are unchanged.
The ``gearte`` command runs through it (:func:`gearte.cli.entry`; the report process forked
from it inherits the room), so does :func:`gearte.run_case`, and the local pools and Dask run each
chunk through it in their worker threads and processes (``execution.backends._in_frame_room``).
"""

from __future__ import annotations

import sys
import types
from collections.abc import Callable
from typing import TypeVar

__all__ = ["ROOM_SLOTS", "with_frame_room"]

T = TypeVar("T")

#: Slots (8 bytes each) of the roomy frame's declared evaluation stack: CPython then allocates
#: a 1 MiB chunk for it, ~0.5 MiB of which is left for the frames below.
ROOM_SLOTS = 1 << 16


def _call(fn: Callable[[], T]) -> T:
    return fn()


def _roomy() -> Callable[[Callable[[], T]], T]:
    """:func:`_call` with :data:`ROOM_SLOTS` more slots of evaluation stack (CPython only;
    elsewhere the plain function)."""
    if sys.implementation.name != "cpython":
        return _call
    code = _call.__code__
    roomy = code.replace(co_stacksize=code.co_stacksize + ROOM_SLOTS)
    return types.FunctionType(roomy, _call.__globals__, _call.__name__)


_ROOMY = _roomy()


def with_frame_room(fn: Callable[[], T]) -> T:
    """``fn()``, run inside a frame that leaves ~0.5 MiB of CPython's frame stack free below it
    (see the module docstring); the result and any exception are ``fn``'s own."""
    return _ROOMY(fn)
