"""The drive interface (gearte.drives): every drive answers the same questions from its own model,
and a gear_chain stage can be any drive (issue 11 item 7)."""

from __future__ import annotations

import shutil
import tomllib

import numpy as np
import pytest

import gearte
from gearte.cases import case_path
from gearte.drives import Drive
from gearte.drives.chain import joint_stiffness, joint_transmission_error
from gearte.errors import CaseFileError, ParameterError
from gearte.io.case_file import load_case, load_case_dict
from gearte.studies import RunOptions
from gearte.studies._drives import drive_from_case
from gearte.tolerance.stackup import z_for_confidence
from gearte.units import arcmin_to_rad, arcsec_to_rad, rad_to_arcmin, rad_to_arcsec

OPTS = RunOptions(progress=False)


def _toml(name: str) -> dict:
    return tomllib.loads(case_path(name).read_text(encoding="utf-8"))


def _rv_catalogue_only_case() -> dict:
    """The bundled RV-110E description with only its catalogue virtual test requested."""
    data = _toml("han2023_rv110e")
    data["analyses"] = {"catalogue": data["analyses"]["catalogue"]}
    return data


@pytest.fixture(scope="module")
def robot_joint():
    return gearte.run_case("robot_joint_spur_rv", OPTS)


# ------------------------------------------------------------------------------- the must-show
def test_robot_joint_chain_rv_lost_motion_equals_the_rv_models_own(robot_joint):
    """The chain's RV stage lost motion is the rv_reducer kind's catalogue value, exactly."""
    own = gearte.run_case(load_case_dict(_rv_catalogue_only_case()), OPTS)
    cat = own["catalogue"].values
    stage = robot_joint["rv_reducer_drive"].values
    chain = robot_joint["chain"].values
    assert stage["lost_motion_max [arcmin]"] == cat["lost_motion [arcmin]"]
    assert chain["stage_lost_motion_max [arcmin]"]["RV reducer"] == cat["lost_motion [arcmin]"]
    assert stage["torsional_stiffness [N*m/arcmin]"] == pytest.approx(
        cat["torsional_rigidity [N*m/arcmin]"], rel=1e-12
    )


def test_robot_joint_chain_end_to_end(robot_joint):
    """Joint lost motion = RV + spur/81 (eq. 30), end effector = joint × 800 mm (eq. 31)."""
    ch = robot_joint["chain"].values
    lm = ch["stage_lost_motion_max [arcmin]"]
    joint = lm["RV reducer"] + lm["spur pair"] / 81.0
    assert ch["joint_lost_motion_max [arcmin]"] == pytest.approx(joint, rel=1e-12)
    assert ch["end_effector_error_max [mm]"] == pytest.approx(
        float(arcmin_to_rad(joint)) * 800.0, rel=1e-12
    )
    k = ch["stage_torsional_stiffness [N*m/arcmin]"]
    series = 1.0 / (1.0 / k["RV reducer"] + 1.0 / (k["spur pair"] * 81.0**2))
    assert ch["joint_torsional_stiffness [N*m/arcmin]"] == pytest.approx(series, rel=1e-12)
    assert robot_joint.warnings == []


def test_robot_joint_te_is_the_rv_models_own_geometric_te(robot_joint):
    """The spur pair has no TE model; the joint TE is the rv_reducer kind's unloaded TE."""
    data = _toml("han2023_rv110e")
    data["analyses"] = {
        "transmission_error": {**data["analyses"]["transmission_error"], "positions": 360}
    }
    own = gearte.run_case(load_case_dict(data), OPTS)["transmission_error"].values
    te = robot_joint["chain_te"].values
    assert te["stages_with_te"] == ["RV reducer"] and te["stages_without_te"] == ["spur pair"]
    assert np.allclose(te["joint_te [arcsec]"], own["geometric_te [arcsec]"], rtol=0, atol=1e-9)
    pp = te["joint_te_peak_to_peak_sampled [arcsec]"]
    assert te["end_effector_te_peak_to_peak_sampled [mm]"] == pytest.approx(
        float(arcsec_to_rad(pp)) * 800.0, rel=1e-12
    )


# ------------------------------------------------------------------------------- each adapter
@pytest.mark.parametrize(
    "name, kind",
    [
        ("jiang2024_spur_pair", "spur_pair"),
        ("jiang2024_bevel_pair", "bevel_pair"),
        ("wang2013_2kh_eq9", "planetary"),
        ("hu2020_rv80e_initial", "cycloid_stage"),
        ("han2023_rv110e", "rv_reducer"),
    ],
)
def test_every_bundled_drive_implements_the_interface(name, kind):
    drive = drive_from_case(load_case(name))
    assert isinstance(drive, Drive)
    assert drive.kind == kind
    assert drive.name == name
    assert drive.ratio >= 1.0


