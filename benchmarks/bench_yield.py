"""Benchmark: production-yield Monte-Carlo through the physics (issue 14).

For each drive, gearte's yield engine (seeded chunks on local threads, spec, yield CI, Cpk,
worst samples) is timed beside the strongest plain baseline a user would write for the same
per-sample physics, in the same run, and the ratio printed:

* cycloid stage geometric TE (nine errors, exact eccentricity term): baseline = one vectorised
  numpy evaluation of the same formula on all samples (numpy draws, no chunks, no statistics);
* planetary coupled TE (Wang 2013 random assembly): baseline = gearte's paper-specific
  ``planetary_mc.run_scenario`` (compiled exact extremes), same sample count;
* RV reducer (han2023_rv110e): each sample one assembled reducer → catalogue virtual loop
  (16 torque levels) + TE at 36 output positions loaded and unloaded + pin loads and Hertz
  pressures; gearte's batched compiled solver (:mod:`gearte.solvers.rv_batch`) against the
  strongest baseline we could write: the same inputs and read-out with gearte's batched
  algorithm in numpy — the same condensed system, Newton on the equilibrium and the pin law
  together with the same stopping rule and fallback, the same warm starts — vectorised over the
  samples of a chunk (batched ``np.linalg.solve``, one BLAS product for the Hessians), run
  through the same engine on the same threads (``benchmarks/_numpy_rv.py``; before
  2026-11-26 the baseline solved the full 20-DOF system by the line-searched Newton with inner
  law solves, ~3.5× slower than this one); and the per-sample path gearte had before (each reducer
  assembled and solved on its own). Samples per minute printed beside the issue's target
  (10 000 / min on 2 cores). BLAS runs single-threaded (``OPENBLAS_NUM_THREADS=1`` unless set):
  the work is split over the engine's threads.

    PYTHONPATH=src python benchmarks/bench_yield.py [--only rv] [--rv-samples 4000]
"""

from __future__ import annotations

import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
os.environ.setdefault("OMP_NUM_THREADS", "1")

import argparse  # noqa: E402
import time  # noqa: E402

