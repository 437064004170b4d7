"""Paper 004 (Li et al. 2023) section 2 / Fig 9: loaded contact of the cycloid–pin pair.

Paper values (section 4.1, 450 N·m output → 225 N·m per disc): unmodified β ≈ 31.9° (31.5–32.1°
over the mesh period), k_cr ≈ 1.24e9 N/m; modified (Δr_p = −0.05, Δr_rp = −0.01 mm) β = 3.8°,
k_cr = 2.62e8 N/m (ratio 0.21). The tests assert gearte's values with the documented deviations
(β 32.833°, +0.93°; ratio 0.2322, +10 %); the absolute k_cr and the modified β do not reproduce
(docs/validation/li2023.md).
"""

import dataclasses

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from gearte.errors import ParameterError
from gearte.models.cycloid_loaded_contact import (
    CycloidPinPair,
    fourier_eval,
    fourier_fit,
    hertz_line_deflection,
    hertz_line_force,
    loaded_contact,
    mesh_period_contact,
    modification_clearance,
    pin_geometry,
    profile_curvature_radius,
)
from li2023_data import li2023_pair

LI2023_PAIR = li2023_pair()  # Table 1, from examples/li2023_rv_unmodified.toml
LI2023_PAIR_MODIFIED = li2023_pair(modified=True)  # section 4.1, examples/li2023_rv.toml
STEEL = dict(youngs_modulus_MPa=2.06e5, poisson_ratio=0.3)

T_DISC = 225e3  # N·mm per disc


@pytest.fixture(scope="module")
def unmod():
    return mesh_period_contact(LI2023_PAIR, T_DISC, 48)


@pytest.fixture(scope="module")
def mod():
    return mesh_period_contact(LI2023_PAIR_MODIFIED, T_DISC, 48)


def test_li2023_fig9_unmodified_pressure_angle(unmod):
    """Fig 9: mean equivalent pressure angle 31.9° (unmodified). gearte: 32.833°, documented
    deviation +0.93° (docs/validation/li2023.md); tolerance 1e-3° (48 positions, converged
    contact)."""
    beta = np.degrees(unmod.pressure_angle_mean)
    assert beta == pytest.approx(32.833, abs=1e-3)
    # small ripple over the mesh period, as Fig 9 (31.5–32.1°)
    assert np.ptp(np.degrees(unmod.pressure_angle)) < 1.0
    # every pin of the loaded flank carries load without modification
    assert set(np.unique(unmod.pins_in_contact)) <= {19, 20}


def test_li2023_fig9_stiffness_ratio(unmod, mod):
    """Paper: k_cr 2.62e8 / 1.24e9 N/m = 0.211 (modified / unmodified). gearte: 0.2322,
    documented deviation +10 %; tolerance 1e-4 (converged contact at 48 positions)."""
    ratio = mod.mesh_stiffness_mean / unmod.mesh_stiffness_mean
    assert ratio == pytest.approx(0.2322, abs=1e-4)
    # the modification concentrates load on a few pins near φ0 and lowers β
    assert mod.pins_in_contact.max() < 10
    assert np.degrees(mod.pressure_angle_mean) < 15.0
    assert np.max(mod.max_force) > 2 * np.max(unmod.max_force)


def test_uniform_stiffness_limit_atan_2_over_pi():
    """With a load-independent pin stiffness, F_i ∝ l_i and β → atan(2/π) for many pins."""
    pair = CycloidPinPair(
        pin_count=400,
        pin_radius_mm=3.0,
        pin_circle_radius_mm=858.0,
        eccentricity_mm=1.3,
        face_width_mm=12.0,
        **STEEL,
    )
    phi = (np.arange(400) + 0.5) * 2 * np.pi / 400
    arm, S = pin_geometry(pair, phi)
    f = np.where(arm > 0, arm, 0.0)
    ft = np.sum(f * arm) / pair.pitch_radius_mm
    fr = np.sum(f * np.abs(pair.K1 - np.cos(phi)) / S)
    limit = np.degrees(np.arctan(2 / np.pi))
    assert np.degrees(np.arctan2(fr, ft)) == pytest.approx(limit, abs=0.05)


def test_equilibrium_and_compatibility():
    c = loaded_contact(LI2023_PAIR_MODIFIED, T_DISC, [0.0, 0.05, 0.1])
    torque = np.sum(c.force * np.where(c.arm > 0, c.arm, 0.0), axis=1)
    np.testing.assert_allclose(torque, T_DISC, rtol=1e-9)
    # compatibility: pins in contact deflect by (Δφ − φ_bl) l, which the Hertz law maps to F
    rho = profile_curvature_radius(LI2023_PAIR_MODIFIED, c.phi)
    delta = (c.rotation[:, None] - c.backlash) * c.arm
    m = c.in_contact
    np.testing.assert_allclose(
        hertz_line_deflection(LI2023_PAIR_MODIFIED, c.force[m], rho[m]), delta[m], rtol=1e-9
    )
    assert np.all(delta[~m & (c.arm > 1e-6)] <= 1e-15)
    # reading A of eq 7 reproduces the quasi-static torsional stiffness exactly
    rc = LI2023_PAIR.pitch_radius_mm
    np.testing.assert_allclose(
        c.mesh_stiffness * rc**2 * np.cos(c.pressure_angle) ** 2, c.torsional_stiffness, rtol=1e-9
    )


