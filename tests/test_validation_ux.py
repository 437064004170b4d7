"""Validation UX (issue 15 item 6) and physical checks at validation time (issue 13): every
problem of a file in one pass, "did you mean" for unknown keys and wrong unit suffixes, gear
pairs that cannot be assembled or have an implausible module are refused by ``validate``."""

from __future__ import annotations

import tomllib

import pytest
from click.testing import CliRunner

from gearte.cases import case_path
from gearte.cli import EXIT_BAD_INPUT, main
from gearte.errors import CaseFileError
from gearte.io.case_file import did_you_mean, load_case_dict


def _bundled(name: str) -> dict:
    return tomllib.loads(case_path(name).read_text(encoding="utf-8"))


def _errors(data: dict) -> dict[str, str]:
    with pytest.raises(CaseFileError) as err:
        load_case_dict(data)
    return dict(err.value.errors)


def test_wrong_unit_suffix_gets_the_right_key_and_its_unit():
    """``torque_Nmm`` where the schema has ``torque_Nm`` (issue 15.6's example)."""
    data = _bundled("han2023_rv110e")
    ls = data["analyses"]["load_sharing"]
    ls["torque_Nmm"] = ls.pop("torque_Nm") * 1000
    errors = _errors(data)
    msg = errors["analyses.load_sharing.torque_Nmm"]
    assert "did you mean 'torque_Nm'" in msg and "N·m" in msg


def test_misspelt_key_gets_a_suggestion():
    data = _bundled("hu2020_rv80e_initial")
    data["stage"]["eccentricty_mm"] = data["stage"].pop("eccentricity_mm")
    assert "did you mean 'eccentricity_mm'" in _errors(data)["stage.eccentricty_mm"]


def test_misspelt_key_in_a_section_with_an_alias_gets_a_suggestion():
    """``[analyses.yield]`` is the field ``yield_`` (alias ``yield``): the section's keys were
    looked up by field name only, so a misspelt key there got no suggestion."""
    data = _bundled("han2023_rv110e_yield")
    data["analyses"]["yield"]["positons"] = data["analyses"]["yield"].pop("positions")
    msg = _errors(data)["analyses.yield.positons"]
    assert "did you mean 'positions'?" in msg


def test_no_suggestion_for_a_key_like_nothing_known():
    assert did_you_mean("zzzz", {"pins", "eccentricity_mm"}) == ""


def test_three_independent_errors_are_reported_in_one_pass(tmp_path):
    data = _bundled("jiang2024_spur_pair")
    data["pair"]["module_mm"] = True
    data["pair"]["runout_um"] = -1.0
    data["pair"]["driving"]["teethh"] = 28
    p = tmp_path / "three.toml"
    from fuzzing import to_toml

    p.write_text(to_toml(data))
    r = CliRunner().invoke(main, ["validate", str(p)])
    assert r.exit_code == EXIT_BAD_INPUT
    for key in ("pair.module_mm", "pair.runout_um", "pair.driving.teethh"):
        assert key in r.output, r.output


def test_gear_pair_that_cannot_be_assembled_is_refused_at_validation():
    """Issue 13: positive tooth-thickness deviations (negative backlash) ran with exit 0."""
    data = _bundled("jiang2024_spur_pair")
    for gear in ("driving", "driven"):
        data["pair"][gear]["thickness_upper_um"] = 80.0
        data["pair"][gear]["thickness_lower_um"] = 60.0
    (msg,) = _errors(data).values()
    assert "cannot be assembled" in msg and "µm" in msg


@pytest.mark.parametrize("case", ["jiang2024_spur_pair", "jiang2024_bevel_pair"])
def test_implausible_module_is_refused(case):
    """Issue 13: a 1e-6 mm module ran with exit 0."""
    data = _bundled(case)
    data["pair"]["module_mm"] = 1e-6
    assert "pair.module_mm" in _errors(data)


def test_rv_dynamics_overlapping_pins_are_refused_by_validate():
    """Issue 13: ``validate`` passed overlapping pins that ``run`` then refused."""
    data = _bundled("li2023_rv")
    data["reducer"]["pins"]["pin_radius_mm"] = 8.0
    (msg,) = _errors(data).values()
    assert "overlap" in msg


def test_three_independent_errors_with_a_cross_section_check_in_one_pass(tmp_path):
    """Issue 15.6: a field error, an unknown key and a contradiction between sections (the
    tolerance-weighted compensation needs a tolerance for each factor) are all reported at once:
    the case-level check runs although another section has field errors."""
    data = _bundled("hu2020_rv80e_initial")
    data["stage"]["face_width_mm"] = -1.0
    data["case"]["titel"] = "typo"
    data["analyses"]["compensation"]["rule"] = "tolerance_weighted"
    data["errors"]["pin_radius_error"]["tolerance_um"] = 0.0
    p = tmp_path / "three.toml"
    from fuzzing import to_toml

    p.write_text(to_toml(data))
    r = CliRunner().invoke(main, ["validate", str(p)])
    assert r.exit_code == EXIT_BAD_INPUT
    assert "3 error(s)" in r.output, r.output
    assert "stage.face_width_mm" in r.output
    assert "case.titel: unknown key; did you mean 'title'?" in r.output
    assert "'tolerance_weighted' needs tolerance_um > 0" in r.output


