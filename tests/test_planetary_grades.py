"""Accuracy grades for planetary stages and their absence for bevel pairs (issue 14 item 2).

``grade = N`` on a planetary gear's manufacturing eccentricity (``E_s`` sun, ``E_p<i>`` planet,
``E_r`` ring — an internal gear) in ``[analyses.yield.tolerances]`` gives the eccentricity
tolerance ``F_rT / 2`` of its ISO 1328-1:2013 class (run-out ``F_rT = 0.9 F_pT``, eq. (6) for
``F_pT``, rounded by §5.2.3), from ``[gearset]``'s module and teeth (``d = m z``). Every expected
value below is recomputed by hand from the equations, the intermediate numbers written out.
"""

from __future__ import annotations

import math
import tomllib

import pytest

import gearte
from gearte.cases import case_path
from gearte.errors import CaseFileError, ParameterError
from gearte.io.case_file import load_case_dict
from gearte.studies import RunOptions

SPEC = {"coupled_te_amplitude [arcsec]": {"upper": 300.0}}
OPTS = RunOptions(progress=False, workers=1)


def _derived(tolerances: dict, samples: int = 2_000, **gearset) -> dict:
    """wang2013_2kh_derived (Wang 2013 Table 1: m 1, z 12/36/84) with a yield section."""
    d = tomllib.loads(case_path("wang2013_2kh_derived").read_text())
    d["gearset"].update(gearset)
    d["analyses"] = {
        "coupled_te": {"assembly": "given"},
        "yield": {
            "samples": samples,
            "seed": 5,
            "chunk_size": 1_000,
            "sobol_samples": 0,
            "keep_worst": 0,
            "tolerances": tolerances,
            "spec": SPEC,
        },
    }
    return d


def _f_pt(d: float, m: float, grade: int) -> float:
    """ISO 1328-1:2013 eq. (6): F_pT = (0.002 d + 0.55 √d + 0.7 m_n + 12) (√2)^(A−5) [µm]."""
    return (0.002 * d + 0.55 * math.sqrt(d) + 0.7 * m + 12.0) * math.sqrt(2.0) ** (grade - 5)


def _run(data: dict):
    return gearte.run_case(load_case_dict(data, name="planetary_grades"), OPTS)["yield"]


def test_wang2013_gears_eccentricity_tolerances_from_iso1328_grades_by_hand():
    """m 1: sun z 12 → d 12 mm, class 6: F_pT = (0.024 + 1.9053 + 0.7 + 12)·√2 = 20.689 µm,
    F_rT = 0.9·F_pT = 18.62 → 19 µm (> 10 µm: nearest 1 µm), tolerance F_rT/2 = 9.5 µm;
    planet z 36 → d 36, class 6: (0.072 + 3.3 + 0.7 + 12)·√2 = 22.729, F_rT 20.46 → 20, 10 µm;
    ring (internal) z 84 → d 84, class 7: (0.168 + 5.0408 + 0.7 + 12)·2 = 35.818, F_rT 32.24 →
    32, 16 µm. The result names the standard and the class; a raw entry (A_c) is as given."""
    assert 0.9 * _f_pt(12, 1.0, 6) == pytest.approx(18.62, abs=0.005)
    assert 0.9 * _f_pt(36, 1.0, 6) == pytest.approx(20.456, abs=0.001)
    assert 0.9 * _f_pt(84, 1.0, 7) == pytest.approx(32.236, abs=0.001)
    tols = _run(
        _derived(
            {
                "E_s": {"grade": 6},
                "E_p1": {"grade": 6},
                "E_r": {"grade": 7},
                "A_c": {"tolerance_um": 5.0},
            },
            samples=500,
        )
    )["tolerances"]
    assert {k: tols[k]["tolerance"] for k in ("E_s", "E_p1", "E_r", "A_c")} == {
        "E_s": 9.5,
        "E_p1": 10.0,
        "E_r": 16.0,
        "A_c": 5.0,
    }
    assert tols["E_s"]["grade"] == 6 and tols["E_r"]["grade"] == 7
    assert "ISO 1328-1:2013 class 6, sun: z = 12" in tols["E_s"]["derived_from"]
    assert "F_rT = 0.9 F_pT = 19 µm" in tols["E_s"]["derived_from"]
    assert "ring (internal gear): z = 84" in tols["E_r"]["derived_from"]
    assert "grade" not in tols["A_c"] and "derived_from" not in tols["A_c"]


