"""Batched quasi-static equilibrium: many reducers × many (position, torque) steps in one call.

The same problem and the same algorithm as :mod:`gearte.solvers.rv_equilibrium` — minimise, at
each step, ``Π(q) = ½ Σ_s k_s (B_s q + e_s)² + ½ Σ_c k_c max(B_c q − g_c, 0)² − T uᵀ q`` plus the
clearance bearings' dead band, by the active-set (semismooth) Newton method with a backtracking
line search inside the contact-stiffness secant fixed point — for ``S`` samples (assembled
reducers that differ only in their manufacturing errors, i.e. in the offsets ``e`` and the
clearances ``g``) in one compiled loop:

* the rows ``B`` depend on the geometry and the output angle only, not on the errors: they are
  shared by every sample and stored sparse (each row touches few degrees of freedom — a pin
  contact three, a bearing six), so a Newton step costs ``O(rows · width²)``, not
  ``O(rows · dofs²)``;
* the linear springs enter through ``K0 = Σ k B Bᵀ`` (one per geometry, shared) and
  ``f0 = T u − h`` with ``h = Σ k e B`` per sample and geometry;
* a sample's *steps* are ``(geometry, torque)`` pairs solved in order, each warm-started from the
  previous one (displacements and contact stiffness), except where ``cold`` marks the start of a
  new sequence (zero displacements, the law's start stiffness) — exactly how
  :func:`~gearte.solvers.rv_equilibrium.solve_positions` follows positions or torques;
* the Newton system is solved by a Cholesky factorisation written out (the Hessian is symmetric
  positive definite: ``K0`` plus positive contact and bearing terms plus a 1e-13 regularisation),
  falling back to LU where a pivot is not positive.

The kernel is ``@njit(cache=True, nogil=True)``, so chunks of samples run in parallel threads;
``compiled=False`` runs its plain-Python twin (tests). Its results equal the per-case solver's
to round-off (a test checks 1e-9 on sampled reducers).
"""

from __future__ import annotations

import threading
from dataclasses import dataclass

import numpy as np
from numba import njit

from gearte.errors import ConvergenceError, ParameterError
from gearte.solvers.rv_equilibrium import (
    CLEARANCE_RESIDUAL,
    LAW_LINEAR,
    LAW_SECANT_PER_CONTACT,
    LAW_SECANT_PER_DISC,
    _bearing_terms,
    _law_delta,
)

__all__ = [
    "SparseRows",
    "sparse_rows",
    "BatchProblem",
    "BatchSolution",
    "problem_from_system",
    "solve_batch",
]

_TWIN_LOCK = threading.Lock()


@dataclass(frozen=True)
class SparseRows:
    """Rows ``B[g, r, :]`` stored by their non-zero columns.

    ``index`` (R, W) column of each stored entry (padding repeats a column with value 0);
    ``value`` (G, R, W) the entries per geometry ``g``.
    """

    index: np.ndarray
    value: np.ndarray


def sparse_rows(B: np.ndarray, *, pairs: bool = False) -> SparseRows:
    """Compress dense rows to the columns non-zero at any geometry.

    Parameters
    ----------
    B : numpy.ndarray
        Rows (G, R, nd) [-, mm per rad for rotations].
    pairs : bool
        Rows ``2m`` and ``2m + 1`` (the x and y rows of one bearing) get the same columns.
    """
    B = np.asarray(B, dtype=float)
    G, R, nd = B.shape
    nz = np.any(B != 0.0, axis=0)  # (R, nd)
    if pairs:
        if R % 2:
            raise ParameterError("rows", R, "pairs=True needs an even number of rows")
        both = nz[0::2] | nz[1::2]
        nz = np.repeat(both, 2, axis=0)
    W = max(1, int(nz.sum(axis=1).max(initial=0)))
    index = np.zeros((R, W), dtype=np.int64)
    value = np.zeros((G, R, W))
    for r in range(R):
        cols = np.flatnonzero(nz[r])
        index[r, : cols.size] = cols
        if cols.size:
            index[r, cols.size :] = cols[0]
            value[:, r, : cols.size] = B[:, r, cols]
    return SparseRows(index, value)


