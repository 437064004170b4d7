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
