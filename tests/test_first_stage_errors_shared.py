"""The RV first stage and the ``planetary`` kind share one eccentricity-error object (issue 11
item 2): :class:`gearte.geometry.planetary.EccentricityError` and
:class:`gearte.geometry.planetary.SunPlanetErrors` (sun eccentricity, sun assembly error, one
eccentricity per planet), read from each kind's own case keys.
"""

from __future__ import annotations

import tomllib

import numpy as np
import pytest

from gearte.cases import case_path
from gearte.errors import CaseFileError, ParameterError
from gearte.geometry.planetary import EccentricityError, SunPlanetErrors
from gearte.io.case_file import load_case_dict
from gearte.models.planetary_errors import derive_terms, first_stage_keys
from gearte.studies._rv_dynamics import build_dynamic_model
from gearte.studies.planetary import build_terms, first_stage_errors
from gearte.studies.rv_reducer import build_reducer
from gearte.units import deg_to_rad, um_to_mm

#: the same first-stage errors [µm, deg] for both kinds: sun, sun assembly, planets 1..3
SUN, SUN_ASSY = (5.0, 45.0), (4.0, 100.0)
PLANETS = ((6.0, 30.0), (3.0, -60.0), (7.0, 150.0))


def _rv_case():
    data = tomllib.loads(case_path("li2023_rv_errors").read_text(encoding="utf-8"))
    others = [
        e
        for e in data["reducer"]["errors"]
        if e["part"] not in ("sun_eccentricity", "sun_assembly", "planet_eccentricity")
    ]
    first = [
        {"part": "sun_eccentricity", "value_um": SUN[0], "angle_deg": SUN[1]},
        {"part": "sun_assembly", "value_um": SUN_ASSY[0], "angle_deg": SUN_ASSY[1]},
    ] + [
        {"part": "planet_eccentricity", "crank": i, "value_um": v, "angle_deg": a}
        for i, (v, a) in enumerate(PLANETS, start=1)
    ]
    data["reducer"]["errors"] = first + others
    return load_case_dict(data)


def _planetary_data(**extra_mags):
    """Wang 2013's 2K-H with the RV's 12/36 first stage (module 1.5, three planets)."""
    mags = {"E_s": SUN[0], "A_s": SUN_ASSY[0], "E_r": 0.0, "A_c": 0.0, "A_p": 0.0}
    angs = {"beta_s": SUN[1], "gamma_s": SUN_ASSY[1], "beta_r": 0.0}
    for i, (v, a) in enumerate(PLANETS, start=1):
        mags[f"E_p{i}"], angs[f"beta_p{i}"] = v, a
    mags.update(extra_mags)
    return {
        "case": {"kind": "planetary", "name": "rv_first_stage_as_planetary"},
        "gearset": {
            "z_sun": 12,
            "z_planet": 36,
            "z_ring": 84,
            "module_mm": 1.5,
            "pressure_angle_deg": 20.0,
            "n_planets": 3,
        },
        "errors": {"source": "derived", "magnitudes_um": mags, "angles_deg": angs},
    }


def _assert_same(a: SunPlanetErrors, b: SunPlanetErrors) -> None:
    for va, vb in zip(a.vectors(), b.vectors(), strict=True):
        np.testing.assert_allclose(va, vb, rtol=1e-14, atol=1e-18)
    for x, y in zip(
        (a.sun, a.sun_assembly, *a.planets), (b.sun, b.sun_assembly, *b.planets), strict=True
    ):
        assert x.amplitude == pytest.approx(y.amplitude, rel=1e-14)
        assert x.phase == pytest.approx(y.phase, rel=1e-14)


def test_rv_and_planetary_cases_with_the_same_errors_give_equal_error_objects():
    rv = build_reducer(_rv_case().reducer).error_set.first_stage
    pl = first_stage_errors(load_case_dict(_planetary_data()))
    assert type(rv) is type(pl) is SunPlanetErrors
    _assert_same(rv, pl)
    assert rv.sun.amplitude == pytest.approx(5e-3)
    assert pl.planets[2].phase == pytest.approx(deg_to_rad(150.0))


