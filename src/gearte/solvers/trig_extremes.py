"""Exact global maximum and minimum of a trigonometric polynomial over its period.

The coupled transmission error of a planetary (Wang et al. 2013) is, over its common period,

    f(u) = c + Σ_g Im(Z_g e^{i n_g u}),    n_g integers >= 1,

and its *amplitude* is ``max_u |f(u)| = max(fmax, -fmin)``. This module finds ``fmax`` and ``fmin``
to ~1e-13 relative, fast enough for millions of Monte-Carlo samples, and keeps a plain-numpy twin
and a naive fixed grid for tests and benchmarks.

Algorithm (:func:`exact_extremes`)
----------------------------------
1. *Dense stage*: f on ``M = 8 n_max`` nodes ``u_j = 2 pi j / M`` from tables of
   ``sin(n_g u_j), cos(n_g u_j)`` (one fused multiply-add per node and harmonic, vectorised).
2. *Pruning*: a maximum between two nodes exceeds the higher of them by at most
   ``h²/8 max|f''| <= h²/8 Σ|Z_g| n_g²`` (f' = 0 there; h = 2 pi / M). So only nodes within that
   margin of the best node can lead to the global maximum. Almost always that is the best node
   alone (counted in one vectorised pass); otherwise every discrete local maximum in the margin is
   refined.
3. *Refinement*: Halley iteration on f' from the vertex of the parabola through the node and its
   neighbours, in the offset ``d`` from the node, with ``e^{i n_g (u_j + d)} = T_gj e^{i n_g d}``:
   the node's table entries rotated by ``n_g d``, whose sine and cosine come from the fdlibm
   polynomial kernels (``|n_g d| <= n_max h = pi/4`` is their exact domain, < 1 ulp). The
   iteration stops when the step is below ``stol``, chosen so that the third-order Taylor value at
   the stepped point is within 1e-13 Σ|Z| of the true maximum; golden-section fallback on
   ``[u_j - h, u_j + h]`` if an iterate leaves it or meets f'' >= 0.

Exact provided two local maxima of f are never closer than two nodes (a quarter period of the
highest harmonic): two maxima that close differ in height by far less than the tolerance. Measured
against a 2^15-node grid refined from every local extremum: < 1e-13 relative
(``tests/test_wang2013_planetary.py``, ``benchmarks/bench_planetary_mc.py``).

Units: whatever the caller's (gearte passes mm); angles in rad.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np
from numba import njit

from gearte._jit import kernel
from gearte.errors import ParameterError

__all__ = [
    "exact_extremes",
    "exact_extremes_numpy",
    "grid_extremes_numpy",
    "grid_points",
    "sincos",
]

# fast-math only where node values are summed and compared: their rounding (a few ulp of Σ|Z|)
# is covered by the pruning margin; the refinement runs with strict IEEE semantics.
_FAST = {"nnan", "ninf", "nsz", "reassoc", "contract", "arcp"}

# fdlibm __kernel_sin / __kernel_cos coefficients (|r| <= pi/4, error < 1 ulp)
_S1 = -1.66666666666666324348e-01
_S2 = 8.33333333332248946124e-03
_S3 = -1.98412698298579493134e-04
_S4 = 2.75573137070700676789e-06
_S5 = -2.50507602534068634195e-08
_S6 = 1.58969099521155010221e-10
_C1 = 4.16666666666666019037e-02
_C2 = -1.38888888888741095749e-03
_C3 = 2.48015872894767294178e-05
_C4 = -2.75573143513906633035e-07
_C5 = 2.08757232129817482790e-09
_C6 = -1.13596475577881948265e-11
# Cody-Waite reduction by pi/2: 33-bit head (k * head exact for |k| < 2^20) + tail
_INV_PIO2 = 6.36619772367581382433e-01
_PIO2_HEAD = 1.57079632673412561417e00
_PIO2_TAIL = 6.07710050650619224932e-11
SINCOS_MAX_ARG = 1.0e5
"""|x| [rad] up to which :func:`sincos` is accurate to ~2e-16 absolute."""


@njit(cache=True, nogil=True, inline="always")
def _sincos_kernel(r):
    """sin r, cos r for |r| <= pi/4 (fdlibm kernels, < 1 ulp)."""
    z = r * r
    s = r + z * r * (_S1 + z * (_S2 + z * (_S3 + z * (_S4 + z * (_S5 + z * _S6)))))
    rc = z * (_C1 + z * (_C2 + z * (_C3 + z * (_C4 + z * (_C5 + z * _C6)))))
    hz = 0.5 * z
    w = 1.0 - hz
    return s, w + (((1.0 - w) - hz) + z * rc)


@kernel
def sincos_into(x, s, c):
    """s[i], c[i] = sin x[i], cos x[i] for 1-D arrays, |x| <= SINCOS_MAX_ARG unchecked (the
    compiled core of :func:`sincos`, callable from other kernels); branch-free, so the loop
    vectorises (~1.5 ns a pair against ~25 ns for two libm calls)."""
    for i in range(x.shape[0]):
        xi = x[i]
        k = math.floor(xi * _INV_PIO2 + 0.5)
        sp, cp = _sincos_kernel((xi - k * _PIO2_HEAD) - k * _PIO2_TAIL)
        q = np.int64(k) & 3
        sa = sp if (q & 1) == 0 else cp
        ca = cp if (q & 1) == 0 else sp
        s[i] = sa if q < 2 else -sa
        c[i] = ca if (q == 0 or q == 3) else -ca


def sincos(x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Sine and cosine of ``x`` [rad] in one compiled, vectorised pass.

    Cody-Waite reduction by pi/2 and the fdlibm polynomial kernels; absolute error <= 2.3e-16 for
    ``|x| <=`` :data:`SINCOS_MAX_ARG` (tested against :func:`numpy.sin` / :func:`numpy.cos`).
    The Monte-Carlo kernel uses it for the random assembly angles.
    """
    x = np.ascontiguousarray(np.asarray(x, dtype=float))
    flat = x.ravel()
    if flat.size and not np.all(np.abs(flat) <= SINCOS_MAX_ARG):
        raise ParameterError("x", float(np.max(np.abs(flat))), f"|x| must be <= {SINCOS_MAX_ARG}")
    s = np.empty_like(flat)
    c = np.empty_like(flat)
    sincos_into(flat, s, c)
    return s.reshape(x.shape), c.reshape(x.shape)


