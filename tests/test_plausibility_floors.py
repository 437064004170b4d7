"""Plausibility floors of physical sizes (gearte.io.plausibility.FLOORS, gearte.io.schema.floored).

Found by the systematic sweep of extreme values (``python tests/fuzzing.py --count -1``,
docs/errors.md): a stiffness, roller length, face width, Young's modulus, bearing reference load
or load torque of 1e-300 (or × 1e-9) passed the schema's ``> 0`` and ended in ``gearte run`` as
"analysis failed: ... did not converge", "rk4: non-finite output statistics" — naming no key — or
as an internal error (a ``ZeroDivisionError`` in the tooth-contact pre-flight, a numpy warning
turned into exit 3). Each such key now refuses a value below its floor at validation, naming the
key, the value, the floor with its unit and the reason, and each bundled case still runs with the
key set to the floor itself.
"""

from __future__ import annotations

import json

import pytest

from fuzzing import _parent, check_text, corpus, extreme_mutants, run_cli, to_toml
from gearte.errors import CaseFileError, ParameterError
from gearte.io.plausibility import FLOORS

CORPUS = corpus()

#: (bundled case, key path, floor quantity): one or more keys of every quantity, among them every
#: key the sweep found failing in ``run``.
KEYS = [
    ("li2023_rv", "reducer.cranks.cam_bearing.stiffness_N_per_mm", "linear_stiffness"),
    ("li2023_rv", "reducer.cranks.carrier_bearing.stiffness_N_per_mm", "linear_stiffness"),
    ("li2023_rv", "reducer.first_stage.mesh_stiffness_N_per_mm", "linear_stiffness"),
    ("li2023_rv", "reducer.dynamics.crank_bending_stiffness_N_per_mm", "linear_stiffness"),
    ("li2023_rv", "reducer.dynamics.input_torsional_stiffness_Nm_per_rad", "torsional_stiffness"),
    ("li2023_rv", "reducer.dynamics.crank_torsional_stiffness_Nm_per_rad", "torsional_stiffness"),
    ("han2023_rv110e_no_errors", "reducer.cranks.cam_bearing.roller_length_mm", "part_length"),
    ("han2023_rv110e_no_errors", "reducer.cranks.eccentricity_mm", "eccentricity"),
    ("hu2020_rv80e_initial", "stage.eccentricity_mm", "eccentricity"),
    (
        "han2023_rv110e_yield",  # the no_errors case linearises at rated torque
        "reducer.cranks.cam_bearing.reference_load_N",
        "bearing_reference_load",
    ),
    ("han2023_rv110e_yield", "reducer.first_stage.face_width_mm", "part_length"),
    ("han2023_rv110e_yield", "reducer.discs.youngs_modulus_MPa", "youngs_modulus"),
    ("hu2020_rv80e_initial", "analyses.tooth_contact.torque_Nm", "load_torque"),
    ("hu2020_rv80e_initial", "analyses.tooth_contact.disc_share", "disc_share"),
    ("hu2020_rv80e_initial_reducer", "analyses.load_sharing.torque_Nm", "load_torque"),
    ("synthetic_rv110e_lot", "analyses.selective_assembly.torque_Nm", "load_torque"),
]


#: Keys whose floor lies outside the validity of a law the bundled case selects: the floor runs
#: with a law valid there (Palmgren's is steel on steel only: docs/contact-law.md).
LAW_FOR_FLOOR = {"reducer.discs.youngs_modulus_MPa": ("reducer.contact_law", "line_contact")}


def _with(name: str, key: str, value: float) -> str:
    return _with_data(json.loads(json.dumps(CORPUS[name])), key, value)


def _with_data(data: dict, key: str, value: object, *more: object) -> str:
    """``data`` with ``key`` set to ``value`` (and further ``key, value`` pairs), as TOML."""
    _set(data, key, value)
    for k, v in zip(more[::2], more[1::2], strict=True):
        _set(data, str(k), v)
    return to_toml(data)


def _set(data: dict, key: str, value: object) -> None:
    path = tuple(key.split("."))
    node = data
    for i, part in enumerate(path[:-1]):  # a dotted key of a tolerance table stays one key
        if part not in node:
            rest = ".".join(path[i:-1])
            node = node[rest]
            break
        node = node[part]
    assert path[-1] in node, f"the case has no {key}"
    node[path[-1]] = value


def _errors(text: str, tmp_path) -> list[tuple[str, str]]:
    from gearte.io.case_file import load_case

    (tmp_path / "c.toml").write_text(text, encoding="utf-8")
    with pytest.raises(CaseFileError) as info:
        load_case(tmp_path / "c.toml")
    return info.value.errors


