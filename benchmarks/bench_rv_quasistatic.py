"""Benchmark: quasi-static RV load sharing at 360 output positions (issue 12).

Part 1 (Hu 2020's per-disc law, the scheme the weak baseline codes): gearte's per-case compiled
active-set Newton kernel (warm-started from position to position, contact-stiffness fixed point
inside the kernel) against a plain ``scipy.optimize.fsolve`` per position (cold start) on the
same residual inside the same fixed point — the weak baseline.

Part 2 (the default textbook line-contact law, each contact its own stiffness): numpy
baselines vectorised over all 360 positions at once (dense rows, batched ``np.matmul`` Hessians
and ``np.linalg.solve``, masks for the positions still iterating; ``benchmarks/_numpy_rv.py``):
the full-DOF active-set Newton started cold, with the per-contact secant fixed point (the
per-case algorithm) and with Newton on the exact law, and the strongest, gearte's own batched
algorithm in numpy (:func:`_numpy_rv.solve_positions_numpy`: condensed onto the contact
degrees of freedom, Newton on the equilibrium and the law together, every position at once from
the first one's answer; its set-up from the assembled system timed, as gearte's); against gearte's
:func:`gearte.solvers.rv_batch.solve_positions` — the path ``load_sharing`` and so
``gearte run`` of an rv_reducer case take: the positions as the steps of one sample of the
batched kernel (condensed onto the disc degrees of freedom, exact law, warm-started along the
positions), its set-up from the assembled system included — its former dense per-position
kernel (``method="per_position"``, the secant fixed point), and the batched kernel alone
(:func:`gearte.solvers.rv_batch.solve_batch` on a prepared problem). All solve han2023_rv110e
(with its measured errors) at rated torque; the script checks they agree and prints the times
(CPU, best of 3–5) and ratios. BLAS runs single-threaded (``OPENBLAS_NUM_THREADS=1`` unless set).

    PYTHONPATH=src python benchmarks/bench_rv_quasistatic.py
"""

from __future__ import annotations

import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
os.environ.setdefault("OMP_NUM_THREADS", "1")

import time  # noqa: E402
import warnings  # noqa: E402

import numpy as np  # noqa: E402
from scipy.optimize import fsolve  # noqa: E402

from _numpy_rv import Systems, dense_rows, solve_positions_numpy  # noqa: E402
from _numpy_rv import solve as numpy_solve  # noqa: E402
from gearte.io.case_file import load_case  # noqa: E402
from gearte.models.rv_load_sharing import assemble, contact_law, output_positions  # noqa: E402
from gearte.solvers.rv_batch import (  # noqa: E402
    problem_from_system,
    solve_batch,
    solve_positions,
)
from gearte.solvers.rv_equilibrium import (  # noqa: E402
    _linear_parts,
    law_delta,
)
from gearte.studies.rv_reducer import build_reducer  # noqa: E402


def baseline(system, torque, law):
    """fsolve per position, cold start, outer fixed point on the per-disc stiffness (Hu 2020)."""
    P = system.theta.size
    load = torque * system.unit_load[None, :]
    K0s, f0s = _linear_parts(
        system.spring_B, system.spring_e, system.spring_k, load
    )  # no clearance
    group = system.contact_group
    ng = int(group.max()) + 1
    coef = law.coefficients(P, system.contact_gap.shape[1])
    out = np.zeros((P, K0s.shape[1]))
    for p in range(P):
        K0, f0, Bc, gc = K0s[p], f0s[p], system.contact_B[p], system.contact_gap[p]
        scale = np.max(np.abs(np.diag(K0)))
        k = np.full(ng, law.stiffness)
        q = np.zeros(K0.shape[0])
        for _ in range(200):
            kc = k[group]

            def res(x, kc=kc, K0=K0, f0=f0, Bc=Bc, gc=gc, scale=scale):
                d = Bc @ x - gc
                return (K0 @ x - f0 + Bc.T @ (kc * np.maximum(d, 0.0))) / scale

            with warnings.catch_warnings():  # fsolve may report slow progress near kinks
                warnings.simplefilter("ignore", RuntimeWarning)
                q = fsolve(res, np.zeros_like(q), xtol=1e-12)
            f = kc * np.maximum(Bc @ q - gc, 0.0)
            knew = k.copy()
            for g in range(ng):
                fm = f[group == g].max()
                if fm > 0:
                    a0, a1, a2, a3 = coef[p][group == g][np.argmax(f[group == g])]
                    knew[g] = fm / law_delta(fm, a0, a1, a2, a3)
            done = np.max(np.abs(knew / k - 1.0)) < 1e-9
            k = knew
            if done:
                break
        out[p] = q
    return out


def _best(fn, reps: int) -> float:
    best = np.inf
    for _ in range(reps):
        t0 = time.process_time()
        fn()
        best = min(best, time.process_time() - t0)
    return best


