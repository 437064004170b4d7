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
the start value. A Newton iteration with its analytic derivative, safeguarded by bisection inside
the bracket (0, compliance limit) that every evaluation narrows, converges in typically 4–6
evaluations from the paper's start (eq 45) and 2–3 from a neighbouring mesh position's answer,
where the plain Picard iteration of eq 44 that the paper uses oscillates (its Table 4).

Two implementations behind one API (``implementation="numba"`` or ``"plain"``):
:func:`solve_load_sharing` compiled (many mesh positions at once) or its plain twin (a flat
per-pin Python loop with bisection, the readable reference the compiled one is tested against).

Pins each on their own law (Hu 2020 eq 37, 42 / Li 2023 eq 3–4): every pin i has its own
log-law coefficients ``δ_i(F) = F (a0_i − a1_i ln F)`` (the form of every law of
:mod:`gearte.models.contact_law`), compatibility ``δ_i = l_i Δφ − c_i`` and equilibrium
``Σ F_i l_i = T``. :func:`solve_rotation` finds the disc rotation Δφ: T(Δφ) is increasing and
convex (each F(δ) is the inverse of a concave increasing δ(F)), so a safeguarded Newton iteration
(dT/dΔφ = Σ k_t l², bisection whenever a step leaves the bracket, doubling while no upper end is
known) converges from any start. Each evaluation inverts every loaded pin's law
(:func:`log_law_force`: Newton on u = ln F inside the bracket (ln δ − 60, a0/a1 − 1)), started
from that pin's ln F of the previous evaluation; over a sweep of mesh positions the compiled
kernel starts each position from the previous one's rotation and forces. Their plain twins
(``implementation="plain"``) are numpy, vectorised over positions.
"""

from __future__ import annotations

import math

import numpy as np

from gearte._jit import inner_kernel, kernel
from gearte.errors import ConvergenceError, ParameterError

__all__ = [
    "solve_load_sharing",
    "compliance_limit",
    "check_status",
    "log_law_force",
    "solve_rotation",
    "check_torque_balance",
]
# the plain twins, by name (tests and the models' ``implementation="plain"`` paths):
# solve_load_sharing_plain, log_law_force_plain, solve_rotation_plain

_OK, _NO_CONV, _NO_BRACKET, _LIMIT = 0, 1, 2, 3


def compliance_limit(B: float) -> float:
    """Largest load [N] for which δ_max(F) = A F (2/3 + ln(B/F)) still increases with F."""
    return B * math.exp(-1.0 / 3.0)


@inner_kernel
def _delta(F, A, B):  # pragma: no cover - compiled
    return A * F * (2.0 / 3.0 + math.log(B / F))


@inner_kernel
def _resid(F, lr, clr, T_c, r_c, A, B):  # pragma: no cover - compiled
    """g(F) and dg/dF: g = r_c (F/δ) Σ max(lr_i δ − Δ_i, 0) lr_i − T_c with δ = δ_max(F)."""
    lbf = math.log(B / F)
    d = A * F * (2.0 / 3.0 + lbf)
    dd = A * (lbf - 1.0 / 3.0)  # dδ/dF
    s = 0.0
    s1 = 0.0
    for i in range(lr.shape[0]):
        if lr[i] > 0.0:
            e = lr[i] * d - clr[i]
            if e > 0.0:
                s += e * lr[i]
                s1 += lr[i] * lr[i]
    g = F / d * s * r_c - T_c
    dg = r_c * ((d - F * dd) / (d * d) * s + F / d * s1 * dd)
    return g, dg


@inner_kernel
def _solve_one(lr, clr, T_c, r_c, A, B, F0, rtol, max_iter):  # pragma: no cover - compiled
    """Safeguarded Newton on g(F) = 0 inside (lo, hi), hi = the compliance limit until a
    point with g ≥ 0 is met; a step leaving the bracket is replaced by bisection."""
    Fcap = B * math.exp(-1.0 / 3.0)
    lo = 0.0
    hi = Fcap
    cap_checked = False
    F = F0
    n_eval = 0
    for _ in range(max_iter):
        g, dg = _resid(F, lr, clr, T_c, r_c, A, B)
        n_eval += 1
        if g == 0.0:
            return F, n_eval, _OK
        if g < 0.0:
            lo = F
        else:
            hi = F
            cap_checked = True
        new = F - g / dg if dg > 0.0 else math.nan
        if not (lo < new < hi):
            if not cap_checked:
                # the step leaves the law's range: is there a root below the limit at all?
                gc, _ = _resid(Fcap, lr, clr, T_c, r_c, A, B)
                n_eval += 1
                if gc < 0.0:
                    return Fcap, n_eval, _LIMIT
                cap_checked = True
            new = 0.5 * (lo + hi)
        if abs(new - F) <= rtol * new:
            return new, n_eval, _OK
        F = new
    return F, n_eval, _NO_CONV


@kernel
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
    implementation: str = "numba",
) -> tuple[np.ndarray, np.ndarray]:
    """Solve eq 44 for F_max at many mesh positions.

    ``implementation="numba"``: safeguarded Newton (module docstring), all positions in one
    compiled call; ``"plain"``: the twin, per-pin Python loops and bisection to a bracket of
    relative width ``rtol``.

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
        Start value(s) of F_max [N]; the answer does not depend on it beyond ``rtol``.
    rtol : float
        Relative size of the last Newton step [-].
    max_iter : int
        Newton/bisection steps allowed per position.
    implementation : {"numba", "plain"}
        The compiled kernel or its plain twin (the readable reference it is tested against).

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
    if implementation not in ("numba", "plain"):
        raise ParameterError("implementation", implementation, "must be 'numba' or 'plain'")
    if implementation == "plain":
        return _solve_load_sharing_plain(lr, clr, T_c, r_c, A, B, F_start, rtol, max_iter)
    lr, clr, F0 = _prep(lr, clr, T_c, r_c, A, B, F_start)
    F, nit, status = _solve_batch(
        lr, clr, float(T_c), float(r_c), float(A), float(B), F0, float(rtol), int(max_iter)
    )
    check_status(status, F, nit, rtol=rtol, T_c=T_c, B=B)
    return F, nit