@dataclass(frozen=True)
class BatchProblem:
    """What every sample of a batch shares.

    Attributes
    ----------
    K0 : (G, nd, nd) stiffness of the linear springs per geometry [N/mm, N·mm/rad …].
    unit_load : (nd,) generalised force of a unit output torque.
    contacts : SparseRows of the pin-contact rows (G, nc, ·).
    bearings : SparseRows of the clearance-bearing rows, x and y interleaved (G, 2 nm, ·).
    bearing_k, bearing_c : (nm,) stiffness [N/mm] and radial clearance [mm] of those bearings.
    group : (nc,) disc of each contact; law : solver law code
        (:data:`~gearte.solvers.rv_equilibrium.LAW_LINEAR` …); coef : (G, nc, 2) law
        coefficients (a0, a1) [mm/N]; start_stiffness : start (or constant) stiffness [N/mm].
    output : index of the output rotation in ``q``.
    """

    K0: np.ndarray
    unit_load: np.ndarray
    contacts: SparseRows
    bearings: SparseRows
    bearing_k: np.ndarray
    bearing_c: np.ndarray
    group: np.ndarray
    law: int
    coef: np.ndarray
    start_stiffness: float
    output: int

    @property
    def ngroups(self) -> int:
        return int(self.group.max()) + 1


def problem_from_system(system, law) -> tuple[BatchProblem, np.ndarray, np.ndarray, np.ndarray]:
    """The batch problem of an assembled system (its ``G`` positions are the geometries) and its
    own per-sample inputs ``(h, bearing offsets, gaps)`` of shape (1, G, …).

    Parameters
    ----------
    system : gearte.models.rv_load_sharing.RVSystem
    law : ContactLaw or a model-level law with ``for_system(system)``
    """
    from gearte.solvers.rv_equilibrium import _linear_parts, _split_springs, as_solver_law

    law = as_solver_law(law, system)
    lin, Bn, en0, kn, cn = _split_springs(system)
    G, nd = system.theta.size, system.layout.size
    K0, f0 = _linear_parts(
        system.spring_B[:, lin], system.spring_e[:, lin], system.spring_k[lin], np.zeros((G, nd))
    )
    nc = system.contact_gap.shape[1]
    problem = BatchProblem(
        K0=K0,
        unit_load=system.unit_load,
        contacts=sparse_rows(system.contact_B),
        bearings=sparse_rows(Bn.reshape(G, -1, nd), pairs=True),
        bearing_k=kn,
        bearing_c=cn,
        group=system.contact_group.astype(np.int64),
        law=law.code,
        coef=law.coefficients(G, nc),
        start_stiffness=law.stiffness,
        output=system.layout.output_rotation,
    )
    return problem, -f0[None], en0[None], system.contact_gap[None]


@dataclass(frozen=True)
class BatchSolution:
    """``output`` (S, K) output rotation at every step [rad]; ``forces`` (S, R, nc) contact forces
    at the recorded steps [N]; ``iterations`` (S, K) Newton iterations per step."""

    output: np.ndarray
    forces: np.ndarray
    iterations: np.ndarray


@njit(cache=True, nogil=True)
def _rows_dot(idx, val, q, r):
    s = 0.0
    for w in range(idx.shape[1]):
        s += val[r, w] * q[idx[r, w]]
    return s


@njit(cache=True, nogil=True)
def _energy_sp(K0, f0, nidx, nval, en, kn, cn, cidx, cval, gc, kc, q):
    nd = q.size
    e = 0.0
    for a in range(nd):
        t = 0.0
        for b in range(nd):
            t += K0[a, b] * q[b]
        e += (0.5 * t - f0[a]) * q[a]
    for c in range(gc.size):
        d = _rows_dot(cidx, cval, q, c) - gc[c]
        if d > 0.0:
            e += 0.5 * kc[c] * d * d
    for m in range(kn.size):
        wx = _rows_dot(nidx, nval, q, 2 * m) + en[m, 0]
        wy = _rows_dot(nidx, nval, q, 2 * m + 1) + en[m, 1]
        rr = wx * wx + wy * wy
        e += 0.5 * CLEARANCE_RESIDUAL * kn[m] * rr
        r = np.sqrt(rr) - cn[m]
        if r > 0.0:
            e += 0.5 * (1.0 - CLEARANCE_RESIDUAL) * kn[m] * r * r
    return e


