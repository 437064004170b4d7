"""Case files may give an accuracy grade instead of raw tolerance numbers (``grade = N``)."""

from __future__ import annotations

import math
import tomllib

import pytest

from gearte.cases import case_path
from gearte.errors import CaseFileError
from gearte.io.case_file import load_case


def _spur_case(**driving):
    data = tomllib.loads(case_path("jiang2024_spur_pair").read_text())
    data["pair"]["driving"].pop("radial_composite_tol_um")
    data["pair"]["driving"].update(driving)
    return data


def test_spur_gear_grade5_gives_iso1328_2_radial_composite_by_hand():
    """z 28, m 2.5 → d 70 mm; F''i = (3.2·2.5 + 1.01·√70 + 6.4) = 22.85 → 23 µm (grade 5)."""
    case = load_case(_spur_case(grade=5))
    pair = case.pair.build()
    assert 3.2 * 2.5 + 1.01 * math.sqrt(70) + 6.4 == pytest.approx(22.85, abs=0.01)
    assert pair.driving.radial_composite_tol == pytest.approx(0.023)


def test_grade_and_raw_number_together_is_an_error():
    with pytest.raises(CaseFileError, match="exactly one of radial_composite_tol_um and grade"):
        load_case(_spur_case(grade=5, radial_composite_tol_um=27.0))


def test_grade_out_of_range_is_an_error_naming_the_field():
    with pytest.raises(CaseFileError, match="grade"):
        load_case(_spur_case(grade=13))


# --- DIN 3967 tooth-thickness classes and ISO 286 js fields (gearte.tolerance.din3967/iso286) --


def _class_case(driving: str | None = "cd25", driven: str | None = "cd25", js: str | None = "js7"):
    """jiang2024_spur_pair with its raw thickness/centre-distance numbers replaced by classes."""
    data = tomllib.loads(case_path("jiang2024_spur_pair").read_text())
    for name, cls in (("driving", driving), ("driven", driven)):
        if cls is not None:
            data["pair"][name].pop("thickness_upper_um")
            data["pair"][name].pop("thickness_lower_um")
            data["pair"][name]["tooth_thickness_allowance"] = cls
    if js is not None:
        data["pair"].pop("centre_distance_tol_um")
        data["pair"]["centre_distance_allowance"] = js
    return data


def test_din3967_class_cd25_and_js7_give_the_tables_values_on_jiangs_pair():
    """z 28/110, m 2.5: d 70 mm → cd25 −70/−110 µm; d 275 mm → −95/−145 µm (DIN 3967 Tables
    1–2); a = 172.5 mm → js7 = ±IT7/2 = ±40/2 = ±20 µm, Jiang's Table 2 value. The built pair
    equals the one given those numbers raw."""
    pair = load_case(_class_case()).pair.build()
    assert (pair.driving.thickness_upper, pair.driving.thickness_lower) == (-0.070, -0.110)
    assert (pair.driven.thickness_upper, pair.driven.thickness_lower) == (-0.095, -0.145)
    assert pair.centre_distance_tol == pytest.approx(0.020)
    raw = _class_case(None, None, None)
    raw["pair"]["driving"].update(thickness_upper_um=-70.0, thickness_lower_um=-110.0)
    raw["pair"]["driven"].update(thickness_upper_um=-95.0, thickness_lower_um=-145.0)
    assert load_case(raw).pair.build() == pair


def test_din3967_class_gives_the_backlash_limits_in_the_result_by_hand():
    """Allowances alone: j_n,min = (70 + 95)·cos 20° − 2·20·sin 20° = 141.37 µm, j_n,max =
    (110 + 145)·cos 20° + 2·20·sin 20° = 253.30 µm; j_t = j_n / cos 20°."""
    from gearte import run_case
    from gearte.studies import RunOptions

    data = _class_case()
    data["analysis"].update(monte_carlo_samples=0, sobol_samples=0)
    v = run_case(load_case(data), RunOptions(progress=False))["backlash"].values
    c, s = math.cos(math.radians(20.0)), math.sin(math.radians(20.0))
    assert v["allowance_backlash_normal_min [um]"] == pytest.approx(165 * c - 40 * s)
    assert v["allowance_backlash_normal_max [um]"] == pytest.approx(255 * c + 40 * s)
    assert v["allowance_backlash_circumferential_max [um]"] == pytest.approx(255 + 40 * s / c)
    assert v["tolerance_classes"] == {"driving": "cd25", "driven": "cd25", "centre_distance": "js7"}
    assert v["thickness_limits [um]"]["driven"] == [-95.0, -145.0]
    # the Jiang stack's mean is the midpoints': −(−90 − 120)·cos 20° = 197.3 µm (+ clearance)
    assert v["backlash_mean_by_source [um]"]["driving gear tooth thickness"] == pytest.approx(
        90 * c
    )


@pytest.mark.parametrize(
    ("change", "message"),
    [
        ({"driving": "xy25"}, r"pair\.driving\.tooth_thickness_allowance.*DIN 3967"),
        ({"driving": "cd31"}, r"pair\.driving\.tooth_thickness_allowance.*21 to 30"),
        ({"js": "h7"}, r"pair\.centre_distance_allowance.*js5"),
        ({"js": "js4"}, r"pair\.centre_distance_allowance.*js5"),
    ],
)
def test_din3967_unknown_class_or_field_is_an_error_naming_the_key(change, message):
    with pytest.raises(CaseFileError, match=message):
        load_case(_class_case(**change))


