"""One description of an RV reducer read by every RV analysis (issue 11 items 2, 3 and 6)."""

from __future__ import annotations

import json
import tomllib

import numpy as np
import pytest

from gearte.cases import case_path
from gearte.errors import CaseFileError, ParameterError
from gearte.io.case_file import load_case_dict
from gearte.studies import RunOptions, run_case

#: Result names issue 11 fixes as API for the bundled RV cases ("Must show").
REQUIRED = [
    "peak_pin_load [N]",
    "max_contact_pressure [MPa]",
    "lost_motion [arcmin]",
    "torsional_rigidity [N*m/arcmin]",
    "total_te_peak_to_peak [arcsec]",
    "dte_peak_to_peak [arcsec]",
    "contact_law",
]
RV_CASES = [
    "han2023_rv110e",
    "han2023_rv110e_no_errors",
    "hu2020_rv80e_initial_reducer",
    "hu2020_rv80e_modified_reducer",
    "li2023_rv",
    "li2023_rv_errors",
    "li2023_rv_unmodified",
    "li2023_rv_modified_fourier",
]


def _data(name: str) -> dict:
    data = tomllib.loads(case_path(name).read_text(encoding="utf-8"))
    data["case"]["name"] = name
    return data


def _fast(data: dict) -> dict:
    """The same case with fewer positions and a short DTE (the physics unchanged)."""
    a = data["analyses"]
    for key in ("load_sharing", "transmission_error"):
        if key in a:
            a[key]["positions"] = 24
    if "catalogue" in a:
        a["catalogue"]["steps_per_segment"] = 3
    if "dte" in a:
        a["dte"].update(duration_s=0.05, settle_s=0.05)
    for key in ("compensation", "cycloid_compensation", "batch", "speed_sweep"):
        a.pop(key, None)
    return data


def test_bundled_rv_cases_share_one_kind():
    for name in RV_CASES:
        assert _data(name)["case"]["kind"] == "rv_reducer", name


@pytest.mark.parametrize(
    "name", ["han2023_rv110e", "li2023_rv_errors", "hu2020_rv80e_initial_reducer"]
)
def test_rv_case_writes_required_names_in_one_results_json(name, tmp_path):
    from gearte.report.outputs import write_outputs

    res = run_case(load_case_dict(_fast(_data(name))), RunOptions(progress=False))
    paths = write_outputs(res, tmp_path)
    doc = json.loads(open(paths["results"], encoding="utf-8").read())
    assert doc["case"]["kind"] == "rv_reducer"
    values: dict = {}
    for a in doc["analyses"].values():
        values.update(a["values"])
    for key in REQUIRED:
        assert key in values, key
        assert values[key] is not None, key
    assert values["contact_law"] == _data(name)["reducer"]["contact_law"]
    assert values["dte_peak_to_peak [arcsec]"] > 0
    assert values["lost_motion [arcmin]"] > 0


def test_analysis_without_its_input_names_the_missing_key():
    data = _data("han2023_rv110e")
    del data["reducer"]["rated_torque_Nm"]
    del data["reducer"]["dynamics"]
    data["analyses"]["geometric_te"] = {}
    with pytest.raises(CaseFileError) as exc:
        load_case_dict(data)
    text = str(exc.value)
    assert "analyses.catalogue needs reducer.rated_torque_Nm" in text
    assert "analyses.dte needs reducer.dynamics" in text
    assert "analyses.geometric_te needs reducer.cycloid_errors" in text


def test_yield_without_the_rated_torque_names_the_missing_key():
    """Found by ``make fuzz`` (2026-11-26): han2023_rv110e_yield without
    ``reducer.rated_torque_Nm`` escaped as an internal TypeError; every sample's catalogue test
    needs it, so the case file is refused naming the key, and the API says the same."""
    import dataclasses

    from gearte.errors import ParameterError
    from gearte.runners.yield_models import RVReducerYield
    from gearte.studies.rv_reducer import build_reducer

    data = _data("han2023_rv110e_yield")
    del data["reducer"]["rated_torque_Nm"]
    with pytest.raises(CaseFileError) as exc:
        load_case_dict(data)
    assert "analyses.yield needs reducer.rated_torque_Nm" in str(exc.value)
    red = build_reducer(load_case_dict(_data("han2023_rv110e_yield")).reducer)
    with pytest.raises(ParameterError, match="reducer.rated_torque"):
        RVReducerYield(dataclasses.replace(red, rated_torque=None))