@njit(cache=True, nogil=True)
def _spd_solve(H, b, L, x):
    """Solve ``H x = b`` for symmetric positive definite ``H`` (Cholesky into the work array
    ``L``, result in ``x``); LU where a pivot is not positive."""
    n = b.size
    for j in range(n):
        s = H[j, j]
        for k in range(j):
            s -= L[j, k] * L[j, k]
        if not s > 0.0:
            x[:] = np.linalg.solve(H, b)
            return
        d = np.sqrt(s)
        L[j, j] = d
        for i in range(j + 1, n):
            t = H[i, j]
            for k in range(j):
                t -= L[i, k] * L[j, k]
            L[i, j] = t / d
    for i in range(n):
        t = b[i]
        for k in range(i):
            t -= L[i, k] * x[k]
        x[i] = t / L[i, i]
    for i in range(n - 1, -1, -1):
        t = x[i]
        for k in range(i + 1, n):
            t -= L[k, i] * x[k]
        x[i] = t / L[i, i]


@njit(cache=True, nogil=True)
def _newton_sp(K0, reg, f0, nidx, nval, en, kn, cn, cidx, cval, gc, kc, q, tol, maxit):
    """:func:`gearte.solvers.rv_equilibrium._newton` on sparse rows (same steps and tests)."""
    nd = q.size
    nc = gc.size
    nm = kn.size
    Wc = cidx.shape[1]
    Wn = nidx.shape[1]
    active = np.zeros(nc, dtype=np.bool_)
    d = np.empty(nc)
    H = np.empty((nd, nd))
    L = np.empty((nd, nd))
    grad = np.empty(nd)
    dq = np.empty(nd)
    qn = np.empty(nd)
    for c in range(nc):
        d[c] = _rows_dot(cidx, cval, q, c) - gc[c]
        active[c] = d[c] > 0.0
    e0 = _energy_sp(K0, f0, nidx, nval, en, kn, cn, cidx, cval, gc, kc, q)
    for it in range(maxit):
        for a in range(nd):
            t = -f0[a]
            for b in range(nd):
                H[a, b] = K0[a, b]
                t += K0[a, b] * q[b]
            grad[a] = t
        for c in range(nc):
            if active[c]:
                w = kc[c] * d[c]
                for a in range(Wc):
                    ia = cidx[c, a]
                    grad[ia] += w * cval[c, a]
                    ba = kc[c] * cval[c, a]
                    for b in range(Wc):
                        H[ia, cidx[c, b]] += ba * cval[c, b]
        for m in range(nm):
            rx, ry = 2 * m, 2 * m + 1
            wx = _rows_dot(nidx, nval, q, rx) + en[m, 0]
            wy = _rows_dot(nidx, nval, q, ry) + en[m, 1]
            gx, gy, hxx, hyy, hxy = _bearing_terms(wx, wy, kn[m], cn[m])
            # x and y rows share one column pattern (both rows of the same bearing)
            for a in range(Wn):
                ia = nidx[rx, a]
                bx, by = nval[rx, a], nval[ry, a]
                grad[ia] += gx * bx + gy * by
                ta = hxx * bx + hxy * by
                tb = hxy * bx + hyy * by
                for b in range(Wn):
                    H[ia, nidx[rx, b]] += ta * nval[rx, b] + tb * nval[ry, b]
        for a in range(nd):
            H[a, a] += reg
        _spd_solve(H, grad, L, dq)
        for a in range(nd):
            dq[a] = -dq[a]
            qn[a] = q[a] + dq[a]
        step = 1.0
        decreased = False
        e1 = e0
        for _ in range(60):
            e1 = _energy_sp(K0, f0, nidx, nval, en, kn, cn, cidx, cval, gc, kc, qn)
            if e1 <= e0 + 1e-12 * abs(e0):
                decreased = True
                break
            step *= 0.5
            for a in range(nd):
                qn[a] = q[a] + step * dq[a]
        if not decreased:
            return q, it + 1, True
        stalled = e0 - e1 <= 1e-14 * abs(e0)
        q = qn.copy()
        e0 = e1
        same = True
        for c in range(nc):
            d[c] = _rows_dot(cidx, cval, q, c) - gc[c]
            a_new = d[c] > 0.0
            if a_new != active[c]:
                same = False
            active[c] = a_new
        big = 0.0
        for a in range(nd):
            big = max(big, abs(step * dq[a]))
        if big < tol or (same and step == 1.0 and nm == 0) or (same and stalled and it > 2):
            return q, it + 1, True
    return q, maxit, False


def law_limit(a0: np.ndarray, a1: np.ndarray) -> np.ndarray:
    """``F* = exp((a0 − a1)/a1)`` [N], where the log law's ``δ'(F)`` vanishes (its range ends);
    capped at ``exp(700)``."""
    return np.exp(np.minimum((a0 - a1) / a1, 700.0))


