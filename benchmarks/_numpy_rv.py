"""Plain numpy baselines of the RV quasi-static equilibrium, for the benchmarks.

What a competent numpy user would write for the same physics as
:mod:`gearte.solvers.rv_equilibrium` / :mod:`gearte.solvers.rv_batch` (linear springs and
unilateral pin contacts with the log law ``δ(F) = F (a0 − a1 ln F)``; clearance bearings are not
coded, the benchmarked case has none): an active-set Newton method with a backtracking line
search on the potential, **vectorised over a batch of independent systems** (samples of a
yield study at one step, or all output positions of one reducer): dense rows, batched
``np.matmul`` for the Hessians, batched ``np.linalg.solve``, masks for the systems still
iterating. Two contact-stiffness schemes:

* ``"exact"``: Newton on the exact law (tangent ``1/δ'(F)``, forces from a vectorised scalar
  Newton) — the algorithm of gearte's batched kernel;
* ``"secant"``: the per-contact secant fixed point around the active-set Newton with frozen
  stiffness — the algorithm of gearte's per-case solver.

:func:`solve_batch_numpy` (the yield benchmark's baseline) runs the algorithm of gearte's
batched kernel step for step: the problem condensed onto the degrees of freedom the contacts
touch (gearte's own :func:`~gearte.solvers.rv_batch.condense`, once per plan), Newton on the
equilibrium and the pin law together (:func:`newton_mixed`, gearte's ``_newton_mixed``: one
logarithm per closed contact and iteration, no line search, no inner law solves) with its
stopping rule, falling back to the line-searched Newton on Π (:func:`newton`) for the samples
that do not converge in 30 iterations — as the kernel does.
"""

from __future__ import annotations

import numpy as np


def law_force(d, a0, a1, guess=None):
    """F with F (a0 − a1 ln F) = d > 0, elementwise (vectorised monotone Newton on the entries
    not yet converged)."""
    d, a0, a1 = np.broadcast_arrays(d, a0, a1)
    F = d / np.maximum(a0 - a1 * np.log(np.maximum(d / a0, 1e-300)), 1e-300)
    if guess is not None:
        F = np.where(guess > 0, guess, F)
    F = F.ravel().copy()
    d, a0, a1 = d.ravel(), a0.ravel(), a1.ravel()
    idx = np.arange(F.size)
    for _ in range(100):
        if idx.size == 0:
            break
        f, dd, b0, b1 = F[idx], d[idx], a0[idx], a1[idx]
        lf = np.log(f)
        gp = b0 - b1 * lf - b1
        fn = np.where(gp > 0, f - (f * (b0 - b1 * lf) - dd) / np.where(gp > 0, gp, 1.0), 0.5 * f)
        fn = np.where(fn > 0, fn, 0.1 * f)
        F[idx] = fn
        idx = idx[np.abs(fn - f) > 1e-15 * f]
    return F.reshape(d.shape) if d.ndim == 1 else F


class Systems:
    """A batch of ``B`` systems: ``K0`` (B, nd, nd) or one shared (nd, nd), ``Bc`` (B, nc, nd)
    or shared (nc, nd), ``f0`` (B, nd), ``gap`` (B, nc), ``a0, a1`` (B, nc) or shared (nc,).
    Shared matrices go through single BLAS products (``q @ K0``, ``w @ (B ⊗ B)``)."""

    def __init__(self, K0, Bc, f0, gap, a0, a1):
        self.K0, self.Bc, self.f0, self.gap, self.a0, self.a1 = K0, Bc, f0, gap, a0, a1
        self.shared = K0.ndim == 2
        if self.shared:
            nc, nd = Bc.shape
            self.BB = np.einsum("ca,cb->cab", Bc, Bc).reshape(nc, nd * nd)
            self.reg = 1e-13 * np.abs(np.diag(K0)).max()
        else:
            self.reg = 1e-13 * np.abs(np.diagonal(K0, axis1=1, axis2=2)).max(axis=1)

    def take(self, i):
        s = Systems.__new__(Systems)
        s.shared = self.shared
        names = ("f0", "gap") if self.shared else ("K0", "Bc", "f0", "gap", "a0", "a1", "reg")
        for k in ("K0", "Bc", "f0", "gap", "a0", "a1", "reg", "BB"):
            if hasattr(self, k):
                setattr(s, k, getattr(self, k)[i] if k in names else getattr(self, k))
        return s

    def Kq(self, q):
        return q @ self.K0 if self.shared else np.matmul(self.K0, q[..., None])[..., 0]

    def Bq(self, q):
        return q @ self.Bc.T if self.shared else np.matmul(self.Bc, q[..., None])[..., 0]

    def BtF(self, F):
        return F @ self.Bc if self.shared else np.matmul(F[:, None, :], self.Bc)[:, 0]

    def hessian(self, w):
        nd = self.f0.shape[1]
        if self.shared:
            return self.K0 + (w @ self.BB).reshape(-1, nd, nd) + self.reg * np.eye(nd)
        H = self.K0 + np.matmul(self.Bc.transpose(0, 2, 1) * w[:, None, :], self.Bc)
        return H + self.reg[:, None, None] * np.eye(nd)