def test_adding_the_inputs_makes_an_analysis_run():
    """li2023_rv does not ask for load sharing; adding the section is all it takes."""
    data = _data("li2023_rv")
    data["analyses"] = {"load_sharing": {"torque_Nm": 450.0, "positions": 8}}
    res = run_case(load_case_dict(data), RunOptions(progress=False))
    assert res["load_sharing"]["peak_pin_load [N]"] > 0


def test_derived_masses_need_a_density_or_material():
    """No paper data as defaults: a mass left out needs the density (or material) and geometry."""
    from gearte.studies.rv_reducer import build_reducer

    data = _fast(_data("han2023_rv110e"))
    del data["reducer"]["material"]
    case = load_case_dict(data)
    from gearte.geometry.rv import mass_properties

    with pytest.raises(ParameterError) as exc:
        mass_properties(build_reducer(case.reducer), None)
    assert "density_kg_per_m3" in str(exc.value)
    data = _fast(_data("han2023_rv110e"))
    del data["reducer"]["cranks"]["shaft_length_mm"]
    case = load_case_dict(data)
    with pytest.raises(ParameterError) as exc:
        mass_properties(build_reducer(case.reducer), 7850.0)
    assert "cranks.shaft_length_mm" in str(exc.value)


def test_derived_masses_are_reported_as_derived():
    data = _data("han2023_rv110e")
    data["analyses"] = {"modal": {}}
    data["reducer"]["dynamics"]["disc_mass_kg"] = 2.0
    data["reducer"]["dynamics"]["disc_inertia_kgm2"] = 0.01
    res = run_case(load_case_dict(data), RunOptions(progress=False))
    v = res["modal"].values
    assert v["derived_mass_properties"] == ["sun", "planet", "crank", "output"]
    assert v["mass [kg]"]["disc"] == 2.0
    # a steel cylinder of the pitch diameter m z1 = 30 mm and the 12 mm face width
    assert v["mass [kg]"]["sun"] == pytest.approx(7850.0 * np.pi * 0.015**2 * 0.012, rel=1e-12)


def test_li2023_table2_masses_come_from_the_case():
    data = _data("li2023_rv")
    data["analyses"] = {"modal": {}}
    res = run_case(load_case_dict(data), RunOptions(progress=False))
    v = res["modal"].values
    assert v["derived_mass_properties"] == []
    assert v["mass [kg]"] == {
        "sun": 1.3,
        "planet": 0.88,
        "crank": 0.4,
        "disc": 2.76,
        "output": 15.33,
    }


def test_first_stage_and_output_errors_reach_the_quasi_static_model():
    """Li's sun eccentricity, sun assembly and output assembly errors load the same springs in the
    quasi-static model as in the dynamics (they used to exist in the dynamics only)."""
    from gearte.models.rv_load_sharing import assemble
    from gearte.studies.rv_reducer import build_reducer

    data = _data("li2023_rv_errors")
    red = build_reducer(load_case_dict(data).reducer)
    th = np.array([0.0, 0.3])
    sys = assemble(red, th)
    sun = sys.spring_e[:, sys.labels["sun_support"]]
    main = sys.spring_e[:, sys.labels["main_bearing"]]
    e_sa = 5e-3 * np.array([np.cos(np.radians(100.0)), np.sin(np.radians(100.0))])
    e_o = 38e-3 * np.array([0.0, 1.0])
    np.testing.assert_allclose(sun, -np.tile(e_sa, (2, 1)), atol=1e-15)
    np.testing.assert_allclose(main, -np.tile(e_o, (2, 1)), atol=1e-15)
    # sun eccentricity rotates with the sun (input angle = ratio x output angle) in every mesh
    no_sun = [e for e in data["reducer"]["errors"] if e["part"] != "sun_eccentricity"]
    data["reducer"]["errors"] = no_sun
    sys0 = assemble(build_reducer(load_case_dict(data).reducer), th)
    mesh = sys.labels["mesh"]
    d = sys.spring_e[:, mesh] - sys0.spring_e[:, mesh]
    assert np.all(np.abs(d) > 0) and np.all(np.abs(d) <= 5e-3 + 1e-15)