def check_status(
    status: np.ndarray, F: np.ndarray, n_eval: np.ndarray, *, rtol: float, T_c: float, B: float
) -> None:
    """Raise for the first mesh position whose load-sharing solve failed (compiled kernels).

    Parameters
    ----------
    status : ndarray (n,)
        Status per position [-]: 0 converged, 1 not converged, 2 no sign change, 3 beyond the
        compliance law's range.
    F : ndarray (n,)
        Last F_max per position [N].
    n_eval : ndarray (n,)
        Residual evaluations per position [-].
    rtol : float
        Relative tolerance that was asked [-].
    T_c : float
        Torque on the disc [N·mm].
    B : float
        Compliance constant B [N] (its limit B e^(-1/3) is quoted).

    Raises
    ------
    ParameterError
        The load lies beyond the compliance law's range.
    ConvergenceError
        A position did not converge.
    """
    status = np.asarray(status)
    if not status.any():  # _OK == 0 everywhere
        return
    bad = np.nonzero(status != _OK)[0]
    if bad.size:
        k = int(bad[0])
        _raise(int(status[k]), k, float(F[k]), int(n_eval[k]), rtol, T_c, compliance_limit(B))


def solve_load_sharing_plain(
    lr: np.ndarray, clr: np.ndarray, **kw
) -> tuple[np.ndarray, np.ndarray]:
    """:func:`solve_load_sharing` with ``implementation="plain"`` (the readable twin)."""
    return solve_load_sharing(lr, clr, implementation="plain", **kw)


def _solve_load_sharing_plain(lr, clr, T_c, r_c, A, B, F_start, rtol, max_iter):
    """Per-pin Python loops and bisection: the flat, readable reference of eq 41–44."""
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


