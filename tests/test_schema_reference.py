"""The generated case-file reference (issue 15 item 2) covers 100 % of the schema fields of every
study kind: each key of each section appears, with its type, unit, allowed values, default and
meaning (every key has one)."""

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


def test_every_key_has_a_meaning() -> None:
    """Every key of every built-in kind has a Field description (or, for a section, a class
    docstring): a new key without one fails here."""
    missing = _missing_meaning(BUILTIN)
    assert not missing, f"add a Field description: {sorted(missing)}"
