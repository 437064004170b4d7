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

``--kernels N`` prints, per kind, the N kernels of the cold run with the most compile CPU of
their own (exclusive: their callees' compiles subtracted; LLVM's re-optimisation of the callees
linked into a caller counts for the caller) and every kernel compiled for more than one
signature (a duplicate specialisation: a literal argument, a read-only or non-contiguous array,
an int where a float is meant — ``docs/numba.md``).

Goals (issue 12): after ``make demo`` ≤ 5 s of compile/cache load on the first run of any kind;
cold, without warm-up, ≤ 10 s CPU per kind. The cold run is the baseline of the warm one; both
are measured in the same invocation. CPU times, as the shared machine's load stretches wall
times; the cold runs go ``--jobs`` at a time (default 2), which leaves their CPU times alone.

    python benchmarks/bench_compile.py [--kinds planetary,gear_pair] [--coverage] [--jobs 2]
                                       [--kernels 8]
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
    starts: list[list[float]] = []  # [start CPU, CPU of the nested compiles]
    kernels: list[tuple[str, str, float]] = []  # name, signature, exclusive CPU

    class Count(event.Listener):
        def on_start(self, ev: event.Event) -> None:
            depth[0] += 1
            starts.append([time.process_time(), 0.0])

        def on_end(self, ev: event.Event) -> None:
            depth[0] -= 1
            t0, nested = starts.pop()
            dt = time.process_time() - t0
            if starts:
                starts[-1][1] += dt
            f = ev.data["dispatcher"].py_func
            if f.__module__.startswith("gearte"):
                count[0] += 1
                sig = ", ".join(str(a) for a in ev.data.get("args", ()))
                kernels.append((f"{f.__module__}.{f.__qualname__}", sig, dt - nested))
            if depth[0] == 0:
                cpu[0] += dt

    event.register("numba:compile", Count())
    from gearte.cli import main as gearte_main

    try:
        gearte_main(argv, standalone_mode=False)
    finally:
        print(f"compiled: {json.dumps({'kernels': count[0], 'cpu': cpu[0]})}", file=sys.stderr)
        print(f"kernels: {json.dumps(kernels)}", file=sys.stderr)


def run_cpu(args: list[str], cache: str) -> dict:
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
    res: dict = {"wall": wall, "cpu": ru.ru_utime + ru.ru_stime}
    for line in err.splitlines():
        if line.startswith("timings [s]: "):
            res.update(json.loads(line[len("timings [s]: ") :]))
        if line.startswith("compiled: "):
            c = json.loads(line[len("compiled: ") :])
            res["kernels"], res["compile_cpu"] = c["kernels"], c["cpu"]
        if line.startswith("kernels: "):
            res["kernel_list"] = json.loads(line[len("kernels: ") :])
    return res


def case_args(case: str, out: str) -> list[str]:
    return ["run", case, "--no-report", "--no-progress", "--timings", "--samples", "256"] + [
        "--out",
        out,
    ]


def print_kernels(kind: str, kernels: list, n: int) -> None:
    """The ``n`` gearte kernels of a cold run with the most exclusive compile CPU, and those
    compiled for more than one signature."""
    print(f"{kind}: the {n} costliest of {len(kernels)} gearte compiles (exclusive CPU s)")
    for name, _sig, dt in sorted(kernels, key=lambda r: -r[2])[:n]:
        print(f"  {dt:6.2f}  {name}")
    sigs: dict[str, list[tuple[str, float]]] = {}
    for name, sig, dt in kernels:
        sigs.setdefault(name, []).append((sig, dt))
    dup = {k: v for k, v in sigs.items() if len(v) > 1}
    for name, v in dup.items():
        print(f"  duplicate: {name} compiled {len(v)}× ({sum(d for _, d in v):.2f} s):")
        for sig, dt in v:
            print(f"      {dt:6.2f}  ({sig[:160]})")
    if not dup:
        print("  no kernel compiled for more than one signature")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--kinds", default=",".join(BENCH_CASES))
    ap.add_argument("--coverage", action="store_true", help="also run every bundled case warm")
    ap.add_argument("--jobs", type=int, default=min(2, os.cpu_count() or 1))
    ap.add_argument(
        "--kernels",
        type=int,
        default=0,
        metavar="N",
        help="per kind, the N costliest kernels of the cold run and the duplicate specialisations",
    )
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
    for k in kinds[: len(kinds) if args.kernels else 0]:
        print_kernels(k, colds[k].get("kernel_list", []), args.kernels)
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
