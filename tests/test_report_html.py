"""The HTML report of bundled cases, parsed: summary block first, contents links resolve, no
``None``/``nan`` strings, every figure inside its analysis section (issue 15 item 1)."""

from __future__ import annotations

import re
from html.parser import HTMLParser
from typing import Any

import numpy as np
import pytest

from gearte.report.html import render_figures, render_report
from gearte.report.summary import headlines, tradeoff_warnings
from gearte.report.tables import analysis_tables, csv_files, summarise_series
from gearte.results import AnalysisResult, StudyResult
from gearte.studies import RunOptions, run_case
from gearte.units import format_quantity

# The cheap bundled cases, one of each kind that has one (samples cut: the layout is under test).
CHEAP_CASES = ["hu2020_rv80e_initial", "jiang2024_shoulder_swing", "jiang2024_spur_pair"]


class _Page(HTMLParser):
    """Sections, ids, links, figures (with the section holding them) and text of a page."""

    def __init__(self) -> None:
        super().__init__()
        self.ids: set[str] = set()
        self.links: list[str] = []
        self.sections: list[tuple[str, str]] = []  # (id, class) in document order
        self.stack: list[tuple[str, str, str]] = []  # (tag, id, class)
        self.figures: list[str | None] = []  # id of the analysis section holding each figure
        self.text: list[str] = []
        self.body_tags: list[str] = []

    def handle_starttag(self, tag: str, attrs: list[tuple[str, str | None]]) -> None:
        a = {k: v or "" for k, v in attrs}
        if "id" in a:
            self.ids.add(a["id"])
        if tag == "a" and a.get("href", "").startswith("#"):
            self.links.append(a["href"][1:])
        if tag in ("section", "nav", "header"):
            self.body_tags.append(f"{tag}#{a.get('id', '')}")
        if tag == "section":
            self.sections.append((a.get("id", ""), a.get("class", "")))
        if tag == "figure":
            holder = next(
                (i for t, i, c in reversed(self.stack) if t == "section" and "analysis" in c),
                None,
            )
            self.figures.append(holder)
        if tag not in ("img", "meta", "br", "link"):
            self.stack.append((tag, a.get("id", ""), a.get("class", "")))

    def handle_endtag(self, tag: str) -> None:
        while self.stack:
            t, _, _ = self.stack.pop()
            if t == tag:
                break

    def handle_data(self, data: str) -> None:
        if not any(t in ("style", "script") for t, _, _ in self.stack):
            self.text.append(data)


@pytest.fixture(scope="module", params=CHEAP_CASES)
def report(request: pytest.FixtureRequest) -> tuple[StudyResult, str, list]:
    result = run_case(request.param, RunOptions(progress=False, samples=2000))
    figs = render_figures(result)
    return result, render_report(result, figs), figs


def test_report_summary_block_comes_first(report: tuple) -> None:
    _, html, _ = report
    page = _Page()
    page.feed(html)
    assert page.body_tags[:3] == ["header#", "section#summary", "nav#contents"]
    assert page.sections[0] == ("summary", "summary")


def test_report_contents_links_resolve(report: tuple) -> None:
    result, html, _ = report
    page = _Page()
    page.feed(html)
    assert page.links, "no links"
    assert set(page.links) <= page.ids, set(page.links) - page.ids
    for a in result.analyses:  # the contents list every analysis
        assert a.name in page.links


def test_report_has_no_none_or_nan_strings(report: tuple) -> None:
    _, html, _ = report
    page = _Page()
    page.feed(html)
    # the case input echo is JSON (null is its spelling): check everything before it
    text = " ".join(page.text)
    text = text.split("The validated case, as run")[0]
    bad = re.findall(r"\b(None|nan|NaN)\b", text)
    assert not bad, bad