# --- pins each on their own log law: inverse of the law and the disc rotation ----------------

_U_SPAN = 60.0  # lower end of the ln F bracket: ln δ − 60 (F below δ e^-60 / a1 is never met)


@inner_kernel
def _log_force(delta, a0, a1, u0, rtol):  # pragma: no cover - compiled
    """(F, ln F) with δ = F (a0 − a1 ln F) on its increasing branch; (0, nan) for δ ≤ 0,
    (inf, inf) at or beyond δ* = a1 exp(a0/a1 − 1), (nan, nan) if Newton did not converge.
    ``u0``: start value of ln F (nan or outside the bracket: the fixed-point start)."""
    if not delta > 0.0:
        return 0.0, np.nan
    hi = a0 / a1 - 1.0
    if delta >= a1 * math.exp(hi):
        return math.inf, math.inf
    ld = math.log(delta)
    lo = ld - _U_SPAN
    u = u0
    if not (lo < u < hi):
        # the fixed point of the slowly varying log, kept inside the bracket
        u = ld - math.log(max(a0 - a1 * (ld - math.log(a0)), a1))
        u = min(max(u, lo), hi)
        if u != u:
            u = 0.5 * (lo + hi)
    for _ in range(100):
        f = math.exp(u)
        g = a0 - a1 * u
        r = f * g - delta
        if r < 0.0:
            lo = u
        elif r > 0.0:
            hi = u
        dr = f * (g - a1)
        un = u - r / dr if dr > 0.0 else math.nan
        if lo < un < hi:
            du = un - u
            if du * du <= rtol:
                # Newton converges quadratically: the error left after a step du is about
                # du²/2 · (g − 2 a1)/(g − a1) ≈ du²/2 (g ≫ a1 on the increasing branch)
                return math.exp(un), un
        else:
            un = 0.5 * (lo + hi)
            du = un - u
            if abs(du) <= rtol:
                return math.exp(un), un
        u = un
    return math.nan, math.nan


@kernel
def _log_force_flat(delta, a0, a1, rtol):  # pragma: no cover - compiled
    out = np.empty(delta.shape[0])
    for i in range(delta.shape[0]):
        out[i] = _log_force(delta[i], a0[i], a1[i], np.nan, rtol)[0]
    return out


def log_law_force(
    delta: np.ndarray,
    a0: np.ndarray,
    a1: np.ndarray,
    *,
    rtol: float = 1e-12,
    implementation: str = "numba",
) -> np.ndarray:
    """Inverse of the log law ``δ = F (a0 − a1 ln F)``: the force F [N] for an approach δ [mm].

    Safeguarded Newton on u = ln F inside (ln δ − 60, a0/a1 − 1), compiled (``"numba"``, one
    element at a time, stopping when the step is below √rtol: quadratic convergence leaves an
    error of about step²/2) or the numpy twin (``"plain"``, vectorised, stopping when every step
    is below rtol). δ ≤ 0 gives 0; at or beyond
    δ* = a1 exp(a0/a1 − 1), where δ(F) stops increasing, ``inf`` (callers report the load as out
    of the law's range).

    Parameters
    ----------
    delta : ndarray
        Approach δ [mm].
    a0, a1 : ndarray
        Law coefficients [mm/N] (:func:`gearte.models.contact_law.log_law_coefficients`),
        broadcast against ``delta``.
    rtol : float
        Tolerance on ln F, i.e. relative on F [-].
    implementation : {"numba", "plain"}
        The compiled kernel or its plain twin (the readable reference it is tested against).

    Returns
    -------
    numpy.ndarray
        F [N], the broadcast shape.

    Raises
    ------
    ConvergenceError
        Newton did not converge in 100 iterations.
    """
    if implementation not in ("numba", "plain"):
        raise ParameterError("implementation", implementation, "must be 'numba' or 'plain'")
    if implementation == "plain":
        return _log_law_force_plain(delta, a0, a1, rtol)
    d, b0, b1 = np.broadcast_arrays(
        np.asarray(delta, dtype=float), np.asarray(a0, dtype=float), np.asarray(a1, dtype=float)
    )
    flat = [np.ascontiguousarray(x, dtype=float).reshape(-1) for x in (d, b0, b1)]
    out = _log_force_flat(flat[0], flat[1], flat[2], float(rtol)).reshape(d.shape)
    if np.any(np.isnan(out) & ~np.isnan(d)):
        raise ConvergenceError(
            f"contact_law.force: Newton did not converge in 100 iterations "
            f"(tolerance {rtol:g} relative)"
        )
    return out


