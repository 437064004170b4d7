"""The RV first stage's backlash in the catalogue test and the yield (first_stage_backlash)."""

from __future__ import annotations

import math
import tomllib

import numpy as np
import pytest

from gearte import run_case
from gearte.cases import case_path
from gearte.errors import CaseFileError
from gearte.io.case_file import load_case, load_case_dict
from gearte.models.rv_first_stage import mesh_backlash, output_free_angle, with_dead_zone
from gearte.studies import RunOptions
from gearte.units import rad_to_arcmin

#: han2023_rv110e: m 1.5, z 20/40 → r_sun 15 mm; 40 pins → i = 1 + 40·40/20 = 81.
R_SUN, RATIO = 15.0, 81.0


def _catalogue_case(**first_stage) -> dict:
    data = tomllib.loads(case_path("han2023_rv110e").read_text())
    data["analyses"] = {"catalogue": {"steps_per_segment": 2}}
    data["reducer"]["first_stage"].update(first_stage)
    return data


def _catalogue(data) -> dict:
    return run_case(load_case_dict(data, name="fs"), RunOptions(progress=False))["catalogue"].values


def test_output_free_angle_is_the_smallest_mesh_gap_over_r_sun_times_ratio_by_hand():
    """Gaps 50, 30, 40 µm: the cranks turn together, the 30 µm mesh stops them:
    0.030 mm / (15 mm · 81) = 2.469e-5 rad; an interfering mesh leaves no free play."""
    got = output_free_angle([[0.05, 0.03, 0.04], [0.05, -0.01, 0.04]], R_SUN, RATIO)
    assert got == pytest.approx([0.03 / (R_SUN * RATIO), 0.0])


def test_mesh_backlash_from_thickness_and_centre_distance_deviations_by_hand():
    """E_sun −60, E_planet −90/−80 µm, A_a +8/−8 µm, α 20°:
    j = 150 + 16 tan 20° = 155.82 µm and 140 − 16 tan 20° = 134.18 µm."""
    t = math.tan(math.radians(20.0))
    j = mesh_backlash([0.0, 0.0], -0.060, [-0.090, -0.080], [0.008, -0.008], math.radians(20))
    assert j == pytest.approx([0.150 + 0.016 * t, 0.140 - 0.016 * t])


def test_dead_zone_shifts_each_side_by_half_and_zero_torque_by_where_it_comes_from():
    got = with_dead_zone([1.0, 0.0, -1.0, 0.0], [0.1, 0.0, -0.1, 0.0], [-1, -1, 1, 1], 0.02)
    assert got == pytest.approx([0.11, 0.01, -0.11, -0.01])


def test_catalogue_raw_first_stage_backlash_adds_its_closed_form_at_the_output():
    """backlash_um = [60, 40, 50]: lost motion, backlash and hysteresis grow by
    0.040 mm / (15 mm · 81) = 0.1132′ exactly; rigidity does not change."""
    base = _catalogue(_catalogue_case())
    got = _catalogue(_catalogue_case(backlash_um=[60.0, 40.0, 50.0]))
    add = rad_to_arcmin(0.040 / (R_SUN * RATIO))
    assert add == pytest.approx(0.11317, abs=1e-5)
    assert got["first_stage_backlash"] == "additive" == base["first_stage_backlash"]
    assert got["first_stage_backlash_at_output [arcmin]"] == pytest.approx(add)
    for k in ("lost_motion [arcmin]", "backlash [arcmin]", "hysteresis_loss [arcmin]"):
        assert got[k] == pytest.approx(base[k] + add, abs=1e-9)
    rig = "torsional_rigidity [N*m/arcmin]"
    assert got[rig] == pytest.approx(base[rig], rel=1e-12)


def test_catalogue_zero_first_stage_backlash_or_ignored_leaves_the_values_unchanged():
    base = _catalogue(_catalogue_case())
    zero = _catalogue(_catalogue_case(backlash_um=0.0))
    ignored = _catalogue_case(backlash_um=80.0)
    ignored["analyses"]["catalogue"]["first_stage_backlash"] = "ignored"
    ign = _catalogue(ignored)
    assert ign["first_stage_backlash"] == "ignored"
    assert "first_stage_backlash_at_output [arcmin]" not in ign
    for k in ("lost_motion [arcmin]", "backlash [arcmin]", "torsional_rigidity [N*m/arcmin]"):
        assert zero[k] == pytest.approx(base[k], abs=1e-12)
        assert ign[k] == base[k]


