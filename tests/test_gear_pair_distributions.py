"""Case-file distribution overrides of a pair's sources (uniform, truncated, measured parts)."""

from __future__ import annotations

import math
import tomllib

import pytest

from gearte.cases import case_path
from gearte.errors import CaseFileError
from gearte.io.case_file import load_case
from gearte.models.backlash import BEVEL_SOURCES, SPUR_SOURCES
from gearte.studies import RunOptions, run_case
from jiang2024_data import bevel_pair, spur_pair


def _spur(**dists):
    d = tomllib.loads(case_path("jiang2024_spur_pair").read_text())
    d["pair"]["distributions"] = dists
    d["analysis"]["sobol_samples"] = 0
    return d


def test_source_names_match_stacks():
    assert tuple(spur_pair().backlash_stack().names) == SPUR_SOURCES
    assert tuple(bevel_pair().backlash_stack().names) == BEVEL_SOURCES


def test_uniform_centre_distance_changes_the_variance():
    d = _spur(**{"centre distance": {"kind": "uniform", "lower_um": -20.0, "upper_um": 20.0}})
    r = run_case(d, RunOptions(progress=False, samples=200_000))
    var = r["backlash"].values["backlash_variance_by_source [um2]"]["centre distance"]
    assert var == pytest.approx(40.0**2 / 12 * (2 * math.sin(math.radians(20))) ** 2)
    mc = r["monte_carlo"].values
    assert mc["engine"] == "numba"
    assert abs(mc["mean_difference_in_standard_errors"]) < 4


def test_truncated_and_measured_sources_run_on_numpy_path():
    d = _spur(
        **{
            "driving gear tooth thickness": {
                "kind": "truncated_normal",
                "lower_um": -30.0,
                "upper_um": -19.0,
            },
            "driven gear eccentricity": {
                "kind": "empirical",
                "values_um": [3.0, 5.5, 4.0, 7.2, 2.1, 6.0, 4.4],
            },
        }
    )
    r = run_case(d, RunOptions(progress=False, samples=200_000))
    mc = r["monte_carlo"].values
    assert mc["engine"] == "numpy"
    assert abs(mc["mean_difference_in_standard_errors"]) < 4
    assert abs(mc["sd_relative_difference"]) < 0.02
    # measured eccentricities are far below F''i/6-Rayleigh ones: smaller spread than the paper's
    base = run_case(_spur(), RunOptions(progress=False, samples=0))
    assert r["backlash"].values["backlash_sd [um]"] < base["backlash"].values["backlash_sd [um]"]


def test_bad_distribution_overrides_name_the_field():
    with pytest.raises(CaseFileError, match="unknown source"):
        load_case(_spur(**{"centre distanse": {"kind": "uniform", "lower_um": 0, "upper_um": 1}}))
    with pytest.raises(CaseFileError, match="inverted limits"):
        load_case(_spur(**{"centre distance": {"kind": "uniform", "lower_um": 5, "upper_um": 1}}))
    with pytest.raises(CaseFileError, match="scale_um"):
        load_case(_spur(**{"reducer output runout": {"kind": "rayleigh", "scale_um": 0.0}}))
    with pytest.raises(CaseFileError, match="values_um"):
        load_case(_spur(**{"centre distance": {"kind": "empirical", "values_um": [1.0]}}))


def test_upper_spec_gives_cp_and_out_of_spec():
    d = _spur()
    d["analysis"]["max_backlash_limit_um"] = 70.0
    v = run_case(d, RunOptions(progress=False, samples=400_000))["monte_carlo"].values
    from scipy.stats import norm

    mu, sd = 53.397, 7.216
    assert v["cp"] == pytest.approx((70.0 - 15.0) / (6 * sd), rel=0.01)
    assert v["cpk"] == pytest.approx((70.0 - mu) / (3 * sd), rel=0.01)
    p = norm.sf((70.0 - mu) / sd)
    assert v["fraction_above_max_limit"] == pytest.approx(p, abs=4 * (p / 400_000) ** 0.5)
    d["analysis"]["max_backlash_limit_um"] = 10.0
    with pytest.raises(CaseFileError, match="max_backlash_limit_um"):
        run_case(d, RunOptions(progress=False, samples=1000))
