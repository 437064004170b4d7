"""Curvature and moment arm at the true contact point of a modified cycloid profile, against a
fine numerical envelope (docs/contact-law.md, "Modified profiles")."""

from __future__ import annotations

import numpy as np
import pytest

from gearte.geometry.cycloid import CycloidStage, profile_xy, true_contact
from gearte.models.contact_law import max_contact_pressure

# Hu 2020 Table 3's modified stage (the CycloidStage docstring's example)
STAGE = CycloidStage(z_p=40, r_p=76.0, r_rp=3.0, a=1.5, b=11.0, dr_rp=-0.022, dr_p=-0.0437)
E, NU, F = 2.06e5, 0.3, 1500.0


def _envelope_contact(phi: float) -> tuple[float, float]:
    """(signed curvature radius [mm], arm [mm]) of the ground profile where the real pin at phase
    φ touches it, from a dense polyline of the profile (eq 1–2 with the ground radii, 0.3 µm
    spacing): the point nearest the real pin's centre, and a least-squares circle through the
    polyline within ±0.06 mm of it."""
    s = STAGE
    i_h = s.z_p / (s.z_p - 1.0)
    # real pin centre in the disc frame (pin circle r_p, unmodified)
    cx = s.r_p * np.cos((1 - i_h) * phi) - s.a * np.cos(i_h * phi)
    cy = s.r_p * np.sin((1 - i_h) * phi) + s.a * np.sin(i_h * phi)
    t = phi + np.radians(np.linspace(-6.0, 6.0, 400_001))
    x, y = profile_xy(t, **s._profile_kw)
    d = np.hypot(x - cx, y - cy)
    k = int(np.argmin(d))
    ds = np.hypot(np.diff(x[k - 1 : k + 1]), np.diff(y[k - 1 : k + 1])).mean()
    w = max(20, int(0.06 / ds))
    px, py = x[k - w : k + w + 1], y[k - w : k + w + 1]
    # algebraic circle fit x² + y² + D x + E y + G = 0 (Kåsa), centred for conditioning
    ox, oy = px.mean(), py.mean()
    u, v = px - ox, py - oy
    A = np.stack([u, v, np.ones_like(u)], 1)
    D, Ec, G = np.linalg.lstsq(A, -(u * u + v * v), rcond=None)[0]
    xc, yc = -D / 2 + ox, -Ec / 2 + oy
    radius = np.sqrt((D * D + Ec * Ec) / 4 - G)
    qx, qy = x[k], y[k]
    # convex (ρ < 0) where the circle's centre lies on the disc's side (away from the pin)
    convex = (xc - qx) * (cx - qx) + (yc - qy) * (cy - qy) < 0.0
    rho = -radius if convex else radius
    nx, ny = (cx - qx) / d[k], (cy - qy) / d[k]
    return float(rho), float(cx * ny - cy * nx)


@pytest.mark.parametrize("phi_deg", [8.0, 15.0, 25.0, 37.8, 60.0, 100.0])
def test_true_contact_pressure_and_arm_match_fine_envelope(phi_deg):
    """Hertz peak pressure with the curvature at the true contact point within 0.5 % of the
    fine envelope's; the arm within 0.5 %. (At φ it was up to 2 % low near the root.)"""
    phi = np.radians(phi_deg)
    rho_env, arm_env = _envelope_contact(phi)
    rho_true = float(STAGE.contact_curvature_radius(phi))
    _, arm_true, _ = true_contact(phi, z_p=40, r_p=76.0, a=1.5, dr_p=-0.0437)
    p_env = max_contact_pressure(F, rho_env, STAGE.r_rp, E, NU, STAGE.b)
    p_true = max_contact_pressure(F, rho_true, STAGE.r_rp, E, NU, STAGE.b)
    assert p_true == pytest.approx(p_env, rel=5e-3)
    assert float(arm_true) == pytest.approx(arm_env, rel=5e-3)