def test_graded_tolerance_enters_the_monte_carlo_as_the_same_number_given_raw():
    """grade = 6 on E_s is tolerance_um = 9.5 µm (above), normal about the case's 13 µm with
    σ = t/3 = 3.17 µm (the yield's stated meaning): the two runs give the same bits; without
    the E_s tolerance the coupled TE's spread is smaller (the tolerance does enter)."""
    from gearte.studies._yield import YieldSection, yield_inputs
    from gearte.studies.planetary import _grade_um, _yield_keys, build_terms

    graded = _derived({"E_s": {"grade": 6}, "beta_s": {"kind": "uniform", "tolerance_deg": 180}})
    case = load_case_dict(graded, name="g")
    terms, mags, angs = build_terms(case)
    units, nominal = _yield_keys(terms, mags, angs)
    sec = YieldSection.model_validate(graded["analyses"]["yield"])
    ts, _ = yield_inputs(sec, units, nominal, grade_um=_grade_um(case))
    (e_s,) = [t for t in ts.tolerances if t.key == "E_s"]
    assert (e_s.kind, e_s.tolerance, e_s.sd) == ("normal", 9.5, pytest.approx(9.5 / 3))
    assert e_s.nominal == pytest.approx(13.0)

    a = _run(graded)
    raw = _derived(
        {"E_s": {"tolerance_um": 9.5}, "beta_s": {"kind": "uniform", "tolerance_deg": 180}}
    )
    b = _run(raw)
    q = "coupled_te_amplitude [arcsec]"
    assert a["quantities"][q] == b["quantities"][q]
    assert a["yield"] == b["yield"]
    fixed = _run(_derived({"beta_s": {"kind": "uniform", "tolerance_deg": 180}}))
    assert fixed["quantities"][q]["sd"] < a["quantities"][q]["sd"]


def test_wang2013_eq9_yield_case_is_unchanged_by_the_grade_reading():
    """The bundled wang2013_2kh_eq9_yield (directions only, no grade) through the case gives
    the same statistics as the general engine called directly with its tolerances (the engine
    that reproduces Fig 2's 297″ / 70″: tests/test_yield_drives.py), and no tolerance is
    marked derived."""
    from gearte.runners.yield_models import PlanetaryCoupledTE
    from gearte.studies.planetary import build_terms
    from gearte.tolerance.yield_mc import SpecLimit, Tolerance, ToleranceSet, run_yield
    from gearte.units import mm_to_um

    case = gearte.load_case("wang2013_2kh_eq9_yield")
    opts = RunOptions(progress=False, workers=1, samples=4_000)
    v = gearte.run_case(case, opts)["yield"]
    assert not any("grade" in t for t in v["tolerances"].values())
    terms, mags_mm, _ = build_terms(case)
    mags = {k: float(mm_to_um(x)) for k, x in mags_mm.items()}
    ts = ToleranceSet(tuple(Tolerance(a, "uniform", 180.0, nominal=180.0) for a in terms.angles))
    q = "coupled_te_amplitude [arcsec]"
    r = run_yield(PlanetaryCoupledTE(terms, mags), ts, [SpecLimit(q, upper=400.0)], 4_000,
                  seed=2013, chunk_size=10_000)  # fmt: skip
    assert v["quantities"][q]["mean"] == r.quantities[q].stats.mean
    assert v["quantities"][q]["sd"] == r.quantities[q].stats.sd
    assert v["yield"] == r.yield_


@pytest.mark.parametrize(
    ("tolerances", "gearset", "message"),
    [
        ({"E_s": {"grade": 12}}, {}, "less than or equal to 11"),
        ({"E_s": {"grade": 0}}, {}, "greater than or equal to 1"),
    ],
)
def test_grade_outside_1_to_11_is_a_case_file_error_naming_the_field(tolerances, gearset, message):
    with pytest.raises(
        CaseFileError, match=rf"analyses\.yield\.tolerances\.E_s\.grade: .*{message}"
    ):
        load_case_dict(_derived(tolerances, **gearset), name="bad")


@pytest.mark.parametrize(
    ("key", "gearset", "message"),
    [
        # m 0.45 < 0.5 mm: below ISO 1328-1's module range
        ("E_s", {"module_mm": 0.45}, r"sun: z = 12, m_n = 0\.45 mm.*module_mm = 0\.45"),
        # ring z 1003 > 1000 (sun 401, planets 301: z_r = z_s + 2 z_p, (z_s + z_r)/3 whole)
        (
            "E_r",
            {"z_sun": 401, "z_planet": 301, "z_ring": 1003},
            r"ring \(internal gear\): z = 1003.*teeth",
        ),
        ("A_s", {}, r"assembly eccentricity \(its bearing seat\).*give tolerance_um"),
    ],
)
def test_gear_outside_the_standards_range_or_not_a_gear_is_an_error_naming_the_key(
    key, gearset, message
):
    """Checked before any sample (the kind's pre-flight, ``gearte validate``) and by a run."""
    from gearte.studies.planetary import preflight

    case = load_case_dict(_derived({key: {"grade": 6}}, **gearset), name="bad")
    with pytest.raises(ParameterError, match=rf"analyses\.yield\.tolerances\.{key}\.grade") as e:
        preflight(case)
    assert e.match(message)
    with pytest.raises(ParameterError, match=message):
        gearte.run_case(case, OPTS)