def _approach(s, q):
    return s.Bq(q) - s.gap


def _energy_exact(s, q, F):
    d = _approach(s, q)
    act = d > 0
    a0 = np.broadcast_to(s.a0, d.shape)[act]
    a1 = np.broadcast_to(s.a1, d.shape)[act]
    dd = d[act]
    dmax = a1 * np.exp(np.minimum((a0 - a1) / a1, 700.0))  # the law's range ends at δ(F*)
    inside = dd < dmax
    f = np.ones(dd.shape)
    f[inside] = law_force(dd[inside], a0[inside], a1[inside], F[act][inside])
    Fn = np.zeros(d.shape)
    Fn[act] = f
    phi = np.zeros(d.shape)
    phi[act] = np.where(inside, f * f * (0.5 * a0 - 0.5 * a1 * np.log(f) - 0.25 * a1), np.inf)
    e = np.sum(q * (0.5 * s.Kq(q) - s.f0), axis=1)
    return e + phi.sum(axis=1), Fn, d


def _energy_secant(s, q, kc):
    d = _approach(s, q)
    dp = np.maximum(d, 0.0)
    e = np.sum(q * (0.5 * s.Kq(q) - s.f0), axis=1)
    return e + 0.5 * np.sum(kc * dp * dp, axis=1), d


def newton(s, q, F=None, kc=None, scheme="exact", tol=1e-13, maxit=100):
    """Active-set Newton for every system of ``s`` from ``q`` (B, nd); returns (q, F, kc)."""
    B, nd = q.shape
    q = q.copy()
    F = np.zeros(s.gap.shape) if F is None else F.copy()
    live = np.arange(B)
    if scheme == "exact":
        e0, F, d = _energy_exact(s, q, F)
    else:
        e0, d = _energy_secant(s, q, kc)
    for _ in range(maxit):
        if live.size == 0:
            break
        t = s.take(live)
        ql, dl, el = q[live], d[live], e0[live]
        if scheme == "exact":
            Fl = F[live]
            act = dl > 0
            Fs = np.where(act, Fl, 1.0)
            w = np.where(act, 1.0 / (t.a0 - t.a1 * np.log(Fs) - t.a1), 0.0)
            force = Fl
        else:
            act = dl > 0
            w = np.where(act, kc[live], 0.0)
            force = w * dl
        H = t.hessian(w)
        g = t.Kq(ql) - t.f0 + t.BtF(force)
        dq = -np.linalg.solve(H, g[..., None])[..., 0]
        step = np.ones(live.size)
        accepted = np.zeros(live.size, bool)
        qn, e1 = ql + dq, el.copy()
        Fn, dn = (Fl.copy() if scheme == "exact" else None), dl.copy()
        pend = np.arange(live.size)
        for _ls in range(60):
            tt = t.take(pend)
            qt = ql[pend] + step[pend, None] * dq[pend]
            if scheme == "exact":
                with np.errstate(over="ignore", invalid="ignore"):
                    et, Ft, dt = _energy_exact(tt, qt, Fl[pend])
            else:
                et, dt = _energy_secant(tt, qt, kc[live][pend])
            ok = et <= el[pend] + 1e-12 * np.abs(el[pend])
            idx = pend[ok]
            accepted[idx] = True
            qn[idx], e1[idx], dn[idx] = qt[ok], et[ok], dt[ok]
            if scheme == "exact":
                Fn[idx] = Ft[ok]
            pend = pend[~ok]
            if pend.size == 0:
                break
            step[pend] *= 0.5
        stalled = el - e1 <= 1e-14 * np.abs(el)
        same = np.all((dn > 0) == (dl > 0), axis=1)
        big = np.max(np.abs(step[:, None] * dq), axis=1)
        q[live] = np.where(accepted[:, None], qn, ql)
        d[live] = np.where(accepted[:, None], dn, dl)
        e0[live] = np.where(accepted, e1, el)
        if scheme == "exact":
            F[live] = np.where(accepted[:, None], Fn, Fl)
            done = ~accepted | (big < tol) | (same & (step == 1.0) & (big < 1e-9))
        else:
            done = ~accepted | (big < tol) | (same & (step == 1.0)) | (same & stalled)
        live = live[~done]
    if scheme == "exact":
        F = np.where(d > 0, F, 0.0)
    return q, F, d