def test_tooth_relation_negative_tolerance_and_unit_suffix_in_one_pass():
    """The issue's own example: wrong tooth relation + negative tolerance + unknown key (a unit
    suffix the schema does not use) in three sections."""
    data = _bundled("hu2020_rv80e_initial")
    data["stage"]["cycloid_teeth"] = 38
    data["errors"]["pin_radius_error"]["tolerance_um"] = -3.0
    tc = data["analyses"]["tooth_contact"]
    tc["torque_Nmm"] = tc.pop("torque_Nm") * 1000
    errors = _errors(data)
    # the renamed key is both unknown and missing: four lines for the three mistakes
    assert sorted(errors) == [
        "analyses.tooth_contact.torque_Nm",
        "analyses.tooth_contact.torque_Nmm",
        "errors.pin_radius_error.tolerance_um",
        "stage",
    ]
    assert "must equal z_p - 1 = 39" in errors["stage"]
    assert "errors.pin_radius_error.tolerance_um" in errors
    assert "did you mean 'torque_Nm'" in errors["analyses.tooth_contact.torque_Nmm"]


def test_rv_check_between_sections_runs_beside_a_field_error():
    """rv_reducer: an analysis that needs a section the case lacks is reported together with a
    field error of another section (before: only the field error, then the rest on the next try).
    """
    data = _bundled("han2023_rv110e")
    data["operation"]["input_speed_rpm"] = -5
    del data["reducer"]["rated_torque_Nm"]
    errors = _errors(data)
    assert "operation.input_speed_rpm" in errors
    assert "needs reducer.rated_torque_Nm" in errors["(case)"]


def test_torque_in_Nmm_typed_as_Nm_is_refused_at_validation_with_the_value():
    """A 500 N·m torque written as 500 000 (N·mm) in ``torque_Nm`` passes the schema range but
    no steel carries it on the Hu 2020 stage: refused by validate, in the user's units."""
    data = _bundled("hu2020_rv80e_initial")
    data["analyses"]["tooth_contact"]["torque_Nm"] = 500_000.0
    (msg,) = _errors(data).values()
    assert "500000 N·m is implausible" in msg and "MPa" in msg
    assert "500000 N·mm = 500 N·m" in msg
    data["analyses"]["tooth_contact"]["torque_Nm"] = 2000.0  # 2x the paper's: plausible
    load_case_dict(data)


def test_rv_torque_in_Nmm_is_refused_for_each_key_that_holds_it():
    data = _bundled("li2023_rv")
    data["operation"]["output_torque_Nm"] *= 1000  # 450 000 "N·m" on an RV-40E-size reducer
    errors = _errors(data)
    assert list(errors) == ["operation.output_torque_Nm"]
    assert "N·mm" in errors["operation.output_torque_Nm"]


def test_plausibility_is_checked_beside_field_errors():
    data = _bundled("li2023_rv")
    data["operation"]["output_torque_Nm"] *= 1000
    data["reducer"]["discs"]["face_width_mm"] = True  # a type error in another key
    errors = _errors(data)
    assert "reducer.discs.face_width_mm" in errors
    # the torque check needs the discs (face width): it cannot be judged, so it is not reported
    assert "operation.output_torque_Nm" not in errors


def test_every_bundled_case_is_plausible():
    from gearte.cases import list_cases
    from gearte.io.case_file import load_case

    for name in list_cases():
        load_case(name)


@pytest.mark.parametrize(
    "key, value, expected",
    [
        ("torque_Nmm", 1011500.0, "write torque_Nm = 1011.5"),
        ("pin_radius_um", 3000, "write pin_radius_mm = 3"),
        ("youngs_modulus_GPa", 206, "write youngs_modulus_MPa = 206000"),
        ("rotation_modification_deg", 0.5, "write rotation_modification_arcmin = 30"),
    ],
)
def test_wrong_unit_suffix_hint_converts_the_value(key, value, expected):
    known = {"torque_Nm", "pin_radius_mm", "youngs_modulus_MPa", "rotation_modification_arcmin"}
    assert expected in did_you_mean(key, known, value)


def test_unit_suffix_hint_gives_no_number_across_dimensions_or_for_text():
    assert "write" not in did_you_mean("length_Nm", {"length_mm"}, 3.0)
    assert "write" not in did_you_mean("torque_Nmm", {"torque_Nm"}, "1000")
