"""Strain-wave (harmonic) gear family: kinematics, the catalogue's three-segment stiffness,
hysteresis and lost motion, the transmission error's once- and twice-per-wave-generator-revolution
terms, its description both ways, its yield, and a wrist chain built on it."""

from __future__ import annotations

import math
import tomllib

import numpy as np
import pytest

import gearte
from gearte.cases import case_path, list_cases
from gearte.drives import Drive
from gearte.errors import CaseFileError, ParameterError
from gearte.families import get_family
from gearte.io.case_file import load_case, load_case_dict
from gearte.models.strain_wave import (
    strain_wave_ratio,
    te_harmonics,
    torsion_angle,
    transmission_error,
)
from gearte.studies import RunOptions
from gearte.units import Nm_to_Nmm, rad_to_arcmin

OPTS = RunOptions(progress=False)
CASE = "harmonicdrive_csf32_100"

#: Harmonic Drive AG, CHA manual 1018854 12/2015, §4.2 worked example: T = 60 N·m with
#: T1 = 29 N·m, K1 = 6.7e4 N·m/rad, T2 = 108 N·m, K2 = 1.1e5 N·m/rad, K3 = 1.2e5 N·m/rad
#: → φ = 7.15e-4 rad = 2.5 arcmin (printed to 3 and 2 significant figures).
HARMONICDRIVE2015_EXAMPLE = {"T": 60.0, "phi_rad": 7.15e-4, "phi_arcmin": 2.5}


def _catalogue_model() -> tuple[float, ...]:
    return tuple(float(Nm_to_Nmm(x)) for x in (29.0, 108.0, 6.7e4, 1.1e5, 1.2e5))


def test_stiffness_harmonicdrive2015_worked_example():
    """The three-segment model gives the manual's worked example (eq. 68.3), to the printed
    precision: 7.15e-4 rad (±0.005e-4) and 2.5 arcmin (±0.05)."""
    phi = float(torsion_angle(Nm_to_Nmm(HARMONICDRIVE2015_EXAMPLE["T"]), *_catalogue_model()))
    assert phi == pytest.approx(HARMONICDRIVE2015_EXAMPLE["phi_rad"], abs=0.005e-4)
    assert float(rad_to_arcmin(phi)) == pytest.approx(
        HARMONICDRIVE2015_EXAMPLE["phi_arcmin"], abs=0.05
    )


def test_stiffness_curve_is_the_catalogue_closed_form_on_every_segment():
    """φ(T) against eq. 68.2–68.4 written out, on both sides of T1 and T2 and for negative
    torques (odd); continuous at the limit torques; the bundled case's drawn curve is it."""
    T1, T2, K1, K2, K3 = _catalogue_model()
    t = np.linspace(-3 * T2, 3 * T2, 2001)
    a = np.abs(t)
    closed = np.empty_like(a)
    for j, x in enumerate(a):
        if x <= T1:
            closed[j] = x / K1
        elif x <= T2:
            closed[j] = T1 / K1 + (x - T1) / K2
        else:
            closed[j] = T1 / K1 + (T2 - T1) / K2 + (x - T2) / K3
    np.testing.assert_allclose(
        torsion_angle(t, T1, T2, K1, K2, K3), np.sign(t) * closed, rtol=1e-14
    )
    for lim in (T1, T2):
        lo, hi = torsion_angle([lim * (1 - 1e-12), lim * (1 + 1e-12)], T1, T2, K1, K2, K3)
        assert hi == pytest.approx(lo, rel=1e-9)
    res = gearte.run_case(CASE, OPTS)["stiffness"].values
    torque = Nm_to_Nmm(np.asarray(res["torque [N*m]"]))
    mid = 0.5 * (np.asarray(res["torsion_loading [arcmin]"]) + res["torsion_unloading [arcmin]"])
    np.testing.assert_allclose(
        mid, rad_to_arcmin(torsion_angle(torque, T1, T2, K1, K2, K3)), rtol=1e-12, atol=1e-15
    )


def test_ratio_from_teeth_and_refusal_of_a_wrong_tooth_difference():
    assert strain_wave_ratio(200, 202) == 100.0
    assert strain_wave_ratio(160, 162) == 80.0
    with pytest.raises(ParameterError, match="circular_spline_teeth"):
        strain_wave_ratio(200, 203)
    data = tomllib.loads(case_path(CASE).read_text())
    data["gear"]["circular_spline_teeth"] = 201
    with pytest.raises(CaseFileError, match="gear: circular_spline_teeth must be"):
        load_case_dict(data)
    data = tomllib.loads(case_path(CASE).read_text())
    data["gear"]["stiffness"]["T2_Nm"] = 10.0
    with pytest.raises(CaseFileError, match="T1_Nm < T2_Nm"):
        load_case_dict(data)