def solve(s, q0, scheme="exact", kstart=2.0e5, tol=1e-9):
    """Equilibrium of every system; ``"secant"`` iterates the per-contact secant stiffness to a
    relative change below ``tol``. Returns (q, F)."""
    if scheme == "exact":
        q, F, _ = newton(s, q0, F=None, scheme="exact")
        return q, F
    B = q0.shape[0]
    kc = np.full(s.gap.shape, kstart)
    q = q0.copy()
    live = np.arange(B)
    F = np.zeros(s.gap.shape)
    for _ in range(200):
        if live.size == 0:
            break
        t = s.take(live)
        ql, _, d = newton(t, q[live], kc=kc[live], scheme="secant")
        q[live] = ql
        f = kc[live] * np.maximum(d, 0.0)
        F[live] = f
        fs = np.where(f > 0, f, 1.0)
        knew = np.where(f > 0, 1.0 / (t.a0 - t.a1 * np.log(fs)), kc[live])
        change = np.max(np.abs(knew / kc[live] - 1.0), axis=1)
        kc[live] = knew
        live = live[change >= tol]
    return q, F


def dense_rows(sparse, nd):
    """Dense (G, R, nd) rows from :class:`gearte.solvers.rv_batch.SparseRows`."""
    G, R, W = sparse.value.shape
    out = np.zeros((G, R, nd))
    for r in range(R):
        for w in range(W):
            out[:, r, sparse.index[r, w]] += sparse.value[:, r, w]
    return out


def law_force_start(d, a0, a1):
    """One-term estimate of the force at approach ``d > 0`` (gearte's ``_law_force_start``)."""
    fstar = a1 * 0.0 + np.exp(np.minimum((a0 - a1) / a1, 700.0))
    den = a0 - a1 * np.log(np.maximum(d / np.maximum(a0, a1), 1e-300))
    return np.where(den > 0, d / np.where(den > 0, den, 1.0), 0.5 * fstar)


