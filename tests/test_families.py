"""The drive-family registry (gearte.families): chains, yield and warm-up find the families there,
and in a chain's yield every family draws its own tolerances."""

from __future__ import annotations

import tomllib

import pytest

import gearte
from gearte.cases import case_path
from gearte.families import FAMILY_MODULES, families, family_kinds, get_family
from gearte.io.case_file import load_case, load_case_dict
from gearte.studies import RunOptions

OPTS = RunOptions(progress=False)


def test_every_registered_family_loads_and_is_a_study_kind_with_its_sections():
    from gearte.io.kinds import available_kinds, get_kind

    assert len(FAMILY_MODULES) == len(family_kinds())
    for kind, fam in families().items():
        assert fam.kind == kind
        assert kind in available_kinds()
        fields = get_kind(kind).Case.model_fields
        for sec in fam.sections:
            assert sec in fields, f"{kind}: section {sec!r} is not in its Case"
        if fam.bench_case is not None:
            assert load_case(fam.bench_case).case.kind == kind


def test_unknown_family_is_an_error_naming_the_registered_ones():
    with pytest.raises(KeyError, match="registered"):
        get_family("harmonic_flux_capacitor")
    data = tomllib.loads(case_path("robot_joint_spur_rv").read_text())
    data["chain"]["stages"][1]["drive"]["kind"] = "nope"
    with pytest.raises(gearte.errors.CaseFileError, match="drive families"):
        load_case_dict(data)


def test_cycloid_family_description_round_trips_through_its_sections():
    """``to_sections`` then ``to_object`` gives the same CycloidStage (one function each way)."""
    fam = get_family("cycloid_stage")
    case = load_case("hu2020_rv80e_initial")
    stage = fam.to_object(case)
    assert fam.to_sections is not None
    data = {"case": {"kind": "cycloid_stage"}, **fam.to_sections(stage)}
    assert fam.to_object(load_case_dict(data)) == stage


def _spur_and_cycloid() -> dict:
    """robot_joint_spur_rv_yield's spur pair (Jiang 2024) driving the cycloid stage of
    hu2020_rv80e_initial (its illustrative component-error bands), inline."""
    chain = tomllib.loads(case_path("robot_joint_spur_rv_yield").read_text())
    cyc = tomllib.loads(case_path("hu2020_rv80e_initial").read_text())
    chain["chain"]["stages"][1] = {
        "name": "cycloid stage",
        "ratio": 39.0,
        "drive": {"kind": "cycloid_stage", "stage": cyc["stage"], "errors": cyc["errors"]},
    }
    chain["analyses"]["yield"].update(samples=2000, sobol_samples=256, bootstrap=0)
    chain["analyses"]["yield"]["spec"] = {"joint_lost_motion [arcmin]": {"upper": 2.0}}
    del chain["analyses"]["yield"]["tolerances"]
    return chain


def test_chain_yield_ranks_each_drives_own_tolerances_in_its_contributions():
    """A spur pair and a cycloid stage in one chain: the yield draws the pair's backlash-stack
    contributors and the cycloid stage's nine component errors (keys ``cycloid_stage.<factor>``),
    never one normal law for the cycloid stage; both drives' errors appear in the ranking, and
    the cycloid stage's drawn lost motion has the mean of its own model (Hu 2020 eq 16)."""
    res = gearte.run_case(load_case_dict(_spur_and_cycloid(), name="spur_cycloid"), OPTS)
    y = res["yield"].values
    keys = set(y["tolerances"])
    assert "cycloid stage" not in keys  # no single law for the stage
    cyc = {k for k in keys if k.startswith("cycloid_stage.")}
    assert "cycloid_stage.pin_circle_radius_error" in cyc
    assert "cycloid_stage.cumulative_pitch_error" in cyc
    assert any(k.startswith("spur_pair.") for k in keys)
    # both drives' own tolerances are ranked (Sobol total indices; the pair's lost motion is
    # divided by the stage's ratio 39 at the joint, so its share is small but not zero; its
    # least-squares linear share is below the fit's noise and reads 0)
    share = y["sobol_total"]
    assert sum(share[k] for k in cyc) > 0.5
    assert sum(share[k] for k in share if k.startswith("spur_pair.")) > 0.0
    ranked = sorted(share, key=share.get, reverse=True)
    assert any(k in cyc for k in ranked[:5])
    q = y["quantities"]["cycloid_stage.lost_motion [arcmin]"]
    own = res["cycloid_stage_drive"].values
    assert q["mean"] == pytest.approx(own["lost_motion_mean [arcmin]"], rel=0.02)
    assert any("draws its own tolerances" in n for n in res["yield"].notes)