def test_grade_with_terms_as_given_is_an_error_saying_no_gear_is_named():
    """wang2013_2kh_eq9 gives eq. 9's terms: its magnitudes name no gear, so no size."""
    d = tomllib.loads(case_path("wang2013_2kh_eq9_yield").read_text())
    d["analyses"]["yield"]["tolerances"]["E_s"] = {"grade": 6}
    case = load_case_dict(d, name="bad")
    from gearte.studies.planetary import preflight

    with pytest.raises(ParameterError, match=r"tolerances\.E_s\.grade.*errors\.source = 'terms'"):
        preflight(case)


# --------------------------------------------------------------------------- bevel pairs
_BEVEL_WHY = r"bevel gears take no accuracy grade.*ISO 17485.*not implemented"


@pytest.mark.parametrize("where", [("pair", "driving"), ("pair",)])
def test_grade_on_a_bevel_gear_or_pair_is_an_error_naming_the_key_and_why(where):
    """Before: ``pair.driving.grade: unknown key; did you mean 'grade'?`` (the spur gear's
    field offered for itself). Now the key and the reason: no bevel standard implemented."""
    d = tomllib.loads(case_path("jiang2024_bevel_pair").read_text())
    table = d
    for k in where:
        table = table[k]
    table["grade"] = 6
    with pytest.raises(CaseFileError, match=rf"{'.'.join(where)}\.grade: {_BEVEL_WHY}") as e:
        load_case_dict(d, name="bad")
    assert "did you mean" not in str(e.value)


def test_grade_on_a_chain_bevel_stage_tolerance_is_an_error_naming_the_key_and_why():
    """Before: 'this error is not a gear's eccentricity' — wrong: it is one, of a bevel gear."""
    d = tomllib.loads(case_path("jiang2024_shoulder_swing_gearte").read_text())
    key = "bevel_pair.driven_gear_eccentricity"
    d.setdefault("analyses", {})["yield"] = {
        "samples": 200,
        "sobol_samples": 0,
        "keep_worst": 0,
        "tolerances": {key: {"grade": 6}},
    }
    case = load_case_dict(d, name="bad")
    from gearte.studies.gear_chain import preflight

    with pytest.raises(ParameterError, match=rf"tolerances\.{key}\.grade = 6: {_BEVEL_WHY}"):
        preflight(case)


def test_unknown_key_hint_never_suggests_the_key_itself():
    from gearte.io.case_file import did_you_mean

    assert did_you_mean("grade", {"grade", "teeth"}) == ""
    assert did_you_mean("grad", {"grade", "teeth"}) == "did you mean 'grade'?"


def test_rv_first_stage_sun_eccentricity_takes_its_grade_too_by_hand():
    """han2023_rv110e_yield's first stage, m 1.5: sun z 20 → d 30 mm, class 6: F_pT =
    (0.06 + 0.55·√30 + 1.05 + 12)·√2 = 16.1225·√2 = 22.80 µm, F_rT = 20.52 → 21 µm,
    tolerance 10.5 µm; the planets (z 40, d 60) keep 11 µm (tests/test_yield_rv.py). Both
    are reported as derived."""
    from gearte.studies.rv_reducer import _grade_um

    assert 0.9 * _f_pt(30, 1.5, 6) == pytest.approx(20.52, abs=0.005)
    read = _grade_um(gearte.load_case("han2023_rv110e_yield"))
    sun, planet = read("sun_eccentricity", 6), read("planet_base_circle", 6)
    assert (sun.tolerance_um, planet.tolerance_um) == (10.5, 11.0)
    assert "sun: z = 20, m_n = 1.5 mm, d = m_n z = 30 mm" in sun.derivation
    assert read("sun_assembly", 6) is None  # a bearing seat: "not a gear's eccentricity"


def test_one_grade_on_E_p_covers_every_planet_each_drawn_on_its_own():
    """``E_p`` (as ``[errors]`` accepts it for every planet) is the family of E_p1 … E_p3
    (planet_model = "mean"): one grade → 10 µm for each planet (z 36, above), reported once
    under E_p as derived; the worst sample holds three different draws."""
    d = _derived({"E_p": {"grade": 6}}, samples=300)
    d["errors"]["planet_model"] = "mean"
    d["analyses"]["yield"]["keep_worst"] = 1
    v = _run(d)
    t = v["tolerances"]
    assert list(t) == ["E_p"] and t["E_p"]["tolerance"] == 10.0
    assert "each planet: z = 36" in t["E_p"]["derived_from"]
    drawn = v["worst_samples"][0]["errors"]
    assert len({drawn["E_p1"], drawn["E_p2"], drawn["E_p3"]}) == 3
