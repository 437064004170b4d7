"""A minimal study kind used to test the foundation (registered by tests/conftest.py)."""

from __future__ import annotations

import numpy as np
from pydantic import Field

from gearte.io.schema import CaseBase, StrictModel
from gearte.results import AnalysisResult, StudyResult

KIND = "foundation_test"
REFERENCES: list[str] = []
FIGURES = "foundation_kind"


class Demo(StrictModel):
    length_mm: float = Field(gt=0, le=1000, description="a length [mm]")
    count: int = Field(default=3, ge=1, le=100)
    fail_in_plot: bool = False


class Case(CaseBase):
    demo: Demo


def run(case: Case, options) -> StudyResult:
    x = np.linspace(0.0, case.demo.length_mm, case.demo.count)
    a = AnalysisResult(
        name="demo",
        title="Demo analysis",
        values={"total_length [mm]": float(x.sum()), "x [mm]": x, "map": {"a": 1.0}, "n": 3},
        notes=["a note"],
        data={"fail": case.demo.fail_in_plot},
    )
    return StudyResult(case=case, analyses=[a])


def figures(result):
    from gearte.plotting import Figure, new_figure

    if result["demo"].data["fail"]:
        raise RuntimeError("plot failed on purpose")
    fig, ax = new_figure()
    ax.plot(result["demo"]["x [mm]"])
    return [Figure("x", "the positions", fig)]
