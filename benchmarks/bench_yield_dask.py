"""Benchmark: a 10⁶-sample yield study on a Dask LocalCluster against local threads (issue 14).

The Wang 2013 random assembly through the general yield engine (``wang2013_2kh_eq9`` terms,
every eccentricity direction uniform) — 10⁶ assembled planetary stages in seeded chunks of
50 000 — run on 2 local threads and on a Dask ``LocalCluster`` (2 worker processes, 1 thread
each). Prints both wall times, whether every statistic is identical, and the peak resident
memory of this process and of each Dask worker (the engine reduces chunk by chunk: memory is
bounded by the chunk, not by the sample count).

    PYTHONPATH=src python benchmarks/bench_yield_dask.py [--samples 1000000]
"""

from __future__ import annotations

import argparse
import resource
import time


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
    ap.add_argument("--samples", type=int, default=1_000_000)
    ap.add_argument("--chunk", type=int, default=50_000)
    a = ap.parse_args()

    terms, mags, _ = build_terms(load_case("wang2013_2kh_eq9"))
    model = PlanetaryCoupledTE(terms, {k: float(mm_to_um(v)) for k, v in mags.items()})
    ts = ToleranceSet(tuple(Tolerance(k, "uniform", 180.0, nominal=180.0) for k in terms.angles))
    spec = [SpecLimit("coupled_te_amplitude [arcsec]", upper=400.0)]
    kw = {"seed": 6, "chunk_size": a.chunk}

    t = time.perf_counter()
    r_t = run_yield(model, ts, spec, a.samples, options=_Opt(2), **kw)
    t_threads = time.perf_counter() - t
    rss_threads = _peak_rss_mib()

    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True) as cluster:
        with Client(cluster) as client:
            t = time.perf_counter()
            r_d = run_yield(model, ts, spec, a.samples, options=_Opt(2, cluster), **kw)
            t_dask = time.perf_counter() - t
            workers = client.run(
                lambda: resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0
            )
    same = r_t.yield_ == r_d.yield_ and all(
        (r_t.quantities[q].stats.mean, r_t.quantities[q].stats.sd, r_t.quantities[q].stats.min,
         r_t.quantities[q].stats.max)
        == (r_d.quantities[q].stats.mean, r_d.quantities[q].stats.sd, r_d.quantities[q].stats.min,
            r_d.quantities[q].stats.max)
        for q in r_t.quantities
    )  # fmt: skip
    q = "coupled_te_amplitude [arcsec]"
    print(f"planetary random assembly through the yield engine, {a.samples} samples, chunks of "
          f"{a.chunk}")  # fmt: skip
    for label, r, t in (("2 local threads:           ", r_t, t_threads),
                        ("Dask LocalCluster (2 proc):", r_d, t_dask)):  # fmt: skip
        st = r.quantities[q].stats
        print(f"  {label} {t:8.2f} s, yield {r.yield_:.6f}, mean {st.mean:.3f}″, σ {st.sd:.3f}″")
    print(f"  identical statistics: {same}")
    print(
        f"  peak RSS: this process {_peak_rss_mib():.0f} MiB (after the threads run "
        f"{rss_threads:.0f} MiB); Dask workers "
        + ", ".join(f"{v:.0f} MiB" for v in workers.values())
    )


if __name__ == "__main__":
    main()