import numpy as np  # noqa: E402


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
    t, c = time.perf_counter(), time.process_time()
    r = run_yield(model, ts, spec, n, seed=1, chunk_size=50_000, options=_Opt(workers))
    t_g, c_g = time.perf_counter() - t, time.process_time() - c

    g = te_gradients(st)
    mod = 2 * st.dr_rp / st.r_c - 2 * st.dr_p * np.sqrt(1 - st.K1**2) / st.r_c + 2 * st.rotation
    t, c = time.perf_counter(), time.process_time()
    rng = np.random.default_rng(1)
    te = np.full(n, mod)
    for k in ERROR_FACTORS:
        x = um_to_mm(means[k] + rng.standard_normal(n) * half[k] / 3.0)
        te += eccentricity_te(st, x) if k == "eccentricity_error" else g[k] * x
    te = rad_to_arcmin(te)
    y = np.mean((te >= 0) & (te <= 1.5))
    t_b, c_b = time.perf_counter() - t, time.process_time() - c
    print(
        f"cycloid geometric TE, {n} samples: gearte {t_g:.2f} s wall on {workers} threads, "
        f"{c_g:.2f} s CPU (yield {r.yield_:.4f}), numpy one-shot {t_b:.2f} s wall, {c_b:.2f} s "
        f"CPU (yield {y:.4f}); ratio baseline/gearte per core (CPU) = {c_b / c_g:.2f}, wall "
        f"({workers} threads vs 1) = {t_b / t_g:.2f}"
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


class _NumpyRV:
    """The same yield model with the batched solver replaced by the numpy baseline."""

    def __init__(self, model) -> None:
        self.model = model

    def __call__(self, errors):
        from _numpy_rv import solve_batch_numpy
        from gearte.runners.rv_yield_batch import batch_quantities

        n = len(next(iter(errors.values())))
        return batch_quantities(self.model, errors, n, solver=solve_batch_numpy)


def rv_study():
    """The RV yield study of the benchmarks: (model, tolerances, spec) on han2023_rv110e."""
    from gearte.io.case_file import load_case
    from gearte.runners.yield_models import RVReducerYield, rv_error_keys
    from gearte.studies.rv_reducer import build_reducer
    from gearte.tolerance.yield_mc import SpecLimit, Tolerance, ToleranceSet

    red = build_reducer(load_case("han2023_rv110e").reducer)
    model = RVReducerYield(red, positions=36)
    keys = rv_error_keys(red)
    tols = []
    for fam in ("cam", "disc_crank_bore", "carrier_crank_bore", "planet_base_circle"):
        tols += [Tolerance(k, "rayleigh", 5.0, phase=True, family=fam) for k in keys[fam]]
    tols += [
        Tolerance(k, "normal", 2.0, family="pins.radius_errors") for k in keys["pins.radius_errors"]
    ]
    spec = [
        SpecLimit("lost_motion [arcmin]", upper=1.0),
        SpecLimit("angular_te [arcmin]", upper=1.0),
    ]
    return model, ToleranceSet(tuple(tols)), spec


def bench_rv(n: int, workers: int, n_loop: int) -> None:
    from gearte.runners.yield_models import RVReducerYield
    from gearte.tolerance.yield_mc import run_yield

    model, ts, spec = rv_study()
    red = model.reducer
    chunk = max(1, min(500, n // (2 * workers)))
    run_yield(model, ts, spec, 2 * workers, seed=0, chunk_size=1, options=_Opt(workers))  # warm
    t, c = time.perf_counter(), time.process_time()
    r = run_yield(model, ts, spec, n, seed=1, chunk_size=chunk, options=_Opt(workers))
    t_g, c_g = time.perf_counter() - t, time.process_time() - c
    base = _NumpyRV(model)
    t, c = time.perf_counter(), time.process_time()
    rb = run_yield(base, ts, spec, n, seed=1, chunk_size=chunk, options=_Opt(workers))
    t_b, c_b = time.perf_counter() - t, time.process_time() - c
    q = "angular_te [arcmin]"
    diff = abs(r.quantities[q].stats.mean - rb.quantities[q].stats.mean)
    # the per-sample path (each reducer assembled and solved on its own, compiled per-case solver)
    per_case = RVReducerYield(red, positions=36, batched=False)
    errs = ts.sample(np.random.default_rng(1), n_loop)
    t = time.perf_counter()
    per_case(errs)
    t_l = (time.perf_counter() - t) / n_loop * n
    print(
        f"RV reducer (catalogue loop + TE at 36 positions loaded and unloaded + pin loads and "
        f"pressures), {n} samples, {workers} threads, chunks of {chunk}:\n"
        f"  gearte batched solver:           {t_g:8.2f} s = {n / t_g * 60:9.0f} samples/min "
        f"(yield {r.yield_:.4f})\n"
        f"  numpy, gearte's batched algorithm (condensed, Newton on equilibrium + law), "
        f"vectorised over the samples of a chunk, same threads:\n"
        f"                                   {t_b:8.2f} s = {n / t_b * 60:9.0f} samples/min "
        f"(yield {rb.yield_:.4f}; mean TE differs by {diff:.1e} arcmin)\n"
        f"  gearte per-sample path (before):  {t_l:8.2f} s = {n / t_l * 60:9.0f} samples/min "
        f"(from {n_loop} samples, 1 thread)\n"
        f"  ratio numpy vectorised / gearte = {t_b / t_g:.2f} (wall), {c_b / c_g:.2f} (CPU); "
        f"per-sample path / gearte = {t_l / t_g:.1f} (wall).\n"
        f"  CPU time: gearte {c_g / n * 1e3:.2f} ms/sample = {n / c_g * 60:.0f} samples per "
        f"CPU-minute; numpy {c_b / n * 1e3:.2f} ms/sample.\n"
        f"  Issue 14 target: 10000 samples/min on 2 cores, >= 10x numpy."
    )
    rate, ratio = n / t_g * 60, c_b / c_g
    met = "met" if rate >= 10_000 else "NOT met"
    print(f"goal (issue 14) >= 10000 full samples/min on {workers} threads: measured "
          f"{rate:.0f}/min wall — {met} ({n / c_g * 60:.0f} per CPU-minute)")  # fmt: skip
    print(f"goal (issue 14) >= 10x the numpy baseline: measured {ratio:.1f}x (CPU), "
          f"{t_b / t_g:.1f}x (wall) — {'met' if ratio >= 10 else 'NOT met'}")  # fmt: skip


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--samples", type=int, default=1_000_000)
    ap.add_argument("--rv-samples", type=int, default=4000)
    ap.add_argument("--rv-loop-samples", type=int, default=20)
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--only", choices=["cycloid", "planetary", "rv"], default=None)
    a = ap.parse_args()
    if a.only in (None, "cycloid"):
        bench_cycloid(a.samples, a.workers)
    if a.only in (None, "planetary"):
        bench_planetary(a.samples, a.workers)
    if a.only in (None, "rv"):
        bench_rv(a.rv_samples, a.workers, a.rv_loop_samples)


if __name__ == "__main__":
    main()
