"""Strict types in case files (issue 13): no lax coercion, deep nesting is a clean error, and
``gearte validate`` checks every file it is given."""

from __future__ import annotations

import tomllib

import pytest
from click.testing import CliRunner

from gearte.cases import case_path
from gearte.cli import EXIT_BAD_INPUT, main
from gearte.errors import CaseFileError
from gearte.io.case_file import MAX_NESTING, load_case, load_case_dict


def _bundled(name: str) -> dict:
    return tomllib.loads(case_path(name).read_text(encoding="utf-8"))


def _one_error(data: dict) -> tuple[str, str]:
    with pytest.raises(CaseFileError) as err:
        load_case_dict(data)
    assert len(err.value.errors) == 1, err.value.errors
    return err.value.errors[0]


@pytest.mark.parametrize("bad", [True, "0.005"])
def test_reproducer_amplitude_mm_true_is_not_a_number(bad):
    """Issue 13 reproducer: ``amplitude_mm = true`` ran as a 1 mm error; ``"0.005"`` as 0.005
    (the error magnitude is ``value_um`` of a ``[[reducer.errors]]`` entry since issue 11)."""
    data = _bundled("li2023_rv_errors")
    cam = next(e for e in data["reducer"]["errors"] if e["part"] == "cam")
    cam["value_um"] = bad
    field, msg = _one_error(data)
    assert field.endswith("value_um") and "valid number" in msg


def test_true_is_not_a_count_and_a_float_is_not_an_integer():
    data = _bundled("jiang2024_spur_pair")
    key, section = next(
        (k, s)
        for s in data.values()
        if isinstance(s, dict)
        for k, v in s.items()
        if isinstance(v, int) and not isinstance(v, bool)
    )
    for bad in (True, float(section[key]) + 0.5, str(section[key])):
        section[key] = bad
        field, msg = _one_error(data)
        assert field.endswith(key) and "integer" in msg


def test_an_integer_is_accepted_where_a_float_is_expected():
    """``1`` for 1.0 changes no type category: TOML users write it."""
    data = _bundled("hu2020_rv80e_initial")
    data["stage"]["eccentricity_mm"] = 1
    assert load_case_dict(data).stage.eccentricity_mm == 1.0


def test_toml_arrays_fill_tuples_and_their_items_are_strict():
    from gearte.io.schema import StrictModel

    class Section(StrictModel):
        pair: tuple[float, float] | None = None

    assert Section.model_validate({"pair": [1, 2.5]}).pair == (1.0, 2.5)
    with pytest.raises(Exception, match="valid number"):
        Section.model_validate({"pair": [1, True]})


@pytest.mark.parametrize("depth", [MAX_NESTING + 2, 600, 3000])
@pytest.mark.parametrize("shape", ["array", "inline_table", "dotted_table"])
def test_reproducer_deep_nesting_is_a_case_error(tmp_path, depth, shape):
    """Issue 13 reproducer: nesting ≥ 500 deep raised RecursionError (exit 3)."""
    text = {
        "array": "x = " + "[" * depth + "]" * depth,
        "inline_table": "x = " + "{a = " * depth + "1" + "}" * depth,
        "dotted_table": "[" + ".".join(["a"] * depth) + "]\nb = 1",
    }[shape]
    p = tmp_path / "deep.toml"
    p.write_text('[case]\nkind = "foundation_test"\n' + text + "\n")
    with pytest.raises(CaseFileError, match="nested deeper"):
        load_case(p)


def test_validate_checks_every_file_it_is_given(tmp_path):
    good = tmp_path / "good.toml"
    good.write_text('[case]\nkind = "foundation_test"\n[demo]\nlength_mm = 4.0\n')
    deep = tmp_path / "deep.toml"
    deep.write_text("x = " + "[" * 3000 + "]" * 3000 + "\n")
    wrong = tmp_path / "wrong.toml"
    wrong.write_text('[case]\nkind = "foundation_test"\n[demo]\nlength_mm = true\n')
    missing = tmp_path / "missing.toml"
    args = ["validate", str(good), str(deep), str(missing), "a\x00b", str(wrong), str(good)]
    r = CliRunner().invoke(main, args)
    assert r.exit_code == EXIT_BAD_INPUT, r.output
    assert r.output.count("good.toml: ok") == 2 and "missing.toml" in r.output
    assert "deep.toml" in r.output and "demo.length_mm" in r.output
    assert "Traceback" not in r.output


def test_case_name_with_control_characters_is_refused():
    data = _bundled("hu2020_rv80e_initial")
    data["case"]["name"] = "a\x00b"
    field, _ = _one_error(data)
    assert field == "case.name"


def test_true_is_not_a_sign():
    """Found by the fuzzer (make fuzz, seed 13): ``angle_coeff = true`` passed as the sign 1,
    since True == 1 satisfies ``Literal[-1, 1]`` even in strict mode."""
    data = _bundled("wang2013_2kh_eq9")
    data["errors"]["terms"][5]["angle_coeff"] = True
    field, msg = _one_error(data)
    assert field == "errors.terms.5.angle_coeff" and "boolean" in msg


@pytest.mark.parametrize("name", ["x" * 300, "a\x00b"])
def test_chain_drive_case_that_cannot_be_a_file_name_is_a_case_error(name):
    """Found by the fuzzing run through the fork server: ``drive.case = "xxx…"`` (300
    characters) raised ``OSError: File name too long`` out of validation (exit 3); it is a
    case error naming the stage's drive."""
    data = _bundled("robot_joint_spur_rv_yield")
    (stage,) = [s for s in data["chain"]["stages"] if "case" in s.get("drive", {})]
    stage["drive"]["case"] = name
    with pytest.raises(CaseFileError) as err:
        load_case_dict(data, base_dir=str(case_path("robot_joint_spur_rv_yield").parent))
    (field, msg), *_ = err.value.errors
    assert field.startswith("chain.stages.") and field.endswith(".drive") and "\n" not in msg