def newton_mixed(K, B, BB, reg, f0, gap, a0, a1, q, F, maxit=30):
    """gearte's ``_newton_mixed`` vectorised over the systems: unknowns ``q`` (S, m) and the
    forces ``F`` (S, nc) of the closed contacts, shared ``K`` (m, m), rows ``B`` (nc, m)
    (``BB`` (nc, m·m) their outer products), per-system load ``f0`` (S, m) and clearances
    ``gap`` (S, nc), law coefficients ``a0, a1`` (nc,). The systems that have converged leave
    the batch. Returns ``(q, F, iterations, failed)``; ``failed``: no convergence within
    ``maxit`` or a force beyond the law's range (state of those rows undefined)."""
    S, m = q.shape
    q, F = q.copy(), F.copy()
    its = np.zeros(S, np.int64)
    failed = np.zeros(S, bool)
    live = np.arange(S)
    ql, Fl, fl, gl = q, F, f0, gap
    d = ql @ B.T - gl
    eye = reg * np.eye(m)
    for it in range(maxit):
        closing = (Fl <= 0) & (d > 0)
        changed = closing.any(axis=1)
        if changed.any():
            Fl[closing] = law_force_start(
                d[closing], np.broadcast_to(a0, d.shape)[closing],
                np.broadcast_to(a1, d.shape)[closing],
            )  # fmt: skip
        act = Fl > 0
        rest = a0 - a1 * np.log(np.where(act, Fl, 1.0))  # δ/F
        slope = rest - a1  # δ'(F)
        bad = np.any(act & ~(slope > 0), axis=1)  # beyond the law's range
        k = np.where(act, 1.0 / np.where(slope > 0, slope, 1.0), 0.0)
        Ft = np.where(act, Fl + (d - Fl * rest) * k, 0.0)
        H = (k @ BB).reshape(-1, m, m) + (K + eye)
        grad = ql @ K - fl + Ft @ B
        dq = np.linalg.solve(H, grad[..., None])[..., 0]
        ql = ql - dq
        Bdq = dq @ B.T
        Fn = Ft - k * Bdq
        opened = np.any(act & ~(Fn > 0), axis=1)
        Fn = np.where(act & (Fn > 0), Fn, 0.0)
        fbig = np.max(np.abs(Fn - Fl), axis=1)
        done = ~(changed | opened) & (np.max(np.abs(dq), axis=1) < 1e-9)
        done &= fbig <= 1e-7 * np.max(Fn, axis=1)
        Fl, d = Fn, d - Bdq
        its[live] = it + 1
        out = done | bad
        if out.any():
            idx = live[out]
            q[idx], F[idx], failed[idx] = ql[out], Fl[out], bad[out]
            keep = ~out
            live, ql, Fl, fl, gl, d = live[keep], ql[keep], Fl[keep], fl[keep], gl[keep], d[keep]
            if live.size == 0:
                break
    failed[live] = True
    return q, F, its, failed


def solve_batch_numpy(
    problem, h, en, gap, step_g, step_T, cold, record, exact=True, start=None, **_
):
    """Drop-in for :func:`gearte.solvers.rv_batch.solve_batch`: every step solved for all
    samples at once (vectorised over samples) by gearte's batched algorithm (condensed,
    :func:`newton_mixed`, the line-searched :func:`newton` where that fails), warm-started along
    each sequence like gearte (``start``: the earlier step whose solution starts each step, −1
    cold; a step that repeats its start's geometry and torque keeps that solution, as gearte)."""
    from gearte.solvers.rv_batch import BatchSolution, _condensed

    if problem.bearing_k.size:
        raise NotImplementedError("the numpy baseline codes no clearance bearings")
    if not exact:
        return solve_batch_numpy_dense(problem, h, en, gap, step_g, step_T, cold, record,
                                       exact=exact, start=start)  # fmt: skip
    cd = _condensed(problem)  # once per problem (cached on it), as in gearte
    S = h.shape[0]
    m = cd.K.shape[1]
    Bd = dense_rows(cd.contacts, m)  # (G, nc, m)
    G, nc, _ = Bd.shape
    BB = np.einsum("gca,gcb->gcab", Bd, Bd).reshape(G, nc, m * m)
    hc = np.einsum("gmn,sgn->sgm", cd.M, h)  # condensed loads
    out_h = np.einsum("gn,sgn->sg", cd.out_hrow, h)
    a0s, a1s = problem.coef[..., 0], problem.coef[..., 1]
    K = len(step_g)
    rot = np.zeros((S, K))
    rec = np.flatnonzero(record)
    forces = np.zeros((S, rec.size, nc))
    iters = np.zeros((S, K), np.int64)
    if start is None:
        start = np.where(np.asarray(cold, bool), -1, np.arange(K) - 1)
    Q, FF = {}, {}
    for t in range(K):
        g, T, u = step_g[t], step_T[t], start[t]
        if u < 0:
            q, F = np.zeros((S, m)), np.zeros((S, nc))
        else:
            q, F = Q[u], FF[u]
        if not (u >= 0 and step_g[u] == g and step_T[u] == T):
            f0 = T * cd.u[g][None] - hc[:, g]
            q1, F1, its, failed = newton_mixed(cd.K[g], Bd[g], BB[g], cd.reg[g], f0, gap[:, g],
                                               a0s[g], a1s[g], q, F)  # fmt: skip
            if failed.any():  # the line-searched Newton on Π from the same start
                s = Systems(cd.K[g], Bd[g], f0[failed], gap[failed, g], a0s[g], a1s[g])
                s.reg = cd.reg[g]
                q1[failed], F1[failed], _ = newton(s, q[failed], F=F[failed], scheme="exact")
            q, F = q1, F1
            iters[:, t] = its
        Q[t], FF[t] = q, F
        rot[:, t] = T * cd.out_u[g] - out_h[:, g] + q @ cd.out_q[g]
        if record[t]:
            forces[:, int(np.searchsorted(rec, t))] = F
    return BatchSolution(rot, forces, iters)


