"""Malformed cycloid_stage case files: one clear line naming the field, never a traceback."""

from __future__ import annotations

import copy
import math
import tomllib
from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from gearte.errors import CaseFileError, ParameterError
from gearte.io.case_file import load_case

BAD = Path(__file__).parent / "bad_cases"
BAD_FILES = sorted(BAD.glob("*.toml"))


def _expected(path: Path) -> str:
    first = path.read_text(encoding="utf-8").splitlines()[0]
    assert first.startswith("# expect: ")
    return first.removeprefix("# expect: ").strip()


def test_there_are_at_least_twenty_bad_cases():
    assert len(BAD_FILES) >= 20


@pytest.mark.parametrize("path", BAD_FILES, ids=[p.stem for p in BAD_FILES])
def test_bad_case_gives_one_line_naming_the_field(path):
    with pytest.raises(CaseFileError) as exc:
        load_case(path)
    err = exc.value
    assert len(err.errors) == 1, str(err)
    field, message = err.errors[0]
    line = f"{field}: {message}"
    assert "\n" not in line
    assert _expected(path) in line, line
    assert "Traceback" not in str(err)


@pytest.mark.parametrize("name", ["negative_face_width", "k1_not_below_one"])
def test_cli_validate_reports_bad_case_without_traceback(name):
    from click.testing import CliRunner

    from gearte.cli import main

    r = CliRunner().invoke(main, ["validate", str(BAD / f"{name}.toml")])
    assert r.exit_code == 2
    assert "Traceback" not in r.output
    assert _expected(BAD / f"{name}.toml") in r.output


# ---------------------------------------------------------------------------------------------
# property test: random case dictionaries

VALID = tomllib.loads(
    (Path(__file__).parents[1] / "examples" / "hu2020_rv80e_initial.toml").read_text(
        encoding="utf-8"
    )
)
VALID["analyses"]["tooth_contact"]["mesh_positions"] = 3

_scalars = st.one_of(
    st.none(),
    st.booleans(),
    st.integers(min_value=-(10**6), max_value=10**6),
    st.floats(allow_nan=True, allow_infinity=True),
    st.floats(min_value=-0.1, max_value=100.0),
    st.text(max_size=8),
    st.lists(st.integers(), max_size=3),
    st.dictionaries(st.text(max_size=5), st.integers(), max_size=2),
)


def _paths(d, prefix=()):
    for k, v in d.items():
        yield (*prefix, k)
        if isinstance(v, dict):
            yield from _paths(v, (*prefix, k))


PATHS = list(_paths(VALID))


@st.composite
def mutated_cases(draw):
    case = copy.deepcopy(VALID)
    for _ in range(draw(st.integers(min_value=1, max_value=4))):
        path = draw(st.sampled_from(PATHS))
        parent = case
        for k in path[:-1]:
            parent = parent.get(k) if isinstance(parent, dict) else None
            if not isinstance(parent, dict):
                break
        if not isinstance(parent, dict):
            continue
        action = draw(st.sampled_from(["replace", "delete", "add", "scale"]))
        key = path[-1]
        if action == "replace":
            parent[key] = draw(_scalars)
        elif action == "delete":
            parent.pop(key, None)
        elif action == "add":
            parent[draw(st.text(min_size=1, max_size=6))] = draw(_scalars)
        elif isinstance(parent.get(key), float | int) and not isinstance(parent.get(key), bool):
            parent[key] = parent[key] * draw(st.floats(min_value=-3, max_value=3))
    return case


