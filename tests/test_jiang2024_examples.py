"""The bundled Jiang et al. (2024) cases run through the CLI and carry the issue's result names."""

from __future__ import annotations

import json

import pytest
from click.testing import CliRunner

from gearte.cli import main

PAIR_NAMES = [
    "backlash_mean [um]",
    "backlash_sd [um]",
    "backlash_min [um]",
    "backlash_max [um]",
    "lost_motion_mean [arcmin]",
    "lost_motion_max [arcmin]",
]


@pytest.mark.parametrize(
    ("name", "mean", "sd"),
    [("jiang2024_spur_pair", 53.0, 7.0), ("jiang2024_bevel_pair", 89.5, 6.7)],
)
def test_pair_case_through_cli(tmp_path, name, mean, sd):
    out = tmp_path / name
    res = CliRunner().invoke(
        main, ["run", name, "--out", str(out), "--no-progress", "--samples", "20000"]
    )
    assert res.exit_code == 0, res.output
    d = json.loads((out / "results.json").read_text())
    v = d["analyses"]["backlash"]["values"]
    for k in PAIR_NAMES:
        assert isinstance(v[k], float), k
    assert round(v["backlash_mean [um]"], 1) == pytest.approx(mean, abs=0.5)
    assert round(v["backlash_sd [um]"], 1) == pytest.approx(sd, abs=0.5)
    assert d["analyses"]["monte_carlo"]["values"]["samples"] == 20000
    assert (out / "report.html").stat().st_size > 10_000  # figures embedded


@pytest.mark.parametrize("name", ["jiang2024_shoulder_swing", "jiang2024_shoulder_swing_gearte"])
def test_chain_case_through_cli(tmp_path, name):
    out = tmp_path / name
    res = CliRunner().invoke(
        main, ["run", name, "--out", str(out), "--no-progress", "--samples", "20000"]
    )
    assert res.exit_code == 0, res.output
    a = json.loads((out / "results.json").read_text())["analyses"]
    assert isinstance(a["chain"]["values"]["joint_lost_motion_max [arcmin]"], float)
    assert isinstance(a["chain"]["values"]["end_effector_error_max [mm]"], float)
    assert isinstance(a["shim"]["values"]["shim_thickness [mm]"], float)
    c = a["compensation"]["values"]
    assert isinstance(c["motor_compensation_angle [deg]"], float)
    assert isinstance(c["end_effector_error_after_compensation [mm]"], float)
    assert (
        c["end_effector_error_after_compensation [mm]"]
        < a["chain"]["values"]["end_effector_error_max [mm]"]
    )
