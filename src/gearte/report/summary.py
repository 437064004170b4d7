"""The summary block of a report: headline quantities, spec checks and trade-off warnings.

* Headlines: for each analysis, the values whose names (without unit) are in
  :data:`HEADLINE_KEYS`, in that order (at most :data:`MAX_HEADLINES`); an analysis with none of
  them shows its first numeric scalars. Before/after pairs show as ``before → after``; shares by
  item show the largest item.
* Spec checks: a boolean ``meets_<limit>`` value, and a value with its limit in the same analysis
  (:data:`SPEC_CHECKS`), give a pass/fail row with the limit; a count of items meeting a limit
  (:data:`SPEC_OF`, e.g. reducers in spec) shows that limit in its spec column.
* Trade-off warnings: an analysis that recommends a change and reports quantities before and after
  it (``X_before``/``X_after``) gets a warning when the change worsens any of them other than the
  first (the one the recommendation aims at), e.g. a compensation that cuts TE while raising the
  peak pin load. Lower is better unless the name is in :data:`HIGHER_IS_BETTER`.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from gearte.labels import label, value_label
from gearte.report.tables import dominant_text, is_run_metadata, item_label, relative_change
from gearte.units import format_quantity, split_unit

__all__ = [
    "HeadlineRow",
    "headlines",
    "analysis_headlines",
    "tradeoff_warnings",
    "HEADLINE_KEYS",
    "SPEC_CHECKS",
    "SPEC_OF",
]

MAX_HEADLINES = 4

#: Value names (without unit) that answer "how accurate, how loaded": in order of importance.
HEADLINE_KEYS: list[str] = [
    # transmission error and lost motion
    "geometric_te_mean",
    "geometric_te_tolerance",
    "total_te_peak_to_peak",
    "mean_output_lag",
    "dte_peak_to_peak",
    "coupled_te_amplitude",
    "optimal_assembly_te",
    "paper_rule_assembly_te_exact",
    "mc_mean",
    "mc_sd",
    "joint_lost_motion_max",
    "end_effector_error_max",
    "joint_lost_motion_max_after_shim",
    "joint_lost_motion_max_after_compensation",
    "motor_compensation_angle",
    "shim_thickness",
    "lost_motion",
    "lost_motion_max",
    "backlash",
    "backlash_mean",
    "backlash_min",
    "backlash_max",
    "mc_backlash_mean",
    "mc_backlash_sd",
    "out_of_spec_fraction",
    "reducers_in_spec",
    "reducers_in_spec_random_mean",
    "reducers_in_spec_orientation_only",
    "torsional_rigidity",
    # loads and contact
    "max_contact_force",
    "pins_in_mesh",
    "peak_pin_load",
    "pairs_in_mesh_min",
    "pairs_in_mesh_max",
    "max_normal_deformation",
    "max_contact_pressure",
    # causes
    "dominant_factor",
    "dominant_source",
    # geometry
    "K1",
    "radial_clearance",
    "backlash_per_flank",
]

#: Names (without unit) where a larger value is better (for trade-off warnings).
HIGHER_IS_BETTER: set[str] = {
    "pairs_in_mesh_min",
    "pairs_in_mesh_max",
    "pins_in_mesh",
    "pins_in_mesh_min",
    "pins_in_mesh_max",
    "torsional_rigidity",
    "cpk",
    "cp",
}

#: (value, limit, relation): the value must be ``>=`` or ``<=`` the limit of the same analysis.
SPEC_CHECKS: list[tuple[str, str, str]] = [
    ("backlash_min", "min_backlash_limit", ">="),
    ("backlash_after_shim_min", "target_min_backlash", ">="),
    ("joint_lost_motion_max", "joint_lost_motion_limit", "<="),
    ("worst_te_peak_to_peak", "te_spec", "<="),
    ("max_contact_pressure", "allowable_contact_pressure", "<="),
]

#: Counts of items that meet a limit of the same analysis: the spec column shows that limit,
#: ``{}`` replaced by its value (a ``[lower, upper]`` pair as a range).
SPEC_OF: dict[str, tuple[str, str]] = {
    "reducers_in_spec": ("te_spec", "TE peak-to-peak ≤ {}"),
    "reducers_in_spec_random_mean": ("te_spec", "TE peak-to-peak ≤ {}"),
    "reducers_in_spec_orientation_only": ("te_spec", "TE peak-to-peak ≤ {}"),
    "reducers_in_spec_full_model": ("te_spec", "TE peak-to-peak ≤ {}"),
    "reducers_graded": ("backlash_window", "backlash {}"),
    "reducers_without_grade": ("backlash_window", "backlash {}"),
}


@dataclass
class HeadlineRow:
    """One row of the summary table."""

    analysis: str  # machine name (anchor)
    title: str
    quantity: str
    value: str
    spec: str = ""
    status: str = ""  # "pass", "fail" or ""


def _by_base(values: dict[str, Any]) -> dict[str, tuple[str, Any]]:
    return {split_unit(k)[0]: (split_unit(k)[1], v) for k, v in values.items()}


def _is_num(v: Any) -> bool:
    return isinstance(v, int | float | np.integer | np.floating) and not isinstance(v, bool)


def _finite(v: Any) -> bool:
    return _is_num(v) and bool(np.isfinite(v))


def _text(v: Any, unit: str) -> str:
    return value_label(v) if isinstance(v, str) else format_quantity(v, unit)


def _limits_text(spec: dict[str, Any]) -> str:
    """A yield's spec (``{"geometric_te [arcmin]": {"lower": 0, "upper": 1.5}}``) for people:
    ``"Geometric TE ≤ 1.5′"``, ``"0.2′ ≤ Lost motion ≤ 1′"``; several joined by ``"; "``."""
    out = []
    for name, lim in spec.items():
        if not isinstance(lim, dict):
            continue
        unit = split_unit(name)[1]
        lo, hi = lim.get("lower"), lim.get("upper")
        what = label(name)
        if _finite(lo) and lo != 0 and _finite(hi):
            out.append(f"{_text(lo, unit)} ≤ {what} ≤ {_text(hi, unit)}")
        elif _finite(hi):
            out.append(f"{what} ≤ {_text(hi, unit)}")
        elif _finite(lo):
            out.append(f"{what} ≥ {_text(lo, unit)}")
    return "; ".join(out)


def _yield_rows(vals: dict[str, tuple[str, Any]]) -> list[tuple[str, str, str, str]]:
    """(quantity, value, spec, status) of a yield analysis: the yield with its confidence
    interval against the case's spec; pass/fail against the allocation's target yield when the
    case gives one."""
    y = vals.get("yield", ("", None))[1]
    spec = vals.get("spec", ("", None))[1]
    if not _finite(y) or not isinstance(spec, dict):
        return []
    value = format_quantity(100 * y, "%")
    lo, hi = vals.get("yield_ci_low", ("", None))[1], vals.get("yield_ci_high", ("", None))[1]
    if _finite(lo) and _finite(hi):
        value += f" ({format_quantity(100 * lo, '%')} – {format_quantity(100 * hi, '%')})"
    spec_text = _limits_text(spec)
    status = ""
    alloc = vals.get("allocation", ("", None))[1]
    target = alloc.get("target_yield") if isinstance(alloc, dict) else None
    if target is not None and _finite(target):
        spec_text += f"; target yield ≥ {format_quantity(100 * target, '%')}"
        status = "pass" if y >= target else "fail"
    return [("Yield (confidence interval)", value, spec_text, status)]


def _spec_of(base: str, vals: dict[str, tuple[str, Any]]) -> str:
    """The spec column of a count of items meeting a limit (:data:`SPEC_OF`), or ``""``."""
    ref = SPEC_OF.get(base)
    if ref is None or ref[0] not in vals:
        return ""
    unit, lim = vals[ref[0]]
    if _finite(lim):
        return ref[1].format(_text(lim, unit))
    if isinstance(lim, list | tuple) and len(lim) == 2 and all(_finite(x) for x in lim):
        return ref[1].format(f"{_text(lim[0], unit)} – {_text(lim[1], unit)}")
    return ""


def headlines(result: Any) -> list[HeadlineRow]:
    """Summary rows of every analysis of a study result (see the module docstring)."""
    rows: list[HeadlineRow] = []
    for a in result.analyses:
        rows += analysis_headlines(a)
    return rows


def analysis_headlines(a: Any) -> list[HeadlineRow]:
    """Summary rows of the analysis ``a`` (an AnalysisResult; see the module docstring)."""
    vals = _by_base(a.values)
    picked: list[HeadlineRow] = []

    def add(quantity: str, value: str, spec: str = "", status: str = "") -> None:
        picked.append(HeadlineRow(a.name, a.title, quantity, value, spec, status))

    # spec checks first: they are the answer to "does it meet the spec"
    checked = set()
    for key, limit, rel in SPEC_CHECKS:
        if key in vals and limit in vals and _finite(vals[key][1]) and _finite(vals[limit][1]):
            unit, v = vals[key]
            lim = vals[limit][1]
            ok = v >= lim if rel == ">=" else v <= lim
            sym = "≥" if rel == ">=" else "≤"
            add(
                label(key),
                _text(v, unit),
                f"{sym} {_text(lim, vals[limit][0])}",
                "pass" if ok else "fail",
            )
            checked |= {key, limit}
    for base, (_, v) in vals.items():
        if base.startswith("meets_") and isinstance(v, bool | np.bool_):
            limit = base[len("meets_") :]
            if limit in checked:
                continue  # its value was checked against it above
            spec = ""
            if limit in vals and _finite(vals[limit][1]):
                spec = _text(vals[limit][1], vals[limit][0])
            add(label(limit), "met" if v else "not met", spec, "pass" if v else "fail")
            checked.add(limit)
    for row in _yield_rows(vals):
        add(*row)
    for base in HEADLINE_KEYS:
        if len(picked) >= MAX_HEADLINES:
            break
        if base in checked:
            continue
        if base in vals:
            unit, v = vals[base]
            dominant = dominant_text({base: v, **{k: x for k, (_, x) in vals.items()}}, base)
            if dominant is not None:
                add(label(base), dominant)
            elif _is_num(v) or isinstance(v, str):
                add(label(base), _text(v, unit), _spec_of(base, vals))
            continue
        if f"{base}_before" in vals and f"{base}_after" in vals:
            unit, b = vals[f"{base}_before"]
            _, af = vals[f"{base}_after"]
            add(label(base), f"{_text(b, unit)} → {_text(af, unit)}")
    if len(picked) < MAX_HEADLINES:
        # a ranking: a yield's total Sobol indices first (they hold where a linear share is 0:
        # a peak-to-peak of errors that act through their magnitude), then any share; none
        # named when its largest entry is 0 (nothing dominates)
        ranked = sorted(vals, key=lambda b: b != "sobol_total")
        for base in ranked:
            unit, v = vals[base]
            if (
                (base == "sobol_total" or "share" in base)
                and isinstance(v, dict)
                and v
                and all(_finite(x) for x in v.values())
            ):
                item, share = max(v.items(), key=lambda kv: kv[1])
                if not share > 0:
                    continue
                what = "total Sobol index" if base == "sobol_total" else label(base).lower()
                add(f"Largest {what}", f"{item_label(item)} ({_text(share, unit)})")
                break
    if not picked:
        for base, (unit, v) in vals.items():
            if _finite(v) and not is_run_metadata(base):
                add(label(base), _text(v, unit), _spec_of(base, vals))
                if len(picked) >= 3:
                    break
    if not picked:  # tables only (ranked lists): their first entry is the headline
        for base, (_, v) in vals.items():
            if isinstance(v, list) and v and isinstance(v[0], dict | str):
                add(f"First of {_lower(label(base))}", _first_entry(v[0]))
                if len(picked) >= 2:
                    break
    return picked


def _first_entry(entry: dict[str, Any] | str, width: int = 120) -> str:
    """One line for the first row of a ranked table (a dict of unit-named fields) or list."""
    if isinstance(entry, str):
        text = entry
    else:
        parts = []
        for key, x in list(entry.items())[:3]:
            base, unit = split_unit(key)
            parts.append(f"{label(base)} {_text(x, unit) if _is_num(x) else x}")
        text = ", ".join(parts)
    return text if len(text) <= width else text[: width - 1] + "…"


def _pairs(values: dict[str, Any]) -> list[tuple[str, str, float, float]]:
    """(stem, unit, before, after) of the numeric before/after pairs, in order."""
    vals = _by_base(values)
    out = []
    for base, (unit, b) in vals.items():
        if base.endswith("_before"):
            stem = base[: -len("_before")]
            if f"{stem}_after" in vals:
                af = vals[f"{stem}_after"][1]
                if _finite(b) and _finite(af):
                    out.append((stem, unit, float(b), float(af)))
    return out


def _worse(stem: str, before: float, after: float) -> bool:
    base = stem
    higher = base in HIGHER_IS_BETTER or base.rsplit("_", 1)[0] in HIGHER_IS_BETTER
    return after < before if higher else abs(after) > abs(before)


def _lower(text: str) -> str:
    """``"Peak pin load"`` → ``"peak pin load"``; acronyms stay (``"TE peak"``)."""
    return text[:1].lower() + text[1:] if text[1:2].islower() else text


def _change_text(stem: str, unit: str, before: float, after: float) -> str:
    rel = relative_change(before, after)
    return f"{_lower(label(stem))} from {_text(before, unit)} to {_text(after, unit)}{rel}"


def tradeoff_warnings(result: Any, *, threshold: float = 0.01) -> list[str]:
    """Warnings for the analyses of ``result`` whose recommendations worsen another reported
    quantity by more than ``threshold`` [-] (relative; any change of a count)."""
    out = []
    for a in result.analyses:
        pairs = _pairs(a.values)
        if len(pairs) < 2:
            continue
        target = pairs[0]
        stem, unit, b, af = target
        worse = []
        merged: set[str] = set()
        by_stem = {p[0]: p for p in pairs}
        for p in pairs[1:]:
            s, u, pb, pa = p
            if s in merged or not _worse(s, pb, pa):
                continue
            rel = abs(pa - pb) / max(abs(pb), 1e-300)
            if rel <= threshold and not float(pb).is_integer():
                continue
            if s.endswith("_min") and f"{s[:-4]}_max" in by_stem:
                q = by_stem[f"{s[:-4]}_max"]
                worse.append(
                    f"{_lower(label(s[:-4]))} from {_text(pb, u)}–{_text(q[2], u)} to "
                    f"{_text(pa, u)}–{_text(q[3], u)}"
                )
                merged.add(q[0])
                continue
            worse.append(_change_text(s, u, pb, pa))
        if not worse:
            continue
        verb = "worsens" if _worse(stem, b, af) else "improves"
        out.append(
            f"{a.title}: the recommendation {verb} {_change_text(stem, unit, b, af)}, but changes "
            + "; ".join(worse)
            + "."
        )
    return out
