"""A measured disc in the one RV model (issue 16): the measured flank enters as a per-tooth
clearance function of the contact position."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from gearte.geometry.cycloid import normal_clearance_unclosed
from gearte.geometry.measured import MeasuredDisc, tooth_and_parameter
from gearte.io.case_file import load_case
from gearte.models.rv_load_sharing import assemble, load_sharing, output_positions
from gearte.studies.rv_reducer import build_reducer

TORQUE = 1078e3  # N·mm, the case's rated torque


@pytest.fixture(scope="module")
def design():
    return build_reducer(load_case("han2023_rv110e_no_errors").reducer)


def _with_measured(red, discs):
    return red.with_errors(dataclasses.replace(red.error_set, measured_discs=tuple(discs)))


def test_tooth_numbering_follows_the_pin_through_the_mesh():
    """One pin, the eccentric turning: each 2π of meshing phase moves the pin one tooth back."""
    tooth, phi0 = tooth_and_parameter(
        np.array([5, 5, 5]), np.array([0.1, 0.1 + 2 * np.pi, -3.0]), 39
    )
    assert tooth.tolist() == [5, 4, 5]
    np.testing.assert_allclose(phi0, [0.1, 0.1, -3.0])


def test_measured_profile_equal_to_equidistant_and_shift_reproduces_that_modification(design):
    """The design flank (no modification) with a measured deviation equal to minus the clearance
    of Δr_rp = +8 µm, Δr_p = +4 µm gives that modification's pin loads and TE.

    Entered as the discs' modification *errors* (through the clearance, as a measured flank) it
    is the same computation: equal to 1e-9. Entered as the *design's* modification it also turns
    the contact normals to the true contact point of the shifted profile (the rows' arms,
    docs/contact-law.md "Modified profiles") and changes the flank curvature by
    O(Δr_p / r_p) = 5e-5, which a measured flank does not: peak pin load −0.20 %, a pin's force
    within 1.2 % of the peak, TE within 0.03 %.
    """
    zp, zc = design.pins.count, design.cycloid_teeth
    d_rp, d_p = 0.008, 0.004
    modified = design.replace(
        discs=dataclasses.replace(
            design.discs, equidistant_modification=d_rp, shift_modification=d_p
        )
    )
    as_error = design.with_errors(
        design.error_set.with_disc_modification(np.tile([d_rp, d_p], (design.discs.count, 1)))
    )
    phi = np.linspace(-np.pi, np.pi, 2001)
    kw = dict(z_p=zp, r_p=design.pins.circle_radius, a=design.cranks.eccentricity)
    dev = -(
        normal_clearance_unclosed(phi, dr_rp=d_rp, dr_p=d_p, **kw)
        - normal_clearance_unclosed(phi, **kw)
    )
    disc = MeasuredDisc(zc, tuple([phi] * zc), tuple([dev] * zc))
    measured = _with_measured(design, [disc, disc])
    th = output_positions(24)
    b = load_sharing(measured, TORQUE, th)
    c = load_sharing(as_error, TORQUE, th)
    np.testing.assert_allclose(b.pin_force, c.pin_force, rtol=0, atol=1e-9 * c.peak_pin_load)
    np.testing.assert_allclose(b.output_error, c.output_error, rtol=1e-9)
    a = load_sharing(modified, TORQUE, th)
    assert b.peak_pin_load == pytest.approx(a.peak_pin_load, rel=3e-3)
    np.testing.assert_allclose(b.pin_force, a.pin_force, rtol=0, atol=1.5e-2 * a.peak_pin_load)
    np.testing.assert_allclose(b.output_error, a.output_error, rtol=1e-3)
    np.testing.assert_array_equal(b.pairs_in_mesh, a.pairs_in_mesh)


def test_local_bump_on_one_tooth_raises_the_load_of_the_pins_touching_it(design):
    """+4 µm of material over φ0 ∈ [-80°, -40°] (the flank a positive torque loads) of tooth
    space 10 of disc 1: the pins in contact there carry more, the others of that disc carry less
    on average."""
    zp, zc = design.pins.count, design.cycloid_teeth
    phi = np.radians(np.arange(-180.0, 181.0, 2.0))
    bump = np.where((phi > np.radians(-80)) & (phi < np.radians(-40)), 0.004, 0.0)
    flat = np.zeros_like(phi)
    disc = MeasuredDisc(zc, tuple([phi] * zc), tuple(bump if t == 9 else flat for t in range(zc)))
    red = _with_measured(design, [disc, None])
    th = output_positions(360)
    base = load_sharing(design, TORQUE, th)
    bumped = load_sharing(red, TORQUE, th)
    system = assemble(design, th)
    tooth, phi0 = tooth_and_parameter(
        system.contact_pin[None, :zp], system.contact_phase[:, :zp], zc
    )
    on_bump = (tooth == 9) & (phi0 > np.radians(-75)) & (phi0 < np.radians(-45))
    loaded = on_bump & (base.pin_force[:, 0, :] > 0)
    assert loaded.sum() >= 3
    df = bumped.pin_force[:, 0, :] - base.pin_force[:, 0, :]
    assert np.all(df[loaded] > 0.0)
    assert df[loaded].mean() > 100.0  # N: 4 µm of interference at ~1e5 N/mm contact stiffness
    rows = np.any(loaded, axis=1)
    others = (base.pin_force[:, 0, :] > 0) & ~on_bump & rows[:, None]
    assert df[others].mean() < 0.0


def test_measured_pitch_per_tooth_matches_the_one_sine_pitch_error(design):
    """A cumulative pitch measured per tooth, sampled from the one-sine pitch error of
    Hu 2020 (``s(ψ) = ΔF_p/2 sin(ψ − angle)``, 12 µm at 40°) at each tooth's root, gives that
    error's TE: the two differ only in where along a tooth the sine is read (the contact point
    against the tooth root, ≤ half a tooth pitch): 2.6 % of the error's TE peak-to-peak here,
    asserted within 4 %."""
    zc = design.cycloid_teeth
    fp, ang = 0.012, np.radians(40.0)
    err = design.error_set
    pitch = err.disc_pitch.copy()
    pitch[0] = fp * np.array([np.cos(ang), np.sin(ang)])
    sine = design.with_errors(dataclasses.replace(err, disc_pitch=pitch))
    psi = 2 * np.pi * np.arange(zc) / zc
    disc = MeasuredDisc(zc, cumulative_pitch=0.5 * fp * np.sin(psi - ang))
    measured = _with_measured(design, [disc, None])
    th = output_positions(72)
    base = load_sharing(design, TORQUE, th).output_error
    a = load_sharing(sine, TORQUE, th).output_error - base
    b = load_sharing(measured, TORQUE, th).output_error - base
    assert np.ptp(a) > 1e-5  # rad: the error shows in the TE
    np.testing.assert_allclose(b, a, rtol=0, atol=0.04 * np.ptp(a))