def grid_points(harmonics: Sequence[int] | np.ndarray) -> int:
    """Nodes of the dense stage: 8 per period of the highest of ``harmonics`` (>= 16), so that
    ``n_max h = pi/4`` bounds the rotation angles of the refinement.

    Parameters
    ----------
    harmonics : sequence of int
        Harmonic orders of the trigonometric polynomial [-].

    Returns
    -------
    int
        Number of grid nodes [-].
    """
    return max(16, 8 * int(max(harmonics)) if len(harmonics) else 16)


@njit(cache=True, nogil=True, inline="always")
def node_tables(nh, M):
    """tab[2g, j] = sin(n_g u_j), tab[2g + 1, j] = cos(n_g u_j), u_j = 2 pi j / M (the product
    n_g j reduced modulo M in integers first)."""
    G = nh.shape[0]
    tab = np.empty((2 * G, M))
    for g in range(G):
        for j in range(M):
            a = 2.0 * math.pi * ((nh[g] * j) % M) / M
            tab[2 * g, j] = math.sin(a)
            tab[2 * g + 1, j] = math.cos(a)
    return tab


@kernel(fastmath=_FAST)
def _grid_fill(c, zr, zi, tab, buf):
    """buf[j] = f(u_j); returns the largest and smallest node value."""
    M = buf.shape[0]
    G = zr.shape[0]
    a = zr[0]
    b = zi[0]
    for j in range(M):
        buf[j] = c + a * tab[0, j] + b * tab[1, j]
    for g in range(1, G):
        a = zr[g]
        b = zi[g]
        for j in range(M):
            buf[j] += a * tab[2 * g, j] + b * tab[2 * g + 1, j]
    mx = buf[0]
    mn = buf[0]
    for j in range(M):
        v = buf[j]
        mx = v if v > mx else mx
        mn = v if v < mn else mn
    return mx, mn


