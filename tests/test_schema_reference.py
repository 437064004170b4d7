"""The generated case-file reference (issue 15 item 2) covers 100 % of the schema fields of every
study kind: each key of each section appears, with its type, unit, allowed values, default and
meaning; keys without a meaning are listed in PENDING, which only shrinks."""

from __future__ import annotations

import re

import pytest

from gearte.io.kinds import available_kinds, get_kind
from gearte.io.schema_reference import (
    kind_markdown,
    kind_sections,
    reference_markdown,
    unit_of,
    walk_fields,
)

BUILTIN = [k for k in available_kinds() if k != "foundation_test"]


def _parse(md: str) -> dict[str, list[list[str]]]:
    """Section heading → rows (cells) of its table; ``Same keys as`` sections get the rows of
    the section they name."""
    sections: dict[str, list[list[str]]] = {}
    current = None
    for line in md.splitlines():
        m = re.match(r"^### `(.+)`$", line)
        if m:
            current = m.group(1)
            sections[current] = []
            continue
        same = re.match(r"^Same keys as `(.+)`\.$", line)
        if same and current:
            sections[current] = sections[same.group(1)]
        elif current and line.startswith("| `"):
            cells = [c.strip() for c in re.split(r"(?<!\\)\|", line)[1:-1]]
            sections[current].append(cells)
    return sections


def _heading(path: str, md_sections: dict[str, list[list[str]]]) -> str:
    for h in (f"[{path}]", f"[[{path}]]") if path else ("top level",):
        if h in md_sections:
            return h
    raise AssertionError(f"no section [{path}] in the reference")


@pytest.mark.parametrize("kind", BUILTIN)
def test_reference_covers_every_schema_field(kind: str) -> None:
    md = _parse(kind_markdown(kind))
    expected = list(walk_fields(get_kind(kind).Case))
    assert expected
    for path, key, _ in expected:
        if not path:
            continue  # the root's keys are the sections themselves
        rows = md[_heading(path, md)]
        assert f"`{key}`" in [r[0] for r in rows], f"{kind}: [{path}] {key} missing"
    # and nothing that is not a field
    n_rows = sum(len(r) for r in md.values())
    n_fields = sum(1 for p, _, _ in expected if p)
    assert n_rows == n_fields


@pytest.mark.parametrize("kind", BUILTIN)
def test_every_key_has_type_default_and_the_unit_of_its_name(kind: str) -> None:
    for sec in kind_sections(kind):
        for k in sec.keys:
            assert k.type and k.default, (sec.path, k.key)
            if re.search(r"_(mm|um|deg|Nm|N|MPa|rpm|s|kg|arcmin)$", k.key):
                assert k.unit, (sec.path, k.key)


def test_ranges_and_defaults_read_from_the_field_constraints() -> None:
    rows = {r[0]: r for r in _parse(kind_markdown("cycloid_stage"))["[stage]"]}
    assert rows["`pins`"][1:5] == ["integer", "", "≥ 4, ≤ 400", "required"]
    assert rows["`equidistant_modification_mm`"][2:5] == ["mm", "≥ -1, ≤ 1", "`0.0`"]
    case = {r[0]: r for r in _parse(kind_markdown("cycloid_stage"))["[case]"]}
    assert case["`references`"][4] == "empty"


@pytest.mark.parametrize(
    ("name", "unit"),
    [
        ("eccentricity_mm", "mm"),
        ("tolerance_um", "µm"),
        ("output_torque_Nm", "N·m"),
        ("crank_bending_stiffness_N_per_mm", "N/mm"),
        ("input_torsional_stiffness_Nm_per_rad", "N·m/rad"),
        ("rig_compliance_arcsec_per_kNm", "arcsec/kN·m"),
        ("density_kg_per_m3", "kg/m³"),
        ("output_inertia_kgm2", "kg·m²"),
        ("count", ""),
        ("seed", ""),
    ],
)
def test_unit_of_a_key_from_its_suffix(name: str, unit: str) -> None:
    assert unit_of(name) == unit