def test_curvature_at_phi_is_off_where_the_true_contact_moved():
    """The fix is needed: at φ = 15° the curvature at φ (not at the true point) gives a peak
    pressure more than 0.5 % from the envelope's, and the unmodified arm (eq 36) is > 5 % off."""
    phi = np.radians(15.0)
    rho_env, arm_env = _envelope_contact(phi)
    p_env = max_contact_pressure(F, rho_env, STAGE.r_rp, E, NU, STAGE.b)
    p_phi = max_contact_pressure(F, STAGE.curvature_radius(phi), STAGE.r_rp, E, NU, STAGE.b)
    assert abs(p_phi / p_env - 1.0) > 5e-3
    assert abs(STAGE.normal_arm(phi) / arm_env - 1.0) > 0.05


def test_true_contact_is_phi_without_shift():
    phi = np.radians([5.0, 40.0, 120.0])
    t, arm, turn = true_contact(phi, z_p=40, r_p=76.0, a=1.5, dr_p=0.0)
    np.testing.assert_array_equal(t, phi)
    np.testing.assert_allclose(arm, STAGE.normal_arm(phi) * 0 + 1.5 * 39 * np.sin(phi)
                               / np.sqrt(1 + (60 / 76) ** 2 - 2 * (60 / 76) * np.cos(phi)),
                               rtol=1e-12)  # fmt: skip
    np.testing.assert_allclose(turn, 0.0, atol=1e-15)


@pytest.fixture(scope="module")
def hu2020_reducer():
    from gearte.io.case_file import load_case
    from gearte.studies.rv_reducer import build_reducer

    # Hu 2020 Table 3's modified stage as a whole reducer (Δr_rp = −0.022, Δr_p = −0.0437 mm)
    return build_reducer(load_case("hu2020_rv80e_initial_reducer").reducer)


def _row_arms(reducer, theta):
    """(P, N, z_p) rotation column of the RV contact rows (the arm of each pin's normal)."""
    from gearte.models.rv_load_sharing import assemble

    s = assemble(reducer, theta)
    N, zp = reducer.discs.count, reducer.pins.count
    d = [s.layout.disc(j) + 2 for j in range(N)]
    return np.stack([s.contact_B[:, j * zp : (j + 1) * zp, d[j]] for j in range(N)], 1), s


def test_rv_rows_take_the_arm_at_the_true_contact_point(hu2020_reducer):
    """On the Hu 2020 modified stage the RV rows' arm of every pin equals ``true_contact``'s
    (the envelope-tested arm above) to 1e-9 mm, and differs from eq 36's near the root."""
    red = hu2020_reducer
    assert red.discs.shift_modification == pytest.approx(-0.0437)
    theta = np.linspace(0.0, 2 * np.pi / 39, 5)
    arms, s = _row_arms(red, theta)
    phase = s.contact_phase.reshape(arms.shape)
    kw = {"z_p": red.pins.count, "r_p": red.pins.circle_radius, "a": red.cranks.eccentricity}
    _, arm_true, _ = true_contact(phase, dr_p=red.discs.shift_modification, **kw)
    np.testing.assert_allclose(arms, arm_true, rtol=0.0, atol=1e-9)
    _, arm_36, _ = true_contact(phase, dr_p=0.0, **kw)  # eq 36 (no shift)
    assert np.max(np.abs(arms - arm_36)) > 1.0  # mm: the turn matters near the root


def test_rv_rows_do_not_depend_on_a_discs_modification_error(hu2020_reducer):
    """The rows (normals and arms) are the design's: a disc's modification error moves only
    the clearances, so the batched yield can share the rows across its samples."""
    red = hu2020_reducer
    theta = np.linspace(0.0, 0.1, 3)
    errs = np.zeros((red.discs.count, 2))
    errs[0] = (0.004, -0.006)  # δΔr_rp, δΔr_p of disc 1 [mm]
    off = red.with_errors(red.error_set.with_disc_modification(errs))
    arms0, s0 = _row_arms(red, theta)
    arms1, s1 = _row_arms(off, theta)
    np.testing.assert_array_equal(s1.contact_B, s0.contact_B)
    assert np.max(np.abs(s1.contact_gap - s0.contact_gap)) > 1e-3