@kernel(fastmath=_FAST)
def _count_beyond(buf, tx, tn):
    """Nodes above tx (count, sum of indices) and below tn (count, sum of indices); with a count
    of one the sum is the index. One vectorised pass."""
    nx = 0
    sx = 0
    nn = 0
    sn = 0
    for j in range(buf.shape[0]):
        v = buf[j]
        ax = v > tx
        an = v < tn
        nx += ax
        sx += j if ax else 0
        nn += an
        sn += j if an else 0
    return nx, sx, nn, sn


@njit(cache=True, nogil=True, inline="always")
def _eval_at(d, c, wr, wi, nh):
    """f, f', f'', f''' at offset d [rad] from a node, given W_g = Z_g e^{i n_g u_j} (wr, wi);
    requires |n_g d| <= pi/4."""
    f = c
    d1 = 0.0
    d2 = 0.0
    d3 = 0.0
    for g in range(nh.shape[0]):
        n = float(nh[g])
        s, co = _sincos_kernel(n * d)
        im = wr[g] * s + wi[g] * co
        re = wr[g] * co - wi[g] * s
        f += im
        d1 += n * re
        d2 -= n * n * im
        d3 -= n * n * n * re
    return f, d1, d2, d3


@kernel
def _refine(j, sgn, buf, tab, c, zr, zi, nh, h, stol, wr, wi):
    """Largest sgn*f on [u_j - h, u_j + h]: Halley on f' from the parabolic vertex; if an
    iterate leaves the interval, meets f'' >= 0 or 30 steps do not converge, golden-section
    search on [-h, h] (200 steps at most, down to 1e-12 rad) and the best of its two last
    points and the node.

    Written as a state machine with a single evaluation of f (:func:`_eval_at`, inlined): each
    call site would compile its own copy (issue 12: first-run compile)."""
    M = buf.shape[0]
    for g in range(nh.shape[0]):
        s = tab[2 * g, j]
        co = tab[2 * g + 1, j]
        wr[g] = zr[g] * co - zi[g] * s
        wi[g] = zr[g] * s + zi[g] * co
    vp = sgn * buf[j - 1 if j > 0 else M - 1]
    v = sgn * buf[j]
    vn = sgn * buf[j + 1 if j < M - 1 else 0]
    den = vp - 2.0 * v + vn
    x = 0.5 * h * (vp - vn) / den if den < 0.0 else 0.0
    gr = 0.6180339887498949
    a = -h
    b = h
    x1 = 0.0
    x2 = 0.0
    f1 = 0.0
    f2 = 0.0
    # phase 0: Halley (it = steps taken); golden section: 1 first point x1, 2 first point x2,
    # 3 new x2, 5 new x1 (it = its steps), 4 the node itself, then done
    phase = 0
    it = 0
    while True:
        f, d1, d2, d3 = _eval_at(x, c, wr, wi, nh)  # the only evaluation
        if phase == 0:
            d1 *= sgn
            d2 *= sgn
            d3 *= sgn
            if d2 < 0.0:
                q = 2.0 * d2 * d2 - d1 * d3
                step = -2.0 * d1 * d2 / q if q > 0.0 else -d1 / d2  # Halley, else Newton
                if abs(step) <= stol:
                    return sgn * f + step * (d1 + step * (0.5 * d2 + step * d3 / 6.0))
                x = x + step
                it += 1
                if not (x < -h or x > h) and it < 30:
                    continue
            # golden-section fallback on [-h, h]
            x1 = b - gr * (b - a)
            x2 = a + gr * (b - a)
            x = x1
            phase = 1
            continue
        if phase == 4:
            return max(f1, f2, sgn * f)
        if phase == 1:
            f1 = sgn * f
            x = x2
            phase = 2
            it = 0
            continue
        if phase == 5:
            f1 = sgn * f
        else:  # phases 2 and 3
            f2 = sgn * f
        if it >= 200 or b - a <= 1e-12:
            x = 0.0
            phase = 4
            continue
        it += 1
        if f1 < f2:
            a = x1
            x1 = x2
            f1 = f2
            x2 = a + gr * (b - a)
            x = x2
            phase = 3
        else:
            b = x2
            x2 = x1
            f2 = f1
            x1 = b - gr * (b - a)
            x = x1
            phase = 5