def test_pair_drive_equals_the_chains_pair_table():
    """The same spur pair as a [pair] table and as a gear_pair drive loses the same motion."""
    pair = _toml("jiang2024_spur_pair")["pair"]
    base = {"case": {"kind": "gear_chain"}, "analysis": {"monte_carlo_samples": 0}}
    as_table = dict(
        base,
        chain={
            "lever_length_mm": 100.0,
            "stages": [{"name": "p", "ratio": 110 / 28, "pair": pair}],
        },
    )
    as_drive = dict(
        base,
        chain={
            "lever_length_mm": 100.0,
            "stages": [
                {"name": "p", "ratio": 110 / 28, "drive": {"kind": "gear_pair", "pair": pair}}
            ],
        },
    )
    a = gearte.run_case(as_table, OPTS)["chain"].values
    b = gearte.run_case(as_drive, OPTS)["chain"].values
    key = "stage_lost_motion_max [arcmin]"
    assert a[key] == b[key]
    assert a["joint_lost_motion_mean [arcmin]"] == b["joint_lost_motion_mean [arcmin]"]


def test_pair_drive_spread_is_the_backlash_stack_through_eq14():
    """Jiang 2024 Table 4 (analytic): spur backlash 53 ± 7 µm → Δφ = 2 jn/(d cos α), d = 275."""
    drive = drive_from_case(load_case("jiang2024_spur_pair"))
    s = drive.lost_motion_spread(0.9973)
    d, c = 275.0, np.cos(np.radians(20.0))
    assert s.mean * d * c / 2 * 1e3 == pytest.approx(53.0, abs=0.5)  # Table 4 prints 53 µm
    assert s.sd * d * c / 2 * 1e3 == pytest.approx(7.0, abs=0.5)  # σ printed as 7 µm
    assert s.min < s.mean < s.max
    assert drive.lost_motion() == s.mean
    assert drive.transmission_error(np.zeros(3)) is None
    assert drive.torsional_stiffness() is None  # no face width given: not modelled


def test_pair_drive_stiffness_and_lost_motion_under_torque():
    """ISO 6336 c_γ b r_b2² with b = 20 mm; lost motion at T adds 2T/K."""
    data = _toml("jiang2024_spur_pair")
    data["pair"]["face_width_mm"] = 20.0
    drive = drive_from_case(load_case_dict(data))
    r_b = 0.5 * 275.0 * np.cos(np.radians(20.0))
    k = 20.0 * 20.0 * 1e3 * r_b**2
    assert drive.torsional_stiffness() == pytest.approx(k, rel=1e-12)
    assert drive.lost_motion(1.0e4) == pytest.approx(drive.lost_motion() + 2e4 / k, rel=1e-12)


def test_cycloid_drive_lost_motion_is_hu2020_geometric_te():
    """The cycloid stage's lost motion is the cycloid_stage kind's mean geometric TE."""
    data = _toml("hu2020_rv80e_initial")
    data["analyses"] = {"geometric_te": data["analyses"]["geometric_te"]}
    case = load_case_dict(data)
    drive = drive_from_case(case)
    te = gearte.run_case(case, OPTS)["geometric_te"].values
    assert rad_to_arcmin(drive.lost_motion()) == te["geometric_te_mean [arcmin]"]
    s = drive.lost_motion_spread()
    assert s.sd == drive.geometric_te().tolerance / 6.0  # eq 17's band read as ±3σ
    assert s.max - s.min == pytest.approx(2 * z_for_confidence(0.9973) * s.sd, rel=1e-12)
    assert drive.ratio == 39.0  # z_c = z_p - 1 (40 pins)
    assert drive.torsional_stiffness() is None


def test_planetary_drive_te_reaches_the_exact_peak_to_peak():
    """Sampled densely over one common period, the drive's TE spans Wang 2013's exact p-p."""
    case = load_case("wang2013_2kh_eq9")
    drive = drive_from_case(case)
    from gearte.models.planetary_errors import coupled_te

    exact = coupled_te(drive.terms, drive.magnitudes, drive.angles)
    period = 2 * np.pi / (float(exact.q0) * drive.ratio)  # output angle of one common period
    te = drive.transmission_error(np.linspace(0.0, period, 200_001))
    assert rad_to_arcsec(np.ptp(te)) == pytest.approx(rad_to_arcsec(exact.peak_to_peak), rel=1e-6)
    assert drive.lost_motion() is None
    assert drive.lost_motion_spread() is None