def test_lost_motion_is_hysteresis_plus_twice_the_torsion_at_the_test_torque():
    """LM = H + 2 φ(T_L): 1.0′ + 2 · 5.5/6.7e4 rad (T_L below T1), exactly."""
    res = gearte.run_case(CASE, OPTS)
    v = res["stiffness"].values
    T1, T2, K1, K2, K3 = _catalogue_model()
    expected = 1.0 + 2.0 * float(rad_to_arcmin(Nm_to_Nmm(5.5) / K1))
    assert v["lost_motion [arcmin]"] == pytest.approx(expected, rel=1e-14)
    assert v["torsional_rigidity [N*m/arcmin]"] == pytest.approx(
        1.2e5 / rad_to_arcmin(1.0), rel=1e-14
    )


def _gear(**errors):
    return get_family("strain_wave").to_object(load_case(CASE)).with_errors(**errors)


def test_te_once_and_twice_per_wave_generator_revolution_terms_are_the_closed_form():
    """Over one WG revolution (no flexspline term), the FFT of eq. te has the closed-form
    amplitudes: once = (tan α/r) d e/h, twice = |e²/(2h) e^{2iψe} + ε_c e^{2iψc}| (tan α/r)."""
    g = _gear(flexspline_ovality=0.0)
    th = np.linspace(0, 2 * np.pi, 512, endpoint=False)
    te = g.transmission_error(th)
    spec = np.abs(np.fft.rfft(te)) * 2 / th.size
    h = te_harmonics(g)
    k = math.tan(g.pressure_angle) / g.pitch_radius
    e = g.errors
    assert h["once"] == pytest.approx(
        k * e.lobe_height_difference * e.wave_generator_eccentricity / g.engagement_depth, rel=1e-14
    )
    assert spec[1] == pytest.approx(h["once"], rel=1e-9)
    assert spec[2] == pytest.approx(h["twice"], rel=1e-9)
    assert np.all(spec[3:] < 1e-15)


def test_te_a_wave_generator_eccentricity_alone_averages_out_to_first_order():
    """Two diametrically opposite zones: e alone gives no once-per-revolution term, only e²/2h
    twice per revolution; a lobe difference alone gives a constant (no TE)."""
    kw = dict(ratio=100.0, pitch_radius=40.0, pressure_angle=math.radians(20), engagement_depth=0.8)
    th = np.linspace(0, 2 * np.pi, 256, endpoint=False)
    spec = np.abs(np.fft.rfft(transmission_error(th, eccentricity=0.01, **kw))) * 2 / th.size
    assert spec[1] < 1e-18
    k = math.tan(math.radians(20)) / 40.0
    assert spec[2] == pytest.approx(k * 0.01**2 / (2 * 0.8), rel=1e-9)
    assert np.ptp(transmission_error(th, lobe_difference=0.01, **kw)) < 1e-18


def test_te_peak_to_peak_exact_over_an_output_revolution_bounds_the_sampled_trace():
    """The exact peak-to-peak (trigonometric extremes, flexspline drift through every phase)
    is >= the sampled trace's and within 1 % of a fine one (64 per WG revolution)."""
    res = gearte.run_case(CASE, OPTS)["transmission_error"].values
    g = _gear()
    out = np.linspace(0, 2 * np.pi, int(64 * g.ratio), endpoint=False)
    fine = float(np.ptp(g.transmission_error(-g.ratio * out)))
    exact = res["te_peak_to_peak [arcsec]"]
    assert exact >= res["te_peak_to_peak_sampled [arcsec]"]
    assert float(rad_to_arcmin(fine)) * 60 == pytest.approx(exact, rel=0.01)
    assert float(rad_to_arcmin(fine)) * 60 <= exact * (1 + 1e-12)


def test_description_round_trips_one_function_each_way():
    """to_sections(to_object(case)) read back gives the same gear (errors and tolerances too)."""
    fam = get_family("strain_wave")
    gear = fam.to_object(load_case(CASE))
    assert fam.to_sections is not None
    again = fam.to_object(
        load_case_dict({"case": {"kind": "strain_wave"}, **fam.to_sections(gear)})
    )
    assert again == gear