@pytest.mark.parametrize(("name", "key", "quantity"), KEYS, ids=[k[1] for k in KEYS])
def test_a_value_below_the_floor_is_refused_naming_key_value_floor_and_reason(
    tmp_path, name, key, quantity
):
    floor, unit, why = FLOORS[quantity]
    for bad in (1e-300, floor * 0.5):
        check_text(to_toml(CORPUS[name]), tmp_path)  # links the bundled data files
        errors = _errors(_with(name, key, bad), tmp_path)
        assert [f for f, _ in errors] == [key], errors
        msg = errors[0][1]
        assert msg.startswith(f"must be >= {floor:g}"), msg
        if unit != "-":
            assert unit in msg, msg
        assert why in msg and f"(got {bad!r})" in msg, msg


@pytest.mark.parametrize(("name", "key", "quantity"), KEYS, ids=[k[1] for k in KEYS])
def test_the_floor_itself_validates(tmp_path, name, key, quantity):
    out = check_text(_with(name, key, FLOORS[quantity][0]), tmp_path)
    # a floored size may still make the drive's torque implausible (the pressure check names
    # the torque): that is a refusal naming a key, not a solver failure
    assert out.status in ("accepted", "rejected"), out
    if out.status == "rejected":
        if key in LAW_FOR_FLOOR:  # the law's range, not the floor, refuses it (the section's
            assert out.detail == "reducer", out  # check; its message: the test above)
        else:
            assert "torque" in out.detail, out


def test_the_tooth_contact_runs_at_the_torque_and_share_floors(tmp_path):
    """Before: 1e-300 N·m or a share of 1e-300 raised ZeroDivisionError in the pre-flight."""
    text = _with("hu2020_rv80e_initial", "analyses.tooth_contact.torque_Nm", 1e-3)
    assert run_cli(text, tmp_path, 600.0).status == "run_exit_0"


def test_a_young_modulus_outside_palmgrens_steel_is_refused_at_validation(tmp_path):
    """With contact_law 'palmgren' (Palmgren's fit for steel on steel) a Young's modulus outside
    steel's is refused when the case is validated, naming the key and the law to select; it
    was refused only when the run reached the contact law."""
    text = _with("han2023_rv110e_yield", "reducer.discs.youngs_modulus_MPa", 7.0e4)
    errors = _errors(text, tmp_path)
    assert len(errors) == 1, errors
    assert "discs.youngs_modulus_MPa = 70000" in errors[0][1], errors
    assert "'palmgren'" in errors[0][1] and "'line_contact'" in errors[0][1], errors


@pytest.mark.slow
@pytest.mark.parametrize(("name", "key", "quantity"), KEYS, ids=[k[1] for k in KEYS])
def test_every_key_at_its_floor_runs(tmp_path, name, key, quantity):
    text = _with(name, key, FLOORS[quantity][0])
    if key in LAW_FOR_FLOOR:
        law_key, law = LAW_FOR_FLOOR[key]
        assert check_text(text, tmp_path).status == "rejected"  # the law's range, named
        data = json.loads(json.dumps(CORPUS[name]))
        text = _with_data(data, key, FLOORS[quantity][0], law_key, law)
    if check_text(text, tmp_path).status != "accepted":
        pytest.skip("refused at validation (the torque check), see the test above")
    out = run_cli(text, tmp_path, 600.0)
    assert out.status == "run_exit_0", out


def test_a_floored_field_shows_its_floor_in_the_schema():
    from gearte.studies.rv_reducer import Bearing

    info = Bearing.model_fields["stiffness_N_per_mm"]
    assert any(getattr(m, "ge", None) == FLOORS["linear_stiffness"][0] for m in info.metadata)
    assert "plausibility_floor" in (info.json_schema_extra or {})


def test_dte_shorter_than_eight_recording_intervals_is_refused_at_validation(tmp_path):
    """Before: exit 2 in ``run`` naming 'dte = 1' (the sample count) instead of the key."""
    from gearte.io.case_file import load_case
    from gearte.studies import preflight

    text = _with("li2023_rv", "analyses.dte.duration_s", 1e-9)
    (tmp_path / "c.toml").write_text(text, encoding="utf-8")
    check_text(to_toml(CORPUS["li2023_rv"]), tmp_path)
    case = load_case(tmp_path / "c.toml")
    with pytest.raises(ParameterError) as info:
        preflight(case)
    assert info.value.field == "analyses.dte.duration_s"
    assert "8 recording intervals" in str(info.value)


