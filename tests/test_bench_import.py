"""Bench files as a rig exports them: column aliases, a column mapping, units given in the case,
the operating point read from the file names, the TE sign convention, every problem reported."""

from __future__ import annotations

import numpy as np
import pytest
from click.testing import CliRunner

from gearte.cli import main
from gearte.errors import BenchFileError, BenchFileErrors, CaseFileError, ParameterError
from gearte.io.bench import (
    ImportOptions,
    metadata_from_name,
    read_te_folder,
    read_te_trace,
)
from gearte.io.case_file import load_case, load_case_dict
from gearte.studies import RunOptions, run_case
from gearte.units import ARCSEC_PER_RAD, rad_to_arcsec, rad_to_deg

PATTERN = "{torque}Nm_{speed}rpm_{temp}C"


def _bundled_traces():
    from gearte.cases import case_path

    opts = load_case("synthetic_rv_bench").data.import_options()
    folder = case_path("synthetic_rv_bench").parent / "synthetic_rv_bench" / "te"
    return read_te_folder(folder, options=opts)


def _write_rig_file(path, trace, *, sign=-1.0, delim=";"):
    """A rig's export: its own column names, no units, no metadata, TE as output − nominal."""
    head = delim.join(["Angle CW", "TE CW", "Angle CCW", "Fehler rueckwaerts"])
    cols = [
        rad_to_deg(trace.forward_position), sign * rad_to_arcsec(trace.forward_te),
        rad_to_deg(trace.backward_position), sign * rad_to_arcsec(trace.backward_te),
    ]  # fmt: skip
    rows = [delim.join(f"{x:.10g}" for x in r) for r in zip(*cols, strict=True)]
    path.write_text("\n".join([head, *rows]) + "\n", encoding="utf-8")


def _rig_case(tmp_path, traces):
    te = tmp_path / "rig_export"
    te.mkdir()
    for k, t in enumerate(traces):
        name = f"SN0001_run{k}_{t.torque / 1e3:g}Nm_{t.speed_rpm:g}rpm_{t.oil_temperature:g}C.csv"
        _write_rig_file(te / name, t)
    lines = [
        "[case]", 'kind = "rv_bench"', 'title = "rig export, unedited"',
        "[reducer]", 'case = "hu2020_rv80e_initial_reducer"',
        "[data]", 'te = "rig_export"', f'file_name_pattern = "{PATTERN}"',
        'units = { position = "deg", te = "arcsec" }',
        'columns = { backward_te = "Fehler rueckwaerts" }',
        'te_convention = "output_minus_nominal"',
        "[analyses.te_orders]", "n_orders = 5",
    ]  # fmt: skip
    path = tmp_path / "rig.toml"
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")
    return path


def test_metadata_from_file_names():
    assert metadata_from_name("a/RV81_300Nm_15rpm_40C.csv", PATTERN) == {
        "torque_Nm": 300.0, "speed_rpm": 15.0, "oil_temperature_C": 40.0}  # fmt: skip
    assert metadata_from_name("x_12p5Nm_7,5rpm_-10C_b.csv", PATTERN) == {
        "torque_Nm": 12.5, "speed_rpm": 7.5, "oil_temperature_C": -10.0}  # fmt: skip
    assert metadata_from_name("RV81_300Nm.csv", PATTERN) is None
    with pytest.raises(ParameterError, match="unknown field"):
        metadata_from_name("a.csv", "{load}Nm")


def test_rig_style_export_runs_without_edits(tmp_path):
    """The rig's own header (aliases + one mapped column), units given per group in the case,
    torque/speed/temperature from the file names, TE written output − nominal."""
    traces = _bundled_traces()[:3]
    path = _rig_case(tmp_path, traces)
    v = CliRunner().invoke(main, ["validate", str(path)])
    assert v.exit_code == 0, v.output
    res = run_case(load_case(path), RunOptions(progress=False)).to_dict()
    cat = res["analyses"]["catalogue"]["values"]
    ops = cat["operating_points"]
    by_point = {(o["torque [N·m]"], o["speed [rpm]"], o["oil_temperature [°C]"]): o for o in ops}
    for t in traces:
        o = by_point[(t.torque / 1e3, t.speed_rpm, t.oil_temperature)]
        assert o["speed [rpm]"] == t.speed_rpm and o["oil_temperature [°C]"] == t.oil_temperature
        # the sign flip restores gearte's convention exactly (same numbers as the original)
        fb = np.mean(t.forward_te) - np.mean(t.backward_te)
        assert o["forward_backward_difference_mean [arcsec]"] == pytest.approx(
            fb * ARCSEC_PER_RAD, abs=0.05)  # fmt: skip
        assert o["forward_backward_difference_mean [arcsec]"] > 0
    assert cat["te_convention"] == "nominal_minus_output"
    assert cat["te_convention_of_files"] == "output_minus_nominal"
    assert "least loaded" in cat["reference_reason"]


