"""Benchmark: tooth contact analysis at 1000 mesh positions over one tooth pitch.

Runs gearte's compiled load-sharing solver (numba, all positions in one call) and, in the same
run, a plain-Python per-pin baseline (the readable twin: pin-by-pin residual, bisection), on the
Hu et al. 2020 Table 3 stage at T = 1011.5 N·m. Prints both warm times and the ratio.

    PYTHONPATH=src python benchmarks/bench_cycloid_contact.py
"""

from __future__ import annotations

import time

import numpy as np

from gearte.geometry.cycloid import CycloidStage
from gearte.models.cycloid_contact import tooth_contact

N_POSITIONS = 1000
GOAL_S = 0.050


def _best(fn, repeat: int) -> float:
    best = float("inf")
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        best = min(best, time.perf_counter() - t0)
    return best


def main() -> None:
    stage = CycloidStage(z_p=40, r_p=76.0, r_rp=3.0, a=1.5, b=11.0, dr_rp=-0.022, dr_p=-0.0437)
    torque = 1011.5e3  # N·mm (fitted to Hu et al.'s Tables 4-5, examples/hu2020_rv80e_initial.toml)
    paper = dict(disc_share=0.55, E=2.06e5, mu=0.3)  # Hu et al. 2020 section 4
    theta = np.arange(N_POSITIONS) * (2 * np.pi / stage.z_p) / N_POSITIONS

    def fast():
        return tooth_contact(stage, torque, **paper, mesh_angle=theta, contact_law="hu2020")

    def plain():
        return tooth_contact(
            stage, torque, **paper, mesh_angle=theta, implementation="plain", contact_law="hu2020"
        )

    t0 = time.perf_counter()
    res = fast()  # compile (or load the cache) and warm up
    t_first = time.perf_counter() - t0
    t_fast = _best(fast, 7)
    t_plain = _best(plain, 1)
    ref = plain()
    err = float(np.max(np.abs(res.F_max - ref.F_max) / ref.F_max))

    print(f"tooth contact, {N_POSITIONS} mesh positions over one pitch, z_p = {stage.z_p}")
    print(f"  first call (compile/cache load): {t_first * 1e3:9.1f} ms")
    print(
        f"  gearte (numba, warm, best of 7): {t_fast * 1e3:9.2f} ms "
        f"(goal <= {GOAL_S * 1e3:.0f} ms: {'met' if t_fast <= GOAL_S else 'NOT met'})"
    )
    print(f"  plain Python per-pin baseline:   {t_plain * 1e3:9.1f} ms")
    print(f"  ratio baseline / gearte:         {t_plain / t_fast:9.1f} x")
    print(f"  max relative difference F_max:   {err:9.2e}")
    print(
        f"  F_max over the pitch: {res.F_max.min():.1f} .. {res.F_max.max():.1f} N, "
        f"pins in mesh {res.pins_in_mesh.min()} .. {res.pins_in_mesh.max()}"
    )


if __name__ == "__main__":
    main()
