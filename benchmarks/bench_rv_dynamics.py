"""RV reducer dynamics (issue 6, paper 004): compiled integrator vs solve_ivp, and error batches.

1. One output revolution at 1500 rpm input (4.84 s simulated + 0.1 s settling) of the paper's
   prototype with the Table 3 errors: compiled RK4 kernel (goal ≤ 1 s on one core) against
   ``scipy.integrate.solve_ivp`` (RK45) on the plain-Python right-hand side, in the same run
   (goal ≥ 200×), both DTEs printed. The plain baseline needs minutes for the full span, so by
   default it runs ``--baseline-span`` seconds and its time is scaled to the full span (its step
   is bound by stability, so its cost is linear in the span); ``--full-baseline`` runs it all.
2. Right-hand side alone (goal ≤ 2 µs per evaluation), timed in a compiled loop.
3. Compile (or cache-load) time of the kernels, reported separately.
4. Batch: ``--samples`` (64) random error realisations on 2 threads vs one after another;
   aggregate simulated seconds per wall second (goal ≥ 50); and a batch of 2 at the default chunk
   size on 1 and 2 workers (issue 12 goal: ≥ 1.6× on 2 workers).
5. Strong baselines (issue 12), same run, CPU seconds: a hand-written numba RK4 loop on the same
   compiled right-hand side and step, reducing the DTE to its extremes (gearte's RK4 goal: within
   1.5× of it), and ``solve_ivp`` (RK45 and DOP853, rtol 1e-6) on the compiled right-hand side
   (on ``--baseline-span`` s, scaled).

Run: ``PYTHONPATH=src python benchmarks/bench_rv_dynamics.py [--full-baseline]``.
"""

from __future__ import annotations

import argparse
import time

import numpy as np
from numba import njit

from gearte.models.rv_dynamics import RHS_WORK_SIZE, rv_dte, rv_rhs
from gearte.runners.rv_dynamics_sim import default_step, dte_batch, ode_system
from gearte.solvers.ode import integrate, kernels
from gearte.studies._rv_dynamics import batch_tolerances
from gearte.studies.rv_reducer import load_dynamic_model
from gearte.units import ARCSEC_PER_RAD


@njit(cache=True, nogil=True)
def _rhs_loop(n, y, args, out, work):
    acc = 0.0
    for k in range(n):
        y[0] = 1e-9 * k
        rv_rhs(1e-6 * k, y, args, out, work)  # a new time every call: no memo hits
        acc += out[-1]
    return acc


