"""The RV stiffness chain: each element against its closed form, the chain's shares and its
tangent compliance against a finite difference of the load-sharing model."""

from __future__ import annotations

import math

import numpy as np
import pytest

from gearte.errors import ParameterError
from gearte.models import rv_stiffness as st


# ---- each element against its closed form, written out independently ---------------------
def test_palmgren_line_deflection_closed_form():
    q, length = np.array([10.0, 1000.0, 12345.0]), np.array([5.0, 10.0, 22.0])
    want = [3.84e-5 * qi**0.9 / li**0.8 for qi, li in zip(q, length, strict=True)]
    np.testing.assert_allclose(st.palmgren_line_deflection(q, length), want, rtol=1e-12)


def test_palmgren_tangent_is_derivative_of_the_law():
    q, length, h = 2500.0, 12.0, 1e-3
    fd = (
        2
        * h
        / (st.palmgren_line_deflection(q + h, length) - st.palmgren_line_deflection(q - h, length))
    )
    assert float(st.palmgren_line_stiffness(q, length)) == pytest.approx(float(fd), rel=1e-7)
    secant = q / (3.84e-5 * q**0.9 / length**0.8)
    assert float(st.palmgren_line_stiffness(q, length, "secant")) == pytest.approx(secant, 1e-12)


def test_roller_bearing_stiffness_palmgren_stribeck_closed_form():
    z, length, fr, alpha, rows = 16, 14.0, 5000.0, math.radians(30.0), 2
    q_max = 4.08 * (fr / rows) / (z * math.cos(alpha))
    delta_r = 2 * 3.84e-5 * q_max**0.9 / length**0.8 / math.cos(alpha)
    k = float(st.roller_bearing_radial_stiffness(z, length, fr, alpha, rows))
    assert k == pytest.approx(fr / delta_r, rel=1e-12)
    k_t = float(st.roller_bearing_radial_stiffness(z, length, fr, alpha, rows, "tangent"))
    assert k_t == pytest.approx(fr / delta_r / 0.9, rel=1e-12)


def test_roller_bearing_value_of_the_former_geometry_function():
    """The value the bundled cases had from gearte.geometry.rv.palmgren_radial_stiffness."""
    assert round(float(st.roller_bearing_radial_stiffness(16, 14.0, 5000.0)) / 1e5, 2) == 8.62


def test_pin_seat_is_palmgren_tangent():
    f, length = 3000.0, 26.0
    want = 1.0 / (0.9 * 3.84e-5 * f**-0.1 / length**0.8)
    assert float(st.pin_seat_stiffness(f, length)) == pytest.approx(want, rel=1e-12)


def test_beam_point_compliance_roark_case_1e_and_shear():
    L, a, d, E, nu = 40.0, 15.0, 7.0, 2.06e5, 0.3
    b = L - a
    inertia = math.pi * d**4 / 64
    bending = a**2 * b**2 / (3 * E * inertia * L)
    shear = (10 / 9) * a * b / (E / (2 * (1 + nu)) * math.pi * d**2 / 4 * L)
    got = st.beam_point_compliance(L, a, d, E, nu, shear=False)
    assert float(got) == pytest.approx(bending, rel=1e-12)
    assert float(st.beam_point_compliance(L, a, d, E, nu)) == pytest.approx(bending + shear, 1e-12)


def test_beam_midspan_is_textbook_wl3_over_48ei():
    L, d, E = 50.0, 10.0, 2.0e5
    inertia = math.pi * d**4 / 64
    got = float(st.beam_point_compliance(L, L / 2, d, E, 0.3, shear=False))
    assert got == pytest.approx(L**3 / (48 * E * inertia), rel=1e-12)


def test_disc_positions_centred():
    np.testing.assert_allclose(st.disc_load_positions(40.0, 2, 13.0), [13.5, 26.5])
    np.testing.assert_allclose(st.disc_load_positions(40.0, 3, 10.0), [10.0, 20.0, 30.0])
    with pytest.raises(ParameterError, match="span"):
        st.disc_load_positions(20.0, 2, 13.0)


def test_shaft_torsion_shigley():
    d, L, E, nu = 22.0, 35.0, 2.06e5, 0.3
    G = E / (2 * (1 + nu))
    want = G * math.pi * d**4 / 32 / L
    assert float(st.shaft_torsional_stiffness(d, L, E, nu)) == pytest.approx(want, rel=1e-12)


