"""Small dense linear algebra for compiled kernels, in scalar loops (cheap to compile).

numba compiles ``np.linalg.solve`` from LAPACK wrappers, finite checks and error messages built
with string formatting: about 5–7 s of first-run compile for every kernel that reaches it (and
``A @ x`` about 1 s, ``np.max(np.abs(x))`` about 1 s; measured on the 2-core development machine,
``benchmarks/bench_compile.py``). The systems gearte's solvers factor have a few tens of
unknowns, where plain loops are as fast as LAPACK; these kernels compile in a fraction of a
second and are shared by every solver that needs them (``docs/numba.md``).

Each function works in caller-provided arrays (no allocation) and is an inner kernel
(:func:`gearte._jit.inner_kernel`: no Python entry point; called from Python it runs its Python
code, ``f.py_func``); both are tested against numpy in ``tests/test_dense.py``, the compiled code
through small test kernels.
"""

from __future__ import annotations

import numpy as np

from gearte._jit import inner_kernel

__all__ = ["copy_into", "matvec_into", "dot", "max_abs", "solve_spd_into", "solve_lu_into"]


@inner_kernel
def dot(a, b):
    """Σ a[i] b[i] of two 1-D arrays."""
    s = 0.0
    for i in range(a.shape[0]):
        s += a[i] * b[i]
    return s


@inner_kernel
def copy_into(src, out):
    """out[i] = src[i] for 1-D arrays of the same length: ``out[:] = src`` inside a kernel
    compiles numba's broadcasting and its shape-mismatch message (string formatting, ~1 s per
    kernel, docs/numba.md); this loop compiles once for every caller."""
    for i in range(out.shape[0]):
        out[i] = src[i]


@inner_kernel
def matvec_into(A, x, out):
    """out[i] = Σ_j A[i, j] x[j] for a 2-D ``A``."""
    for i in range(A.shape[0]):
        s = 0.0
        for j in range(A.shape[1]):
            s += A[i, j] * x[j]
        out[i] = s


@inner_kernel
def max_abs(x):
    """max |x[i]| of a 1-D array (0 for an empty one; NaN if any element is NaN)."""
    m = 0.0
    for i in range(x.shape[0]):
        v = abs(x[i])
        if v != v:
            return v
        if v > m:
            m = v
    return m


@inner_kernel
def solve_lu_into(A, b, LU, x):
    """Solve ``A x = b`` by Gaussian elimination with partial pivoting (LAPACK ``dgesv``'s
    algorithm, unblocked); ``LU`` (n, n) work array, result in ``x``. A zero pivot gives
    non-finite ``x`` (the callers test for it)."""
    n = b.shape[0]
    for i in range(n):
        x[i] = b[i]
        for j in range(n):
            LU[i, j] = A[i, j]
    for k in range(n):
        p = k
        big = abs(LU[k, k])
        for i in range(k + 1, n):
            v = abs(LU[i, k])
            if v > big:
                big = v
                p = i
        if p != k:
            for j in range(n):
                t = LU[k, j]
                LU[k, j] = LU[p, j]
                LU[p, j] = t
            t = x[k]
            x[k] = x[p]
            x[p] = t
        piv = LU[k, k]
        for i in range(k + 1, n):
            f = LU[i, k] / piv
            for j in range(k + 1, n):
                LU[i, j] -= f * LU[k, j]
            x[i] -= f * x[k]
    for k in range(n - 1, -1, -1):
        s = x[k]
        for j in range(k + 1, n):
            s -= LU[k, j] * x[j]
        x[k] = s / LU[k, k]


@inner_kernel
def solve_spd_into(H, b, L, x):
    """Solve ``H x = b`` for a symmetric positive definite ``H`` by Cholesky (the lower factor
    in the work array ``L``, its diagonal stored as reciprocals: one division per column, the
    rest multiplications; result in ``x``); Gaussian elimination with partial pivoting
    (:func:`solve_lu_into`) where a pivot is not positive."""
    n = b.shape[0]
    for j in range(n):
        s = H[j, j]
        for k in range(j):
            s -= L[j, k] * L[j, k]
        if not s > 0.0:
            solve_lu_into(H, b, L, x)
            return
        r = 1.0 / np.sqrt(s)
        L[j, j] = r
        for i in range(j + 1, n):
            t = H[i, j]
            for k in range(j):
                t -= L[i, k] * L[j, k]
            L[i, j] = t * r
    for i in range(n):
        t = b[i]
        for k in range(i):
            t -= L[i, k] * x[k]
        x[i] = t * L[i, i]
    for i in range(n - 1, -1, -1):
        t = x[i]
        for k in range(i + 1, n):
            t -= L[k, i] * x[k]
        x[i] = t * L[i, i]
