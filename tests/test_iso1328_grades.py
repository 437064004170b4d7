"""Accuracy grades → tolerances (ISO 1328-1:2013 flank, ISO 1328-2:1997 radial composite).

Sources of the expected values:
* ``worked_example_class6``: a published worked example of the 2013 formulas (m_n = 3 mm,
  z = 40, d = 120 mm, b = 30 mm, class 6: f_pT 8.94 → 9.0, F_pT 28.80 → 29, F_αT → 12), found in
  a public calculator's test-suite; F_βT and F_rT of the same gear computed by hand below.
* the other rows: computed by hand from equations (5)–(12) of ISO 1328-1:2013 and the rounding
  rule of §5.2.3, each intermediate written in the test.
"""

from __future__ import annotations

import math

import pytest

from gearte.errors import ParameterError
from gearte.tolerance.iso1328 import (
    flank_tolerances,
    grade_tolerances_um,
    iso1328_round,
    radial_composite_tolerances,
)


def test_iso1328_2013_worked_example_class6_m3_d120_b30():
    t = flank_tolerances(6, 3.0, 120.0, 30.0)
    assert t.unrounded["f_pT"] == pytest.approx(8.94, abs=0.005)  # (0.12+1.2+5)·√2
    assert t.f_pT == 9.0  # 5…10 µm → nearest 0.5
    assert t.unrounded["F_pT"] == pytest.approx(28.80, abs=0.005)
    assert t.F_pT == 29.0  # > 10 µm → nearest 1
    assert t.F_alphaT == 12.0  # √(7.52² + 9.41²) = 12.04
    # by hand: f_Hβ = (0.05·√120 + 0.35·√30 + 4)·√2 = 9.143, f_fβ = (0.07·√120 + 0.45·√30 + 4)·√2
    # = 10.227 → F_β = 13.72 → 14;  F_r = 0.9·28.80 = 25.92 → 26
    assert t.unrounded["F_betaT"] == pytest.approx(13.718, abs=0.001)
    assert t.F_betaT == 14.0
    assert t.F_rT == 26.0


def test_iso1328_2013_by_hand_class5_m2_d40_b20():
    """Class 5 (step factor 1): every formula by hand."""
    t = flank_tolerances(5, 2.0, 40.0, 20.0)
    assert t.unrounded["f_pT"] == pytest.approx(0.04 + 0.8 + 5)  # 5.84
    assert t.f_pT == 6.0
    assert t.unrounded["F_pT"] == pytest.approx(0.08 + 0.55 * math.sqrt(40) + 1.4 + 12)  # 16.96
    assert t.F_pT == 17.0
    assert t.f_HalphaT == 4.8  # 0.8 + 0.04 + 4 = 4.84; < 5 µm → nearest 0.1
    assert t.unrounded["F_alphaT"] == pytest.approx(math.hypot(4.84, 6.1))  # 7.787
    assert t.F_alphaT == 8.0
    assert t.F_betaT == 8.5  # √(5.882² + 6.455²) = 8.733
    assert t.F_rT == 15.0  # 15.26


def test_iso1328_2013_class9_m4_d200():
    t = flank_tolerances(9, 4.0, 200.0, 40.0)
    assert t.unrounded["f_pT"] == pytest.approx((0.2 + 1.6 + 5) * 4)  # 27.2 → 27
    assert t.f_pT == 27.0
    assert t.F_pT == 92.0  # (0.4 + 0.55·√200 + 2.8 + 12)·4 = 91.91


def test_iso1328_2013_step_between_classes_is_sqrt2():
    a = flank_tolerances(5, 2.0, 80.0, 20.0).unrounded
    b = flank_tolerances(6, 2.0, 80.0, 20.0).unrounded
    for k in a:
        assert b[k] / a[k] == pytest.approx(math.sqrt(2))


@pytest.mark.parametrize(
    ("value", "rounded"),
    [(12.49, 12.0), (10.4, 10.0), (7.3, 7.5), (7.2, 7.0), (7.25, 7.5), (4.96, 5.0), (4.94, 4.9)],
)
def test_iso1328_2013_rounding_rule_5_2_3(value, rounded):
    assert iso1328_round(value) == rounded


def test_iso1328_2_1997_radial_composite_by_hand():
    r = radial_composite_tolerances(5, 2.0, 40.0)
    assert r.unrounded["F_i2"] == pytest.approx(6.4 + 1.01 * math.sqrt(40) + 6.4)  # 19.19
    assert r.F_i2 == 19.0
    r7 = radial_composite_tolerances(7, 2.0, 60.0)
    assert r7.F_i2 == 41.0  # (6.4 + 1.01·√60 + 6.4)·2 = 41.25
    assert r7.f_i2 == 14.0  # (5.92 + 0.01·√60 + 0.8)·2 = 13.59


def test_grade_tolerances_names():
    g = grade_tolerances_um(6, 3.0, 120.0, 30.0)
    assert g["single_pitch_um"] == 9.0
    assert g["runout_um"] == 26.0
    assert "radial_composite_um" in g


@pytest.mark.parametrize(
    ("args", "field"),
    [
        ((0, 2.0, 40.0, 20.0), "grade"),
        ((12, 2.0, 40.0, 20.0), "grade"),
        ((5, 0.3, 40.0, 20.0), "module_mm"),
        ((5, 2.0, 4.0, 20.0), "reference_diameter_mm"),
        ((5, 2.0, 40.0, 2.0), "face_width_mm"),
    ],
)
def test_iso1328_out_of_range_is_an_error_not_extrapolated(args, field):
    with pytest.raises(ParameterError) as e:
        flank_tolerances(*args)
    assert e.value.field == field


def test_iso1328_2013_runout_needs_no_face_width():
    from gearte.tolerance.iso1328 import runout_tolerance

    assert runout_tolerance(6, 3.0, 120.0) == flank_tolerances(6, 3.0, 120.0, 30.0).F_rT == 26.0