@njit(cache=True, nogil=True)
def _law_force(d, a0, a1, fstar, f_prev, d_prev):
    """Force ``F`` with ``δ(F) = F (a0 − a1 ln F) = d`` for an approach ``d > 0`` [N].

    δ is increasing and concave up to ``F* = exp((a0 − a1)/a1)`` (where δ' = 0; δ(F*) = a1 F*).
    Start: the tangent predictor from a known point ``(d_prev, f_prev)`` of the law (where
    ``f_prev > 0``; ``1/δ'(F) = 1/(d/F − a1)`` needs no logarithm), else a one-term estimate;
    then Newton until a relative step below 1e-8 (the error is then ~1e-17: quadratic
    convergence). ``fstar``: F* (:func:`law_limit`). Returns -1 when ``d ≥ a1 F*`` (beyond the
    law's range).
    """
    if d >= a1 * fstar:
        return -1.0
    F = -1.0
    if f_prev > 0.0 and d_prev > 0.0:
        slope = d_prev / f_prev - a1
        if slope > 0.0:
            F = f_prev + (d - d_prev) / slope
    if not (F > 0.0 and F < fstar):
        den = a0 - a1 * np.log(max(d / max(a0, a1), 1e-300))
        F = d / den if den > 0.0 else 0.5 * fstar
    for _ in range(100):
        lf = np.log(F)
        gp = a0 - a1 * lf - a1
        if not gp > 0.0:
            F = 0.5 * F
            continue
        Fn = F - (F * (a0 - a1 * lf) - d) / gp
        if not Fn > 0.0:
            Fn = 0.1 * F
        # quadratic convergence: after a relative step below 1e-8 the error is ~1e-17
        if abs(Fn - F) <= 1e-8 * F:
            return Fn
        F = Fn
    return F


@njit(cache=True, nogil=True)
def _energy_law(K0, f0, nidx, nval, en, kn, cn, cidx, cval, gc, coef, q, Fp, dp, F, d):
    """Π with the exact pin law; fills the approaches ``d`` and forces ``F`` (from the known
    pairs ``Fp``, ``dp``); +inf beyond the law's range.

    ``φ(d) = ∫F dd = F² (a0/2 − a1 ln F/2 − a1/4) = F d/2 − a1 F²/4`` (with ``a1 ln F =
    a0 − d/F`` on the law).
    """
    nd = q.size
    e = 0.0
    for a in range(nd):
        t = 0.0
        for b in range(nd):
            t += K0[a, b] * q[b]
        e += (0.5 * t - f0[a]) * q[a]
    for c in range(gc.size):
        d[c] = _rows_dot(cidx, cval, q, c) - gc[c]
        if d[c] > 0.0:
            f = _law_force(d[c], coef[c, 0], coef[c, 1], coef[c, 2], Fp[c], dp[c])
            if f < 0.0:
                return np.inf
            F[c] = f
            e += 0.5 * f * d[c] - 0.25 * coef[c, 1] * f * f
        else:
            F[c] = 0.0
    for m in range(kn.size):
        wx = _rows_dot(nidx, nval, q, 2 * m) + en[m, 0]
        wy = _rows_dot(nidx, nval, q, 2 * m + 1) + en[m, 1]
        rr = wx * wx + wy * wy
        e += 0.5 * CLEARANCE_RESIDUAL * kn[m] * rr
        r = np.sqrt(rr) - cn[m]
        if r > 0.0:
            e += 0.5 * (1.0 - CLEARANCE_RESIDUAL) * kn[m] * r * r
    return e


