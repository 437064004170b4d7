"""A study kind for signal tests: ``stall = true`` announces itself (touches $GEARTE_TEST_STALL)
and sleeps until a signal stops it."""

from __future__ import annotations

import os
import time
from pathlib import Path

from pydantic import Field

from gearte.io.schema import CaseBase, StrictModel
from gearte.results import AnalysisResult, StudyResult

KIND = "stall_test"
REFERENCES: list[str] = []
FIGURES = "gearte.plotting"


class Demo(StrictModel):
    length_mm: float = Field(gt=0, le=1000)
    stall: bool = False


class Case(CaseBase):
    demo: Demo


def run(case: Case, options) -> StudyResult:
    if case.demo.stall:
        Path(os.environ["GEARTE_TEST_STALL"]).touch()
        time.sleep(120)
    a = AnalysisResult(name="demo", title="Demo", values={"twice [mm]": 2 * case.demo.length_mm})
    return StudyResult(case=case, analyses=[a])