def test_unit_from_the_description_when_the_name_has_none() -> None:
    assert unit_of("ratio", "Reduction ratio [-]") == ""
    assert unit_of("stiffness", "mesh stiffness [N/mm]") == "N/mm"


def test_reference_links_every_kind() -> None:
    md = reference_markdown(BUILTIN)
    for kind in BUILTIN:
        assert f"[`{kind}`](#{kind})" in md and f"## `{kind}`" in md


def _missing_meaning(kinds: list[str]) -> set[str]:
    out = set()
    for kind in kinds:
        for sec in kind_sections(kind):
            for k in sec.keys:
                if not k.meaning:
                    out.add(f"{sec.model.__module__.split('.')[-1]}.{sec.model.__name__}.{k.field}")
    return out


def test_the_meaning_check_finds_an_undocumented_key() -> None:
    """The check can fail: the test kind's ``fail_in_plot`` has no description."""
    assert "foundation_kind.Demo.fail_in_plot" in _missing_meaning(["foundation_test"])


def test_every_key_has_a_meaning_except_the_pending_ones() -> None:
    missing = _missing_meaning(BUILTIN)
    assert not missing - PENDING, f"add a Field description: {sorted(missing - PENDING)}"


def test_meaning_debt_only_shrinks() -> None:
    fixed = PENDING - _missing_meaning(BUILTIN)
    assert not fixed, f"remove from PENDING (documented now): {sorted(fixed)}"


