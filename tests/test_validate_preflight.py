"""`gearte validate` makes every check `gearte run` makes (issue 13: none deferred).

The checks that need the built drive (a yield tolerance or cost naming an error key the drive
does not have, a planetary angle entering one frequency group with both signs, RV dynamics
masses derived without a density, the RK4 step-count budget) ran only when their analysis
started in `run`, after earlier analyses had done their work; the long fuzzing job found 44
mutants that `validate` accepted and `run` refused. `gearte.studies.preflight` runs them
before any analysis, in both commands, with the same message. Each test mutates one key of a
small bundled case.
"""

from __future__ import annotations

from pathlib import Path

import pytest
from click.testing import CliRunner

from gearte.cases import case_path, list_cases
from gearte.cli import EXIT_BAD_INPUT, main


def _mutant(tmp_path: Path, case: str, old: str, new: str) -> Path:
    text = case_path(case).read_text(encoding="utf-8")
    assert old in text, f"{case} no longer has {old!r}: update the mutation"
    p = tmp_path / f"{case}_mutant.toml"
    p.write_text(text.replace(old, new, 1), encoding="utf-8")
    return p


def _validate_and_run(path: Path, tmp_path: Path) -> tuple[str, str]:
    """The error line of `validate` and of `run` (both must exit 2; run writes nothing)."""
    runner = CliRunner()
    v = runner.invoke(main, ["validate", str(path)])
    assert v.exit_code == EXIT_BAD_INPUT, v.output
    lines = v.output.strip().splitlines()
    assert lines[0] == f"{path}: 1 error(s)", v.output
    out = tmp_path / "out"
    r = runner.invoke(main, ["run", str(path), "--out", str(out), "--no-report", "--no-progress"])
    assert r.exit_code == EXIT_BAD_INPUT, r.output
    assert not (out / "results.json").exists()
    run_lines = [ln for ln in r.output.splitlines() if ln.startswith("error (invalid parameter): ")]
    assert len(run_lines) == 1, r.output
    return lines[1].strip(), run_lines[0].removeprefix("error (invalid parameter): ")


def test_yield_tolerance_on_a_key_the_stage_does_not_have_is_refused_by_validate(tmp_path):
    """(a) cycloid_stage: a misspelt error key in [analyses.yield.tolerances]."""
    p = _mutant(
        tmp_path,
        "hu2020_rv80e_yield",
        "[analyses.yield.tolerances.eccentricity_error]",
        "[analyses.yield.tolerances.eccentricity_eror]",
    )
    v, r = _validate_and_run(p, tmp_path)
    assert v == r
    assert v.startswith("analyses.yield.tolerances.eccentricity_eror = ")
    assert "is not an error key or family" in v


def test_allocation_cost_on_a_key_without_tolerance_is_refused_by_validate(tmp_path):
    """(a) cycloid_stage: an allocation cost naming a key that has no tolerance."""
    p = _mutant(
        tmp_path, "hu2020_rv80e_yield", "costs.pin_radius_error =", "costs.pin_radius_eror ="
    )
    v, r = _validate_and_run(p, tmp_path)
    assert v == r
    assert v.startswith("analyses.yield.allocation.costs.pin_radius_eror = ")
    assert "has no tolerance to allocate" in v


def test_rv_yield_tolerance_on_a_key_the_reducer_does_not_have_is_refused_by_validate(tmp_path):
    """(a) rv_reducer: the reducer's error keys come from the built reducer."""
    p = _mutant(
        tmp_path,
        "han2023_rv110e_yield",
        'disc_radial_runout = { kind = "rayleigh"',
        'disc_radial_runot = { kind = "rayleigh"',
    )
    v, r = _validate_and_run(p, tmp_path)
    assert v == r
    assert v.startswith("analyses.yield.tolerances.disc_radial_runot = ")


def test_planetary_angle_with_both_signs_in_one_group_is_refused_by_validate(tmp_path):
    """(b) eq 9's e7 with angle_coeff +1: beta_p enters the 11/24 group with both signs."""
    text = case_path("wang2013_2kh_eq9").read_text(encoding="utf-8")
    head, tail = text.split("# e7", 1)
    tail = tail.replace("angle_coeff = -1", "angle_coeff = 1", 1)
    p = tmp_path / "eq9_mutant.toml"
    p.write_text(head + "# e7" + tail, encoding="utf-8")
    v, r = _validate_and_run(p, tmp_path)
    assert v == r
    assert v == "terms = 'beta_p': an angle enters one frequency group with both signs"


def test_rv_dynamics_mass_derived_without_density_is_refused_by_validate(tmp_path):
    """(c) li2023_rv without disc_mass_kg: the disc mass must be derived, no density given."""
    p = _mutant(tmp_path, "li2023_rv", "disc_mass_kg = 2.76\n", "")
    v, r = _validate_and_run(p, tmp_path)
    assert v == r
    assert v.startswith("reducer.density_kg_per_m3 = None: needed to derive the disc mass")


def test_rk4_step_count_over_the_time_budget_is_refused_by_validate(tmp_path, monkeypatch):
    """(d) li2023_rv's DTE (about 1.7e4 RK4 steps) against a budget of 1 ms."""
    monkeypatch.setenv("GEARTE_MAX_SECONDS", "0.001")
    p = _mutant(tmp_path, "li2023_rv", "[case]", "[case]")
    v, r = _validate_and_run(p, tmp_path)
    assert v == r
    assert v.startswith("dt = ")
    assert "RK4 integration of" in v and "GEARTE_MAX_SECONDS" in v


@pytest.mark.parametrize("name", sorted(list_cases()))
def test_validate_still_accepts_every_bundled_case(name):
    r = CliRunner().invoke(main, ["validate", name])
    assert r.exit_code == 0, r.output
