"""Optimal assembly phases of a planetary (Wang 2013 cases, issue 12: same optimum in ≤ 10 %).

gearte: :func:`gearte.runners.planetary_assembly.optimal_assembly` with the case's settings
(4096 quasi-random starts in one compiled batch, Nelder-Mead from the best 8 + the paper's rule,
each restarted once), the polish compiled.

Baselines, same run, same starts and the same Nelder-Mead steps:

* **twin** (today's algorithm before issue 12): SciPy's ``minimize(method="Nelder-Mead")`` on
  gearte's compiled amplitude, called once per step from Python (``compiled=False``);
* **numpy**: SciPy's Nelder-Mead on a plain-numpy amplitude — the grouped phasors
  (``group_phasors``) and a grid of 8 n_max nodes with vectorised Newton refinement from every
  local extremum (``exact_extremes_numpy``, the same accuracy) — what a competent user writes
  without numba. Its start batch is timed once, its polish on ``--numpy-polish`` starts and
  scaled to ``polish + 1``.

CPU times (``time.process_time``), which a loaded machine stretches less than wall times. The
optimum of every method is printed with its relative difference to gearte's (goal ≤ 1e-9).

    PYTHONPATH=src python benchmarks/bench_planetary_assembly.py [--cases a,b] [--repeat 3]
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from gearte.io.case_file import load_case
from gearte.models.planetary_errors import exact_extremes_numpy, frequency_basis, group_phasors
from gearte.runners.planetary_assembly import optimal_assembly, paper_rule_assembly
from gearte.studies.planetary import build_terms


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--cases", default="wang2013_2kh_eq9,wang2013_2kh_derived")
    ap.add_argument("--repeat", type=int, default=3, help="gearte runs per case (best CPU)")
    ap.add_argument("--numpy-polish", type=int, default=1, help="starts polished by numpy NM")
    args = ap.parse_args()
    asec = 648000 / np.pi
    for name in args.cases.split(","):
        case = load_case(name)
        terms, mags, angs = build_terms(case)
        ao = case.analyses.assembly
        starts, polish = (ao.starts, ao.polish) if ao is not None else (4096, 8)
        paper = paper_rule_assembly(terms, mags, angs)
        ref = angs.get(terms.reference_angle, 0.0) if terms.reference_angle else 0.0
        kw = dict(reference_value=ref, starts=starts, polish=polish, extra_starts=[paper.angles])
        optimal_assembly(terms, mags, **{**kw, "starts": 16, "polish": 1})  # JIT / cache load
        cpu = []
        for _ in range(args.repeat):
            t0 = time.process_time()
            fast = optimal_assembly(terms, mags, **kw)
            cpu.append(time.process_time() - t0)
        t_fast = min(cpu)
        t0 = time.process_time()
        twin = optimal_assembly(terms, mags, compiled=False, **kw)
        t_twin = time.process_time() - t0

        # numpy: the same Nelder-Mead on a numpy objective, fewer starts, scaled per start
        _, harm, _ = frequency_basis(terms)
        # optimal_assembly imports sample_extremes from the model where it calls it: swap it there
        import gearte.models.planetary_errors as pa

        real = pa.sample_extremes

        def numpy_extremes(t, m, th, harm=harm):  # the signature of sample_extremes
            return exact_extremes_numpy(*group_phasors(t, m, th), harm)

        n_np = min(args.numpy_polish, polish)
        pa.sample_extremes = numpy_extremes
        try:
            t0 = time.process_time()
            slow = optimal_assembly(
                terms, mags, compiled=False, **{**kw, "polish": n_np, "extra_starts": []}
            )
            t_run = time.process_time() - t0
        finally:
            pa.sample_extremes = real
        # its start batch once, its polish scaled from n_np starts to polish + 1
        mvec = np.array([mags[k] for k in terms.magnitudes])
        th = np.zeros((starts, len(terms.angles)))
        t0 = time.process_time()
        numpy_extremes(terms, np.broadcast_to(mvec, (starts, mvec.size)), th)
        t_batch = time.process_time() - t0
        t_np = t_batch + (t_run - t_batch) * (polish + 1) / n_np
        rel_twin = abs(twin.amplitude - fast.amplitude) / fast.amplitude
        rel_np = abs(slow.amplitude - fast.amplitude) / fast.amplitude
        print(f"{name}: {len(terms.free_angles)} free angles, {starts} starts, polish {polish}+1")
        print(
            f"  gearte (compiled polish): {t_fast:7.3f} s CPU (best of {args.repeat}: "
            + ", ".join(f"{c:.3f}" for c in cpu)
            + f")  optimum {fast.amplitude * asec:.6f}″"
        )
        print(
            f"  twin (SciPy NM, compiled amplitude): {t_twin:7.3f} s CPU  ratio "
            f"{t_twin / t_fast:6.1f}× (goal ≥ 10×)  optimum rel. diff {rel_twin:.1e}"
        )
        print(
            f"  numpy (SciPy NM, numpy grid + Newton): {t_np:7.3f} s CPU (scaled from {n_np} "
            f"start(s) to {polish + 1})  ratio {t_np / t_fast:6.1f}×  optimum of its "
            f"{n_np} start(s) rel. diff {rel_np:.1e}"
        )


if __name__ == "__main__":
    main()
