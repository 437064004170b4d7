"""Palmgren's line-contact law, the required ``contact_law`` key, the root-squeeze warning and the
near-conformal refusal of Johnson's line contact (docs/contact-law.md)."""

from __future__ import annotations

import copy
import dataclasses
import tomllib

import numpy as np
import pytest

from gearte import load_case
from gearte.cases import case_path
from gearte.errors import CaseFileError, ParameterError
from gearte.models import contact_law as cl
from gearte.models.rv_load_sharing import (
    CONFORMAL_HALF_WIDTH_LIMIT,
    assemble,
    contact_law,
    load_sharing,
    output_positions,
    peak_pin,
    pin_series_compliance,
)
from gearte.solvers.rv_batch import solve_positions as solve_batched
from gearte.studies.rv_reducer import build_reducer

# Hu 2020 Table 3 stage at φ0 (docs/contact-law.md), steel
KW = dict(rho=-43.598, r=2.978, E=2.06e5, nu=0.3, b=11.0)


def _palmgren(F, length):
    """Palmgren 1959 / Harris & Kotzalas 2007 ch. 7, written out: δ = 3.84e-5 F^0.9 / l^0.8."""
    return 3.84e-5 * F**0.9 / length**0.8


@pytest.mark.parametrize("F", [1.0, 250.0, 1810.0, 1e4])
def test_palmgren_law_is_the_closed_form(F):
    """approach, force, secant and tangent stiffness of ``"palmgren"`` against the closed form
    to 1e-9 (relative)."""
    delta = _palmgren(F, KW["b"])
    assert cl.approach(F, "palmgren", **KW) == pytest.approx(delta, rel=1e-9)
    assert cl.palmgren_approach(F, KW["b"]) == pytest.approx(delta, rel=1e-9)
    assert cl.force(delta, "palmgren", **KW) == pytest.approx(F, rel=1e-9)
    assert cl.secant_stiffness(F, "palmgren", **KW) == pytest.approx(F / delta, rel=1e-9)
    # dF/dδ = 1 / (0.9 δ / F)
    assert cl.tangent_stiffness(F, "palmgren", **KW) == pytest.approx(F / (0.9 * delta), rel=1e-9)


def test_palmgren_does_not_read_the_curvature_and_refuses_non_steel():
    assert cl.approach(1000.0, "palmgren", **{**KW, "rho": 5.0}) == pytest.approx(
        cl.approach(1000.0, "palmgren", **KW), rel=1e-15
    )
    with pytest.raises(ParameterError, match="youngs_modulus_MPa.*steel"):
        cl.approach(1000.0, "palmgren", **{**KW, "E": 7.0e4})
    with pytest.raises(ParameterError, match="power law"):
        cl.log_law_coefficients("palmgren", **KW)


@pytest.fixture(scope="module")
def han():
    case = load_case("han2023_rv110e")
    return build_reducer(case.reducer)


def test_palmgren_in_the_rv_kernels_is_the_closed_form(han):
    """The compiled load sharing with ``"palmgren"``: every loaded pin's secant stiffness is the
    closed form's F/δ(F); the batched kernel (Newton on the exact law) equals the per-position
    secant fixed point and the plain twin."""
    law = contact_law(han, "palmgren")
    system = assemble(han, output_positions(12))
    T = han.rated_torque
    a = solve_batched(system, T, law)
    b = solve_batched(system, T, law, method="per_position")
    c = solve_batched(system, T, law, compiled=False)
    F = a.contact_force
    on = F > 1.0
    # the case's pin seat (and pin bending, where given) in series with each contact: F c
    series = np.broadcast_to(pin_series_compliance(han)[system.contact_group], F.shape)
    assert np.all(series > 0.0)
    delta = _palmgren(F[on], han.discs.face_width) + F[on] * series[on]
    np.testing.assert_allclose(a.pin_stiffness[on], F[on] / delta, rtol=1e-9)
    scale = F.max()
    np.testing.assert_allclose(b.contact_force, F, rtol=0, atol=1e-6 * scale)
    np.testing.assert_allclose(c.contact_force, F, rtol=0, atol=1e-9 * scale)
    # equilibrium: approach of every loaded contact = δ(F) of Palmgren's law + the series springs
    d = np.einsum("pci,pi->pc", system.contact_B, a.q) - system.contact_gap
    np.testing.assert_allclose(d[on], delta, rtol=1e-7)


def _data(name):
    with open(case_path(name), "rb") as fh:
        return tomllib.load(fh)


def test_contact_law_is_required_in_rv_case_files():
    data = copy.deepcopy(_data("han2023_rv110e_no_errors"))
    del data["reducer"]["contact_law"]
    with pytest.raises(CaseFileError) as exc:
        load_case(data)
    text = str(exc.value)
    assert "contact_law is required" in text
    assert 'contact_law = "line_contact" gives the results of a case written before' in text


def test_han2023_case_selects_palmgren_and_names_it():
    from gearte.studies import run_case

    data = copy.deepcopy(_data("han2023_rv110e"))
    data["analyses"] = {"load_sharing": {"torque_Nm": 1078.0, "positions": 360}}
    res = run_case(load_case(data))
    v = res["load_sharing"].values
    assert v["contact_law"] == "palmgren"
    assert "3.84e-05 F^0.9 / l^0.8" in v["contact_law_form"]
    assert "l = b = 13 mm" in v["contact_law_form"]
    # the root-squeeze warning names the pin and its angle
    warn = [w for w in res.warnings if "radial squeeze" in w]
    assert len(warn) == 1
    assert "disc 1, pin 38 at output angle 185.0°" in warn[0]
    assert "12.0° from the line of centres" in warn[0]