@njit(cache=True, nogil=True)
def _newton_law(K0, reg, f0, nidx, nval, en, kn, cn, cidx, cval, gc, coef, F, dprev, q, tol, maxit):
    """Newton on Π with the exact load-dependent pin law (tangent stiffness ``1/δ'(F)``).

    The fixed point of the per-contact secant iteration of
    :func:`gearte.solvers.rv_equilibrium._solve_position` is the root of this Π's gradient;
    Newton reaches it quadratically instead of linearly. ``F`` (nc,) holds warm force guesses
    and returns the contact forces, ``dprev`` the approaches those guesses belong to (the
    previous step's). Returns (q, iterations, ok).
    """
    nd = q.size
    nc = gc.size
    nm = kn.size
    Wc = cidx.shape[1]
    Wn = nidx.shape[1]
    d = np.empty(nc)
    dn = np.empty(nc)
    Fn = F.copy()
    H = np.empty((nd, nd))
    L = np.empty((nd, nd))
    grad = np.empty(nd)
    dq = np.empty(nd)
    qn = np.empty(nd)
    e0 = _energy_law(K0, f0, nidx, nval, en, kn, cn, cidx, cval, gc, coef, q, Fn, dprev, F, d)
    if not np.isfinite(e0):
        return q, 0, False
    for it in range(maxit):
        for a in range(nd):
            t = -f0[a]
            for b in range(nd):
                H[a, b] = K0[a, b]
                t += K0[a, b] * q[b]
            grad[a] = t
        for c in range(nc):
            if d[c] > 0.0:
                f = F[c]
                kt = 1.0 / (d[c] / f - coef[c, 1])  # 1/δ'(F), δ' = a0 − a1 ln F − a1
                for a in range(Wc):
                    ia = cidx[c, a]
                    grad[ia] += f * cval[c, a]
                    ba = kt * cval[c, a]
                    for b in range(Wc):
                        H[ia, cidx[c, b]] += ba * cval[c, b]
        for m in range(nm):
            rx, ry = 2 * m, 2 * m + 1
            wx = _rows_dot(nidx, nval, q, rx) + en[m, 0]
            wy = _rows_dot(nidx, nval, q, ry) + en[m, 1]
            gx, gy, hxx, hyy, hxy = _bearing_terms(wx, wy, kn[m], cn[m])
            for a in range(Wn):
                ia = nidx[rx, a]
                bx, by = nval[rx, a], nval[ry, a]
                grad[ia] += gx * bx + gy * by
                ta = hxx * bx + hxy * by
                tb = hxy * bx + hyy * by
                for b in range(Wn):
                    H[ia, nidx[rx, b]] += ta * nval[rx, b] + tb * nval[ry, b]
        for a in range(nd):
            H[a, a] += reg
        _spd_solve(H, grad, L, dq)
        for a in range(nd):
            dq[a] = -dq[a]
            qn[a] = q[a] + dq[a]
        step = 1.0
        decreased = False
        e1 = e0
        for _ in range(60):
            e1 = _energy_law(K0, f0, nidx, nval, en, kn, cn, cidx, cval, gc, coef, qn, F, d, Fn, dn)
            if e1 <= e0 + 1e-12 * abs(e0):
                decreased = True
                break
            step *= 0.5
            for a in range(nd):
                qn[a] = q[a] + step * dq[a]
        if not decreased:
            return q, it + 1, True
        same = True
        for c in range(nc):
            if (dn[c] > 0.0) != (d[c] > 0.0):
                same = False
        q = qn.copy()
        F[:] = Fn
        d[:] = dn
        e0 = e1
        big = 0.0
        for a in range(nd):
            big = max(big, abs(step * dq[a]))
        # quadratic convergence: after a full step of size s the error is O(s²)
        if big < tol or (same and step == 1.0 and big < 1e-9):
            return q, it + 1, True
    return q, maxit, False