def test_din3967_class_and_raw_numbers_together_or_neither_is_an_error():
    data = _class_case()
    data["pair"]["driving"]["thickness_upper_um"] = -19.0
    with pytest.raises(CaseFileError, match="either tooth_thickness_allowance or thickness_"):
        load_case(data)
    data = _class_case()
    data["pair"]["driving"].pop("tooth_thickness_allowance")
    with pytest.raises(CaseFileError, match="or tooth_thickness_allowance"):
        load_case(data)
    data = _class_case()
    data["pair"]["centre_distance_tol_um"] = 20.0
    with pytest.raises(CaseFileError, match="exactly one of centre_distance_tol_um and centre_"):
        load_case(data)


def test_din3967_class_outside_the_tables_is_an_error_naming_the_gear():
    """m 100, z 110 → d = 11 000 mm > 10 000 mm: DIN 3967's tables end there."""
    data = _class_case(js=None)
    data["pair"]["module_mm"] = 100.0
    with pytest.raises(CaseFileError, match=r"driven\.tooth_thickness_allowance.*not extrapolated"):
        load_case(data)


def test_din3967_class_on_a_gear_chain_spur_stage_sets_the_yield_tolerances():
    """robot_joint_spur_rv_yield's spur stage (Jiang's pair) given cd25/cd25/js7: the chain
    yield draws each gear's thickness normal about the class midpoint (−90 µm, −120 µm) with
    3σ = T_sn/2 (20 µm, 25 µm) and the centre distance with 3σ = IT7/2 = 20 µm."""
    from gearte import run_case
    from gearte.io.case_file import load_case_dict
    from gearte.studies import RunOptions

    data = tomllib.loads(case_path("robot_joint_spur_rv_yield").read_text())
    data["chain"]["stages"][1] = {"name": "planetary", "ratio": 81.0, "lost_motion_max_arcmin": 1.0}
    data["analyses"]["yield"].update(samples=10, sobol_samples=0)
    data["analyses"]["yield"]["spec"] = {"joint_lost_motion [arcmin]": {"upper": 1.02}}
    pair = data["chain"]["stages"][0]["drive"]["pair"]
    for g in ("driving", "driven"):
        pair[g].pop("thickness_upper_um")
        pair[g].pop("thickness_lower_um")
        pair[g]["tooth_thickness_allowance"] = "cd25"
    pair.pop("centre_distance_tol_um")
    pair["centre_distance_allowance"] = "js7"
    res = run_case(load_case_dict(data, name="chain_classes"), RunOptions(progress=False))
    tols = res["yield"].values["tolerances"]
    keys = ("driving_gear_tooth_thickness", "driven_gear_tooth_thickness", "centre_distance")
    got = [tols[f"spur_pair.{k}"][f] for k in keys for f in ("tolerance", "nominal")]
    assert got == pytest.approx([20.0, -90.0, 25.0, -120.0, 20.0, 0.0])


def _rv_first_stage(**keys) -> dict:
    data = tomllib.loads(case_path("han2023_rv110e").read_text())
    data["analyses"] = {}  # no reducer analysis: the first stage's backlash alone (fast)
    data["reducer"]["first_stage"].update(keys)
    return data


def test_din3967_classes_on_the_rv_first_stage_report_its_backlash_by_hand():
    """han2023_rv110e's first stage (m 1.5, z 20/40, α 20°, 40 pins → i = 1 + 40·40/20 = 81):
    sun d 30 mm cd25 −54/−84 µm, planet d 60 mm cd25 −70/−110 µm, a = 45 mm js6 ±8 µm
    (IT6 = 16 µm): j_t = 124 − 16 tan 20° = 118.18 µm … 194 + 16 tan 20° = 199.82 µm; at the
    output j_t / (r_sun·i) = j_t / (15 mm · 81) = 0.334′ … 0.565′."""
    from gearte import run_case
    from gearte.studies import RunOptions
    from gearte.units import rad_to_arcmin

    data = _rv_first_stage(
        sun_tooth_thickness_allowance="cd25",
        planet_tooth_thickness_allowance="25 cd",
        centre_distance_allowance="js6",
    )
    v = run_case(load_case(data), RunOptions(progress=False))["first_stage_backlash"].values
    t, c = math.tan(math.radians(20.0)), math.cos(math.radians(20.0))
    assert v["sun_allowances [um]"] == [-54.0, -84.0]
    assert v["planet_allowances [um]"] == [-70.0, -110.0]
    assert v["centre_distance_allowances [um]"] == [8.0, -8.0]
    assert v["first_stage_backlash_circumferential_min [um]"] == pytest.approx(124 - 16 * t)
    assert v["first_stage_backlash_circumferential_max [um]"] == pytest.approx(194 + 16 * t)
    assert v["first_stage_backlash_normal_max [um]"] == pytest.approx((194 + 16 * t) * c)
    out = v["first_stage_backlash_at_output_max [arcmin]"]
    assert out == pytest.approx(rad_to_arcmin((194 + 16 * t) * 1e-3 / (15.0 * 81.0)))
    assert out == pytest.approx(0.5654, abs=1e-4)
    assert v["planet_class"] == "cd25"


@pytest.mark.parametrize(
    ("keys", "message"),
    [
        ({"sun_tooth_thickness_allowance": "cd25"}, "go together"),
        (
            {
                "sun_tooth_thickness_allowance": "zz25",
                "planet_tooth_thickness_allowance": "cd25",
                "centre_distance_allowance": "js6",
            },
            r"reducer\.first_stage\.sun_tooth_thickness_allowance.*DIN 3967",
        ),
        (
            {
                "sun_tooth_thickness_allowance": "cd25",
                "planet_tooth_thickness_allowance": "cd25",
                "centre_distance_allowance": "k6",
            },
            r"reducer\.first_stage\.centre_distance_allowance.*js5",
        ),
    ],
)
def test_din3967_bad_rv_first_stage_classes_are_errors_naming_the_key(keys, message):
    with pytest.raises(CaseFileError, match=message):
        load_case(_rv_first_stage(**keys))