def test_iso6336_mesh_stiffness():
    assert float(st.iso6336_mesh_stiffness(12.0)) == pytest.approx(20.0 * 12.0 * 1000.0)
    assert float(st.iso6336_mesh_stiffness(12.0, 15.0)) == pytest.approx(15.0 * 12.0 * 1000.0)


def test_ideal_peak_pin_force_hu2020_eq30():
    T, share, K1, zc, rp = 1.078e6, 0.5, 1.5 * 40 / 82.0, 39, 82.0
    assert float(st.ideal_peak_pin_force(T, share, K1, zc, rp)) == pytest.approx(
        4 * share * T / (K1 * zc * rp), rel=1e-12
    )


def test_series_and_shares():
    assert float(st.series_compliance(1.0, None, 2.5)) == 3.5
    shares = st.compliance_shares({"a": 1.0, "b": 3.0})
    assert shares == {"a": 0.25, "b": 0.75}
    with pytest.raises(ParameterError):
        st.compliance_shares({"a": -1.0})


@pytest.mark.parametrize(
    "call",
    [
        lambda: st.palmgren_line_deflection(-1.0, 10.0),
        lambda: st.palmgren_line_deflection(1.0, 0.0),
        lambda: st.stribeck_max_roller_load(100.0, 2),
        lambda: st.roller_bearing_radial_stiffness(10, 5.0, 100.0, math.radians(95.0)),
        lambda: st.beam_point_compliance(10.0, 12.0, 5.0, 2e5, 0.3),
        lambda: st.shaft_torsional_stiffness(-1.0, 10.0, 2e5, 0.3),
        lambda: st.palmgren_line_stiffness(100.0, 5.0, "chord"),
    ],
)
def test_bad_inputs_are_refused(call):
    with pytest.raises(ParameterError):
        call()


# ---- the chain on the bundled cases -------------------------------------------------------
@pytest.fixture(scope="module")
def han():
    from gearte.io.case_file import load_case
    from gearte.studies.rv_reducer import build_reducer

    return build_reducer(load_case("han2023_rv110e").reducer)


def test_chain_shares_sum_to_one_and_name_left_out(han):
    from gearte.models.rv_stiffness_chain import stiffness_chain

    chain = stiffness_chain(han)
    assert sum(chain.shares.values()) == pytest.approx(1.0, abs=1e-9)
    assert set(chain.left_out) == {"output_flange", "pin_bending"}
    assert not set(chain.left_out) & set(chain.shares)
    for e in ("pin_seat", "crank_bending", "crank_torsion", "cam_bearing", "carrier_bearing"):
        assert chain.shares[e] > 0.0


def test_chain_tangent_compliance_is_the_models_derivative(han):
    """C = uᵀ K_t⁻¹ u equals dθ/dT of the load-sharing model (line_contact law: each contact's
    secant satisfies its law exactly), by a central difference at ±0.1 % of rated torque."""
    from gearte.models.rv_load_sharing import assemble, load_sharing
    from gearte.models.rv_stiffness_chain import stiffness_chain

    chain = stiffness_chain(han)
    T = han.rated_torque
    h = 1e-3 * T
    system = assemble(han, np.array([0.0]))
    up = load_sharing(han, T + h, system=system).output_error[0]
    down = load_sharing(han, T - h, system=system).output_error[0]
    assert chain.total_compliance == pytest.approx(-(up - down) / (2 * h), rel=1e-6)


def test_series_elements_change_the_load_sharing(han):
    """Pin seat and crank bending are in the solve: removing them changes the pin forces."""
    import dataclasses

    from gearte.models.rv_load_sharing import load_sharing

    rigid = han.replace(
        pins=dataclasses.replace(han.pins, seat_compliance=None),
        cranks=dataclasses.replace(han.cranks, bending_compliance=None, torsional_stiffness=None),
    )
    theta = np.linspace(0, 2 * np.pi, 12, endpoint=False)
    a = load_sharing(han, han.rated_torque, theta).pin_force
    b = load_sharing(rigid, han.rated_torque, theta).pin_force
    assert np.max(np.abs(a - b)) > 10.0  # N