def log_law_force_plain(delta: np.ndarray, a0: np.ndarray, a1: np.ndarray, **kw) -> np.ndarray:
    """:func:`log_law_force` with ``implementation="plain"`` (the numpy twin)."""
    return log_law_force(delta, a0, a1, implementation="plain", **kw)


def _log_law_force_plain(delta, a0, a1, rtol):
    """The inverse vectorised in numpy (every element iterates until all steps are ≤ rtol)."""
    d = np.asarray(delta, dtype=float)
    d, a0, a1 = np.broadcast_arrays(d, np.asarray(a0, dtype=float), np.asarray(a1, dtype=float))
    out = np.zeros(d.shape)
    pos = d > 0
    if not np.any(pos):
        return out
    dd, b0, b1 = d[pos], a0[pos], a1[pos]
    u_star = b0 / b1 - 1.0
    beyond = dd >= b1 * np.exp(u_star)
    res = np.full(dd.shape, np.inf)
    ok = ~beyond
    if np.any(ok):
        dd, b0, b1, hi = dd[ok], b0[ok], b1[ok], u_star[ok]
        lo = np.log(dd) - _U_SPAN
        # start from the fixed point of the slowly varying log, kept inside the bracket
        u = np.clip(np.log(dd) - np.log(np.maximum(b0 - b1 * np.log(dd / b0), b1)), lo, hi)
        r = np.zeros_like(u)
        for _ in range(100):
            f = np.exp(u)
            r = f * (b0 - b1 * u) - dd
            lo = np.where(r < 0.0, u, lo)
            hi = np.where(r > 0.0, u, hi)
            dr = f * (b0 - b1 * u - b1)
            step = np.where(dr > 0.0, r / np.where(dr > 0.0, dr, 1.0), np.inf)
            u_new = u - step
            bad = ~((u_new > lo) & (u_new < hi))
            u_new = np.where(bad, 0.5 * (lo + hi), u_new)
            if np.all(np.abs(u_new - u) <= rtol):
                u = u_new
                break
            u = u_new
        else:
            raise ConvergenceError(
                f"contact_law.force: Newton did not converge in 100 iterations (max residual "
                f"{np.max(np.abs(r)):.3g} mm, tolerance {rtol:g} relative)"
            )
        res[ok] = np.exp(u)
    out[pos] = res
    return out


@inner_kernel
def _torque_at(rot, arm, clr, a0, a1, u, f, frtol):  # pragma: no cover - compiled
    """T(Δφ) = Σ F_i l_i and dT/dΔφ = Σ k_t,i l_i²; fills f (forces) and u (ln F, warm start)."""
    t = 0.0
    slope = 0.0
    for i in range(arm.shape[0]):
        li = arm[i]
        if li > 0.0:
            fi, ui = _log_force(li * rot - clr[i], a0[i], a1[i], u[i], frtol)
            f[i] = fi
            u[i] = ui
            if fi > 0.0:
                t += fi * li
                if fi < math.inf:
                    slope += li * li / (a0[i] - a1[i] * ui - a1[i])
        else:
            f[i] = 0.0
    return t, slope


