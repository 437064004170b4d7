"""Results in Jupyter (issue 15 item 4): ``_repr_html_``, ``to_pandas()`` and ``plot()`` of
:class:`StudyResult` and :class:`AnalysisResult`, on the test kind and a bundled case."""

from __future__ import annotations

import sys
from html.parser import HTMLParser

import numpy as np
import pandas as pd
import pytest
from matplotlib.figure import Figure as MplFigure

from gearte.io.case_file import load_case
from gearte.plotting import figures_for
from gearte.report.summary import headlines
from gearte.results import AnalysisResult, StudyResult
from gearte.studies import run_case

FOUNDATION = {
    "case": {"kind": "foundation_test", "title": "A <demo> & co"},
    "demo": {"length_mm": 2.0},
}


@pytest.fixture(scope="module")
def demo() -> StudyResult:
    return run_case(load_case(FOUNDATION))


@pytest.fixture(scope="module")
def shoulder() -> StudyResult:
    return run_case(load_case("jiang2024_shoulder_swing"))


class _Cells(HTMLParser):
    def __init__(self) -> None:
        super().__init__()
        self.cells: list[str] = []
        self.tags: list[str] = []
        self._in = False

    def handle_starttag(self, tag: str, attrs: object) -> None:
        self.tags.append(tag)
        self._in = tag in ("td", "th")
        if self._in:
            self.cells.append("")

    def handle_endtag(self, tag: str) -> None:
        self._in = False if tag in ("td", "th") else self._in

    def handle_data(self, data: str) -> None:
        if self._in:
            self.cells[-1] += data


def _cells(text: str) -> _Cells:
    p = _Cells()
    p.feed(text)
    p.close()
    return p


def test_study_repr_html_shows_every_headline_row_escaped(shoulder: StudyResult) -> None:
    text = shoulder._repr_html_()
    cells = _cells(text).cells
    rows = headlines(shoulder)
    assert rows
    for r in rows:
        assert r.quantity in cells and r.value in cells
    for a in shoulder.analyses:
        assert f"<code>{a.name}</code>" in text
    assert "None" not in cells and "nan" not in cells


def test_repr_html_escapes_the_title(demo: StudyResult) -> None:
    text = demo._repr_html_()
    assert "A &lt;demo&gt; &amp; co" in text and "<demo>" not in text


def test_analysis_repr_html_shows_its_results_table(demo: StudyResult) -> None:
    cells = _cells(demo["demo"]._repr_html_()).cells
    assert "Demo analysis" in demo["demo"]._repr_html_()
    assert "3 mm" in cells  # total_length 0 + 1 + 2 = 3 mm


def test_study_to_pandas_has_one_row_per_scalar(shoulder: StudyResult) -> None:
    df = shoulder.to_pandas()
    assert list(df.columns) == ["analysis", "quantity", "unit", "value"]
    n = sum(
        1
        for a in shoulder.analyses
        for v in a.values.values()
        if v is None or isinstance(v, str | bool | int | float | np.generic)
    )
    assert len(df) == n
    row = df[(df.analysis == "chain") & (df.quantity == "end_effector_error_max")]
    assert row.unit.item() == "mm"
    assert row.value.item() == shoulder["chain"]["end_effector_error_max [mm]"]


def test_analysis_to_pandas_scalars_series_mappings(demo: StudyResult) -> None:
    a = demo["demo"]
    df = a.to_pandas()
    assert df.set_index("quantity").loc["total_length", "value"] == 3.0
    x = a.to_pandas("x")  # name without its unit
    np.testing.assert_array_equal(x["x [mm]"].to_numpy(), [0.0, 1.0, 2.0])
    m = a.to_pandas("map")
    assert m.to_dict("list") == {"item": ["a"], "map": [1.0]}


def test_analysis_to_pandas_records_and_nested_mappings(shoulder: StudyResult) -> None:
    df = shoulder["chain"].to_pandas("stage_share [%]")
    assert list(df.columns) == ["item", "stage_share [%]"]
    assert df["stage_share [%]"].sum() == pytest.approx(100.0, abs=0.5)


def test_to_pandas_unknown_key_names_the_values(demo: StudyResult) -> None:
    with pytest.raises(KeyError, match="its values: .*total_length"):
        demo["demo"].to_pandas("totl_length")


def test_to_pandas_without_pandas_names_the_extra(
    demo: StudyResult, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setitem(sys.modules, "pandas", None)  # import pandas -> ImportError
    with pytest.raises(ImportError, match=r"gearte\[notebooks\]"):
        demo.to_pandas()
    with pytest.raises(ImportError, match=r"gearte\[notebooks\]"):
        demo["demo"].to_pandas()


def test_plot_returns_the_report_figures(shoulder: StudyResult) -> None:
    figs = shoulder.plot()
    assert len(figs) == len(figures_for(shoulder)) > 0
    assert all(isinstance(f, MplFigure) for f in figs)
    per_analysis = sum(len(a.plot()) for a in shoulder.analyses)
    assert per_analysis == len(figs)


def test_plot_of_an_unknown_analysis_names_the_analyses(demo: StudyResult) -> None:
    with pytest.raises(KeyError, match="have \\['demo'\\]"):
        demo.plot("dmo")


def test_analysis_plot_follows_its_study(demo: StudyResult) -> None:
    figs = demo["demo"].plot()
    assert len(figs) == 1 and isinstance(figs[0], MplFigure)
    assert figs[0].get_suptitle() == "x"


def test_a_lone_analysis_cannot_plot() -> None:
    a = AnalysisResult(name="alone", title="Alone", values={"v [mm]": 1.0})
    with pytest.raises(ValueError, match="belongs to no StudyResult"):
        a.plot()
    assert isinstance(a.to_pandas(), pd.DataFrame)


def test_study_link_does_not_enter_json(demo: StudyResult) -> None:
    assert demo["demo"].study is demo
    assert "study" not in demo["demo"].to_dict()
    demo.to_json()  # no cycle through the back-link