def test_output_flange_adds_its_compliance(han):
    import dataclasses

    from gearte.models.rv_stiffness_chain import stiffness_chain

    k_out = 2.0e9  # N·mm/rad
    flanged = han.replace(
        supports=dataclasses.replace(han.supports, output_torsional_stiffness=k_out)
    )
    a, b = stiffness_chain(han), stiffness_chain(flanged)
    assert b.total_compliance == pytest.approx(a.total_compliance + 1.0 / k_out, rel=1e-12)
    assert "output_flange" not in b.left_out
    assert b.shares["output_flange"] == pytest.approx(1.0 / k_out / b.total_compliance)


def test_catalogue_results_carry_shares_and_sources():
    from gearte.io.case_file import load_case
    from gearte.studies.rv_reducer import chain_sources

    src = chain_sources(load_case("hu2020_rv80e_initial_reducer").reducer)
    assert src["pin_seat"].startswith("derived")
    assert src["main_bearing"].startswith("derived")
    assert src["output_flange"] == "left out"
    assert src["sun_support"] == "given"


# ---- the case keys -------------------------------------------------------------------------
def _han_dict():
    import tomllib

    from gearte.cases import case_path

    return tomllib.loads(case_path("han2023_rv110e").read_text(encoding="utf-8"))


def test_seat_without_rated_torque_is_refused_naming_both_keys():
    from gearte.errors import CaseFileError
    from gearte.io.case_file import load_case_dict

    data = _han_dict()
    del data["reducer"]["rated_torque_Nm"]
    for a in ("catalogue", "compensation"):
        data["analyses"].pop(a, None)
    with pytest.raises(CaseFileError, match="pins.seat_length_mm needs reducer.rated_torque_Nm"):
        load_case_dict(data)


@pytest.mark.parametrize(
    ("section", "derived", "given", "value"),
    [
        ("pins", "seat_length_mm", "seat_stiffness_N_per_mm", 8e5),
        ("cranks", "bearing_span_mm", "bending_stiffness_N_per_mm", 1e6),
        ("cranks", "torsion_length_mm", "torsional_stiffness_Nm_per_rad", 5e4),
    ],
)
def test_an_element_given_and_derived_is_refused(section, derived, given, value):
    from gearte.errors import CaseFileError
    from gearte.io.case_file import load_case_dict

    data = _han_dict()
    data["reducer"][section][given] = value
    with pytest.raises(CaseFileError, match=f"give {derived} \\(derived\\) or {given}"):
        load_case_dict(data)


def test_given_stiffnesses_reach_the_reducer_and_sources_say_given():
    from gearte.io.case_file import load_case_dict
    from gearte.studies.rv_reducer import build_reducer, chain_sources

    data = _han_dict()
    pins, cranks, sup = (
        data["reducer"]["pins"],
        data["reducer"]["cranks"],
        data["reducer"]["supports"],
    )
    del pins["seat_length_mm"], cranks["bearing_span_mm"], cranks["torsion_length_mm"]
    pins["seat_stiffness_N_per_mm"] = 8e5
    pins["bending_stiffness_N_per_mm"] = 2e6
    cranks["bending_stiffness_N_per_mm"] = 1e6
    cranks["torsional_stiffness_Nm_per_rad"] = 5e4
    sup["output_flange_torsional_stiffness_Nm_per_rad"] = 2e6
    case = load_case_dict(data)
    red = build_reducer(case.reducer)
    assert red.pins.seat_compliance == pytest.approx(1 / 8e5)
    assert red.pins.bending_compliance == pytest.approx((1 / 2e6,) * 2)
    assert red.cranks.bending_compliance == pytest.approx((1 / 1e6,) * 2)
    assert red.cranks.torsional_stiffness == pytest.approx(5e7)  # N·mm/rad
    assert red.supports.output_torsional_stiffness == pytest.approx(2e9)
    src = chain_sources(case.reducer)
    for e in ("pin_seat", "pin_bending", "crank_bending", "crank_torsion", "output_flange"):
        assert src[e] == "given"