@inner_kernel
def _rotation_one(arm, clr, a0, a1, T, rot, u, f, rtol, frtol, max_iter):  # pragma: no cover
    """Disc rotation carrying T at one position: (Δφ, evaluations, status); forces into f."""
    if not rot > 0.0:
        rot = 1e-6
    lo = 0.0
    hi = math.inf
    n = 0
    for _ in range(max_iter):
        t, slope = _torque_at(rot, arm, clr, a0, a1, u, f, frtol)
        n += 1
        if t != t:
            return rot, n, _NO_CONV
        if t == T:
            return rot, n, _OK
        if t > T:
            hi = rot
        else:
            lo = rot
        new = rot - (t - T) / slope if slope > 0.0 else math.nan
        if not (lo < new < hi):
            new = 2.0 * rot if hi == math.inf else 0.5 * (lo + hi)
        if abs(new - rot) <= rtol * new or (hi < math.inf and hi - lo <= rtol * hi):
            # rot is within rtol of the root (the step, or the bracket, says so) and the
            # forces in f are those at rot: answer rot, no further evaluation
            return rot, n, _OK
        rot = new
    return rot, n, _NO_CONV


@kernel
def _rotation_batch(arm, clr, a0, a1, T, rot0, rtol, frtol, max_iter):  # pragma: no cover
    n, z = arm.shape
    rot = np.empty(n)
    force = np.empty((n, z))
    nev = np.empty(n, dtype=np.int64)
    status = np.empty(n, dtype=np.int64)
    u = np.full(z, np.nan)
    prev = 1e-6
    for k in range(n):
        start = rot0[k] if rot0[k] > 0.0 else prev
        rk, nk, sk = _rotation_one(
            arm[k], clr[k], a0[k], a1[k], T, start, u, force[k], rtol, frtol, max_iter
        )
        rot[k] = rk
        nev[k] = nk
        status[k] = sk
        if sk == _OK:
            prev = rk
    return rot, force, nev, status


def _rotation_inputs(arm, clearance, a0, a1, torque):
    if not (math.isfinite(torque) and torque > 0.0):
        raise ParameterError("torque", torque, "must be finite and > 0 [N·mm]")
    # fresh writeable C arrays: a read-only one (np.broadcast_to of an array of that shape is
    # a read-only view, which ascontiguousarray keeps) compiles _rotation_batch, _rotation_one
    # and _torque_at a second time beside the cycloid line-contact kernel's writeable arrays
    # (~1 s CPU on the first run of a case with both, docs/numba.md)
    arm = np.require(np.atleast_2d(np.asarray(arm, dtype=float)), float, ["C", "W"])
    shape = arm.shape
    clearance, a0, a1 = (
        np.require(np.broadcast_to(np.asarray(x, dtype=float), shape), float, ["C", "W"])
        for x in (clearance, a0, a1)
    )
    return arm, clearance, a0, a1


#: Largest relative torque imbalance of a solved rotation [-] (see :func:`check_torque_balance`).
_BALANCE_RTOL = 1e-6


def _beyond_the_law(torque: float) -> ParameterError:
    return ParameterError(
        "torque",
        torque,
        "[N·mm] loads a pin beyond the range of the elastic contact law (its approach δ(F) "
        "stops increasing); the stage is far too small for this torque",
    )