def test_report_every_figure_in_its_analysis_section(report: tuple) -> None:
    result, html, figs = report
    page = _Page()
    page.feed(html)
    assert len(page.figures) == len(figs) > 0
    names = {a.name for a in result.analyses}
    assert all(h in names for h in page.figures), page.figures
    assert page.figures == [f.analysis for f in figs if f.analysis in names] or sorted(
        page.figures
    ) == sorted(f.analysis for f in figs)


def test_report_headlines_name_each_analysis(report: tuple) -> None:
    result, _, _ = report
    rows = headlines(result)
    assert {r.analysis for r in rows} == {a.name for a in result.analyses}
    assert all("nan" not in r.value and "None" not in r.value for r in rows)


def test_tables_never_hold_csv_text_and_summarise_lists() -> None:
    a = AnalysisResult(
        "x",
        "X",
        values={
            "peak [N]": 1904.6,
            "table_csv": "a,b\n1,2\n3,4\n",
            "signal [um]": np.r_[np.nan, np.arange(40.0)],
            "instructions": ["turn the sun to 12 deg", "turn the planet to 40 deg"] * 5,
        },
    )
    tables = {t.key: t for t in analysis_tables(a)}
    assert tables["x_table_csv"].rows == [[1, 2], [3, 4]]
    assert tables["x_instructions"].kind == "list" and len(tables["x_instructions"].rows) == 10
    series = tables["x_series"].formatted[0]
    assert series[:3] == ["Signal", "µm", "41 (1 missing)"] and series[3] == "0"
    cells = [c for t in tables.values() for r in t.formatted for c in r]
    assert not any("\n" in c for c in cells)


def test_summarise_series_skips_nan() -> None:
    s = summarise_series([None, 1.0, float("nan"), 3.0])
    assert (s["n"], s["missing"], s["min"], s["mean"], s["max"]) == (4, 2, 1.0, 2.0, 3.0)


def test_format_quantity_one_spelling() -> None:
    assert format_quantity(1.0339, "arcmin") == "1.034′"
    assert format_quantity(17.1875, "um") == "17.19 µm"
    assert format_quantity(579.34, "N*m/arcmin") == "579.3 N·m/arcmin"
    assert format_quantity(float("nan"), "N") == "—"
    assert format_quantity(None) == "—"


class _Case:
    class case:  # noqa: N801 - stands in for CaseMeta
        kind = "x"
        name = "x"
        title = "x"
        references: list[str] = []


def test_tradeoff_warning_when_compensation_raises_pin_load() -> None:
    """han2023_rv110e's numbers: TE cut 0.08 % while peak pin load +17 %, lag +43 %, pairs in mesh
    10–20 → 6–11."""
    comp = AnalysisResult(
        "compensation",
        "Compensation of the total TE through the model",
        values={
            "total_te_peak_to_peak_before [arcsec]": 71.589,
            "mean_output_lag_before [arcmin]": 2.5106,
            "peak_pin_load_before [N]": 1904.6,
            "pairs_in_mesh_min_before": 10,
            "pairs_in_mesh_max_before": 20,
            "total_te_peak_to_peak_after [arcsec]": 71.528,
            "mean_output_lag_after [arcmin]": 3.5922,
            "peak_pin_load_after [N]": 2225.5,
            "pairs_in_mesh_min_after": 6,
            "pairs_in_mesh_max_after": 11,
        },
    )
    (w,) = tradeoff_warnings(StudyResult(case=_Case, analyses=[comp]))
    assert "improves total TE peak-to-peak from 71.59″ to 71.53″ (-0.085 %)" in w
    assert "peak pin load from 1905 N to 2226 N (+17 %)" in w
    assert "mean output lag from 2.511′ to 3.592′ (+43 %)" in w
    assert "pairs in mesh from 10–20 to 6–11" in w
    better = dict(comp.values, **{"peak_pin_load_after [N]": 1800.0})
    better.update({"mean_output_lag_after [arcmin]": 2.0, "pairs_in_mesh_min_after": 10})
    better.update({"pairs_in_mesh_max_after": 20})
    ok = AnalysisResult("compensation", "C", values=better)
    assert tradeoff_warnings(StudyResult(case=_Case, analyses=[ok])) == []


