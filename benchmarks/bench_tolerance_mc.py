"""Spur-pair Monte-Carlo throughput (issue 3: goal ≥ 10 M samples/s on 2 cores, ≥ 100× a loop).

gearte: :func:`gearte.tolerance.montecarlo.monte_carlo` on the spur pair of Jiang et al. (2024),
Tables 1-2 (7 contributors; the three "Rayleigh magnitude × uniform phase" terms drawn as their
exactly equivalent normal — the polar draw is timed too), 1e7 samples in 1e6-sample chunks on
the local threads (numba ``nogil`` kernel drawing from
numpy Generators, in-kernel reduction).

Baselines, same run, each printed with its ratio (wall and CPU seconds; gearte's CPU counts
every worker thread):

* **strong — numpy, one normal per sample**: what a competent numpy user writes for this stack:
  the sum of the independent normal contributors drawn as one vectorised normal (exact), reduced
  with the same numpy statistics as gearte's (``reduce_samples``: sums, extremes, spec counts,
  the same histogram), 1e6-sample chunks; goal (issue 12) ≥ 5×;
* **numpy per contributor**: gearte's vectorised numpy engine (``engine="numpy"``), one draw per
  contributor (what issue 12 measured 1.6× against);
* **weak — Python loop**: the plain per-sample loop
  (:func:`gearte.tolerance.montecarlo.linear_stack_reference`, the same Generator calls as the
  kernel, bit-identical samples) on a smaller n, its rate extrapolated.

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
from gearte.tolerance.montecarlo import linear_stack_reference, monte_carlo, reduce_samples
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


def numpy_grouped(stack: LinearStack, n: int, seed: int, chunk: int = 1_000_000) -> float:
    """Strong numpy baseline: one vectorised normal per sample for the (all-normal) stack, the
    same reduction as gearte's numpy twin; returns the mean [mm]."""
    mu, sd = stack.mean, stack.sd
    lo, hi = mu - 8 * sd, mu + 8 * sd
    rng = np.random.default_rng(seed)
    done = 0
    s1 = 0.0
    while done < n:
        m = min(chunk, n - done)
        y = mu + sd * rng.standard_normal(m)
        part = reduce_samples(
            y, shift=mu, lo=lo, hi=hi, nbins=4000, lsl=-np.inf, usl=np.inf, keep=0
        )
        s1 += part.s1
        done += m
    return mu + s1 / n


def timed(f, *a, **kw) -> tuple[float, float]:
    """(wall, CPU) seconds of f(*a, **kw)."""
    w, c = time.perf_counter(), time.process_time()
    f(*a, **kw)
    return time.perf_counter() - w, time.process_time() - c


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
    t0, c0 = time.perf_counter(), time.process_time()
    r = monte_carlo(st, n, seed=2024, options=opts)
    t_gearte, c_gearte = time.perf_counter() - t0, time.process_time() - c0
    rate = n / t_gearte
    assert all(type(c.distribution).__name__ in ("Normal", "RadialPhase") for c in st.contributors)
    n_s = min(n, 4_000_000)
    w_s, c_s = timed(numpy_grouped, st, n_s, 2024)

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
    w_np, c_np = timed(monte_carlo, st, n_np, seed=2024, engine="numpy", options=opts)
    rate_np = n_np / w_np

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
        f"numpy, one normal  : {w_s:8.3f} s  {n_s / w_s / 1e6:8.2f} M samples/s "
        f"({n_s:.3g} samples, 1 thread; strong baseline)"
    )
    print(
        f"numpy per contrib. : {w_np:8.3f} s  {rate_np / 1e6:8.2f} M samples/s "
        f"({n_np:.3g} samples; gearte engine='numpy')"
    )
    print(
        f"python loop        : {t_loop:8.3f} s  {rate_loop / 1e6:8.4f} M samples/s "
        f"({args.loop_samples} samples; 1e7 would take {n / rate_loop:.0f} s)"
    )
    per = c_gearte / n  # CPU seconds per sample, all gearte threads
    print(
        f"ratio gearte / numpy one normal (strong): wall {rate / (n_s / w_s):6.1f}x, "
        f"CPU {c_s / n_s / per:6.1f}x (goal >= 5x)"
    )
    print(
        f"ratio gearte / numpy per contributor   : wall {rate / rate_np:6.1f}x, "
        f"CPU {c_np / n_np / per:6.1f}x"
    )
    print(f"ratio gearte / Python loop (weak)      : wall {rate / rate_loop:6.0f}x (goal >= 100x)")


if __name__ == "__main__":
    main()