def test_hertz_inverse_roundtrip():
    rho = np.array([3.6, 20.0, -65.0, -6.0, np.inf])
    f = np.array([10.0, 300.0, 2000.0, 50.0, 5000.0])
    d = hertz_line_deflection(LI2023_PAIR, f, rho)
    assert np.all(d > 0)
    np.testing.assert_allclose(hertz_line_force(LI2023_PAIR, d, rho), f, rtol=1e-10)
    assert hertz_line_force(LI2023_PAIR, np.array([0.0, -1e-3]), np.array([10.0, 10.0])).sum() == 0


def test_curvature_inflection_and_cap():
    phi = np.linspace(0.01, np.pi - 0.01, 2000)
    rho = profile_curvature_radius(LI2023_PAIR, phi)
    flip = phi[np.argmax(np.diff(np.sign(rho)) != 0)]
    assert np.degrees(flip) == pytest.approx(50.8, abs=0.2)
    # the cap keeps the pin stiffness finite and positive through the inflection
    d = hertz_line_deflection(LI2023_PAIR, 1000.0, rho)
    assert np.all(np.isfinite(d)) and np.all(d > 0)


def test_modification_clearance_sign():
    phi = np.linspace(0.01, np.pi - 0.01, 500)
    gap = modification_clearance(LI2023_PAIR_MODIFIED, phi)
    assert gap.min() >= -1e-12
    assert modification_clearance(
        LI2023_PAIR_MODIFIED, np.arccos(LI2023_PAIR_MODIFIED.K1)
    ) == pytest.approx(0.0, abs=1e-15)
    with pytest.raises(ParameterError, match="interferes"):
        dataclasses.replace(
            LI2023_PAIR, pin_radius_modification_mm=0.01, pin_position_modification_mm=0.05
        )


def test_stiffness_and_angle_grow_with_load():
    loads = [20e3, 100e3, 225e3, 450e3]
    k = [mesh_period_contact(LI2023_PAIR_MODIFIED, t, 16).mesh_stiffness_mean for t in loads]
    b = [mesh_period_contact(LI2023_PAIR_MODIFIED, t, 16).pressure_angle_mean for t in loads]
    assert np.all(np.diff(k) > 0) and np.all(np.diff(b) > 0)


def test_fourier_fit_roundtrip(mod):
    mean, a, b = fourier_fit(mod.mesh_stiffness, 12)
    s = 2 * np.pi * np.arange(48) / 48
    assert mean == pytest.approx(mod.mesh_stiffness_mean, rel=1e-12)
    rec = fourier_eval(mean, a, b, s)
    assert np.max(np.abs(rec - mod.mesh_stiffness)) < 0.1 * np.ptp(mod.mesh_stiffness)
    with pytest.raises(ParameterError):
        fourier_fit(mod.mesh_stiffness, 30)


def test_bad_torque():
    with pytest.raises(ParameterError, match="torque_Nmm"):
        loaded_contact(LI2023_PAIR, -5.0)


@settings(max_examples=25, deadline=None)
@given(
    torque=st.floats(1e3, 1e6),
    drr=st.floats(-0.02, 0.0),
    drp=st.floats(-0.1, 0.0),
    pos=st.floats(0.0, 2 * np.pi / 40),
)
def test_equilibrium_property(torque, drr, drp, pos):
    try:
        pair = dataclasses.replace(
            LI2023_PAIR, pin_radius_modification_mm=drr, pin_position_modification_mm=drp
        )
    except ParameterError:
        return  # interfering modification, rejected on construction
    c = loaded_contact(pair, torque, pos)
    moment = np.sum(c.force * np.where(c.arm > 0, c.arm, 0.0))
    assert moment == pytest.approx(torque, rel=1e-8)
    assert c.pins_in_contact[0] >= 1
    assert 0.0 < c.pressure_angle[0] < np.radians(45.0)
    assert c.mesh_stiffness[0] > 0


def test_pair_without_geometry_or_material_is_an_error_naming_it():
    """No paper data as code defaults (issue 11): Li's Table 1 pair lives in the bundled cases."""
    with pytest.raises(TypeError, match="face_width_mm"):
        CycloidPinPair(
            pin_count=40, pin_radius_mm=3.0, pin_circle_radius_mm=85.8, eccentricity_mm=1.3, **STEEL
        )
    with pytest.raises(TypeError, match="youngs_modulus_MPa"):
        CycloidPinPair(
            pin_count=40,
            pin_radius_mm=3.0,
            pin_circle_radius_mm=85.8,
            eccentricity_mm=1.3,
            face_width_mm=12.0,
            poisson_ratio=0.3,
        )
