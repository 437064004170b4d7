"""Spur-pair Monte-Carlo throughput (issue 3: goal ≥ 10 M samples/s on 2 cores, ≥ 100× a loop).

gearte: :func:`gearte.tolerance.montecarlo.monte_carlo` on the spur pair of Jiang et al. (2024),
Tables 1-2 (7 contributors; the three "Rayleigh magnitude × uniform phase" terms drawn as their
exactly equivalent normal — the polar draw is timed too), 1e7 samples in 1e6-sample chunks on
the local threads (numba ``nogil`` kernel drawing from
numpy Generators, in-kernel reduction).

Baseline, same run: the plain per-sample Python loop
(:func:`gearte.tolerance.montecarlo.linear_stack_reference`, which makes the same Generator calls
and gives bit-identical samples) on a smaller n, its rate extrapolated. For reference also the
vectorised numpy path (``engine="numpy"``).

Run: ``PYTHONPATH=src python benchmarks/bench_tolerance_mc.py [--samples 1e7] [--workers N]``
"""

from __future__ import annotations

import argparse
import math
import time

import numpy as np

from gearte.models.backlash import SpurGear, SpurPair
from gearte.studies import RunOptions
from gearte.tolerance.distributions import RadialPhase
from gearte.tolerance.montecarlo import linear_stack_reference, monte_carlo
from gearte.tolerance.stackup import Contributor, LinearStack

UM = 1e-3


def spur_stack():
    pair = SpurPair(
        SpurGear(28, -19 * UM, -30 * UM, 27 * UM),
        SpurGear(110, -21 * UM, -32 * UM, 31 * UM),
        2.5,
        math.radians(20),
        20 * UM,
        (2 * UM, 30 * UM),
        8 * UM,
        15 * UM,
    )
    return pair.backlash_stack()


def polar(stack: LinearStack) -> LinearStack:
    """The same stack with eccentricities drawn as Rayleigh magnitude × sin(uniform phase)."""
    cs = [
        Contributor(c.name, RadialPhase(c.distribution.magnitude, polar=True), c.sensitivity)
        if isinstance(c.distribution, RadialPhase)
        else c
        for c in stack.contributors
    ]
    return LinearStack(cs, stack.constant)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--samples", type=float, default=1e7)
    ap.add_argument("--loop-samples", type=int, default=50_000)
    ap.add_argument("--workers", type=int, default=None)
    args = ap.parse_args()
    n = int(args.samples)
    st = spur_stack()
    opts = RunOptions(progress=False, workers=args.workers)

    monte_carlo(st, 20_000, seed=0, options=opts)  # compile / load the numba cache
    t0 = time.perf_counter()
    r = monte_carlo(st, n, seed=2024, options=opts)
    t_gearte = time.perf_counter() - t0
    rate = n / t_gearte

    stp = polar(st)
    monte_carlo(stp, 20_000, seed=0, options=opts)
    n_p = min(n, 4_000_000)
    t0 = time.perf_counter()
    monte_carlo(stp, n_p, seed=2024, options=opts)
    rate_polar = n_p / (time.perf_counter() - t0)

    t0 = time.perf_counter()
    linear_stack_reference(st, np.random.default_rng(1), args.loop_samples)
    t_loop = time.perf_counter() - t0
    rate_loop = args.loop_samples / t_loop

    n_np = min(n, 2_000_000)
    t0 = time.perf_counter()
    monte_carlo(st, n_np, seed=2024, engine="numpy", options=opts)
    rate_np = n_np / (time.perf_counter() - t0)

    print(f"spur-pair Monte-Carlo, {r.n:.3g} samples, engine {r.engine}, workers {args.workers}")
    print(
        f"  mean {r.mean * 1e3:.3f} µm (analytic {st.mean * 1e3:.3f}), "
        f"sd {r.sd * 1e3:.3f} µm (analytic {st.sd * 1e3:.3f})"
    )
    print(f"gearte kernel      : {t_gearte:8.3f} s  {rate / 1e6:8.2f} M samples/s (goal >= 10)")
    print(
        f"kernel, polar draw : {n_p / rate_polar:8.3f} s  {rate_polar / 1e6:8.2f} M samples/s "
        f"({n_p:.3g} samples; eccentricities as Rayleigh × sin(uniform phase))"
    )
    print(
        f"numpy vectorised   : {n_np / rate_np:8.3f} s  {rate_np / 1e6:8.2f} M samples/s "
        f"({n_np:.3g} samples)"
    )
    print(
        f"python loop        : {t_loop:8.3f} s  {rate_loop / 1e6:8.4f} M samples/s "
        f"({args.loop_samples} samples; 1e7 would take {n / rate_loop:.0f} s)"
    )
    print(f"ratio gearte / loop: {rate / rate_loop:8.0f}x (goal >= 100x)")
    print(f"ratio gearte / numpy: {rate / rate_np:7.1f}x")


if __name__ == "__main__":
    main()
