"""What the bundled cases' reports show people: every value through the label registry (no
program identifiers such as ``shifted_modification`` or ``line_contact``, no literal ``[]``),
run metadata (solver timings and counters, seeds, sample counts) apart from the results, the spec
column filled wherever the case gives a limit, and no "dominant" factor when every contribution
is zero. A fast subset runs with the suite; every bundled case with ``-m slow``."""

from __future__ import annotations

import re
from html.parser import HTMLParser

import pytest

from gearte.cases import list_cases
from gearte.labels import is_identifier, value_label
from gearte.report.html import render_report
from gearte.report.summary import SPEC_CHECKS, SPEC_OF, analysis_headlines
from gearte.report.tables import RUN_METADATA, analysis_tables, dominant_text
from gearte.results import AnalysisResult
from gearte.units import split_unit

#: Fast cases covering every report path that shows text values, limits and metadata: the
#: cycloid stage (factors, law), a gear chain (stage limits, shim), a planetary yield (paper
#: symbols, yield spec), a gear pair (seed, samples, backlash limit).
FAST = [
    "hu2020_rv80e_initial",
    "jiang2024_shoulder_swing",
    "wang2013_2kh_eq9_yield",
    "jiang2024_spur_pair",
]
SAMPLES = 64

#: Keys of a case that set a limit the results are checked against (value > 0 or a table).
LIMIT_KEYS = re.compile(
    r"^(min_backlash_limit_um|target_min_backlash_um|allowable_contact_pressure_MPa|"
    r"te_spec_arcsec|spec|backlash_window_arcmin|joint_lost_motion_limit_arcmin)$"
)


class _Cells(HTMLParser):
    """Text of every table cell of a page, by table (caption or first header)."""

    def __init__(self) -> None:
        super().__init__()
        self.cells: list[tuple[str, str]] = []  # (tag, text)
        self._buf: list[str] | None = None

    def handle_starttag(self, tag, attrs):
        if tag in ("td", "th"):
            self._buf = []

    def handle_endtag(self, tag):
        if tag in ("td", "th") and self._buf is not None:
            self.cells.append((tag, "".join(self._buf).strip()))
            self._buf = None

    def handle_data(self, data):
        if self._buf is not None:
            self._buf.append(data)


def _case_limits(data, path="") -> list[str]:
    out = []
    if isinstance(data, dict):
        for k, v in data.items():
            if LIMIT_KEYS.match(str(k)) and v not in (None, 0, 0.0, {}, []):
                out.append(f"{path}{k}")
            out += _case_limits(v, f"{path}{k}.")
    elif isinstance(data, list):
        for i, v in enumerate(data):
            out += _case_limits(v, f"{path}{i}.")
    return out


def _limit_names() -> set[str]:
    """Result names (without unit) that are limits the summary checks against."""
    return {lim for _, lim, _ in SPEC_CHECKS} | {ref for ref, _ in SPEC_OF.values()} | {"spec"}


@pytest.fixture(scope="module")
def run(tmp_path_factory):
    from gearte.io.case_file import load_case
    from gearte.studies import RunOptions, run_case

    cache = {}

    def get(name):
        if name not in cache:
            cache[name] = run_case(load_case(name), RunOptions(samples=SAMPLES))
        return cache[name]

    return get


def check_report(result) -> None:
    html = render_report(result, figures=[])  # the tables and the summary, without figures
    parser = _Cells()
    parser.feed(html)
    values = [t for tag, t in parser.cells if tag == "td"]
    raw = sorted({t for t in values if is_identifier(t)})
    assert raw == [], f"program identifiers shown as values: {raw}"
    assert not [t for t in values if "[]" in t], "a literal [] in a table cell"

    # run metadata in its own section, not among the results
    meta_labels = set()
    for a in result.analyses:
        for t in analysis_tables(a):
            for row in t.rows:
                assert split_unit(str(row[0]))[0] not in RUN_METADATA
        meta_labels |= {k for k in a.values if split_unit(k)[0] in RUN_METADATA}
    if meta_labels:
        assert 'id="run-metadata"' in html

    # spec columns filled where the results carry a limit, and where the case gives one
    limits = _limit_names()
    specced = 0
    for a in result.analyses:
        rows = analysis_headlines(a)
        specced += sum(1 for r in rows if r.spec)
        if {split_unit(k)[0] for k in a.values} & limits:
            assert any(r.spec for r in rows), f"{a.name}: a limit in the results, no spec shown"
    given = _case_limits(result.case.model_dump(mode="json"))
    if given:
        assert specced, f"the case gives limits {given}, the summary shows no spec"


