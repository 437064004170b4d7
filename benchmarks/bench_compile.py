"""First-run numba compile per study kind, cold and after `gearte warm-cache` (issue 12).

For each kind, in fresh processes (``gearte run CASE --no-report --no-progress --timings
--samples 256``, one case per kind from :data:`gearte.warm.WARM_CASES`):

* **cold**: an empty ``NUMBA_CACHE_DIR``: every kernel the case uses is compiled — the process
  CPU seconds (``resource.getrusage`` of the child) and gearte's own "numba load/compile" stage;
* **after warm-up**: ``gearte warm-cache`` once into another empty cache folder (its CPU time
  printed too), then the same run: what a user sees on the first run after ``make demo``.

Goals (issue 12): after ``make demo`` ≤ 5 s of compile on the first run of any kind; cold,
without warm-up, ≤ 10 s CPU per kind. The baseline of the second is the cold run itself; both
are measured in the same invocation. CPU times, as the shared machine's load stretches wall
times.

    python benchmarks/bench_compile.py [--kinds planetary,gear_pair]
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from gearte.warm import WARM_CASES

GEARTE = [sys.executable, "-m", "gearte"]


def child_cpu() -> float:
    r = resource.getrusage(resource.RUSAGE_CHILDREN)
    return r.ru_utime + r.ru_stime


def run(args: list[str], cache: str) -> tuple[float, float, dict[str, float]]:
    """(wall s, CPU s, timings) of ``gearte ARGS`` with ``NUMBA_CACHE_DIR=cache``."""
    env = {**os.environ, "NUMBA_CACHE_DIR": cache}
    c0, w0 = child_cpu(), time.perf_counter()
    p = subprocess.run(GEARTE + args, env=env, capture_output=True, text=True, check=False)
    wall, cpu = time.perf_counter() - w0, child_cpu() - c0
    if p.returncode != 0:
        raise SystemExit(f"gearte {' '.join(args)} failed:\n{p.stderr[-2000:]}")
    timings: dict[str, float] = {}
    for line in p.stderr.splitlines():
        if line.startswith("timings [s]: "):
            timings = json.loads(line[len("timings [s]: ") :])
    return wall, cpu, timings


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--kinds", default=",".join(WARM_CASES))
    args = ap.parse_args()
    kinds = args.kinds.split(",")
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        warm_cache = str(Path(tmp, "warm"))
        kind_args = [a for k in kinds for a in ("--kind", k)]
        w_warm, c_warm, _ = run(["warm-cache", *kind_args], warm_cache)
        for k in kinds:
            case = WARM_CASES[k][0]
            out = str(Path(tmp, "out", k))
            cmd = ["run", case, "--no-report", "--no-progress", "--timings", "--samples", "256"]
            cmd += ["--out", out]
            cold = run(cmd, str(Path(tmp, "cold", k)))
            warm = run(cmd, warm_cache)
            rows.append((k, case, cold, warm))
    print(f"gearte warm-cache ({', '.join(kinds)}): {c_warm:.1f} s CPU, {w_warm:.1f} s wall")
    print(
        f"{'kind':14s} {'case':30s} {'cold CPU':>9s} {'cold compile':>13s} "
        f"{'warm CPU':>9s} {'warm load':>10s}  goals: cold CPU <= 10 s, warm load <= 5 s"
    )
    for k, case, cold, warm in rows:
        print(
            f"{k:14s} {case:30s} {cold[1]:8.1f}s {cold[2].get('numba load/compile', 0):12.1f}s "
            f"{warm[1]:8.1f}s {warm[2].get('numba load/compile', 0):9.2f}s"
        )


if __name__ == "__main__":
    main()
