"""Table 2 (error coefficients, sensitivity indices) and the geometric TE model (eq 5–17, 24–27)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from gearte.errors import ParameterError
from gearte.geometry.cycloid import CycloidStage
from gearte.models.cycloid_te import (
    ERROR_FACTORS,
    TABLE2_ROWS,
    compensate,
    eccentricity_te,
    error_coefficients,
    factor_contributions,
    geometric_te,
    sensitivity_indices,
    te_gradients,
)
from gearte.units import arcmin_to_rad, rad_to_arcmin

TABLE3 = dict(z_p=40, r_p=76.0, r_rp=3.0, a=1.5, b=11.0, dr_rp=-0.022, dr_p=-0.0437)

# Table 2, third column (sensitivity indices), rows a-h, printed to 4 decimals
TABLE2_INDICES = {
    "a": 1.0,
    "b": -1.6308,
    "c": 0.8154,
    "d": 0.4077,
    "e": 1.2882,
    "f": 1.6308,
    "g": -1.0,
    "h": -0.6441,
}


def test_hu2020_table2_sensitivity_indices():
    # Table 3's K1 = 0.78993; indices printed to 4 decimals -> compare after rounding
    idx = sensitivity_indices(CycloidStage(**TABLE3))
    for row, printed in TABLE2_INDICES.items():
        assert round(idx[TABLE2_ROWS[row]], 4) == pytest.approx(printed, abs=1e-12), row


def test_hu2020_table2_error_coefficients():
    K1 = CycloidStage(**TABLE3).K1
    c = error_coefficients(K1)
    expected = {  # Table 2, second column (signs restored from the third)
        "a": math.sqrt(1 - K1**2),
        "b": -1.0,
        "c": 0.5,
        "d": 0.25,
        "e": K1,
        "f": 1.0,
        "g": -math.sqrt(1 - K1**2),
        "h": -K1 / 2,
    }
    for row, v in expected.items():
        assert c[TABLE2_ROWS[row]] == pytest.approx(v, rel=1e-14)


def test_hu2020_table2_eccentricity_index_is_derived_zero():
    """Row i: the printed -0.00024 is 'negligible'; gearte derives k_n = 0 exactly (linear)."""
    st = CycloidStage(**TABLE3)
    assert sensitivity_indices(st)["eccentricity_error"] == 0.0
    # the finite effect is second order and negative (always reduces the lost motion)
    d = np.array([1e-4, 1e-3, -1e-3, 5e-3])
    te = eccentricity_te(st, d)
    assert np.all(te <= 0)
    ratio = te[:3] / d[:3] ** 2
    assert ratio[1] == pytest.approx(ratio[2], rel=1e-3)  # even in delta_a
    assert ratio[0] == pytest.approx(ratio[1], rel=2e-2)  # quadratic
    # secant index at 1 um stays below the printed magnitude's order (0.024 % of g0 ~ 1e-3)
    g0 = te_gradients(st)["pin_circle_radius_error"]
    assert abs(te[0] / d[0] / g0) < 1e-2


def test_eccentricity_te_matches_brute_force_minimum():
    st = CycloidStage(**TABLE3)
    phi = np.linspace(0.05, np.pi - 0.05, 2_000_001)
    K1 = st.K1
    S = np.sqrt(1 + K1**2 - 2 * K1 * np.cos(phi))
    lr = np.sin(phi) / S
    dn = st.dr_rp - st.dr_p * (1 - K1 * np.cos(phi)) / S
    w = (K1 - np.cos(phi)) / S
    for da in (1e-3, 1e-2):
        ref = 2 * (np.min((dn + da * w) / lr) - np.min(dn / lr)) / st.r_c
        assert float(eccentricity_te(st, da)) == pytest.approx(ref, rel=1e-4)


def test_factor_contributions_signs_and_modification_backlash():
    st = CycloidStage(**TABLE3)
    c = factor_contributions(st, {})
    # A + B = twice the closing rotation Delta_n(phi0)/r_c (eq 32 geometry)
    assert c["equidistant_modification"] + c["shifted_modification"] == pytest.approx(
        2 * st.backlash_per_flank, rel=1e-12
    )
    assert c["equidistant_modification"] < 0 < c["shifted_modification"]
    one = {k: 1e-3 for k in ERROR_FACTORS if k != "eccentricity_error"}
    c1 = factor_contributions(st, one)
    g = te_gradients(st)
    for k, v in one.items():
        assert c1[k] == pytest.approx(g[k] * v, rel=1e-14)
    # negative coefficients b, g, h (Table 2) reduce the TE for positive errors
    for row in "bgh":
        assert c1[TABLE2_ROWS[row]] < 0


def test_geometric_te_mean_and_rss_tolerance():
    st = CycloidStage(**TABLE3)
    means = {"pin_radius_error": -0.002, "pin_groove_clearance": 0.004}
    tols = {k: 0.004 for k in ERROR_FACTORS}
    te = geometric_te(st, means, tols)
    assert te.mean == pytest.approx(sum(te.contributions.values()), rel=1e-14)
    g = te_gradients(st)
    linear = [abs(g[k]) * 0.004 for k in ERROR_FACTORS if k != "eccentricity_error"]
    ecc = te.tolerances["eccentricity_error"]
    assert te.tolerance == pytest.approx(math.sqrt(sum(x * x for x in linear) + ecc**2))
    assert 0 < ecc < 0.02 * max(linear)  # second order: ~1 % here, negligible as the paper says
    assert sum(te.tolerance_shares().values()) == pytest.approx(1.0)
    # eq 16-17 conversion: 180*60/pi
    assert rad_to_arcmin(te.mean) == pytest.approx(te.mean * 10800 / math.pi)


@pytest.mark.parametrize("rule", ["equal_share", "equal_change", "tolerance_weighted"])
@pytest.mark.parametrize("target_arcmin", [-1.4559, -0.3, 0.7])
def test_compensation_inverts_forward_model(rule, target_arcmin):
    st = CycloidStage(**TABLE3)
    x = {"pin_radius_error": 0.001, "cumulative_pitch_error": 0.006, "radial_runout": 0.01}
    tols = {k: 0.005 + 0.001 * i for i, k in enumerate(ERROR_FACTORS)}
    target = arcmin_to_rad(target_arcmin)
    comp = compensate(st, target, rule=rule, tolerances=tols)
    new = dict(x)
    for k, d in comp.changes.items():
        new[k] = new.get(k, 0.0) + d
    before = geometric_te(st, x).mean
    after = geometric_te(st, new).mean
    assert after - before == pytest.approx(target, rel=1e-12, abs=1e-16)
    assert sum(comp.te_changes.values()) == pytest.approx(target, rel=1e-12)


def test_compensation_equal_share_is_eq27_with_diagonal_A():
    """eq 27: delta = (pi a z_c / 10800) A^-1 dtheta[arcmin], A = diag(2 c_j)."""
    st = CycloidStage(**TABLE3)
    dtheta_arcmin = -1.4559
    comp = compensate(st, arcmin_to_rad(dtheta_arcmin), rule="equal_share")
    c = error_coefficients(st.K1)
    for k, d in comp.changes.items():
        share = dtheta_arcmin / 3
        assert d == pytest.approx(math.pi * st.a * st.z_c / 10800 * share / (2 * c[k]), rel=1e-12)


def test_compensation_rejects_bad_requests():
    st = CycloidStage(**TABLE3)
    with pytest.raises(ParameterError):
        compensate(st, 1e-4, factors=["eccentricity_error"])
    with pytest.raises(ParameterError):
        compensate(st, 1e-4, factors=["nonsense"])
    with pytest.raises(ParameterError):
        compensate(st, 1e-4, rule="inverse")
    with pytest.raises(ParameterError):
        compensate(st, 1e-4, rule="tolerance_weighted")
    with pytest.raises(ParameterError):
        geometric_te(st, {"bogus": 1.0})