def solve_batch_numpy_dense(
    problem, h, en, gap, step_g, step_T, cold, record, exact=True, start=None, **_
):
    """The earlier baseline (before 2026-11-26): the full (uncondensed) system and the
    line-searched Newton on Π with a vectorised scalar Newton for the forces at every trial
    point (``exact``), or the secant fixed point — gearte's batched algorithm before its
    rework; every step solved for all samples at once, warm-started like gearte."""
    from gearte.solvers.rv_batch import BatchSolution

    if problem.bearing_k.size:
        raise NotImplementedError("the numpy baseline codes no clearance bearings")
    S = h.shape[0]
    nd = problem.unit_load.size
    Bd = dense_rows(problem.contacts, nd)
    nc = Bd.shape[1]
    K = len(step_g)
    rot = np.zeros((S, K))
    rec = np.flatnonzero(record)
    forces = np.zeros((S, rec.size, nc))
    q = np.zeros((S, nd))
    F = np.zeros((S, nc))
    if start is None:
        start = np.where(np.asarray(cold, bool), -1, np.arange(K) - 1)
    Q, FF = {}, {}
    for t in range(K):
        g = step_g[t]
        if start[t] < 0:
            q, F = np.zeros((S, nd)), np.zeros((S, nc))
        else:
            q, F = Q[start[t]].copy(), FF[start[t]].copy()
        s = Systems(
            problem.K0[g],
            Bd[g],
            step_T[t] * problem.unit_load[None] - h[:, g],
            gap[:, g],
            problem.coef[g, :, 0],
            problem.coef[g, :, 1],
        )
        if exact:
            q, F, _ = newton(s, q, F=F, scheme="exact")
        else:
            q, F = solve(s, q, scheme="secant", kstart=problem.start_stiffness)
        Q[t], FF[t] = q, F
        rot[:, t] = q[:, problem.output]
        if record[t]:
            forces[:, int(np.searchsorted(rec, t))] = F
    return BatchSolution(rot, forces, np.zeros((S, K), np.int64))