def test_both_kinds_compute_the_same_first_stage_excitation_from_the_shared_object():
    """Planetary kind: Wang's external-line terms of planet 1 (E_s, A_s, E_p1) are the projection
    of the object's sun offset minus planet-1 offset on the sun–planet line of action. RV kind:
    the dynamics builds its sun and planet tooth-centre offsets from the same object."""
    case = _rv_case()
    red = build_reducer(case.reducer)
    fs = red.error_set.first_stage
    pcase = load_case_dict(_planetary_data())
    pset = pcase.gearset.build()
    terms, mags, angs = build_terms(pcase)
    t = np.linspace(0.0, 4.0 * np.pi, 97)  # input (sun) angle [rad]
    wang = np.zeros_like(t)
    for term in terms.terms:
        if term.name in ("E_s/external/planet1", "A_s/external/planet1", "E_p1/external"):
            ang = term.angle_coeff * angs.get(term.angle, 0.0) if term.angle else 0.0
            wang += (
                term.gain
                * mags[term.magnitude]
                * np.sin(float(term.frequency) * t + term.phase + ang)
            )
    w = {k: float(v) for k, v in pset.speed_ratios().items()}
    phi = w["carrier"] * t + pset.eta[0]  # planet 1's radial line
    nu = phi - pset.pressure_angle + np.pi / 2  # sun–planet line of action
    n_w = np.stack([np.cos(nu), np.sin(nu)], -1)
    d_p = fs.planet_offsets(w["planet_rel"] * t)[:, 0]  # planet frame → rotate by phi
    d_p = np.stack(
        [
            np.cos(phi) * d_p[:, 0] - np.sin(phi) * d_p[:, 1],
            np.sin(phi) * d_p[:, 0] + np.cos(phi) * d_p[:, 1],
        ],
        -1,
    )
    from_object = np.sum((fs.sun_offset(w["sun"] * t) - d_p) * n_w, axis=-1)
    np.testing.assert_allclose(wang, from_object, rtol=0, atol=1e-15)
    assert np.ptp(wang) > 1e-2  # a real excitation of ~µm (mm units)

    errs = build_dynamic_model(case, red)[0].errors
    theta = np.linspace(0.0, 2 * np.pi, 13)
    amp, ph = errs.sun_eccentricity  # rotates with the sun (assembly.py: sun_off)
    got = amp * np.stack([np.cos(theta + ph), np.sin(theta + ph)], -1)
    np.testing.assert_allclose(got, fs.sun.offset(theta), rtol=0, atol=1e-15)
    amp, ph = errs.sun_assembly  # fixed offset of the sun support
    got = amp * np.array([np.cos(ph), np.sin(ph)])
    np.testing.assert_allclose(got, fs.sun_assembly.vector, rtol=0, atol=1e-15)
    pe = np.asarray(errs.planet_eccentricity)
    got = pe[:, 0, None, None] * np.stack(
        [np.cos(theta + pe[:, 1, None]), np.sin(theta + pe[:, 1, None])], -1
    )
    np.testing.assert_allclose(np.swapaxes(got, 0, 1), fs.planet_offsets(theta), atol=1e-15)


def test_planetary_results_read_the_object_unchanged_wang2013():
    """Overwriting Wang's sun/planet keys with the object's values is exact (0 difference)."""
    data = tomllib.loads(case_path("wang2013_2kh_derived").read_text(encoding="utf-8"))
    case = load_case_dict(data)
    _, mags, angs = build_terms(case)
    assert mags["E_s"] == float(um_to_mm(13.0)) and mags["E_p1"] == float(um_to_mm(16.0))
    assert angs == {"beta_r": 0.0}  # angles not given stay free, as before


def test_negative_amplitude_is_refused_naming_the_key():
    with pytest.raises(ParameterError) as e:
        EccentricityError(-1e-3, 0.0, "planet_eccentricity[2]")
    assert e.value.field == "planet_eccentricity[2]"
    with pytest.raises(ParameterError, match="finite"):
        EccentricityError(1e-3, float("nan"))


def test_wrong_planet_count_is_refused_naming_the_key():
    red = build_reducer(_rv_case().reducer)
    with pytest.raises(ParameterError) as e:
        red.error_set.with_first_stage(SunPlanetErrors.none(2))
    assert e.value.field == "planet_eccentricity"
    assert "3 planets" in e.value.reason
    with pytest.raises(CaseFileError, match="E_p4"):
        load_case_dict(_planetary_data(E_p4=1.0))


def test_rv_error_set_takes_the_object_back():
    red = build_reducer(_rv_case().reducer)
    fs = red.error_set.first_stage
    again = red.error_set.scaled(0.0).with_first_stage(fs).first_stage
    _assert_same(again, fs)


def test_object_sets_the_planetary_models_own_term_keys():
    pcase = load_case_dict(_planetary_data())
    terms = derive_terms(pcase.gearset.build(), "mean")
    mags, angs = first_stage_keys(first_stage_errors(pcase))
    assert set(mags) == {"E_s", "A_s", "E_p1", "E_p2", "E_p3"} <= set(terms.magnitudes)
    assert set(angs) <= set(terms.angles)
    assert mags["E_p3"] == pytest.approx(7e-3) and angs["beta_p3"] == pytest.approx(
        deg_to_rad(150.0)
    )
