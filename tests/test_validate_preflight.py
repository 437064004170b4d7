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


# --- the refusals the 10 000-file fuzzing job (seed 13) still found in `run` after `validate`
def _validate_and_run_schema(path: Path, tmp_path: Path) -> str:
    """A schema refusal: validate and run both exit 2 with the same error line."""
    runner = CliRunner()
    v = runner.invoke(main, ["validate", str(path)])
    assert v.exit_code == EXIT_BAD_INPUT, v.output
    line = v.output.strip().splitlines()[1].strip()
    out = tmp_path / "out"
    r = runner.invoke(main, ["run", str(path), "--out", str(out), "--no-report", "--no-progress"])
    assert r.exit_code == EXIT_BAD_INPUT, r.output
    assert not (out / "results.json").exists()
    assert line in r.output
    return line


def test_yield_spec_on_a_quantity_the_stage_model_does_not_give_is_refused_by_validate(tmp_path):
    """A typo in a spec quantity (fuzzing: `geometric_te [rcmin]`): the names come from the
    yield model's `quantities`, the same list its outputs are checked against."""
    p = _mutant(
        tmp_path,
        "hu2020_rv80e_yield",
        '[analyses.yield.spec."geometric_te [arcmin]"]',
        '[analyses.yield.spec."geometric_te [rcmin]"]',
    )
    v, r = _validate_and_run(p, tmp_path)
    assert v == r
    assert v.startswith("analyses.yield.spec.geometric_te [rcmin] = ")
    assert "is not a quantity of the model ['geometric_te [arcmin]']" in v


def test_rv_yield_spec_on_a_quantity_the_reducer_model_does_not_give_is_refused(tmp_path):
    p = _mutant(
        tmp_path, "han2023_rv110e_yield", '"angular_te [arcmin]" = {', '"angular_te [rcmin]" = {'
    )
    v, r = _validate_and_run(p, tmp_path)
    assert v == r
    assert v.startswith("analyses.yield.spec.angular_te [rcmin] = ")
    assert "'loaded_te [arcmin]'" in v


def test_gear_chain_yield_tolerance_on_a_key_the_pair_stack_does_not_have_is_refused(tmp_path):
    """A pair stage's keys come from its backlash stack: the gear_chain pre-flight builds the
    pair (and the RV stage's drive) without computing a lost motion."""
    p = _mutant(
        tmp_path,
        "robot_joint_spur_rv_yield",
        '[analyses.yield.tolerances."spur_pair.driven_gear_eccentricity"]',
        '[analyses.yield.tolerances."spur_pair.driven_ear_eccentricity"]',
    )
    v, r = _validate_and_run(p, tmp_path)
    assert v == r
    assert v.startswith("analyses.yield.tolerances.spur_pair.driven_ear_eccentricity = ")
    assert "'spur_pair.driven_gear_eccentricity'" in v  # the known keys are listed


def test_gear_chain_yield_spec_on_a_quantity_of_no_stage_is_refused(tmp_path):
    p = _mutant(
        tmp_path,
        "robot_joint_spur_rv_yield",
        '[analyses.yield.spec."joint_lost_motion [arcmin]"]',
        '[analyses.yield.spec."joint_lost_motion [arcsec]"]',
    )
    v, r = _validate_and_run(p, tmp_path)
    assert v == r
    assert v.startswith("analyses.yield.spec.joint_lost_motion [arcsec] = ")
    assert "'spur_pair.lost_motion [arcmin]'" in v


def test_planetary_angle_beyond_the_kernels_sincos_range_is_a_schema_error(tmp_path):
    """errors.angles_deg is bounded by the TE kernels' sine/cosine range (1e5 rad)."""
    p = _mutant(tmp_path, "wang2013_2kh_eq9", "beta_l = 0.0", "beta_l = -1e30")
    line = _validate_and_run_schema(p, tmp_path)
    assert line.startswith("errors.angles_deg: angle 'beta_l' = -1e+30: must be a finite number")
    assert "5729577.95 deg" in line


def test_planetary_angle_at_the_bound_is_accepted(tmp_path):
    p = _mutant(tmp_path, "wang2013_2kh_eq9", "beta_l = 0.0", "beta_l = -5729577.9")
    r = CliRunner().invoke(main, ["validate", str(p)])
    assert r.exit_code == 0, r.output


def test_speed_sweep_duration_lost_beside_the_settling_time_is_refused_by_validate(tmp_path):
    """duration_s = 1e-300: settle_s + duration_s == settle_s, the integrator's t_settle check
    (solvers.ode.check_span) refuses it; the pre-flight names the case key."""
    text = case_path("li2023_rv_modified_fourier").read_text(encoding="utf-8")
    head, tail = text.split("[analyses.speed_sweep]", 1)
    tail = tail.replace("duration_s = 0.1", "duration_s = 1e-300", 1)
    p = tmp_path / "sweep_mutant.toml"
    p.write_text(head + "[analyses.speed_sweep]" + tail, encoding="utf-8")
    v, r = _validate_and_run(p, tmp_path)
    assert v == r
    assert v.startswith("analyses.speed_sweep.duration_s = 1e-300: leaves no simulated time")