def newton_mixed_each(K, B, reg, f0, gap, a0, a1, q, F, maxit=30):
    """:func:`newton_mixed` where every system has its own matrix ``K`` (S, m, m), rows ``B``
    (S, nc, m), regularisation ``reg`` (S,) and law ``a0, a1`` (S, nc) — the positions of one
    reducer, each its own geometry — started from ``q`` (S, m) and ``F`` (S, nc). Returns
    ``(q, F, iterations, failed)`` as :func:`newton_mixed`."""
    S, nc, m = B.shape
    q, F = np.array(q, dtype=float), np.array(F, dtype=float)
    its = np.zeros(S, np.int64)
    failed = np.zeros(S, bool)
    live = np.arange(S)
    Kl, Bl, rl, fl, gl, b0, b1 = K, B, reg, f0, gap, a0, a1
    ql, Fl = q.copy(), F.copy()
    d = np.matmul(Bl, ql[..., None])[..., 0] - gl
    eye = np.eye(m)
    for it in range(maxit):
        closing = (Fl <= 0) & (d > 0)
        changed = closing.any(axis=1)
        if changed.any():
            Fl[closing] = law_force_start(d[closing], b0[closing], b1[closing])
        act = Fl > 0
        rest = b0 - b1 * np.log(np.where(act, Fl, 1.0))  # δ/F
        slope = rest - b1  # δ'(F)
        bad = np.any(act & ~(slope > 0), axis=1)  # beyond the law's range
        k = np.where(act, 1.0 / np.where(slope > 0, slope, 1.0), 0.0)
        Ft = np.where(act, Fl + (d - Fl * rest) * k, 0.0)
        H = Kl + np.matmul(Bl.transpose(0, 2, 1) * k[:, None, :], Bl) + rl[:, None, None] * eye
        grad = np.matmul(Kl, ql[..., None])[..., 0] - fl + np.matmul(Ft[:, None, :], Bl)[:, 0]
        dq = np.linalg.solve(H, grad[..., None])[..., 0]
        ql = ql - dq
        Bdq = np.matmul(Bl, dq[..., None])[..., 0]
        Fn = Ft - k * Bdq
        opened = np.any(act & ~(Fn > 0), axis=1)
        Fn = np.where(act & (Fn > 0), Fn, 0.0)
        fbig = np.max(np.abs(Fn - Fl), axis=1)
        done = ~(changed | opened) & (np.max(np.abs(dq), axis=1) < 1e-9)
        done &= fbig <= 1e-7 * np.max(Fn, axis=1)
        Fl, d = Fn, d - Bdq
        its[live] = it + 1
        out = done | bad
        if out.any():
            idx = live[out]
            q[idx], F[idx], failed[idx] = ql[out], Fl[out], bad[out]
            keep = ~out
            live = live[keep]
            ql, Fl, d = ql[keep], Fl[keep], d[keep]
            Kl, Bl, rl, fl, gl, b0, b1 = (a[keep] for a in (Kl, Bl, rl, fl, gl, b0, b1))
            if live.size == 0:
                break
    failed[live] = True
    return q, F, its, failed


def solve_positions_numpy(problem, h, gap, torque):
    """The output rotation [rad] at every position of one reducer (the ``G`` geometries of
    ``problem``, its sample 0: ``h`` (1, G, nd), ``gap`` (1, G, nc)) under ``torque`` [N·mm]:
    gearte's batched algorithm (condensed onto the contact degrees of freedom with gearte's
    own :func:`~gearte.solvers.rv_batch.condense`, Newton on the equilibrium and the pin law
    together, the line-searched Newton on Π where that fails), **vectorised over the
    positions**: the first position solved cold, then every position at once from its answer
    (the positions are independent and alike: numpy gains more from one batched solve than from
    warm starts one position after the other). Returns ``(rotation (G,), forces (G, nc))``."""
    from gearte.solvers.rv_batch import _condensed

    if problem.bearing_k.size:
        raise NotImplementedError("the numpy baseline codes no clearance bearings")
    cd = _condensed(problem)
    m = cd.K.shape[1]
    Bd = dense_rows(cd.contacts, m)  # (G, nc, m)
    hc = np.einsum("gmn,gn->gm", cd.M, h[0])  # condensed loads
    out_h = np.einsum("gn,gn->g", cd.out_hrow, h[0])
    f0 = torque * cd.u - hc
    a0, a1 = problem.coef[..., 0], problem.coef[..., 1]
    # the first position cold, by the line-searched Newton on Π; every position from its answer
    s0 = Systems(cd.K[:1], Bd[:1], f0[:1], gap[0][:1], a0[:1], a1[:1])
    s0.reg = cd.reg[:1]
    q0, F0, _ = newton(s0, np.zeros((1, m)), scheme="exact")
    G = f0.shape[0]
    q, F, _, failed = newton_mixed_each(cd.K, Bd, cd.reg, f0, gap[0], a0, a1,
                                        np.repeat(q0, G, 0), np.repeat(F0, G, 0))  # fmt: skip
    if failed.any():  # the line-searched Newton on Π from the same start
        s = Systems(cd.K[failed], Bd[failed], f0[failed], gap[0][failed], a0[failed], a1[failed])
        s.reg = cd.reg[failed]
        m_f = int(failed.sum())
        q[failed], F[failed], _ = newton(s, np.repeat(q0, m_f, 0), F=np.repeat(F0, m_f, 0),
                                         scheme="exact")  # fmt: skip
    rot = torque * cd.out_u - out_h + np.einsum("gm,gm->g", q, cd.out_q)
    return rot, F