def solve_rotation(
    arm: np.ndarray,
    clearance: np.ndarray,
    a0: np.ndarray,
    a1: np.ndarray,
    torque: float,
    *,
    rtol: float = 1e-11,
    rot_start: float | np.ndarray | None = None,
    force_rtol: float = 1e-12,
    max_iter: int = 200,
    implementation: str = "numba",
    power: tuple[np.ndarray, np.ndarray] | None = None,
) -> tuple[np.ndarray, np.ndarray]:
    """Disc rotation and pin forces that carry ``torque`` (compatibility + equilibrium).

    Pin i is compressed by ``δ_i = l_i Δφ − c_i`` and carries ``F_i = F(δ_i)`` of the log law
    ``δ = F (a0_i − a1_i ln F)`` with its own coefficients; ``Σ F_i l_i = T``. Safeguarded
    Newton on T(Δφ) (dT/dΔφ = Σ k_t l², bisection when a step leaves the bracket).
    ``"numba"``: positions in order, each started from the previous one's answer, every pin's
    force from its previous ln F (module docstring); the answer is the last evaluated rotation,
    once the Newton step or the bracket is below ``rtol``. ``"plain"``: the numpy twin, all
    positions at once, the bracket found by doubling from ``rot_start``, every pin's law
    inverted from scratch at each step.

    Parameters
    ----------
    arm : ndarray (n, z)
        Arm l_i of each pin's contact normal [mm]; ≤ 0 for pins that cannot carry load.
    clearance : ndarray (n, z)
        Normal clearance c_i at Δφ = 0 [mm] (finite where the arm is > 0), ≥ 0.
    a0, a1 : ndarray (n, z)
        Log-law coefficients of each pin [mm/N].
    torque : float
        Torque T [N·mm], > 0.
    rtol : float
        Relative tolerance on Δφ [-].
    rot_start : float or ndarray (n,), optional
        Start value(s) of Δφ [rad]; default: 1e-6 for the first position, then (``"numba"``)
        the previous position's answer. The answer does not depend on it beyond ``rtol``.
    force_rtol : float
        Relative tolerance of each pin's force [-].
    max_iter : int
        Newton/bisection steps allowed per position.
    implementation : {"numba", "plain"}
        The compiled kernel or its plain twin (the readable reference it is tested against).
    power : (ndarray, ndarray), optional
        ``(a2, a3)`` [mm/N^a3, -]: the pins follow the power law ``δ = a0 F + a2 F^a3``
        instead (Palmgren's line contact, ``gearte.models.contact_law.law_coefficients``, with a
        linear compliance ``a0`` in series, e.g. the pin seat; ``a1`` must then be 0), inverted
        in closed form where ``a0 = 0`` (``F = (δ/a2)^(1/a3)``), else by Newton's method
        (:func:`power_law_force`); solved by the plain implementation.

    Returns
    -------
    rotation : ndarray (n,)
        Δφ [rad].
    force : ndarray (n, z)
        F_i [N].

    Raises
    ------
    ParameterError
        A pin would be loaded beyond the range of the law (δ(F) no longer increasing).
    ConvergenceError
        Not converged within ``max_iter`` steps.

    References
    ----------
    Li et al. (2023) eq 3–4, doi:10.3390/machines11060626; Hu et al. (2020) eq 37–44,
    doi:10.3390/app10020481.
    """
    if implementation not in ("numba", "plain"):
        raise ParameterError("implementation", implementation, "must be 'numba' or 'plain'")
    arm, clearance, a0, a1 = _rotation_inputs(arm, clearance, a0, a1, torque)
    if power is not None:
        if np.any(a1 != 0.0) or np.any(a0 < 0.0):
            raise ParameterError(
                "a0/a1", (a0, a1), "a power law (power=) takes a1 = 0 and a linear a0 >= 0"
            )
        a2, a3 = (np.broadcast_to(np.asarray(x, dtype=float), arm.shape) for x in power)
        if not (np.all(a2 > 0.0) and np.all((a3 > 0.0) & (a3 <= 1.0))):
            raise ParameterError("power", power, "needs a2 > 0 and 0 < a3 <= 1")
        rot, force = _solve_rotation_plain(
            arm, clearance, a0, a1, torque, rtol, rot_start, force_rtol, max_iter, (a2, a3)
        )
    elif implementation == "plain":
        rot, force = _solve_rotation_plain(
            arm, clearance, a0, a1, torque, rtol, rot_start, force_rtol, max_iter
        )
    else:
        rot, force = _solve_rotation_compiled(
            arm, clearance, a0, a1, torque, rtol, rot_start, force_rtol, max_iter
        )
    check_torque_balance(np.sum(force * np.where(arm > 0.0, arm, 0.0), axis=1), torque, rtol)
    return rot, force


