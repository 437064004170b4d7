"""gearte.solvers.dense: the loop-written linear algebra of the compiled solvers against numpy."""

import numpy as np
import pytest

from gearte.solvers.dense import copy_into, dot, matvec_into, max_abs, solve_lu_into, solve_spd_into


@pytest.mark.parametrize("compiled", [True, False])
def test_dense_kernels_match_numpy(compiled):
    rng = np.random.default_rng(3)
    n = 9
    A = rng.normal(size=(n, n))
    H = A @ A.T + n * np.eye(n)  # symmetric positive definite
    b = rng.normal(size=n)
    f = (lambda k: k) if compiled else (lambda k: k.py_func)
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
