"""First-run numba compile per study kind, cold and after `gearte warm-cache` (issue 12).

For each study kind (one bundled case per kind, :data:`gearte.warm.BENCH_CASES`), in fresh
processes (``gearte run CASE --no-report --no-progress --timings --samples 256``):

* **cold**: an empty ``NUMBA_CACHE_DIR``: every kernel the case uses is compiled — the process
  CPU seconds (``resource.getrusage`` of the child), gearte's own "numba load/compile" stage and
  the number of kernels numba compiled (its ``numba:compile`` events);
* **after warm-up**: ``gearte warm-cache`` once into another empty cache folder (its wall and CPU
  time printed), then the same run: what a user sees on the first run after ``make demo``.

``--coverage`` runs, after the warm-up, every bundled case (not only one per kind) and lists any
that still compiles a kernel: the warm-up must leave none.

Goals (issue 12): after ``make demo`` ≤ 5 s of compile/cache load on the first run of any kind;
cold, without warm-up, ≤ 10 s CPU per kind. The cold run is the baseline of the warm one; both
are measured in the same invocation. CPU times, as the shared machine's load stretches wall
times; the cold runs go ``--jobs`` at a time (default 2), which leaves their CPU times alone.

    python benchmarks/bench_compile.py [--kinds planetary,gear_pair] [--coverage] [--jobs 2]
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

from gearte.warm import BENCH_CASES

COLD_GOAL = 10.0  # s CPU, cold cache, per kind
WARM_GOAL = 5.0  # s of numba load/compile, first run after the warm-up


def _child_main(argv: list[str]) -> None:
    """``--child ARGS``: ``gearte ARGS`` in this process, then the kernels numba compiled."""
    from numba.core import event

    count = [0]
    cpu = [0.0]
    depth = [0]
    starts: list[float] = []

    class Count(event.Listener):
        def on_start(self, ev: event.Event) -> None:
            depth[0] += 1
            starts.append(time.process_time())

        def on_end(self, ev: event.Event) -> None:
            depth[0] -= 1
            t0 = starts.pop()
            if ev.data["dispatcher"].py_func.__module__.startswith("gearte"):
                count[0] += 1
            if depth[0] == 0:
                cpu[0] += time.process_time() - t0

    event.register("numba:compile", Count())
    from gearte.cli import main as gearte_main

    try:
        gearte_main(argv, standalone_mode=False)
    finally:
        print(f"compiled: {json.dumps({'kernels': count[0], 'cpu': cpu[0]})}", file=sys.stderr)


def run_cpu(args: list[str], cache: str) -> dict[str, float]:
    """Wall s, CPU s (the child and its worker processes: ``wait4``), gearte's timings and
    numba's compiles of ``gearte ARGS`` in a fresh process with ``NUMBA_CACHE_DIR=cache``."""
    env = {**os.environ, "NUMBA_CACHE_DIR": cache}
    cmd = [sys.executable, os.path.abspath(__file__), "--child", *args]
    w0 = time.perf_counter()
    p = subprocess.Popen(cmd, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    out = p.stdout.read() if p.stdout else ""
    err = p.stderr.read() if p.stderr else ""
    _, status, ru = os.wait4(p.pid, 0)
    wall = time.perf_counter() - w0
    if os.waitstatus_to_exitcode(status) != 0:
        raise SystemExit(f"gearte {' '.join(args)} failed:\n{err[-2000:]}{out[-500:]}")
    res: dict[str, float] = {"wall": wall, "cpu": ru.ru_utime + ru.ru_stime}
    for line in err.splitlines():
        if line.startswith("timings [s]: "):
            res.update(json.loads(line[len("timings [s]: ") :]))
        if line.startswith("compiled: "):
            c = json.loads(line[len("compiled: ") :])
            res["kernels"], res["compile_cpu"] = c["kernels"], c["cpu"]
    return res


def case_args(case: str, out: str) -> list[str]:
    return ["run", case, "--no-report", "--no-progress", "--timings", "--samples", "256"] + [
        "--out",
        out,
    ]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--kinds", default=",".join(BENCH_CASES))
    ap.add_argument("--coverage", action="store_true", help="also run every bundled case warm")
    ap.add_argument("--jobs", type=int, default=min(2, os.cpu_count() or 1))
    args = ap.parse_args()
    kinds = args.kinds.split(",")
    load0 = os.getloadavg()[0]
    with tempfile.TemporaryDirectory() as tmp:
        warm_dir = str(Path(tmp, "warm"))

        def cold(k: str) -> dict[str, float]:
            return run_cpu(case_args(BENCH_CASES[k], str(Path(tmp, "out", k))), str(Path(tmp, k)))

        with ThreadPoolExecutor(max_workers=max(1, args.jobs)) as pool:
            colds = dict(zip(kinds, pool.map(cold, kinds), strict=True))
        w0 = time.perf_counter()
        every = args.coverage or set(kinds) == set(BENCH_CASES)
        warm_up = run_cpu(
            ["warm-cache"] + ([] if every else [a for k in kinds for a in ("--kind", k)]), warm_dir
        )
        warm_up["wall"] = time.perf_counter() - w0
        warms = {
            k: run_cpu(case_args(BENCH_CASES[k], str(Path(tmp, "out", k))), warm_dir) for k in kinds
        }
        cov: dict[str, dict[str, float]] = {}
        if args.coverage:
            from gearte.cases import list_cases

            for c in list_cases():
                cov[c] = run_cpu(case_args(c, str(Path(tmp, "out", "c_" + c))), warm_dir)
    load1 = os.getloadavg()[0]

    print(f"load average {load0:.1f} at the start, {load1:.1f} at the end (2 cores: > 2 = shared)")
    print(
        f"gearte warm-cache ({'every kind' if every else ', '.join(kinds)}): "
        f"{warm_up['wall']:.1f} s wall, "
        f"{warm_up['cpu']:.1f} s CPU (all its processes)"
    )
    print(
        f"{'kind':14s} {'case':30s} {'cold CPU':>9s} {'compiled':>9s} {'compile':>8s} "
        f"{'warm CPU':>9s} {'compiled':>9s} {'load':>7s}"
    )
    for k in kinds:
        c, w = colds[k], warms[k]
        print(
            f"{k:14s} {BENCH_CASES[k]:30s} {c['cpu']:8.1f}s {int(c.get('kernels', 0)):9d} "
            f"{c.get('compile_cpu', 0):7.1f}s {w['cpu']:8.1f}s {int(w.get('kernels', 0)):9d} "
            f"{w.get('numba load/compile', 0):6.2f}s"
        )
    worst_cold = max(kinds, key=lambda k: colds[k]["cpu"])
    worst_warm = max(kinds, key=lambda k: warms[k].get("numba load/compile", 0.0))
    wc = colds[worst_cold]["cpu"]
    ww = warms[worst_warm].get("numba load/compile", 0.0)
    met = [k for k in kinds if colds[k]["cpu"] <= COLD_GOAL]
    print(
        f"goal cold <= {COLD_GOAL:g} s CPU per kind: worst {wc:.1f} s ({worst_cold}); "
        f"met for {len(met)}/{len(kinds)} ({', '.join(met) or 'none'}) — "
        f"{'met' if wc <= COLD_GOAL else 'NOT met'}"
    )
    print(
        f"goal after warm-up <= {WARM_GOAL:g} s of numba load/compile: worst {ww:.2f} s "
        f"({worst_warm}), kernels compiled after warm-up: "
        f"{sum(int(warms[k].get('kernels', 0)) for k in kinds)} — "
        f"{'met' if ww <= WARM_GOAL else 'NOT met'}"
    )
    if args.coverage:
        bad = {c: r for c, r in cov.items() if r.get("kernels", 0)}
        worst = max(cov, key=lambda c: cov[c].get("numba load/compile", 0.0))
        print(
            f"coverage: {len(cov)} bundled cases after the warm-up, worst numba load/compile "
            f"{cov[worst].get('numba load/compile', 0.0):.2f} s ({worst}); "
            + (
                "every case loads all its kernels from the cache"
                if not bad
                else "still compiling: "
                + ", ".join(f"{c} ({int(r['kernels'])} kernels)" for c, r in bad.items())
            )
        )


if __name__ == "__main__":
    if len(sys.argv) > 1 and sys.argv[1] == "--child":
        _child_main(sys.argv[2:])
    else:
        main()
