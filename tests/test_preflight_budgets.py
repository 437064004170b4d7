"""Budgets checked before any work: free disk space for the result set, the estimated time of
the sample counts (the case's own, or ``--samples``), and ``--samples`` above a count it only
caps (a Sobol base count) no longer refused."""

from __future__ import annotations

import shutil
from collections import namedtuple

import pytest
from click.testing import CliRunner

from gearte.cli import main
from gearte.errors import ParameterError
from gearte.io.case_file import load_case
from gearte.report.outputs import expected_output_bytes
from gearte.studies import SECONDS_PER_SAMPLE, check_sample_time, check_samples_override

Usage = namedtuple("Usage", "total used free")


def test_a_full_disk_is_refused_before_computing(tmp_path, monkeypatch):
    calls = []
    monkeypatch.setattr(shutil, "disk_usage", lambda p: Usage(10**9, 10**9 - 1000, 1000))
    monkeypatch.setattr("gearte.studies.run_case", lambda *a, **k: calls.append(a))
    out = tmp_path / "o"
    res = CliRunner().invoke(main, ["run", "hu2020_rv80e_initial", "--out", str(out)])
    assert res.exit_code == 4, res.output
    assert "the disk has 0.001 MB free" in res.output and str(out) in res.output
    assert calls == [] and not out.exists()


def test_expected_output_size_counts_analyses_and_the_report():
    case = load_case("li2023_rv_errors")
    with_report = expected_output_bytes(case)
    assert expected_output_bytes(case, report=False) < with_report
    assert with_report > expected_output_bytes(load_case("hu2020_rv80e_yield"))


def test_samples_above_the_sobol_cap_are_accepted():
    """``--samples`` sets the Monte-Carlo count and only caps the Sobol base count
    (``min(sobol_samples, N)``): the Sobol field's bound 1e7 no longer refuses 2e7."""
    case = load_case("jiang2024_spur_pair")
    check_samples_override(case, 20_000_000)
    with pytest.raises(ParameterError, match="over the cap of analysis.monte_carlo_samples"):
        check_samples_override(case, 10**11)


def test_sample_counts_are_checked_against_the_time_budget_up_front(monkeypatch):
    monkeypatch.setenv("GEARTE_MAX_SECONDS", "100")
    case = load_case("han2023_rv110e_yield")
    per = SECONDS_PER_SAMPLE[("rv_reducer", "analyses.yield_.samples")]
    n = int(2 * 100 / per)  # twice the budget on one core
    with pytest.raises(
        ParameterError,
        match=r"--samples = .*analyses\.yield\.samples = .* over "
        r"the budget of 100 s",
    ):
        check_sample_time(case, n, workers=1)
    check_sample_time(case, n // 4, workers=1)
    section = case.analyses.yield_.model_copy(update={"samples": n})
    big = case.model_copy(update={"analyses": case.analyses.model_copy(update={"yield_": section})})
    with pytest.raises(ParameterError, match=r"^analyses\.yield\.samples = "):
        check_sample_time(big, None, workers=1)


def test_every_bundled_case_is_within_the_time_budget():
    from gearte.cases import list_cases

    for name in list_cases():
        check_sample_time(load_case(name), None, workers=1)
