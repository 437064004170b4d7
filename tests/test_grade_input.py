"""Case files may give an accuracy grade instead of raw tolerance numbers (``grade = N``)."""

from __future__ import annotations

import math
import tomllib

import pytest

from gearte.cases import case_path
from gearte.errors import CaseFileError
from gearte.io.case_file import load_case


def _spur_case(**driving):
    data = tomllib.loads(case_path("jiang2024_spur_pair").read_text())
    data["pair"]["driving"].pop("radial_composite_tol_um")
    data["pair"]["driving"].update(driving)
    return data


def test_spur_gear_grade5_gives_iso1328_2_radial_composite_by_hand():
    """z 28, m 2.5 → d 70 mm; F''i = (3.2·2.5 + 1.01·√70 + 6.4) = 22.85 → 23 µm (grade 5)."""
    case = load_case(_spur_case(grade=5))
    pair = case.pair.build()
    assert 3.2 * 2.5 + 1.01 * math.sqrt(70) + 6.4 == pytest.approx(22.85, abs=0.01)
    assert pair.driving.radial_composite_tol == pytest.approx(0.023)


def test_grade_and_raw_number_together_is_an_error():
    with pytest.raises(CaseFileError, match="exactly one of radial_composite_tol_um and grade"):
        load_case(_spur_case(grade=5, radial_composite_tol_um=27.0))


def test_grade_out_of_range_is_an_error_naming_the_field():
    with pytest.raises(CaseFileError, match="grade"):
        load_case(_spur_case(grade=13))
