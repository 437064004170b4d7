"""DIN 3967 tooth-thickness classes → allowances → backlash; ISO 286 js centre-distance fields.

Sources of the expected values (the standards are not in gearte's corpus; see
docs/tolerance_grades.md):
* ``norm_example_27cd``: DIN 3967 §3.1's own example as a public transcription of the norm
  pins it (class 27cd at d = 100 mm → A_sne = −70 µm, A_sni = −170 µm).
* ``cd25_two_gears``: the same transcription's worked pair (m 2, z 20/41 → d 40/82 mm, both
  cd25): −54/−84 µm and −70/−110 µm, j_n = (0.054 + 0.070)·cos 20° at the nominal centre
  distance.
* ``cd_column`` / ``tolerance_25_column``: an independent public optimiser quotes Table 1's
  cd column and Table 2's series-25 column for all eleven diameter rows.
* ``stplus_js7``: a published FVA STplus report: a = 52 mm, DIN 3964 field JS7 → A_Ae = +0.015,
  A_Ai = −0.015 mm; at α_wt = 21.46251° the backlash change by A_Ae is j_t 0.012 / j_n 0.011 mm.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from gearte.errors import ParameterError
from gearte.tolerance.din3967 import (
    ALLOWANCE_SERIES,
    DIAMETER_UPPER_BOUNDS_MM,
    TOLERANCE_SERIES,
    pair_backlash_limits,
    parse_thickness_class,
    thickness_tolerance_um,
    tooth_thickness_allowances,
    upper_allowance_um,
)
from gearte.tolerance.iso286 import (
    SIZE_UPPER_BOUNDS_MM,
    js_allowances_um,
    standard_tolerance_um,
)
from gearte.units import deg_to_rad

# one diameter inside each row of DIN 3967's tables
ROW_D = (5.0, 30.0, 100.0, 200.0, 400.0, 800.0, 1200.0, 2000.0, 3000.0, 5000.0, 8000.0)


def test_din3967_norm_example_27cd_at_d100():
    t = tooth_thickness_allowances("27cd", 100.0)
    assert (t.upper_um, t.tolerance_um, t.lower_um) == (-70.0, 100.0, -170.0)
    assert (t.allowance_series, t.tolerance_series, t.thickness_class) == ("cd", 27, "cd27")


def test_din3967_cd25_two_gears_m2_z20_z41_and_their_normal_backlash():
    g1, g2 = tooth_thickness_allowances("cd25", 40.0), tooth_thickness_allowances("cd25", 82.0)
    assert (g1.upper_um, g1.lower_um) == (-54.0, -84.0)
    assert (g2.upper_um, g2.lower_um) == (-70.0, -110.0)
    b = pair_backlash_limits(-0.054, -0.084, -0.070, -0.110, 0.0, 0.0, deg_to_rad(20.0))
    assert b.normal_min == pytest.approx((0.054 + 0.070) * math.cos(math.radians(20.0)))
    assert b.circumferential_max == pytest.approx(0.084 + 0.110)


def test_din3967_cd_column_and_tolerance_25_column_two_independent_sources():
    cd = [-40, -54, -70, -95, -130, -175, -240, -320, -430, -580, -780]
    t25 = [20, 30, 40, 50, 60, 80, 100, 130, 160, 200, 250]
    assert [upper_allowance_um("cd", d) for d in ROW_D] == cd
    assert [thickness_tolerance_um(25, d) for d in ROW_D] == t25


def test_din3967_tables_are_monotonic_in_series_and_diameter():
    """Transcription check: thinning grows from h to a and with d; T_sn grows with series and d."""
    up = np.array([[upper_allowance_um(s, d) for s in ALLOWANCE_SERIES] for d in ROW_D])
    tol = np.array([[thickness_tolerance_um(t, d) for t in TOLERANCE_SERIES] for d in ROW_D])
    assert np.all(np.diff(up, axis=1) > 0) and np.all(up[:, -1] == 0.0)
    assert np.all(np.diff(up[:, :-1], axis=0) < 0)
    assert np.all(np.diff(tol, axis=1) > 0) and np.all(np.diff(tol, axis=0) > 0)


def test_din3967_row_bounds_are_over_up_to():
    assert upper_allowance_um("a", 10.0) == -100.0  # "up to 10" includes 10
    assert upper_allowance_um("a", 10.001) == -135.0
    assert upper_allowance_um("cd", 50.0) == -54.0
    assert thickness_tolerance_um(30, DIAMETER_UPPER_BOUNDS_MM[-1]) == 2400.0


@pytest.mark.parametrize("text", ["cd25", "CD 25", "25cd", " 25 cd "])
def test_din3967_class_spellings(text):
    assert parse_thickness_class(text) == ("cd", 25)


@pytest.mark.parametrize("text", ["xy25", "cd20", "cd31", "cd", "25", "i25", 25, ""])
def test_din3967_unknown_class_is_an_error_naming_the_field(text):
    with pytest.raises(ParameterError, match="driving.tooth_thickness_allowance.*DIN 3967"):
        tooth_thickness_allowances(text, 100.0, field="driving.tooth_thickness_allowance")


@pytest.mark.parametrize("d", [0.0, -5.0, 10_000.1, math.nan])
def test_din3967_diameter_outside_the_tables_is_an_error(d):
    with pytest.raises(ParameterError, match="not extrapolated"):
        tooth_thickness_allowances("cd25", d)


def test_pair_backlash_limits_stplus_js7_centre_distance_term():
    """Only A_a differs from zero: Δj_t = 2·0.015·tan 21.46251° → 0.012, Δj_n → 0.011 mm."""
    hi, lo = (v / 1000.0 for v in js_allowances_um("js7", 52.0))
    assert (hi, lo) == (0.015, -0.015)
    b = pair_backlash_limits(0.0, 0.0, 0.0, 0.0, hi, lo, deg_to_rad(21.46251))
    assert round(float(b.circumferential_max), 3) == 0.012
    assert round(float(b.normal_max), 3) == 0.011
    assert b.normal_min == pytest.approx(-b.normal_max)


def test_pair_backlash_limits_broadcast_over_arrays():
    up = np.array([-0.05, -0.07])
    b = pair_backlash_limits(up, up - 0.03, up, up - 0.03, 0.01, -0.01, deg_to_rad(20.0))
    assert np.shape(b.normal_max) == (2,)
    assert np.all(b.normal_max - b.normal_min > 0)


def test_iso286_table_within_6_percent_of_the_formula_k_times_i():
    """Transcription check, 6 < size <= 500 mm: IT = k·i, i = 0.45·∛D + 0.001·D, D the geometric
    mean of the row bounds (ISO 286-1); the table rounds to preferred numbers (worst 5.6 %)."""
    k = {5: 7, 6: 10, 7: 16, 8: 25, 9: 40, 10: 64, 11: 100}
    lows = (1.0, *SIZE_UPPER_BOUNDS_MM[:-1])
    for lo, hi in zip(lows, SIZE_UPPER_BOUNDS_MM, strict=True):
        if hi <= 6 or hi > 500:
            continue
        D = math.sqrt(lo * hi)  # noqa: N806 - the standard's symbol
        i = 0.45 * D ** (1 / 3) + 0.001 * D
        for grade, kk in k.items():
            it = standard_tolerance_um(grade, hi)
            assert abs(it / (kk * i) - 1.0) < 0.06, (grade, hi, it, kk * i)


def test_iso286_values_and_errors():
    assert standard_tolerance_um(7, 52.0) == 30.0
    assert standard_tolerance_um(6, 3150.0) == 135.0
    assert js_allowances_um("JS 6", 100.0) == (11.0, -11.0)
    with pytest.raises(ParameterError, match="centre_distance_allowance.*js"):
        js_allowances_um("h7", 100.0)
    with pytest.raises(ParameterError, match="js5"):
        js_allowances_um("js12", 100.0)
    with pytest.raises(ParameterError, match="not extrapolated"):
        js_allowances_um("js7", 4000.0)


def test_helical_backlash_normal_allowances_to_transverse_by_hand():
    """cd25 pinion and wheel (−54/−84, −70/−110 µm), js7 ±20 µm, α_n 20°, β 15°:
    α_t = atan(tan 20° / cos 15°) = 20.6469°; j_t,max = 194 / cos 15° + 40 tan α_t
    = 200.846 + 15.075 = 215.92 µm; j_n = j_t cos 20° cos 15°; at the nominal centre distance
    j_n = −(A_sn,1 + A_sn,2) cos α_n, the spur law in the normal section; β = 0 is the spur pair."""
    from gearte.tolerance.din3967 import helical_pair_backlash_limits, pair_backlash_limits

    an, b = math.radians(20.0), math.radians(15.0)
    h = helical_pair_backlash_limits(-0.054, -0.084, -0.070, -0.110, 0.020, -0.020, an, b)
    at = math.atan(math.tan(an) / math.cos(b))
    assert math.degrees(at) == pytest.approx(20.6469, abs=1e-4)
    assert float(h.circumferential_max) == pytest.approx(0.194 / math.cos(b) + 0.040 * math.tan(at))
    assert float(h.circumferential_max) == pytest.approx(0.21592, abs=1e-5)
    assert float(h.normal_min) == pytest.approx(
        float(h.circumferential_min) * math.cos(an) * math.cos(b)
    )
    # cos α_n cos β = cos α_t cos β_b (ISO 21771's form of the same factor)
    beta_b = math.asin(math.sin(b) * math.cos(an))
    assert math.cos(an) * math.cos(b) == pytest.approx(math.cos(at) * math.cos(beta_b))
    h0 = helical_pair_backlash_limits(-0.054, -0.084, -0.070, -0.110, 0, 0, an, b)
    assert float(h0.normal_min) == pytest.approx(0.124 * math.cos(an))
    s = pair_backlash_limits(-0.054, -0.084, -0.070, -0.110, 0.020, -0.020, an)
    z = helical_pair_backlash_limits(-0.054, -0.084, -0.070, -0.110, 0.020, -0.020, an, 0.0)
    assert float(z.normal_max) == pytest.approx(float(s.normal_max))
    with pytest.raises(ParameterError, match="helix_angle"):
        helical_pair_backlash_limits(0, 0, 0, 0, 0, 0, an, math.pi / 2)
