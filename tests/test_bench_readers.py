"""Bench measurement readers (issue 17 item 1): TE traces and hysteresis curves from CSV.

Every malformed file gives ONE BenchFileError naming file, line and column; random files never
let another exception escape.
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from gearte.errors import BenchFileError
from gearte.io.bench import (
    HysteresisCurve,
    TETrace,
    read_hysteresis,
    read_te_folder,
    read_te_trace,
    write_hysteresis,
    write_te_trace,
)
from gearte.units import arcsec_to_rad, deg_to_rad

N = 64


def _te_text(n=N, header=None, meta=("# speed_rpm: 15", "# torque_Nm: 10")):
    pos = np.linspace(0.0, 360.0, n, endpoint=False)
    te = 10 * np.sin(np.radians(pos) * 40)
    lines = [*meta]
    lines.append(
        header
        or "forward_position [deg],forward_te [arcsec],backward_position [deg],backward_te [arcsec]"
    )
    for p, t in zip(pos, te, strict=True):
        lines.append(f"{p:.6f},{t:.6f},{360 - p:.6f},{t - 20:.6f}")
    return lines


def _hyst_text(n=40):
    t = np.concatenate([np.linspace(784, -784, n), np.linspace(-784, 784, n)])
    a = t / 500.0 + np.sign(t) * 0.3
    lines = ["torque [N·m],angle [arcmin]"]
    lines += [f"{x:.6f},{y:.6f}" for x, y in zip(t, a, strict=True)]
    return lines


def _write(tmp_path, lines, name="f.csv"):
    p = tmp_path / name
    p.write_text("\n".join(lines) + "\n", encoding="utf-8")
    return p


def test_te_trace_reads_four_column_layout_in_declared_units(tmp_path):
    tr = read_te_trace(_write(tmp_path, _te_text()))
    assert tr.speed_rpm == 15.0 and tr.torque == pytest.approx(10_000.0)
    assert tr.forward_position[1] == pytest.approx(deg_to_rad(360 / N))
    assert np.max(tr.forward_te) == pytest.approx(arcsec_to_rad(10.0), rel=1e-3)
    assert tr.backward_te.mean() == pytest.approx(arcsec_to_rad(-20.0), abs=1e-9)


def test_te_trace_units_declared_in_header_instead_of_names(tmp_path):
    lines = _te_text(
        header="forward_position,forward_te,backward_position,backward_te",
        meta=("# angle_unit: deg", "# te_unit: arcsec", "# oil_temperature_C: 40"),
    )
    lines = ["# te_unit: arcsec" if ln == "# te_unit: arcsec" else ln for ln in lines]
    tr = read_te_trace(_write(tmp_path, lines))
    assert tr.oil_temperature == 40.0
    # the angle_unit declares the positions; TE in arcsec
    assert np.ptp(tr.forward_position) == pytest.approx(deg_to_rad(360 * (N - 1) / N))


def test_te_trace_semicolon_and_arcmin_and_forward_only(tmp_path):
    pos = np.linspace(0, 2 * np.pi, 50, endpoint=False)
    lines = ["position [rad];te [arcmin]"] + [f"{p};{0.1 * np.sin(p)}" for p in pos]
    tr = read_te_trace(_write(tmp_path, lines))
    assert tr.backward_te is None and set(tr.directions()) == {"forward"}
    assert tr.forward_te.max() == pytest.approx(np.radians(0.1 / 60), rel=1e-2)


def test_te_round_trip_through_writer_is_exact(tmp_path):
    tr = read_te_trace(_write(tmp_path, _te_text()))
    write_te_trace(tmp_path / "g.csv", tr)
    back = read_te_trace(tmp_path / "g.csv")
    for a, b in zip(
        (tr.forward_position, tr.forward_te, tr.backward_position, tr.backward_te),
        (back.forward_position, back.forward_te, back.backward_position, back.backward_te),
        strict=True,
    ):
        np.testing.assert_allclose(a, b, rtol=1e-14, atol=1e-18)
    assert back.speed_rpm == tr.speed_rpm and back.torque == pytest.approx(tr.torque)


def test_te_folder_reads_every_operating_point_sorted(tmp_path):
    for k in (2, 1, 3):
        _write(tmp_path, _te_text(meta=(f"# speed_rpm: {k}", "# torque_Nm: 0")), name=f"op{k}.csv")
    traces = read_te_folder(tmp_path)
    assert [t.speed_rpm for t in traces] == [1.0, 2.0, 3.0]


def test_hysteresis_reads_and_marks_branches(tmp_path):
    c = read_hysteresis(_write(tmp_path, _hyst_text()))
    assert isinstance(c, HysteresisCurve) and c.branch is None
    assert c.torque.max() == pytest.approx(784e3)
    lines = _hyst_text()
    lines[0] += ",branch"
    n = len(lines) - 1
    marks = ["unloading"] * (n // 4) + ["loading"] * (n // 4)
    marks += ["unloading"] * (n // 4) + ["loading"] * (n - 3 * (n // 4))
    lines[1:] = [f"{ln},{m}" for ln, m in zip(lines[1:], marks, strict=True)]
    c = read_hysteresis(_write(tmp_path, lines))
    assert set(np.unique(c.branch)) == {-1, 1}
    assert np.all(c.branch[: n // 2 - 1] == -1) and np.all(c.branch[n // 2 + 1 :] == 1)


def _te_mutants():
    """(label, lines, expected line or None, fragment of the column or None, reason fragment)."""
    base = _te_text()
    hdr = len(base) - N  # 1-based line of the header
    m = []

    def mut(label, lines, line, col, why):
        m.append(pytest.param(lines, line, col, why, id=label))

    mut("empty_file", [""], 1, None, "empty")
    mut("only_metadata", ["# speed_rpm: 10"], 1, None, "no column names")
    mut("header_without_data", base[:hdr], hdr + 1, None, "no data rows")
    mut(
        "missing_column",
        [
            *base[: hdr - 1],
            "forward_position [deg],forward_te [arcsec],backward_position [deg]",
            *[",".join(r.split(",")[:3]) for r in base[hdr:]],
        ],
        hdr,
        None,
        "backward_te",
    )
    lines = list(base)
    lines[hdr - 1] = lines[hdr - 1].replace("forward_te [arcsec]", "forward_te [furlong]")
    mut("wrong_unit", lines, hdr, "forward_te", "not an angle unit")
    lines = list(base)
    lines[hdr - 1] = lines[hdr - 1].replace("forward_te [arcsec]", "forward_te")
    mut("no_unit", lines, hdr, "forward_te", "no unit")
    lines = list(base)
    lines[hdr + 9] = lines[hdr + 9].replace(lines[hdr + 9].split(",")[1], "nan", 1)
    mut("nan_cell", lines, hdr + 10, "forward_te", "not a finite number")
    lines = list(base)
    lines[hdr + 5] = lines[hdr + 5].replace(lines[hdr + 5].split(",")[1], "abc", 1)
    mut("non_numeric_cell", lines, hdr + 6, "forward_te", "not a number")
    lines = list(base)
    lines[hdr + 7] = ",".join([lines[hdr + 7].split(",")[0], "", *lines[hdr + 7].split(",")[2:]])
    mut("empty_cell", lines, hdr + 8, "forward_te", "empty cell")
    lines = list(base)
    lines[hdr + 3] = lines[hdr + 3] + ",7"
    mut("ragged_row", lines, hdr + 4, None, "5 cells")
    lines = list(base)
    a, b = lines[hdr + 20], lines[hdr + 21]
    lines[hdr + 20], lines[hdr + 21] = b, a
    mut("non_monotone_positions", lines, hdr + 22, "forward_position", "monotone")
    mut("too_few_points", _te_text(n=8), hdr + 8, "forward_position", "at least")
    lines = list(base)
    lines.insert(hdr + 30, base[hdr - 1])
    mut("duplicate_header", lines, hdr + 31, None, "repeats the column header")
    lines = list(base)
    lines[hdr - 1] = lines[hdr - 1].replace("backward_te [arcsec]", "forward_te [arcsec]")
    mut("duplicate_column", lines, hdr, "4", "appears twice")
    lines = list(base)
    lines[hdr - 1] = lines[hdr - 1].replace("backward_te", "backwrd_te")
    mut("unknown_column", lines, hdr, "backwrd_te", "did you mean 'backward_te'")
    lines = ["# sped_rpm: 10", *base[2:]]
    mut("unknown_metadata", lines, 1, None, "did you mean 'speed_rpm'")
    lines = ["# speed_rpm: fast", *base[1:]]
    mut("bad_metadata_value", lines, 1, None, "finite number")
    lines = ["# speed_rpm: 10", "# speed_rpm: 12", *base[2:]]
    mut("repeated_metadata", lines, 2, None, "repeated")
    lines = ["# speed_rpm: -3", *base[1:]]
    mut("negative_speed", lines, 1, None, "> 0")
    lines = list(base)
    lines[hdr - 1] = lines[hdr - 1].replace("forward_position [deg]", "forward_position [rad]")
    mut("positions_wrong_unit", lines, None, "forward_position", "one output revolution")
    lines = list(base)
    lines[hdr - 1] = lines[hdr - 1].replace("forward_te [arcsec]", "forward_te [deg]")
    mut("te_wrong_unit", lines, None, "forward_te", "wrong unit")
    lines = list(base)
    lines[hdr - 1] = lines[hdr - 1].replace("forward_position [deg]", "forward_position [arcmin]")
    mut("positions_partial_revolution", lines, None, "forward_position", "one output revolution")
    lines = [*base[:hdr], *[r.replace(",", ",", 1) for r in base[hdr:]]]
    lines[hdr + 2] = "1.0,2.0,3.0,4.0"
    mut("jump_in_positions", lines, None, "forward_position", "monotone")
    mut("numbers_instead_of_header", [*base[: hdr - 1], *base[hdr:]], hdr, "1", "name the columns")
    return m


@pytest.mark.parametrize(("lines", "line", "col", "why"), _te_mutants())
def test_malformed_te_file_gives_one_clear_error(tmp_path, lines, line, col, why):
    p = _write(tmp_path, lines)
    with pytest.raises(BenchFileError) as ei:
        read_te_trace(p)
    err = ei.value
    msg = str(err)
    assert str(p) in msg and why in msg, msg
    if line is not None:
        assert err.line == line, msg
    if col is not None:
        assert err.column is not None and col in err.column, msg
    assert "\n" not in msg


def test_malformed_hysteresis_files(tmp_path):
    base = _hyst_text()
    cases = {
        "one sign": (
            ["torque [N·m],angle [arcmin]", *[f"{k},{k}" for k in range(1, 40)]],
            "never changes sign",
        ),
        "torque unit": ([base[0].replace("N·m", "deg"), *base[1:]], "not a torque unit"),
        "angle column": ([base[0].replace("angle", "angel"), *base[1:]], "did you mean 'angle'"),
        "branch mark": ([base[0] + ",branch", *[r + ",up" for r in base[1:]]], "branch mark"),
        "angle unit": ([base[0].replace("arcmin", "deg"), *base[1:]], "wrong unit"),
        "missing angle": (["torque [N·m]", *[r.split(",")[0] for r in base[1:]]], "'angle'"),
    }
    for label, (lines, why) in cases.items():
        p = _write(tmp_path, lines, name=f"{label.replace(' ', '_')}.csv")
        with pytest.raises(BenchFileError, match=why) as ei:
            read_hysteresis(p)
        assert str(p) in str(ei.value)


def test_unreadable_and_binary_files_and_folders(tmp_path):
    p = tmp_path / "bin.csv"
    p.write_bytes(b"\xff\xfe\x00\x01garbage")
    with pytest.raises(BenchFileError, match="UTF-8"):
        read_te_trace(p)
    with pytest.raises(BenchFileError, match="cannot read"):
        read_te_trace(tmp_path / "missing.csv")
    with pytest.raises(BenchFileError, match="folder"):
        read_te_trace(tmp_path)
    with pytest.raises(BenchFileError, match="cannot read: embedded null byte"):
        read_te_trace(str(tmp_path / "a\x00b.csv"))
    (tmp_path / "empty").mkdir()
    with pytest.raises(BenchFileError, match="no file matching"):
        read_te_folder(tmp_path / "empty")


_cell = st.one_of(
    st.floats(allow_nan=True, allow_infinity=True).map(repr),
    st.integers(-(10**6), 10**6).map(str),
    st.text(alphabet=st.characters(blacklist_categories=("Cs",)), max_size=6),
    st.sampled_from(["", "nan", "1e999", "-", "#", "[deg]", "loading", "forward_te [arcsec]"]),
)
_header = st.lists(
    st.sampled_from(
        ["forward_position [deg]", "forward_te [arcsec]", "backward_position [deg]",
         "backward_te [arcsec]", "position", "te [rad]", "torque [N·m]", "angle [arcmin]",
         "branch", "x", "forward_te [°]"]
    ),
    min_size=0, max_size=5,
)  # fmt: skip


@settings(
    max_examples=150, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture]
)
@given(
    header=_header,
    rows=st.lists(st.lists(_cell, min_size=0, max_size=5), max_size=25),
    meta=st.lists(
        st.sampled_from(["# speed_rpm: 5", "# te_unit: arcsec", "# bogus: 1", "#"]), max_size=3
    ),
    sep=st.sampled_from([",", ";", "\t"]),
)
def test_random_files_never_let_a_traceback_escape(tmp_path, header, rows, meta, sep):
    lines = [*meta, sep.join(header), *[sep.join(r) for r in rows]]
    p = tmp_path / "random.csv"
    p.write_text("\n".join(lines), encoding="utf-8")
    for reader in (read_te_trace, read_hysteresis):
        try:
            out = reader(p)
        except BenchFileError as exc:
            assert str(p) in str(exc)
        else:  # nothing half-imported: a complete, finite object
            assert isinstance(out, TETrace | HysteresisCurve)
            arrays = (
                [a for d in out.directions().values() for a in d]
                if isinstance(out, TETrace)
                else [out.torque, out.angle]
            )
            assert arrays and all(np.all(np.isfinite(a)) for a in arrays)


@settings(
    max_examples=40, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture]
)
@given(
    n=st.integers(16, 300),
    amp=st.floats(0.01, 100.0),
    offset=st.floats(-100.0, 100.0),
)
def test_valid_random_traces_round_trip(tmp_path, n, amp, offset):
    pos = np.linspace(0.0, 2 * np.pi, n, endpoint=False)
    te = arcsec_to_rad(offset + amp * np.sin(3 * pos))
    tr = TETrace("mem", pos, te, pos[::-1].copy(), te[::-1].copy(), speed_rpm=10.0)
    write_te_trace(tmp_path / "rt.csv", tr)
    back = read_te_trace(tmp_path / "rt.csv")
    np.testing.assert_allclose(back.forward_te, te, rtol=1e-13, atol=1e-20)
    hc = HysteresisCurve("mem", np.array([1.0, -1.0] * 8) * 1e3, np.arange(16) * 1e-5)
    write_hysteresis(tmp_path / "h.csv", hc)
    np.testing.assert_allclose(read_hysteresis(tmp_path / "h.csv").angle, hc.angle, rtol=1e-13)
