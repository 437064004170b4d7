"""Every bundled case run by the CLI, warm (and with ``--cold`` cold), with the time of each stage
(issue 12).

For each case ``gearte run NAME --timings`` runs in a fresh process against one numba cache
folder: first an untimed run that fills the cache (shown as the *cold* row with ``--cold``, where
each case gets its own empty cache), then ``--repeat`` timed *warm* runs (the fastest is shown).
The CLI reports the time of each stage (``results.json`` records the same, but for the final
write); this script adds the process's wall and CPU time (the report worker and its helpers
included) and prints, per case:

* imports (gearte, what loading the case imports, the preflight), numba (its import where a
  study imports it, cache load or compile, in the preflight or the analyses), analyses (without
  numba: the work the user asked for), figures (build),
  render (PNG, forked workers), the slowest figure, html, csv, write, and *startup/exit* (the
  wall time outside gearte's own timing: interpreter start, exit); then, in the report process,
  its warm-up (importing matplotlib, drawing a first figure; it runs beside the case load and
  the analyses), how long it waited for the parent in all (*rp idle*: ~0 means the warm-up, not
  the analyses, held the report back) and how long it built and drew the figures of analyses
  streamed to it while the next ones ran (*rp early*, off the critical path; *figures* and
  *render* are what was left after the final result came);
* *other* = wall − analyses: everything the user did not ask for, and its ratio to the analyses.

Then one summary line per goal of issue 12: a warm run of a case whose analyses take < 1 s
finishes in ≤ 1.5 s wall; for every case other ≤ analyses + 1 s; no figure over 1 s; a Wang 2013
case's whole warm run ≤ 2.5 s. Each says how many cases meet it and which miss by how much.

The child processes run with bytecode writing on (``PYTHONDONTWRITEBYTECODE`` removed), as an
installed gearte has its ``.pyc`` files. Run ``.venv/bin/python benchmarks/bench_cases.py
[--cases a,b] [--repeat N] [--cold]``. On a loaded machine wall times are stretched by the load:
read the CPU column and the printed load average, and check the goals on a quiet machine.
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

STAGES = ["imports", "numba", "analyses", "figures", "render", "fig max", "html", "csv", "write",
          "startup", "rp warm", "rp idle", "rp early"]  # fmt: skip
REPORT_PROCESS = {"report process: warm-up": "rp warm",
                  "report process: waited for the result": "rp idle",
                  "report process: figures during the analyses": "rp early"}  # fmt: skip
WANG_GOAL_S = 2.5
FAST_GOAL_S = 1.5
FIGURE_GOAL_S = 1.0


def run_once(case: str, cache_dir: str, out_dir: str) -> dict[str, float]:
    """One CLI run; the stage times [s], the process's ``wall`` and ``cpu`` (user + system, its
    reaped child processes included)."""
    env = dict(os.environ, NUMBA_CACHE_DIR=cache_dir)
    env.pop("PYTHONDONTWRITEBYTECODE", None)
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
    in_analyses = 0.0  # numba's import and cache load inside the analyses' intervals
    for k, v in t.items():
        if k.startswith(("numba", "imports: numba")):  # its import and cache load / compile
            out["numba"] += v
            if not k.endswith(": preflight"):
                in_analyses += v
            else:  # inside the preflight's interval
                out["imports"] -= v
        elif k.startswith("imports") or k in ("load case", "preflight"):
            out["imports"] += v
        elif k.startswith("analysis: "):
            out["analyses"] += v
        elif k == "render: slowest figure":
            out["fig max"] = v
        elif k in REPORT_PROCESS:
            out[REPORT_PROCESS[k]] = v
        elif k in out:
            out[k] += v
    out["analyses"] = max(0.0, out["analyses"] - in_analyses)
    out["startup"] = wall - t["total in gearte"]
    out["wall"] = wall
    out["cpu"] = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    out["fallback"] = float(any(k.startswith("report process failed") for k in t))
    return out


# What any warm run of a case with a compiled kernel cannot avoid, each in a fresh process
FLOOR_STEPS = [
    ("interpreter", "pass"),
    ("+ numpy", "import numpy"),
    ("+ numba import", "import numpy, numba"),
    (
        "+ one cached kernel call",
        "from gearte._blas import preload_scipy_blas; preload_scipy_blas()\n"
        "from gearte.models.contact_law import max_contact_pressure_scalar as f\n"
        "f(1000.0, -40.0, 3.0, 1.1e5, 10.0)",
    ),
    (
        "+ load the case (pydantic)",
        "from gearte._blas import preload_scipy_blas; preload_scipy_blas()\n"
        "from gearte.io.case_file import load_case; load_case('hu2020_rv80e_initial')\n"
        "from gearte.models.contact_law import max_contact_pressure_scalar as f\n"
        "f(1000.0, -40.0, 3.0, 1.1e5, 10.0)",
    ),
    (
        "report: matplotlib + 1 figure",
        "import io\nfrom gearte.plotting import new_figure\n"
        "fig, ax = new_figure(); ax.plot([0, 1], [0, 1]); ax.set_xlabel('x [mm]')\n"
        "fig.savefig(io.BytesIO(), format='png', dpi=100)",
    ),
]


def floor(cache_dir: str, repeat: int) -> dict[str, tuple[float, float]]:
    """Each of :data:`FLOOR_STEPS` in fresh processes (after one untimed run that fills the numba
    cache): the fastest wall [s] and the CPU [s] of that run."""
    env = dict(os.environ, NUMBA_CACHE_DIR=cache_dir)
    env.pop("PYTHONDONTWRITEBYTECODE", None)
    out: dict[str, tuple[float, float]] = {}
    for label, code in FLOOR_STEPS:
        runs = []
        for i in range(repeat + 1):
            before = resource.getrusage(resource.RUSAGE_CHILDREN)
            t0 = time.perf_counter()
            subprocess.run([sys.executable, "-c", code], env=env, check=True)
            wall = time.perf_counter() - t0
            after = resource.getrusage(resource.RUSAGE_CHILDREN)
            cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
            if i > 0:  # the first run fills the cache and the bytecode
                runs.append((wall, cpu))
        out[label] = min(runs)
    return out


def _row(name: str, label: str, r: dict[str, float]) -> str:
    other = r["wall"] - r["analyses"]
    ratio = other / r["analyses"] if r["analyses"] > 0 else float("inf")
    cells = " ".join(f"{r[s]:7.3f}" for s in STAGES)
    flag = "  (report rendered in-process: the report process failed)" if r["fallback"] else ""
    return (
        f"{name:32s} {label:4s} {cells} {r['wall']:7.2f} {r['cpu']:7.2f} {other:7.2f} "
        f"{ratio:8.1f}{flag}"
    )


def _summary(goal: str, rows: list[tuple[str, float, float]]) -> str:
    """``rows``: (case, measured, limit); one line: how many meet the goal, who misses by how
    much."""
    misses = [(n, m, lim) for n, m, lim in rows if m > lim]
    verdict = "met" if not misses else "NOT met"
    text = f"goal {goal}: {len(rows) - len(misses)}/{len(rows)} cases meet it — {verdict}"
    if misses:
        text += "; misses: " + ", ".join(
            f"{n} {m:.2f} s (+{m - lim:.2f} s)" for n, m, lim in misses
        )
    return text


def main() -> None:
    from gearte.cases import list_cases

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--cases", default="", help="comma-separated case names (default: all)")
    ap.add_argument("--repeat", type=int, default=1, help="timed warm runs per case (fastest)")
    ap.add_argument("--cold", action="store_true", help="also show the cold run (empty cache)")
    ap.add_argument(
        "--cache-dir", default="", help="numba cache folder to use and keep (default: a new one)"
    )
    ap.add_argument("--no-floor", action="store_true", help="skip the floor measurement")
    args = ap.parse_args()
    names = [c for c in args.cases.split(",") if c] or list(list_cases())
    print(f"load average at start: {os.getloadavg()[0]:.2f} (cores: {os.cpu_count()})")
    head = " ".join(f"{s:>7s}" for s in STAGES)
    print(f"{'case':32s} run  {head} {'wall':>7s} {'cpu':>7s} {'other':>7s} {'ratio':>8s}")
    print("(seconds; analyses without numba; other = wall - analyses; ratio = other / analyses;"
          " cpu = the processes' user + system)")  # fmt: skip
    warm_rows: dict[str, dict[str, float]] = {}
    with tempfile.TemporaryDirectory() as tmp:
        shared = args.cache_dir or str(Path(tmp) / "numba")
        floors = {} if args.no_floor else floor(shared, max(3, args.repeat))
        for label, (wall, cpu) in floors.items():
            print(f"floor: {label:32s} wall {wall:6.3f} s  cpu {cpu:6.3f} s", flush=True)
        for name in names:
            cache = str(Path(tmp) / f"numba-{name}") if args.cold else shared
            cold = run_once(name, cache, str(Path(tmp) / "out"))
            if args.cold:
                print(_row(name, "cold", cold), flush=True)
            warm = min(
                (run_once(name, cache, str(Path(tmp) / "out")) for _ in range(max(1, args.repeat))),
                key=lambda r: r["wall"],
            )
            warm_rows[name] = warm
            print(_row(name, "warm", warm), flush=True)
    print(f"load average at end: {os.getloadavg()[0]:.2f}")
    fast = [(n, r["wall"], FAST_GOAL_S) for n, r in warm_rows.items() if r["analyses"] < 1.0]
    print(_summary(f"warm run ≤ {FAST_GOAL_S} s wall where analyses < 1 s", fast))
    other = [(n, r["wall"] - r["analyses"], r["analyses"] + 1.0) for n, r in warm_rows.items()]
    print(_summary("other ≤ analyses + 1 s (measured: other)", other))
    figs = [(n, r["fig max"], FIGURE_GOAL_S) for n, r in warm_rows.items()]
    print(_summary(f"no figure over {FIGURE_GOAL_S} s (measured: slowest figure)", figs))
    wang = [(n, r["wall"], WANG_GOAL_S) for n, r in warm_rows.items() if n.startswith("wang2013")]
    if wang:
        print(_summary(f"Wang 2013 whole warm run ≤ {WANG_GOAL_S} s wall", wang))
    cpu = sum(r["cpu"] for r in warm_rows.values())
    print(f"warm runs: {len(warm_rows)} cases, {cpu:.1f} s CPU in all")
    if floors:
        w, c = floors["+ load the case (pydantic)"]
        print(
            f"floor of a warm run with a compiled kernel (interpreter, numpy, numba, one cached "
            f"kernel call, loading a case; no report): {w:.2f} s wall, {c:.2f} s CPU — "
            f"{FAST_GOAL_S - w:+.2f} s left of the {FAST_GOAL_S} s goal for the analyses and the "
            "report (matplotlib and one figure alone: "
            f"{floors['report: matplotlib + 1 figure'][0]:.2f} s wall in its own process)"
        )


if __name__ == "__main__":
    main()