def test_a_series_without_metadata_names_every_file(tmp_path):
    traces = _bundled_traces()[:2]
    for k, t in enumerate(traces):
        _write_rig_file(tmp_path / f"run{k}.csv", t)
    opts = ImportOptions(units={"position": "deg", "te": "arcsec"},
                         columns={"backward_te": "Fehler rueckwaerts"})  # fmt: skip
    with pytest.raises(BenchFileErrors) as ei:
        read_te_folder(tmp_path, options=opts)
    files = {e.file for e in ei.value.errors}
    assert files == {str(tmp_path / "run0.csv"), str(tmp_path / "run1.csv")}
    assert all("torque_Nm" in e.reason for e in ei.value.errors)


def test_a_name_contradicting_the_header_is_an_error(tmp_path):
    t = _bundled_traces()[0]
    from gearte.io.bench import write_te_trace

    p = tmp_path / f"x_{t.torque / 1e3 + 1:g}Nm_{t.speed_rpm:g}rpm_{t.oil_temperature:g}C.csv"
    write_te_trace(p, t)
    with pytest.raises(BenchFileError, match="contradicts the file name"):
        read_te_trace(p, ImportOptions(file_name_pattern=PATTERN))


def test_te_convention_flips_the_sign(tmp_path):
    t = _bundled_traces()[0]
    _write_rig_file(tmp_path / "a.csv", t, sign=1.0, delim=",")
    units = {"position": "deg", "te": "arcsec"}
    cols = {"backward_te": "Fehler rueckwaerts"}
    a = read_te_trace(tmp_path / "a.csv", ImportOptions(columns=cols, units=units))
    flipped = ImportOptions(columns=cols, units=units, te_convention="output_minus_nominal")
    b = read_te_trace(tmp_path / "a.csv", flipped)
    np.testing.assert_allclose(a.forward_te, -b.forward_te)
    np.testing.assert_allclose(a.backward_te, -b.backward_te)


def test_bad_import_options_are_field_errors(tmp_path):
    with pytest.raises(ParameterError, match="data.columns.forward_tee"):
        ImportOptions(columns={"forward_tee": "x"})
    with pytest.raises(ParameterError, match="data.units.te"):
        ImportOptions(units={"te": "furlong"})
    traces = _bundled_traces()[:1]
    path = _rig_case(tmp_path, traces)
    data = __import__("tomllib").loads(path.read_text(encoding="utf-8"))
    data["data"]["te_convention"] = "upside_down"
    data["data"]["te"] = str(tmp_path / "rig_export")
    with pytest.raises(CaseFileError, match="te_convention"):
        load_case_dict(data)


def test_validate_reports_every_problem_of_every_file(tmp_path):
    traces = _bundled_traces()[:3]
    path = _rig_case(tmp_path, traces)
    files = sorted((tmp_path / "rig_export").iterdir())
    # file 0: two unknown columns; file 1: renamed so its name lacks the operating point
    text = files[0].read_text(encoding="utf-8").splitlines()
    text[0] = "Angle CW;Bogus one;Angle CCW;Bogus two"
    files[0].write_text("\n".join(text) + "\n", encoding="utf-8")
    files[1].rename(files[1].with_name("no_operating_point.csv"))
    r = CliRunner().invoke(main, ["validate", str(path)])
    assert r.exit_code != 0
    out = r.output
    assert "3 error(s)" in out, out
    assert out.count("Bogus") >= 2 and "no_operating_point.csv" in out


def test_the_reference_trace_is_chosen_or_stated_never_silent(tmp_path):
    traces = _bundled_traces()[:3]
    path = _rig_case(tmp_path, traces)
    data = __import__("tomllib").loads(path.read_text(encoding="utf-8"))
    data["data"]["te"] = str(tmp_path / "rig_export")
    names = sorted(p.name for p in (tmp_path / "rig_export").iterdir())
    data["data"]["reference"] = names[-1]
    res = run_case(load_case_dict(data), RunOptions(progress=False)).to_dict()
    cat = res["analyses"]["catalogue"]["values"]
    assert cat["reference_operating_point"] == names[-1]
    assert "chosen in the case" in cat["reference_reason"]
    data["data"]["reference"] = "nope.csv"
    with pytest.raises(BenchFileError, match="reference 'nope.csv' is not one of"):
        run_case(load_case_dict(data), RunOptions(progress=False))