def test_drive_answers_the_interface_and_its_spread_is_the_yields_linear_sd():
    fam = get_family("strain_wave")
    drive = fam.drive(load_case(CASE), "sw")
    assert isinstance(drive, Drive)
    assert drive.kind == "strain_wave" and drive.ratio == 100.0
    spread = drive.lost_motion_spread()
    assert spread is not None
    res = gearte.run_case(CASE, RunOptions(progress=False, samples=2000))
    assert res["yield"].values["sobol_quantity"] == "te_peak_to_peak [arcsec]"
    assert float(rad_to_arcmin(spread.sd)) == pytest.approx(
        res["stiffness"].values["lost_motion_sd [arcmin]"], rel=1e-14
    )


def test_yield_worst_sample_case_file_reproduces_that_sample():
    """The worst gear is written back by the family's to_sections; run on its own it gives that
    sample's lost motion and TE peak-to-peak."""
    data = tomllib.loads(case_path(CASE).read_text())
    data["analyses"]["yield"].update(samples=500, sobol_samples=0, keep_worst=1)
    res = gearte.run_case(load_case_dict(data, name="sw_worst"), OPTS)
    worst = res["yield"].values["worst_samples"][0]
    again = gearte.run_case(
        load_case_dict(tomllib.loads(res["yield"].files["worst_sample_1.toml"])), OPTS
    )
    assert again["stiffness"].values["lost_motion [arcmin]"] == pytest.approx(
        worst["values"]["lost_motion [arcmin]"], rel=1e-12
    )
    assert again["transmission_error"].values["te_peak_to_peak [arcsec]"] == pytest.approx(
        worst["values"]["te_peak_to_peak [arcsec]"], rel=1e-9
    )


def test_wrist_chain_lost_motion_equals_the_strain_wave_gears_own():
    """robot_wrist_strain_wave (motor → the catalogue gear): the chain's stage lost motion mean
    is the strain_wave kind's lost_motion, its maximum the drive's spread maximum, and without
    tolerances the joint's lost motion is the gear's own — exactly (the same function)."""
    sw = tomllib.loads(case_path(CASE).read_text())
    del sw["analyses"]["yield"]
    own = gearte.run_case(load_case_dict(sw, name="own"), OPTS)
    lm = own["stiffness"].values["lost_motion [arcmin]"]
    data = tomllib.loads(case_path("robot_wrist_strain_wave").read_text())
    del data["analyses"]
    chain = gearte.run_case(
        load_case_dict(data, name="wrist", base_dir=str(case_path(CASE).parent)), OPTS
    )
    stage = chain["strain_wave_drive"].values
    assert stage["lost_motion_mean [arcmin]"] == lm
    spread = get_family("strain_wave").drive(load_case(CASE), "sw").lost_motion_spread()
    assert chain["chain"].values["joint_lost_motion_max [arcmin]"] == float(
        rad_to_arcmin(spread.max)
    )
    data["chain"]["stages"][0]["drive"] = {
        "kind": "strain_wave",
        "gear": sw["gear"],
        "errors": sw["errors"],
        "tolerances": {},
    }
    chain = gearte.run_case(load_case_dict(data, name="wrist_exact"), OPTS)
    assert chain["chain"].values["joint_lost_motion_max [arcmin]"] == lm
    assert (
        chain["chain"].values["joint_torsional_stiffness [N*m/arcmin]"]
        == own["stiffness"].values["torsional_rigidity [N*m/arcmin]"]
    )


def test_wrist_chain_yield_draws_the_gears_own_tolerances():
    """The wrist's yield ranks the gear's hysteresis loss and torsion at T1 (its own
    tolerances, keys strain_wave.<error>), not one normal law for the stage."""
    data = tomllib.loads(case_path("robot_wrist_strain_wave").read_text())
    data["analyses"]["yield"].update(samples=2000, sobol_samples=256, bootstrap=0)
    data["chain"]["te_positions"] = None
    del data["chain"]["te_positions"]
    res = gearte.run_case(
        load_case_dict(data, name="wrist_yield", base_dir=str(case_path(CASE).parent)), OPTS
    )
    share = res["yield"].values["linear_share"]
    assert set(share) == {"strain_wave.hysteresis_loss", "strain_wave.torsion_at_T1"}
    assert max(share, key=share.get) == "strain_wave.hysteresis_loss"
    assert share["strain_wave.torsion_at_T1"] > 0.05


def test_both_cases_are_bundled():
    cases = list_cases()
    assert CASE in cases and "robot_wrist_strain_wave" in cases


def test_family_labels_join_the_label_registry_when_its_module_is_imported():
    """A family's own labels reach every process that reads its results (importing its
    description module registers them; the report's background process unpickles the case)."""
    import gearte.families.strain_wave  # noqa: F401
    from gearte.labels import label_with_unit

    assert (
        label_with_unit("te_once_per_wg_revolution [arcsec]")
        == "TE once per wave-generator revolution [arcsec]"
    )
