"""Selective assembly of a lot of 100 RV reducers' parts (issue 16: ≤ 2 min on 2 cores).

gearte: the ``rv_lot`` study end to end on a synthetic lot of ``--reducers`` reducers written by
``examples/lots/make_synthetic_lot.py`` (read the measurement files, linearised model, scores of
every disc set × 6 disc orientations × crank set × 12 crank orientations, exact assignment, 200
random assemblies, orientation-only rule, full-model check of the chosen reducers; no pin
grading). The generated case chooses planet phasing among 4 spline positions: 72 orientations
per pairing. Wall time printed, and the scoring step alone.

Baselines of the scoring step, same run (timed on ``--sample`` random pairings × orientations
and scaled to the whole table; their scores are compared with gearte's on those samples):

* **loop**: the plain loop a user of the linearised model writes — build each oriented reducer
  and its offsets with the model's ``assemble()`` and apply the same sensitivities
  (:func:`gearte.runners.selective_assembly.score_lot_loop`, numpy inside);
* **full model**: solve the full non-linear model for every pairing and orientation
  (:func:`gearte.runners.selective_assembly.full_model_te`).

    PYTHONPATH=src python benchmarks/bench_selective_assembly.py [--reducers 100] [--sample 20]
"""

from __future__ import annotations

import argparse
import importlib.util
import tempfile
import time
from pathlib import Path

import numpy as np

from gearte.cases import examples_dir
from gearte.io.case_file import load_case
from gearte.models.rv_load_sharing import output_positions
from gearte.runners import selective_assembly as sa
from gearte.studies import run_case
from gearte.studies.rv_lot import build_lot
from gearte.units import rad_to_arcsec


def _maker():
    path = examples_dir() / "lots" / "make_synthetic_lot.py"
    spec = importlib.util.spec_from_file_location("make_synthetic_lot", path)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--reducers", type=int, default=100)
    ap.add_argument("--sample", type=int, default=20, help="baseline evaluations timed")
    args = ap.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        root = Path(tmp) / "examples"
        folder = root / "lots" / "bench_lot"
        _maker().make(folder, reducers=args.reducers, seed=7)
        case_file = root / "bench_lot_lot.toml"
        text = case_file.read_text(encoding="utf-8").split("[analyses.pin_grading]")[0]
        case_file.write_text(text, encoding="utf-8")
        t0 = time.perf_counter()
        c0 = time.process_time()
        res = run_case(load_case(case_file))
        wall, cpu = time.perf_counter() - t0, time.process_time() - c0
        v = res["selective_assembly"].values
        print(
            f"gearte rv_lot, {v['reducers']} reducers, {v['pairings_scored']} pairings × "
            f"orientations: {wall:.1f} s wall ({cpu:.1f} s CPU) end to end; scoring "
            f"{v['scoring_time [s]']:.2f} s, assignment {v['assignment_time [s]']:.2f} s, "
            f"full-model re-scoring {v['rescoring_time [s]']:.2f} s "
            f"({v['full_model_evaluations']} solves, {v['rescoring_rounds']} rounds, certified: "
            f"{v['rescoring_certified']})"
        )
        print(
            f"  in spec: optimiser {v['reducers_in_spec']} by the full model (first, "
            f"linearised round claimed {v['reducers_in_spec_linearised_only']}), orientation only "
            f"{v['reducers_in_spec_orientation_only']}, random mean "
            f"{v['reducers_in_spec_random_mean']:.2f}"
        )
        design, lot = build_lot(load_case(case_file))
        sec = res.case.analyses.selective_assembly
        theta = output_positions(sec.positions)
        torque = sec.torque_Nm * 1e3
        model = sa.linear_te_model(design, torque, theta)
        t1 = time.perf_counter()
        table = sa.score_lot(design, lot, model, sec.planet_indexings)
        t_fast = time.perf_counter() - t1
        rng = np.random.default_rng(0)
        kd, od, kc, oc = table.pp.shape
        picks = [
            (
                int(rng.integers(kd)),
                int(rng.integers(od)),
                int(rng.integers(kc)),
                int(rng.integers(oc)),
            )
            for _ in range(args.sample)
        ]
        # loop baseline on single-pairing lots (same code path as score_lot_loop)
        t1 = time.perf_counter()
        diff = 0.0
        for d, o_d, c, o_c in picks:
            sub = sa.Lot(
                [lot.disc_serials[d]], [lot.discs[d]], lot.disc_bores[[d]],
                [lot.crank_serials[c]], lot.cam_eccentricity[[c]], lot.cam_phase[[c]],
                lot.planet_runout[[c]], lot.cam_clearance[[c]], lot.carrier_clearance[[c]],
            )  # fmt: skip
            one = sa.score_lot_loop(design, sub, model, sec.planet_indexings)
            diff = max(diff, abs(one.pp[0, o_d, 0, o_c] - table.pp[d, o_d, c, o_c]))
        t_loop = (time.perf_counter() - t1) / (len(picks) * od * oc) * table.pp.size
        t1 = time.perf_counter()
        fdiff = 0.0
        for d, o_d, c, o_c in picks:
            red = sa.assembled_reducer(design, lot, d, c, table.orientation(o_d, o_c))
            f = sa.full_model_te(red, torque, theta)
            fdiff = max(fdiff, abs(f - table.pp[d, o_d, c, o_c]))
        t_full = (time.perf_counter() - t1) / len(picks) * table.pp.size
        print(f"scoring {table.pp.size} pairings × orientations (wall):")
        print(f"  gearte score_lot        {t_fast:10.2f} s")
        print(
            f"  loop baseline           {t_loop:10.1f} s (scaled from {len(picks) * od * oc}; "
            f"ratio {t_loop / t_fast:.0f}×; max |Δ| {rad_to_arcsec(diff):.2e} arcsec)"
        )
        print(
            f"  full model per pairing  {t_full:10.1f} s (scaled from {len(picks)}; ratio "
            f"{t_full / t_fast:.0f}×; linearised − full max {rad_to_arcsec(fdiff):.2f} arcsec)"
        )


if __name__ == "__main__":
    main()
