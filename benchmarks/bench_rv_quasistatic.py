"""Benchmark: quasi-static RV load sharing at 360 output positions.

gearte: compiled active-set Newton kernel, warm-started from position to position, contact
stiffness fixed point inside the kernel. Baseline, measured in the same run: a plain
``scipy.optimize.fsolve`` per position (cold start) on the same residual, inside the same
contact-stiffness fixed point. Both solve the han2023_rv110e case (with its measured errors) at
rated torque; the script checks they agree and prints both times and the ratio.

    PYTHONPATH=src python benchmarks/bench_rv_quasistatic.py
"""

from __future__ import annotations

import time
import warnings

import numpy as np
from scipy.optimize import fsolve

from gearte.io.case_file import load_case
from gearte.models.rv_load_sharing import assemble, contact_law, output_positions
from gearte.solvers.rv_equilibrium import _law_delta, _linear_parts, solve_positions
from gearte.studies.rv_reducer import build_reducer


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
                    a0, a1 = coef[p][group == g][np.argmax(f[group == g])]
                    knew[g] = fm / _law_delta(fm, a0, a1)
            done = np.max(np.abs(knew / k - 1.0)) < 1e-9
            k = knew
            if done:
                break
        out[p] = q
    return out


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
    print("RV quasi-static load sharing, han2023_rv110e with errors, 360 output positions")
    print(f"  gearte (numba active-set Newton, warm start): {t_gearte * 1e3:9.2f} ms")
    print(f"  baseline (scipy fsolve per position, cold):    {t_base * 1e3:9.2f} ms")
    print(f"  ratio baseline/gearte: {t_base / t_gearte:8.1f}x")
    print(f"  max |output angle difference|: {diff:.2e} rad")


if __name__ == "__main__":
    main()