@njit(cache=True, nogil=True)
def _position_sp(
    K0, reg, f0, nidx, nval, en, kn, cn, cidx, cval, gc, group, ngroups, law, coef, k, kc, q0,
    tol, maxit, force, approach, exact,
):  # fmt: skip
    """:func:`gearte.solvers.rv_equilibrium._solve_position` on sparse rows; updates ``k``,
    ``kc`` and ``force`` in place, returns (q, iterations, ok).

    ``exact``: with the per-contact law, Newton on the exact law (:func:`_newton_law`, warm
    forces ``force`` at approaches ``approach``, both updated) first; the secant fixed point only
    where it fails."""
    nc = gc.size
    if law == LAW_SECANT_PER_CONTACT and exact:
        guess = force.copy()
        q, its, ok = _newton_law(K0, reg, f0, nidx, nval, en, kn, cn, cidx, cval, gc, coef,
                                 guess, approach, q0.copy(), 1e-13 * max(1.0, np.max(np.abs(q0))),
                                 maxit)  # fmt: skip
        if ok:
            for c in range(nc):
                force[c] = guess[c]
                approach[c] = _rows_dot(cidx, cval, q, c) - gc[c]
                if force[c] > 0.0 and approach[c] > 0.0:
                    kc[c] = force[c] / approach[c]
            return q, its, True
    q = q0.copy()
    if law != LAW_SECANT_PER_CONTACT:
        for c in range(nc):
            kc[c] = k[group[c]]
    total = 0
    qtol = 1e-13 * max(1.0, np.max(np.abs(q0)))
    for _outer in range(200):
        q, its, ok = _newton_sp(K0, reg, f0, nidx, nval, en, kn, cn, cidx, cval, gc, kc, q,
                                qtol, maxit)  # fmt: skip
        total += its
        if not ok:
            return q, total, False
        for c in range(nc):
            d = _rows_dot(cidx, cval, q, c) - gc[c]
            force[c] = kc[c] * d if d > 0.0 else 0.0
        if law == LAW_LINEAR:
            return q, total, True
        change = 0.0
        if law == LAW_SECANT_PER_DISC:
            for g in range(ngroups):
                fmax = 0.0
                cm = -1
                for c in range(nc):
                    if group[c] == g and force[c] > fmax:
                        fmax = force[c]
                        cm = c
                if fmax > 0.0:
                    if coef[cm, 0] - coef[cm, 1] * np.log(fmax) <= coef[cm, 1]:
                        return q, total, False
                    knew = fmax / _law_delta(fmax, coef[cm, 0], coef[cm, 1])
                    change = max(change, abs(knew / k[g] - 1.0))
                    k[g] = knew
            for c in range(nc):
                kc[c] = k[group[c]]
        else:
            for c in range(nc):
                if force[c] > 0.0:
                    if coef[c, 0] - coef[c, 1] * np.log(force[c]) <= coef[c, 1]:
                        return q, total, False
                    knew = force[c] / _law_delta(force[c], coef[c, 0], coef[c, 1])
                    change = max(change, abs(knew / kc[c] - 1.0))
                    kc[c] = knew
            for g in range(ngroups):
                kg = 0.0
                for c in range(nc):
                    if group[c] == g and force[c] > 0.0 and kc[c] > kg:
                        kg = kc[c]
                if kg > 0.0:
                    k[g] = kg
        if change < tol:
            for c in range(nc):
                d = _rows_dot(cidx, cval, q, c) - gc[c]
                force[c] = kc[c] * d if d > 0.0 else 0.0
            return q, total, True
    return q, total, False


@njit(cache=True, nogil=True)
def _solve_batch(
    K0s, us, regs, cidx, cvals, nidx, nvals, kn, cn, group, ngroups, law, coefs, kstart, Hs, ENs,
    GAPs, step_g, step_T, cold, rec, nrec, out_u, out_h, out_q, tol, maxit, exact,
):  # fmt: skip
    """All samples × steps. The system is the condensed one (:func:`condense`): stiffness
    ``K0s[g]``, load ``T us[g] − Hs[s, g]``; the output rotation is recovered as
    ``T out_u[g] − out_h[s, g] + out_q[g] · q``."""
    S = Hs.shape[0]
    K = step_g.size
    nd = us.shape[1]
    nc = GAPs.shape[2]
    rot = np.zeros((S, K))
    forces = np.zeros((S, nrec, nc))
    iters = np.zeros((S, K), dtype=np.int64)
    k = np.empty(ngroups)
    kc = np.empty(nc)
    force = np.zeros(nc)
    approach = np.zeros(nc)
    f0 = np.empty(nd)
    q = np.zeros(nd)
    for s in range(S):
        for t in range(K):
            g = step_g[t]
            T = step_T[t]
            if cold[t]:
                q[:] = 0.0
                force[:] = 0.0
                approach[:] = 0.0
                k[:] = kstart
                for c in range(nc):
                    kc[c] = k[group[c]]
            for a in range(nd):
                f0[a] = T * us[g, a] - Hs[s, g, a]
            q, its, ok = _position_sp(
                K0s[g], regs[g], f0, nidx, nvals[g], ENs[s, g], kn, cn, cidx, cvals[g],
                GAPs[s, g], group, ngroups, law, coefs[g], k, kc, q, tol, maxit, force, approach,
                exact,
            )  # fmt: skip
            if not ok:
                iters[s, t] = -1
                break
            iters[s, t] = its
            r = T * out_u[g] - out_h[s, g]
            for a in range(nd):
                r += out_q[g, a] * q[a]
            rot[s, t] = r
            if rec[t] >= 0:
                forces[s, rec[t]] = force
    return rot, forces, iters


@dataclass(frozen=True)
class Condensed:
    """The batch problem on the degrees of freedom that a contact or a clearance bearing touches.

    The other degrees of freedom ``f`` are linear: minimising over them gives
    ``q_f = K_ff⁻¹ (f0_f − K_fc q_c)`` exactly (static condensation), so the solver iterates on
    ``q_c`` only with ``K = K_cc − K_cf K_ff⁻¹ K_fc`` and load ``f0_c − K_cf K_ff⁻¹ f0_f``. Where
    ``K_ff`` is not positive definite (a degree of freedom held only by contacts or clearance
    bearings) nothing is condensed. ``reg``: the Newton regularisation, 1e-13 of the largest
    diagonal entry of the full ``K0`` (as the per-case solver), added to the Hessian only.
    """

    keep: np.ndarray
    K: np.ndarray
    reg: np.ndarray
    u: np.ndarray
    M: np.ndarray
    out_u: np.ndarray
    out_hrow: np.ndarray
    out_q: np.ndarray
    contacts: SparseRows
    bearings: SparseRows