@njit(cache=True, nogil=True, inline="always")
def extremes_kernel(c, zr, zi, nh, tab, buf, wr, wi):
    """(max f, min f) over one period for one sample (compiled; see the module docstring).

    ``tab`` from :func:`node_tables` with ``M = len(buf)`` >= 8 n_max nodes; ``wr, wi`` scratch of
    length G. Inlined into the kernels that call it (one call site each: the Monte-Carlo /
    optimisation kernel of :mod:`gearte.models.planetary_errors` and :func:`exact_extremes`), with
    a single call site of the refinement: every call site of a kernel compiles its own copy.
    """
    M = buf.shape[0]
    h = 2.0 * math.pi / M
    mx, mn = _grid_fill(c, zr, zi, tab, buf)
    K2 = 0.0
    s1 = 0.0
    s4 = 0.0
    for g in range(nh.shape[0]):
        a = math.sqrt(zr[g] * zr[g] + zi[g] * zi[g])
        n2 = float(nh[g] * nh[g])
        K2 += a * n2
        s1 += a
        s4 += a * n2 * n2
    # margin: h²/8 max|f''| plus the rounding of the (fast-math) node values
    bound = h * h / 8.0 * K2 + 1e-14 * (s1 + abs(c))
    # Taylor-stop step: Σ|Z| n⁴ stol⁴ / 24 <= 1e-13 Σ|Z|, and never above 1e-3 rad
    stol = min(1e-3, math.sqrt(math.sqrt(2.4e-12 * s1 / s4))) if s4 > 0.0 else 1e-3
    nx, sx, nn, sn = _count_beyond(buf, mx - bound, mn + bound)
    fmax = 0.0
    fmin = 0.0
    for side in range(2):  # the maximum, then the minimum as the maximum of -f
        sgn = 1.0 if side == 0 else -1.0
        cnt = nx if side == 0 else nn
        thr = mx - bound if side == 0 else -(mn + bound)
        # the best node alone within the margin: refine it; else every discrete local maximum
        # of sgn*f above the margin
        j0 = (sx if side == 0 else sn) if cnt == 1 else 0
        j1 = j0 + 1 if cnt == 1 else M
        best = -np.inf
        for j in range(j0, j1):
            if cnt != 1:
                v = sgn * buf[j]
                if not v > thr:
                    continue
                vp = sgn * buf[j - 1 if j > 0 else M - 1]
                vn = sgn * buf[j + 1 if j < M - 1 else 0]
                if not (v >= vp and v >= vn):
                    continue
            r = _refine(j, sgn, buf, tab, c, zr, zi, nh, h, stol, wr, wi)
            if cnt == 1 or r > best:
                best = r
        if side == 0:
            fmax = best
        else:
            fmin = -best
    return max(fmax, mx), min(fmin, mn)


@kernel
def _extremes_batch(c, zr, zi, nh, M):
    n = c.shape[0]
    G = nh.shape[0]
    tab = node_tables(nh, M)
    buf = np.empty(M)
    wr = np.empty(G)
    wi = np.empty(G)
    fmax = np.empty(n)
    fmin = np.empty(n)
    for i in range(n):
        fmax[i], fmin[i] = extremes_kernel(c[i], zr[i], zi[i], nh, tab, buf, wr, wi)
    return fmax, fmin


def exact_extremes(
    c: np.ndarray, Z: np.ndarray, harmonics: Sequence[int]
) -> tuple[np.ndarray, np.ndarray]:
    """Exact max and min over one period of ``f(u) = c + Σ_g Im(Z_g e^{i n_g u})``.

    Parameters
    ----------
    c : ndarray, shape (n,)
        Constant part [mm].
    Z : ndarray of complex, shape (n, G)
        Phasors per harmonic [mm].
    harmonics : sequence of int
        Harmonic numbers n_g (>= 1).

    Returns
    -------
    fmax, fmin : ndarray, shape (n,)
        [mm]. The coupled-TE *amplitude* is ``max(fmax, -fmin)`` (= max |Σe(t)|, Wang 2013's
        amplitude of the coupled error) and the peak-to-peak ``fmax - fmin``.

    Notes
    -----
    Algorithm and accuracy in the module docstring; compiled with numba.
    :func:`exact_extremes_numpy` is the plain twin.

    Examples
    --------
    Third-harmonic injection, ``sin u + sin(3u)/6``, peaks at sqrt(3)/2:

    >>> fx, fn = exact_extremes(np.array([0.0]), np.array([[1.0, 1 / 6]]), (1, 3))
    >>> round(float(fx[0]), 12), round(float(fn[0]), 12)
    (0.866025403784, -0.866025403784)
    """
    nh = np.ascontiguousarray(np.asarray(harmonics, dtype=np.int64))
    c = np.ascontiguousarray(np.atleast_1d(np.asarray(c, dtype=float)))
    Z = np.atleast_2d(np.asarray(Z, dtype=complex))
    if nh.size == 0:
        return c.copy(), c.copy()
    if np.any(nh < 1):
        raise ParameterError("harmonics", harmonics, "must be integers >= 1")
    M = grid_points(nh)
    return _extremes_batch(c, np.ascontiguousarray(Z.real), np.ascontiguousarray(Z.imag), nh, M)


