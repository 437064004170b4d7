"""The compiled ask/tell Nelder–Mead (``gearte.solvers.nelder_mead``) against SciPy's."""

from __future__ import annotations

import numpy as np
import pytest

from gearte.solvers.nelder_mead import nm_best, nm_start, nm_tell


def _rosenbrock(x: np.ndarray) -> float:
    return float(100.0 * (x[1] - x[0] ** 2) ** 2 + (1.0 - x[0]) ** 2)


def _ask_tell(fun, x0: np.ndarray, xatol: float, fatol: float, maxiter: int):
    N = x0.size
    sim, fsim, vec = np.empty((N + 1, N)), np.empty(N + 2), np.empty((4, N))
    ist = np.zeros(4, dtype=np.int64)
    nm_start(x0, maxiter, sim, fsim, vec, ist)
    nfev = 0
    while True:
        nfev += 1
        if nm_tell(fun(vec[2]), xatol, fatol, sim, fsim, vec, ist):
            return sim[0].copy(), nm_best(fsim, N), nfev, int(ist[2])


@pytest.mark.parametrize("x0", [(-1.2, 1.0), (0.0, 0.0), (2.0, -1.5)])
def test_ask_tell_nelder_mead_reproduces_scipy_adaptive_rosenbrock(x0):
    """Same operations in the same order as SciPy's adaptive Nelder–Mead: the same vertex, value,
    evaluations and iterations, bit for bit (a zero coordinate exercises SciPy's 0.00025 step;
    the Rosenbrock valley exercises expansion, both contractions and shrinks)."""
    from scipy.optimize import minimize

    x0 = np.array(x0)
    opts = {"xatol": 1e-10, "fatol": 1e-14, "maxiter": 4000, "adaptive": True}
    ref = minimize(_rosenbrock, x0, method="Nelder-Mead", options=opts)
    x, f, nfev, nit = _ask_tell(_rosenbrock, x0, 1e-10, 1e-14, 4000)
    assert np.array_equal(x, ref.x)
    assert f == ref.fun
    assert (nfev, nit) == (ref.nfev, ref.nit)


def test_ask_tell_nelder_mead_stops_at_maxiter():
    """``maxiter`` iterations at most, as SciPy's (which then reports no success)."""
    from scipy.optimize import minimize

    x0 = np.array([-1.2, 1.0])
    ref = minimize(_rosenbrock, x0, method="Nelder-Mead", options={"maxiter": 7, "adaptive": True})
    x, f, _, nit = _ask_tell(_rosenbrock, x0, 1e-4, 1e-4, 7)
    assert not ref.success
    assert nit == ref.nit == 7
    assert np.array_equal(x, ref.x) and f == ref.fun