def test_derived_elements_match_their_closed_forms():
    """The case's dimensions become the closed forms of gearte.models.rv_stiffness."""
    from gearte.io.case_file import load_case
    from gearte.studies.rv_reducer import build_reducer

    case = load_case("han2023_rv110e")
    red = build_reducer(case.reducer)
    c = case.reducer.cranks
    E, nu = 2.06e5, 0.3
    a = st.disc_load_positions(c.bearing_span_mm, 2, 13.0)
    np.testing.assert_allclose(
        red.cranks.bending_compliance,
        st.beam_point_compliance(c.bearing_span_mm, a, c.shaft_diameter_mm, E, nu),
        rtol=1e-12,
    )
    assert red.cranks.torsional_stiffness == pytest.approx(
        float(st.shaft_torsional_stiffness(22.0, 35.0, E, nu)), rel=1e-12
    )
    f = st.ideal_peak_pin_force(1.078e6, 0.5, 1.5 * 40 / 82.0, 39, 82.0)
    assert 1 / red.pins.seat_compliance == pytest.approx(
        float(st.pin_seat_stiffness(f, 30.0)), rel=1e-12
    )
    assert red.supports.carrier_radial_stiffness == pytest.approx(
        float(st.roller_bearing_radial_stiffness(40, 6.0, 5000.0, math.radians(45.0), 2)),
        rel=1e-12,
    )


def test_case_without_chain_names_what_it_leaves_out():
    from gearte.io.case_file import load_case
    from gearte.models.rv_stiffness_chain import stiffness_chain
    from gearte.studies.rv_reducer import build_reducer, chain_sources

    case = load_case("li2023_rv_errors")
    chain = stiffness_chain(build_reducer(case.reducer))
    assert set(chain.left_out) == {
        "output_flange",
        "crank_bending",
        "pin_seat",
        "pin_bending",
        "crank_torsion",
    }
    assert sum(chain.shares.values()) == pytest.approx(1.0, abs=1e-9)
    assert chain_sources(case.reducer)["cam_bearing"] == "given"


def test_crank_bearings_at_rated_torque_are_a_fixed_point_of_the_load_sharing():
    """at_rated_torque: each crank bearing's stiffness is Palmgren's secant at its own largest
    load at rated torque over 36 positions of the error-free design (tolerance 1e-4 of the load:
    the fixed point's stopping rule; the stiffness moves as F^0.1, i.e. 1e-5)."""
    from gearte.io.case_file import load_case
    from gearte.models.rv_load_sharing import load_sharing, output_positions
    from gearte.studies.rv_reducer import build_reducer

    case = load_case("han2023_rv110e")
    red = build_reducer(case.reducer)
    red0 = build_reducer(case.reducer, with_errors=False)
    # a property of the design: the reducer with errors has the same bearing stiffness
    assert red.cranks.cam_bearing_stiffness == red0.cranks.cam_bearing_stiffness
    ls = load_sharing(red0, red0.rated_torque, output_positions(36))
    for load, k, (z, length) in (
        (ls.cam_bearing_load.max(), red.cranks.cam_bearing_stiffness, (14, 12.0)),
        (ls.carrier_bearing_load.max(), red.cranks.carrier_bearing_stiffness, (16, 10.0)),
    ):
        assert k == pytest.approx(float(st.roller_bearing_radial_stiffness(z, length, load)), 1e-5)


def test_main_bearing_at_rated_torque_is_refused():
    from gearte.errors import CaseFileError
    from gearte.io.case_file import load_case_dict

    data = _han_dict()
    main = data["reducer"]["supports"]["main_bearing"]
    del main["reference_load_N"]
    main["at_rated_torque"] = True
    with pytest.raises(CaseFileError, match="preload"):
        load_case_dict(data)


@pytest.mark.parametrize("name", ["han2023_rv110e", "hu2020_rv80e_initial_reducer"])
def test_paper_cases_report_compliance_shares_and_rigidity(name):
    """The catalogue analysis of the paper cases carries the breakdown (sum 1 ± 1e-9) beside
    the catalogue rigidity, and the tangent rigidity is within 2 % of that secant one."""
    import tomllib

    from gearte.cases import case_path
    from gearte.io.case_file import load_case_dict
    from gearte.studies.rv_reducer import run

    data = tomllib.loads(case_path(name).read_text(encoding="utf-8"))
    data["analyses"] = {"catalogue": data["analyses"]["catalogue"]}
    data["reducer"].pop("dynamics", None)
    data.pop("operation", None)
    values = run(load_case_dict(data, name=name))["catalogue"].values
    shares = values["compliance_shares"]
    assert sum(shares.values()) == pytest.approx(1.0, abs=1e-9)
    assert {"pin_contact", "pin_seat", "cam_bearing", "crank_bending"} <= set(shares)
    k = values["torsional_rigidity [N*m/arcmin]"]
    assert values["tangent_rigidity_at_rated [N*m/arcmin]"] == pytest.approx(k, rel=0.02)
    assert "pin bending" in values["stiffness_chain_left_out"]