def test_same_cycloid_stage_in_every_analysis():
    """The reducer's cycloid stage, the cycloid_stage kind's stage and the dynamics' pair share
    K1, the clearance and the curvature at the first contact."""
    from gearte.models.rv_load_sharing import cycloid_stage
    from gearte.studies import cycloid_stage as cs
    from gearte.studies.rv_reducer import build_reducer, build_stage_case

    case = load_case_dict(_data("hu2020_rv80e_initial_reducer"))
    red = build_reducer(case.reducer)
    st_rv = cycloid_stage(red)
    st_kind = cs.build_stage(build_stage_case(case).stage)
    for attr in ("K1", "rho0", "phi0", "backlash_per_flank", "r_c"):
        assert getattr(st_rv, attr) == getattr(st_kind, attr), attr
    assert red.K1 == st_rv.K1


def _han_errors(extra: list[dict], **discs) -> dict:
    data = _data("han2023_rv110e_no_errors")
    data["reducer"]["errors"] = extra
    data["reducer"]["discs"].update(discs)
    return data


def test_disc_profile_errors_change_the_pin_clearances_as_derived():
    """Run-out acts like a translation of the disc's profile, the cumulative pitch deviation
    s(ψ) like a local rotation s/r_c, a modification error like the modification itself."""
    from gearte.models.rv_load_sharing import assemble
    from gearte.studies.rv_reducer import build_reducer

    th = np.array([0.0, 0.7])
    base = assemble(build_reducer(load_case_dict(_han_errors([])).reducer), th)
    runout = {"part": "disc_radial_runout", "disc": 1, "value_um": 10.0, "angle_deg": 0.0}
    sys_r = assemble(build_reducer(load_case_dict(_han_errors([runout])).reducer), th)
    n_pins = 40
    dgap = sys_r.contact_gap - base.contact_gap
    # disc 1 only; its change is -n . (10 um along the disc's x axis turned by th)
    assert np.all(dgap[:, n_pins:] == 0)
    u = 0.010 * np.stack([np.cos(th), np.sin(th)], -1)
    dof = base.layout.disc(0)
    normal = base.contact_B[:, :n_pins, dof : dof + 2]
    np.testing.assert_allclose(dgap[:, :n_pins], -np.sum(normal * u[:, None, :], -1), atol=1e-15)
    pitch = {"part": "disc_cumulative_pitch", "disc": 2, "value_um": 20.0, "angle_deg": 30.0}
    sys_p = assemble(build_reducer(load_case_dict(_han_errors([pitch])).reducer), th)
    dgap = sys_p.contact_gap - base.contact_gap
    assert np.all(dgap[:, :n_pins] == 0) and np.any(dgap[:, n_pins:] != 0)
    # at most the peak deviation (10 um) times the lever/pitch-radius ratio
    assert np.max(np.abs(dgap)) <= 0.010 * 1.1
    mod = build_reducer(
        load_case_dict(_han_errors([], equidistant_modification_errors_um=[5.0, 0.0])).reducer
    )
    dgap = assemble(mod, th).contact_gap - base.contact_gap
    np.testing.assert_allclose(dgap[:, :n_pins], 0.005, atol=1e-15)
    assert np.all(dgap[:, n_pins:] == 0)


def test_disc_profile_errors_raise_peak_pin_load():
    from gearte.models.rv_load_sharing import load_sharing
    from gearte.studies.rv_reducer import build_reducer

    th = np.linspace(0, 2 * np.pi, 12, endpoint=False)
    red0 = build_reducer(load_case_dict(_han_errors([])).reducer)
    runout = {"part": "disc_radial_runout", "disc": 1, "value_um": 15.0, "angle_deg": 0.0}
    red = build_reducer(load_case_dict(_han_errors([runout])).reducer)
    assert (
        load_sharing(red, 1.078e6, th).peak_pin_load > load_sharing(red0, 1.078e6, th).peak_pin_load
    )
