"""A small sampled study kind for the sweep tests (registered by tests/test_sweep.py).

It runs its Monte-Carlo through gearte.execution exactly like a real kind: seeded chunks whose
split does not depend on the backend, ``options`` handing over scheduler/workers, ordered
reduction with RunningStats.
"""

from __future__ import annotations

import numpy as np
from pydantic import Field

from gearte.errors import ConvergenceError
from gearte.execution import Chunk, RunningStats, map_chunks, seeded_chunks
from gearte.io.schema import CaseBase, StrictModel
from gearte.results import AnalysisResult, StudyResult

KIND = "mc_test"
REFERENCES: list[str] = []
FIGURES = ""


class Mc(StrictModel):
    sigma_mm: float = Field(gt=0, le=10, description="standard deviation of the error [mm]")
    offset_mm: float = Field(default=0.0, ge=-10, le=10, description="mean error [mm]")
    samples: int = Field(default=40_000, ge=1, le=10_000_000)
    chunk_size: int = Field(default=5_000, ge=1)
    seed: int = 1
    fail_above_mm: float | None = Field(default=None, gt=0)


class Case(CaseBase):
    mc: Mc


def chunk_stats(task: tuple[Chunk, float, float]) -> RunningStats:
    chunk, sigma, offset = task
    rng = chunk.rng()
    return RunningStats.of(offset + sigma * rng.standard_normal(chunk.size))


def run(case: Case, options) -> StudyResult:
    mc = case.mc
    if mc.fail_above_mm is not None and mc.sigma_mm > mc.fail_above_mm:
        raise ConvergenceError(f"sigma {mc.sigma_mm} above {mc.fail_above_mm} (on purpose)")
    samples = options.samples or mc.samples
    seed = mc.seed if options.seed is None else options.seed
    tasks = [(c, mc.sigma_mm, mc.offset_mm) for c in seeded_chunks(samples, mc.chunk_size, seed)]
    s = map_chunks(chunk_stats, tasks, options=options, reduce=RunningStats.merge)
    a = AnalysisResult(
        name="error",
        title="Sampled error",
        values={
            "mean [mm]": s.mean,
            "sd [mm]": s.sd,
            "samples": s.count,
            "quantiles [mm]": np.array([s.min, s.max]),
            "range": {"min [mm]": s.min, "max [mm]": s.max},
        },
    )
    return StudyResult(case=case, analyses=[a])