@pytest.mark.parametrize("name", FAST)
def test_bundled_report_values(run, name):
    check_report(run(name))


@pytest.mark.slow
@pytest.mark.parametrize("name", [c for c in list_cases() if c not in FAST])
def test_every_bundled_report_values(run, name):
    check_report(run(name))


def test_the_check_finds_raw_values(run, monkeypatch):
    """The check can fail: with the registry bypassed, an identifier or an empty list shown as a
    value is caught."""
    import gearte.report.summary
    import gearte.report.tables

    for module in (gearte.report.tables, gearte.report.summary):
        monkeypatch.setattr(module, "value_label", lambda v: v)
    monkeypatch.setattr(gearte.report.tables, "EMPTY", "[]")
    result = run("hu2020_rv80e_initial")
    bad = AnalysisResult(name="x", title="X", values={"law": "some_raw_name"})
    result.analyses.append(bad)
    try:
        with pytest.raises(AssertionError, match="identifiers"):
            check_report(result)
        bad.values.clear()
        bad.values["nothing"] = []
        with pytest.raises(AssertionError, match=r"\[\]"):
            check_report(result)
    finally:
        result.analyses.remove(bad)


def test_values_read_through_the_registry():
    assert value_label("shifted_modification") == "Shifted modification"
    assert value_label("line_contact") == "line contact (Johnson 1985)"
    assert value_label("hu2020") == "Hu et al. 2020 (eq. 38–39)"
    assert value_label("beta_p1") == "β_p1"
    assert value_label("a sentence, kept") == "a sentence, kept"
    a = AnalysisResult(name="x", title="X", values={"items": [], "modes": {}, "kind": "spur_pair"})
    cells = [c for t in analysis_tables(a) for r in t.formatted for c in r]
    assert "[]" not in cells and "{}" not in cells and "none" in cells
    assert "spur pair" in cells


def test_no_dominant_factor_when_every_contribution_is_zero():
    zero = {"contribution [arcmin]": {"a_error": 0.0, "b_error": 0.0}}
    assert dominant_text({**zero, "dominant_factor": "a_error"}, "dominant_factor") == (
        "none (every contribution is zero)"
    )
    some = {"contribution [arcmin]": {"a_error": 0.0, "b_error": -0.3}}
    assert dominant_text({**some, "dominant_factor": "b_error"}, "dominant_factor") == "B error"
    a = AnalysisResult(
        name="geometric_te", title="TE", values={**zero, "dominant_factor": "a_error"}
    )
    rows = {r.quantity: r.value for r in analysis_headlines(a)}
    assert rows["Dominant factor"] == "none (every contribution is zero)"


def test_cycloid_stage_names_no_dominant_factor_without_errors():
    """A stage with every error zero: nothing dominates (the study says so, not the first of
    nine zeros)."""
    from gearte.io.case_file import load_case
    from gearte.studies import run_case

    case = load_case("hu2020_rv80e_initial").model_dump(mode="json")
    for k in ("equidistant_modification_mm", "shifted_modification_mm"):
        case["stage"][k] = 0.0
    for v in case["errors"].values():
        if isinstance(v, dict) and "mean_um" in v:
            v["mean_um"] = 0.0
    case["analyses"] = {"geometric_te": case["analyses"]["geometric_te"]}
    result = run_case(case)
    assert result["geometric_te"]["dominant_factor"] == ""
    rows = {r.quantity: r.value for r in analysis_headlines(result["geometric_te"])}
    assert rows["Dominant factor"] == "none (every contribution is zero)"