def test_catalogue_with_classes_adds_the_class_midpoint_and_gives_the_limits_by_hand():
    """cd25/cd25/js6 (test_grade_input): j_t 118.18 … 199.82 µm, midpoint 159 µm (js field
    symmetric): at the output 0.4497′, limits 0.334′ … 0.565′."""
    base = _catalogue(_catalogue_case())
    got = _catalogue(
        _catalogue_case(
            sun_tooth_thickness_allowance="cd25",
            planet_tooth_thickness_allowance="cd25",
            centre_distance_allowance="js6",
        )
    )
    t = math.tan(math.radians(20.0))
    mid, lo, hi = (
        rad_to_arcmin(j * 1e-3 / (R_SUN * RATIO)) for j in (159, 124 - 16 * t, 194 + 16 * t)
    )
    assert got["first_stage_backlash_at_output [arcmin]"] == pytest.approx(mid)
    assert got["first_stage_backlash_at_output_min [arcmin]"] == pytest.approx(lo)
    assert got["first_stage_backlash_at_output_max [arcmin]"] == pytest.approx(hi)
    lm = "lost_motion [arcmin]"
    assert got[lm] == pytest.approx(base[lm] + mid, abs=1e-9)
    assert got["lost_motion_max [arcmin]"] == pytest.approx(base[lm] + hi, abs=1e-9)


@pytest.mark.parametrize(
    ("keys", "message"),
    [
        (
            {
                "backlash_um": 40.0,
                "sun_tooth_thickness_allowance": "cd25",
                "planet_tooth_thickness_allowance": "cd25",
                "centre_distance_allowance": "js6",
            },
            "not both",
        ),
        ({"backlash_um": [40.0, 50.0]}, "one per planet"),
        ({"backlash_um": 1e5}, "backlash_um"),
    ],
)
def test_first_stage_backlash_input_errors_name_the_key(keys, message):
    with pytest.raises(CaseFileError, match=message):
        load_case(_catalogue_case(**keys))


def _yield_case(**first_stage) -> dict:
    data = tomllib.loads(case_path("han2023_rv110e_yield").read_text())
    data["analyses"]["yield"].update(samples=6, chunk_size=3, sobol_samples=0, keep_worst=1)
    data["reducer"]["first_stage"].update(first_stage)
    return data


def test_yield_draws_the_first_stage_classes_and_adds_them_to_each_sample(tmp_path):
    """With cd25/cd25/js6 the first-stage deviations become tolerances (truncated normal within
    the class limits: 3σ = half the width, nominal the midpoint); a sample's lost motion is the
    same reducer's without them plus min_k j_t,k / (r_sun i); the worst sample's case file
    (first-stage backlash_um written) reproduces it when run alone."""
    import gearte
    from gearte.runners.yield_models import RVReducerYield
    from gearte.studies.rv_reducer import build_reducer

    classes = dict(
        sun_tooth_thickness_allowance="cd25",
        planet_tooth_thickness_allowance="cd25",
        centre_distance_allowance="js6",
    )
    case = load_case_dict(_yield_case(**classes), name="y")
    res = gearte.run_case(case, RunOptions(progress=False))
    y = res["yield"]
    tol = y.values["tolerances"]
    assert tol["first_stage.sun_thickness"] == {
        "kind": "truncated_normal",
        "tolerance": 15.0,
        "nominal": -69.0,
    }
    assert tol["first_stage.planet_thickness"]["nominal"] == -90.0
    assert tol["first_stage.centre_distance"]["tolerance"] == 8.0
    assert y.values["first_stage_backlash"] == "additive"
    q, lm = "first_stage_backlash_at_output [arcmin]", "lost_motion [arcmin]"
    st = y.values["quantities"]
    t = math.tan(math.radians(20))
    lo, hi = (rad_to_arcmin(j * 1e-3 / (R_SUN * RATIO)) for j in (124 - 16 * t, 194 + 16 * t))
    assert lo <= st[q]["min"] < st[q]["max"] <= hi
    worst = y.values["worst_samples"][0]
    errors = worst["errors"]
    j = [
        -(errors["first_stage.sun_thickness"] + errors[f"first_stage.planet_thickness.c{i}"])
        + 2 * errors[f"first_stage.centre_distance.c{i}"] * t
        for i in (1, 2, 3)
    ]
    add = rad_to_arcmin(min(j) * 1e-3 / (R_SUN * RATIO))
    assert worst["values"][q] == pytest.approx(add)
    inner = RVReducerYield(build_reducer(case.reducer), positions=36)
    rest = {k: np.array([v]) for k, v in errors.items() if not k.startswith("first_stage.")}
    assert worst["values"][lm] == pytest.approx(float(inner(rest)[lm][0]) + add, rel=1e-9)
    gearte.write_outputs(res, tmp_path / "out")
    alone = gearte.run_case(gearte.load_case(tmp_path / "out" / "worst_sample_1.toml"))
    assert alone["catalogue"]["first_stage_backlash_at_output [arcmin]"] == pytest.approx(add)
    assert alone["catalogue"][lm] == pytest.approx(worst["values"][lm], rel=1e-6)


