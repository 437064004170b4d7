"""Study kind rv_bench (issue 17 item 6): a bench case runs end to end, results.json carries the
required names, the calibrated serial is a valid rv_reducer case."""

from __future__ import annotations

import json
import tomllib

import numpy as np
import pytest

from gearte.errors import CaseFileError
from gearte.io.bench import read_te_folder, write_hysteresis, write_te_trace
from gearte.io.case_file import load_case, load_case_dict
from gearte.models.catalogue import forward_backward_difference, te_peak_to_peak
from gearte.studies import RunOptions, run_case
from gearte.units import ARCSEC_PER_RAD

REQUIRED = (
    "angular_te_peak_to_peak_forward [arcsec]",
    "angular_te_peak_to_peak_backward [arcsec]",
    "forward_backward_difference_mean [arcsec]",
)


def _case(tmp_path, **analyses):
    from gearte.cases import case_path

    bundled = case_path("synthetic_rv_bench").parent / "synthetic_rv_bench"
    opts = load_case("synthetic_rv_bench").data.import_options()
    traces = read_te_folder(bundled / "te", options=opts)
    write_te_trace(tmp_path / "te.csv", traces[0])
    return {
        "case": {"kind": "rv_bench", "title": "test"},
        "reducer": {"case": "hu2020_rv80e_initial_reducer"},
        "data": {"te": str(tmp_path / "te.csv"),
                 "hysteresis": str(bundled / "hysteresis.csv")},
        "analyses": analyses,
    }, traces[0]  # fmt: skip


def test_bench_case_gives_the_required_result_names_from_the_shared_definitions(tmp_path):
    data, trace = _case(tmp_path, te_orders={"n_orders": 5})
    res = run_case(load_case_dict(data), RunOptions(progress=False)).to_dict()
    cat = res["analyses"]["catalogue"]["values"]
    for name in REQUIRED:
        assert name in cat
    assert cat[REQUIRED[0]] == pytest.approx(te_peak_to_peak(trace.forward_te) * ARCSEC_PER_RAD)
    diff = forward_backward_difference(
        trace.forward_position, trace.forward_te, trace.backward_position, trace.backward_te
    )
    assert cat[REQUIRED[2]] == pytest.approx(diff.mean() * ARCSEC_PER_RAD)
    orders = res["analyses"]["te_orders"]["values"]["te_orders"]
    assert len(orders) == 5
    assert set(orders[0]) == {"order", "amplitude [arcsec]", "phase [deg]", "source"}
    assert orders[0]["order"] == 40 and orders[0]["source"] == "crank rotation"
    assert cat["lost_motion [arcmin]"] > cat["backlash [arcmin]"] > 0
    json.dumps(res)


def test_bench_case_errors_name_the_field(tmp_path):
    data, _ = _case(tmp_path)
    data["data"]["te"] = str(tmp_path / "nope.csv")
    data["analyses"] = {"diagnosis": {}}
    with pytest.raises(CaseFileError) as ei:
        load_case_dict(data)
    text = str(ei.value)
    assert "data.te" in text and "nope.csv" in text and "calibration" in text


def test_relative_data_paths_resolve_beside_the_case_file(tmp_path):
    data, trace = _case(tmp_path)
    write_hysteresis(tmp_path / "h.csv", _hyst())
    lines = [
        "[case]", 'kind = "rv_bench"', "[reducer]", 'case = "hu2020_rv80e_initial_reducer"',
        "[data]", 'te = "te.csv"', 'hysteresis = "h.csv"',
    ]  # fmt: skip
    (tmp_path / "serial.toml").write_text("\n".join(lines) + "\n", encoding="utf-8")
    case = load_case(tmp_path / "serial.toml")
    assert case.data.te == str(tmp_path / "te.csv")


def _hyst():
    from gearte.models.bench_data import HysteresisCurve

    t = np.concatenate([np.linspace(784e3, -784e3, 50), np.linspace(-784e3, 784e3, 50)])
    return HysteresisCurve("mem", t, t / 1.4e9)


def test_bundled_synthetic_bench_runs_calibrates_and_writes_the_serial(tmp_path):
    from gearte.report.outputs import write_outputs

    result = run_case("synthetic_rv_bench", RunOptions(progress=False))
    paths = write_outputs(result, tmp_path / "out")
    res = json.loads(open(paths["results"], encoding="utf-8").read())
    a = res["analyses"]
    for name in REQUIRED:
        assert name in a["catalogue"]["values"]
    trend = a["te_orders"]["values"]["order_trend"]
    assert len(trend) == 24
    cal = a["calibration"]["values"]
    # known synthetic values (examples/synthetic_rv_bench/make_synthetic_bench.py)
    p = cal["parameters"]["contact_stiffness_factor"]
    assert not p["identified"] and "rig_compliance" in p["note"]  # only their sum is seen
    assert ["contact_stiffness_factor", "rig_compliance"] in cal["unidentifiable_groups"]
    # so the serial carries the whole compliance: f K_nom in series with the rig's 0.1/K_nom
    serial_rec = cal["calibrated_serial"]
    assert serial_rec["stiffness_scale"] == pytest.approx(1 / (1 / 0.9 + 0.1), rel=0.03)
    assert ["cam_bearing_clearance", "carrier_bearing_clearance"] in cal["unidentifiable_groups"]
    top = a["diagnosis"]["values"]["te_culprits"][0]
    assert top["source"] == "crank rotation" and top["probability_largest"] > 0.9
    text = (tmp_path / "out" / "calibrated_serial.toml").read_text(encoding="utf-8")
    serial = load_case_dict(tomllib.loads(text), source="calibrated_serial.toml")
    assert serial.case.kind == "rv_reducer"
    cranks = serial.reducer.cranks
    assert cranks.cam_bearing.radial_clearance_um == pytest.approx(3.5, abs=0.3)


@pytest.mark.parametrize("bad", ["x" * 5000, "nul\x00.csv"])
def test_unusable_data_paths_are_field_errors_not_crashes(tmp_path, bad):
    """Found by the case fuzzer: a name too long for the OS was an OSError."""
    data, _ = _case(tmp_path)
    data["data"]["te"] = bad
    data["reducer"]["case"] = bad
    with pytest.raises(CaseFileError) as ei:
        load_case_dict(data)
    assert "data.te" in str(ei.value) and "reducer.case" in str(ei.value)