def test_root_squeeze_is_the_force_direction_at_the_peak_pin(han):
    """sin of the force angle from radial is K1 |sin φ| / S (the normal through the pitch point):
    checked against the contact normal of the assembled rows."""
    th = output_positions(360)
    system = assemble(han, th)
    ls = load_sharing(han, han.rated_torque, th, law=contact_law(han, "palmgren"), system=system)
    pk = peak_pin(han, ls)
    assert pk.root_squeeze
    N, zp = han.discs.count, han.pins.count
    c = (pk.disc - 1) * zp + (pk.pin - 1)
    dof = system.layout.disc(pk.disc - 1)
    n = system.contact_B[pk.position, c, dof : dof + 2]
    # the pin's radial direction: pin k at angle 2π k / z_p
    ang = 2 * np.pi * (pk.pin - 1) / zp
    radial = np.array([np.cos(ang), np.sin(ang)])
    sin_alpha = abs(n[0] * radial[1] - n[1] * radial[0]) / np.linalg.norm(n)
    assert np.sin(pk.force_angle_from_radial) == pytest.approx(sin_alpha, abs=1e-9)
    assert N == 2


def test_near_conformal_concave_contact_is_refused_for_johnson_naming_the_pin(han):
    """han2023's peak pin sits on a concave root flank of radius ~3.7 mm on a 3.5 mm pin: the
    Hertz strip of Johnson's law is wider than 0.1 r there; the load sharing refuses it,
    naming the pin."""
    # the pin contacts alone (no pin seat in series, which spreads the load over more pins and
    # keeps the root contacts narrow enough on this case)
    bare = han.replace(pins=dataclasses.replace(han.pins, seat_compliance=None))
    with pytest.raises(ParameterError) as exc:
        load_sharing(
            bare, bare.rated_torque, output_positions(360), law=contact_law(bare, "line_contact")
        )
    msg = str(exc.value)
    assert msg.startswith("contact_law = 'line_contact'")
    assert "disc 1, pin 17 at output angle 347.0°" in msg
    assert "concave flank of radius 3.7" in msg
    assert f"> {CONFORMAL_HALF_WIDTH_LIMIT:g} r" in msg
    # the same reducer without errors: every concave contact is narrow enough
    red0 = build_reducer(load_case("han2023_rv110e_no_errors").reducer)
    ls0 = load_sharing(red0, red0.rated_torque, output_positions(36),
                       law=contact_law(red0, "line_contact"))  # fmt: skip
    assert ls0.peak_pin_load > 0


def test_tooth_contact_refuses_palmgren_by_name():
    """The cycloid-stage tooth contact solves the logarithmic laws only: Palmgren's is refused
    naming the key, in the model and in an rv_reducer case asking for [analyses.tooth_contact]."""
    from gearte.geometry.cycloid import CycloidStage
    from gearte.models.cycloid_contact import tooth_contact

    st = CycloidStage(z_p=40, r_p=82.0, r_rp=3.5, a=1.5, b=13.0)
    with pytest.raises(ParameterError, match="contact_law = 'palmgren'.*logarithmic laws"):
        tooth_contact(st, 4.0e5, disc_share=0.5, E=2.06e5, mu=0.3, contact_law="palmgren")
    data = copy.deepcopy(_data("han2023_rv110e_no_errors"))
    data["analyses"] = {"tooth_contact": {"torque_Nm": 500.0, "disc_share": 0.5}}
    from gearte.studies import run_case

    with pytest.raises((ParameterError, CaseFileError), match="reducer.contact_law"):
        run_case(load_case(data))


def test_every_rv_result_names_the_law_form():
    from gearte.studies import run_case

    data = copy.deepcopy(_data("han2023_rv110e_no_errors"))
    data["analyses"] = {
        "transmission_error": {"torque_Nm": 1078.0, "positions": 36},
        "catalogue": {"position_deg": 0.0, "torque_sweep": [0.0, 1.0, 0.0, -1.0, 0.0]},
    }
    res = run_case(load_case(data))
    for name in ("transmission_error", "catalogue"):
        assert res[name].values["contact_law"] == "palmgren"
        assert res[name].values["contact_law_form"].startswith("palmgren: δ = 3.84e-05 F^0.9")


@pytest.mark.parametrize("a0", [0.0, 1e-6, 3e-5])
def test_power_law_with_a_series_spring_inverts_to_the_closed_form(a0):
    """Palmgren's law with a linear compliance in series (the pin seat): δ = a0 F + a2 F^a3;
    the inverse returns every force whose δ it is given, to 1e-10."""
    from gearte.solvers.contact import power_law_force

    F = np.array([0.0, 1e-3, 1.0, 250.0, 1810.0, 1e4, 1e5])
    a2, a3 = 3.84e-5 / 11.0**0.8, 0.9
    delta = a0 * F + _palmgren(F, 11.0)
    got = power_law_force(delta, np.full(F.shape, a0), np.full(F.shape, a2), np.full(F.shape, a3))
    np.testing.assert_allclose(got, F, rtol=1e-10, atol=1e-12)
    assert power_law_force(np.array([-1e-3]), np.array([a0]), np.array([a2]), np.array([a3]))[
        0
    ] == pytest.approx(0.0)
