"""Foundation: units, case files, results, report writing, execution layer, CLI."""

from __future__ import annotations

import json
import math
import subprocess
import sys

import numpy as np
import pytest
from click.testing import CliRunner

from gearte import units
from gearte.cases import list_cases
from gearte.errors import CaseFileError, ParameterError
from gearte.execution import RunningStats, chunk_sizes, map_chunks, spawn_generators, spawn_seeds
from gearte.io.case_file import load_case, load_case_dict
from gearte.report.outputs import write_outputs
from gearte.studies import run_case

GOOD = {"case": {"kind": "foundation_test", "title": "t"}, "demo": {"length_mm": 10.0}}


def test_units_round_trip_and_dms():
    assert units.rad_to_arcmin(math.pi / 10800) == pytest.approx(1.0)
    assert units.arcsec_to_rad(units.rad_to_arcsec(0.123)) == pytest.approx(0.123)
    assert np.allclose(units.deg_to_rad(np.array([180.0])), [math.pi])
    assert units.format_dms(units.arcmin_to_rad(9 + 59 / 60)) == "9′59″"
    assert units.format_dms(units.arcsec_to_rad(34)) == "0′34″"


def test_case_dict_validates_and_names_fields():
    case = load_case_dict(GOOD)
    assert case.demo.length_mm == 10.0
    bad = {"case": {"kind": "foundation_test"}, "demo": {"length_mm": -1, "colour": "red"}}
    with pytest.raises(CaseFileError) as err:
        load_case_dict(bad)
    fields = [f for f, _ in err.value.errors]
    assert fields == ["demo.length_mm", "demo.colour"]
    assert "greater than 0" in str(err.value) and "unknown key" in str(err.value)


@pytest.mark.parametrize(
    "data, field",
    [
        ({"demo": {"length_mm": 1}}, "case"),
        ({"case": {"kind": "nope"}, "demo": {"length_mm": 1}}, "case.kind"),
        ({"case": {"kind": "foundation_test"}}, "demo"),
        (
            {"case": {"kind": "foundation_test"}, "demo": {"length_mm": float("nan")}},
            "demo.length_mm",
        ),
        ({"case": {"kind": "foundation_test"}, "demo": {"length_mm": "ten"}}, "demo.length_mm"),
        (
            {"case": {"kind": "foundation_test", "references": ["x"]}, "demo": {"length_mm": 1}},
            "case.references",
        ),
        ([1, 2], "(case)"),
    ],
)
def test_bad_case_dicts_name_the_field(data, field):
    with pytest.raises(CaseFileError) as err:
        load_case_dict(data)
    assert err.value.errors[0][0] == field


def test_toml_syntax_error_is_a_case_error(tmp_path):
    p = tmp_path / "broken.toml"
    p.write_text("[case\nkind = 'x'")
    with pytest.raises(CaseFileError, match="TOML syntax"):
        load_case(p)


def test_case_name_defaults_to_file_stem(tmp_path):
    p = tmp_path / "my_drive.toml"
    p.write_text('[case]\nkind = "foundation_test"\n[demo]\nlength_mm = 2.0\n')
    assert load_case(p).case.name == "my_drive"


def test_results_json_and_report_are_written(tmp_path):
    result = run_case(GOOD)
    paths = write_outputs(result, tmp_path / "out")
    data = json.loads(paths["results"].read_text())
    assert data["analyses"]["demo"]["values"]["total_length [mm]"] == pytest.approx(15.0)
    assert data["analyses"]["demo"]["values"]["x [mm]"] == [0.0, 5.0, 10.0]
    assert data["case"]["kind"] == "foundation_test" and "gearte_version" in data
    assert paths["results"].stat().st_mode & 0o044 == 0o044  # readable by others, like any file
    html = paths["report"].read_text()
    assert "data:image/png;base64," in html and "Total length" in html and "15 mm" in html


