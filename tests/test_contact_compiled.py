"""The compiled tooth contact and its compiled twins against the numpy references (issue 12).

``tooth_contact`` runs one numba kernel per contact law (pin geometry, solve, forces and
pressures); ``implementation="plain"`` is the reference built from the numpy geometry of
``gearte.geometry.cycloid``, the numpy law of ``gearte.models.contact_law`` and the plain solvers.
Each compiled building block is compared with its numpy original to 1e-12 (rounding: the
compiled geometry takes sin φ, cos φ from sum formulas; the law's inverse stops on a quadratic
convergence estimate); the whole analysis to the solvers' tolerance.
"""

from __future__ import annotations

import numpy as np
import pytest

from gearte.geometry.cycloid import CycloidStage, geometry_radii
from gearte.geometry.cycloid_kernels import pin_mesh_table
from gearte.models import contact_law as cl
from gearte.models.cycloid_contact import tooth_contact
from gearte.solvers.contact import (
    log_law_force,
    log_law_force_plain,
    solve_rotation,
    solve_rotation_plain,
)

TABLE3 = dict(z_p=40, r_p=76.0, r_rp=3.0, a=1.5, b=11.0, dr_rp=-0.022, dr_p=-0.0437)
TABLE6 = dict(z_p=40, r_p=76.0, r_rp=2.9721, a=1.5, b=11.0, dr_rp=-0.022, dr_p=-0.0266)
UNMODIFIED = TABLE3 | {"dr_rp": 0.0, "dr_p": 0.0}
LI2023_NOMINAL_K1 = dict(
    z_p=40, r_p=85.8, r_rp=3.0, a=1.3, b=12.0, dr_rp=-0.01, dr_p=-0.05, k1_definition="nominal"
)
TORQUE = 1011.5e3  # N·mm, fitted to Hu 2020 Tables 4-5 (examples/hu2020_rv80e_initial.toml)
MATERIAL = dict(disc_share=0.55, E=2.06e5, mu=0.3)
E_STAR = cl.contact_modulus(2.06e5, 0.3)


def _stage_and_sweep(params, n=40):
    st = CycloidStage(**params)
    return st, np.linspace(0.0, 2 * np.pi / st.z_p, n, endpoint=False)


@pytest.mark.parametrize("params", [TABLE3, TABLE6, UNMODIFIED, LI2023_NOMINAL_K1])
def test_pin_mesh_table_equals_numpy_geometry_eq4_32_36_40(params):
    st, theta = _stage_and_sweep(params)
    theta = np.concatenate([theta, [-7.3, 13.1]])  # mesh angles outside [0, 2π) wrap the same
    R, r = geometry_radii(st.r_p, st.r_rp, st.dr_rp, st.dr_p, st.k1_definition)
    phase, lr, clr, rho = pin_mesh_table(
        theta, z_p=st.z_p, K1=st.K1, R=R, r=r, dr_rp=st.dr_rp, dr_p=st.dr_p
    )
    ref_phase = st.pin_phases(theta)
    np.testing.assert_allclose(phase, ref_phase, rtol=0, atol=1e-12)
    np.testing.assert_allclose(lr, st.normal_arm(ref_phase) / st.r_c, rtol=0, atol=1e-12)
    np.testing.assert_allclose(clr, st.initial_clearance(ref_phase), rtol=0, atol=1e-15)
    np.testing.assert_allclose(rho, st.curvature_radius(ref_phase), rtol=1e-12)


def test_line_contact_a0_scalar_equals_log_law_coefficients_to_1e12():
    rho = np.array([-43.6, -3.5, -1e4, 4.0, 47.0, 1e6, np.inf, -np.inf])
    r, b = 2.978, 11.0
    for cap in (None, 80.0):
        a0, a1 = cl.log_law_coefficients("line_contact", rho, r, 2.06e5, 0.3, b, rho_cap=cap)
        got = [
            cl.line_contact_a0_scalar(x, r, E_STAR, b, a1[0], np.inf if cap is None else cap)
            for x in rho
        ]
        finite = np.isfinite(a0)
        np.testing.assert_allclose(np.array(got)[finite], a0[finite], rtol=1e-12)
        assert np.array_equal(np.isfinite(got), finite)


def test_pressure_scalar_equals_max_contact_pressure_to_1e12():
    F = np.array([0.0, -3.0, 1.0, 1810.0, 5e4])
    rho = np.array([-43.6, 7.0, np.inf, -43.6, 120.0])
    ref = cl.max_contact_pressure(F, rho, 2.978, 2.06e5, 0.3, 11.0)
    got = [
        cl.max_contact_pressure_scalar(f, x, 2.978, E_STAR, 11.0)
        for f, x in zip(F, rho, strict=True)
    ]
    np.testing.assert_allclose(got, ref, rtol=1e-12, atol=0)