def exact_extremes_numpy(
    c: np.ndarray,
    Z: np.ndarray,
    harmonics: Sequence[int],
    iterations: int = 30,
    points: int | None = None,
) -> tuple[np.ndarray, np.ndarray]:
    """Plain-numpy twin of :func:`exact_extremes`: grid of ``points`` (default 8 n_max) nodes,
    Newton from *every* discrete local extremum (no pruning, ``iterations`` steps), vectorised;
    used to test the compiled kernel and, with a fine grid, as the reference of the benchmark.
    ``c`` constant part [mm], ``Z`` phasors per harmonic [mm], ``harmonics`` n_g [-] as for
    :func:`exact_extremes`."""
    nh = np.asarray(harmonics, dtype=np.int64)
    c = np.atleast_1d(np.asarray(c, dtype=float))
    Z = np.atleast_2d(np.asarray(Z, dtype=complex))
    if nh.size == 0:
        return c.copy(), c.copy()
    M = grid_points(nh) if points is None else int(points)
    h = 2 * np.pi / M
    u = np.arange(M) * h

    def fd(rows: np.ndarray, uu: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        e = np.exp(1j * nh * uu[..., None]) * Z[rows]
        f = c[rows] + e.imag.sum(-1)
        d1 = (nh * e.real).sum(-1)
        d2 = -(nh**2 * e.imag).sum(-1)
        return f, d1, d2

    f = c[:, None] + (Z.real @ np.sin(np.outer(nh, u)) + Z.imag @ np.cos(np.outer(nh, u)))
    out = []
    for sgn in (1.0, -1.0):
        g = sgn * f
        is_ext = (g >= np.roll(g, 1, axis=1)) & (g >= np.roll(g, -1, axis=1))
        rows, cols = np.nonzero(is_ext)  # Newton from every discrete local extremum
        u0 = u[cols]
        uu = u0.copy()
        for _ in range(iterations):
            _, d1, d2 = fd(rows, uu)
            step = np.where(sgn * d2 < 0, -d1 / np.where(d2 == 0, 1.0, d2), 0.0)
            uu = np.clip(uu + step, u0 - h, u0 + h)
        fr, _, _ = fd(rows, uu)
        val = np.maximum(sgn * fr, g[rows, cols])
        best = np.full(len(c), -np.inf)
        np.maximum.at(best, rows, val)
        out.append(sgn * best)
    return out[0], out[1]


def grid_extremes_numpy(
    c: np.ndarray, Z: np.ndarray, harmonics: Sequence[int], points: int = 2048
) -> tuple[np.ndarray, np.ndarray]:
    """Fixed-grid max/min over one period from the phasors (``points`` nodes, no refinement,
    one matrix product) [mm]: the *optimised* grid of ``benchmarks/bench_planetary_mc.py``.
    ``c`` constant part [mm], ``Z`` phasors per harmonic [mm], ``harmonics`` n_g [-]."""
    nh = np.asarray(harmonics, dtype=np.int64)
    c = np.atleast_1d(np.asarray(c, dtype=float))
    Z = np.atleast_2d(np.asarray(Z, dtype=complex))
    u = np.arange(points) * (2 * np.pi / points)
    E = np.exp(1j * np.outer(nh, u))  # (G, P)
    f = c[:, None] + (Z.real @ E.imag + Z.imag @ E.real)
    return f.max(axis=1), f.min(axis=1)
