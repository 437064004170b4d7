"""Bad input to the RV reducer description and the rv_reducer case kind.

Every error names the field, the value and the allowed range.
"""

from __future__ import annotations

import copy
import tomllib

import numpy as np
import pytest

from gearte.cases import case_path
from gearte.errors import CaseFileError, ParameterError
from gearte.geometry.rv import ErrorEntry, ManufacturingErrors
from gearte.io.case_file import load_case_dict
from gearte.models.rv_catalogue import torque_path


@pytest.fixture(scope="module")
def han_dict():
    return tomllib.loads(case_path("han2023_rv110e").read_text(encoding="utf-8"))


def _errors_of(data):
    with pytest.raises(CaseFileError) as exc:
        load_case_dict(data)
    return exc.value.errors


def test_crank_count_differs_from_planet_count(han_dict):
    data = copy.deepcopy(han_dict)
    data["reducer"]["first_stage"]["planets"] = 2
    errs = _errors_of(data)
    text = " ".join(f"{f}: {m}" for f, m in errs)
    assert "first_stage.planets" in text and "cranks.count" in text


@pytest.mark.parametrize(
    ("entry", "field"),
    [
        ({"part": "cam", "crank": 4, "disc": 1, "value_um": 5.0, "angle_deg": 0.0}, "crank"),
        ({"part": "cam", "crank": 1, "disc": 3, "value_um": 5.0, "angle_deg": 0.0}, "disc"),
        ({"part": "disc_crank_bore", "crank": 2, "value_um": 5.0, "angle_deg": 0.0}, "disc"),
        ({"part": "carrier_crank_bore", "crank": 7, "value_um": 1.0, "angle_deg": 0.0}, "crank"),
    ],
)
def test_error_for_index_that_does_not_exist(han_dict, entry, field):
    data = copy.deepcopy(han_dict)
    data["reducer"]["errors"].append(entry)
    k = len(data["reducer"]["errors"]) - 1
    text = " ".join(f"{f}: {m}" for f, m in _errors_of(data))
    assert f"errors[{k}].{field}" in text
    assert "index must be in 1.." in text


def test_error_index_api():
    with pytest.raises(ParameterError, match=r"errors\[0\]\.crank"):
        ManufacturingErrors.from_entries([ErrorEntry("cam", 5, 1, 0.01, 0.0)], 3, 2)
    with pytest.raises(ParameterError, match="given twice"):
        ManufacturingErrors.from_entries(
            [ErrorEntry("cam", 1, 1, 0.01, 0.0), ErrorEntry("cam", 1, 1, 0.02, 0.0)], 3, 2
        )


def test_torque_sweep_without_zero_crossing(han_dict):
    data = copy.deepcopy(han_dict)
    data["analyses"]["catalogue"]["torque_sweep"] = [0.0, 1.0, 0.2, 1.0]
    text = " ".join(f"{f}: {m}" for f, m in _errors_of(data))
    assert "analyses.catalogue" in text and "zero crossing" in text
    with pytest.raises(ParameterError, match="torque_sweep"):
        torque_path([0.1, 1.0, 0.5])


def test_palmgren_or_stiffness_not_both(han_dict):
    data = copy.deepcopy(han_dict)
    data["reducer"]["cranks"]["cam_bearing"]["stiffness_N_per_mm"] = 1e5
    text = " ".join(f"{f}: {m}" for f, m in _errors_of(data))
    assert "reducer.cranks.cam_bearing" in text


def test_pin_error_list_length(han_dict):
    data = copy.deepcopy(han_dict)
    data["reducer"]["pins"]["radius_errors_um"] = [1.0] * 39
    text = " ".join(f"{f}: {m}" for f, m in _errors_of(data))
    assert "radius_errors_um" in text and "40" in text


def test_eccentricity_too_large_names_field(han_dict):
    data = copy.deepcopy(han_dict)
    data["reducer"]["cranks"]["eccentricity_mm"] = 2.1  # K1 = 2.1*40/82 > 1
    text = " ".join(f"{f}: {m}" for f, m in _errors_of(data))
    assert "cranks.eccentricity" in text and "K1" in text


def test_valid_case_loads(han_dict):
    case = load_case_dict(copy.deepcopy(han_dict))
    assert len(case.reducer.errors) == 18
    assert np.isclose(case.reducer.rated_torque_Nm, 1078.0)


def test_all_reducer_problems_reported_at_once(han_dict):
    data = copy.deepcopy(han_dict)
    data["reducer"]["first_stage"]["planets"] = 2
    data["reducer"]["errors"][0]["crank"] = 5
    text = " ".join(f"{f}: {m}" for f, m in _errors_of(data))
    assert "first_stage.planets = 2" in text
    assert "errors[0].crank = 5" in text
