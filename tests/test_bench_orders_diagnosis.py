"""TE orders from every tooth number (z_c = z_p − 1 included), tracked across a series; the
unexplained-line warning in arcsec relative to the trace; a diagnosis that claims nothing the
data cannot decide."""

from __future__ import annotations

import numpy as np
import pytest

from gearte.io.bench import write_te_trace
from gearte.io.case_file import load_case_dict
from gearte.models.bench_data import TETrace
from gearte.models.orders import label_order, rv_tooth_orders, unexplained_lines
from gearte.studies import RunOptions, run_case
from gearte.units import arcsec_to_rad


def test_orders_of_40_pins_39_lobes_are_labelled():
    """The lines that grow with load on a 40-pin / 39-lobe RV (orders 39, 78, 156, 159, 318)."""
    src = rv_tooth_orders(22, 60, 40)
    got = {n: label_order(n, src) for n in (39, 78, 156, 159, 318, 40, 1560, 2400)}
    assert got[39] == "cycloid lobes" and got[78] == "2× cycloid lobes"
    assert got[156] == "4× cycloid lobes"
    assert got[159] == "4× crank rotation − output rotation (sideband)"
    assert got[318] == "8× crank rotation − 2× output rotation (sideband)"
    assert got[40] == "crank rotation" and got[1560] == "cycloid mesh"
    assert got[2400] == "involute mesh"
    assert label_order(17, src) == "unidentified"


def test_unexplained_lines_threshold_is_relative_to_the_trace():
    lines = [{"order": 17, "amplitude": 1.0, "source": "unidentified"},
             {"order": 40, "amplitude": 9.0, "source": "crank rotation"}]  # fmt: skip
    assert unexplained_lines(lines, peak_to_peak=10.0, noise=0.01) == [lines[0]]
    assert unexplained_lines(lines, peak_to_peak=30.0, noise=0.01) == []  # 1 < 5 % of 30
    assert unexplained_lines(lines, peak_to_peak=10.0, noise=0.3) == []  # 1 < 4 × noise


def _trace(path, extra_order=None, extra_arcsec=0.0, torque=0.0):
    rng = np.random.default_rng(5)
    n = 3600
    pos = 2 * np.pi * np.arange(n) / n
    te = {}
    for d in (1, -1):
        y = (arcsec_to_rad(3.0) + d * arcsec_to_rad(40.0) + arcsec_to_rad(6.0) * np.cos(40 * pos)
             + rng.normal(0, arcsec_to_rad(0.3), n))  # fmt: skip
        if extra_order:
            y = y + arcsec_to_rad(extra_arcsec) * np.cos(extra_order * pos + 0.3)
        te[d] = y
    tr = TETrace(str(path), pos, te[1], pos[::-1].copy(), te[-1][::-1].copy(), speed_rpm=10.0,
                 torque=torque, oil_temperature=40.0)  # fmt: skip
    write_te_trace(path, tr)
    return tr


def _case(te, hysteresis=None, **analyses):
    data = {"te": str(te)}
    if hysteresis is not None:
        data["hysteresis"] = str(hysteresis)
    return load_case_dict({
        "case": {"kind": "rv_bench", "title": "test"},
        "reducer": {"case": "hu2020_rv80e_initial_reducer"},
        "data": data, "analyses": analyses,
    })  # fmt: skip


def test_unexplained_line_warning_fires_in_arcsec(tmp_path):
    _trace(tmp_path / "te.csv", extra_order=17, extra_arcsec=1.5)
    res = run_case(_case(tmp_path / "te.csv", te_orders={}), RunOptions(progress=False))
    warn = [w for w in res.warnings if "order 17" in w]
    assert len(warn) == 1 and "″" in warn[0] and "rad" not in warn[0], res.warnings
    rows = res.to_dict()["analyses"]["te_orders"]["values"]["unexplained_lines"]
    assert rows[0]["order"] == 17
    assert rows[0]["largest_amplitude [arcsec]"] == pytest.approx(1.5, abs=0.05)
    # a line below 5 % of the trace's peak-to-peak stays quiet
    _trace(tmp_path / "te2.csv", extra_order=17, extra_arcsec=0.2)
    res2 = run_case(_case(tmp_path / "te2.csv", te_orders={}), RunOptions(progress=False))
    assert not [w for w in res2.warnings if "order 17" in w]


def test_without_a_hysteresis_file_no_lost_motion_culprit_is_named(tmp_path):
    _trace(tmp_path / "te.csv")
    res = run_case(_case(tmp_path / "te.csv", calibration={"families": ["crank rotation"]},
                         diagnosis={}), RunOptions(progress=False)).to_dict()  # fmt: skip
    dg = res["analyses"]["diagnosis"]["values"]
    assert dg["lost_motion_culprits"] == []
    text = " ".join(dg["statements"])
    assert "lost motion: no culprit named" in text and "hysteresis file" in text
    assert "lost motion: most likely" not in text
    assert dg["te_culprits"][0]["source"] == "crank rotation"  # the TE data decide that one


def test_with_a_hysteresis_file_the_lost_motion_culprit_is_named():
    res = run_case("synthetic_rv_bench", RunOptions(progress=False)).to_dict()
    dg = res["analyses"]["diagnosis"]["values"]
    assert dg["lost_motion_culprits"][0]["source"] == "bearing clearances"


def test_orders_are_tracked_across_the_series():
    res = run_case("synthetic_rv_bench", RunOptions(progress=False)).to_dict()
    trend = res["analyses"]["te_orders"]["values"]["order_trend"]
    keys = set(trend[0]["amplitude [arcsec]"])
    assert {"39: cycloid lobes", "40: crank rotation", "78: 2× cycloid lobes"} <= keys
    # the bundled truth: the lobe order grows with load (0.3 + 2.5 T/T_r arcsec)
    lobes = {r["torque [N·m]"]: r["amplitude [arcsec]"]["39: cycloid lobes"] for r in trend}
    assert lobes[784.0] == pytest.approx(2.8, abs=0.05) and lobes[0.0] == pytest.approx(
        0.3, abs=0.05
    )
