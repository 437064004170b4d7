"""Cycloid geometry of Hu et al. 2020 (Table 3, eq 1–4, 32–34, 40) and its envelope check."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.optimize import brentq, minimize_scalar

from gearte.errors import ParameterError
from gearte.geometry.cycloid import (
    CycloidStage,
    curvature_radius,
    envelope_clearance,
    initial_clearance,
    profile_xy,
    short_width_coefficient,
    theoretical_profile_xy,
)

# Table 3 (initial prototype) and Table 6 (modified prototype)
TABLE3 = dict(z_p=40, r_p=76.0, r_rp=3.0, a=1.5, b=11.0, dr_rp=-0.022, dr_p=-0.0437)
TABLE6 = dict(z_p=40, r_p=76.0, r_rp=2.9721, a=1.5, b=11.0, dr_rp=-0.022, dr_p=-0.0266)


def test_hu2020_table3_short_width_coefficient():
    # Table 3 prints K1 = 0.78993 (5 decimals) -> half a unit of the last digit
    st = CycloidStage(**TABLE3)
    assert st.K1 == pytest.approx(0.78993, abs=5e-6)
    assert short_width_coefficient(40, 76.0, 1.5, -0.0437) == pytest.approx(0.789928, abs=5e-7)
    assert st.z_c == 39


def test_hu2020_table6_short_width_coefficient():
    # Table 6 prints 0.7898 (4 decimals): 1.5*40/(76-0.0266) = 0.78975
    assert CycloidStage(**TABLE6).K1 == pytest.approx(0.7898, abs=5e-5)


def test_root_and_tip_radius_match_profile():
    st = CycloidStage(**TABLE3)
    assert st.root_radius == pytest.approx(71.4783, abs=1e-10)
    assert st.tip_radius == pytest.approx(74.4783, abs=1e-10)
    phi = np.linspace(0.0, 2 * np.pi * st.z_c, 200001)
    x, y = st.profile_xy(phi)
    rad = np.hypot(x, y)
    assert rad.min() == pytest.approx(st.root_radius, abs=1e-9)
    assert rad.max() == pytest.approx(st.tip_radius, abs=1e-6)


def test_profile_closes_after_z_c_teeth_and_is_periodic_per_tooth():
    st = CycloidStage(**TABLE3)
    x0, y0 = st.profile_xy(0.3)
    x1, y1 = st.profile_xy(0.3 + 2 * np.pi * st.z_c)
    assert (x0, y0) == pytest.approx((x1, y1), abs=1e-9)
    # one tooth later: same radius, rotated by 2*pi/z_c
    xa, ya = st.profile_xy(1.1)
    xb, yb = st.profile_xy(1.1 + 2 * np.pi)
    assert math.hypot(xa, ya) == pytest.approx(math.hypot(xb, yb), abs=1e-9)
    ang = math.atan2(ya, xa) - math.atan2(yb, xb)
    assert abs(math.remainder(ang, 2 * np.pi / st.z_c)) < 1e-9


def test_curvature_radius_eq40_matches_numerical_curvature():
    st = CycloidStage(**TABLE3)
    phi = np.array([0.3, st.phi0, 1.2, 2.0])
    h = 1e-3
    x, y = st.profile_xy(phi)
    xp, yp = st.profile_xy(phi + h)
    xm, ym = st.profile_xy(phi - h)
    dx, dy = (xp - xm) / (2 * h), (yp - ym) / (2 * h)
    ddx, ddy = (xp - 2 * x + xm) / h**2, (yp - 2 * y + ym) / h**2
    rho_num = (dx**2 + dy**2) ** 1.5 / (dx * ddy - dy * ddx)
    rho = st.curvature_radius(phi)
    # the profile runs clockwise as phi grows, so the signed curvature has eq 40's sign:
    # convex (the working flank near phi0) < 0, concave (around the root) > 0
    np.testing.assert_allclose(np.abs(rho), np.abs(rho_num), rtol=2e-4)  # O(h^2) of the FD
    np.testing.assert_array_equal(np.sign(rho), np.sign(rho_num))
    # eq 40 at phi0 reduces to -R sqrt(1-K1^2) + r
    R, r, K1 = st.R, st.r, st.K1
    assert st.rho0 == pytest.approx(-R * math.sqrt(1 - K1**2) + r, rel=1e-12)
    assert curvature_radius(st.phi0, z_p=40, r_p=76, r_rp=3, a=1.5, dr_rp=-0.022, dr_p=-0.0437) == (
        pytest.approx(st.rho0)
    )


def test_eq32_zero_at_phi0_and_nonnegative_on_loaded_flank():
    st = CycloidStage(**TABLE3)
    assert st.phi0 == pytest.approx(math.acos(st.K1))
    assert float(st.initial_clearance(st.phi0)) == pytest.approx(0.0, abs=1e-15)
    phi = np.linspace(1e-3, np.pi - 1e-3, 1000)
    assert np.all(st.initial_clearance(phi) >= -1e-15)
    # root and tip: the radial clearance dr_rp - dr_p
    assert float(st.initial_clearance(0.0)) == pytest.approx(0.0217, abs=1e-12)
    assert float(st.initial_clearance(np.pi)) == pytest.approx(0.0217, abs=1e-12)


def _envelope_gaps(st: CycloidStage, beta: float, theta: float, **mods) -> np.ndarray:
    """Gap [mm] between every nominal pin and the modified profile, disc turned by beta.

    Explicit construction: the nominal pins (radius r_rp on the circle r_p) are placed in the
    disc frame on the pin-centre path of the *unmodified* stage, rotated by -beta, and the
    minimum distance from each pin centre to the modified profile curve (eq 1-3) is found by a
    bounded scalar minimisation over the profile parameter.
    """
    zp, zc = st.z_p, st.z_c
    c, s = math.cos(-beta), math.sin(-beta)
    kw = dict(z_p=zp, r_p=st.r_p, r_rp=st.r_rp, a=st.a, dr_rp=st.dr_rp, dr_p=st.dr_p) | mods
    out = np.empty(zp)
    for i in range(zp):
        t = theta + 2 * np.pi * ((-i) % zp) * zc / zp  # pin i has meshing phase theta + 2 pi i/z_p
        px, py = theoretical_profile_xy(t, z_p=zp, R=st.r_p, a=st.a)
        qx, qy = c * px - s * py, s * px + c * py

        def dist(p, qx=qx, qy=qy):
            x, y = profile_xy(p, **kw)
            return math.hypot(x - qx, y - qy)

        res = minimize_scalar(
            dist, bounds=(t - 0.3, t + 0.3), method="bounded", options={"xatol": 1e-12}
        )
        out[i] = res.fun - st.r_rp
    return out


@pytest.mark.parametrize(
    "params",
    [TABLE3, dict(z_p=12, r_p=40.0, r_rp=3.0, a=2.0, b=10.0, dr_rp=0.01, dr_p=-0.01)],
    ids=["hu2020_table3", "z12_positive_equidistant"],
)
def test_eq32_initial_clearance_against_envelope(params):
    """Eq 32 against an explicit envelope construction of the modified profile.

    The disc is turned until the first loaded-flank pin touches (bisection on the rotation); the
    remaining gaps must equal eq 32. Eq 32 is first order in the modifications: its error is of
    the order (|dr_rp| + |dr_p|)^2 / |rho(phi0)| in the working zone (phi >= phi0; bound: 3
    times that), where the profile curvature radius is large; near the root the pin-centre path
    is sharply curved (radius ~0.1 mm for Table 3) and the first-order formula deviates by up to
    ~1.7 um (see docs/validation/hu2020.md), which is checked separately with a looser bound.
    """
    st = CycloidStage(**params)
    theta = st.phi0 - 2 * np.pi * 4 / st.z_p  # pin 5 sits at phi0, where first contact closes
    phi = st.pin_phases(theta)
    loaded = np.sin(phi) > 1e-9
    b0 = st.backlash_per_flank
    w = 0.2 * abs(b0) + 2e-6
    beta = brentq(
        lambda b: np.min(_envelope_gaps(st, b, theta)[loaded]), b0 - w, b0 + w, xtol=1e-15
    )
    # the closing rotation is Delta_n(phi0)/r_c to first order
    scale = (abs(st.dr_rp) + abs(st.dr_p)) ** 2 / abs(st.rho0)
    assert beta == pytest.approx(b0, abs=2 * scale / st.r_c)
    gaps = _envelope_gaps(st, beta, theta)
    eq32 = st.initial_clearance(phi)
    work = loaded & (phi >= st.phi0 - 1e-9)
    assert np.max(np.abs(gaps[work] - eq32[work])) <= 3 * scale
    assert np.max(np.abs(gaps[loaded] - eq32[loaded])) <= 0.1 * np.max(eq32[loaded])
    # the pin at phi0 touches, every loaded pin has a non-negative gap
    assert np.min(gaps[loaded]) == pytest.approx(0.0, abs=1e-10)
    # gearte's vectorised envelope (Newton foot points) equals this explicit construction
    np.testing.assert_allclose(envelope_clearance(st, theta)[0][loaded], gaps[loaded], atol=1e-9)


def test_rotation_modification_leaves_eq32_unchanged_and_opens_both_flanks():
    st = CycloidStage(**TABLE3)
    theta = 0.0
    g0 = _envelope_gaps(st, 0.0, theta)
    rot = 1e-4
    phi = st.pin_phases(theta)
    arm = np.abs(st.normal_arm(phi))
    for flank, side in ((1, np.sin(phi) > 0.2), (-1, np.sin(phi) < -0.2)):
        g1 = _envelope_gaps(st, 0.0, theta, rotation=rot, flank=flank)
        np.testing.assert_allclose((g1 - g0)[side], arm[side] * rot, rtol=0.05)
    st_rot = CycloidStage(**TABLE3, rotation=rot)
    np.testing.assert_allclose(st_rot.initial_clearance(phi), st.initial_clearance(phi))
    assert st_rot.backlash_per_flank == pytest.approx(st.backlash_per_flank + rot)


def test_initial_clearance_function_matches_method():
    st = CycloidStage(**TABLE3)
    phi = np.linspace(0.1, 3.0, 7)
    np.testing.assert_allclose(
        initial_clearance(phi, z_p=40, r_p=76.0, a=1.5, dr_rp=-0.022, dr_p=-0.0437),
        st.initial_clearance(phi),
    )


@pytest.mark.parametrize(
    ("changes", "field"),
    [
        (dict(a=2.0), "K1"),  # K1 = 80/76 > 1
        (dict(z_c=38), "z_c"),
        (dict(dr_rp=-0.05, dr_p=0.0), "dr_rp/dr_p"),  # negative equidistant alone interferes
        (dict(dr_rp=0.0, dr_p=0.02), "dr_rp/dr_p"),  # positive shift alone interferes
        (dict(b=-1.0), "b"),
        (dict(r_rp=float("nan")), "r_rp"),
        (dict(r_rp=5.9), "r_rp"),  # pins overlap: r_p sin(pi/z_p) = 5.96 -> fine; undercut
        (dict(a=1.85), "r_rp"),  # K1 ~ 0.974: convex curvature radius below the pin radius
        (dict(z_p=40.5), "z_p"),
        (dict(rotation=0.2), "rotation"),
    ],
)
def test_stage_rejects_bad_parameters(changes, field):
    with pytest.raises(ParameterError) as exc:
        CycloidStage(**(TABLE3 | changes))
    assert exc.value.field == field


def test_paper_modified_prototype_has_negative_nominal_backlash_but_is_accepted():
    # Table 6 compensates positive errors with a preloaded nominal design: Delta_n(phi0) < 0
    st = CycloidStage(**TABLE6)
    assert st.backlash_per_flank < 0
