"""Load-sharing fixed point of a cycloid disc on its pins (Hu et al. 2020, eq 37–44).

The model (in :mod:`gearte.models.cycloid_contact`) gives, for each mesh position, the pins'
normalised arms ``lr_i = l_i / r_c`` and initial clearances ``Δ_i`` [mm], and a compliance law
``δ_max(F) = A F (2/3 + ln(B / F))`` [mm] (eq 38–39 written with two constants). The pins touch
when ``lr_i δ_max > Δ_i`` and carry ``F_i = (lr_i δ_max − Δ_i)/δ_max F_max`` (eq 41); the
moment balance (eq 42–44) is the fixed point

    F_max = T_c / Σ_i (lr_i − Δ_i/δ_max(F_max)) lr_i r_c          (eq 44)

This module solves it as the root of ``g(F) = (F/δ_max(F)) Σ_i max(lr_i δ_max(F) − Δ_i, 0) lr_i r_c
− T_c``. ``g`` is continuous and strictly increasing in F (δ_max increases, so every term does),
negative at F → 0 and unbounded above, so the root is unique and the answer does not depend on
the start value; the start only seeds the bracket. A bracketed Illinois (modified regula falsi)
iteration with bisection safeguard converges in typically 8–15 evaluations, where the plain
Picard iteration of eq 44 that the paper uses oscillates (its Table 4).

Two implementations with one API: :func:`solve_load_sharing` (numba, many mesh positions at
once) and :func:`solve_load_sharing_plain` (a flat per-pin Python loop with bisection, the
readable reference the compiled one is tested against).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from gearte.errors import ConvergenceError, ParameterError

__all__ = [
    "solve_load_sharing",
    "solve_load_sharing_plain",
    "compliance_limit",
]

_OK, _NO_CONV, _NO_BRACKET, _LIMIT = 0, 1, 2, 3


def compliance_limit(B: float) -> float:
    """Largest load [N] for which δ_max(F) = A F (2/3 + ln(B/F)) still increases with F."""
    return B * math.exp(-1.0 / 3.0)


@njit(cache=True, nogil=True)
def _delta(F, A, B):  # pragma: no cover - compiled
    return A * F * (2.0 / 3.0 + math.log(B / F))


@njit(cache=True, nogil=True)
def _resid(F, lr, clr, T_c, r_c, A, B):  # pragma: no cover - compiled
    d = _delta(F, A, B)
    s = 0.0
    for i in range(lr.shape[0]):
        if lr[i] > 0.0:
            e = lr[i] * d - clr[i]
            if e > 0.0:
                s += e * lr[i]
    return F / d * s * r_c - T_c


@njit(cache=True, nogil=True)
def _solve_one(lr, clr, T_c, r_c, A, B, F0, rtol, max_iter):  # pragma: no cover - compiled
    Fcap = B * math.exp(-1.0 / 3.0)
    n_eval = 0
    lo = F0
    hi = F0
    glo = _resid(lo, lr, clr, T_c, r_c, A, B)
    n_eval += 1
    if glo < 0.0:
        ghi = glo
        while ghi < 0.0:
            lo, glo = hi, ghi
            hi = 2.0 * hi
            if hi > Fcap:
                hi = Fcap
                ghi = _resid(hi, lr, clr, T_c, r_c, A, B)
                n_eval += 1
                if ghi < 0.0:
                    return hi, n_eval, _LIMIT
                break
            ghi = _resid(hi, lr, clr, T_c, r_c, A, B)
            n_eval += 1
            if n_eval > 2000:
                return hi, n_eval, _NO_BRACKET
    else:
        ghi = glo
        hi = lo
        while glo >= 0.0:
            hi, ghi = lo, glo
            lo = 0.5 * lo
            glo = _resid(lo, lr, clr, T_c, r_c, A, B)
            n_eval += 1
            if n_eval > 2000:
                return lo, n_eval, _NO_BRACKET
    # Illinois iteration on [lo, hi] with g(lo) < 0 <= g(hi)
    side = 0
    x = hi
    for _ in range(max_iter):
        if hi - lo <= rtol * hi:
            return 0.5 * (lo + hi), n_eval, _OK
        x = (lo * ghi - hi * glo) / (ghi - glo)
        if not (lo < x < hi):
            x = 0.5 * (lo + hi)
        gx = _resid(x, lr, clr, T_c, r_c, A, B)
        n_eval += 1
        if gx == 0.0:
            return x, n_eval, _OK
        if gx < 0.0:
            lo, glo = x, gx
            if side == -1:
                ghi *= 0.5
            side = -1
        else:
            hi, ghi = x, gx
            if side == 1:
                glo *= 0.5
            side = 1
        if min(x - lo, hi - x) <= 0.5 * rtol * x:
            # the new point sits on a bracket end: close the other end by a bisection-size step
            m = 0.5 * (lo + hi)
            gm = _resid(m, lr, clr, T_c, r_c, A, B)
            n_eval += 1
            if gm < 0.0:
                lo, glo = m, gm
            else:
                hi, ghi = m, gm
    if hi - lo <= rtol * hi:
        return 0.5 * (lo + hi), n_eval, _OK
    return x, n_eval, _NO_CONV


@njit(cache=True, nogil=True)
def _solve_batch(lr, clr, T_c, r_c, A, B, F0, rtol, max_iter):  # pragma: no cover - compiled
    n = lr.shape[0]
    F = np.empty(n)
    nit = np.empty(n, dtype=np.int64)
    status = np.empty(n, dtype=np.int64)
    for k in range(n):
        f, it, st = _solve_one(lr[k], clr[k], T_c, r_c, A, B, F0[k], rtol, max_iter)
        F[k] = f
        nit[k] = it
        status[k] = st
    return F, nit, status


def _raise(status: int, k: int, F: float, n_eval: int, rtol: float, T_c: float, Fcap: float):
    if status == _LIMIT:
        raise ParameterError(
            "torque",
            T_c,
            f"needs a pin force above {Fcap:.4g} N, beyond the range of the compliance law "
            "(eq 38: ln(16 r |rho| / c^2) must exceed 1/3); lower the torque or widen the face",
        )
    what = "no sign change found" if status == _NO_BRACKET else "not converged"
    raise ConvergenceError(
        f"tooth-contact load sharing (mesh position {k}): {what} after {n_eval} residual "
        f"evaluations; last F_max = {F:.6g} N, relative tolerance {rtol:g}"
    )


def _prep(lr, clr, T_c, r_c, A, B, F0):
    lr = np.ascontiguousarray(np.atleast_2d(np.asarray(lr, dtype=float)))
    clr = np.ascontiguousarray(np.broadcast_to(np.asarray(clr, dtype=float), lr.shape), dtype=float)
    for name, v in (("T_c", T_c), ("r_c", r_c), ("A", A), ("B", B)):
        if not (math.isfinite(v) and v > 0.0):
            raise ParameterError(name, v, "must be finite and > 0")
    if not np.all(np.isfinite(lr)) or not np.all(np.isfinite(clr)):
        raise ParameterError("clearance", "non-finite", "arms and clearances must be finite")
    if not np.any(lr > 0.0, axis=1).all():
        raise ParameterError("lr", "no loaded pin", "every mesh position needs a pin with l_i > 0")
    F0 = np.broadcast_to(np.asarray(F0, dtype=float), (lr.shape[0],)).copy()
    if not (np.all(np.isfinite(F0)) and np.all(F0 > 0.0)):
        raise ParameterError("F_start", F0, "start values must be finite and > 0 [N]")
    if np.any(F0 >= compliance_limit(B)):
        raise ParameterError(
            "F_start",
            F0,
            f"start values must be below the compliance limit {compliance_limit(B):.4g} N",
        )
    return lr, clr, F0


def solve_load_sharing(
    lr: np.ndarray,
    clr: np.ndarray,
    *,
    T_c: float,
    r_c: float,
    A: float,
    B: float,
    F_start: float | np.ndarray,
    rtol: float = 1e-12,
    max_iter: int = 200,
) -> tuple[np.ndarray, np.ndarray]:
    """Solve eq 44 for F_max at many mesh positions (numba kernel).

    Parameters
    ----------
    lr : ndarray, shape (n, z_p)
        l_i / r_c of every pin at each mesh position [-]; pins with lr ≤ 0 never touch.
    clr : ndarray, shape (n, z_p)
        Initial clearance Δ_i (eq 32) [mm].
    T_c : float
        Torque on the disc [N·mm].
    r_c : float
        Cycloid pitch radius a z_c [mm].
    A, B : float
        Compliance constants: δ_max(F) = A F (2/3 + ln(B/F)) [mm/N, N].
    F_start : float or ndarray
        Start value(s) of F_max [N] (seed the bracket only).
    rtol : float
        Relative width of the final bracket [-].
    max_iter : int
        Iterations allowed after bracketing.

    Returns
    -------
    F_max : ndarray, shape (n,)
        The fixed point [N].
    n_eval : ndarray, shape (n,)
        Residual evaluations used.

    Raises
    ------
    ConvergenceError
        When a position does not converge within ``max_iter``.
    ParameterError
        When the load lies beyond the compliance law's range.
    """
    lr, clr, F0 = _prep(lr, clr, T_c, r_c, A, B, F_start)
    F, nit, status = _solve_batch(
        lr, clr, float(T_c), float(r_c), float(A), float(B), F0, float(rtol), int(max_iter)
    )
    bad = np.nonzero(status != _OK)[0]
    if bad.size:
        k = int(bad[0])
        _raise(int(status[k]), k, float(F[k]), int(nit[k]), rtol, T_c, compliance_limit(B))
    return F, nit


def solve_load_sharing_plain(
    lr: np.ndarray,
    clr: np.ndarray,
    *,
    T_c: float,
    r_c: float,
    A: float,
    B: float,
    F_start: float | np.ndarray,
    rtol: float = 1e-12,
    max_iter: int = 200,
) -> tuple[np.ndarray, np.ndarray]:
    """Plain-Python twin of :func:`solve_load_sharing`: per-pin loops and bisection.

    Same arguments and results; kept flat and readable as the reference implementation.

    Parameters
    ----------
    lr : ndarray, shape (n, z_p)
        l_i / r_c of every pin at each mesh position [-]; pins with lr ≤ 0 never touch.
    clr : ndarray, shape (n, z_p)
        Initial clearance Δ_i (eq 32) [mm].
    T_c : float
        Torque on the disc [N·mm].
    r_c : float
        Cycloid pitch radius a z_c [mm].
    A, B : float
        Compliance constants: δ_max(F) = A F (2/3 + ln(B/F)) [mm/N, N].
    F_start : float or ndarray
        Start value(s) of F_max [N] (seed the bracket only).
    rtol : float
        Relative width of the final bracket [-].
    max_iter : int
        Iterations allowed after bracketing.

    Returns
    -------
    F_max : ndarray, shape (n,)
        The fixed point [N].
    n_eval : ndarray, shape (n,)
        Residual evaluations used.
    """
    lr, clr, F0 = _prep(lr, clr, T_c, r_c, A, B, F_start)
    Fcap = compliance_limit(B)
    out = np.empty(lr.shape[0])
    nev = np.zeros(lr.shape[0], dtype=np.int64)

    def residual(F: float, k: int) -> float:
        d = A * F * (2.0 / 3.0 + math.log(B / F))  # eq 38
        total = 0.0
        for i in range(lr.shape[1]):  # eq 41-43, pin by pin
            if lr[k, i] > 0.0 and lr[k, i] * d > clr[k, i]:
                total += (lr[k, i] * d - clr[k, i]) * lr[k, i]
        return F / d * total * r_c - T_c

    for k in range(lr.shape[0]):
        lo = hi = float(F0[k])
        n = 1
        if residual(lo, k) < 0.0:
            while residual(hi, k) < 0.0:
                lo, hi = hi, min(2.0 * hi, Fcap)
                n += 1
                if hi >= Fcap and residual(hi, k) < 0.0:
                    _raise(_LIMIT, k, hi, n, rtol, T_c, Fcap)
        else:
            while residual(lo, k) >= 0.0:
                hi, lo = lo, 0.5 * lo
                n += 1
        it = 0
        while hi - lo > rtol * hi:
            it += 1
            if it > max_iter:
                _raise(_NO_CONV, k, 0.5 * (lo + hi), n, rtol, T_c, Fcap)
            mid = 0.5 * (lo + hi)
            n += 1
            if residual(mid, k) < 0.0:
                lo = mid
            else:
                hi = mid
        out[k] = 0.5 * (lo + hi)
        nev[k] = n
    return out, nev