def part2(red, system, T) -> None:
    """Strong baselines on the line-contact law (see the module docstring)."""
    law = contact_law(red, "line_contact").for_system(system)  # the law the baselines code
    P = system.theta.size
    sol = solve_positions(system, T, law, method="per_position")  # compiles / loads the cache
    solve_positions(system, T, law)
    prob, h, en, gap = problem_from_system(system, law)
    steps = np.arange(P)
    cold = steps == 0

    def batched():
        return solve_batch(prob, h, en, gap, steps, np.full(P, T), cold)

    bsol = batched()
    t_case = _best(lambda: solve_positions(system, T, law), 5)
    t_pp = _best(lambda: solve_positions(system, T, law, method="per_position"), 3)
    d_case = np.max(np.abs(solve_positions(system, T, law).q[:, system.layout.output_rotation]
                           - sol.q[:, system.layout.output_rotation]))  # fmt: skip
    t_batch = _best(batched, 5)
    load = T * system.unit_load[None, :]
    K0, f0 = _linear_parts(system.spring_B, system.spring_e, system.spring_k, load)
    nd = K0.shape[1]
    Bd = dense_rows(prob.contacts, nd)
    coef = law.coefficients(P, system.contact_gap.shape[1])
    s = Systems(K0, Bd, f0, system.contact_gap, coef[..., 0], coef[..., 1])
    out = system.layout.output_rotation
    res = {}
    for scheme in ("secant", "exact"):

        def run(scheme=scheme):
            with np.errstate(over="ignore", invalid="ignore"):
                return numpy_solve(s, np.zeros((P, nd)), scheme=scheme, kstart=law.stiffness)[0]

        q = run()
        res[scheme] = (_best(run, 3), np.max(np.abs(q[:, out] - sol.q[:, out])))
    d_batch = np.max(np.abs(bsol.output[0] - sol.q[:, out]))

    def condensed():  # from the assembled system, as solve_positions: set-up and condensation
        prob_n, h_n, _, gap_n = problem_from_system(system, law)
        return solve_positions_numpy(prob_n, h_n, gap_n, T)[0]

    with np.errstate(over="ignore", invalid="ignore"):
        rot_n = condensed()
        res["condensed"] = (_best(condensed, 5), np.max(np.abs(rot_n - sol.q[:, out])))
    print("Part 2: line-contact law (per-contact secant), 360 positions, strong baselines "
          f"(CPU time, best of 3-5; load average {os.getloadavg()[0]:.1f})")  # fmt: skip
    print(f"  gearte solve_positions (gearte run's path):    {t_case * 1e3:9.2f} ms"
          f"   (|Δ output angle| {d_case:.1e} rad)")  # fmt: skip
    print(f"  gearte per-position kernel (secant, before):   {t_pp * 1e3:9.2f} ms")
    print(f"  gearte batched kernel (exact-law Newton):      {t_batch * 1e3:9.2f} ms"
          f"   (|Δ output angle| {d_batch:.1e} rad)")  # fmt: skip
    what = {
        "secant": "numpy full-DOF active-set Newton, secant, cold",
        "exact": "numpy full-DOF active-set Newton, exact law, cold",
        "condensed": "numpy, gearte's algorithm (condensed, mixed Newton), all positions at once",
    }
    for scheme, (t, d) in res.items():
        print(f"  {what[scheme]}: {t * 1e3:9.2f} ms   (|Δ output angle| {d:.1e} rad)")
    for scheme, (t, _) in res.items():
        print(f"  ratio numpy ({scheme}) / gearte solve_positions: {t / t_case:7.1f}x;"
              f"  / per-position kernel: {t / t_pp:6.1f}x;  / batched kernel alone: "
              f"{t / t_batch:6.1f}x")  # fmt: skip
    best = min(t for t, _ in res.values())  # the fastest numpy baseline: the strong one
    name = min(res, key=lambda k: res[k][0])
    for label, t in (("solve_positions (the path of gearte run's load_sharing)", t_case),
                     ("batched kernel alone", t_batch)):  # fmt: skip
        r = best / t
        print(f"goal (issue 12) quasi-static >= 8x the strongest numpy baseline ({name}), "
              f"{label}: measured {r:.1f}x per core (one thread each) — "
              f"{'met' if r >= 8 else 'NOT met'}")  # fmt: skip


def main() -> None:
    red = build_reducer(load_case("han2023_rv110e").reducer)
    T = red.rated_torque
    system = assemble(red, output_positions(360))
    law = contact_law(red, "hu2020").for_system(system)  # the per-disc scheme the baseline codes
    solve_positions(system, T, law)  # compile / load the numba cache outside the timing

    t0 = time.perf_counter()
    reps = 5
    for _ in range(reps):
        sol = solve_positions(system, T, law)
    t_gearte = (time.perf_counter() - t0) / reps

    t0 = time.perf_counter()
    q_ref = baseline(system, T, law)
    t_base = time.perf_counter() - t0

    out = system.layout.output_rotation
    diff = np.max(np.abs(sol.q[:, out] - q_ref[:, out]))
    print("Part 1: RV quasi-static load sharing, han2023_rv110e with errors, 360 output positions")
    print(f"  gearte (numba active-set Newton, warm start): {t_gearte * 1e3:9.2f} ms")
    print(f"  baseline (scipy fsolve per position, cold):    {t_base * 1e3:9.2f} ms")
    print(f"  ratio baseline/gearte: {t_base / t_gearte:8.1f}x")
    print(f"  max |output angle difference|: {diff:.2e} rad")
    part2(red, system, T)


if __name__ == "__main__":
    main()
