"""A sampled study kind for the interrupt tests (issue 13): a Monte-Carlo whose chunks from
``stall_from`` on announce themselves (touch $GEARTE_TEST_STALL) and wait until the file
$GEARTE_TEST_STALL.release exists (at most 60 s), then a second, short Monte-Carlo. Runs through
gearte.execution exactly like a real kind."""

from __future__ import annotations

import os
import time
from pathlib import Path

from pydantic import Field

from gearte.execution import Chunk, RunningStats, map_chunks, seeded_chunks
from gearte.io.schema import CaseBase, StrictModel
from gearte.results import AnalysisResult, StudyResult

KIND = "stall_mc_test"
REFERENCES: list[str] = []
FIGURES = ""


class Mc(StrictModel):
    samples: int = Field(default=10_000, ge=1, le=10_000_000)
    chunk_size: int = Field(default=1_000, ge=1)
    stall_from: int = Field(default=3, ge=0, description="first chunk that stalls")
    seed: int = 1


class Case(CaseBase):
    mc: Mc


def chunk_stats(task: tuple[Chunk, int]) -> RunningStats:
    chunk, stall_from = task
    marker = os.environ.get("GEARTE_TEST_STALL")
    if marker and chunk.index >= stall_from:
        Path(marker).touch()
        release = Path(marker + ".release")
        t0 = time.monotonic()
        while not release.exists() and time.monotonic() - t0 < 60:
            time.sleep(0.02)
    return RunningStats.of(chunk.rng().standard_normal(chunk.size))


def run(case: Case, options) -> StudyResult:
    mc = case.mc
    analyses = []
    for name, n, stall in (("first", mc.samples, mc.stall_from), ("second", 3 * mc.chunk_size, 99)):
        tasks = [(c, stall) for c in seeded_chunks(n, mc.chunk_size, mc.seed)]
        s = map_chunks(
            chunk_stats, tasks, options=options, reduce=RunningStats.merge, description=name
        )
        values = {"mean": s.mean, "samples": s.count}
        analyses.append(AnalysisResult(name=name, title=name, values=values))
    return StudyResult(case=case, analyses=analyses)
