"""Benchmark: a large yield study on a Dask LocalCluster against local threads (issue 14).

``--drive planetary`` (default): the Wang 2013 random assembly through the general yield engine
(``wang2013_2kh_eq9`` terms, every eccentricity direction uniform) — 10⁶ assembled planetary
stages in seeded chunks of 50 000. ``--drive rv``: han2023_rv110e, each sample one assembled
reducer (catalogue loop + TE at 36 positions loaded and unloaded + pin loads, the batched
solver), the tolerances of ``bench_yield.py``; default 10⁴ samples in chunks of 500 (10⁶ with
``--samples 1000000``: ~600–1000 s CPU per backend).

Each runs on 2 local threads and on gearte's ``"local-cluster"`` backend (a Dask
``LocalCluster``, 2 worker processes × 1 thread), after a warm-up on both (imports, numba cache).
Measured, per backend: wall and CPU time (threads: this process; Dask: the workers' CPU during
the run, from ``getrusage`` in each worker), the CPU the model itself spent per chunk (timed
inside the chunk with ``time.thread_time``: what is left is the backend's overhead), and the
resident memory (RSS) of each worker and of this process, polled every ``--poll`` seconds over
the whole run. Prints whether every statistic is identical and one summary line per goal;
``--log FILE`` also writes everything (RSS timelines included) as JSON, and appends each chunk
(time, process, its model CPU) and each RSS reading to ``FILE.trace.txt`` as it happens (a run
stopped early still leaves its timeline).

    PYTHONPATH=src:benchmarks python benchmarks/bench_yield_dask.py [--drive rv] [--samples N]
"""

from __future__ import annotations

import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
os.environ.setdefault("OMP_NUM_THREADS", "1")

import argparse  # noqa: E402
import json  # noqa: E402
import resource  # noqa: E402
import threading  # noqa: E402
import time  # noqa: E402

import numpy as np  # noqa: E402

CPU_KEY = "_chunk_model_cpu [s]"


class TimedModel:
    """The study's model, plus the thread CPU time of each call as an extra quantity (one value
    per chunk, repeated for its samples) — the model's own share of a chunk's CPU."""

    def __init__(self, inner, trace: str | None = None) -> None:
        self.inner, self.trace = inner, trace

    def __call__(self, errors):
        c = time.thread_time()
        out = dict(self.inner(errors))
        dt = time.thread_time() - c
        n = np.asarray(next(iter(out.values()))).shape[0] if out else 1
        if self.trace:  # a line per chunk, for long runs
            with open(self.trace, "a") as f:
                f.write(f"{time.time():.1f} {os.getpid()} chunk {n} {dt:.4f}\n")
        out[CPU_KEY] = np.full(n, dt)
        return out


class _Opt:
    def __init__(self, workers: int, scheduler=None) -> None:
        self.workers, self.scheduler, self.progress = workers, scheduler, False


def _proc() -> dict:
    """In a worker: CPU time so far [s] and process id."""
    r = resource.getrusage(resource.RUSAGE_SELF)
    return {"cpu_s": r.ru_utime + r.ru_stime, "pid": os.getpid()}


def _profiler_on() -> bool:
    import dask

    return bool(dask.config.get("distributed.worker.profile.enabled"))


class RSSPoller:
    """RSS [MiB] of some processes every ``period`` seconds, in a background thread."""

    def __init__(self, pids: dict[str, int], period: float, trace: str | None = None) -> None:
        import psutil

        self.trace = trace
        self.procs = {k: psutil.Process(p) for k, p in pids.items()}
        self.period = period
        self.t0 = time.perf_counter()
        self.series: dict[str, list[tuple[float, float]]] = {k: [] for k in pids}
        self._stop = threading.Event()
        self._th = threading.Thread(target=self._run, daemon=True)
        self._th.start()

    def _run(self) -> None:
        while True:
            t = time.perf_counter() - self.t0
            for k, p in self.procs.items():
                try:
                    self.series[k].append((round(t, 1), p.memory_info().rss / 2**20))
                except Exception:  # noqa: BLE001 - a process that ended
                    continue
                if self.trace:
                    with open(self.trace, "a") as f:
                        f.write(f"{time.time():.1f} {p.pid} rss {k} {self.series[k][-1][1]:.1f}\n")
            if self._stop.wait(self.period):
                return

    def stop(self) -> dict[str, list[tuple[float, float]]]:
        self._stop.set()
        self._th.join()
        return self.series


