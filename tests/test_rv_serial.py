"""A serial's model from its measurement files (issue 16, ``rv_serial``): round trip through the
metrology files, and the report's list of measured inputs."""

from __future__ import annotations

import re

import numpy as np
import pytest

from gearte.cases import case_path
from gearte.geometry.measured import measurements_of
from gearte.io import metrology as mt
from gearte.io.case_file import load_case
from gearte.studies import run_case
from gearte.studies.rv_reducer import build_reducer

ANALYSES = """
[analyses.load_sharing]
torque_Nm = 1078.0
positions = 24
compare_without_errors = false
[analyses.transmission_error]
torque_Nm = 1078.0
positions = 24
[analyses.catalogue]
steps_per_segment = 4
"""


def _han_cases(tmp_path):
    """The Han 2023 RV-110E with its Table 1-3 errors and pin errors (known design, known
    errors), and the same design without errors. Table 4 (carrier bores) has no measurement
    format here and is left out of both."""
    text = case_path("han2023_rv110e").read_text(encoding="utf-8")
    head = text[: text.index("[reducer.dynamics]")]
    blocks = re.split(r"(?=\[\[reducer\.errors\]\])", head)
    keep = [b for b in blocks[1:] if 'part = "carrier_crank_bore"' not in b]
    pins = "radius_errors_um = [" + ", ".join(f"{3 * np.sin(k):.3f}" for k in range(40)) + "]\n"
    base = blocks[0].replace("circle_radius_mm = 82.0\n", "circle_radius_mm = 82.0\n" + pins)
    known = tmp_path / "known.toml"
    known.write_text(base + "".join(keep) + ANALYSES, encoding="utf-8")
    design = tmp_path / "design.toml"
    nominal = blocks[0]
    design.write_text(nominal + ANALYSES, encoding="utf-8")
    return known, design


def _export(reducer, folder):
    """Measurement files of the known reducer's parts (the metrology a lab would write)."""
    meas = measurements_of(reducer)
    m, n = reducer.cranks.count, reducer.discs.count
    mt.write_disc_bores(
        folder / "bores.csv", {f"D{j + 1}": meas["disc_bores"][j] for j in range(n)}
    )
    mt.write_crank_eccentricity(
        folder / "cranks.csv",
        {
            f"C{i + 1}": mt.CrankCams(meas["cam_eccentricity"][i], meas["cam_phase"][i])
            for i in range(m)
        },
    )
    mt.write_runout(
        folder / "planets.csv",
        {f"P{i + 1}": mt.Runout(*meas["planet_runout"][i]) for i in range(m)},
    )
    mt.write_pins(
        folder / "pins.csv",
        {"H1": mt.PinSet(meas["pin_diameters"], meas["slot_radial"], meas["slot_tangential"])},
    )
    (folder / "serial.toml").write_text(
        """[case]
kind = "rv_serial"
title = "round trip"
[reducer]
case = "design.toml"
[serial]
name = "RV-1"
discs = ["D1", "D2"]
cranks = ["C1", "C2", "C3"]
planets = ["P1", "P2", "P3"]
pins = "H1"
[serial.files]
disc_bores = "bores.csv"
crank_eccentricity = "cranks.csv"
planet_runout = "planets.csv"
pins = "pins.csv"
"""
        + ANALYSES,
        encoding="utf-8",
    )
    return folder / "serial.toml"


def test_round_trip_known_errors_through_measurement_files_same_results_1e9(tmp_path):
    """Known design + known errors → measurement files → re-imported serial: every result to
    1e-9 (relative, or 1e-9 of the largest value of an array)."""
    known, design = _han_cases(tmp_path)
    kcase = load_case(known)
    serial = _export(build_reducer(kcase.reducer), tmp_path)
    a = run_case(kcase)
    b = run_case(load_case(serial))
    assert b["measured_inputs"]["measured"]["cam eccentricity and phase"].startswith(str(tmp_path))
    for name in ("load_sharing", "transmission_error", "catalogue"):
        va, vb = a[name].values, b[name].values
        for key, x in va.items():
            if isinstance(x, str | dict):
                continue
            x, y = np.asarray(x, dtype=float), np.asarray(vb[key], dtype=float)
            scale = max(float(np.max(np.abs(x))), 1e-12)
            np.testing.assert_allclose(y, x, rtol=0, atol=1e-9 * scale, err_msg=f"{name}: {key}")


def test_serial_names_a_part_missing_from_its_file(tmp_path):
    known, _ = _han_cases(tmp_path)
    serial = _export(build_reducer(load_case(known).reducer), tmp_path)
    serial.write_text(serial.read_text().replace('"P3"]', '"P9"]'))
    with pytest.raises(Exception, match="P9"):
        run_case(load_case(serial))


def test_validate_refuses_a_malformed_measurement_file_naming_file_line_column(tmp_path):
    """``gearte validate`` reads the measurement files: a NaN in one of them is one line naming
    the file, the line and the column, exit code 2, no traceback."""
    from click.testing import CliRunner

    from gearte.cli import main

    known, _ = _han_cases(tmp_path)
    serial = _export(build_reducer(load_case(known).reducer), tmp_path)
    p = tmp_path / "cranks.csv"
    lines = p.read_text().splitlines()
    cells = lines[3].split(",")
    lines[3] = ",".join([cells[0], cells[1], "nan", cells[3]])
    p.write_text("\n".join(lines) + "\n")
    r = CliRunner().invoke(main, ["validate", str(serial)])
    assert r.exit_code == 2
    assert f"{p}, line 4, column 3 'eccentricity [mm]'" in r.output
    assert "Traceback" not in r.output


