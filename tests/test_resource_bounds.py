"""Resource bounds decided at validation time (issue 13): every input that sizes an allocation or
a loop is bounded, and combinations are checked by a memory/time estimate before any work, with an
error naming the override."""

from __future__ import annotations

import tomllib

import pytest
from click.testing import CliRunner

from gearte.cases import case_path
from gearte.cli import EXIT_BAD_INPUT, main
from gearte.errors import CaseFileError, ParameterError
from gearte.io.case_file import load_case_dict


def _eq9() -> dict:
    return tomllib.loads(case_path("wang2013_2kh_eq9").read_text(encoding="utf-8"))


@pytest.mark.parametrize("frequency", [1000000.0, 0.1234567, "1/123457"])
def test_reproducer_planetary_frequency_is_bounded_at_validation(frequency):
    """Issue 13 reproducer: ``frequency = 1000000.0`` (or ``0.1234567``) passed validate and
    then allocated > 5 GB; now it is a case error naming the term's frequency."""
    data = _eq9()
    data["errors"]["terms"][0]["frequency"] = frequency
    with pytest.raises(CaseFileError) as err:
        load_case_dict(data)
    (field, msg), *_ = err.value.errors
    assert field == "errors.terms.0.frequency" and "<=" in msg


def test_planetary_grid_memory_is_estimated_before_work():
    """Two terms each within bounds whose common period is huge (10000 and 1/9973 x input:
    largest harmonic ~1e8) are refused by the estimate, naming the override."""
    data = _eq9()
    data["errors"]["terms"][0]["frequency"] = 10000
    data["errors"]["terms"][1]["frequency"] = "1/9973"
    with pytest.raises(CaseFileError, match="GEARTE_MAX_MEMORY_GB") as err:
        load_case_dict(data)
    assert "errors.terms.frequency" in str(err.value)


def test_planetary_time_is_estimated_before_work(monkeypatch):
    data = _eq9()
    data["analyses"]["monte_carlo"] = {"samples": 100_000_000}
    monkeypatch.setenv("GEARTE_MAX_SECONDS", "1")
    with pytest.raises(CaseFileError, match="GEARTE_MAX_SECONDS"):
        load_case_dict(data)
    monkeypatch.delenv("GEARTE_MAX_SECONDS")
    load_case_dict(data)  # the default budget allows it


def test_budget_override_must_be_a_positive_number(monkeypatch):
    from gearte.limits import max_memory_bytes

    monkeypatch.setenv("GEARTE_MAX_MEMORY_GB", "lots")
    with pytest.raises(ParameterError, match="GEARTE_MAX_MEMORY_GB"):
        max_memory_bytes()


def test_samples_option_obeys_the_case_cap():
    """``--samples 10**12`` was accepted although the case field caps at 10**10."""
    r = CliRunner().invoke(main, ["run", "jiang2024_spur_pair", "--samples", str(10**12)])
    assert r.exit_code == EXIT_BAD_INPUT, r.output
    assert "--samples" in r.output and "monte_carlo_samples" in r.output


@pytest.mark.parametrize(
    "vary", [["demo.length_mm=1:2:100000"], ["demo.length_mm=1:2:100", "demo.x=1:2:100"]]
)
def test_sweep_points_are_capped_before_the_grid_is_built(tmp_path, vary):
    case = tmp_path / "c.toml"
    case.write_text('[case]\nkind = "foundation_test"\n[demo]\nlength_mm = 4.0\n')
    args = ["sweep", str(case), "--out", str(tmp_path / "o")]
    for v in vary:
        args += ["--vary", v]
    r = CliRunner().invoke(main, args)
    assert r.exit_code == EXIT_BAD_INPUT, r.output
    assert "GEARTE_MAX_SWEEP_POINTS" in r.output and not (tmp_path / "o").exists()