def _rss_line(series: list[tuple[float, float]]) -> str:
    v = [m for _, m in series]
    if not v:
        return "no samples"
    q = [v[min(len(v) - 1, int(f * (len(v) - 1)))] for f in (0.0, 0.25, 0.5, 0.75, 1.0)]
    return (
        f"start {q[0]:.0f}, 25 % {q[1]:.0f}, 50 % {q[2]:.0f}, 75 % {q[3]:.0f}, end {q[4]:.0f}, "
        f"max {max(v):.0f} MiB ({len(v)} readings)"
    )


def main() -> None:
    from gearte.execution import open_executor
    from gearte.io.case_file import load_case
    from gearte.runners.yield_models import PlanetaryCoupledTE
    from gearte.studies.planetary import build_terms
    from gearte.tolerance.yield_mc import SpecLimit, Tolerance, ToleranceSet, run_yield
    from gearte.units import mm_to_um

    ap = argparse.ArgumentParser()
    ap.add_argument("--drive", choices=["planetary", "rv"], default="planetary")
    ap.add_argument("--samples", type=int, default=None)
    ap.add_argument("--chunk", type=int, default=None)
    ap.add_argument("--backend", choices=["both", "threads", "dask"], default="both")
    ap.add_argument("--poll", type=float, default=2.0, help="RSS polling period [s]")
    ap.add_argument("--log", default=None, help="write the measurements as JSON here")
    a = ap.parse_args()
    rv = a.drive == "rv"
    a.samples = a.samples or (10_000 if rv else 1_000_000)
    a.chunk = a.chunk or (500 if rv else 50_000)

    if rv:
        from bench_yield import rv_study

        model, ts, spec = rv_study()
        q = "angular_te [arcmin]"
    else:
        terms, mags, _ = build_terms(load_case("wang2013_2kh_eq9"))
        model = PlanetaryCoupledTE(terms, {k: float(mm_to_um(v)) for k, v in mags.items()})
        ts = ToleranceSet(
            tuple(Tolerance(k, "uniform", 180.0, nominal=180.0) for k in terms.angles)
        )
        spec = [SpecLimit("coupled_te_amplitude [arcsec]", upper=400.0)]
        q = "coupled_te_amplitude [arcsec]"
    trace = f"{a.log}.trace.txt" if a.log else None
    model = TimedModel(model, trace)
    kw = {"seed": 6, "chunk_size": a.chunk}
    n_chunks = -(-a.samples // a.chunk)
    log: dict = {"drive": a.drive, "samples": a.samples, "chunk": a.chunk, "runs": {}}
    results = {}

    def record(label, r, wall, cpu, extra):
        model_cpu = r.quantities[CPU_KEY].stats.mean * n_chunks  # one value per chunk
        st = r.quantities[q].stats
        log["runs"][label] = {
            "wall_s": wall,
            "cpu_s": cpu,
            "model_cpu_s": model_cpu,
            "overhead_ms_per_chunk": (cpu - model_cpu) / n_chunks * 1e3,
            "yield": r.yield_,
            "ci": list(r.ci),
            "cpk": r.cpk,
            "mean": st.mean,
            "sd": st.sd,
            "passed": r.passed,
            # every statistic, bit for bit (JSON floats round-trip): compare runs made apart
            "stats": {
                k: [*v.stats.as_tuple(), v.fail_fraction, v.cpk]
                for k, v in r.quantities.items()
                if k != CPU_KEY
            },
            "worst_samples": [w["sample"] for w in r.worst],
            **extra,
        }
        results[label] = r
        print(
            f"  {label:8s} {wall:8.1f} s wall, {cpu:7.1f} s CPU "
            f"({cpu / a.samples * 1e3:.3f} ms/sample; model {model_cpu:.1f} s, outside it "
            f"{(cpu - model_cpu) / n_chunks * 1e3:.0f} ms per chunk); yield {r.yield_:.6f}, "
            f"Cpk {r.cpk}, {q} mean {st.mean:.6g} σ {st.sd:.6g}",
            flush=True,
        )

    what = "RV reducer (han2023_rv110e)" if rv else "planetary random assembly"
    print(f"{what} through the yield engine, {a.samples} samples, chunks of {a.chunk}", flush=True)
    if a.backend in ("both", "threads"):
        run_yield(model, ts, spec, 4, seed=0, chunk_size=2, options=_Opt(2))  # compile / load
        poll = RSSPoller({"this process": os.getpid()}, a.poll, trace)
        t, c = time.perf_counter(), time.process_time()
        r = run_yield(model, ts, spec, a.samples, options=_Opt(2), **kw)
        wall, cpu = time.perf_counter() - t, time.process_time() - c
        rss = poll.stop()
        record("threads", r, wall, cpu, {"rss_mib": rss})
        print(f"    RSS this process: {_rss_line(rss['this process'])}", flush=True)

    if a.backend in ("both", "dask"):
        t = time.perf_counter()
        with open_executor("local-cluster", 2) as ex:
            client = ex.client
            t_up = time.perf_counter() - t
            run_yield(model, ts, spec, 4, seed=0, chunk_size=2, options=_Opt(2, ex))  # warm
            before = client.run(_proc)
            prof = set(client.run(_profiler_on).values())
            pids = {w.rsplit(":", 1)[-1]: v["pid"] for w, v in before.items()}
            pids["this process"] = os.getpid()
            poll = RSSPoller(pids, a.poll, trace)
            t = time.perf_counter()
            r = run_yield(model, ts, spec, a.samples, options=_Opt(2, ex), **kw)
            wall = time.perf_counter() - t
            after = client.run(_proc)
            rss = poll.stop()
        cpu_w = {w: after[w]["cpu_s"] - before[w]["cpu_s"] for w in before}
        record(
            "dask",
            r,
            wall,
            sum(cpu_w.values()),
            {"worker_cpu_s": cpu_w, "rss_mib": rss, "cluster_start_s": t_up},
        )
        print(
            f"    cluster start {t_up:.1f} s; workers' profiler on: {sorted(prof)}; CPU per "
            "worker during the run: " + ", ".join(f"{v:.1f} s" for v in cpu_w.values()),
            flush=True,
        )
        for k, s in rss.items():
            print(f"    RSS {'worker ' + k if k != 'this process' else k}: {_rss_line(s)}")

    if a.log:
        with open(a.log, "w") as f:
            json.dump(log, f, indent=1, default=str)
    if len(results) == 2:
        rt, rd = results["threads"], results["dask"]
        same = (rt.yield_, rt.ci, rt.cpk, rt.passed) == (
            rd.yield_,
            rd.ci,
            rd.cpk,
            rd.passed,
        ) and all(
            rt.quantities[k].stats.as_tuple() == rd.quantities[k].stats.as_tuple()
            and rt.quantities[k].fail_fraction == rd.quantities[k].fail_fraction
            for k in rt.quantities
            if k != CPU_KEY
        )
        same = same and [w["sample"] for w in rt.worst] == [w["sample"] for w in rd.worst]
        print(
            "goal (issue 14) same result on Dask as on threads (yield, CI, Cpk, every "
            f"statistic, worst samples): {'met' if same else 'NOT met'}"
        )
        ratio = log["runs"]["dask"]["cpu_s"] / log["runs"]["threads"]["cpu_s"]
        print(f"Dask workers' CPU / threads' CPU for the same run: {ratio:.2f}")
    dask_rss = [
        max(m for _, m in s)
        for k, s in log["runs"].get("dask", {}).get("rss_mib", {}).items()
        if k != "this process" and s
    ]
    if dask_rss:
        print(
            f"goal (issue 14) bounded memory: peak worker RSS {max(dask_rss):.0f} MiB for "
            f"{a.samples} samples (flat over time above; compare runs of other sizes)"
        )


if __name__ == "__main__":
    main()
