"""``[analyses.yield]`` of a gear chain (gearte.runners.chain_yield, gearte.studies.gear_chain):
each stage's lost motion drawn from its own tolerances, combined at the joint sample by sample."""

from __future__ import annotations

import math
import tomllib

import numpy as np
import pytest

import gearte
from gearte.cases import case_path
from gearte.errors import CaseFileError, ParameterError
from gearte.io.case_file import load_case_dict
from gearte.runners.chain_yield import ChainStage, GearChainYield, PairLostMotion, StageTerm
from gearte.studies import RunOptions
from gearte.units import rad_to_arcmin

OPTS = RunOptions(progress=False)


def _spur_and_given(samples: int = 20_000, **yield_extra) -> dict:
    """robot_joint_spur_rv_yield's spur pair (Jiang 2024 Tables 1–2) followed by a stage given by
    its maker's lost motion (1′, Jiang's planetary) instead of the RV reducer (fast)."""
    data = tomllib.loads(case_path("robot_joint_spur_rv_yield").read_text())
    data["chain"]["stages"][1] = {"name": "planetary", "ratio": 81.0, "lost_motion_max_arcmin": 1.0}
    data["analyses"]["yield"].update(samples=samples, sobol_samples=0, **yield_extra)
    data["analyses"]["yield"]["spec"] = {"joint_lost_motion [arcmin]": {"upper": 1.02}}
    return data


def test_chain_yield_spur_stage_reproduces_its_backlash_stack_and_eq30_at_the_joint():
    """The spur stage's Monte-Carlo lost motion has the mean and σ of the pair's own linear stack
    (Jiang 2024 eqs. 2–14: normals and Rayleigh magnitudes with uniform direction, r sin φ being
    exactly normal) within 4 standard errors; the joint is eq. (30) sample by sample: given
    1′ + spur / 81, so its mean and σ follow from the stage's."""
    data = _spur_and_given()
    res = gearte.run_case(load_case_dict(data, name="chain_yield"), OPTS)
    q = res["yield"].values["quantities"]
    spread = res["spur_pair_drive"].values
    mean, sd = spread["lost_motion_mean [arcmin]"], spread["lost_motion_sd [arcmin]"]
    n = 20_000
    assert q["spur_pair.lost_motion [arcmin]"]["mean"] == pytest.approx(
        mean, abs=4 * sd / math.sqrt(n)
    )
    assert q["spur_pair.lost_motion [arcmin]"]["sd"] == pytest.approx(sd, rel=4 / math.sqrt(2 * n))
    j = q["joint_lost_motion [arcmin]"]
    assert j["mean"] == pytest.approx(1.0 + q["spur_pair.lost_motion [arcmin]"]["mean"] / 81.0)
    assert j["sd"] == pytest.approx(q["spur_pair.lost_motion [arcmin]"]["sd"] / 81.0, rel=1e-6)
    assert 0.0 < res["yield"].values["yield"] < 1.0


def test_chain_yield_grade_of_a_spur_gear_eccentricity_is_its_iso1328_2_radial_composite():
    """``grade = 5`` on the driven gear (m 2.5, z 110, d 275 mm): ISO 1328-2:1997 F_i″ =
    (3.2·2.5 + 1.01·√275 + 6.4)·√2^0 = 31.15 → 31 µm (rounded to 1 µm above 10 µm): the
    tolerance the yield uses (Jiang's Table 1 value); grade 7 doubles the unrounded value
    (62.3 → 62 µm)."""
    data = _spur_and_given(samples=10)
    res = gearte.run_case(load_case_dict(data, name="chain_grade"), OPTS)
    tol = res["yield"].values["tolerances"]["spur_pair.driven_gear_eccentricity"]
    assert tol["tolerance"] == 31.0
    assert tol["grade"] == 5  # reported as derived, naming the standard
    assert tol["derived_from"].startswith("ISO 1328-2:1997 radial composite, grade 5, driven gear")
    data["analyses"]["yield"]["tolerances"]["spur_pair.driven_gear_eccentricity"]["grade"] = 7
    res = gearte.run_case(load_case_dict(data, name="chain_grade7"), OPTS)
    assert (
        res["yield"].values["tolerances"]["spur_pair.driven_gear_eccentricity"]["tolerance"] == 62.0
    )


def test_chain_yield_zero_tolerances_give_the_deterministic_stack_mean():
    """Every tolerance of the spur stage at zero: each sample is the stack's nominal backlash and
    the joint its deterministic value (given + return error of the mean backlash / 81)."""
    data = _spur_and_given(samples=5)
    keys = [
        "driving_gear_tooth_thickness",
        "driven_gear_tooth_thickness",
        "centre_distance",
        "bearing_radial_clearance",
    ]
    tols = {f"spur_pair.{k}": {"kind": "normal", "tolerance_um": 0.0} for k in keys}
    for k in ("driving_gear_eccentricity", "driven_gear_eccentricity", "reducer_output_runout"):
        tols[f"spur_pair.{k}"] = {"kind": "rayleigh", "tolerance_um": 0.0, "phase": True}
    data["analyses"]["yield"]["tolerances"] = tols
    res = gearte.run_case(load_case_dict(data, name="chain_zero"), OPTS)
    q = res["yield"].values["quantities"]["joint_lost_motion [arcmin]"]
    spur = res["spur_pair_drive"].values["lost_motion_mean [arcmin]"]
    assert q["min"] == q["max"] == pytest.approx(1.0 + spur / 81.0, rel=1e-12)


def test_chain_yield_unknown_tolerance_key_is_an_error_naming_it():
    data = _spur_and_given(samples=5)
    data["analyses"]["yield"]["tolerances"]["spur_pair.tooth_thicknes"] = {"tolerance_um": 3.0}
    with pytest.raises((ParameterError, CaseFileError), match="spur_pair.tooth_thicknes"):
        gearte.run_case(load_case_dict(data, name="chain_bad"), OPTS)


def test_chain_yield_model_interfering_pair_has_zero_lost_motion_not_negative():
    """A drawn backlash below zero (parts interfere) is no lost motion (eq. 14 on max(jn, 0))."""
    st = ChainStage(
        "p", "p", 2.0, PairLostMotion((StageTerm("p.x", 1.0),), 100.0, math.radians(20))
    )
    model = GearChainYield([st], {}, 500.0)
    out = model({"p.x": np.array([-10.0, 10.0])})
    lm = out["p.lost_motion [arcmin]"]
    assert lm[0] == 0.0
    assert lm[1] == pytest.approx(rad_to_arcmin(2 * 0.010 / (100.0 * math.cos(math.radians(20)))))
    assert out["end_effector_error [mm]"][1] == pytest.approx(
        2 * 0.010 / (100.0 * math.cos(math.radians(20))) * 500.0
    )


def test_chain_yield_worst_sample_case_file_reproduces_that_sample(tmp_path):
    """The worst chain is written as a case file (every error constant at its drawn value, a
    radial one as r sin φ); run on its own it gives that sample's joint lost motion."""
    data = _spur_and_given(samples=2000, keep_worst=1)
    res = gearte.run_case(load_case_dict(data, name="chain_worst"), OPTS)
    worst = res["yield"].values["worst_samples"][0]
    text = res["yield"].files["worst_sample_1.toml"]
    again = gearte.run_case(load_case_dict(tomllib.loads(text), name="again"), OPTS)
    q = again["yield"].values["quantities"]["joint_lost_motion [arcmin]"]
    assert (
        q["min"]
        == q["max"]
        == pytest.approx(worst["values"]["joint_lost_motion [arcmin]"], rel=1e-12)
    )