#: Keys the sweep must reach, written out by hand (not found with the sweep's own filter): one
#: or more per study kind and section, among them a list's first element and keys nested in
#: arrays of tables.
SWEPT = [
    ("han2023_rv110e", "reducer.rated_torque_Nm"),
    ("han2023_rv110e", "operation.input_speed_rpm"),
    ("han2023_rv110e_yield", "reducer.supports.carrier_radial_stiffness_N_per_mm"),
    ("hu2020_rv80e_initial", "errors.pin_groove_clearance.tolerance_um"),
    ("hu2020_rv80e_initial_reducer", "reducer.discs.face_width_mm"),
    ("li2023_rv", "reducer.cranks.cam_bearing.stiffness_N_per_mm"),
    ("li2023_rv_errors", "reducer.errors.2.angle_deg"),
    ("jiang2024_spur_pair", "pair.pressure_angle_deg"),
    ("jiang2024_shoulder_swing_gearte", "chain.stages.1.pair.bearing_clearance_min_um"),
    ("wang2013_2kh_eq9", "errors.magnitudes_um.E_s"),
    ("synthetic_rv110e_lot", "analyses.selective_assembly.planet_indexings"),
]


@pytest.mark.parametrize("name,key", SWEPT, ids=[f"{n}:{k}" for n, k in SWEPT])
def test_the_extreme_sweep_sets_each_extreme_at_a_named_key(name, key):
    """The sweep has the three mutants of ``key`` in ``name``, each a TOML text that carries
    exactly that value at that key (1e-300, the case's value × 1e-9 and × 1e9) and leaves the
    rest of the case as it is."""
    import tomllib

    path = [int(p) if p.isdigit() else p for p in key.split(".")]
    given = float(_parent(CORPUS[name], path)[path[-1]])
    assert given > 0
    got = {d: t for base, d, t in SWEEP if base == name and d.split(" ")[1] == key}
    assert set(got) == {f"extreme {key} {label}" for label in ("= 1e-300", "x 1e-9", "x 1e9")}
    for label, want in (("= 1e-300", 1e-300), ("x 1e-9", given * 1e-9), ("x 1e9", given * 1e9)):
        data = tomllib.loads(got[f"extreme {key} {label}"])
        assert _parent(data, path)[path[-1]] == pytest.approx(want, rel=1e-15)
        _parent(data, path)[path[-1]] = _parent(CORPUS[name], path)[path[-1]]
        assert data == tomllib.loads(to_toml(CORPUS[name]))


def test_the_extreme_sweep_skips_the_case_name_and_the_non_first_list_elements():
    """What the sweep leaves out on purpose: the ``[case]`` table (names, seeds) and every
    number of a list of numbers after the first (its elements share one schema); the tables of
    an array of tables are each swept (``reducer.errors.2.angle_deg`` above)."""
    keys = {d.split(" ")[1] for _, d, _ in SWEEP}
    assert not any(k.startswith("case.") for k in keys)
    assert not any(p.isdigit() and p != "0" for k in keys for p in k.split(".")[-1:])
    assert len(SWEEP) > 2000


SWEEP = extreme_mutants()


def test_serial_torque_in_n_mm_is_refused_naming_the_key(tmp_path):
    """Fuzzing seed 16: ``rv_serial`` had no torque plausibility check; 1e6 'N·m' on an RV-110E
    ended in ``run`` as "no equilibrium at position 1" (exit 1). Its analyses' torques are now
    checked against the design's size in the pre-flight (validate and run), naming the key."""
    text = _with("synthetic_rv110e_serial", "analyses.load_sharing.torque_Nm", 1e6)
    out = check_text(text, tmp_path)
    assert (out.status, out.detail) == ("rejected", "analyses.load_sharing.torque_Nm"), out
    got = run_cli(text, tmp_path, 600.0)
    assert got.status == "run_exit_2", got
    assert "analyses.load_sharing.torque_Nm = 1000000.0: is implausible" in got.detail, got
    assert "26,870 MPa" in got.detail, got  # the pressure the torque would give


def test_validating_a_case_without_a_torque_check_imports_no_numba():
    """The pin-pressure estimate (``gearte.models.contact_law``, which imports numba) is
    imported by ``gearte.io.plausibility`` on first use: loading and validating a case of a kind
    with no torque check and no kernel (a gear chain) imports no numba (~0.3 s of a ~1.4 s warm
    run), and the re-exported name still resolves."""
    import subprocess
    import sys

    code = (
        "import sys\n"
        "from gearte.cases import case_path\n"
        "from gearte.io.case_file import load_case\n"
        "load_case(case_path('jiang2024_shoulder_swing'))\n"
        "print('numba' in sys.modules)\n"
        "from gearte.io import plausibility\n"
        "from gearte.models import contact_law\n"
        "print(plausibility.pin_pressure_estimate is contact_law.pin_pressure_estimate)\n"
    )
    out = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, check=True, timeout=120
    ).stdout.split()
    assert out == ["False", "True"], out
