"""Benchmark: a large yield study on a Dask LocalCluster against local threads (issue 14).

``--drive planetary`` (default): the Wang 2013 random assembly through the general yield engine
(``wang2013_2kh_eq9`` terms, every eccentricity direction uniform) — 10⁶ assembled planetary
stages in seeded chunks of 50 000. ``--drive rv``: han2023_rv110e, each sample one assembled
reducer (catalogue loop + TE at 36 positions loaded and unloaded + pin loads, the batched
solver), the tolerances of ``bench_yield.py``; default 10⁵ samples in chunks of 500 (10⁶ with
``--samples 1000000``: ~1000 s CPU per backend). Each runs on 2 local threads and on a Dask
``LocalCluster`` (2 worker processes, 1 thread each). Prints both wall and CPU times, whether
every statistic is identical, and the peak resident memory of this process and of each Dask
worker (the engine reduces chunk by chunk: memory is bounded by the chunk, not by the sample
count), and one summary line per goal.

    PYTHONPATH=src python benchmarks/bench_yield_dask.py [--drive rv] [--samples N]
"""

from __future__ import annotations

import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
os.environ.setdefault("OMP_NUM_THREADS", "1")

import argparse  # noqa: E402
import resource  # noqa: E402
import time  # noqa: E402


class _Opt:
    def __init__(self, workers: int, scheduler=None) -> None:
        self.workers, self.scheduler, self.progress = workers, scheduler, False


def _peak_rss_mib() -> float:
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0


def main() -> None:
    from distributed import Client, LocalCluster

    from gearte.io.case_file import load_case
    from gearte.runners.yield_models import PlanetaryCoupledTE
    from gearte.studies.planetary import build_terms
    from gearte.tolerance.yield_mc import SpecLimit, Tolerance, ToleranceSet, run_yield
    from gearte.units import mm_to_um

    ap = argparse.ArgumentParser()
    ap.add_argument("--drive", choices=["planetary", "rv"], default="planetary")
    ap.add_argument("--samples", type=int, default=None)
    ap.add_argument("--chunk", type=int, default=None)
    a = ap.parse_args()
    rv = a.drive == "rv"
    a.samples = a.samples or (100_000 if rv else 1_000_000)
    a.chunk = a.chunk or (500 if rv else 50_000)

    if rv:
        from bench_yield import rv_study

        model, ts, spec = rv_study()
        q = "angular_te [arcmin]"
        run_yield(model, ts, spec, 4, seed=0, chunk_size=2, options=_Opt(2))  # compile / load
    else:
        terms, mags, _ = build_terms(load_case("wang2013_2kh_eq9"))
        model = PlanetaryCoupledTE(terms, {k: float(mm_to_um(v)) for k, v in mags.items()})
        ts = ToleranceSet(
            tuple(Tolerance(k, "uniform", 180.0, nominal=180.0) for k in terms.angles)
        )
        spec = [SpecLimit("coupled_te_amplitude [arcsec]", upper=400.0)]
        q = "coupled_te_amplitude [arcsec]"
    kw = {"seed": 6, "chunk_size": a.chunk}

    t, c = time.perf_counter(), time.process_time()
    r_t = run_yield(model, ts, spec, a.samples, options=_Opt(2), **kw)
    t_threads, c_threads = time.perf_counter() - t, time.process_time() - c
    rss_threads = _peak_rss_mib()

    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True) as cluster:
        with Client(cluster) as client:
            t = time.perf_counter()
            r_d = run_yield(model, ts, spec, a.samples, options=_Opt(2, cluster), **kw)
            t_dask = time.perf_counter() - t
            workers = client.run(
                lambda: resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0
            )
            cpu_workers = client.run(lambda: time.process_time())
    same = r_t.yield_ == r_d.yield_ and all(
        (r_t.quantities[q].stats.mean, r_t.quantities[q].stats.sd, r_t.quantities[q].stats.min,
         r_t.quantities[q].stats.max)
        == (r_d.quantities[q].stats.mean, r_d.quantities[q].stats.sd, r_d.quantities[q].stats.min,
            r_d.quantities[q].stats.max)
        for q in r_t.quantities
    )  # fmt: skip
    what = "RV reducer (han2023_rv110e)" if rv else "planetary random assembly"
    print(f"{what} through the yield engine, {a.samples} samples, chunks of {a.chunk}")
    for label, r, t in (("2 local threads:           ", r_t, t_threads),
                        ("Dask LocalCluster (2 proc):", r_d, t_dask)):  # fmt: skip
        st = r.quantities[q].stats
        print(f"  {label} {t:8.2f} s, yield {r.yield_:.6f}, mean {st.mean:.6g}, σ {st.sd:.6g} "
              f"({q})")  # fmt: skip
    cpu_w = ", ".join(f"{v:.1f} s" for v in cpu_workers.values())
    print(f"  CPU: threads run {c_threads:.1f} s = {c_threads / a.samples * 1e3:.3f} ms/sample; "
          f"Dask workers (whole life) {cpu_w}")  # fmt: skip
    print(f"  identical statistics: {same}")
    peak = max([_peak_rss_mib(), *workers.values()])
    print(
        f"  peak RSS: this process {_peak_rss_mib():.0f} MiB (after the threads run "
        f"{rss_threads:.0f} MiB); Dask workers "
        + ", ".join(f"{v:.0f} MiB" for v in workers.values())
    )
    print(f"goal (issue 14) same result on Dask as on threads: {'met' if same else 'NOT met'}; "
          f"bounded memory: peak {peak:.0f} MiB per process for {a.samples} samples (compare a "
          "run with fewer samples)")  # fmt: skip


if __name__ == "__main__":
    main()
