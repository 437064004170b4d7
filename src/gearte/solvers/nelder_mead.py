"""Compiled Nelder–Mead as an ask/tell state machine: the caller evaluates the objective.

A port of SciPy 1.17 ``_minimize_neldermead`` (``adaptive=True``, no bounds, ``maxfev``
unlimited) with the same operations in the same order, split so that the objective is called by
the caller's own loop: :func:`nm_start` builds the initial simplex and puts the first point to
evaluate in ``vec[2]``; the caller evaluates it and passes the value to :func:`nm_tell`, which
advances the method and puts the next point in ``vec[2]``, until it returns True.

Why ask/tell: a compiled kernel that calls its objective at several places, or an optimiser that
calls a compiled objective, compiles its own copy of the objective at every call site (numba
inlines and re-optimises what a kernel calls). With the loop in the caller, the objective has a
single call site in one kernel (issue 12: first-run compile; ``docs/numba.md``).

State (all arrays, owned by the caller):

* ``sim`` (N + 1, N): the simplex' vertices; ``sim[0]`` the best after :func:`nm_tell` returns
  True;
* ``fsim`` (N + 2,): their values, ``fsim[N + 1]`` the reflected point's value;
* ``vec`` (4, N): rows centroid, reflected point, point to evaluate, scratch;
* ``ist`` (4,) int64: phase, vertex counter, iteration count, ``maxiter``.

References
----------
Gao, F., Han, L. (2012). Implementing the Nelder-Mead simplex algorithm with adaptive
parameters. Computational Optimization and Applications 51, 259–277.
https://doi.org/10.1007/s10589-010-9329-3
"""

from __future__ import annotations

import numpy as np
from numba import njit

from gearte._jit import kernel

__all__ = ["nm_best", "nm_start", "nm_tell"]


@njit(cache=True, nogil=True, inline="always")
def _sort_simplex(sim, fsim, row):
    """Order the vertices by value (stable insertion sort, as numpy's argsort on < 16 items);
    ``row`` scratch of one vertex. Written with scalar loops only: array expressions and slice
    assignments would triple the compile time."""
    n, N = sim.shape
    for i in range(1, n):
        f = fsim[i]
        for q in range(N):
            row[q] = sim[i, q]
        j = i - 1
        while j >= 0 and fsim[j] > f:
            fsim[j + 1] = fsim[j]
            for q in range(N):
                sim[j + 1, q] = sim[j, q]
            j -= 1
        fsim[j + 1] = f
        for q in range(N):
            sim[j + 1, q] = row[q]


def nm_start(
    x0: np.ndarray,
    maxiter: int,
    sim: np.ndarray,
    fsim: np.ndarray,
    vec: np.ndarray,
    ist: np.ndarray,
) -> None:
    """Initial simplex around ``x0`` (SciPy's: 5 % along each axis, 0.00025 where a coordinate
    is 0) and the first point to evaluate in ``vec[2]``. Plain numpy (called once per start,
    nothing to compile).

    Parameters
    ----------
    x0 : ndarray, shape (N,)
        Start point [the objective's units].
    maxiter : int
        Iterations at most [-].
    sim, fsim, vec, ist : ndarray
        The state arrays of the module docstring, filled here (shapes (N + 1, N), (N + 2,),
        (4, N), (4,) int64) [the point's, the objective's, the point's units; counters -].
    """
    N = x0.shape[0]
    sim[:] = x0
    for k in range(1, N + 1):
        y = x0[k - 1]
        sim[k, k - 1] = (1.0 + 0.05) * y if y != 0 else 0.00025
    vec[2] = sim[0]
    fsim[N + 1] = 0.0
    ist[:] = (0, 0, 1, maxiter)