def _rv_cases() -> list[str]:
    import tomllib

    from gearte.cases import list_cases

    return sorted(
        n
        for n, p in list_cases().items()
        if tomllib.loads(p.read_text())["case"]["kind"] == "rv_reducer"
    )


@pytest.mark.parametrize("name", _rv_cases())
def test_rv_cycloid_stage_is_built_once_whichever_description(name):
    """The reducer's cycloid stage from its [reducer] section (stage_section → the
    cycloid_stage kind's build_stage) equals the reducer object's own (rv_load_sharing's
    cycloid_stage), and RVReducer.K1 is that stage's K1 (one K1)."""
    from gearte.models.rv_load_sharing import cycloid_stage
    from gearte.studies.cycloid_stage import build_stage
    from gearte.studies.rv_reducer import build_reducer, stage_section

    case = load_case(name)
    red = build_reducer(case.reducer)
    stage = build_stage(stage_section(case.reducer))
    assert stage == cycloid_stage(red)
    assert red.K1 == stage.K1


@pytest.mark.parametrize("name", ["jiang2024_spur_pair", "jiang2024_bevel_pair"])
def test_gear_pair_family_description_round_trips_through_its_section(name):
    """to_sections then to_object gives the same pair (to the µm ↔ mm round trip)."""
    import dataclasses

    fam = get_family("gear_pair")
    pair = fam.to_object(load_case(name))
    assert fam.to_sections is not None
    again = fam.to_object(load_case_dict({"case": {"kind": "gear_pair"}, **fam.to_sections(pair)}))
    assert type(again) is type(pair)

    def flat(x):
        if dataclasses.is_dataclass(x):
            return [v for f in dataclasses.fields(x) for v in flat(getattr(x, f.name))]
        if isinstance(x, tuple):
            return [v for y in x for v in flat(y)]
        return [x]

    assert flat(again) == pytest.approx(flat(pair), rel=1e-12, abs=1e-15)


@pytest.mark.slow
def test_chain_yield_rv_stage_draws_its_cases_own_yield_tolerances():
    """An RV drive whose case has [analyses.yield] (han2023_rv110e_yield) draws those tolerances
    in the chain (keys rv_reducer.<family>, each sample one reducer through the catalogue virtual
    test); its drawn lost motion centres on the drive's deterministic one (slow: RV tests)."""
    d = tomllib.loads(case_path("robot_joint_spur_rv_yield").read_text())
    d["chain"]["stages"][1]["drive"]["case"] = "han2023_rv110e_yield.toml"
    d["analyses"]["yield"].update(samples=48, sobol_samples=0, bootstrap=0, chunk_size=48)
    base = str(case_path("han2023_rv110e").parent)
    res = gearte.run_case(load_case_dict(d, name="rv_chain", base_dir=base), OPTS)
    keys = set(res["yield"].values["tolerances"])
    assert "RV reducer" not in keys
    assert {"rv_reducer.cam", "rv_reducer.disc_cumulative_pitch"} <= keys
    q = res["yield"].values["quantities"]["rv_reducer.lost_motion [arcmin]"]
    own = res["rv_reducer_drive"].values["lost_motion [arcmin]"]
    assert q["sd"] > 0
    assert q["mean"] == pytest.approx(own, abs=4 * q["sd"] / 48**0.5)


