"""Measured values against the design: a metrology file whose header says ``[um]`` where its
numbers are millimetres (or a file of another reducer) is refused naming file, line, column and
unit — by ``gearte validate`` as by ``gearte run``, before any analysis. Before, ``x [um]`` on
the bore centres of the bundled serial ran silently (cam-bearing loads of 10.2 MN, a negative
disc torque share)."""

from __future__ import annotations

import re
import shutil
from pathlib import Path

import pytest
from click.testing import CliRunner

from gearte.cli import main
from gearte.errors import CaseFileError
from gearte.io.case_file import load_case

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
LOT = EXAMPLES / "lots" / "synthetic_rv110e"


def _copy_lot(tmp_path: Path) -> Path:
    d = tmp_path / "lot"
    shutil.copytree(LOT, d)
    return d


def _case(tmp_path: Path, bundled: str, folder: Path) -> Path:
    text = (EXAMPLES / f"{bundled}.toml").read_text(encoding="utf-8")
    text = text.replace('"lots/synthetic_rv110e/', f'"{folder.as_posix()}/')
    p = tmp_path / f"{bundled}.toml"
    p.write_text(text, encoding="utf-8")
    return p


def _edit(path: Path, old: str, new: str) -> None:
    text = path.read_text(encoding="utf-8")
    assert old in text
    path.write_text(text.replace(old, new), encoding="utf-8")


@pytest.mark.parametrize("bundled", ["synthetic_rv110e_serial", "synthetic_rv110e_lot"])
def test_bore_centres_in_mm_under_an_um_header_are_refused(tmp_path, bundled):
    folder = _copy_lot(tmp_path)
    _edit(folder / "disc_bores.csv", "x [mm],y [mm]", "x [um],y [um]")
    case = _case(tmp_path, bundled, folder)
    with pytest.raises(CaseFileError) as info:
        load_case(case)
    msg = str(info.value)
    assert "disc_bores.csv, line 3, column 3 'x [um]'" in msg
    assert "44.999 [um]" in msg and "from the design's 45 mm" in msg
    assert "read as [mm] it would fit" in msg


def test_validate_and_run_both_refuse_the_unit_slip_with_exit_2(tmp_path):
    folder = _copy_lot(tmp_path)
    _edit(folder / "disc_bores.csv", "x [mm],y [mm]", "x [um],y [um]")
    case = _case(tmp_path, "synthetic_rv110e_serial", folder)
    for args in (["validate", str(case)], ["run", str(case), "--out", str(tmp_path / "o")]):
        res = CliRunner().invoke(main, args)
        assert res.exit_code == 2, res.output
        assert "'x [um]'" in res.output
    assert not (tmp_path / "o").exists()


def test_eccentricity_of_another_reducer_is_refused(tmp_path):
    """Eccentricities 2 mm above the design's 1.5 mm: in the format's range, not the design's."""
    folder = _copy_lot(tmp_path)
    p = folder / "crank_eccentricity.csv"
    text = p.read_text(encoding="utf-8")
    p.write_text(re.sub(r",1\.(\d+),", lambda m: f",3.{m[1]},", text), encoding="utf-8")
    case = _case(tmp_path, "synthetic_rv110e_serial", folder)
    with pytest.raises(
        CaseFileError,
        match=r"crank_eccentricity.csv, line 3, column 3 "
        r"'eccentricity \[mm\]': 3.50603 \[mm\] \(cam 1 of serial 'C-0001'\)",
    ):
        load_case(case)


def test_pin_diameters_against_the_design(tmp_path):
    from gearte.errors import MeasurementFileError
    from gearte.io import metrology as mt
    from gearte.studies._measured import check_measured_against_design
    from gearte.studies.rv_reducer import build_reducer

    red = build_reducer(load_case("han2023_rv110e_no_errors").reducer)
    zp, d = red.pins.count, 2.0 * red.pins.pin_radius
    import numpy as np

    ok = {"P-1": mt.PinSet(np.full(zp, d + 0.002), np.zeros(zp), np.zeros(zp))}
    mt.write_pins(tmp_path / "pins.csv", ok)
    check_measured_against_design(
        red, str(tmp_path / "pins.csv"), pins=mt.read_pins(tmp_path / "pins.csv", pins=zp)
    )
    bad = {"P-1": mt.PinSet(np.full(zp, 0.5 * d), np.zeros(zp), np.zeros(zp))}
    mt.write_pins(tmp_path / "pins.csv", bad)
    with pytest.raises(MeasurementFileError, match=r"pins.csv, line \d+, column 3 'diameter"):
        check_measured_against_design(
            red, str(tmp_path / "pins.csv"), pins=mt.read_pins(tmp_path / "pins.csv", pins=zp)
        )


def test_bundled_measured_cases_pass_the_design_checks():
    assert load_case("synthetic_rv110e_serial").case.kind == "rv_serial"
    assert load_case("synthetic_rv110e_lot").case.kind == "rv_lot"


_LENGTH_HEADERS = [
    ("disc_bores.csv", "x [mm],y [mm]", "x [um],y [um]"),
    ("crank_eccentricity.csv", "eccentricity [mm]", "eccentricity [um]"),
    ("bearing_clearance.csv", "radial_clearance [um]", "radial_clearance [mm]"),
    ("planet_runout.csv", "runout [um]", "runout [mm]"),
    ("disc_profile.csv", "deviation [um]", "deviation [mm]"),
    ("disc_pitch.csv", "cumulative_pitch [um]", "cumulative_pitch [mm]"),
]


@pytest.mark.slow
@pytest.mark.parametrize(("file", "old", "new"), _LENGTH_HEADERS)
def test_validate_refuses_what_run_refuses_for_every_length_unit_slip(tmp_path, file, old, new):
    """Every length column of the bundled serial's files with the other unit in its header:
    ``validate`` and ``run`` end the same way (both exit 2 naming the file, or both 0)."""
    folder = _copy_lot(tmp_path)
    _edit(folder / file, old, new)
    case = _case(tmp_path, "synthetic_rv110e_serial", folder)
    v = CliRunner().invoke(main, ["validate", str(case)])
    r = CliRunner().invoke(main, ["run", str(case), "--out", str(tmp_path / "o"), "--no-report"])
    assert v.exit_code == r.exit_code, (v.output, r.output)
    if v.exit_code:
        assert v.exit_code == 2 and file in v.output


def test_design_check_of_a_serial_with_another_bore_count_does_not_crash(tmp_path):
    """Found by the fuzz run: a serial with 2 bores where the design has 3 (read without the
    design's count) broke the comparison (a numpy broadcast error); the count is the reader's
    check, the bores given are compared."""
    import numpy as np

    from gearte.io import metrology as mt

    nominal = np.array([[45.0, 0.0], [-22.5, 38.97], [-22.5, -38.97]])
    mt.write_disc_bores(tmp_path / "b.csv", {"D-1": nominal[:2] + 0.001})
    rows = mt.read_disc_bores(tmp_path / "b.csv")
    mt.check_against_design(tmp_path / "b.csv", "disc_bores", rows, nominal, 45.0)
