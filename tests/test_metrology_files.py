"""Metrology readers (issue 16): formats, exact write/read round trip, every malformed file one
clear error naming file, line and column, and random files never escape as a traceback."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from gearte.errors import MeasurementFileError
from gearte.io import metrology as mt

PROFILE = """# format: disc_profile
# instrument: gear measuring machine
serial,tooth,profile_parameter [deg],deviation [um]
D-01,1,-60,1.0
D-01,1,0,0.5
D-01,1,60,-1.0
D-01,2,-60,0.0
D-01,2,0,0.2
D-01,2,60,0.1
"""


def _write(tmp_path, text, name="f.csv"):
    p = tmp_path / name
    p.write_text(text, encoding="utf-8")
    return p


def test_disc_profile_read_in_gearte_units(tmp_path):
    got = mt.read_disc_profiles(_write(tmp_path, PROFILE), teeth=2)
    p = got["D-01"]
    assert p.teeth == 2
    np.testing.assert_allclose(p.phase[0], np.radians([-60, 0, 60]), rtol=0, atol=1e-15)
    np.testing.assert_allclose(p.deviation[1], [0.0, 2e-4, 1e-4], rtol=1e-12)


def test_every_format_round_trips_exactly(tmp_path):
    rng = np.random.default_rng(1)
    prof = {
        "D-1": mt.DiscProfile(
            tuple(np.sort(rng.uniform(-3, 3, 5)) for _ in range(3)),
            tuple(rng.normal(0, 0.003, 5) for _ in range(3)),
        )
    }
    pitch = {"D-1": rng.normal(0, 0.005, 3), "D-2": rng.normal(0, 0.005, 3)}
    pins = {"H-7": mt.PinSet(rng.uniform(9.9, 10, 4), rng.normal(0, 1e-3, 4), np.zeros(4))}
    cranks = {"C-1": mt.CrankCams(rng.uniform(1.4, 1.6, 2), rng.normal(0, 0.01, 2))}
    bores = {"D-1": rng.normal(50, 0.01, (3, 2))}
    runout = {"P-1": mt.Runout(0.012, 1.3), "P-2": mt.Runout(0.004, -2.0)}
    clear = {"C-1": {"cam_1": 0.003, "cam_2": 0.004, "carrier": 0.002}}
    mt.write_disc_profiles(tmp_path / "a.csv", prof)
    mt.write_disc_pitch(tmp_path / "b.csv", pitch)
    mt.write_pins(tmp_path / "c.csv", pins)
    mt.write_crank_eccentricity(tmp_path / "d.csv", cranks)
    mt.write_disc_bores(tmp_path / "e.csv", bores)
    mt.write_runout(tmp_path / "f.csv", runout)
    mt.write_bearing_clearances(tmp_path / "g.csv", clear)
    p2 = mt.read_disc_profiles(tmp_path / "a.csv", teeth=3)["D-1"]
    for a, b in zip(prof["D-1"].deviation, p2.deviation, strict=True):
        np.testing.assert_allclose(b, a, rtol=1e-14, atol=1e-19)
    back = mt.read_disc_pitch(tmp_path / "b.csv", teeth=3)
    np.testing.assert_allclose(back["D-2"], pitch["D-2"], rtol=1e-14)
    np.testing.assert_array_equal(
        mt.read_pins(tmp_path / "c.csv", 4)["H-7"].diameter, pins["H-7"].diameter
    )
    c2 = mt.read_crank_eccentricity(tmp_path / "d.csv", 2)["C-1"]
    np.testing.assert_array_equal(c2.eccentricity, cranks["C-1"].eccentricity)
    np.testing.assert_allclose(c2.phase, cranks["C-1"].phase, rtol=1e-14)
    np.testing.assert_array_equal(mt.read_disc_bores(tmp_path / "e.csv", 3)["D-1"], bores["D-1"])
    assert mt.read_runout(tmp_path / "f.csv")["P-2"].phase == pytest.approx(-2.0, rel=1e-14)
    assert mt.read_bearing_clearances(tmp_path / "g.csv", 2)["C-1"]["cam_2"] == pytest.approx(4e-3)


HEAD = "serial,tooth,profile_parameter [deg],deviation [um]\n"
ROWS = "D-01,1,-60,1.0\nD-01,1,0,0.5\nD-01,1,60,-1.0\n"

# (what is wrong, reader, file text, expected line, text expected in the column, in the message)
MALFORMED = [
    ("empty file", "profile", "", 1, None, "empty"),
    (
        "unknown column",
        "profile",
        HEAD.replace("deviation", "deviaton") + ROWS,
        1,
        "4",
        "did you mean 'deviation'",
    ),
    (
        "missing column",
        "profile",
        "serial,tooth,profile_parameter [deg]\nD-01,1,0\n",
        1,
        "deviation",
        "missing",
    ),
    ("wrong unit", "profile", HEAD.replace("[um]", "[N]") + ROWS, 1, "4", "not a length unit"),
    ("missing unit", "profile", HEAD.replace(" [um]", "") + ROWS, 1, "4", "no unit"),
    ("NaN value", "profile", HEAD + ROWS.replace("0.5", "nan"), 3, "deviation", "finite"),
    ("not a number", "profile", HEAD + ROWS.replace("0.5", "abc"), 3, "deviation", "not a number"),
    (
        "non-monotone angles",
        "profile",
        HEAD + "D-01,1,-60,1\nD-01,1,10,0\nD-01,1,5,0\n",
        4,
        "profile_parameter",
        "strictly increasing",
    ),
    ("wrong tooth count", "profile", HEAD + ROWS, 4, "tooth", "expected 2"),
    (
        "tooth beyond the disc",
        "pitch",
        "serial,tooth,cumulative_pitch [um]\nD,1,0\nD,2,1\nD,3,2\n",
        4,
        "tooth",
        "does not exist",
    ),
    (
        "duplicate serial",
        "runout",
        "serial,runout [um],phase [deg]\nP-1,3,0\nP-1,4,10\n",
        3,
        "serial",
        "duplicate",
    ),
    (
        "duplicate tooth",
        "pitch",
        "serial,tooth,cumulative_pitch [um]\nD,1,0\nD,1,1\n",
        3,
        "tooth",
        "duplicate",
    ),
    ("ragged row", "profile", HEAD + "D-01,1,0\n", 2, None, "cells"),
    ("bad serial", "runout", "serial,runout [um],phase [deg]\n,3,0\n", 2, "serial", "empty cell"),
    (
        "implausible magnitude (unit mistake)",
        "profile",
        HEAD + ROWS.replace("1.0", "900"),
        2,
        "deviation",
        "plausible",
    ),
    (
        "too few points per tooth",
        "profile",
        HEAD + "D-01,1,0,1\nD-01,1,10,1\n",
        3,
        "tooth",
        "at least 3",
    ),
    ("duplicate column", "runout", "serial,runout [um],runout [mm],phase [deg]\n", 1, "3", "twice"),
    ("header only", "runout", "serial,runout [um],phase [deg]\n", 2, None, "no data"),
    (
        "unknown metadata",
        "runout",
        "# temprature_C: 20\nserial,runout [um],phase [deg]\nP,1,0\n",
        1,
        None,
        "did you mean",
    ),
    (
        "wrong format declared",
        "runout",
        "# format: pins\nserial,runout [um],phase [deg]\nP,1,0\n",
        1,
        None,
        "declares format",
    ),
    (
        "unknown bearing",
        "bearing",
        "serial,bearing,radial_clearance [um]\nC,cam_9,3\n",
        2,
        "bearing",
        "cam_<j>",
    ),
    (
        "missing pin",
        "pins",
        "serial,pin,diameter [mm]\nH,1,10\nH,3,10\n",
        3,
        "pin",
        "missing pin 2",
    ),
    ("non-integer index", "pins", "serial,pin,diameter [mm]\nH,1.5,10\n", 2, "pin", "whole number"),
    (
        "negative diameter",
        "pins",
        "serial,pin,diameter [mm]\nH,1,-10\n",
        2,
        "diameter",
        "plausible",
    ),
    (
        "unit on an index",
        "pins",
        "serial,pin [mm],diameter [mm]\nH,1,10\n",
        1,
        "2",
        "takes no unit",
    ),
]

READERS = {
    "profile": lambda p: mt.read_disc_profiles(p, teeth=2),
    "pitch": lambda p: mt.read_disc_pitch(p, teeth=2),
    "runout": mt.read_runout,
    "bearing": lambda p: mt.read_bearing_clearances(p, cams=2),
    "pins": lambda p: mt.read_pins(p, pins=3),
}


@pytest.mark.parametrize(
    ("what", "reader", "text", "line", "column", "words"), MALFORMED, ids=[m[0] for m in MALFORMED]
)
def test_malformed_file_one_clear_error(tmp_path, what, reader, text, line, column, words):
    path = _write(tmp_path, text)
    with pytest.raises(MeasurementFileError) as info:
        READERS[reader](path)
    err = info.value
    assert err.file == str(path)
    assert err.line == line, str(err)
    if column is not None:
        assert column in str(err.column), str(err)
    assert words in str(err), str(err)


def test_at_least_fifteen_kinds_of_malformed_files():
    assert len({m[0] for m in MALFORMED}) >= 15


def test_binary_file_is_refused(tmp_path):
    p = tmp_path / "x.csv"
    p.write_bytes(b"serial,runout [um]\n\xff\xfe\x00")
    with pytest.raises(MeasurementFileError, match="UTF-8"):
        mt.read_runout(p)


def test_folder_and_nul_path_give_one_plain_error(tmp_path):
    """A folder is named as such (not wrapped in "cannot read: <file>: ..."), and a path with a
    NUL byte is a MeasurementFileError, not a bare ValueError (io/_textfile.py)."""
    with pytest.raises(MeasurementFileError, match="is a folder") as ei:
        mt.read_runout(tmp_path)
    assert "cannot read" not in str(ei.value)
    with pytest.raises(MeasurementFileError, match="cannot read: embedded null byte"):
        mt.read_runout(str(tmp_path / "a\x00b.csv"))


_ALPHABET = st.sampled_from(list("serial,toothpfiledv_[]um1234567890.-#: \nDnaNx;\t"))


@settings(
    max_examples=150, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture]
)
@given(
    text=st.text(_ALPHABET, max_size=300),
    head=st.sampled_from(
        ["", HEAD, "serial,runout [um],phase [deg]\n", "serial,pin,diameter [mm]\n"]
    ),
    which=st.sampled_from(sorted(READERS)),
)
def test_random_files_raise_only_measurement_errors(tmp_path, text, head, which):
    """A property test: whatever the bytes, a reader returns parts or raises
    MeasurementFileError — never another exception."""
    path = _write(tmp_path, head + text, "random.csv")
    try:
        READERS[which](path)
    except MeasurementFileError as exc:
        assert exc.file == str(path)