#: The bundled rv_reducer cases whose [reducer] round-trips through the family's sections.
RV_ROUND_TRIP_CASES = [
    "han2023_rv110e",
    "han2023_rv110e_no_errors",
    "hu2020_rv80e_initial_reducer",
    "hu2020_rv80e_modified_reducer",
    "li2023_rv",
    "li2023_rv_errors",
]


@pytest.mark.parametrize("name", RV_ROUND_TRIP_CASES)
def test_rv_reducer_family_description_round_trips_through_its_section(name):
    """to_sections then to_object gives the same RVReducer, every field and array (its derived
    stiffnesses written back as given ones, its measured errors as [[reducer.errors]])."""
    from rv_sections import assert_same_reducer

    fam = get_family("rv_reducer")
    assert fam.to_sections is not None
    red = fam.to_object(load_case(name))
    sections = fam.to_sections(red)
    again = fam.to_object(load_case_dict({"case": {"kind": "rv_reducer"}, **sections}))
    assert_same_reducer(again, red)


def test_rv_reducer_sections_write_derived_stiffnesses_as_given_keys():
    """han2023_rv110e derives its bearings (Palmgren), stiffness chain (spans, seat length) and
    keeps the measured errors: the section written back gives each stiffness, no dimension it
    was derived from, and every measured error entry (length and direction)."""
    import math
    import tomllib

    fam = get_family("rv_reducer")
    case = load_case("han2023_rv110e")
    assert fam.to_sections is not None
    sec = fam.to_sections(fam.to_object(case))["reducer"]
    for key in ("bearing_span_mm", "torsion_length_mm"):
        assert key not in sec["cranks"]
    assert {"bending_stiffness_N_per_mm", "torsional_stiffness_Nm_per_rad"} <= set(sec["cranks"])
    assert "seat_length_mm" not in sec["pins"] and "seat_stiffness_N_per_mm" in sec["pins"]
    assert "main_bearing" not in sec["supports"]
    assert set(sec["cranks"]["cam_bearing"]) == {"stiffness_N_per_mm", "radial_clearance_um"}
    raw = tomllib.loads(case_path("han2023_rv110e").read_text())["reducer"]["errors"]
    written = {(e["part"], e.get("crank"), e.get("disc")): e for e in sec["errors"]}
    given = [e for e in raw if e["value_um"] > 0]
    assert len(written) == len(given)
    for e in given:
        w = written[(e["part"], e.get("crank"), e.get("disc"))]
        assert w["value_um"] == pytest.approx(e["value_um"], rel=1e-12)
        turn = math.remainder(w["angle_deg"] - e["angle_deg"], 360.0)
        assert turn == pytest.approx(0.0, abs=1e-10)


def test_rv_reducer_sections_refuse_a_serials_measured_discs():
    """A serial's measured discs and bearing clearances (rv_serial) have no [reducer] key: an
    error naming the field, not a silently different reducer."""
    from gearte.errors import ParameterError
    from gearte.studies.rv_serial import build_serial

    fam = get_family("rv_reducer")
    assert fam.to_sections is not None
    _, red, _ = build_serial(load_case("synthetic_rv110e_serial"))
    with pytest.raises(ParameterError, match="errors.measured_discs|errors.cam_clearance"):
        fam.to_sections(red)


@pytest.mark.parametrize(
    "name", ["wang2013_2kh_derived", "wang2013_2kh_eq9", "wang2013_2kh_eq9_yield"]
)
def test_planetary_family_description_round_trips_through_its_sections(name):
    """to_sections then to_object gives the same set, term set, magnitudes and angles (exactly:
    the values converted back are written to 15 significant digits, as the case gave them); a
    derived term set is written as source = "derived", a published table as its terms."""
    fam = get_family("planetary")
    assert fam.to_sections is not None
    case = load_case(name)
    obj = fam.to_object(case)
    sections = fam.to_sections(obj)
    assert sections["errors"]["source"] == case.errors.source
    again = fam.to_object(load_case_dict({"case": {"kind": "planetary"}, **sections}))
    assert again == obj