def test_tooth_contact_deformation_beyond_the_elastic_range_is_refused_by_validate(tmp_path):
    """E = 1000 MPa (the plausibility floor; 0.12 MPa, the value this test first used, is now
    refused by the schema): the solve at the paper's mesh position (the pre-flight) deforms a
    pin far beyond 0.1 x pin radius; exit 2 naming the torque key, before any analysis."""
    p = _mutant(
        tmp_path,
        "hu2020_rv80e_modified",
        "youngs_modulus_MPa = 2.06e5",
        "youngs_modulus_MPa = 1000.0",
    )
    v, r = _validate_and_run(p, tmp_path)
    assert v == r
    assert v.startswith("analyses.tooth_contact.torque_Nm = ")
    assert "beyond the elastic contact model's range" in v and "youngs_modulus_MPa = 1000" in v


def test_malformed_bench_file_is_refused_by_validate_as_by_run(tmp_path):
    """rv_bench's pre-flight reads the bench files with the run's readers: a malformed file is
    exit 2 ('invalid data file') in both, one line naming file, line and column."""
    import shutil

    src = case_path("synthetic_rv_bench")
    shutil.copytree(src.parent / "synthetic_rv_bench", tmp_path / "synthetic_rv_bench")
    shutil.copy(src, tmp_path / "bench.toml")
    hyst = tmp_path / "synthetic_rv_bench" / "hysteresis.csv"
    lines = hyst.read_text(encoding="utf-8").splitlines()
    lines[4] = "1.95,abc,ascending"
    hyst.write_text("\n".join(lines) + "\n", encoding="utf-8")
    p = tmp_path / "bench.toml"
    runner = CliRunner()
    v = runner.invoke(main, ["validate", str(p)])
    assert v.exit_code == EXIT_BAD_INPUT, v.output
    line = v.output.strip().splitlines()[1].strip()
    assert "hysteresis.csv, line 5" in line
    r = runner.invoke(main, ["run", str(p), "--out", str(tmp_path / "o"), "--no-report"])
    assert r.exit_code == EXIT_BAD_INPUT, r.output
    assert f"error (invalid data file): {line}" in r.output


def test_every_kind_has_a_preflight():
    from gearte.io.kinds import available_kinds, get_kind

    ours = [k for k in available_kinds() if get_kind(k).__name__.startswith("gearte.studies.")]
    assert {"gear_pair", "gear_chain", "rv_bench", "rv_lot", "rv_serial"} <= set(ours)
    missing = [k for k in ours if not callable(getattr(get_kind(k), "preflight", None))]
    assert missing == []


def test_yield_model_whose_quantities_differ_from_its_outputs_is_a_bug():
    """The pre-flight checks a spec against a model's `quantities`; run_yield holds the model to
    them (a mismatch is an internal error, never a silently unchecked spec)."""
    from gearte.tolerance.yield_mc import Tolerance, ToleranceSet, run_yield

    class Wrong:
        quantities = ("a [mm]",)

        def __call__(self, errors):
            return {"b [mm]": errors["x"] * 1.0}

    ts = ToleranceSet((Tolerance("x", "normal", 1.0),), ())
    with pytest.raises(RuntimeError, match="quantities"):
        run_yield(Wrong(), ts, [], 4, seed=1)


def test_rv_tooth_contact_deformation_beyond_the_elastic_range_is_refused_by_validate(tmp_path):
    """The reducer's cycloid analyses run as a cycloid_stage case: its pre-flight too."""
    p = _mutant(
        tmp_path,
        "hu2020_rv80e_initial_reducer",
        "youngs_modulus_MPa = 2.06e5",
        "youngs_modulus_MPa = 1000.0",
    )
    v, r = _validate_and_run(p, tmp_path)
    assert v == r
    assert v.startswith("analyses.tooth_contact.torque_Nm = ")
    assert "beyond the elastic contact model's range" in v


def test_reducer_case_that_is_a_folder_is_refused_by_validate(tmp_path):
    """Issue 13 fuzz (seed 13, final main): ``reducer.case`` naming an existing *folder* passed
    the schema's exists-check and crashed the design load (FileNotFoundError, counted as an
    internal error); it is a schema error naming the key."""
    folder = tmp_path / "a_folder"
    folder.mkdir()
    p = _mutant(
        tmp_path,
        "synthetic_rv110e_serial",
        'case = "han2023_rv110e_no_errors"',
        f'case = "{folder.as_posix()}"',
    )
    line = _validate_and_run_schema(p, tmp_path)
    assert line.startswith("reducer.case: ") and "is a folder, not a case file" in line


def test_design_case_removed_after_validation_names_the_key(tmp_path):
    """The design file checked at validation and gone before the design is loaded: a
    ParameterError naming ``reducer.case``, not a FileNotFoundError."""
    from gearte.errors import ParameterError
    from gearte.io.case_file import load_case

    design = tmp_path / "design.toml"
    design.write_text(case_path("han2023_rv110e_no_errors").read_text(encoding="utf-8"))
    p = _mutant(
        tmp_path,
        "synthetic_rv110e_serial",
        'case = "han2023_rv110e_no_errors"',
        f'case = "{design.as_posix()}"',
    )
    case = load_case(p)
    design.unlink()
    with pytest.raises(ParameterError, match="reducer.case"):
        case.design()