def test_rv_drive_answers_from_the_catalogue_test():
    drive = drive_from_case(load_case_dict(_rv_catalogue_only_case()))
    cat = drive.catalogue()
    assert drive.lost_motion() == cat.lost_motion
    assert drive.torsional_stiffness() == cat.torsional_rigidity
    assert drive.lost_motion_spread() is None
    te = drive.transmission_error(np.linspace(0, 2 * np.pi, 8, endpoint=False))
    assert te.shape == (8,) and np.all(np.isfinite(te))
    with pytest.raises(ParameterError, match="torque"):
        drive.lost_motion(drive.reducer.rated_torque)  # beyond 0.5 x rated


# ------------------------------------------------------------------------------- composition
def test_joint_stiffness_series_closed_form():
    assert joint_stiffness([5.0e6], [7.0]) == 5.0e6
    assert joint_stiffness([1.0e6, 1.0e8], [10.0, 100.0]) == pytest.approx(1 / (1e-10 + 1e-8))
    with pytest.raises(ParameterError, match="stiffness"):
        joint_stiffness([1.0e6, 0.0], [10.0, 100.0])


def test_joint_te_sums_each_drives_te_referred_to_the_joint():
    class Sine:
        kind, name, ratio = "spur_pair", "s", 4.0

        def transmission_error(self, th):
            return 1e-4 * np.sin(th)

    class Rigid(Sine):
        def transmission_error(self, th):
            return None

    th = np.linspace(0, 1, 5)
    te = joint_transmission_error([Sine(), Rigid(), None], [4.0, 3.0, 2.0], th)
    assert np.allclose(te, 1e-4 * np.sin(th * 6.0) / 6.0)  # f_1 = 1/(3*2)


# ------------------------------------------------------------------------------- bad input
def _chain(drive: dict, ratio: float = 81.0, **stage) -> dict:
    return {
        "case": {"kind": "gear_chain"},
        "chain": {
            "lever_length_mm": 500.0,
            "stages": [{"name": "d", "ratio": ratio, "drive": drive, **stage}],
        },
    }


@pytest.mark.parametrize(
    "drive, extra, message",
    [
        ({"kind": "rv_reducer", "case": "jiang2024_spur_pair"}, {}, "is a 'gear_pair' case"),
        ({"kind": "rv_reducer", "case": "no_such_case.toml"}, {}, "no case file"),
        ({"kind": "rv_reducer"}, {}, "give case = '<file>' or the 'rv_reducer' sections"),
        ({"kind": "gear_pair", "stage": {}}, {}, "unknown section(s) ['stage']"),
        ({"kind": "planetary", "case": "wang2013_2kh_eq9"}, {}, "give lost_motion_max_arcmin"),
        (
            {"kind": "rv_reducer", "case": "han2023_rv110e"},
            {"lost_motion_max_arcmin": 1.0},
            "remove lost_motion",
        ),
        ({"kind": "cycloid_stage", "case": "hu2020_rv80e_initial"}, {}, "disagrees with the drive"),
        ({"kind": "gear_pair", "pair": {"type": "spur"}}, {}, "pair.spur.module_mm: required"),
    ],
)
def test_bad_drive_stage_names_field_and_reason(drive, extra, message):
    with pytest.raises(CaseFileError) as err:
        load_case_dict(_chain(drive, **extra))
    assert any(f.startswith("chain.stages.0") and message in m for f, m in err.value.errors), (
        err.value.errors
    )


def test_planetary_stage_with_given_lost_motion_runs():
    res = gearte.run_case(
        _chain(
            {"kind": "planetary", "case": "wang2013_2kh_eq9"}, ratio=8.0, lost_motion_max_arcmin=1.0
        ),
        OPTS,
    )
    assert res["chain"].values["joint_lost_motion_max [arcmin]"] == 1.0
    assert res["d_drive"].values["torsional_stiffness [N*m/arcmin]"] is None
    assert res["chain"].values["joint_torsional_stiffness [N*m/arcmin]"] is None


def test_drive_case_path_is_relative_to_the_chain_file(tmp_path, monkeypatch):
    """case = 'x.toml' is read beside the chain case, whatever the working directory."""
    (tmp_path / "cases").mkdir()
    shutil.copy(case_path("jiang2024_spur_pair"), tmp_path / "cases" / "my_pair.toml")
    (tmp_path / "cases" / "joint.toml").write_text(
        '[case]\nkind = "gear_chain"\n[chain]\nlever_length_mm = 100.0\n'
        '[[chain.stages]]\nname = "p"\nratio = 3.9285714\n'
        '[chain.stages.drive]\nkind = "gear_pair"\ncase = "my_pair.toml"\n',
        encoding="utf-8",
    )
    monkeypatch.chdir(tmp_path)
    case = load_case(tmp_path / "cases" / "joint.toml")
    assert case.chain.stages[0].drive.source == str(tmp_path / "cases" / "my_pair.toml")
