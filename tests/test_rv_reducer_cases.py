"""The bundled rv_reducer cases run through the CLI and report the names the issue fixes as API."""

from __future__ import annotations

import json

import pytest
from click.testing import CliRunner

from gearte.cli import main

MUST = [
    "peak_pin_load [N]",
    "pairs_in_mesh_min",
    "pairs_in_mesh_max",
    "total_te_peak_to_peak [arcsec]",
    "geometric_te_peak_to_peak [arcsec]",
    "elastic_te_peak_to_peak [arcsec]",
    "torsional_rigidity [N*m/arcmin]",
    "lost_motion [arcmin]",
    "backlash [arcmin]",
]
CASES = [
    "han2023_rv110e",
    "han2023_rv110e_no_errors",
    "hu2020_rv80e_initial_reducer",
    "hu2020_rv80e_modified_reducer",
]


@pytest.mark.parametrize("name", CASES)
def test_rv_reducer_case_runs_through_cli(name, tmp_path):
    out = tmp_path / name
    res = CliRunner().invoke(main, ["run", name, "--out", str(out)])
    assert res.exit_code == 0, res.output
    data = json.loads((out / "results.json").read_text(encoding="utf-8"))
    assert data["case"]["kind"] == "rv_reducer"
    values = {}
    for a in data["analyses"].values():
        values.update(a["values"])
    for key in MUST:
        assert key in values, key
        assert values[key] is not None
    assert (out / "report.html").stat().st_size > 10_000
    pins = (out / "pin_loads.csv").read_text(encoding="utf-8").splitlines()
    assert pins[0].startswith("output_angle [deg],disc,pin_1 [N]")
    assert len(pins) == 1 + 360 * 2
    te = (out / "transmission_error.csv").read_text(encoding="utf-8").splitlines()
    assert len(te) == 1 + 360
