"""The RV first stage reuses the planetary kind's gear set (issue 11 item 2).

Both :class:`gearte.geometry.planetary.PlanetarySet` (the ``planetary`` kind) and
:class:`gearte.geometry.rv.FirstStage` hold a :class:`gearte.geometry.planetary.SunPlanets`
(sun + planets, a ring optional): one class, one validation, one set of derived quantities.
"""

from __future__ import annotations

import dataclasses
import tomllib

import numpy as np
import pytest

from gearte.cases import case_path
from gearte.errors import CaseFileError, ParameterError
from gearte.geometry.planetary import PlanetarySet, SunPlanets
from gearte.geometry.rv import FirstStage
from gearte.io.case_file import load_case, load_case_dict
from gearte.studies.rv_reducer import build_reducer
from gearte.units import deg_to_rad


def test_rv_first_stage_and_planetary_set_share_one_gear_set_li2023():
    red = build_reducer(load_case("li2023_rv").reducer)
    g = red.first_stage.gears
    pset = PlanetarySet(
        z_sun=g.z_sun,
        z_planet=g.z_planet,
        z_ring=g.z_sun + 2 * g.z_planet,
        module=g.module,
        pressure_angle=g.pressure_angle,
        n_planets=g.n_planets,
    )
    assert type(pset.gears) is type(g) is SunPlanets
    assert dataclasses.replace(pset.gears, z_ring=None) == g  # same numbers, same object
    assert pset.centre_distance == g.centre_distance == red.cranks.circle_radius
    np.testing.assert_array_equal(pset.eta, g.eta)
    assert red.first_stage.base_radii == (pset.base_radius("sun"), pset.base_radius("planet"))
    with pytest.raises(ParameterError, match="no ring"):
        g.base_radius("ring")


def test_gear_set_checks_give_the_same_message_in_both_kinds():
    """Four planets of 12/36, m = 1.5 overlap: the same refusal from the planetary set, the
    gear set of an RV first stage, and an ``rv_reducer`` case (named by its key there)."""
    nums = dict(z_sun=12, z_planet=36, module=1.5, pressure_angle=deg_to_rad(20.0), n_planets=4)
    with pytest.raises(ParameterError) as planetary:
        PlanetarySet(z_ring=84, **nums)
    with pytest.raises(ParameterError) as rv:
        FirstStage(SunPlanets(**nums), 2e5, 5e4)
    assert planetary.value.reason == rv.value.reason
    assert "neighbouring planets overlap" in rv.value.reason
    data = tomllib.loads(case_path("li2023_rv").read_text(encoding="utf-8"))
    data["case"]["name"] = "four_planets"
    data["reducer"]["first_stage"]["planets"] = 4
    data["reducer"]["cranks"]["count"] = 4
    with pytest.raises(CaseFileError) as case:
        load_case_dict(data)
    assert f"first_stage.planets = 4: {rv.value.reason}" in str(case.value)


def test_rv_first_stage_has_no_ring():
    with pytest.raises(ParameterError, match="no ring"):
        FirstStage(SunPlanets(12, 36, 1.5, deg_to_rad(20.0), z_ring=84), 2e5, 5e4)