def test_rv_rows_keep_eq36_without_shift(hu2020_reducer):
    """Without a shifted modification the rows' arm is eq 36's (the normal through the pitch
    point), whatever the equidistant modification."""
    import dataclasses

    red = hu2020_reducer
    red0 = red.replace(discs=dataclasses.replace(red.discs, shift_modification=0.0))
    theta = np.linspace(0.0, 0.1, 3)
    arms, s = _row_arms(red0, theta)
    phase = s.contact_phase.reshape(arms.shape)
    arm_36 = CycloidStage(
        z_p=red.pins.count, r_p=red.pins.circle_radius, r_rp=red.pins.pin_radius,
        a=red.cranks.eccentricity, b=STAGE.b,
    ).normal_arm(phase)  # fmt: skip
    np.testing.assert_allclose(arms, arm_36, rtol=0.0, atol=1e-9)


def test_peak_pin_force_angle_is_that_of_the_rows_normal(hu2020_reducer):
    """The root-squeeze check reads the angle between the peak pin's force (the rows' normal,
    turned to the true contact point) and the radial direction through the pin."""
    from gearte.geometry.rv import pin_contacts
    from gearte.models.rv_load_sharing import load_sharing, output_positions, peak_pin

    red = hu2020_reducer
    th = output_positions(12)
    pk = peak_pin(red, load_sharing(red, red.rated_torque, th))
    n = pin_contacts(red, th[pk.position : pk.position + 1]).normal[0, pk.disc - 1, pk.pin - 1]
    al = 2.0 * np.pi * (pk.pin - 1) / red.pins.count
    expected = np.arccos(abs(n[0] * np.cos(al) + n[1] * np.sin(al)))
    assert pk.force_angle_from_radial == pytest.approx(expected, abs=1e-9)
    k1 = red.cranks.eccentricity * red.pins.count / red.pins.circle_radius
    s = np.sqrt(1 + k1 * k1 - 2 * k1 * np.cos(pk.phase))
    eq36 = np.arcsin(k1 * abs(np.sin(pk.phase)) / s)
    assert abs(pk.force_angle_from_radial - eq36) > 1e-4  # the turn is seen


def test_true_contact_normal_passes_through_the_pin_centre():
    """The Newton root (exact derivative): the ground profile's normal at t goes through the real
    pin's centre, to float precision, over a whole tooth pitch and both signs of Δr_p."""
    from gearte.geometry.cycloid import _centre_path

    phi = np.linspace(-np.pi, np.pi, 721)
    for dr_p in (-0.0437, 0.03):
        t, _, _ = true_contact(phi, z_p=40, r_p=76.0, a=1.5, dr_p=dr_p)
        cx, cy, _, _ = _centre_path(phi, 76.0, 1.5, 40)
        x, y, nx, ny = _centre_path(t, 76.0 + dr_p, 1.5, 40)
        assert np.max(np.abs((cx - x) * ny - (cy - y) * nx)) < 1e-11  # [mm]
        assert np.max(np.abs(t - phi)) > 1e-3  # the contact did move


def test_true_contact_remembered_answers_are_fresh_arrays_of_the_callers_shape():
    """Repeated phases are answered from memory: the same values, in the caller's shape, and
    arrays the caller may change without changing the next answer."""
    from gearte.geometry.cycloid import _REMEMBER_UP_TO

    phi = np.linspace(0.1, 0.9, 12).reshape(3, 4)
    kw = {"z_p": 40, "r_p": 76.0, "a": 1.5, "dr_p": -0.0437}
    first = true_contact(phi, **kw)
    assert all(v.shape == (3, 4) for v in first)
    expect = [v.copy() for v in first]
    for v in first:
        v[...] = np.nan  # the caller scribbles on its copy
    again = true_contact(phi.ravel(), **kw)  # same phases, another shape
    for v, e in zip(again, expect, strict=True):
        assert v.shape == (12,)
        np.testing.assert_array_equal(v, e.ravel())
    big = np.linspace(-3.0, 3.0, _REMEMBER_UP_TO + 1)  # above the size that is remembered
    t_big = true_contact(big, **kw)[0]
    np.testing.assert_array_equal(t_big[:1], true_contact(big[:1], **kw)[0])
