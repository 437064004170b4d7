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
``compiled=False`` runs its plain-Python twin (tests; :func:`gearte.solvers.twins.plain_twins`).
Its results equal the per-case solver's to round-off (a test checks 1e-9 on sampled reducers).
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np
from numba import njit

from gearte._jit import inner_kernel, kernel
from gearte.errors import ConvergenceError, ParameterError
from gearte.solvers.dense import copy_into as _copy
from gearte.solvers.dense import solve_spd_into as _spd_solve
from gearte.solvers.rv_equilibrium import (
    CLEARANCE_RESIDUAL,
    LAW_LINEAR,
    LAW_SECANT_PER_CONTACT,
    NEWTON_MAXIT,
    _bearing_terms,
    _secant_update,
    law_terms,
)

__all__ = [
    "SparseRows",
    "sparse_rows",
    "BatchProblem",
    "BatchSolution",
    "problem_from_system",
    "solve_batch",
    "solve_system",
    "solve_positions",
]


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
    count = nz.sum(axis=1)
    W = max(1, int(count.max(initial=0)))
    # each row's non-zero columns in increasing order, then padding: its first column again
    # (value 0; a row with no entry: column 0)
    order = np.argsort(~nz, axis=1, kind="stable")[:, :W]
    pad = np.arange(W)[None, :] >= count[:, None]
    index = np.ascontiguousarray(np.where(pad, order[:, :1], order), dtype=np.int64)
    value = np.take_along_axis(B, index[None], axis=2)
    value[:, pad] = 0.0
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
        (:data:`~gearte.solvers.rv_equilibrium.LAW_LINEAR` …); coef : (G, nc, 4) law
        coefficients (a0, a1, a2, a3) of ``δ = F (a0 − a1 ln F) + a2 F^a3``;
        start_stiffness : start (or constant) stiffness [N/mm].
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

    Built once per system and law (code, start stiffness, coefficients): kept on ``system``
    and returned again for the same law, with the condensation kept on the problem. The arrays
    are shared between those calls: read them, do not modify them.

    Parameters
    ----------
    system : gearte.models.rv_load_sharing.RVSystem
    law : ContactLaw or a model-level law with ``for_system(system)``
    """
    from gearte.solvers.rv_equilibrium import _linear_parts, _split_springs, as_solver_law

    law = as_solver_law(law, system)
    G, nd = system.theta.size, system.layout.size
    nc = system.contact_gap.shape[1]
    coef = law.coefficients(G, nc)
    # kept on the system for the next solve with the same law (its condensation is kept on the
    # problem): transmission_error solves each system at two torques, the compensation and
    # the catalogue loop many systems several times
    kept = system.__dict__.get("_batch_problem")
    if kept is not None:
        (code, stiffness, kept_coef), out = kept
        if code == law.code and stiffness == law.stiffness and np.array_equal(kept_coef, coef):
            return out
    lin, Bn, en0, kn, cn = _split_springs(system)
    K0, f0 = _linear_parts(
        system.spring_B[:, lin], system.spring_e[:, lin], system.spring_k[lin], np.zeros((G, nd))
    )
    problem = BatchProblem(
        K0=K0,
        unit_load=system.unit_load,
        contacts=sparse_rows(system.contact_B),
        bearings=sparse_rows(Bn.reshape(G, -1, nd), pairs=True),
        bearing_k=kn,
        bearing_c=cn,
        group=system.contact_group.astype(np.int64),
        law=law.code,
        coef=coef,
        start_stiffness=law.stiffness,
        output=system.layout.output_rotation,
    )
    out = (problem, -f0[None], en0[None], system.contact_gap[None])
    object.__setattr__(system, "_batch_problem", ((law.code, law.stiffness, coef), out))
    return out


@dataclass(frozen=True)
class BatchSolution:
    """``output`` (S, K) output rotation at every step [rad]; ``forces`` (S, R, nc) contact forces
    at the recorded steps [N]; ``iterations`` (S, K) Newton iterations per step."""

    output: np.ndarray
    forces: np.ndarray
    iterations: np.ndarray


@inner_kernel
def _rows_dot(idx, val, q, r):
    s = 0.0
    for w in range(idx.shape[1]):
        s += val[r, w] * q[idx[r, w]]
    return s


@inner_kernel
def _rows_times(idx, val, x, out):
    """``out[r] = B[r]·x`` for every stored row (rows of three columns: the columns' values
    read once per run of rows on the same columns)."""
    if idx.shape[1] != 3:
        for r in range(out.size):
            out[r] = _rows_dot(idx, val, x, r)
        return
    i0 = i1 = i2 = -1
    x0 = x1 = x2 = 0.0
    for r in range(out.size):
        if idx[r, 0] != i0 or idx[r, 1] != i1 or idx[r, 2] != i2:
            i0, i1, i2 = idx[r, 0], idx[r, 1], idx[r, 2]
            x0, x1, x2 = x[i0], x[i1], x[i2]
        out[r] = val[r, 0] * x0 + val[r, 1] * x1 + val[r, 2] * x2


def law_limit(a0: np.ndarray, a1: np.ndarray) -> np.ndarray:
    """``F* = exp((a0 − a1)/a1)`` [N], where the log law's ``δ'(F)`` vanishes (its range ends);
    capped at ``exp(700)``; ``inf`` where ``a1 = 0`` (a power law: no end)."""
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(a1 > 0.0, np.exp(np.minimum((a0 - a1) / np.where(a1 > 0.0, a1, 1.0),
                                                    700.0)), np.inf)  # fmt: skip


def law_columns(coef: np.ndarray) -> np.ndarray:
    """The kernel's per-contact law columns: ``coef`` (…, 4) and the end of its range,
    ``F*`` (:func:`law_limit`) and ``δ* = δ(F*)`` (``a1 F*`` for the log law, ``inf`` for a
    power law) — (…, 6)."""
    a0, a1 = coef[..., :1], coef[..., 1:2]
    if np.all(a1 > 0.0):  # every contact on the log law (the usual case: two passes less)
        fstar = np.exp(np.minimum((a0 - a1) / a1, 700.0))
        dstar = a1 * fstar
    else:
        fstar = law_limit(a0, a1)
        dstar = np.where(a1 > 0.0, a1 * np.where(a1 > 0.0, fstar, 0.0), np.inf)
    return np.ascontiguousarray(np.concatenate([coef, fstar, dstar], axis=-1))


@inner_kernel
def _law_force(d, a0, a1, a2, a3, fstar, dstar, f_prev, d_prev):
    """Force ``F`` with ``δ(F) = F (a0 − a1 ln F) + a2 F^a3 = d`` for an approach ``d > 0`` [N].

    ``a0 … dstar``: the contact's law columns (:func:`law_columns`). δ is
    increasing and concave up to ``F*`` (where δ' = 0; the log law's ``exp((a0 − a1)/a1)``, no
    end for a power law). Start: the tangent predictor from a known point ``(d_prev, f_prev)``
    of the law (where ``f_prev > 0``), else a one-term estimate; then Newton until a relative
    step below 1e-8 (the error is then ~1e-17: quadratic convergence). Returns -1 when
    ``d ≥ δ*`` (beyond the law's range).
    """
    if d >= dstar:
        return -1.0
    F = -1.0
    if f_prev > 0.0 and d_prev > 0.0:
        if a2 == 0.0:
            slope = d_prev / f_prev - a1  # δ'(F) of the log law without a logarithm
        else:
            slope = law_terms(np.log(f_prev), a0, a1, a2, a3)[1]
        if slope > 0.0:
            F = f_prev + (d - d_prev) / slope
    if not (F > 0.0 and F < fstar):
        F = _law_force_start(d, a0, a1, a2, a3, fstar)
    for _ in range(100):
        lf = np.log(F)
        rest, gp = law_terms(lf, a0, a1, a2, a3)
        if not gp > 0.0:
            F = 0.5 * F
            continue
        Fn = F - (F * rest - d) / gp
        if not Fn > 0.0:
            Fn = 0.1 * F
        # quadratic convergence: after a relative step below 1e-8 the error is ~1e-17
        if abs(Fn - F) <= 1e-8 * F:
            return Fn
        F = Fn
    return F


@inner_kernel
def _law_force_start(d, a0, a1, a2, a3, fstar):
    """One-term estimate of the force at approach ``d > 0``: ``F ≈ d / (a0 − a1 ln(d/a))`` for
    the log law; for a power law the force of its power part, ``(d/a2)^(1/a3)``, combined with
    the linear part ``d/a0`` as compliances in series."""
    if a2 == 0.0:
        den = a0 - a1 * np.log(max(d / max(a0, a1), 1e-300))
        return d / den if den > 0.0 else 0.5 * fstar
    fp = (d / a2) ** (1.0 / a3)
    return fp if a0 <= 0.0 else 1.0 / (1.0 / fp + a0 / d)


@inner_kernel
def _energy(exact, K0, f0, nidx, nval, en, kn, cn, cidx, cval, gc, coef, kc, q, Fp, dp, F, d, kt,
            exact_law):  # fmt: skip
    """Π at ``q``; fills the approaches ``d``, contact forces ``F`` and tangent stiffnesses
    ``kt`` of every contact (0 where open).

    ``exact``: the exact law (forces from the known pairs ``Fp``, ``dp``;
    ``φ(d) = ∫F dd = F d/2 − a1 F²/4 + a2 F^(a3+1) (a3 − 1)/(2 (a3 + 1))``, tangent
    ``1/δ'(F)``; +inf beyond the law's range),
    else the fixed stiffnesses ``kc`` (``φ = kc d²/2``). ``exact_law``: ``None`` where the
    batch solves no exact per-contact law (``exact`` is then always False: numba prunes that
    branch, and :func:`_law_force` is not compiled for the per-disc and linear laws); any
    array otherwise (:func:`_solve_batch`'s ``fd0``).
    """
    nd = q.size
    e = 0.0
    for a in range(nd):
        t = 0.0
        for b in range(nd):
            t += K0[a, b] * q[b]
        e += (0.5 * t - f0[a]) * q[a]
    _rows_times(cidx, cval, q, d)
    for c in range(gc.size):
        dc = d[c] - gc[c]
        d[c] = dc
        if dc > 0.0:
            fixed = True
            if exact_law is not None:
                if exact:
                    fixed = False
                    a1, a2, a3 = coef[c, 1], coef[c, 2], coef[c, 3]
                    f = _law_force(dc, coef[c, 0], a1, a2, a3, coef[c, 4], coef[c, 5], Fp[c],
                                   dp[c])  # fmt: skip
                    if f < 0.0:
                        return np.inf
                    F[c] = f
                    if a2 == 0.0:
                        kt[c] = 1.0 / (dc / f - a1)  # 1/δ'(F), δ' = a0 − a1 ln F − a1
                        e += 0.5 * f * dc - 0.25 * a1 * f * f
                    else:
                        kt[c] = 1.0 / law_terms(np.log(f), coef[c, 0], a1, a2, a3)[1]
                        e += (0.5 * f * dc - 0.25 * a1 * f * f
                              + a2 * f ** (a3 + 1.0) * (a3 - 1.0) / (2.0 * (a3 + 1.0)))  # fmt: skip
            if fixed:
                F[c] = kc[c] * dc
                kt[c] = kc[c]
                e += 0.5 * kc[c] * dc * dc
        else:
            F[c] = 0.0
            kt[c] = 0.0
    for m in range(kn.size):
        wx = _rows_dot(nidx, nval, q, 2 * m) + en[m, 0]
        wy = _rows_dot(nidx, nval, q, 2 * m + 1) + en[m, 1]
        rr = wx * wx + wy * wy
        e += 0.5 * CLEARANCE_RESIDUAL * kn[m] * rr
        r = np.sqrt(rr) - cn[m]
        if r > 0.0:
            e += 0.5 * (1.0 - CLEARANCE_RESIDUAL) * kn[m] * r * r
    return e


@inner_kernel
def _assemble_rows3(cidx, cval, F, kt, H, grad):
    """:func:`_assemble`'s contact rows where each row has three columns (a disc's x, y and
    rotation): consecutive rows on the same columns are summed in registers and added to ``H``
    and ``grad`` once per run (the contacts of one disc are consecutive)."""
    # -1 as an int64, not a literal: numba would compile _add_block3 a second time for
    # Literal[int](-1) columns at one of its two call sites (docs/numba.md)
    i0 = i1 = i2 = np.int64(-1)
    g0 = g1 = g2 = h00 = h01 = h02 = h11 = h12 = h22 = 0.0
    for c in range(kt.size):
        k = kt[c]
        if not k > 0.0:
            continue
        if cidx[c, 0] != i0 or cidx[c, 1] != i1 or cidx[c, 2] != i2:
            if i0 >= 0:
                _add_block3(i0, i1, i2, g0, g1, g2, h00, h01, h02, h11, h12, h22, H, grad)
            i0, i1, i2 = cidx[c, 0], cidx[c, 1], cidx[c, 2]
            g0 = g1 = g2 = h00 = h01 = h02 = h11 = h12 = h22 = 0.0
        f = F[c]
        v0, v1, v2 = cval[c, 0], cval[c, 1], cval[c, 2]
        g0 += f * v0
        g1 += f * v1
        g2 += f * v2
        k0, k1, k2 = k * v0, k * v1, k * v2
        h00 += k0 * v0
        h01 += k0 * v1
        h02 += k0 * v2
        h11 += k1 * v1
        h12 += k1 * v2
        h22 += k2 * v2
    if i0 >= 0:
        _add_block3(i0, i1, i2, g0, g1, g2, h00, h01, h02, h11, h12, h22, H, grad)


@inner_kernel
def _add_block3(i0, i1, i2, g0, g1, g2, h00, h01, h02, h11, h12, h22, H, grad):
    """Add a symmetric 3 × 3 block and its gradient on columns (i0, i1, i2) (repeated columns,
    the padding of :func:`sparse_rows`, carry zero entries and add nothing)."""
    grad[i0] += g0
    grad[i1] += g1
    grad[i2] += g2
    H[i0, i0] += h00
    H[i1, i1] += h11
    H[i2, i2] += h22
    H[i0, i1] += h01
    H[i1, i0] += h01
    H[i0, i2] += h02
    H[i2, i0] += h02
    H[i1, i2] += h12
    H[i2, i1] += h12


@inner_kernel
def _assemble(K0, reg, f0, nidx, nval, en, kn, cn, cidx, cval, F, kt, q, H, grad):
    """Gradient ``K0 q − f0 + Σ F_c B_c + bearings`` and Hessian ``K0 + Σ kt_c B_c B_cᵀ +
    bearings + reg I`` at ``q`` — the one contact-row assembly of every Newton variant here
    (a contact enters where ``kt_c > 0``)."""
    nd = q.size
    Wc = cidx.shape[1]
    Wn = nidx.shape[1]
    for a in range(nd):
        t = -f0[a]
        for b in range(nd):
            H[a, b] = K0[a, b]
            t += K0[a, b] * q[b]
        grad[a] = t
    if Wc == 3:
        _assemble_rows3(cidx, cval, F, kt, H, grad)
    else:
        for c in range(kt.size):
            if kt[c] > 0.0:
                f = F[c]
                k = kt[c]
                for a in range(Wc):
                    ia = cidx[c, a]
                    grad[ia] += f * cval[c, a]
                    ba = k * cval[c, a]
                    for b in range(Wc):
                        H[ia, cidx[c, b]] += ba * cval[c, b]
    for m in range(kn.size):
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


@njit(cache=True, nogil=True, inline="always")
def _newton(
    exact, K0, reg, f0, nidx, nval, en, kn, cn, cidx, cval, gc, coef, kc, q, F, d, kt, wm, wv,
    wc, tol, maxit, exact_law,
):  # fmt: skip
    """Active-set Newton with a backtracking line search on Π (:func:`_energy`), in place.

    ``exact=False``: fixed contact stiffnesses ``kc`` — :func:`gearte.solvers.rv_equilibrium.
    _newton` on sparse rows (same steps and tests). ``exact=True``: the exact load-dependent
    pin law (tangent ``1/δ'(F)``): the fixed point of the per-contact secant iteration of
    :func:`gearte.solvers.rv_equilibrium._solve_all` is the root of this Π's gradient, and
    Newton reaches it quadratically. On entry ``F``, ``d`` hold warm (force, approach) pairs of
    the law (exact only); on return ``q`` the minimiser and ``F``, ``d``, ``kt`` its forces,
    approaches and tangents. ``wm`` (2, nd, nd), ``wv`` (3, nd), ``wc`` (3, nc): work arrays
    (three arrays, not a tuple of eight: each array argument is several flattened arguments of
    the compiled function, docs/numba.md); ``exact_law``: as :func:`_energy`'s. Returns
    (iterations, ok).
    """
    nd = q.size
    nc = gc.size
    nm = kn.size
    H, L = wm[0], wm[1]
    grad, dq, qn = wv[0], wv[1], wv[2]
    Fn, dn, ktn = wc[0], wc[1], wc[2]
    e0 = _energy(exact, K0, f0, nidx, nval, en, kn, cn, cidx, cval, gc, coef, kc, q, F, d, Fn,
                 dn, ktn, exact_law)  # fmt: skip
    if not np.isfinite(e0):
        return 0, False
    _copy(Fn, F)
    _copy(dn, d)
    _copy(ktn, kt)
    for it in range(maxit):
        _assemble(K0, reg, f0, nidx, nval, en, kn, cn, cidx, cval, F, kt, q, H, grad)
        _spd_solve(H, grad, L, dq)
        for a in range(nd):
            dq[a] = -dq[a]
            qn[a] = q[a] + dq[a]
        step = 1.0
        decreased = False
        e1 = e0
        for _ in range(60):
            e1 = _energy(exact, K0, f0, nidx, nval, en, kn, cn, cidx, cval, gc, coef, kc, qn, F,
                         d, Fn, dn, ktn, exact_law)  # fmt: skip
            if e1 <= e0 + 1e-12 * abs(e0):
                decreased = True
                break
            step *= 0.5
            for a in range(nd):
                qn[a] = q[a] + step * dq[a]
        if not decreased:
            # no descent left at round-off level: q is the minimiser to machine precision
            return it + 1, True
        stalled = e0 - e1 <= 1e-14 * abs(e0)
        same = True
        for c in range(nc):
            if (dn[c] > 0.0) != (d[c] > 0.0):
                same = False
        _copy(qn, q)
        _copy(Fn, F)
        _copy(dn, d)
        _copy(ktn, kt)
        e0 = e1
        big = 0.0
        for a in range(nd):
            big = max(big, abs(step * dq[a]))
        if big < tol:
            return it + 1, True
        if exact:
            # quadratic convergence: after a full step of size s the error is O(s²)
            if same and step == 1.0 and big < 1e-9:
                return it + 1, True
        elif (same and step == 1.0 and nm == 0) or (same and stalled and it > 2):
            return it + 1, True
    return maxit, False


@njit(cache=True, nogil=True, inline="always")
def _newton_mixed(K0, reg, f0, nidx, nval, en, kn, cn, cidx, cval, gc, coef, q, F, d, kt, wm,
                  wv, wc, maxit):  # fmt: skip
    """Newton on the equilibrium *and* the pin law together, in place: no inner law solves.

    Unknowns ``q`` and the force ``F_c`` of every closed contact; equations
    ``K0 q − f0 + Σ F_c B_c (+ bearings) = 0`` and ``δ(F_c) = d_c(q)``. Linearising the law,
    ``ΔF_c = (B_c·Δq − (δ(F_c) − d_c)) / δ'(F_c)``, and eliminating ``ΔF`` leaves the Hessian of
    :func:`_newton` with the force replaced by its tangent prediction
    ``F̃_c = F_c + (d_c − δ(F_c))/δ'(F_c)``. ``ln F_c`` is computed at the first iteration and
    where a contact closes, then carried along the force updates (:func:`_log_update`: a
    series where the force changed by less than 2⁻¹⁰ relative). The approaches follow the
    steps (``d ← d − B Δq``) once the steps are small (below 1e-3), are recomputed from ``q``
    after larger ones (the rounding of a huge first step from a cold start would stay in
    them: 1e-3 relative errors of Palmgren's law) and at the end.
    A contact opens where its updated force is not positive; an open one closes where its
    approach is positive (start force :func:`_law_force_start`). Converged when the step in
    ``q`` is below 1e-9 and every force moved by less than 1e-7 of the largest, with no contact
    opening or closing (quadratic convergence: the errors left are of the order of the squares
    of those steps, ~1e-14 of the largest force). On entry ``F``
    holds the start forces (> 0: closed); on return ``q``, ``F`` (forces), ``d`` (approaches)
    and ``kt`` (tangents). Returns (iterations, ok); not ok (no convergence within ``maxit``,
    or a force beyond the law's range) leaves the state undefined.
    """
    nd = q.size
    nc = gc.size
    H, L, grad, dq = wm[0], wm[1], wv[0], wv[1]
    Ft, Bdq, lf = wc[0], wc[1], wc[2]
    big = np.inf
    for it in range(maxit):
        changed = False
        if big > 1e-3:
            # from q itself after a large step (the first, from a cold start, can be huge: an
            # update by −B dq would keep its rounding, ~1e-16 of the step, in every approach;
            # below 1e-3 that rounding is under 1e-17 mm)
            _rows_times(cidx, cval, q, d)
            for c in range(nc):
                d[c] -= gc[c]
        else:  # q moved by −dq: the approaches by −B dq (computed below for the forces)
            for c in range(nc):
                d[c] -= Bdq[c]
        for c in range(nc):
            dc = d[c]
            f = F[c]
            if not f > 0.0:
                if dc > 0.0:
                    f = _law_force_start(dc, coef[c, 0], coef[c, 1], coef[c, 2], coef[c, 3],
                                         coef[c, 4])  # fmt: skip
                    changed = True
                    lf[c] = np.log(f)
                else:
                    kt[c] = 0.0
                    Ft[c] = 0.0
                    F[c] = 0.0
                    continue
            elif it == 0:
                lf[c] = np.log(f)
            # δ/F and δ'(F)
            rest, slope = law_terms(lf[c], coef[c, 0], coef[c, 1], coef[c, 2], coef[c, 3])
            if not slope > 0.0:
                return it, False  # beyond the law's range
            k = 1.0 / slope
            kt[c] = k
            F[c] = f
            Ft[c] = f + (dc - f * rest) * k
        _assemble(K0, reg, f0, nidx, nval, en, kn, cn, cidx, cval, Ft, kt, q, H, grad)
        _spd_solve(H, grad, L, dq)
        big = 0.0
        for a in range(nd):
            q[a] -= dq[a]
            big = max(big, abs(dq[a]))
        fbig = 0.0
        fmax = 0.0
        _rows_times(cidx, cval, dq, Bdq)
        for c in range(nc):
            if kt[c] > 0.0:
                fn = Ft[c] - kt[c] * Bdq[c]
                if fn > 0.0:
                    df = fn - F[c]
                    fbig = max(fbig, abs(df))
                    fmax = max(fmax, fn)
                    lf[c] = _log_update(lf[c], fn, df / F[c])
                    F[c] = fn
                else:
                    F[c] = 0.0
                    changed = True
        if not changed and big < 1e-9 and fbig <= 1e-7 * fmax:
            _rows_times(cidx, cval, q, d)
            for c in range(nc):
                d[c] -= gc[c]
                if not F[c] > 0.0:
                    F[c] = 0.0
                    kt[c] = 0.0
            return it + 1, True
    return maxit, False


@inner_kernel
def _log_update(lf, f, r):
    """``ln f`` from ``lf = ln(f / (1 + r))``: ``lf + log1p(r)`` by its series where
    ``|r| < 2⁻¹⁰`` (five terms: the first omitted, ``r⁶/6``, is below 2e-19 — under the
    rounding of ``lf``), else ``ln f`` itself. Near convergence the forces change by far less:
    one logarithm per closed contact and iteration becomes a few multiplications."""
    if abs(r) < 0.0009765625:
        return lf + r * (1.0 - r * (0.5 - r * (1.0 / 3.0 - r * (0.25 - r * 0.2))))
    return np.log(f)


@kernel
def _solve_batch(
    K0s, us, regs, cidx, cvals, nidx, nvals, kn, cn, group, ngroups, law, coefs, kstart, Hs, ENs,
    GAPs, step_g, step_T, start, rec, nrec, out_u, out_h, out_q, tol, maxit, exact, given_state,
    given, fd0,
):  # fmt: skip
    """All samples × steps. The system is the condensed one (:func:`condense`): stiffness
    ``K0s[g]``, load ``T us[g] − Hs[s, g]``; the output rotation is recovered as
    ``T out_u[g] − out_h[s, g] + out_q[g] · q``. ``start[t]``: the step whose solution (of the
    same sample) starts step ``t`` (−1: zero displacements and the law's start stiffness);
    where ``given[t]``, step ``t`` starts from the state ``given_state[t]`` instead. Each
    step's equilibrium is :func:`gearte.solvers.rv_equilibrium._solve_all` on sparse rows
    (:func:`_newton_mixed`, :func:`_newton` and the stiffness fixed point), written out here.

    A step's state is one vector (:func:`_state_parts`): displacements ``q`` (nd), contact
    forces and approaches (nc each), per-disc (ngroups) and per-contact (nc) stiffness — one
    copy where a step starts from another (each copy site is compiled code of its own).
    ``fd0``: (2, nc) work array of the exact per-contact law's start (its forces and
    approaches, kept for the fallback), or ``None`` where the batch does not solve that law
    (another law, or ``exact=False``): numba then prunes the ``fd0 is not None`` branches
    before typing, and that specialisation compiles neither :func:`_newton_mixed` nor the
    fallback (issue 12: the per-disc law's cases compile less).

    Returns the output rotation, the recorded forces and the iterations per step, and the
    state of every step of the last sample (a one-sample batch's whole solution)."""
    S = Hs.shape[0]
    K = step_g.size
    nd = us.shape[1]
    nc = GAPs.shape[2]
    rot = np.zeros((S, K))
    forces = np.zeros((S, nrec, nc))
    iters = np.zeros((S, K), dtype=np.int64)
    # the state of the step being solved (views of one vector) and the solver's work arrays:
    # nothing is allocated inside the loops
    ns = nd + 3 * nc + ngroups
    state = np.zeros(ns)
    q = state[:nd]
    force = state[nd : nd + nc]
    approach = state[nd + nc : nd + 2 * nc]
    k = state[nd + 2 * nc : nd + 2 * nc + ngroups]
    kc = state[nd + 2 * nc + ngroups :]
    kt = np.zeros(nc)
    f0 = np.zeros(nd)
    q0 = np.zeros(nd)
    wm = np.zeros((2, nd, nd))
    wv = np.zeros((3, nd))
    wc = np.zeros((3, nc))
    # the state of every step of the current sample (starts of later steps)
    ST = np.zeros((K, ns))
    for s in range(S):
        for t in range(K):
            g = step_g[t]
            T = step_T[t]
            u = start[t]
            if given[t]:
                _copy(given_state[t], state)
            elif u < 0:
                state[: nd + 2 * nc] = 0.0
                state[nd + 2 * nc :] = kstart
            else:
                _copy(ST[u], state)
            if u >= 0 and not given[t] and step_g[u] == g and step_T[u] == T:
                its, ok = 0, True  # the same equilibrium (unique): its solution as it is
            else:
                # the equilibrium of this step: rv_equilibrium._solve_all on sparse rows, in
                # place (written here, not as a kernel of its own: each level of compiled calls
                # re-optimises the code below it, and numba's inlining copies the callee's IR
                # block by block, docs/numba.md)
                K0, reg, nval, cval = K0s[g], regs[g], nvals[g], cvals[g]
                en, gc, coef = ENs[s, g], GAPs[s, g], coefs[g]
                for a in range(nd):
                    f0[a] = T * us[g, a] - Hs[s, g, a]
                qmax = 1.0
                for a in range(nd):
                    qmax = max(qmax, abs(q[a]))
                qtol = 1e-13 * qmax
                # exact (per-contact law only): _newton_mixed from the warm forces first; where
                # it fails, Newton on Π with the exact law (_newton); the secant fixed point only
                # where both fail. One call site of _newton (inlined) for the exact-law retry and
                # the fixed point; its law flag a run-time bool (a constant True/False would
                # compile _energy once per literal value, docs/numba.md). Where fd0 is None (no
                # exact per-contact law in this batch) numba prunes the branches on it.
                use_exact = law == LAW_SECANT_PER_CONTACT and exact
                its, ok = 0, False
                if fd0 is not None:
                    if use_exact:
                        _copy(q, q0)
                        _copy(force, fd0[0])
                        _copy(approach, fd0[1])
                        its, ok = _newton_mixed(K0, reg, f0, nidx, nval, en, kn, cn, cidx, cval,
                                                gc, coef, q, force, approach, kt, wm, wv, wc,
                                                30)  # fmt: skip
                        if not ok:
                            _copy(q0, q)
                            _copy(fd0[0], force)
                            _copy(fd0[1], approach)
                if law != LAW_SECANT_PER_CONTACT:
                    for c in range(nc):
                        kc[c] = k[group[c]]
                outer = 0
                while not ok and outer < 200:
                    more, ok = _newton(use_exact, K0, reg, f0, nidx, nval, en, kn, cn, cidx, cval,
                                       gc, coef, kc, q, force, approach, kt, wm, wv, wc, qtol,
                                       maxit, fd0)  # fmt: skip
                    its += more
                    if fd0 is not None:
                        if use_exact:
                            # Newton on Π with the exact law, after _newton_mixed failed
                            if ok:
                                break
                            use_exact = False
                            its = 0
                            _copy(q0, q)
                            _copy(fd0[0], force)
                            _copy(fd0[1], approach)
                            for c in range(nc):  # the start's secant stiffness: the fixed point's
                                if force[c] > 0.0 and approach[c] > 0.0:  # start
                                    kc[c] = force[c] / approach[c]
                            continue
                    outer += 1
                    # force = kc d on the closed contacts (from the last energy evaluation)
                    if not ok or law == LAW_LINEAR:
                        break
                    ok = False  # until the stiffness fixed point has converged
                    change, in_range = _secant_update(law, force, coef, group, ngroups, k, kc)
                    if not in_range:  # a force beyond the law's range
                        break
                    if change < tol:
                        for c in range(nc):
                            dc = approach[c]
                            force[c] = kc[c] * dc if dc > 0.0 else 0.0
                        ok = True
            if not ok:
                iters[s, t] = -1
                break
            iters[s, t] = its
            _copy(state, ST[t])
            r = T * out_u[g] - out_h[s, g]
            for a in range(nd):
                r += out_q[g, a] * q[a]
            rot[s, t] = r
            if rec[t] >= 0:
                _copy(force, forces[s, rec[t]])
    return rot, forces, iters, ST


@dataclass(frozen=True)
class Condensed:
    """The batch problem on the degrees of freedom that a contact or a clearance bearing touches.

    The other degrees of freedom ``f`` are linear: minimising over them gives
    ``q_f = K_ff⁻¹ (f0_f − K_fc q_c)`` exactly (static condensation), so the solver iterates on
    ``q_c`` only with ``K = K_cc − K_cf K_ff⁻¹ K_fc`` and load ``f0_c − K_cf K_ff⁻¹ f0_f``. Where
    ``K_ff`` is not positive definite (a degree of freedom held only by contacts or clearance
    bearings) nothing is condensed. ``reg``: the Newton regularisation, 1e-13 of the largest
    diagonal entry of the full ``K0`` (as the per-case solver), added to the Hessian only.
    ``keep``, ``free``: the iterated and the condensed degrees of freedom; ``Kffinv`` (G, nf, nf)
    ``K_ff⁻¹`` and ``KffKfc`` (G, nf, m) ``K_ff⁻¹ K_fc``, which recover ``q_f`` from a solution.
    """

    keep: np.ndarray
    free: np.ndarray
    Kffinv: np.ndarray
    KffKfc: np.ndarray
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
        KcfT = Kfc.transpose(0, 2, 1)
        M = np.matmul(KcfT, Kffinv)  # K_cf K_ff⁻¹, (G, m, nf)
        K = Kcc - np.matmul(KcfT, KffKfc)
        K = 0.5 * (K + K.transpose(0, 2, 1))
    else:
        Kffinv = np.zeros((G, 0, 0))
        KffKfc = np.zeros((G, 0, keep.size))
        M = np.zeros((G, keep.size, 0))
        K = Kcc
    u = p.unit_load
    uc = u[keep][None] - M @ u[free]
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
    return Condensed(keep, free, Kffinv, KffKfc, np.ascontiguousarray(K), reg,
                     np.ascontiguousarray(uc), Mfull, out_u, out_hrow, out_q, remap(p.contacts),
                     remap(p.bearings))  # fmt: skip


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
    start: np.ndarray | None = None,
    tol: float = 1e-9,
    maxit: int = NEWTON_MAXIT,
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
        (K,) bool [-]: start a new sequence at this step (zero displacements, start stiffness);
        otherwise a step starts from the previous step's solution.
    record : numpy.ndarray, optional
        (K,) bool [-]: keep the contact forces at this step (default none).
    start : numpy.ndarray, optional
        (K,) int [-]: instead of ``cold``, the earlier step whose solution starts each step
        (−1: cold). A step that repeats an earlier one (same geometry and torque, e.g. the
        rising branch of a hysteresis loop) starting from it is verified in one iteration.
    tol : float
        Relative tolerance of the secant fixed point [-] (as
        :func:`gearte.solvers.rv_equilibrium.solve_positions`).
    maxit : int
        Most Newton iterations per solve [-] (default
        :data:`gearte.solvers.rv_equilibrium.NEWTON_MAXIT`).
    exact : bool
        Per-contact law: Newton on the exact law (quadratic convergence to the secant fixed
        point's limit; :func:`_newton_mixed`, falling back to a line-searched Newton) instead
        of the secant fixed point (linear convergence, stopped at ``tol``); ``False`` runs the
        fixed point exactly as the per-case solver does.
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
    if start is None:
        if K and not bool(np.asarray(cold)[0]):
            raise ParameterError("cold", cold, "the first step must start a sequence (cold)")
        start = np.where(np.asarray(cold, dtype=bool), -1, np.arange(K) - 1)
    start = np.asarray(start, dtype=np.int64)
    if start.shape != (K,) or np.any(start >= np.arange(K)) or np.any(start < -1):
        raise ParameterError("start", start, "one entry per step: an earlier step or -1")
    rec = np.full(K, -1, dtype=np.int64)
    if record is not None:
        r = np.flatnonzero(np.asarray(record, dtype=bool))
        rec[r] = np.arange(r.size)
    rot, forces, iters = _run(problem, h, bearing_offset, gap, step_geometry, step_torque,
                              start, rec, tol, maxit, exact, compiled)[:3]  # fmt: skip
    if np.any(iters < 0):
        s, t = (int(v[0]) for v in np.nonzero(iters < 0))
        raise ConvergenceError(
            f"rv_batch: no equilibrium for sample {s} at step {t} (geometry "
            f"{int(np.asarray(step_geometry)[t])}, torque {float(np.asarray(step_torque)[t]):.6g} "
            f"N·mm) within {maxit} Newton iterations / 200 stiffness iterations, tolerance {tol:g} "
            "(or a pin force beyond the range of the contact law)"
        )
    return BatchSolution(rot, forces, iters)


def _condensed(problem: BatchProblem) -> Condensed:
    """:func:`condense` of ``problem``, computed once and kept on it."""
    cd = problem.__dict__.get("_condensed")
    if cd is None:
        cd = condense(problem)
        object.__setattr__(problem, "_condensed", cd)
    return cd


def _run(problem, h, en, gap, step_g, step_T, start, rec, tol, maxit, exact, compiled,
         first=None):  # fmt: skip
    """The kernel's raw outputs for the inputs of :func:`solve_batch` (``rec``: index of each
    step among the recorded ones, −1 if not recorded); ``first``: optional start states
    ``(steps, q condensed, k per disc, kc per contact)`` (one row per step named) of the steps
    that start a sweep."""
    p = problem
    cd = _condensed(p)
    coef3 = p.__dict__.get("_law_columns")  # computed once per problem, as its condensation
    if coef3 is None:
        coef3 = law_columns(p.coef) if p.law != LAW_LINEAR else np.zeros(p.coef.shape[:-1] + (6,))
        object.__setattr__(p, "_law_columns", coef3)
    h = np.asarray(h, dtype=float)
    # condensed loads (S, G, m), one small product per sample and geometry: a sample's value
    # does not depend on its place in the batch (a BLAS product over the samples rounds rows
    # differently; equal samples must give equal results, bit for bit)
    hc = np.matmul(cd.M[None], h[..., None])[..., 0]
    out_h = np.sum(cd.out_hrow[None] * h, axis=2)
    K = np.asarray(step_g).size
    nd, nc, ng = cd.K.shape[1], np.shape(gap)[2], p.ngroups
    parts = _state_parts(nd, nc, ng)
    given = np.zeros(K, dtype=np.bool_)
    given_state = np.zeros((K, parts[-1].stop))
    if first is not None and K:
        at, q_, k_, kc_ = first
        given[at] = True
        given_state[at, parts[0]], given_state[at, parts[3]] = q_, k_
        given_state[at, parts[4]] = kc_
    args = (
        cd.K, cd.u, cd.reg, cd.contacts.index, np.ascontiguousarray(cd.contacts.value),
        cd.bearings.index, np.ascontiguousarray(cd.bearings.value),
        np.ascontiguousarray(p.bearing_k, dtype=float),
        np.ascontiguousarray(p.bearing_c, dtype=float), p.group.astype(np.int64), p.ngroups,
        int(p.law), coef3, float(p.start_stiffness), np.ascontiguousarray(hc),
        np.ascontiguousarray(en, dtype=float), np.ascontiguousarray(gap, dtype=float),
        np.asarray(step_g, dtype=np.int64), np.array(step_T, dtype=float), start, rec,
        int((rec >= 0).sum()), np.ascontiguousarray(cd.out_u), np.ascontiguousarray(out_h),
        np.ascontiguousarray(cd.out_q), float(tol), int(maxit), bool(exact), given_state, given,
        np.zeros((2, nc)) if p.law == LAW_SECANT_PER_CONTACT and exact else None,
    )  # fmt: skip
    # step_T a fresh C array: solve_system passes a read-only broadcast ('A' layout), the yield
    # a contiguous one; each compiled _solve_batch again (~7 s CPU, gear_chain's first run)
    if compiled:
        rot, forces, iters, ST = _solve_batch(*args)
    else:
        rot, forces, iters, ST = _plain()["_solve_batch"](*args)
    return (rot, forces, iters) + tuple(ST[:, part] for part in parts)


def _state_parts(nd: int, nc: int, ngroups: int) -> tuple[slice, ...]:
    """The parts of :func:`_solve_batch`'s state vector: displacements, contact forces,
    approaches, per-disc and per-contact stiffness."""
    ends = np.cumsum([0, nd, nc, nc, ngroups, nc])
    return tuple(slice(int(a), int(b)) for a, b in zip(ends[:-1], ends[1:], strict=True))


def solve_positions(
    system,
    torque: float | np.ndarray,
    law,
    *,
    q0: np.ndarray | None = None,
    k0: np.ndarray | None = None,
    tol: float = 1e-9,
    maxit: int = NEWTON_MAXIT,
    compiled: bool = True,
    method: str = "batched",
):
    """Quasi-static equilibrium at every position of ``system`` under output torque(s): the
    solver of ``load_sharing``, ``transmission_error`` and the catalogue loop.

    Result as :func:`gearte.solvers.rv_equilibrium.solve_positions`.

    Parameters
    ----------
    system : gearte.models.rv_load_sharing.RVSystem
        Spring and contact rows at ``P`` positions.
    torque : float or numpy.ndarray
        Output load torque, scalar or (P,) [N·mm].
    law : ContactLaw or a model-level law with ``for_system(system)``
        Pin-contact law.
    q0 : numpy.ndarray, optional
        Warm start of the first position: displacements [mm, rad].
    k0 : numpy.ndarray, optional
        Warm start of the first position: per-disc contact stiffness [N/mm].
    tol : float
        Relative tolerance of the contact-stiffness fixed point [-].
    maxit : int
        Most Newton iterations per solve [-] (default
        :data:`gearte.solvers.rv_equilibrium.NEWTON_MAXIT`).
    compiled : bool
        ``False`` runs the plain-Python twin [-].
    method : str
        ``"batched"`` (default, :func:`solve_system`: the positions as the steps of one sample
        of the batched kernel, condensed, Newton on the exact law where the law is per contact
        — the limit of the secant fixed point, equal to ``tol``) or ``"per_position"`` (the
        dense per-position kernel, the flat reference it is tested against) [-].
    """
    from gearte.solvers import rv_equilibrium

    if method == "batched":
        return solve_system(system, torque, law, q0=q0, k0=k0, tol=tol, maxit=maxit,
                            compiled=compiled)  # fmt: skip
    if method != "per_position":
        raise ParameterError("method", method, "must be 'batched' or 'per_position'")
    return rv_equilibrium.solve_positions(system, torque, law, q0=q0, k0=k0, tol=tol,
                                          maxit=maxit, compiled=compiled)  # fmt: skip


def solve_system(
    system,
    torque: float | np.ndarray,
    law,
    *,
    q0: np.ndarray | None = None,
    k0: np.ndarray | None = None,
    tol: float = 1e-9,
    maxit: int = NEWTON_MAXIT,
    compiled: bool = True,
    restart: int | None = None,
):
    """:func:`gearte.solvers.rv_equilibrium.solve_positions` through the batched kernel.

    The positions of ``system`` are the steps of one sample, each warm-started from the
    previous one (the first from ``q0``, ``k0`` or cold), solved condensed (:func:`condense`)
    with Newton on the exact law where the law is per contact (its limit is the per-case secant
    fixed point's: equal to ``tol``); the linear degrees of freedom are recovered exactly
    afterwards. Parameters and result as ``solve_positions`` (an
    :class:`~gearte.solvers.rv_equilibrium.EquilibriumSolution`); with a per-contact law each
    contact's secant stiffness is ``F/δ(F) = 1/(a0 − a1 ln F)`` where it is loaded, an open
    contact keeps its last loaded value (as the per-case fixed point), and the per-disc value is
    the stiffest loaded contact's.

    Parameters
    ----------
    system : gearte.models.rv_load_sharing.RVSystem
        Spring and contact rows at ``P`` positions.
    torque : float or numpy.ndarray
        Output load torque, scalar or (P,) [N·mm].
    law : ContactLaw or a model-level law with ``for_system(system)``
        Pin-contact law.
    q0 : numpy.ndarray, optional
        Warm start of the first position: displacements [mm, rad].
    k0 : numpy.ndarray, optional
        Warm start of the first position: per-disc contact stiffness [N/mm].
    tol : float
        Relative tolerance of the contact-stiffness fixed point [-].
    maxit : int
        Most Newton iterations per solve [-] (default
        :data:`gearte.solvers.rv_equilibrium.NEWTON_MAXIT`).
    compiled : bool
        ``False`` runs the plain-Python twin [-].
    restart : int, optional
        The positions are consecutive sweeps of ``restart`` positions each (``P`` a multiple
        of it), sweep ``i`` starting from row ``i`` of ``q0`` (W, nd) and ``k0`` (W, ngroups)
        — the same solutions as one call per sweep, in one kernel call (the TE's refinement
        windows). Default: one sweep.

    Raises
    ------
    ConvergenceError
        Naming the first position without an equilibrium.
    """
    from gearte.solvers.rv_equilibrium import EquilibriumSolution, as_solver_law

    law = as_solver_law(law, system)
    P = system.theta.size
    torque = np.broadcast_to(np.asarray(torque, dtype=float), (P,))
    problem, h, en, gap = problem_from_system(system, law)
    cd = _condensed(problem)
    nd, ng = problem.unit_load.size, problem.ngroups
    group = problem.group
    L = max(P, 1) if restart is None else int(restart)
    if restart is not None:
        if L != restart or L < 1 or P % L:
            raise ParameterError("restart", restart, f"must divide the {P} positions")
        if q0 is None or k0 is None:
            raise ParameterError("restart", restart, "needs q0 and k0, one row per sweep")
    W = 1 if restart is None else P // L
    kg0 = np.full((W, ng), law.stiffness) if k0 is None else np.asarray(k0, dtype=float)
    kg0 = kg0.reshape(W, ng)
    first = None
    if q0 is not None or k0 is not None:
        qs = np.zeros((W, nd)) if q0 is None else np.asarray(q0, dtype=float).reshape(W, nd)
        first = (np.arange(W) * L, qs[:, cd.keep], kg0, kg0[:, group])
    steps = np.arange(P)
    exact = problem.law == LAW_SECANT_PER_CONTACT
    _, _, iters, Q, F, _, KG, KC = _run(problem, h, en, gap, steps, torque, steps - 1,
                                        np.full(P, -1), tol, maxit, exact, compiled,
                                        first)  # fmt: skip
    iters = iters[0]
    if np.any(iters < 0):
        p = int(np.argmax(iters < 0))
        raise ConvergenceError(
            f"rv_equilibrium: no equilibrium at position {p} (theta = {system.theta[p]:.6f} rad) "
            f"within {maxit} Newton iterations / 200 stiffness iterations, tolerance {tol:g} "
            "(or a pin force beyond the range of the contact law)"
        )
    f0 = torque[:, None] * problem.unit_load[None] - h[0]
    q = np.empty((P, nd))
    q[:, cd.keep] = Q
    if cd.free.size:
        q[:, cd.free] = (np.matmul(cd.Kffinv, f0[:, cd.free, None])
                         - np.matmul(cd.KffKfc, Q[..., None]))[..., 0]  # fmt: skip
    if exact:
        # each contact's last loaded secant within its sweep (before the sweep's first loaded
        # step: the sweep's start stiffness); seg: the first step of each step's sweep
        sweep = steps // L
        seg = sweep * L
        loaded = F > 0.0
        sec = np.where(loaded, law.secant_stiffness(np.where(loaded, F, 1.0)), 0.0)
        last = np.maximum.accumulate(np.where(loaded, steps[:, None], seg[:, None] - 1), axis=0)
        KC = np.where(last >= seg[:, None], sec[np.maximum(last, 0), np.arange(F.shape[1])],
                      kg0[:, group][sweep])  # fmt: skip
        KG = np.empty((P, ng))
        for g in range(ng):
            kg = np.max(sec[:, group == g], axis=1, initial=0.0)
            last = np.maximum.accumulate(np.where(kg > 0.0, steps, seg - 1))
            KG[:, g] = np.where(last >= seg, kg[np.maximum(last, 0)], kg0[sweep, g])
    return EquilibriumSolution(q, F, KG, iters, KC)


_KERNELS = ("_solve_batch", "_newton", "_newton_mixed", "_energy", "_assemble",
            "_assemble_rows3", "_add_block3", "_rows_times",
            "_spd_solve", "_copy", "_rows_dot", "_law_force", "_law_force_start",
            "_log_update",
            "_bearing_terms", "_secant_update", "law_terms")  # fmt: skip


@functools.cache
def _plain() -> dict:
    """The plain-Python twins of :data:`_KERNELS` (:func:`gearte.solvers.twins.plain_twins`):
    ``_plain()["_solve_batch"]`` runs the batch with every kernel it calls as plain Python."""
    from gearte.solvers.twins import plain_twins

    return plain_twins(globals(), _KERNELS)
