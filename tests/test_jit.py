"""gearte._jit: every compiled kernel goes through ``kernel`` or ``inner_kernel``.

numba compiles a numpy or builtin overload (``np.empty``, ``max``, …) once per set of compile
flags, and a kernel without the cfunc wrapper has other flags than a plain ``@njit`` one: a
plain ``@njit(cache=True)`` kernel beside the others would compile those overloads again on a
cold cache. ``inline="always"`` kernels are typed inside their callers (their flags do not
matter).
"""

import ast
from pathlib import Path

import numpy as np

from gearte._jit import InnerKernel, inner_kernel, kernel

SRC = Path(__file__).resolve().parents[1] / "src" / "gearte"


def _njit_calls_not_inlined() -> list[str]:
    found = []
    for path in sorted(SRC.rglob("*.py")):
        if path.name == "_jit.py":
            continue
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if not isinstance(node, ast.Call):
                continue
            f = node.func
            name = getattr(f, "id", getattr(f, "attr", ""))
            if name not in ("njit", "jit"):
                continue
            inline = [k for k in node.keywords if k.arg == "inline"]
            if not (inline and isinstance(inline[0].value, ast.Constant)
                    and inline[0].value.value == "always"):  # fmt: skip
                found.append(f"{path.relative_to(SRC)}:{node.lineno}")
    return found


def test_every_kernel_is_a_kernel_or_an_inner_kernel():
    assert _njit_calls_not_inlined() == []


def test_kernel_and_inner_kernel_results_equal_the_python_code():
    def f(x):
        s = 0.0
        for i in range(x.size):
            s += x[i] * x[i]
        return s

    g = inner_kernel(f)
    h = kernel(lambda x: g(x) + 1.0)
    x = np.linspace(0.0, 1.0, 7)
    assert isinstance(g, InnerKernel)
    assert h(x) == f(x) + 1.0
    assert g(x) == f(x)  # from Python: the Python code, not a jump to a missing entry point