def test_yield_without_first_stage_input_or_ignored_draws_no_first_stage_tolerance():
    data = _yield_case(
        sun_tooth_thickness_allowance="cd25",
        planet_tooth_thickness_allowance="cd25",
        centre_distance_allowance="js6",
    )
    data["analyses"]["yield"].update(first_stage_backlash="ignored", samples=2, keep_worst=0)
    ign = run_case(load_case_dict(data, name="y0"), RunOptions(progress=False))["yield"]
    assert ign.values["first_stage_backlash"] == "ignored"
    assert not any(k.startswith("first_stage") for k in ign.values["tolerances"])
    assert "first_stage_backlash_at_output [arcmin]" not in ign.values["quantities"]


def test_yield_with_raw_first_stage_backlash_adds_the_same_closed_form_to_every_sample():
    data = _yield_case(backlash_um=[60.0, 40.0, 50.0])
    data["analyses"]["yield"].update(samples=2, chunk_size=2, keep_worst=0)
    y = run_case(load_case_dict(data, name="yraw"), RunOptions(progress=False))["yield"]
    st = y.values["quantities"]["first_stage_backlash_at_output [arcmin]"]
    add = rad_to_arcmin(0.040 / (R_SUN * RATIO))
    assert st["min"] == pytest.approx(add) and st["max"] == pytest.approx(add)


def test_bundled_first_stage_example_adds_its_f24_js5_midpoint_to_the_catalogue():
    """han2023_rv110e_first_stage_yield (catalogue only here): f24/f24/js5 → j_t midpoint
    (14 + 34 + 19 + 44)/2 = 55.5 µm → 0.0555 / (15 · 81) rad = 0.1570′ at the output."""
    data = tomllib.loads(case_path("han2023_rv110e_first_stage_yield").read_text())
    data["analyses"].pop("yield")
    data["analyses"]["catalogue"]["steps_per_segment"] = 2
    v = _catalogue(data)
    assert v["first_stage_backlash"] == "additive"
    assert v["first_stage_backlash_at_output [arcmin]"] == pytest.approx(
        rad_to_arcmin(0.0555 / (R_SUN * RATIO))
    )
    assert v["lost_motion_min [arcmin]"] < v["lost_motion [arcmin]"] < v["lost_motion_max [arcmin]"]


def test_rv_drive_of_a_chain_takes_the_first_stage_backlash_like_the_catalogue_analysis():
    """A gear chain's RV stage (drive_from_case) has the rv_reducer catalogue's lost motion with
    the first stage's free angle; first_stage_backlash = 'ignored' leaves it out."""
    from gearte.studies._drives import drive_from_case
    from gearte.units import rad_to_arcmin as arcmin

    data = _catalogue_case(backlash_um=[60.0, 40.0, 50.0])
    cat = _catalogue(data)
    drive = drive_from_case(load_case_dict(data, name="fs"))
    assert arcmin(drive.lost_motion()) == pytest.approx(cat["lost_motion [arcmin]"], rel=1e-12)
    data["analyses"]["catalogue"]["first_stage_backlash"] = "ignored"
    plain = drive_from_case(load_case_dict(data, name="fs"))
    add = rad_to_arcmin(0.040 / (R_SUN * RATIO))
    assert arcmin(plain.lost_motion()) == pytest.approx(cat["lost_motion [arcmin]"] - add)
