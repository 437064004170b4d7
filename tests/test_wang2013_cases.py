"""Wang 2013 bundled cases through the study kind ``planetary`` and the CLI; case-file errors."""

from __future__ import annotations

import copy
import json
import tomllib

import pytest
from click.testing import CliRunner

from gearte.cases import case_path
from gearte.errors import CaseFileError
from gearte.io.case_file import load_case_dict
from gearte.studies import RunOptions, run_case

NAMES = ("wang2013_2kh_eq9", "wang2013_2kh_derived")
MC_NAMES = ("mc_mean [arcsec]", "mc_sd [arcsec]", "mc_min [arcsec]", "mc_max [arcsec]")


def raw(name: str) -> dict:
    return tomllib.loads(case_path(name).read_text(encoding="utf-8"))


@pytest.fixture(scope="module")
def eq9_result():
    return run_case("wang2013_2kh_eq9", RunOptions(progress=False))


def test_eq9_case_reproduces_the_paper(eq9_result):
    r = eq9_result
    assert r["assembly"]["paper_rule_assembly_te [arcsec]"] == pytest.approx(131.5, abs=0.05)
    ang = r["assembly"]["paper_rule_angles [deg]"]
    assert ang == pytest.approx({"gamma_p": 0.0, "gamma_s": 140.0, "gamma_c": 160.0}, abs=1e-6)
    assert (
        r["assembly"]["optimal_assembly_te [arcsec]"]
        < r["coupled_te"]["coupled_te_amplitude [arcsec]"]
    )
    # Fig 2 (50 000 samples): 111 / 456 / 297 / 70 (tolerances: see test_wang2013_planetary)
    mc = r["mc_random_assembly"]
    assert mc["mc_mean [arcsec]"] == pytest.approx(297, abs=1.5)
    assert mc["mc_sd [arcsec]"] == pytest.approx(70, abs=1.0)
    assert mc["mc_min [arcsec]"] == pytest.approx(111, abs=5.8)
    assert mc["mc_max [arcsec]"] == pytest.approx(456, abs=2.9)
    # Fig 4 (allocated assembly, Rayleigh magnitudes): mean 90, sd 30
    mc4 = r["mc_allocated_assembly_random_magnitudes"]
    assert mc4["mc_mean [arcsec]"] == pytest.approx(90, abs=1.0)
    assert mc4["mc_sd [arcsec]"] == pytest.approx(30, abs=0.8)


def test_result_names_and_json(eq9_result, tmp_path):
    from gearte.report.outputs import write_outputs

    r = eq9_result
    for key in ("coupled_te_amplitude [arcsec]", "coupled_te_peak_to_peak [arcsec]"):
        assert r["coupled_te"][key] > 0
    for key in (
        "optimal_assembly_te [arcsec]",
        "paper_rule_assembly_te [arcsec]",
        "assembly_angles [deg]",
    ):
        assert key in r["assembly"].values
    assert set(r["assembly"]["assembly_angles [deg]"]) == {
        "beta_s",
        "beta_p",
        "gamma_s",
        "gamma_p",
        "gamma_c",
    }
    scen = [a.name for a in r.analyses if a.name.startswith("mc_")]
    assert len(scen) == 5
    for s in scen:
        assert all(k in r[s].values for k in MC_NAMES)
    write_outputs(r, tmp_path)
    d = json.loads((tmp_path / "results.json").read_text())
    assert d["analyses"]["mc_random_assembly"]["values"]["samples"] == 50_000
    assert (tmp_path / "report.html").stat().st_size > 1000


def test_derived_case_runs_through_cli(tmp_path):
    from gearte.cli import main

    res = CliRunner().invoke(
        main, ["run", "wang2013_2kh_derived", "--out", str(tmp_path), "--samples", "2000"]
    )
    assert res.exit_code == 0, res.output
    d = json.loads((tmp_path / "results.json").read_text())
    v = d["analyses"]["assembly"]["values"]
    # derived terms: planet group 2 E_p cos(alpha) = 30.07 µm at 7/24 of the input speed
    g = d["analyses"]["coupled_te"]["values"]["group_amplitude [um]"]
    assert g["7/24"] == pytest.approx(30.07, abs=0.005)
    assert v["optimal_assembly_te [arcsec]"] <= v["paper_rule_assembly_te_exact [arcsec]"]


@pytest.mark.parametrize(
    "path, value, field",
    [
        (("gearset", "z_ring"), 85, "gearset"),
        (("gearset", "n_planets"), 5, "gearset"),
        (("errors", "magnitudes_um", "E_s"), -1.0, "errors.magnitudes_um"),
        (("errors", "magnitudes_um", "E_x"), 1.0, "(case)"),
        (("gearset", "pressure_angle_deg"), 50.0, "gearset.pressure_angle_deg"),
    ],
)
def test_bad_case_values_are_named(path, value, field):
    data = copy.deepcopy(raw("wang2013_2kh_derived"))
    node = data
    for p in path[:-1]:
        node = node[p]
    node[path[-1]] = value
    with pytest.raises(CaseFileError) as err:
        load_case_dict(data)
    fields = [f for f, _ in err.value.errors]
    assert fields[0] == field
    assert str(value) in str(err.value) or path[-1] in str(err.value)


def test_mean_planet_model_case_runs():
    """planet_model = 'mean': per-planet keys, sun/ring/carrier terms average out."""
    data = copy.deepcopy(raw("wang2013_2kh_derived"))
    data["errors"]["planet_model"] = "mean"
    data["errors"]["magnitudes_um"].pop("E_p")
    data["errors"]["magnitudes_um"].update({"E_p1": 16.0, "E_p2": 10.0, "E_p3": 4.0})
    data["analyses"]["monte_carlo"]["samples"] = 2000
    data["analyses"]["monte_carlo"]["scenarios"] = ["random_assembly"]
    data["analyses"]["coupled_te"]["assembly"] = "given"
    data["analyses"]["assembly"] = {"starts": 256, "polish": 1}
    r = run_case(load_case_dict(data), RunOptions(progress=False))
    g = r["coupled_te"]["group_amplitude [um]"]
    # only the planets' 7/24 group and their pin errors survive (sun/ring/carrier cancel)
    assert set(g) == {"1/8", "7/24", "7/8"}
    assert g["1/8"] < 1e-12 and g["7/8"] < 1e-12
    assert r["mc_random_assembly"]["samples"] == 2000