def power_law_force(
    delta: np.ndarray, a0: np.ndarray, a2: np.ndarray, a3: np.ndarray, *, rtol: float = 1e-12
) -> np.ndarray:
    """Inverse of ``δ = a0 F + a2 F^a3`` (a power law with a linear compliance ``a0 ≥ 0`` in
    series): the force F [N] for an approach δ [mm]; δ ≤ 0 → 0.

    With ``a0 = 0`` the closed form ``F = (δ/a2)^(1/a3)``. Otherwise Newton's method from the
    lower bound ``min(δ/(2 a0), (δ/(2 a2))^(1/a3))`` (at the root one of the two terms is at
    least δ/2): g(F) = a0 F + a2 F^a3 − δ is increasing and concave for 0 < a3 ≤ 1, so every
    Newton step from below stays below the root and the iteration increases monotonically to it.

    Parameters
    ----------
    delta : ndarray
        Approach [mm].
    a0 : ndarray
        Linear compliance in series [mm/N], ≥ 0.
    a2, a3 : ndarray
        Power law ``δ = a2 F^a3`` [mm/N^a3, -], a2 > 0, 0 < a3 ≤ 1.
    rtol : float
        Relative tolerance on F [-].

    Raises
    ------
    ConvergenceError
        Not converged in 100 steps.
    """
    d = np.maximum(np.asarray(delta, dtype=float), 0.0)
    a0, a2, a3 = (np.broadcast_to(np.asarray(x, dtype=float), d.shape) for x in (a0, a2, a3))
    if not np.any(a0 > 0.0):
        return (d / a2) ** (1.0 / a3)
    with np.errstate(divide="ignore"):
        lo_linear = np.where(a0 > 0.0, d / np.where(a0 > 0.0, 2.0 * a0, 1.0), np.inf)
    f = np.minimum(lo_linear, (d / (2.0 * a2)) ** (1.0 / a3))
    for _ in range(100):
        fp = np.where(f > 0.0, f, 1.0)
        g = a0 * f + a2 * f**a3 - d
        step = np.where(f > 0.0, g / (a0 + a3 * a2 * fp ** (a3 - 1.0)), 0.0)
        f = f - step
        if np.all(np.abs(step) <= rtol * np.maximum(f, 1e-300)):
            return f
    raise ConvergenceError("power_law_force: Newton did not converge in 100 steps")


def check_torque_balance(carried: np.ndarray, torque: float, rtol: float) -> None:
    """Raise the out-of-range :class:`ParameterError` (naming ``"torque"``) when the pins'
    torque ``carried`` = Σ F_i l_i of a solved position falls short of ``torque``.

    The rotation solvers stop when the rotation's bracket is narrower than ``rtol``; when the
    torque exceeds what the law can carry (a pin reaches the end of its range, δ(F) stops
    increasing and F jumps to inf), the bracket closes on that edge instead of on a root and the
    last finite state balances only part of the torque (found at × 1e9 of a bundled torque:
    5 % – 1e-7 of it). A solved position balances it to about ``rtol``.

    Parameters
    ----------
    carried : ndarray (n,)
        Σ F_i l_i of each position [N·mm].
    torque : float
        The torque to carry [N·mm].
    rtol : float
        The solver's relative tolerance on the rotation [-]; the balance may be off by
        ``max(1e-6, 10 rtol)``.

    Raises
    ------
    ParameterError
        Naming ``torque``: it loads a pin beyond the range of the law.
    """
    if np.any(np.abs(np.asarray(carried) - torque) > max(_BALANCE_RTOL, 10.0 * rtol) * torque):
        raise _beyond_the_law(torque)