def _without_stiffness_chain(red):
    """The serial's reducer as it was before its design case had a stiffness chain (no pin
    seat, crank bending or torsion; crank bearings at 5 and 6 kN, main bearings 2e6 N/mm): the
    state the reproducers below were found in (with the chain the clearances close earlier and
    the former Newton cap no longer fails)."""
    import dataclasses

    from gearte.models.rv_stiffness import roller_bearing_radial_stiffness as k_roller

    return red.replace(
        pins=dataclasses.replace(red.pins, seat_compliance=None, bending_compliance=None),
        cranks=dataclasses.replace(
            red.cranks,
            bending_compliance=None,
            torsional_stiffness=None,
            cam_bearing_stiffness=float(k_roller(14, 12.0, 5000.0)),
            carrier_bearing_stiffness=float(k_roller(16, 10.0, 6000.0)),
        ),
        supports=dataclasses.replace(red.supports, carrier_radial_stiffness=2.0e6),
    )


def test_reproducer_serial_te_at_default_zero_load_fraction_with_measured_clearances():
    """The bundled serial (measured bearing clearances) raised ConvergenceError in
    ``transmission_error`` at the default zero_load_fraction 1e-3 (its case file used 0.01).
    Cause: the mesh-period refinement windows were solved as one sweep, each window
    warm-started from the end of the previous one, far away; at 0.1 % of the torque the parts
    float in their bearing clearances (residual stiffness 1e-6 k) and Newton needs > 100 steps
    from such a start (a cold start fails too). Each window now starts from the coarse solution
    nearest it. The equilibrium is unique, so the result is the old sweep's with a 10× longer
    Newton budget, to round-off."""
    from gearte.models import rv_load_sharing as ls
    from gearte.solvers.rv_batch import solve_positions
    from gearte.studies.rv_serial import build_serial

    case = load_case(case_path("synthetic_rv110e_serial"))
    assert case.analyses.transmission_error.zero_load_fraction == 1e-3  # the default again
    _, red, _ = build_serial(case)
    red = _without_stiffness_chain(red)
    torque = 1078e3
    # the law of the reproducer (the serial's case then selected Johnson's line contact)
    law = ls.contact_law(red, "line_contact")
    te = ls.transmission_error(red, torque, zero_load_fraction=1e-3, law=law)
    # the former path: every window in one sweep, with maxit 1000 instead of 100
    centres = {int(np.argmax(x)) for x in (te.total, te.geometric, te.elastic)}
    centres |= {int(np.argmin(x)) for x in (te.total, te.geometric, te.elastic)}
    offs = (np.arange(24) / 24 - 0.5) * ls.mesh_period(red)
    fsys = ls.assemble(red, np.concatenate([te.theta[c] + offs for c in sorted(centres)]))
    slaw = ls.solver_law(red, fsys, law)
    with pytest.raises(Exception, match="no equilibrium"):
        # the reproducer, at the former cap of 100 (the default is now NEWTON_MAXIT)
        solve_positions(fsys, 1e-3 * torque, slaw, maxit=100, method="per_position")
    old = solve_positions(fsys, 1e-3 * torque, slaw, maxit=1000, method="per_position")
    geo = ls._postprocess(red, fsys, old, 1e-3 * torque, slaw.name).output_error
    every = np.concatenate([te.geometric, geo])
    assert te.geometric_pp == pytest.approx(every.max() - every.min(), rel=1e-9, abs=1e-15)


def test_serial_without_its_bore_file_solves_a_cold_first_position_at_small_torque(tmp_path):
    """Found by ``make fuzz`` (2026-11-26): the bundled serial with its ``disc_bores`` file left
    out (bores at nominal) floats in its measured bearing clearances at the geometric TE's
    0.1 % of torque (1078 N·mm); from the sweep's cold first position the line-searched Newton
    needs ~150 iterations, and the cap of 100 ended the run with "no equilibrium at position 0".
    With ``NEWTON_MAXIT`` the whole case runs; the batched and per-position solvers agree to
    1e-9; the former cap still fails (so a cap put back would fail this test)."""
    from gearte.errors import ConvergenceError
    from gearte.models import rv_load_sharing as ls
    from gearte.solvers.rv_batch import solve_positions
    from gearte.solvers.rv_equilibrium import NEWTON_MAXIT
    from gearte.studies.rv_serial import build_serial

    src = case_path("synthetic_rv110e_serial")
    text = src.read_text(encoding="utf-8")
    text = re.sub(r"(?m)^disc_bores = .*\n", "", text)
    text = text.replace('"lots/', f'"{src.parent.as_posix()}/lots/')
    path = tmp_path / "serial_without_bores.toml"
    path.write_text(text, encoding="utf-8")
    case = load_case(path)
    _, red, measured = build_serial(case)
    red = _without_stiffness_chain(red)
    assert not any("crank-bore" in k for k in measured)
    system = ls.assemble(red, np.zeros(1))
    # the law of the fuzz find (the serial's case then selected Johnson's line contact)
    slaw = ls.solver_law(red, system, ls.contact_law(red, "line_contact"))
    with pytest.raises(ConvergenceError, match="no equilibrium at position 0"):
        solve_positions(system, 1078.0, slaw, maxit=100)
    assert NEWTON_MAXIT >= 200
    batched = solve_positions(system, 1078.0, slaw)
    flat = solve_positions(system, 1078.0, slaw, method="per_position")
    assert batched.iterations[0] > 100
    np.testing.assert_allclose(batched.q, flat.q, rtol=1e-9, atol=1e-12)
    result = run_case(case)
    values = result["transmission_error"].values
    assert np.isfinite(values["geometric_te_peak_to_peak [arcsec]"])
