"""gearte._blas: numba's BLAS check finds SciPy's BLAS/LAPACK modules without the scipy.linalg
package, kernels call the same LAPACK, and a later ``import scipy.linalg`` is the usual one."""

from __future__ import annotations

import os
import subprocess
import sys
import textwrap

import pytest


def _run(code: str, tmp_path: object) -> str:
    env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path))
    p = subprocess.run(
        [sys.executable, "-c", code],
        env=env,
        capture_output=True,
        text=True,
        check=False,
    )
    assert p.returncode == 0, p.stderr[-3000:]
    return p.stdout


_KERNEL = """
import sys
import numpy as np
import numba

@numba.njit
def solve(a, b):
    return np.linalg.solve(a, b), np.dot(b, b)

a = np.array([[4.0, 1.0, 0.5], [1.0, 3.0, 0.2], [0.5, 0.2, 2.0]])
b = np.array([1.0, 2.0, 3.0])
x, d = solve(a, b)
print(repr(x.tolist()), repr(d))
"""


def test_numba_blas_check_without_scipy_linalg_package(tmp_path):
    out = _run(
        textwrap.dedent("""
        import sys
        from gearte._blas import preload_scipy_blas

        assert preload_scipy_blas()
        import numba
        import numba.np.arraymath  # numba's BLAS check: import scipy.linalg.cython_blas

        assert numba.np.arraymath._HAVE_BLAS
        assert "scipy.linalg" not in sys.modules, "numba imported the scipy.linalg package"
        import scipy.linalg  # the package as usual, the preloaded submodules as its attributes

        assert scipy.linalg.cython_blas is sys.modules["scipy.linalg.cython_blas"]
        assert scipy.linalg.cython_lapack is sys.modules["scipy.linalg.cython_lapack"]
        print("ok")
        """),
        tmp_path,
    )
    assert out.strip() == "ok"


@pytest.mark.slow
def test_kernel_calls_the_same_lapack_with_and_without_preload(tmp_path):
    """np.linalg.solve and np.dot in a kernel (two compiles: ~10 s CPU)."""
    preloaded = _run(
        textwrap.dedent("""
        import sys
        from gearte._blas import preload_scipy_blas

        assert preload_scipy_blas()
        import numba
        import numba.np.arraymath  # numba's BLAS check: import scipy.linalg.cython_blas

        assert numba.np.arraymath._HAVE_BLAS
        assert "scipy.linalg" not in sys.modules, "numba imported the scipy.linalg package"
        """)
        + _KERNEL
        + textwrap.dedent("""
        assert "scipy.linalg" not in sys.modules
        import scipy.linalg  # the package as usual, the preloaded submodules as its attributes

        assert scipy.linalg.cython_blas is sys.modules["scipy.linalg.cython_blas"]
        assert scipy.linalg.cython_lapack is sys.modules["scipy.linalg.cython_lapack"]
        assert preload_scipy_blas()  # idempotent
        """),
        tmp_path,
    )
    usual = _run(_KERNEL + "\nassert 'scipy.linalg' in sys.modules\n", tmp_path)
    # the same LAPACK dgesv and BLAS ddot either way: the same bits
    assert preloaded == usual


def test_preload_leaves_an_imported_scipy_linalg_alone(tmp_path):
    out = _run(
        textwrap.dedent("""
        import sys
        import scipy.linalg
        from gearte._blas import preload_scipy_blas

        before = sys.modules.get("scipy.linalg.cython_blas")
        n = len(sys.meta_path)
        preload_scipy_blas()
        assert sys.modules.get("scipy.linalg.cython_blas") is before
        assert len(sys.meta_path) == n
        print("ok")
        """),
        tmp_path,
    )
    assert out.strip() == "ok"