def _solve_rotation_compiled(arm, clearance, a0, a1, torque, rtol, rot_start, force_rtol, max_iter):
    """The compiled kernel over the positions in order (:func:`_rotation_batch`)."""
    n = arm.shape[0]
    rot0 = np.full(n, np.nan) if rot_start is None else np.broadcast_to(rot_start, (n,))
    rot, force, nev, status = _rotation_batch(
        arm,
        clearance,
        a0,
        a1,
        float(torque),
        np.require(rot0, float, ["C", "W"]),
        float(rtol),
        float(force_rtol),
        int(max_iter),
    )
    bad = np.nonzero(status != _OK)[0]
    if bad.size:
        k = int(bad[0])
        raise ConvergenceError(
            f"solve_rotation: Newton/bisection stopped after {int(nev[k])} evaluations at "
            f"position {k} (tolerance {rtol:g})"
        )
    if not np.all(np.isfinite(force)):
        raise _beyond_the_law(torque)
    return rot, force


def solve_rotation_plain(
    arm: np.ndarray, clearance: np.ndarray, a0: np.ndarray, a1: np.ndarray, torque: float, **kw
) -> tuple[np.ndarray, np.ndarray]:
    """:func:`solve_rotation` with ``implementation="plain"`` (the numpy twin)."""
    return solve_rotation(arm, clearance, a0, a1, torque, implementation="plain", **kw)


def _solve_rotation_plain(arm, clearance, a0, a1, torque, rtol, rot_start, force_rtol, max_iter,
                          power=None):  # fmt: skip
    """All positions at once in numpy: bracket by doubling, then safeguarded Newton
    (``power``: ``(a2, a3)`` of the power law ``δ = a2 F^a3`` instead of the log law)."""
    n = arm.shape[0]
    loaded = arm > 0.0
    la = np.where(loaded, arm, 0.0)

    def torque_at(rot: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        delta = np.where(loaded, rot[:, None] * la - clearance, 0.0)
        if power is None:
            f = _log_law_force_plain(delta, a0, a1, force_rtol)
        else:
            f = power_law_force(delta, a0, power[0], power[1], rtol=force_rtol)
        return np.sum(f * la, axis=1), f

    def tangent(f: np.ndarray) -> np.ndarray:
        pos = f > 0.0
        fp = np.where(pos, f, 1.0)
        if power is None:
            return np.where(pos, 1.0 / (a0 - a1 * np.log(fp) - a1), 0.0)
        return np.where(pos, 1.0 / (a0 + power[1] * power[0] * fp ** (power[1] - 1.0)), 0.0)

    lo = np.zeros(n)
    hi = np.full(n, 1e-6) if rot_start is None else np.broadcast_to(rot_start, (n,)).copy()
    for _ in range(200):
        t_hi, _ = torque_at(hi)
        short = t_hi < torque
        if not np.any(short):
            break
        lo = np.where(short, hi, lo)
        hi = np.where(short, hi * 2.0, hi)
    else:  # pragma: no cover - only for absurd loads
        raise ConvergenceError("solve_rotation: could not bracket the elastic rotation")
    rot = 0.5 * (lo + hi)
    for it in range(max_iter):  # noqa: B007 - reported on failure
        t_mid, f = torque_at(rot)
        above = t_mid > torque
        hi = np.where(above, rot, hi)
        lo = np.where(above, lo, rot)
        with np.errstate(divide="ignore", invalid="ignore"):
            kt = tangent(f)
        slope = np.sum(kt * la * la, axis=1)
        step = np.where(slope > 0.0, (t_mid - torque) / np.where(slope > 0.0, slope, 1.0), 0.0)
        new = rot - step
        new = np.where((slope > 0.0) & (new > lo) & (new < hi), new, 0.5 * (lo + hi))
        done = np.abs(new - rot) <= rtol * np.abs(new)
        rot = new
        if np.all(done) or np.all(hi - lo <= rtol * hi):
            break
    else:  # pragma: no cover
        raise ConvergenceError(
            f"solve_rotation: Newton/bisection stopped after {it + 1} iterations "
            f"(bracket {np.max((hi - lo) / hi):.3g} relative, tolerance {rtol:g})"
        )
    force = torque_at(rot)[1]
    if not np.all(np.isfinite(force)):
        raise _beyond_the_law(torque)
    return rot, force
