"""gearte.solvers.dense: the loop-written linear algebra of the compiled solvers against numpy."""

import numpy as np
import pytest
from numba import njit

from gearte._jit import InnerKernel
from gearte.solvers.dense import copy_into, dot, matvec_into, max_abs, solve_lu_into, solve_spd_into

# The dense kernels have no Python entry point (gearte._jit.inner_kernel): their compiled code
# is reached from a kernel, as the solvers do.


@njit(cache=True)
def _call_solve_spd(H, b, L, x):
    solve_spd_into(H, b, L, x)


@njit(cache=True)
def _call_solve_lu(A, b, L, x):
    solve_lu_into(A, b, L, x)


@njit(cache=True)
def _call_matvec(A, x, out):
    matvec_into(A, x, out)


@njit(cache=True)
def _call_dot(a, b):
    return dot(a, b)


@njit(cache=True)
def _call_max_abs(x):
    return max_abs(x)


@njit(cache=True)
def _call_copy(src, out):
    copy_into(src, out)


COMPILED = {
    "solve_spd_into": _call_solve_spd,
    "solve_lu_into": _call_solve_lu,
    "matvec_into": _call_matvec,
    "dot": _call_dot,
    "max_abs": _call_max_abs,
    "copy_into": _call_copy,
}


@pytest.mark.parametrize("compiled", [True, False])
def test_dense_kernels_match_numpy(compiled):
    rng = np.random.default_rng(3)
    n = 9
    A = rng.normal(size=(n, n))
    H = A @ A.T + n * np.eye(n)  # symmetric positive definite
    b = rng.normal(size=n)
    f = (lambda k: COMPILED[k.__name__]) if compiled else (lambda k: k.py_func)
    L = np.empty((n, n))
    x = np.empty(n)
    f(solve_spd_into)(H, b, L, x)
    np.testing.assert_allclose(x, np.linalg.solve(H, b), rtol=1e-12)
    f(solve_lu_into)(A, b, L, x)
    np.testing.assert_allclose(x, np.linalg.solve(A, b), rtol=1e-10)
    out = np.empty(n)
    f(matvec_into)(A, b, out)
    np.testing.assert_allclose(out, A @ b, rtol=1e-13, atol=1e-14)
    assert f(dot)(A[0], b) == pytest.approx(float(A[0] @ b), rel=1e-13)
    assert f(max_abs)(b) == np.max(np.abs(b))
    assert np.isnan(f(max_abs)(np.array([1.0, np.nan, 2.0])))
    f(copy_into)(A[2], out)  # a row of a 2-D array into a 1-D one
    np.testing.assert_array_equal(out, A[2])


def test_solve_spd_falls_back_to_pivoting_on_an_indefinite_matrix():
    """A symmetric matrix with a non-positive pivot is solved by LU with partial pivoting."""
    H = np.array([[0.0, 2.0, 1.0], [2.0, 1.0, 0.0], [1.0, 0.0, 3.0]])
    b = np.array([1.0, 2.0, 3.0])
    x = np.empty(3)
    solve_spd_into(H, b, np.empty((3, 3)), x)
    np.testing.assert_allclose(H @ x, b, rtol=1e-13)


def test_inner_kernel_called_from_python_runs_its_python_code():
    """An inner kernel (compiled without the CPython wrapper) called from Python runs its Python
    code instead of jumping to the missing entry point: the same result, no crash."""
    assert isinstance(solve_spd_into, InnerKernel)
    assert solve_spd_into.targetoptions["no_cpython_wrapper"]
    rng = np.random.default_rng(5)
    A = rng.normal(size=(5, 5))
    H = A @ A.T + 5 * np.eye(5)
    b = rng.normal(size=5)
    x, y = np.empty(5), np.empty(5)
    solve_spd_into(H, b, np.empty((5, 5)), x)
    _call_solve_spd(H, b, np.empty((5, 5)), y)
    np.testing.assert_allclose(x, np.linalg.solve(H, b), rtol=1e-12)
    np.testing.assert_allclose(y, x, rtol=1e-14)
