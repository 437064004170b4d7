"""Equilibrium of spring rows + unilateral contacts with a load-dependent contact stiffness.

Solves, at each output position ``p``, for the displacement ``q`` minimising the potential

``Π(q) = ½ Σ_s k_s (B_s q + e_s)² + ½ Σ_c k_g(c) max(B_c q − g_c, 0)² − T uᵀ q``

(springs ``s``, contacts ``c`` grouped by disc ``g``), i.e. the quasi-static equilibrium with
unilateral pin contacts. For a fixed contact stiffness Π is convex and piecewise quadratic; it
is minimised by an active-set (semismooth) Newton method with a backtracking line search on Π,
which terminates when the active set repeats — the solution is then exact to round-off.

The contact stiffness is load dependent: a contact law
``δ(F) = F (a0 − a1 ln F) + a2 F^a3`` whose coefficients ``(a0, a1, a2, a3)`` per position and
contact are computed by the caller (:func:`gearte.models.contact_law.law_coefficients`, the one
implementation of every pin law; this solver only evaluates that form: the logarithmic laws have
``a2 = 0``, Palmgren's power law ``a0 = a1 = 0``, and a linear series compliance adds to
``a0``). Two secant schemes: ``"secant_per_disc"`` — one stiffness per disc
``k_g = F_max,g / δ(F_max,g)`` (Hu et al. 2020 section 4, with ρ(φ0)) — and
``"secant_per_contact"`` — each contact its own ``k_c = F_c / δ_c(F_c)`` with its own
coefficients (its own flank curvature). This outer fixed point is a contraction (the secant
stiffness varies with ``ln F``) and is iterated to a relative change below ``tol``. Positions are
solved in sequence, each warm-started from the previous one.

A compiled kernel (numba) and its plain-Python twin (``_plain()["_solve_all"]``) run the same
algorithm; :func:`solve_reference` is an independent scipy check.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np

from gearte._jit import inner_kernel, kernel
from gearte.errors import ConvergenceError, ParameterError
from gearte.solvers.dense import dot, max_abs, solve_spd_into

__all__ = ["ContactLaw", "EquilibriumSolution", "solve_positions", "solve_reference"]

LAW_LINEAR = 0
LAW_SECANT_PER_DISC = 1
LAW_SECANT_PER_CONTACT = 2
_SCHEMES = {
    "linear": LAW_LINEAR,
    "secant_per_disc": LAW_SECANT_PER_DISC,
    "secant_per_contact": LAW_SECANT_PER_CONTACT,
}
#: Stiffness left inside a bearing clearance, relative to the bearing's stiffness. It keeps the
#: equilibrium unique when parts float in their clearances (at zero load); its force is below
#: 1e-6 k c (< 1 N for 10 µm at 1e5 N/mm).
CLEARANCE_RESIDUAL = 1e-6
#: Most Newton iterations per solve: the ``maxit`` default of every RV equilibrium solver.
#: Newton with a line search on the strictly convex Π converges from any start, but where parts
#: float in their bearing clearances (a small torque) and the start is far (a sweep's cold first
#: position) it crosses the clearances' kinks many times and converges linearly: the bundled
#: serial without its crank-bore file took 150 iterations at 0.1 % of its torque (the cap was
#: 100, docs/metrology.md). A solve that converges stops where it did before; the cap only ends
#: one that does not.
NEWTON_MAXIT = 1000


@dataclass(frozen=True)
class ContactLaw:
    """Pin-contact stiffness law as the solver sees it.

    Attributes
    ----------
    kind : str
        ``"linear"`` (constant ``stiffness``), ``"secant_per_disc"`` (per-disc secant stiffness at
        the disc's largest pin force) or ``"secant_per_contact"`` (each contact its own secant).
    stiffness : float
        Constant stiffness for ``"linear"`` [N/mm]; starting value otherwise.
    a0, a1 : array_like
        Coefficients of the logarithmic part ``F (a0 − a1 ln F)`` of ``δ(F)`` [mm/N],
        broadcastable to (positions, contacts); from
        :func:`gearte.models.contact_law.law_coefficients`.
    a2, a3 : array_like
        Coefficient [mm/N^a3] and exponent [-] of the power part ``a2 F^a3`` of ``δ(F)``
        (Palmgren's line contact: ``a3 = 0.9``); ``a2 = 0`` for the logarithmic laws.
    name : str
        Name of the physical law (echoed in results; ``"linear"`` for a constant stiffness).
    """

    kind: str = "secant_per_contact"
    stiffness: float = 2.0e5
    a0: np.ndarray | float = 0.0
    a1: np.ndarray | float = 0.0
    name: str = ""
    a2: np.ndarray | float = 0.0
    a3: np.ndarray | float = 1.0

    @property
    def code(self) -> int:
        if self.kind not in _SCHEMES:
            raise ParameterError("contact_law.kind", self.kind, f"must be one of {list(_SCHEMES)}")
        return _SCHEMES[self.kind]

    def coefficients(self, n_positions: int, n_contacts: int) -> np.ndarray:
        """``(P, nc, 4)`` array of (a0, a1, a2, a3) per position and contact.

        Accepted: all finite; either the logarithmic law (``a1 > 0``, ``a2 = 0``) or a power
        law (``a1 = 0``, ``a2 > 0``, ``0 < a3 ≤ 1``, ``a0 ≥ 0``: a linear series compliance),
        so that δ(F) increases from 0 (the power law without a limit, the logarithmic one up to
        ``F* = exp(a0/a1 − 1)``)."""
        shape = (n_positions, n_contacts)
        if self.code == LAW_LINEAR:
            return np.zeros(shape + (N_COEF,))
        cols = [np.broadcast_to(np.asarray(x, dtype=float), shape)
                for x in (self.a0, self.a1, self.a2, self.a3)]  # fmt: skip
        a0, a1, a2, a3 = cols
        log_law = (a1 > 0.0) & (a2 == 0.0)
        power_law = (a1 == 0.0) & (a2 > 0.0) & (a3 > 0.0) & (a3 <= 1.0) & (a0 >= 0.0)
        if not (all(np.all(np.isfinite(x)) for x in cols) and np.all(log_law | power_law)):
            raise ParameterError(
                "contact_law.a0/a1/a2/a3",
                (self.a0, self.a1, self.a2, self.a3),
                "must be finite: a1 > 0 and a2 = 0 (logarithmic law), or a1 = 0, a2 > 0, "
                "0 < a3 <= 1 and a0 >= 0 (power law)",
            )
        return np.ascontiguousarray(np.stack(cols, axis=-1))

    def secant_stiffness(self, F: np.ndarray) -> np.ndarray:
        """Secant stiffness ``F/δ(F)`` [N/mm] at forces ``F`` > 0 (broadcast with the
        coefficients; not for ``"linear"``)."""
        lf = np.log(F)
        return 1.0 / (self.a0 - self.a1 * lf + self.a2 * np.exp((self.a3 - 1.0) * lf))

    def tangent_stiffness(self, F: np.ndarray) -> np.ndarray:
        """Tangent stiffness ``1/δ'(F)`` [N/mm] at forces ``F`` > 0 (as
        :meth:`secant_stiffness`)."""
        lf = np.log(F)
        power = self.a2 * np.exp((self.a3 - 1.0) * lf)
        return 1.0 / (self.a0 - self.a1 * lf - self.a1 + self.a3 * power)


@dataclass(frozen=True)
class EquilibriumSolution:
    """Solution at ``P`` positions.

    Attributes
    ----------
    q : (P, nd) displacements [mm, rad].
    contact_force : (P, nc) [N].
    contact_stiffness : (P, ngroups) [N/mm] (per disc; with a per-contact law the stiffest
        loaded contact's secant).
    pin_stiffness : (P, nc) secant stiffness of every contact [N/mm].
    iterations : (P,) Newton iterations used (summed over the stiffness fixed point).
    """

    q: np.ndarray
    contact_force: np.ndarray
    contact_stiffness: np.ndarray
    iterations: np.ndarray
    pin_stiffness: np.ndarray | None = None


#: Columns of a contact's coefficients: (a0, a1, a2, a3) of δ(F) = F (a0 − a1 ln F) + a2 F^a3.
N_COEF = 4


@inner_kernel
def law_terms(lf, a0, a1, a2, a3):
    """``(δ/F, δ'(F))`` of the law ``δ(F) = F (a0 − a1 ln F) + a2 F^a3`` at ``lf = ln F``.

    ``δ/F = a0 − a1 ln F + a2 F^(a3−1)`` [mm/N] and ``δ' = a0 − a1 ln F − a1 + a3 a2 F^(a3−1)``
    [mm/N]; the power part (one ``exp``) only where ``a2 ≠ 0``. Shared by this module's
    kernels and the batched solver (:mod:`gearte.solvers.rv_batch`)."""
    rest = a0 - a1 * lf
    slope = rest - a1
    if a2 != 0.0:
        p = a2 * np.exp((a3 - 1.0) * lf)
        rest += p
        slope += a3 * p
    return rest, slope


@kernel
def law_delta(f, a0, a1, a2, a3):
    """Approach ``δ = F (a0 − a1 ln F) + a2 F^a3`` [mm] of the solver's law form at ``F = f``."""
    return f * law_terms(np.log(f), a0, a1, a2, a3)[0]


@inner_kernel
def _secant_update(law, force, coef, group, ngroups, k, kc):
    """One step of the secant fixed point of the law: the new stiffnesses from ``force``.

    ``LAW_SECANT_PER_DISC``: each disc (``group``) its secant ``F/δ(F)`` at its largest pin
    force (that contact's coefficients), copied to its contacts' ``kc``; otherwise
    (``LAW_SECANT_PER_CONTACT``) each loaded contact its own secant, and ``k`` per disc the
    stiffest loaded contact's (reported). Updates ``k`` and ``kc`` in place; returns the
    largest relative change of a stiffness and ``False`` (leaving them part-updated) where a
    force lies beyond the law's range (``a0 − a1 ln F ≤ a1``: δ(F) no longer increasing).
    Shared by :func:`_solve_all` and the batched solver (:mod:`gearte.solvers.rv_batch`)."""
    change = 0.0
    nc = force.size
    if law == LAW_SECANT_PER_DISC:
        for g in range(ngroups):
            fmax = 0.0
            cm = -1
            for c in range(nc):
                if group[c] == g and force[c] > fmax:
                    fmax = force[c]
                    cm = c
            if fmax > 0.0:
                rest, slope = law_terms(np.log(fmax), coef[cm, 0], coef[cm, 1], coef[cm, 2],
                                        coef[cm, 3])  # fmt: skip
                if slope <= 0.0:
                    return change, False
                knew = 1.0 / rest
                change = max(change, abs(knew / k[g] - 1.0))
                k[g] = knew
        for c in range(nc):
            kc[c] = k[group[c]]
    else:
        for c in range(nc):
            if force[c] > 0.0:
                rest, slope = law_terms(np.log(force[c]), coef[c, 0], coef[c, 1], coef[c, 2],
                                        coef[c, 3])  # fmt: skip
                if slope <= 0.0:
                    return change, False
                knew = 1.0 / rest
                change = max(change, abs(knew / kc[c] - 1.0))
                kc[c] = knew
        for g in range(ngroups):
            kg = 0.0
            for c in range(nc):
                if group[c] == g and force[c] > 0.0 and kc[c] > kg:
                    kg = kc[c]
            if kg > 0.0:
                k[g] = kg
    return change, True


@inner_kernel
def _energy(K0, f0, Bn, en, kn, cn, Bc, gc, kc, q):
    """Π(q) (scalar loops: no array expressions, cheap to compile; ``docs/numba.md``)."""
    nd = q.size
    e = 0.0
    for a in range(nd):
        e += 0.5 * q[a] * dot(K0[a], q)
    e -= dot(f0, q)
    for c in range(gc.size):
        d = dot(Bc[c], q) - gc[c]
        if d > 0.0:
            e += 0.5 * kc[c] * d * d
    for m in range(kn.size):
        wx = dot(Bn[m, 0], q) + en[m, 0]
        wy = dot(Bn[m, 1], q) + en[m, 1]
        rr = wx * wx + wy * wy
        e += 0.5 * CLEARANCE_RESIDUAL * kn[m] * rr
        r = np.sqrt(rr) - cn[m]
        if r > 0.0:
            e += 0.5 * (1.0 - CLEARANCE_RESIDUAL) * kn[m] * r * r
    return e


@inner_kernel
def _bearing_terms(wx, wy, k, c):
    """Gradient (gx, gy) and Hessian (hxx, hyy, hxy) in w-space of a bearing with radial
    clearance ``c`` [mm] and stiffness ``k`` [N/mm] at relative displacement (wx, wy) [mm]:
    k (|w| − c) u and k [s I + (1 − s) u uᵀ] beyond the clearance, plus the residual
    stiffness CLEARANCE_RESIDUAL·k everywhere (s = 1 − c/|w|, u = w/|w|)."""
    rr = np.sqrt(wx * wx + wy * wy)
    k0 = CLEARANCE_RESIDUAL * k
    gx, gy = k0 * wx, k0 * wy
    hxx, hyy, hxy = k0, k0, 0.0
    if rr > c:
        k1 = k - k0
        ux, uy = wx / rr, wy / rr
        s = 1.0 - c / rr
        gx += k1 * (rr - c) * ux
        gy += k1 * (rr - c) * uy
        hxx += k1 * (s + (1.0 - s) * ux * ux)
        hyy += k1 * (s + (1.0 - s) * uy * uy)
        hxy += k1 * (1.0 - s) * ux * uy
    return gx, gy, hxx, hyy, hxy


@inner_kernel
def _newton(K0, f0, Bn, en, kn, cn, Bc, gc, kc, q, tol, maxit):
    """Minimise Π for fixed contact stiffness; returns (q, iterations, ok).

    ``Bn, en, kn, cn``: isotropic bearings with radial clearance, energy
    ``ε k |w|²/2 + (1 − ε) k (|w| − c)₊² / 2`` with ``w = (Bn[m,0]·q + en[m,0], Bn[m,1]·q +
    en[m,1])`` and ``ε = CLEARANCE_RESIDUAL`` (convex: squared distance to a disc). The Newton
    system is solved by Cholesky (:func:`gearte.solvers.dense.solve_spd_into`, as the batched
    kernel of :mod:`gearte.solvers.rv_batch`); scalar loops throughout (``docs/numba.md``).
    """
    nd = q.size
    nc = gc.size
    nm = kn.size
    reg = 0.0
    for a in range(nd):
        reg = max(reg, abs(K0[a, a]))
    reg *= 1e-13
    active = np.zeros(nc, dtype=np.bool_)
    d = np.empty(nc)
    H = np.empty((nd, nd))
    L = np.empty((nd, nd))
    grad = np.empty(nd)
    dq = np.empty(nd)
    for c in range(nc):
        d[c] = dot(Bc[c], q) - gc[c]
        active[c] = d[c] > 0.0
    for it in range(maxit):
        for a in range(nd):
            grad[a] = dot(K0[a], q) - f0[a]
            for b in range(nd):
                H[a, b] = K0[a, b]
        for c in range(nc):
            if active[c]:
                w = kc[c] * d[c]
                for a in range(nd):
                    grad[a] += w * Bc[c, a]
                    ba = kc[c] * Bc[c, a]
                    for b in range(nd):
                        H[a, b] += ba * Bc[c, b]
        for m in range(nm):
            wx = dot(Bn[m, 0], q) + en[m, 0]
            wy = dot(Bn[m, 1], q) + en[m, 1]
            gx, gy, hxx, hyy, hxy = _bearing_terms(wx, wy, kn[m], cn[m])
            for a in range(nd):
                bx, by = Bn[m, 0, a], Bn[m, 1, a]
                grad[a] += gx * bx + gy * by
                ta = hxx * bx + hxy * by
                tb = hxy * bx + hyy * by
                for b in range(nd):
                    H[a, b] += ta * Bn[m, 0, b] + tb * Bn[m, 1, b]
        for a in range(nd):
            H[a, a] += reg
        solve_spd_into(H, grad, L, dq)
        for a in range(nd):
            dq[a] = -dq[a]
        # backtracking line search on the convex potential
        e0 = _energy(K0, f0, Bn, en, kn, cn, Bc, gc, kc, q)
        step = 1.0
        qn = np.empty(nd)
        for a in range(nd):
            qn[a] = q[a] + dq[a]
        decreased = False
        e1 = e0
        for _ in range(60):
            e1 = _energy(K0, f0, Bn, en, kn, cn, Bc, gc, kc, qn)
            if e1 <= e0 + 1e-12 * abs(e0):
                decreased = True
                break
            step *= 0.5
            for a in range(nd):
                qn[a] = q[a] + step * dq[a]
        if not decreased:
            # no descent left at round-off level: q is the minimiser to machine precision
            return q, it + 1, True
        stalled = e0 - e1 <= 1e-14 * abs(e0)
        q = qn
        same = True
        for c in range(nc):
            d[c] = dot(Bc[c], q) - gc[c]
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


@kernel
def _solve_all(
    K0s, f0s, Bns, ens, kn, cn, Bcs, gcs, group, ngroups, law, coefs, k0, q0, tol, maxit
):
    """Every position in turn, each warm-started from the previous one: Newton (:func:`_newton`)
    inside, the fixed point on the contact stiffness outside.

    ``law``: LAW_LINEAR (``k0`` per disc, fixed), LAW_SECANT_PER_DISC (per-disc secant at the
    disc's largest force, with that contact's coefficients) or LAW_SECANT_PER_CONTACT (``kc``
    per contact). Returns (q, forces, k per disc, kc per contact, iterations) per position;
    iterations −1 at the first position without an equilibrium (the later ones are not solved).

    One kernel for the positions and the fixed point (it was two): numba links and re-optimises
    every callee's code into each caller, so a level less saves seconds of first-run compile
    (``docs/numba.md``).
    """
    P = K0s.shape[0]
    nd = q0.size
    nc = gcs.shape[1]
    Q = np.zeros((P, nd))
    F = np.zeros((P, nc))
    Ks = np.zeros((P, ngroups))
    KC = np.zeros((P, nc))
    its = np.zeros(P, dtype=np.int64)
    q = q0.copy()
    k = k0.copy()
    kc = np.empty(nc)
    force = np.zeros(nc)
    for c in range(nc):
        kc[c] = k[group[c]]
    for p in range(P):
        Bc = Bcs[p]
        gc = gcs[p]
        coef = coefs[p]
        if law != LAW_SECANT_PER_CONTACT:
            for c in range(nc):
                kc[c] = k[group[c]]
        total = 0
        qtol = 1e-13 * max(1.0, max_abs(q))
        ok = False
        for _outer in range(200):
            q, n, converged = _newton(K0s[p], f0s[p], Bns[p], ens[p], kn, cn, Bc, gc, kc, q,
                                      qtol, maxit)  # fmt: skip
            total += n
            if not converged:
                break
            for c in range(nc):
                d = dot(Bc[c], q) - gc[c]
                force[c] = kc[c] * d if d > 0.0 else 0.0
            if law == LAW_LINEAR:
                ok = True
                break
            change, in_range = _secant_update(law, force, coef, group, ngroups, k, kc)
            if not in_range:
                break
            if change < tol:
                for c in range(nc):
                    d = dot(Bc[c], q) - gc[c]
                    force[c] = kc[c] * d if d > 0.0 else 0.0
                ok = True
                break
        if not ok:
            its[p] = -1
            return Q, F, Ks, KC, its
        for a in range(nd):
            Q[p, a] = q[a]
        for c in range(nc):
            F[p, c] = force[c]
            KC[p, c] = kc[c]
        for g in range(ngroups):
            Ks[p, g] = k[g]
        its[p] = total
    return Q, F, Ks, KC, its


def as_solver_law(law, system) -> ContactLaw:
    """``law`` itself, or the solver law a model-level law builds for ``system``.

    A model-level law (e.g. :class:`gearte.models.rv_load_sharing.PinContactLaw`) provides
    ``for_system(system) -> ContactLaw`` (the law's coefficients at the system's contacts); the
    solver does not import the model.
    """
    if isinstance(law, ContactLaw):
        return law
    build = getattr(law, "for_system", None)
    if build is None:
        raise ParameterError("law", law, "must be a ContactLaw or provide for_system(system)")
    return build(system)


def _split_springs(system):
    """Linear rows and clearance pairs of a system (pairs: consecutive x, y rows with c > 0)."""
    c = getattr(system, "spring_c", None)
    ns = system.spring_k.size
    c = np.zeros(ns) if c is None else np.asarray(c, dtype=float)
    lin = c == 0.0
    first = np.flatnonzero(~lin)[::2]
    Bn = np.ascontiguousarray(
        np.stack([system.spring_B[:, first], system.spring_B[:, first + 1]], 2)
    )
    en = np.ascontiguousarray(
        np.stack([system.spring_e[:, first], system.spring_e[:, first + 1]], 2)
    )
    return lin, Bn, en, system.spring_k[first].copy(), c[first].copy()


def _linear_parts(spring_B, spring_e, spring_k, load):
    """``K0 = Σ k B Bᵀ`` and ``f0 = load − Σ k e B`` per position."""
    kBt = (spring_B * spring_k[None, :, None]).transpose(0, 2, 1)
    K0 = np.matmul(kBt, spring_B)  # batched BLAS products (einsum does not use BLAS here)
    f0 = load - np.matmul(kBt, spring_e[..., None])[..., 0]
    return np.ascontiguousarray(K0), np.ascontiguousarray(f0)


def solve_positions(
    system,
    torque: float | np.ndarray,
    law: ContactLaw,
    *,
    q0: np.ndarray | None = None,
    k0: np.ndarray | None = None,
    tol: float = 1e-9,
    maxit: int = NEWTON_MAXIT,
    compiled: bool = True,
) -> EquilibriumSolution:
    """Quasi-static equilibrium at every position of ``system`` under output torque(s), by the
    dense per-position kernel (the secant fixed point around an active-set Newton): the flat
    reference of :func:`gearte.solvers.rv_batch.solve_positions`, which the models call.

    Parameters
    ----------
    system : gearte.models.rv_load_sharing.RVSystem
        Spring and contact rows at ``P`` positions.
    torque : float or (P,) array
        Output load torque [N·mm] (positive resists the drive; may change sign along a sweep).
    law : ContactLaw or a model-level law with ``for_system(system)``
    q0, k0 : arrays, optional
        Warm start for the first position: displacements [mm, rad] and per-disc contact
        stiffness [N/mm].
    tol : float
        Relative tolerance of the contact-stiffness fixed point [-].
    maxit : int
        Most Newton iterations per solve [-] (default :data:`NEWTON_MAXIT`).
    compiled : bool
        ``False`` runs the plain-Python twin of the same kernel (for tests).
    Raises
    ------
    ConvergenceError
        If Newton or the stiffness fixed point fails at some position.
    """
    P = system.theta.size
    law = as_solver_law(law, system)
    torque = np.broadcast_to(np.asarray(torque, dtype=float), (P,))
    load = torque[:, None] * system.unit_load[None, :]
    lin, Bn, en, kn, cn = _split_springs(system)
    K0, f0 = _linear_parts(
        system.spring_B[:, lin], system.spring_e[:, lin], system.spring_k[lin], load
    )
    ngroups = int(system.contact_group.max()) + 1
    nd = K0.shape[1]
    q0 = np.zeros(nd) if q0 is None else np.asarray(q0, dtype=float)
    k0 = np.full(ngroups, law.stiffness) if k0 is None else np.asarray(k0, dtype=float)
    coefs = law.coefficients(P, system.contact_gap.shape[1])
    fn = _solve_all if compiled else _plain()["_solve_all"]
    out = fn(
        K0, f0, Bn, en, kn, cn, np.ascontiguousarray(system.contact_B),
        np.ascontiguousarray(system.contact_gap), system.contact_group.astype(np.int64),
        ngroups, law.code, coefs, k0, q0, tol, maxit,
    )  # fmt: skip
    Q, F, Ks, KC, its = out
    if np.any(its < 0):
        p = int(np.argmax(its < 0))
        raise ConvergenceError(
            f"rv_equilibrium: no equilibrium at position {p} (theta = {system.theta[p]:.6f} rad) "
            f"within {maxit} Newton iterations / 200 stiffness iterations, tolerance {tol:g} "
            "(or a pin force beyond the range of the contact law)"
        )
    return EquilibriumSolution(Q, F, Ks, its, KC)


def solve_reference(system, torque: float, law: ContactLaw, p: int = 0, k=None, tol: float = 1e-10):
    """Independent check at one position with ``scipy.optimize.root`` on the equilibrium.

    Uses the *given* contact stiffness ``k`` (fixed; per disc, or per contact), residual
    ``K0 q − f0 + Σ k max(Bq − g, 0) B + Σ_bearings k (|w| − c)₊ ŵ·B``. Returns ``q``.

    The residual is only piecewise smooth (contacts open and close), so MINPACK's ``hybr`` may
    stall near a kink ("not making good progress"); it is then restarted from its last iterate
    with Levenberg–Marquardt (``lm``). The answer is accepted on its scaled residual, not on the
    solvers' own flags: ``‖r(q)‖∞ ≤ tol`` or :class:`~gearte.errors.ConvergenceError`.

    Parameters
    ----------
    system : gearte.models.rv_load_sharing.RVSystem
        Spring and contact rows.
    torque : float
        Output load torque [N·mm].
    law : ContactLaw
        The contact law (its stiffness scheme).
    p : int
        The position checked [-].
    k : array_like, optional
        Fixed contact stiffness [N/mm], per disc or per contact.
    tol : float
        Accepted scaled residual ‖r(q)‖∞ [-].

    Returns
    -------
    numpy.ndarray
        q, the displacements [mm, rad].
    """
    from scipy.optimize import root

    law = as_solver_law(law, system)
    load = torque * system.unit_load[None, :]
    lin, Bn, en, kn, cn = _split_springs(system)
    K0, f0 = _linear_parts(
        system.spring_B[p : p + 1, lin], system.spring_e[p : p + 1, lin], system.spring_k[lin], load
    )
    K0, f0 = K0[0], f0[0]
    Bn, en = Bn[p], en[p]
    Bc, gc = system.contact_B[p], system.contact_gap[p]
    ngroups = int(system.contact_group.max()) + 1
    k = np.full(ngroups, law.stiffness) if k is None else np.asarray(k, dtype=float)
    kc = k if k.size == gc.size != ngroups else k[system.contact_group]
    scale = np.max(np.abs(np.diag(K0)))

    def res(q):
        d = Bc @ q - gc
        r = K0 @ q - f0 + Bc.T @ (kc * np.maximum(d, 0.0))
        w = np.einsum("mxi,i->mx", Bn, q) + en
        n = np.linalg.norm(w, axis=1)
        eps = CLEARANCE_RESIDUAL
        gain = eps * kn + (1 - eps) * kn * np.maximum(n - cn, 0.0) / np.where(n > 0, n, 1.0)
        f = gain[:, None] * w
        return (r + np.einsum("mxi,mx->i", Bn, f)) / scale

    q = np.zeros(K0.shape[0])
    worst = np.inf
    for method in ("hybr", "lm"):
        sol = root(res, q, method=method, options={"xtol": 1e-14})
        q = sol.x
        worst = float(np.max(np.abs(res(q))))
        if worst <= tol:
            return q
    raise ConvergenceError(
        f"solve_reference: scipy root (hybr, then lm) stopped at scaled residual {worst:.3e} "
        f"> tol {tol:.1e} at position {p}"
    )


@functools.cache
def _plain() -> dict:
    """The plain-Python twins of the kernels (:func:`gearte.solvers.twins.plain_twins`):
    ``_plain()["_solve_all"]`` runs the solve with its inner kernels as plain Python too."""
    from gearte.solvers.twins import plain_twins

    return plain_twins(
        globals(), ("_solve_all", "_newton", "_energy", "law_terms", "_secant_update")
    )
