"""Benchmark: production-yield Monte-Carlo through the physics (issue 14).

For each drive, gearte's yield engine (seeded chunks on local threads, spec, yield CI, Cpk,
worst samples) is timed beside the strongest plain baseline a user would write for the same
per-sample physics, in the same run, and the ratio printed:

* cycloid stage geometric TE (nine errors, exact eccentricity term): baseline = one vectorised
  numpy evaluation of the same formula on all samples (numpy draws, no chunks, no statistics);
* planetary coupled TE (Wang 2013 random assembly): baseline = gearte's paper-specific
  ``planetary_mc.run_scenario`` (compiled exact extremes), same sample count;
* RV reducer (han2023_rv110e): each sample one assembled reducer → catalogue test + TE at 36
  output positions + peak pin load; baseline = the same per-sample physics in a plain loop on
  one thread. Samples per minute printed beside the issue's target (10 000 / min on 2 cores).

    PYTHONPATH=src python benchmarks/bench_yield.py [--rv-samples 40]
"""

from __future__ import annotations

import argparse
import time

import numpy as np


class _Opt:
    def __init__(self, workers: int) -> None:
        self.workers, self.scheduler, self.progress = workers, None, False


def bench_cycloid(n: int, workers: int) -> None:
    from gearte.io.case_file import load_case
    from gearte.models.cycloid_te import ERROR_FACTORS, eccentricity_te, te_gradients
    from gearte.runners.yield_models import CycloidGeometricTE
    from gearte.studies.cycloid_stage import build_stage
    from gearte.tolerance.yield_mc import SpecLimit, Tolerance, ToleranceSet, run_yield
    from gearte.units import rad_to_arcmin, um_to_mm

    case = load_case("hu2020_rv80e_initial")
    st = build_stage(case.stage)
    means = {k: getattr(case.errors, k).mean_um for k in ERROR_FACTORS}
    half = {k: 0.5 * getattr(case.errors, k).tolerance_um for k in ERROR_FACTORS}
    ts = ToleranceSet(
        tuple(Tolerance(k, "normal", half[k], nominal=means[k]) for k in ERROR_FACTORS)
    )
    model = CycloidGeometricTE(st, means)
    spec = [SpecLimit("geometric_te [arcmin]", 0.0, 1.5)]
    run_yield(model, ts, spec, 10_000, seed=0, options=_Opt(workers))  # warm-up
    t = time.perf_counter()
    r = run_yield(model, ts, spec, n, seed=1, chunk_size=50_000, options=_Opt(workers))
    t_g = time.perf_counter() - t

    g = te_gradients(st)
    mod = 2 * st.dr_rp / st.r_c - 2 * st.dr_p * np.sqrt(1 - st.K1**2) / st.r_c + 2 * st.rotation
    t = time.perf_counter()
    rng = np.random.default_rng(1)
    te = np.full(n, mod)
    for k in ERROR_FACTORS:
        x = um_to_mm(means[k] + rng.standard_normal(n) * half[k] / 3.0)
        te += eccentricity_te(st, x) if k == "eccentricity_error" else g[k] * x
    te = rad_to_arcmin(te)
    y = np.mean((te >= 0) & (te <= 1.5))
    t_b = time.perf_counter() - t
    print(
        f"cycloid geometric TE, {n} samples: gearte {t_g:.2f} s (yield {r.yield_:.4f}), "
        f"numpy one-shot {t_b:.2f} s (yield {y:.4f}); ratio baseline/gearte = {t_b / t_g:.2f}"
    )


def bench_planetary(n: int, workers: int) -> None:
    from gearte.io.case_file import load_case
    from gearte.runners.planetary_mc import run_scenario
    from gearte.runners.yield_models import PlanetaryCoupledTE
    from gearte.studies.planetary import build_terms
    from gearte.tolerance.yield_mc import Tolerance, ToleranceSet, run_yield
    from gearte.units import mm_to_um

    terms, mags, _ = build_terms(load_case("wang2013_2kh_eq9"))
    model = PlanetaryCoupledTE(terms, {k: float(mm_to_um(v)) for k, v in mags.items()})
    ts = ToleranceSet(tuple(Tolerance(a, "uniform", 180.0, nominal=180.0) for a in terms.angles))
    run_yield(model, ts, [], 10_000, seed=0, options=_Opt(workers))
    run_scenario(terms, "random_assembly", mags, samples=10_000, seed=0, workers=workers)
    t = time.perf_counter()
    r = run_yield(model, ts, [], n, seed=1, chunk_size=50_000, options=_Opt(workers))
    t_g = time.perf_counter() - t
    t = time.perf_counter()
    b = run_scenario(
        terms, "random_assembly", mags, samples=n, seed=1, chunk_size=50_000, workers=workers
    )
    t_b = time.perf_counter() - t
    asec = 180 / np.pi * 3600
    print(
        f"planetary random assembly, {n} samples: gearte general {t_g:.2f} s "
        f"(mean {r.quantities['coupled_te_amplitude [arcsec]'].stats.mean:.1f}″), "
        f"paper-specific run_scenario {t_b:.2f} s (mean {b.stats.mean * asec:.1f}″); "
        f"ratio baseline/gearte = {t_b / t_g:.2f}"
    )


def bench_rv(n: int, workers: int) -> None:
    from gearte.io.case_file import load_case
    from gearte.runners.yield_models import RVReducerYield, rv_error_keys
    from gearte.studies.rv_reducer import build_reducer
    from gearte.tolerance.yield_mc import SpecLimit, Tolerance, ToleranceSet, run_yield

    red = build_reducer(load_case("han2023_rv110e").reducer)
    model = RVReducerYield(red, positions=36)
    keys = rv_error_keys(red)
    tols = []
    for fam in ("cam", "disc_crank_bore", "carrier_crank_bore", "planet_base_circle"):
        tols += [Tolerance(k, "rayleigh", 5.0, phase=True, family=fam) for k in keys[fam]]
    tols += [
        Tolerance(k, "normal", 2.0, family="pins.radius_errors") for k in keys["pins.radius_errors"]
    ]
    ts = ToleranceSet(tuple(tols))
    spec = [
        SpecLimit("lost_motion [arcmin]", upper=1.0),
        SpecLimit("angular_te [arcmin]", upper=1.0),
    ]
    model.one(red)  # compile / warm caches
    t = time.perf_counter()
    r = run_yield(
        model, ts, spec, n, seed=1, chunk_size=max(1, n // (4 * workers)), options=_Opt(workers)
    )
    t_g = time.perf_counter() - t
    errs = ts.sample(np.random.default_rng(1), n)
    t = time.perf_counter()
    for s in range(n):
        model.one(model.reducer_for({k: float(v[s]) for k, v in errs.items()}))
    t_b = time.perf_counter() - t
    print(
        f"RV reducer (catalogue test + TE at 36 positions + peak pin load), {n} samples: gearte "
        f"{t_g:.2f} s = {n / t_g * 60:.0f} samples/min on {workers} threads "
        f"(yield {r.yield_:.3f}); "
        f"plain loop on 1 thread {t_b:.2f} s = {n / t_b * 60:.0f} samples/min; ratio = "
        f"{t_b / t_g:.2f}. Issue target: 10000 samples/min on 2 cores."
    )


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--samples", type=int, default=1_000_000)
    ap.add_argument("--rv-samples", type=int, default=40)
    ap.add_argument("--workers", type=int, default=2)
    a = ap.parse_args()
    bench_cycloid(a.samples, a.workers)
    bench_planetary(a.samples, a.workers)
    bench_rv(a.rv_samples, a.workers)


if __name__ == "__main__":
    main()
