"""Every bundled case run by the CLI, cold and warm, with the time of each stage (issue 12).

For each case, ``gearte run NAME --timings`` runs twice in a fresh process with its own numba cache
folder: *cold* (empty cache: kernels compiled) and *warm* (cache filled by the cold run). The CLI
reports the time of each stage (``results.json`` records the same, but for the final write);
this script adds the process's wall and CPU time and prints, per case and run:

* imports (gearte, the case's kind and what loading the case imports), numba cache load or compile
  (when the kind's kernels were imported before the run), analyses, figures (build), render
  (PNG), html, csv, write, and *startup/exit* (the wall time outside gearte's own timing:
  interpreter start, exit);
* the ratio of everything else to the analyses (the analyses are the baseline: the work the user
  asked for), and the issue's goals: a warm run of a case whose analyses take < 1 s finishes in
  ≤ 1.5 s wall, and for every case the time outside the analyses is ≤ the analyses + 1 s.

Run ``.venv/bin/python benchmarks/bench_cases.py [--cases a,b] [--warm-only]``. Timings on a
loaded machine are wall times stretched by the load: compare the CPU column, and run on a quiet
machine to check the goals.
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

STAGES = ["imports", "numba", "analyses", "figures", "render", "html", "csv", "write", "startup"]


def run_once(case: str, cache_dir: str, out_dir: str) -> dict[str, float]:
    """One CLI run; the stage times [s], the process's ``wall`` and ``cpu`` (user + system)."""
    env = dict(os.environ, NUMBA_CACHE_DIR=cache_dir)
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    p = subprocess.run(
        [sys.executable, "-m", "gearte", "run", case, "--out", out_dir, "--no-progress",
         "--timings"],
        env=env, capture_output=True, text=True, check=False,
    )  # fmt: skip
    wall = time.perf_counter() - t0
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    if p.returncode != 0:
        raise RuntimeError(f"{case}: exit {p.returncode}\n{p.stderr[-2000:]}")
    line = next(ln for ln in p.stderr.splitlines() if ln.startswith("timings [s]: "))
    t: dict[str, float] = json.loads(line.removeprefix("timings [s]: "))
    out = {s: 0.0 for s in STAGES}
    for k, v in t.items():
        if k.startswith("imports") or k == "load case":
            out["imports"] += v
        elif k.startswith("analysis: "):
            out["analyses"] += v
        elif k.startswith("numba"):
            out["numba"] += v  # inside the analyses' intervals: shown, not added again
        elif k in out:
            out[k] += v
    out["startup"] = wall - t["total in gearte"]
    out["wall"] = wall
    out["cpu"] = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    return out


def _row(name: str, label: str, r: dict[str, float]) -> str:
    other = r["wall"] - r["analyses"]
    ratio = other / r["analyses"] if r["analyses"] > 0 else float("inf")
    goals = []
    if label == "warm" and r["analyses"] < 1.0:
        goals.append("≤1.5s " + ("ok" if r["wall"] <= 1.5 else "MISS"))
    goals.append("other≤an+1s " + ("ok" if other <= r["analyses"] + 1.0 else "MISS"))
    cells = " ".join(f"{r[s]:7.3f}" for s in STAGES)
    return (
        f"{name:36s} {label:4s} {cells} {r['wall']:7.2f} {r['cpu']:7.2f} {ratio:7.2f}  "
        + ", ".join(goals)
    )


def main() -> None:
    from gearte.cases import list_cases

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--cases", default="", help="comma-separated case names (default: all)")
    ap.add_argument("--warm-only", action="store_true", help="skip the cold-run row")
    args = ap.parse_args()
    names = [c for c in args.cases.split(",") if c] or list(list_cases())
    head = " ".join(f"{s:>7s}" for s in STAGES)
    print(f"{'case':36s} run  {head} {'wall':>7s} {'cpu':>7s} {'ratio':>7s}  goals")
    print("(seconds; ratio = (wall - analyses) / analyses; numba is inside analyses)")
    for name in names:
        with tempfile.TemporaryDirectory() as tmp:
            cache = str(Path(tmp) / "numba")
            cold = run_once(name, cache, str(Path(tmp) / "cold"))
            warm = run_once(name, cache, str(Path(tmp) / "warm"))
        if not args.warm_only:
            print(_row(name, "cold", cold), flush=True)
        print(_row(name, "warm", warm), flush=True)


if __name__ == "__main__":
    main()