def condense(problem: BatchProblem) -> Condensed:
    """:class:`Condensed` form of ``problem`` (see there)."""
    p = problem
    G, nd, _ = p.K0.shape
    used = np.zeros(nd, bool)
    used[p.contacts.index.ravel()] = True
    if p.bearings.index.size and p.bearing_k.size:
        used[p.bearings.index.ravel()] = True
    keep = np.flatnonzero(used)
    free = np.flatnonzero(~used)
    pos = np.full(nd, -1)
    pos[keep] = np.arange(keep.size)
    K0 = p.K0
    if free.size:
        try:  # the linear degrees of freedom must be held by the linear springs alone
            np.linalg.cholesky(K0[:, free][:, :, free])
        except np.linalg.LinAlgError:
            keep, free = np.arange(nd), np.arange(0)
            pos = np.arange(nd)
    Kcc = K0[:, keep][:, :, keep]
    if free.size:
        Kff = K0[:, free][:, :, free]
        Kfc = K0[:, free][:, :, keep]
        X = np.linalg.solve(Kff, np.concatenate([Kfc, np.eye(free.size)[None].repeat(G, 0)], 2))
        KffKfc, Kffinv = X[:, :, : keep.size], X[:, :, keep.size :]
        M = np.einsum("gfc,gfe->gce", Kfc, Kffinv)  # K_cf K_ff⁻¹, (G, m, nf)
        K = Kcc - np.einsum("gfc,gfe->gce", Kfc, KffKfc)
        K = 0.5 * (K + K.transpose(0, 2, 1))
    else:
        Kffinv = np.zeros((G, 0, 0))
        KffKfc = np.zeros((G, 0, keep.size))
        M = np.zeros((G, keep.size, 0))
        K = Kcc
    u = p.unit_load
    uc = u[keep][None] - np.einsum("gcf,f->gc", M, u[free])
    out_q = np.zeros((G, keep.size))
    out_hrow = np.zeros((G, nd))
    if pos[p.output] >= 0:
        out_q[:, pos[p.output]] = 1.0
        out_u = np.zeros(G)
    else:
        r = int(np.flatnonzero(free == p.output)[0])
        out_q = -KffKfc[:, r, :]
        out_u = Kffinv[:, r, :] @ u[free]
        out_hrow[:, free] = Kffinv[:, r, :]
    Mfull = np.zeros((G, keep.size, nd))
    Mfull[:, :, keep] = np.eye(keep.size)[None]
    Mfull[:, :, free] = -M

    def remap(rows: SparseRows) -> SparseRows:
        idx = pos[rows.index] if rows.index.size else rows.index
        return SparseRows(np.ascontiguousarray(idx, dtype=np.int64), rows.value)

    reg = 1e-13 * np.abs(np.diagonal(p.K0, axis1=1, axis2=2)).max(axis=1)
    return Condensed(keep, np.ascontiguousarray(K), reg, np.ascontiguousarray(uc), Mfull, out_u,
                     out_hrow, out_q, remap(p.contacts), remap(p.bearings))  # fmt: skip