def test_log_law_inverse_compiled_equals_numpy_twin_to_1e12():
    rng = np.random.default_rng(12)
    a1 = np.full(400, 2 * (1 - 0.3**2) / (np.pi * 2.06e5 * 11.0))
    a0 = a1 * rng.uniform(8.0, 20.0, 400)
    delta = a1 * np.exp(rng.uniform(-5.0, 12.0, 400))
    delta[:20] = -np.abs(delta[:20])  # no contact: 0
    delta[20] = 0.0
    delta[21:30] = 2.0 * a1[21:30] * np.exp(a0[21:30] / a1[21:30] - 1.0)  # beyond the law: inf
    fast = log_law_force(delta, a0, a1)
    plain = log_law_force_plain(delta, a0, a1)
    assert np.array_equal(fast == 0.0, plain == 0.0) and np.array_equal(
        np.isinf(fast), np.isinf(plain)
    )
    ok = np.isfinite(plain) & (plain > 0)
    np.testing.assert_allclose(fast[ok], plain[ok], rtol=1e-12)
    np.testing.assert_allclose(  # and it inverts the law
        fast[ok] * (a0[ok] - a1[ok] * np.log(fast[ok])), delta[ok], rtol=1e-12
    )
    # the law's public inverse is the numpy one
    np.testing.assert_array_equal(cl.force_from_coefficients(delta, a0, a1), plain)


def test_solve_rotation_compiled_equals_numpy_twin_and_balances_the_torque():
    st, theta = _stage_and_sweep(TABLE3, 30)
    phase = st.pin_phases(theta)
    arm = np.where(st.normal_arm(phase) > 0, st.normal_arm(phase), 0.0)
    clr = np.where(arm > 0, st.initial_clearance(phase), 0.0)
    a0, a1 = cl.log_law_coefficients(
        "line_contact", st.curvature_radius(phase), st.r, 2.06e5, 0.3, st.b, rho_cap=80.0
    )
    T = 0.55 * TORQUE
    rot, f = solve_rotation(arm, clr, a0, a1, T, rtol=1e-12)
    rot_p, f_p = solve_rotation_plain(arm, clr, a0, a1, T, rtol=1e-12)
    np.testing.assert_allclose(rot, rot_p, rtol=1e-11)
    np.testing.assert_allclose(f, f_p, rtol=1e-8, atol=1e-8)
    np.testing.assert_allclose(np.sum(f * arm, axis=1), T, rtol=1e-10)


@pytest.mark.parametrize("law", ["hu2020", "line_contact"])
@pytest.mark.parametrize("params", [TABLE3, TABLE6, UNMODIFIED, LI2023_NOMINAL_K1])
def test_compiled_tooth_contact_equals_plain_twin_over_a_pitch(law, params):
    """Every field over 40 positions of one pitch; tolerances: the solvers' 1e-12 on F_max or
    the rotation, amplified on a pin that barely touches (force ∝ δ_i = l_i Δφ − Δ_i)."""
    st, theta = _stage_and_sweep(params)
    fast = tooth_contact(st, TORQUE, **MATERIAL, mesh_angle=theta, contact_law=law)
    plain = tooth_contact(
        st, TORQUE, **MATERIAL, mesh_angle=theta, contact_law=law, implementation="plain"
    )
    np.testing.assert_allclose(fast.F_max, plain.F_max, rtol=1e-10)
    np.testing.assert_allclose(fast.delta_max, plain.delta_max, rtol=1e-10)
    np.testing.assert_array_equal(fast.in_mesh, plain.in_mesh)
    np.testing.assert_allclose(fast.force, plain.force, rtol=1e-8, atol=1e-8)
    np.testing.assert_allclose(fast.pressure, plain.pressure, rtol=1e-8, atol=1e-4)
    np.testing.assert_allclose(fast.approach, plain.approach, rtol=1e-10, atol=1e-16)
    np.testing.assert_allclose(fast.clearance, plain.clearance, rtol=0, atol=1e-15)
    np.testing.assert_allclose(fast.curvature, plain.curvature, rtol=1e-12)
    np.testing.assert_allclose(fast.phase, plain.phase, rtol=0, atol=1e-12)
    assert fast.T_c == plain.T_c and fast.rho == plain.rho


@pytest.mark.parametrize("law", ["hu2020", "line_contact"])
def test_compiled_tooth_contact_envelope_clearances_equal_plain_twin(law):
    st, theta = _stage_and_sweep(TABLE3, 8)
    kw = dict(mesh_angle=theta, contact_law=law, clearance_model="envelope")
    fast = tooth_contact(st, TORQUE, **MATERIAL, **kw)
    plain = tooth_contact(st, TORQUE, **MATERIAL, **kw, implementation="plain")
    np.testing.assert_allclose(fast.F_max, plain.F_max, rtol=1e-10)
    np.testing.assert_array_equal(fast.in_mesh, plain.in_mesh)
    np.testing.assert_allclose(fast.force, plain.force, rtol=1e-8, atol=1e-8)


@pytest.mark.parametrize("law", ["hu2020", "line_contact"])
def test_warm_started_sweep_does_not_depend_on_the_order_of_positions(law):
    """Each position starts from the previous one's answer; the answer is the same in any
    order and equals the position solved alone (to the solvers' tolerance)."""
    st, theta = _stage_and_sweep(TABLE6, 30)
    fwd = tooth_contact(st, TORQUE, **MATERIAL, mesh_angle=theta, contact_law=law)
    rev = tooth_contact(st, TORQUE, **MATERIAL, mesh_angle=theta[::-1], contact_law=law)
    one = tooth_contact(st, TORQUE, **MATERIAL, mesh_angle=theta[17], contact_law=law)
    np.testing.assert_allclose(rev.F_max[::-1], fwd.F_max, rtol=1e-10)
    np.testing.assert_allclose(rev.force[::-1], fwd.force, rtol=1e-8, atol=1e-8)
    assert one.F_max[0] == pytest.approx(fwd.F_max[17], rel=1e-10)
