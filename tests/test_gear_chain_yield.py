"""``[analyses.yield]`` of a gear chain: stage lost-motion distributions combined by Monte-Carlo."""

from __future__ import annotations

import tomllib

import pytest

import gearte
from gearte.cases import case_path
from gearte.io.case_file import load_case_dict
from gearte.studies import RunOptions
from gearte.tolerance.stackup import z_for_confidence


def _shoulder_swing(yield_section: dict):
    data = tomllib.loads(case_path("jiang2024_shoulder_swing").read_text())
    data["analyses"] = {"yield": yield_section}
    return gearte.run_case(load_case_dict(data, name="chain_yield"), RunOptions(progress=False))


def test_chain_yield_joint_distribution_matches_the_statistical_combination_jiang2024():
    """jiang2024_shoulder_swing: the planetary stage is constant at its 1′ maximum, the spur and
    bevel stages normal about their mean backlash with σ = (max − min)/(2z) (Tables 4 and 8
    through eq. 14/29). 40 000 drawn chains: the joint's mean and mean + z·σ equal the chain
    analysis' linear combination (``joint_lost_motion_statistical_max``) to 1 %, no stage
    interferes, so eq. (30)'s clipping at zero does not act."""
    res = _shoulder_swing({"samples": 40_000, "seed": 3, "chunk_size": 10_000})
    y = res["yield"]
    q = y["quantities"]["joint_lost_motion [arcmin]"]
    chain = res["chain"]
    z = z_for_confidence(0.9973)
    assert q["mean"] + z * q["sd"] == pytest.approx(
        chain["joint_lost_motion_statistical_max [arcmin]"], rel=0.01
    )
    # the mean: planetary at its maximum / 3.929 plus the pairs' means at the joint
    mean = 1.0 / 3.929 + res["spur_pair_backlash"]["lost_motion_mean [arcmin]"]
    mean += res["bevel_pair_backlash"]["lost_motion_mean [arcmin]"]
    assert q["mean"] == pytest.approx(mean, rel=0.005)
    assert y["tolerances"]["planetary reducer"]["kind"] == "constant"


def test_chain_yield_spec_and_a_stage_tolerance_from_the_section():
    """A spec on the joint's lost motion gives a yield with its interval; a tolerance given in
    the section replaces the stage's own law (here the planetary stage ±0.3′ about 0.7′)."""
    res = _shoulder_swing(
        {
            "samples": 4000,
            "seed": 1,
            "tolerances": {
                "planetary reducer": {"kind": "normal", "tolerance_arcmin": 0.3,
                                      "nominal_arcmin": 0.7},
            },
            "spec": {"joint_lost_motion [arcmin]": {"upper": 9.0}},
        }
    )  # fmt: skip
    y = res["yield"]
    assert 0.0 < y["yield_ci_low"] <= y["yield"] <= y["yield_ci_high"] <= 1.0
    assert y["tolerances"]["planetary reducer"]["nominal"] == 0.7