# Keys whose Field has no description yet (module.Model.field); the reference shows their
# type, unit, range and default. Fill the description and remove the entry.
PENDING = frozenset(
    {
        "_rv_dynamics.BatchOptions.duration_s",
        "_rv_dynamics.BatchOptions.samples",
        "_rv_dynamics.BatchOptions.seed",
        "_rv_dynamics.BatchOptions.settle_s",
        "_rv_dynamics.DTEOptions.method",
        "_rv_dynamics.ModalOptions.speed_max_rpm",
        "_rv_dynamics.ModalOptions.speed_min_rpm",
        "_rv_dynamics.SpeedSweepOptions.count",
        "_rv_dynamics.SpeedSweepOptions.settle_s",
        "_rv_dynamics.SpeedSweepOptions.speed_max_rpm",
        "_rv_dynamics.SpeedSweepOptions.speed_min_rpm",
        "rv_reducer.Analyses.batch",
        "rv_reducer.Analyses.catalogue",
        "rv_reducer.Analyses.compensation",
        "rv_reducer.Analyses.contact",
        "rv_reducer.Analyses.dte",
        "rv_reducer.Analyses.load_sharing",
        "rv_reducer.Analyses.modal",
        "rv_reducer.Analyses.transmission_error",
        "rv_reducer.Bounds.equidistant_modification",
        "rv_reducer.Bounds.pin_circle_radius",
        "rv_reducer.Bounds.pin_radius",
        "rv_reducer.Bounds.shift_modification",
        "rv_reducer.CatalogueSection.lost_motion_fraction",
        "rv_reducer.CatalogueSection.position_deg",
        "rv_reducer.CatalogueSection.steps_per_segment",
        "rv_reducer.CompensationSection.bounds_um",
        "rv_reducer.CompensationSection.grid",
        "rv_reducer.CompensationSection.min_backlash_arcmin",
        "rv_reducer.CompensationSection.objective",
        "rv_reducer.CompensationSection.positions",
        "rv_reducer.CompensationSection.torque_Nm",
        "rv_reducer.CranksSection.circle_radius_mm",
        "rv_reducer.CranksSection.count",
        "rv_reducer.CranksSection.eccentricity_mm",
        "rv_reducer.DiscsSection.count",
        "rv_reducer.DiscsSection.equidistant_modification_mm",
        "rv_reducer.DiscsSection.face_width_mm",
        "rv_reducer.DiscsSection.poisson_ratio",
        "rv_reducer.DiscsSection.shift_modification_mm",
        "rv_reducer.DiscsSection.youngs_modulus_MPa",
        "rv_reducer.DynamicsSection.crank_bending_stiffness_N_per_mm",
        "rv_reducer.DynamicsSection.crank_inertia_kgm2",
        "rv_reducer.DynamicsSection.crank_mass_kg",
        "rv_reducer.DynamicsSection.crank_torsional_stiffness_Nm_per_rad",
        "rv_reducer.DynamicsSection.cycloid_harmonics",
        "rv_reducer.DynamicsSection.disc_inertia_kgm2",
        "rv_reducer.DynamicsSection.disc_mass_kg",
        "rv_reducer.DynamicsSection.input_torsional_stiffness_Nm_per_rad",
        "rv_reducer.DynamicsSection.involute_harmonics",
        "rv_reducer.DynamicsSection.output_inertia_kgm2",
        "rv_reducer.DynamicsSection.output_mass_kg",
        "rv_reducer.DynamicsSection.planet_inertia_kgm2",
        "rv_reducer.DynamicsSection.planet_mass_kg",
        "rv_reducer.DynamicsSection.sun_inertia_kgm2",
        "rv_reducer.DynamicsSection.sun_mass_kg",
        "rv_reducer.ErrorSection.angle_deg",
        "rv_reducer.ErrorSection.part",
        "rv_reducer.ErrorSection.value_um",
        "rv_reducer.FirstStageSection.module_mm",
        "rv_reducer.FirstStageSection.planet_teeth",
        "rv_reducer.FirstStageSection.pressure_angle_deg",
        "rv_reducer.FirstStageSection.sun_support_stiffness_N_per_mm",
        "rv_reducer.FirstStageSection.sun_teeth",
        "rv_reducer.LoadSharingSection.compare_without_errors",
        "rv_reducer.LoadSharingSection.positions",
        "rv_reducer.LoadSharingSection.torque_Nm",
        "rv_reducer.OperationSection.input_speed_rpm",
        "rv_reducer.OperationSection.output_torque_Nm",
        "rv_reducer.PinsSection.circle_radius_mm",
        "rv_reducer.PinsSection.count",
        "rv_reducer.PinsSection.pin_radius_mm",
        "rv_reducer.PinsSection.radial_position_errors_um",
        "rv_reducer.PinsSection.tangential_position_errors_um",
        "rv_reducer.ReducerSection.cranks",
        "rv_reducer.ReducerSection.density_kg_per_m3",
        "rv_reducer.ReducerSection.discs",
        "rv_reducer.ReducerSection.pins",
        "rv_reducer.ReducerSection.supports",
        "rv_reducer.SupportsSection.carrier_radial_stiffness_N_per_mm",
        "rv_reducer.SupportsSection.main_bearing_clearance_um",
        "rv_reducer.TESection.positions",
        "rv_reducer.TESection.torque_Nm",
        "rv_reducer.TESection.zero_load_fraction",
        "rv_reducer.ToothContactSection.clearance_model",
        "rv_reducer.ToothContactSection.mesh_positions",
        "rv_reducer.ToothContactSection.start_force_N",
        "rv_serial.Analyses.catalogue",
        "rv_serial.Analyses.load_sharing",
        "rv_serial.Analyses.transmission_error",
        "rv_serial.FilesSection.bearing_clearance",
        "rv_serial.FilesSection.crank_eccentricity",
        "rv_serial.FilesSection.disc_bores",
        "rv_serial.FilesSection.disc_pitch",
        "rv_serial.FilesSection.disc_profile",
        "rv_serial.FilesSection.pins",
        "rv_serial.FilesSection.planet_runout",
        "rv_serial.FilesSection.sun_runout",
        "rv_serial.SerialSection.sun",
    }
)