@njit(nogil=True)
def _rk4_hand(y0, t0, dt, n_steps, settle_steps, args, work_size):
    """The plainest RK4 a numba user writes on gearte's compiled rhs: fixed step, DTE extremes
    after settling; returns (max - min) of the DTE [rad]."""
    n = y0.size
    work = np.full(work_size, np.nan)
    y = y0.copy()
    k1 = np.empty(n)
    k2 = np.empty(n)
    k3 = np.empty(n)
    k4 = np.empty(n)
    tmp = np.empty(n)
    lo, hi = np.inf, -np.inf
    for s in range(n_steps):
        t = t0 + s * dt
        rv_rhs(t, y, args, k1, work)
        for i in range(n):
            tmp[i] = y[i] + 0.5 * dt * k1[i]
        rv_rhs(t + 0.5 * dt, tmp, args, k2, work)
        for i in range(n):
            tmp[i] = y[i] + 0.5 * dt * k2[i]
        rv_rhs(t + 0.5 * dt, tmp, args, k3, work)
        for i in range(n):
            tmp[i] = y[i] + dt * k3[i]
        rv_rhs(t0 + (s + 1) * dt, tmp, args, k4, work)
        for i in range(n):
            y[i] += dt / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i])
        if s + 1 >= settle_steps:
            o = rv_dte(t0 + (s + 1) * dt, y, args)
            lo = min(lo, o)
            hi = max(hi, o)
    return hi - lo


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--baseline-span", type=float, default=0.02, help="simulated s for solve_ivp")
    ap.add_argument("--full-baseline", action="store_true", help="run solve_ivp on the full span")
    ap.add_argument("--samples", type=int, default=64)
    ap.add_argument("--batch-duration", type=float, default=1.0, help="simulated s/realisation")
    ap.add_argument("--workers", type=int, default=2)
    a = ap.parse_args()

    model, red = load_dynamic_model("li2023_rv_errors")  # Li 2023 Tables 1-3, mean k_cr
    system = ode_system(model)
    dt = default_step(model)
    q0 = model.static_equilibrium(0.0)
    y0 = np.concatenate([q0, np.zeros_like(q0)])
    settle, span = 0.1, 4.84
    print(f"model: {model.n_dof} DOF, RK4 step {dt:.3g} s (0.85 × stability limit)")

    # compile / cache load, reported separately
    t0 = time.perf_counter()
    rk4, _ = kernels(system.rhs, system.output, system.key)
    integrate(system, y0, (0.0, 10 * dt), method="rk4", dt=dt)
    t_compile = time.perf_counter() - t0
    hits = sum(rk4.stats.cache_hits.values())
    how = "cache hit" if hits else "compiled"
    print(f"kernel compile/cache load      : {t_compile:8.3f} s ({how})")

    # right-hand side alone
    args = system.args
    out = np.empty_like(y0)
    work = np.full(RHS_WORK_SIZE, np.nan)
    _rhs_loop(10, y0.copy(), args, out, work)
    n = 200_000
    t0 = time.perf_counter()
    _rhs_loop(n, y0.copy(), args, out, work)
    t_rhs = (time.perf_counter() - t0) / n
    yy = y0.copy()
    t0 = time.perf_counter()
    for _ in range(200):
        model.rhs_numpy(0.01, yy)
    t_rhs_py = (time.perf_counter() - t0) / 200
    print(f"rhs compiled, new t every call : {t_rhs * 1e6:8.3f} µs (goal ≤ 2 µs)")
    print(f"rhs plain Python (element loop): {t_rhs_py * 1e6:8.1f} µs")

    # compiled path, full revolution
    t0 = time.perf_counter()
    r = integrate(system, y0, (0.0, settle + span), method="rk4", dt=dt, t_settle=settle)
    t_fast = time.perf_counter() - t0
    p2p = r.stats["peak_to_peak"] * ARCSEC_PER_RAD
    print(f"RK4 cost per rhs evaluation    : {t_fast / r.n_rhs * 1e6:8.3f} µs (with the memo)")
    print(
        f"compiled RK4, {span + settle:.2f} s simulated : {t_fast:8.3f} s "
        f"(goal ≤ 1 s), DTE p2p {p2p:.3f}″ (paper 17.25″)"
    )

    # strong baselines: hand-written numba RK4, solve_ivp on the compiled rhs
    n_steps = int(round((settle + span) / dt))
    settle_steps = int(round(settle / dt))
    _rk4_hand(y0, 0.0, dt, 10, 0, args, RHS_WORK_SIZE)  # compile
    c0 = time.process_time()
    p2p_hand = _rk4_hand(y0, 0.0, dt, n_steps, settle_steps, args, RHS_WORK_SIZE)
    c_hand = time.process_time() - c0
    c0 = time.process_time()
    integrate(system, y0, (0.0, settle + span), method="rk4", dt=dt, t_settle=settle)
    c_fast = time.process_time() - c0
    print(
        f"hand-written numba RK4, same rhs/step: {c_hand:8.3f} s CPU (gearte {c_fast:.3f} s CPU:"
        f" {c_fast / c_hand:.2f}× of it, goal ≤ 1.5×), DTE p2p {p2p_hand * ARCSEC_PER_RAD:.3f}″"
    )
    from scipy.integrate import solve_ivp

    w = np.full(RHS_WORK_SIZE, np.nan)

    def f_numba(t, y):
        d = np.empty_like(y)
        rv_rhs(t, y, args, d, w)
        return d

    for meth in ("RK45", "DOP853"):
        c0 = time.process_time()
        sol = solve_ivp(f_numba, (0.0, a.baseline_span), y0, method=meth, rtol=1e-6, atol=1e-10)
        c_ivp = (time.process_time() - c0) * (settle + span) / a.baseline_span
        print(
            f"solve_ivp {meth:6s} on the numba rhs : {c_ivp:8.1f} s CPU for the full span (scaled "
            f"from {a.baseline_span:g} s, {sol.nfev} rhs calls): gearte {c_ivp / c_fast:.0f}×"
        )

    # baseline: solve_ivp on the plain-Python rhs
    b_total = span + settle if a.full_baseline else a.baseline_span
    b_settle = settle if a.full_baseline else 0.25 * b_total
    t0 = time.perf_counter()
    rb = integrate(
        system,
        y0,
        (0.0, b_total),
        method="scipy",
        rtol=1e-6,
        atol=1e-10,
        t_settle=b_settle,
        record_dt=dt,
    )
    t_base = time.perf_counter() - t0
    rc = integrate(system, y0, (0.0, b_total), method="rk4", dt=dt, t_settle=b_settle)
    scale = (span + settle) / b_total
    t_base_full = t_base * scale
    print(
        f"solve_ivp RK45 plain rhs, {b_total:.3g} s: {t_base:8.2f} s, {rb.n_rhs} rhs calls; DTE "
        f"p2p {rb.stats['peak_to_peak'] * ARCSEC_PER_RAD:.4f}″ vs compiled RK4 "
        f"{rc.stats['peak_to_peak'] * ARCSEC_PER_RAD:.4f}″ on the same span"
    )
    kind = "measured" if a.full_baseline else f"scaled ×{scale:.1f} from the short span"
    print(f"baseline for the full span     : {t_base_full:8.1f} s ({kind})")
    print(f"speed-up compiled / baseline   : {t_base_full / t_fast:8.0f}× (goal ≥ 200×)")

    # batch of error realisations
    kw = dict(seed=1, duration_s=a.batch_duration, settle_s=settle, chunk_size=4, dt=dt)
    kw["tolerances"] = batch_tolerances(red)
    dte_batch(model, 2, workers=1, **kw)  # warm the threads' first call
    r1 = dte_batch(model, a.samples, workers=1, **kw)
    r2 = dte_batch(model, a.samples, workers=a.workers, **kw)
    same = np.array_equal(r1["rows"], r2["rows"])
    diff = float(np.max(np.abs(r1["rows"] - r2["rows"])))
    print(f"batch rows identical for 1 and {a.workers} workers: {same} (max diff {diff:.3g})")
    for lab, rr in (("one after another", r1), (f"{a.workers} threads", r2)):
        print(
            f"batch {a.samples} realisations, {lab:17s}: {rr['wall_s']:7.2f} s wall, "
            f"{rr['simulated_s'] / rr['wall_s']:7.1f} sim-s/s (goal ≥ 50 aggregate)"
        )
    print(f"batch speed-up threads / sequential: {r1['wall_s'] / r2['wall_s']:.2f}×")
    kw2 = {k: v for k, v in kw.items() if k != "chunk_size"}  # the default chunk size
    b1 = dte_batch(model, 2, workers=1, **kw2)
    b2 = dte_batch(model, 2, workers=2, **kw2)
    print(
        f"batch of 2, default chunks: 1 worker {b1['wall_s']:.2f} s, 2 workers {b2['wall_s']:.2f}"
        f" s wall: {b1['wall_s'] / b2['wall_s']:.2f}× (goal ≥ 1.6×; needs 2 idle cores)"
    )
    print(
        f"DTE p2p over realisations: mean {r2['peak_to_peak_mean']:.2f}″, sd "
        f"{r2['peak_to_peak_sd']:.2f}″, max {r2['peak_to_peak_max']:.2f}″"
    )


if __name__ == "__main__":
    main()