def test_csv_files_of_every_tabular_result(report: tuple) -> None:
    result, _, _ = report
    files = csv_files(result)
    assert "summary.csv" in files
    n_scalar = sum(
        1
        for a in result.analyses
        for v in a.values.values()
        if v is None or isinstance(v, str | bool | int | float | np.generic)
    )
    assert files["summary.csv"].count("\n") >= n_scalar - 5
    for name, text in files.items():
        assert name.endswith(".csv") and text.splitlines()[0] and len(text.splitlines()) > 1


def test_decimate_keeps_the_envelope_of_a_long_signal() -> None:
    from gearte.plotting.display import MAX_POINTS, decimate

    x = np.linspace(0.0, 10.0, 200_001)
    y = np.sin(40 * x) + (np.arange(x.size) % 7919 == 0) * 3.0  # sparse one-sample spikes
    keep = decimate(x, y)
    assert keep.size <= MAX_POINTS + 2 and np.all(np.diff(keep) > 0)
    assert keep[0] == 0 and keep[-1] == x.size - 1
    spikes = np.flatnonzero(y > 2.0)
    assert np.isin(spikes, keep).all()  # every one-sample spike survives
    assert y[keep].min() == y.min()


def test_polish_moves_legends_off_the_data_and_sets_integer_ticks() -> None:
    from matplotlib.ticker import AutoLocator, MaxNLocator

    from gearte.plotting import new_figure
    from gearte.plotting.display import polish

    fig, ax = new_figure()
    ax.plot([], [], label="proxy")  # a legend-only handle
    ax.plot([1, 2, 3, 4], [0.5, 1.5, 1.0, 2.5], "o-", label="pins")
    ax.set_xlabel("pin i")
    ax.legend()
    polish(fig)
    assert type(ax.xaxis.get_major_locator()) is MaxNLocator  # integer pin numbers
    assert type(ax.yaxis.get_major_locator()) is AutoLocator  # fractional values: untouched
    fig.canvas.draw()
    assert ax.get_legend().get_window_extent().y1 < ax.get_window_extent().y0


def test_results_json_records_stage_timings(tmp_path: Any) -> None:
    import json

    from gearte.report.outputs import write_outputs

    result = run_case("hu2020_rv80e_initial", RunOptions(progress=False))
    paths = write_outputs(result, tmp_path / "out", report=False)
    t = json.loads(paths["results"].read_text())["timings [s]"]
    stages = {f"analysis: {a.name}" for a in result.analyses} | {"imports: study kind", "csv"}
    assert stages <= set(t) and all(v >= 0 for v in t.values())
    assert sum(v for k, v in t.items() if k.startswith("analysis: ")) == pytest.approx(
        result.elapsed_s, abs=2e-3
    )
    assert "write" in result.timings  # known only after results.json is serialised


def _every_bundled_case() -> list[str]:
    from gearte.cases import list_cases

    return sorted(n for n in list_cases() if n not in CHEAP_CASES)


@pytest.mark.slow
@pytest.mark.parametrize("name", _every_bundled_case())
def test_every_bundled_report_parses(name: str) -> None:
    """Issue 15 must-show over every bundled case (the cheap three run above in the fast
    suite): summary block first, contents links resolve, no ``None``/``nan`` strings, every
    figure inside its analysis section. Sample counts are cut: the layout is under test."""
    result = run_case(name, RunOptions(progress=False, samples=500))
    figs = render_figures(result)
    report = (result, render_report(result, figs), figs)
    test_report_summary_block_comes_first(report)
    test_report_contents_links_resolve(report)
    test_report_has_no_none_or_nan_strings(report)
    if figs:
        test_report_every_figure_in_its_analysis_section(report)
    test_report_headlines_name_each_analysis(report)