def test_failed_report_leaves_nothing_half_written(tmp_path):
    bad = {**GOOD, "demo": {"length_mm": 1.0, "fail_in_plot": True}}
    result = run_case(bad)
    with pytest.raises(RuntimeError):
        write_outputs(result, tmp_path / "out")
    assert not (tmp_path / "out").exists() or not any((tmp_path / "out").iterdir())


def test_chunking_and_streams_do_not_depend_on_workers():
    assert chunk_sizes(10, 4) == [4, 4, 2] and chunk_sizes(0, 3) == []
    with pytest.raises(ParameterError):
        chunk_sizes(10, 0)

    def task(args):
        n, ss = args
        return RunningStats.of(np.random.default_rng(ss).normal(size=n))

    tasks = list(zip(chunk_sizes(100_000, 7_000), spawn_seeds(42, 15), strict=True))
    stats = []
    for workers in (1, 2):
        parts = map_chunks(task, tasks, workers=workers, progress=False)
        total = RunningStats()
        for p in parts:
            total = total.merge(p)
        stats.append((total.count, total.mean, total.sd, total.min, total.max))
    assert stats[0] == stats[1]
    g1, g2 = spawn_generators(1, 2)
    assert g1.random() != g2.random()


def test_running_stats_merge_matches_numpy():
    x = np.random.default_rng(0).normal(3.0, 2.0, size=10_001)
    s = RunningStats()
    for part in np.array_split(x, 7):
        s = s.merge(RunningStats.of(part))
    assert s.count == x.size
    assert s.mean == pytest.approx(x.mean(), rel=1e-12)
    assert s.sd == pytest.approx(x.std(ddof=1), rel=1e-12)
    assert (s.min, s.max) == (x.min(), x.max())


@pytest.mark.parametrize("name", sorted(list_cases()))
def test_every_bundled_case_loads(name):
    case = load_case(name)
    assert case.case.name == name


def test_cli_help_and_cases():
    from gearte.cli import main

    r = CliRunner().invoke(main, ["--help"])
    assert r.exit_code == 0 and "gearte" in r.output
    r = CliRunner().invoke(main, ["cases", "--kinds"])
    assert r.exit_code == 0


def test_cli_help_does_not_import_heavy_modules():
    code = (
        "import sys, gearte.cli; "
        "mods = ('numpy', 'pydantic', 'matplotlib', 'numba', 'scipy'); "
        "heavy = [m for m in mods if m in sys.modules]; "
        "print(','.join(heavy))"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == ""


def test_cli_run_validate_and_errors(tmp_path):
    from gearte.cli import main

    good = tmp_path / "good.toml"
    good.write_text('[case]\nkind = "foundation_test"\n[demo]\nlength_mm = 4.0\n')
    bad = tmp_path / "bad.toml"
    bad.write_text('[case]\nkind = "foundation_test"\n[demo]\nlength_mm = -4.0\n')
    runner = CliRunner()
    r = runner.invoke(main, ["run", str(good), "--out", str(tmp_path / "o"), "--no-progress"])
    assert r.exit_code == 0, r.output
    assert (tmp_path / "o" / "results.json").is_file()
    assert (tmp_path / "o" / "report.html").is_file()
    r = runner.invoke(main, ["validate", str(bad)])
    assert r.exit_code == 2
    assert "demo.length_mm" in r.output and "Traceback" not in r.output
    r = runner.invoke(main, ["run", "no_such_case"])
    assert r.exit_code == 2 and "bundled cases" in r.output


def test_extra_output_files_are_written_beside_results(tmp_path):
    result = run_case(GOOD)
    result["demo"].files["table.csv"] = "a,b\n1,2\n"
    paths = write_outputs(result, tmp_path / "o", report=False)
    assert (tmp_path / "o" / "table.csv").read_text() == "a,b\n1,2\n"
    # with the tabular results every kind writes as CSV (scalars, series, mappings)
    assert set(paths) == {"results", "table.csv", "summary.csv", "demo_x.csv", "demo_map.csv"}
    result["demo"].files = {"../escape.csv": "x"}
    with pytest.raises(ValueError, match="bad output file name"):
        write_outputs(result, tmp_path / "o2", report=False)