@kernel
def nm_tell(f, xatol, fatol, sim, fsim, vec, ist):
    """The objective's value ``f`` at ``vec[2]``: advance the method; True when it has converged
    (SciPy's test on ``xatol``, ``fatol``) or run ``ist[3]`` iterations, else the next point to
    evaluate is in ``vec[2]``.

    Phases (``ist[0]``): 0 initial vertex ``ist[1]``, 1 reflection, 2 expansion, 3 outside /
    4 inside contraction, 5 shrunk vertex ``ist[1]``. Each step (replace the worst vertex, sort,
    test, next trial point) is written once: every call site of a helper compiles a copy.

    Parameters
    ----------
    f : float
        The objective at ``vec[2]`` [the objective's units].
    xatol, fatol : float
        SciPy's absolute tolerances on the vertices [the point's units] and on their values
        [the objective's units].
    sim, fsim, vec, ist : ndarray
        The state arrays of the module docstring, from :func:`nm_start`, updated in place.
    """
    N = sim.shape[1]
    dim = float(N)
    rho = 1.0
    chi = 1.0 + 2.0 / dim
    psi = 0.75 - 1.0 / (2.0 * dim)
    sigma = 1.0 - 1.0 / dim
    xbar = vec[0]
    xr = vec[1]
    xt = vec[2]
    row = vec[3]
    state = ist[0]
    # 1: the initial simplex is complete (sort, test, reflect); 2: an iteration ends (count too)
    end = 0
    put_x = 0  # vertex N := (xt if 1, xr if 2) with value put_f
    put_f = f
    ab_set = False  # next trial point xt = ca xbar + cb sim[N]
    ca = 0.0
    cb = 0.0
    if state == 0 or state == 5:
        k = ist[1]
        fsim[k] = f
        k += 1
        ist[1] = k
        if k <= N:
            for q in range(N):
                if state == 5:
                    sim[k, q] = sim[0, q] + sigma * (sim[k, q] - sim[0, q])
                xt[q] = sim[k, q]
            return False
        end = 1 if state == 0 else 2
    elif state == 1:
        fsim[N + 1] = f
        for q in range(N):
            xr[q] = xt[q]
        if f < fsim[0]:  # expand
            ab_set = True
            ca = 1.0 + rho * chi
            cb = -(rho * chi)
            ist[0] = 2
        elif f < fsim[N - 1]:
            put_x = 2
            end = 2
        elif f < fsim[N]:  # outside contraction
            ab_set = True
            ca = 1.0 + psi * rho
            cb = -(psi * rho)
            ist[0] = 3
        else:  # inside contraction
            ab_set = True
            ca = 1.0 - psi
            cb = psi
            ist[0] = 4
    elif state == 2:
        if f < fsim[N + 1]:
            put_x = 1
        else:
            put_x = 2
            put_f = fsim[N + 1]
        end = 2
    elif (state == 3 and f <= fsim[N + 1]) or (state == 4 and f < fsim[N]):
        put_x = 1
        end = 2
    else:  # contraction failed: shrink towards the best vertex
        ist[0] = 5
        ist[1] = 1
        for q in range(N):
            sim[1, q] = sim[0, q] + sigma * (sim[1, q] - sim[0, q])
            xt[q] = sim[1, q]
    if put_x != 0:
        for q in range(N):
            sim[N, q] = xt[q] if put_x == 1 else xr[q]
        fsim[N] = put_f
    if end != 0:
        if end == 2:
            ist[2] += 1
        _sort_simplex(sim, fsim, row)
        if ist[2] >= ist[3]:
            return True
        # SciPy's convergence test; if not converged, the centroid of the best N vertices and
        # the reflected point
        dx = 0.0
        df = 0.0
        for k in range(1, N + 1):
            df = max(df, abs(fsim[0] - fsim[k]))
            for q in range(N):
                dx = max(dx, abs(sim[k, q] - sim[0, q]))
        if dx <= xatol and df <= fatol:
            return True
        for q in range(N):
            acc = sim[0, q]
            for k in range(1, N):
                acc += sim[k, q]
            xbar[q] = acc / N
        ab_set = True
        ca = 1.0 + rho
        cb = -rho
        ist[0] = 1
    if ab_set:  # SciPy's operation order: a x + b y
        for q in range(N):
            xt[q] = ca * xbar[q] + cb * sim[N, q]
    return False


def nm_best(fsim: np.ndarray, N: int) -> float:
    """The smallest of the N + 1 vertex values (plain Python: called once per run).

    Parameters
    ----------
    fsim : ndarray, shape (N + 2,)
        The vertex values of the state (module docstring) [the objective's units].
    N : int
        Dimension [-].
    """
    best = float(fsim[0])
    for k in range(1, N + 1):
        best = min(best, float(fsim[k]))
    return best