def solve_batch(
    problem: BatchProblem,
    h: np.ndarray,
    bearing_offset: np.ndarray,
    gap: np.ndarray,
    step_geometry: np.ndarray,
    step_torque: np.ndarray,
    cold: np.ndarray,
    record: np.ndarray | None = None,
    *,
    tol: float = 1e-9,
    maxit: int = 100,
    exact: bool = True,
    compiled: bool = True,
) -> BatchSolution:
    """Equilibrium of ``S`` samples at ``K`` steps each.

    Parameters
    ----------
    problem : BatchProblem
    h : numpy.ndarray
        (S, G, nd) ``Σ k e B`` of each sample's linear springs [N, N·mm].
    bearing_offset : numpy.ndarray
        (S, G, nm, 2) offsets ``e`` of the clearance bearings [mm].
    gap : numpy.ndarray
        (S, G, nc) contact clearances [mm].
    step_geometry : numpy.ndarray
        (K,) geometry index of each step [-].
    step_torque : numpy.ndarray
        (K,) output torque of each step [N·mm].
    cold : numpy.ndarray
        (K,) bool [-]: start a new sequence at this step (zero displacements, start stiffness).
    record : numpy.ndarray, optional
        (K,) bool [-]: keep the contact forces at this step (default none).
    tol : float
        Relative tolerance of the secant fixed point [-] (as
        :func:`gearte.solvers.rv_equilibrium.solve_positions`).
    maxit : int
        Newton iterations per solve.
    exact : bool
        Per-contact law: Newton on the exact law (quadratic convergence to the secant fixed
        point's limit) instead of the secant fixed point (linear convergence, stopped at ``tol``);
        ``False`` runs the fixed point exactly as the per-case solver does.
    compiled : bool
        ``False`` runs the plain-Python twin.

    Raises
    ------
    ConvergenceError
        Naming the first sample and step without an equilibrium.
    """
    S, G = h.shape[:2]
    K = np.asarray(step_geometry).size
    if np.asarray(step_torque).shape != (K,) or np.asarray(cold).shape != (K,):
        raise ParameterError("steps", K, "step_geometry, step_torque and cold need one entry each")
    if K and not bool(np.asarray(cold)[0]):
        raise ParameterError("cold", cold, "the first step must start a sequence (cold)")
    rec = np.full(K, -1, dtype=np.int64)
    if record is not None:
        r = np.flatnonzero(np.asarray(record, dtype=bool))
        rec[r] = np.arange(r.size)
    nrec = int((rec >= 0).sum())
    p = problem
    cd = problem.__dict__.get("_condensed")
    if cd is None:
        cd = condense(p)
        object.__setattr__(problem, "_condensed", cd)
    coef3 = np.ascontiguousarray(
        np.concatenate([p.coef, law_limit(p.coef[..., :1], p.coef[..., 1:2])], axis=-1)
        if p.law != LAW_LINEAR
        else np.zeros(p.coef.shape[:-1] + (3,))
    )
    h = np.asarray(h, dtype=float)
    hc = np.einsum("gcn,sgn->sgc", cd.M, h)  # condensed loads, (S, G, m)
    out_h = np.einsum("gn,sgn->sg", cd.out_hrow, h)
    args = (
        cd.K, cd.u, cd.reg, cd.contacts.index, np.ascontiguousarray(cd.contacts.value),
        cd.bearings.index, np.ascontiguousarray(cd.bearings.value),
        np.ascontiguousarray(p.bearing_k, dtype=float),
        np.ascontiguousarray(p.bearing_c, dtype=float), p.group.astype(np.int64), p.ngroups,
        int(p.law), coef3, float(p.start_stiffness),
        np.ascontiguousarray(hc), np.ascontiguousarray(bearing_offset, dtype=float),
        np.ascontiguousarray(gap, dtype=float), np.asarray(step_geometry, dtype=np.int64),
        np.asarray(step_torque, dtype=float), np.asarray(cold, dtype=np.bool_), rec, nrec,
        np.ascontiguousarray(cd.out_u), np.ascontiguousarray(out_h),
        np.ascontiguousarray(cd.out_q), float(tol), int(maxit), bool(exact),
    )  # fmt: skip
    if compiled:
        rot, forces, iters = _solve_batch(*args)
    else:
        g = _solve_batch.py_func.__globals__
        names = ("_position_sp", "_newton_sp", "_energy_sp", "_spd_solve", "_rows_dot",
                 "_newton_law", "_energy_law", "_law_force")  # fmt: skip
        with _TWIN_LOCK:
            saved = {n: g[n] for n in names}
            for n in names:
                g[n] = saved[n].py_func
            try:
                rot, forces, iters = _solve_batch.py_func(*args)
            finally:
                g.update(saved)
        # _law_delta is imported compiled; its py_func is called through the compiled object,
        # which is fine: it is a pure scalar expression.
    if np.any(iters < 0):
        s, t = (int(v[0]) for v in np.nonzero(iters < 0))
        raise ConvergenceError(
            f"rv_batch: no equilibrium for sample {s} at step {t} (geometry "
            f"{int(np.asarray(step_geometry)[t])}, torque {float(np.asarray(step_torque)[t]):.6g} "
            f"N·mm) within {maxit} Newton iterations / 200 stiffness iterations, tolerance {tol:g} "
            "(or a pin force beyond the range of the contact law)"
        )
    return BatchSolution(rot, forces, iters)