@settings(max_examples=120, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(mutated_cases())
def test_random_case_dicts_raise_only_gearte_errors(case):
    """Only CaseFileError (invalid file) or ParameterError (valid file, impossible load) escape."""
    from gearte.studies import RunOptions, run_case

    try:
        valid = load_case(case)
    except CaseFileError as exc:
        assert exc.errors and all(isinstance(f, str) and m for f, m in exc.errors)
        return
    try:
        result = run_case(valid, RunOptions(progress=False))
    except ParameterError:
        return
    v = result["geometry"].values
    assert 0 < v["K1"] < 1
    if "tooth_contact" in result:
        assert math.isfinite(result["tooth_contact"].values["max_contact_force [N]"])


@st.composite
def physical_range_cases(draw):
    """Cases whose numbers all lie in the schema ranges: exercises the physical validators."""
    pins = draw(st.integers(min_value=4, max_value=80))
    stage = {
        "pins": pins,
        "pin_circle_radius_mm": draw(st.floats(min_value=5.0, max_value=300.0)),
        "pin_radius_mm": draw(st.floats(min_value=0.2, max_value=12.0)),
        "eccentricity_mm": draw(st.floats(min_value=0.1, max_value=6.0)),
        "face_width_mm": draw(st.floats(min_value=1.0, max_value=60.0)),
        "equidistant_modification_mm": draw(st.floats(min_value=-0.1, max_value=0.1)),
        "shifted_modification_mm": draw(st.floats(min_value=-0.1, max_value=0.1)),
        "rotation_modification_arcmin": draw(st.floats(min_value=-5.0, max_value=5.0)),
    }
    return {
        "case": {"kind": "cycloid_stage", "title": "random"},
        "stage": stage,
        "errors": {"radial_runout": {"mean_um": 5.0, "tolerance_um": 10.0}},
        "analyses": {
            "geometric_te": {},
            "tooth_contact": {
                "torque_Nm": draw(st.floats(min_value=1.0, max_value=5000.0)),
                "disc_share": 0.5,
                "youngs_modulus_MPa": 2.06e5,
                "poisson_ratio": 0.3,
                "mesh_positions": 3,
            },
            "compensation": {},
        },
    }


@settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(physical_range_cases())
def test_random_physical_cases_run_or_fail_cleanly(case):
    from gearte.studies import RunOptions, run_case

    try:
        valid = load_case(case)
    except CaseFileError as exc:
        assert len(exc.errors) >= 1
        return
    try:
        result = run_case(valid, RunOptions(progress=False))
    except ParameterError:
        return
    tc = result["tooth_contact"].values
    assert tc["pins_in_mesh"] >= 1
    assert tc["max_contact_force [N]"] > 0
    assert math.isfinite(result["geometric_te"].values["geometric_te_tolerance [arcmin]"])


_any_number = st.one_of(
    st.floats(allow_nan=True, allow_infinity=True),
    st.floats(min_value=-5.0, max_value=200.0),
    st.integers(min_value=-5, max_value=100),
    st.booleans(),
    st.text(max_size=3),
    st.none(),
)


@settings(max_examples=200, deadline=None)
@given(
    z_p=st.one_of(st.integers(min_value=-3, max_value=120), _any_number),
    r_p=_any_number,
    r_rp=_any_number,
    a=_any_number,
    b=_any_number,
    dr_rp=st.one_of(st.floats(min_value=-0.2, max_value=0.2), _any_number),
    dr_p=st.one_of(st.floats(min_value=-0.2, max_value=0.2), _any_number),
)
def test_cycloid_stage_api_raises_only_parameter_error(z_p, r_p, r_rp, a, b, dr_rp, dr_p):
    from gearte.geometry.cycloid import CycloidStage

    try:
        stage = CycloidStage(z_p=z_p, r_p=r_p, r_rp=r_rp, a=a, b=b, dr_rp=dr_rp, dr_p=dr_p)
    except ParameterError as exc:
        assert exc.field and exc.reason
        return
    assert 0 < stage.K1 < 1
    assert stage.root_radius < stage.tip_radius


@pytest.mark.parametrize("a", [1e-300, 5e-324, 1e-9])
def test_an_eccentricity_lost_to_round_off_is_refused(a):
    """An eccentricity far below any drive's (the random search above once found a = 1e-300 mm,
    where the root radius equals the tip radius in floating point) is refused, naming ``a``."""
    from gearte.geometry.cycloid import CycloidStage

    with pytest.raises(ParameterError) as err:
        CycloidStage(z_p=40, r_p=76.0, r_rp=3.0, a=a, b=11.0)
    assert err.value.field == "a" and "eccentricity" in err.value.reason
