"""Study kind ``gear_chain``: lost motion of a gear chain at the joint and at the end effector,
shim of a bevel pair, motor-angle compensation (Jiang et al. 2024, §4, eqs. 30–33).

A chain is a list of stages from the motor to the joint, of any length and order. Each stage
gives its return error in one of three ways:

* ``lost_motion_max_arcmin`` (optionally mean/min): a catalogue value (the paper's planetary
  reducer, 1′);
* ``backlash_{min,mean,max}_um`` with ``output_diameter_mm``: backlash values obtained
  elsewhere (measured, or the paper's 3DCS simulation, Tables 4 and 8) → eq. (14)/(29);
* ``[chain.stages.pair]``: the pair's data and tolerances (same tables as the ``gear_pair``
  kind) → gearte's backlash stack, min/mean/max at ``analysis.confidence`` → eq. (14)/(29);
* ``[chain.stages.drive]``: any registered drive family (:mod:`gearte.families`: ``kind`` =
  ``"rv_reducer"``, ``"cycloid_stage"``, ``"planetary"``, ``"gear_pair"``, ...) and either
  ``case = "<file>"`` (a case file of that kind, relative to this one) or the family's sections
  inline (``[chain.stages.drive.reducer]`` …). Its lost motion (and its spread where it has a
  tolerance stack) and its torsional stiffness come from that drive's own model through the drive
  interface (:mod:`gearte.drives`); a family whose model has no lost motion (``planetary``) takes
  ``lost_motion_max_arcmin`` beside it.

Optional ``[shim]``: shim thickness under both gears of a bevel stage for a target minimum
backlash (eq. 32), the backlash after shimming (shifted stack), and the chain after shimming.
The paper verified the shimmed backlash by a 3DCS run (0.025–0.061 mm) and used that range
downstream; ``verified_backlash_*_um`` lets a case do the same with a verified (measured or
simulated) range; without it, gearte's shifted backlash is used.

Optional ``[compensation]``: stages compensated by their mean return error when the load torque
reverses; motor offset (eq. 33), residual per stage, joint and end error after it. It acts on
the chain after the shim when there is one (the paper's order).

Optional ``[analyses.yield]``: each stage's lost motion from its own drawn tolerances (its
family's errors: a pair's backlash stack, a cycloid stage's component errors, ...), or drawn from
its min/mean/max, or constant, combined at the joint by eq. (30) by Monte-Carlo — the joint's
distribution, yield, Cpk and contributions per tolerance (``gearte.studies._yield``).

Analyses: one group per stage (``<stage>_backlash`` …, see ``gear_pair``), ``chain``
(``joint_lost_motion_max [arcmin]``, ``end_effector_error_max [mm]``), ``shim``
(``shim_thickness [mm]`` …), ``compensation`` (``motor_compensation_angle [deg]``,
``end_effector_error_after_compensation [mm]``, the compensation table).
"""

from __future__ import annotations

import math
import re
from typing import Any, Literal

from pydantic import Field, model_validator

from gearte.io.schema import CaseBase, StrictModel
from gearte.models.backlash import BevelPair, summarise_backlash
from gearte.models.lost_motion import (
    StageLostMotion,
    analyse_chain,
    compensation_table,
    compensation_table_csv,
    compensation_table_json,
    return_error,
    shim_backlash_reduction,
    shim_thickness,
)
from gearte.results import AnalysisResult, StudyResult
from gearte.studies._drives import DriveSpec
from gearte.studies._yield import YieldSection
from gearte.studies.gear_pair import PairAnalysisSpec, PairSpec, analyse_pair
from gearte.units import (
    Nmm_to_Nm,
    arcmin_to_rad,
    deg_to_rad,
    format_dms,
    mm_to_um,
    rad_to_arcmin,
    rad_to_arcsec,
    rad_to_deg,
    um_to_mm,
)

__all__ = ["KIND", "REFERENCES", "FIGURES", "StageSpec", "ChainSpec", "ShimSpec", "Case", "run"]

KIND = "gear_chain"
REFERENCES = ["jiang2024"]
FIGURES = "gearte.plotting.gear_chain"


def _slug(name: str) -> str:
    return re.sub(r"[^a-z0-9]+", "_", name.lower()).strip("_") or "stage"


class StageSpec(StrictModel):
    """One stage of the chain (motor side first)."""

    name: str = Field(min_length=1, description="Unique stage name.")
    ratio: float = Field(gt=0, le=1e6, description="Reduction ratio i = ω_in/ω_out (> 0).")
    compensate: bool = Field(default=False, description="Compensate by the motor angle (eq. 33).")
    lost_motion_max_arcmin: float | None = Field(
        default=None,
        ge=0,
        le=6000,
        description="Catalogue lost motion of the stage [arcmin] (one of three ways to give a "
        "stage's return error).",
    )
    lost_motion_mean_arcmin: float | None = Field(
        default=None,
        ge=0,
        le=6000,
        description="Catalogue mean lost motion [arcmin] (optional, with the maximum).",
    )
    lost_motion_min_arcmin: float | None = Field(
        default=None,
        ge=0,
        le=6000,
        description="Catalogue minimum lost motion [arcmin] (optional, with the maximum).",
    )
    backlash_min_um: float | None = Field(
        default=None,
        ge=0,
        le=100_000,
        description="Minimum normal backlash obtained elsewhere (measured, simulated) [µm], with "
        "output_diameter_mm.",
    )
    backlash_mean_um: float | None = Field(
        default=None, ge=0, le=100_000, description="Mean normal backlash obtained elsewhere [µm]."
    )
    backlash_max_um: float | None = Field(
        default=None,
        ge=0,
        le=100_000,
        description="Maximum normal backlash obtained elsewhere [µm].",
    )
    output_diameter_mm: float | None = Field(
        default=None, gt=0, le=100_000, description="Driven gear d (spur) or dm (bevel) [mm]."
    )
    pressure_angle_deg: float = Field(
        default=20.0,
        gt=0,
        lt=45,
        description="Pressure angle α of a stage given by backlash values [deg].",
    )
    min_backlash_limit_um: float = Field(
        default=0.0,
        ge=0,
        le=100_000,
        description="Smallest allowed minimum backlash of a stage given by values [µm] (0: none).",
    )
    pair: PairSpec | None = Field(
        None,
        description="The stage's gear pair and its tolerances (same tables as the gear_pair kind).",
    )
    drive: DriveSpec | None = Field(
        default=None, description="A drive gearte models (rv_reducer, cycloid_stage, ...)."
    )

    @model_validator(mode="after")
    def _one_source(self):
        lm = self.lost_motion_max_arcmin is not None
        bl = any(
            v is not None
            for v in (self.backlash_min_um, self.backlash_mean_um, self.backlash_max_um)
        )
        pr = self.pair is not None
        dr = self.drive is not None
        if dr:
            self._check_drive(lm, bl or pr)
        if (lm and not dr) + bl + pr + dr != 1:
            raise ValueError(
                f"stage {self.name!r}: give exactly one of lost_motion_max_arcmin, "
                "backlash_{min,mean,max}_um (+ output_diameter_mm), a [pair] table or a "
                "[drive] table"
            )
        if lm:
            vals = [
                v
                for v in (
                    self.lost_motion_min_arcmin,
                    self.lost_motion_mean_arcmin,
                    self.lost_motion_max_arcmin,
                )
                if v is not None
            ]
            if vals != sorted(vals):
                raise ValueError(f"stage {self.name!r}: lost motion needs min <= mean <= max")
        if bl:
            trio = (self.backlash_min_um, self.backlash_mean_um, self.backlash_max_um)
            if any(v is None for v in trio) or self.output_diameter_mm is None:
                raise ValueError(
                    f"stage {self.name!r}: backlash_min_um, backlash_mean_um, backlash_max_um "
                    "and output_diameter_mm are all required"
                )
            if list(trio) != sorted(trio):  # type: ignore[type-var]
                raise ValueError(
                    f"stage {self.name!r}: inverted limits, need backlash_min_um <= "
                    f"backlash_mean_um <= backlash_max_um (got {trio})"
                )
        if pr:
            p = self.pair
            assert p is not None
            z = p.driven.teeth / p.driving.teeth
            if abs(z / self.ratio - 1) > 1e-3:
                raise ValueError(
                    f"stage {self.name!r}: ratio {self.ratio} disagrees with the pair's teeth "
                    f"{p.driven.teeth}/{p.driving.teeth} = {z:.6g} (more than 0.1 %)"
                )
        if self.compensate and not (
            bl or pr or self.lost_motion_mean_arcmin is not None or self._drive_has_lost_motion()
        ):
            raise ValueError(
                f"stage {self.name!r}: compensate = true needs a mean return error "
                "(lost_motion_mean_arcmin, backlash values, a pair or a drive that models it)"
            )
        return self

    def _drive_has_lost_motion(self) -> bool:
        from gearte.families import get_family

        return self.drive is not None and get_family(self.drive.kind).lost_motion

    def _check_drive(self, lost_given: bool, other: bool) -> None:
        """A drive stage: ratio as the drive's; lost motion given only where unmodelled."""
        assert self.drive is not None
        if other:
            return  # reported by the one-source rule
        if self._drive_has_lost_motion() and lost_given:
            raise ValueError(
                f"stage {self.name!r}: the {self.drive.kind} drive's lost motion comes from its "
                "own model; remove lost_motion_*_arcmin"
            )
        if not self._drive_has_lost_motion() and not lost_given:
            raise ValueError(
                f"stage {self.name!r}: the {self.drive.kind} model has no lost motion (no "
                "backlash in it); give lost_motion_max_arcmin (e.g. the maker's value) beside it"
            )
        ratio = self.drive.build(self.name).ratio
        if abs(ratio / self.ratio - 1) > 1e-3:
            raise ValueError(
                f"stage {self.name!r}: ratio {self.ratio} disagrees with the drive's own ratio "
                f"{ratio:.6g} (more than 0.1 %)"
            )


class ChainSpec(StrictModel):
    """The chain: its stages from the motor to the joint and the lever to the end effector."""

    lever_length_mm: float = Field(
        gt=0, le=1e6, description="Distance L from the joint axis to the end effector [mm]."
    )
    stages: list[StageSpec] = Field(min_length=1, description="Stages from motor to joint.")
    te_positions: int | None = Field(
        default=None,
        ge=8,
        le=7200,
        description="Joint positions over one joint turn for the chain's transmission error "
        "from the drives that model one (not in Jiang 2024; default: not computed).",
    )

    @model_validator(mode="after")
    def _unique(self):
        names = [s.name for s in self.stages]
        dup = sorted({n for n in names if names.count(n) > 1})
        if dup:
            raise ValueError(f"stage names must be unique; repeated: {dup}")
        slugs = [_slug(n) for n in names]
        if len(set(slugs)) != len(slugs):
            raise ValueError(f"stage names must differ in letters/digits: {names}")
        return self


class ShimSpec(StrictModel):
    """Shims under both gears of a bevel stage to reach a target minimum backlash (eq. 32)."""

    stage: str = Field(description="Name of the bevel stage to shim.")
    target_min_backlash_um: float = Field(
        gt=0, le=100_000, description="Wanted minimum normal backlash [µm]."
    )
    current_min_backlash_um: float | None = Field(
        default=None,
        gt=0,
        le=100_000,
        description="Minimum backlash eq. 32 starts from [µm]; default: the stage's minimum.",
    )
    rounding_mm: float = Field(
        default=0.001, ge=0, le=1, description="Shim stock increment [mm] (0: exact)."
    )
    rounding: Literal["nearest", "down", "up"] = Field(
        default="nearest", description="How to round to the stock ('down' keeps min >= target)."
    )
    cone_angle_driving_deg: float = Field(
        default=45.0, gt=0, lt=90, description="δ1, only for stages given by backlash values."
    )
    cone_angle_driven_deg: float = Field(
        default=45.0, gt=0, lt=90, description="δ2, only for stages given by backlash values."
    )
    verified_backlash_min_um: float | None = Field(
        default=None,
        ge=0,
        le=100_000,
        description="Verified (measured or simulated) minimum backlash after shimming [µm], used "
        "downstream instead of gearte's shifted backlash.",
    )
    verified_backlash_mean_um: float | None = Field(
        default=None,
        ge=0,
        le=100_000,
        description="Verified mean backlash after shimming [µm] (needs min and max).",
    )
    verified_backlash_max_um: float | None = Field(
        default=None,
        ge=0,
        le=100_000,
        description="Verified maximum backlash after shimming [µm] (with the minimum).",
    )

    @model_validator(mode="after")
    def _verified(self):
        lo, mid, hi = (
            self.verified_backlash_min_um,
            self.verified_backlash_mean_um,
            self.verified_backlash_max_um,
        )
        if (lo is None) != (hi is None):
            raise ValueError("verified_backlash_min_um and verified_backlash_max_um go together")
        if mid is not None and lo is None:
            raise ValueError("verified_backlash_mean_um needs verified min and max")
        if lo is not None and hi is not None:
            vals = [v for v in (lo, mid, hi) if v is not None]
            if vals != sorted(vals):
                raise ValueError(
                    f"inverted verified backlash range {vals}: need min <= mean <= max"
                )
        return self


class CompensationSpec(StrictModel):
    """Motor-angle compensation when the load torque reverses (eq. 33)."""

    enabled: bool = Field(
        True, description="Compute the motor-angle compensation (false: skip it)."
    )


class ChainAnalyses(StrictModel):
    """``[analyses]`` of a chain: ``[analyses.yield]`` (gearte.studies._yield)."""

    yield_: YieldSection | None = Field(
        default=None,
        alias="yield",
        description="production yield of the chain: each stage's lost motion drawn from its "
        "distribution, combined at the joint by eq. (30); tolerance keys are the stage names "
        "(tolerance_arcmin, nominal_arcmin at the stage output) and, for a pair stage, its "
        "backlash stack's contributors <stage slug>.<contributor> [µm] (e.g. "
        "spur_pair.centre_distance; spur_pair.driven_gear_eccentricity takes grade = N: "
        "ISO 1328-2 F_i″)",
    )


class Case(CaseBase):
    chain: ChainSpec
    analysis: PairAnalysisSpec = PairAnalysisSpec()
    shim: ShimSpec | None = None
    compensation: CompensationSpec | None = None
    analyses: ChainAnalyses | None = None

    @model_validator(mode="after")
    def _shim_target(self):
        if self.shim is None:
            return self
        stages = {s.name: s for s in self.chain.stages}
        st = stages.get(self.shim.stage)
        if st is None:
            raise ValueError(
                f"shim.stage = {self.shim.stage!r} is not a stage name; stages: {list(stages)}"
            )
        if st.drive is not None:
            raise ValueError(
                f"shim.stage = {st.name!r} is a {st.drive.kind} drive; shims are for bevel pairs "
                "given by a [pair] table or backlash values"
            )
        if st.lost_motion_max_arcmin is not None:
            raise ValueError(
                f"shim.stage = {st.name!r} gives only a lost motion; a shim needs its backlash"
            )
        if st.pair is not None and st.pair.type != "bevel":
            raise ValueError(f"shim.stage = {st.name!r} is a spur pair; shims are for bevel pairs")
        current, limit = _current_min_um(st, self.analysis.confidence)
        if self.shim.current_min_backlash_um is not None:
            current = self.shim.current_min_backlash_um
        if not self.shim.target_min_backlash_um < current:
            raise ValueError(
                f"shim.target_min_backlash_um = {self.shim.target_min_backlash_um} must be below "
                f"the current minimum backlash {current:.4g} µm of stage {st.name!r} "
                "(a shim can only reduce backlash)"
            )
        if self.shim.target_min_backlash_um < limit:
            raise ValueError(
                f"shim.target_min_backlash_um = {self.shim.target_min_backlash_um} is below the "
                f"minimum limit normal backlash {limit:g} µm of stage {st.name!r}"
            )
        return self


def _current_min_um(st: StageSpec, confidence: float) -> tuple[float, float]:
    """Current minimum backlash [µm] of a stage and its minimum limit [µm]."""
    if st.pair is not None:
        s = summarise_backlash(st.pair.backlash_stack(), confidence=confidence)
        return float(mm_to_um(s.min)), st.pair.min_backlash_limit_um
    assert st.backlash_min_um is not None
    return st.backlash_min_um, st.min_backlash_limit_um


def _stage_backlash_mm(st: StageSpec, confidence: float):
    """(min, mean, max) backlash [mm], output diameter [mm], α [rad], pair or None."""
    if st.pair is not None:
        pair = st.pair.build()
        s = summarise_backlash(st.pair.backlash_stack(), confidence=confidence)
        return (s.min, s.mean, s.max), pair.output_diameter, pair.pressure_angle, pair
    assert st.backlash_min_um is not None and st.backlash_max_um is not None
    assert st.backlash_mean_um is not None and st.output_diameter_mm is not None
    trio = tuple(
        float(um_to_mm(v)) for v in (st.backlash_min_um, st.backlash_mean_um, st.backlash_max_um)
    )
    return trio, st.output_diameter_mm, float(deg_to_rad(st.pressure_angle_deg)), None


def _lost(trio, d, alpha, name: str, warnings: list[str]) -> tuple[float, float, float]:
    """(min, mean, max) return error [rad]; a negative backlash (interference) loses no motion."""
    if trio[0] < 0:
        warnings.append(
            f"{name}: minimum normal backlash {mm_to_um(trio[0]):.1f} µm < 0 (the flanks "
            "interfere); its lost motion is counted as 0 there"
        )
    return tuple(float(return_error(max(j, 0.0), d, alpha)) for j in trio)  # type: ignore[return-value]


def _statistical_joint_max(res, confidence: float) -> float:
    """Joint lost motion [rad] at ``confidence`` for independent normal stages (not eq. 30)."""
    from gearte.tolerance.stackup import z_for_confidence

    z = z_for_confidence(confidence)
    mean = 0.0
    var = 0.0
    for s, f in zip(res.stages, res.transfer, strict=True):
        if s.mean is None or s.min is None:
            mean += f * s.max
            continue
        mean += f * s.mean
        var += (f * (s.max - s.min) / (2 * z)) ** 2
    return mean + z * math.sqrt(var)


def _given_lost_motion(st: StageSpec) -> tuple[float, float | None, float | None]:
    """(max, mean, min) return error [rad] given in the case (mean/min optional)."""
    assert st.lost_motion_max_arcmin is not None

    def rad(v: float | None) -> float | None:
        return None if v is None else float(arcmin_to_rad(v))

    return (
        float(arcmin_to_rad(st.lost_motion_max_arcmin)),
        rad(st.lost_motion_mean_arcmin),
        rad(st.lost_motion_min_arcmin),
    )


def _pair_drive(st: StageSpec, pair):
    """The drive-interface view of a ``[pair]`` stage (its stiffness)."""
    from gearte.drives.gear_pair import GearPairDrive

    assert st.pair is not None
    return GearPairDrive(pair, name=st.name, face_width=getattr(st.pair, "face_width_mm", None))


def _drive_stage(st: StageSpec, drive, confidence: float):
    """Lost motion of a ``[drive]`` stage from the drive's own model, and its result."""
    from gearte.labels import value_label

    assert st.drive is not None
    values: dict = {
        "drive_kind": drive.kind,
        "drive_case": st.drive.case or "inline",
        "ratio": st.ratio,
        "drive_ratio": drive.ratio,
    }
    notes = [
        f"{value_label(drive.kind)} drive; lost motion and stiffness from its own model "
        "(gearte.drives)."
    ]
    if st.lost_motion_max_arcmin is not None:  # a model without lost motion: the given values
        mx, mean, lo = _given_lost_motion(st)
        notes.append("Its model has no lost motion: the values given in the case are used.")
    else:
        spread = drive.lost_motion_spread(confidence)
        if spread is None:
            lm = drive.lost_motion()
            assert lm is not None
            mx = mean = lo = float(lm)
            values["lost_motion [arcmin]"] = float(rad_to_arcmin(lm))
            notes.append(
                "No tolerance stack in this description: min = mean = max = the model's "
                "lost motion (a deterministic reducer with its given errors)."
            )
        else:
            mx, mean, lo = spread.max, spread.mean, spread.min
            values["lost_motion_sd [arcmin]"] = float(rad_to_arcmin(spread.sd))
            notes.append(
                f"Lost motion mean and range at confidence {confidence} from the drive's "
                "tolerance stack."
            )
    values.update(
        {
            "lost_motion_max [arcmin]": float(rad_to_arcmin(mx)),
            "lost_motion_mean [arcmin]": None if mean is None else float(rad_to_arcmin(mean)),
            "lost_motion_min [arcmin]": None if lo is None else float(rad_to_arcmin(lo)),
            "lost_motion_max_dms": format_dms(mx),
        }
    )
    k = drive.torsional_stiffness()
    values["torsional_stiffness [N*m/arcmin]"] = None if k is None else _nm_per_arcmin(k)
    pair = getattr(st.drive.validated_case, "pair", None)
    if pair is not None and pair.min_backlash_limit_um > 0:  # a gear pair with a limit
        s = summarise_backlash(pair.backlash_stack(), confidence=confidence)
        values["backlash_min [um]"] = float(mm_to_um(s.min))
        values["min_backlash_limit [um]"] = pair.min_backlash_limit_um  # the report checks it
    result = AnalysisResult(
        name=f"{_slug(st.name)}_drive",
        title=f"{st.name}: {value_label(drive.kind)} drive (its own model)",
        values=values,
        references=[],
        notes=notes,
    )
    return StageLostMotion(st.name, st.ratio, mx, mean, lo, st.compensate), result


def _chain_te(case: Case, drives: dict) -> AnalysisResult:
    """Transmission error at the joint over one joint turn from the stages that model one."""
    import numpy as np

    from gearte.drives.chain import joint_te_contributions

    n = case.chain.te_positions
    assert n is not None
    sts = case.chain.stages
    th = np.linspace(0.0, 2.0 * np.pi, n, endpoint=False)
    parts = joint_te_contributions([drives.get(s.name) for s in sts], [s.ratio for s in sts], th)
    te = sum((p for p in parts if p is not None), np.zeros_like(th))
    with_te = [s.name for s, p in zip(sts, parts, strict=True) if p is not None]
    without = [s.name for s, p in zip(sts, parts, strict=True) if p is None]
    pp = float(np.ptp(te))
    return AnalysisResult(
        name="chain_te",
        title="Transmission error at the joint from the drives' own models",
        values={
            "joint_te_peak_to_peak_sampled [arcsec]": float(rad_to_arcsec(pp)),
            "end_effector_te_peak_to_peak_sampled [mm]": pp * case.chain.lever_length_mm,
            "stages_with_te": with_te,
            "stages_without_te": without,
            "joint_angle [deg]": rad_to_deg(th),
            "joint_te [arcsec]": rad_to_arcsec(te),
        },
        references=[],
        notes=[
            "Not in Jiang 2024. TE_joint(θ) = Σ_k f_k TE_k(θ/f_k), f_k = 1/Π_(j>k) i_j, each "
            "stage's unloaded TE from its drive's own model (gearte.drives); stages listed in "
            "stages_without_te have no TE model and count as exact.",
            f"Peak-to-peak over {n} equally spaced joint positions (sampled: a mesh ripple "
            "between the samples is not resolved).",
        ],
    )


def _nm_per_arcmin(k: float) -> float:
    """Torsional stiffness N·mm/rad → N·m/arcmin."""
    return float(Nmm_to_Nm(k) / rad_to_arcmin(1.0))


def _joint_stiffness_values(stages, stiffness: dict[str, float | None]) -> dict:
    """Stage stiffnesses and, when all are modelled, the chain's at the joint [N·m/arcmin]."""
    from gearte.drives.chain import joint_stiffness

    ks = [stiffness[s.name] for s in stages]
    known = [k for k in ks if k is not None]
    joint = None
    if len(known) == len(ks):
        joint = _nm_per_arcmin(joint_stiffness(known, [s.ratio for s in stages]))
    return {
        "stage_torsional_stiffness [N*m/arcmin]": {
            s.name: None if k is None else _nm_per_arcmin(k)
            for s, k in zip(stages, ks, strict=True)
        },
        "joint_torsional_stiffness [N*m/arcmin]": joint,
    }


def _round_shim(x: float, step: float, how: str) -> float:
    if step <= 0:
        return x
    q = x / step
    k = {"nearest": round(q), "down": math.floor(q + 1e-9), "up": math.ceil(q - 1e-9)}[how]
    return k * step


def _stage_tolerances(case: Case, stages, drives: dict, backlash: dict) -> dict:
    """Each stage's lost-motion law at its output [arcmin], as ``[analyses.yield]`` entries.

    A stage whose model has a tolerance stack (a pair, a cycloid stage) is normal with the
    stack's mean and σ (tolerance = 3σ); a stage given by min/mean/max values is normal about
    its mean with σ = (max − min)/(2z) at the case's confidence (the reading of
    ``joint_lost_motion_statistical_max``); a stage with a single value (a catalogue maximum, a
    deterministic reducer) is constant at it.
    """
    from gearte.studies._yield import ToleranceEntry
    from gearte.tolerance.stackup import z_for_confidence

    conf = case.analysis.confidence
    z = z_for_confidence(conf)
    specs = {st.name: st for st in case.chain.stages}
    out: dict[str, ToleranceEntry] = {}
    for s in stages:
        st = specs[s.name]
        spread = None
        if s.name in drives and st.lost_motion_max_arcmin is None:
            spread = drives[s.name].lost_motion_spread(conf)
        elif s.name in backlash and backlash[s.name][3] is not None:
            spread = _pair_drive(st, backlash[s.name][3]).lost_motion_spread(conf)
        if spread is not None:
            out[s.name] = ToleranceEntry(
                kind="normal",
                tolerance_arcmin=float(rad_to_arcmin(3.0 * spread.sd)),
                nominal_arcmin=float(rad_to_arcmin(spread.mean)),
            )
        elif s.mean is not None and s.min is not None and s.max > s.min:
            out[s.name] = ToleranceEntry(
                kind="normal",
                tolerance_arcmin=float(rad_to_arcmin(3.0 * (s.max - s.min) / (2.0 * z))),
                nominal_arcmin=float(rad_to_arcmin(s.mean)),
            )
        else:
            out[s.name] = ToleranceEntry(
                kind="constant", tolerance_arcmin=0.0, nominal_arcmin=float(rad_to_arcmin(s.max))
            )
    return out


def _yield_setup(case: Case, sec: YieldSection, own: dict, defaults: dict):
    """What the chain's yield model and its inputs are built from, nothing evaluated: the
    :class:`~gearte.runners.chain_yield.GearChainYield`, the error keys' units and nominals, the
    tolerances the stages imply (``defaults`` from :func:`_stage_tolerances`, updated: a stage
    that draws its own tolerances has its law replaced by its family's errors) and the grade
    reading.

    ``own``: stage name → its :class:`~gearte.families.StageYield` (:func:`_own_tolerances`).
    :func:`_chain_yield` runs it; :func:`preflight` checks it.
    """
    from gearte.runners.chain_yield import ChainStage, GearChainYield

    units = {s.name: "arcmin" for s in case.chain.stages}
    nominal = {k: float(t.nominal_arcmin or 0.0) for k, t in defaults.items()}
    chain: list[ChainStage] = []
    graders: dict[str, Any] = {}
    families: dict[str, list[str]] = {}
    for s in case.chain.stages:
        sy = own.get(s.name)
        if sy is None or s.name in sec.tolerances:
            chain.append(ChainStage(s.name, _slug(s.name), s.ratio))
            continue
        del units[s.name]
        defaults.pop(s.name, None)
        nominal.pop(s.name, None)
        chain.append(ChainStage(s.name, _slug(s.name), s.ratio, sy.model))
        units.update(sy.units)
        families.update(sy.families)
        for key, law in sy.laws.items():
            if key in sy.nominal:
                nominal[key] = float(sy.nominal[key])
            defaults[key] = law
        if sy.grade_um is not None:
            graders.update({key: sy.grade_um for key in sy.units})

    def grade_um(key: str, grade: int):
        """The tolerance a grade implies for a key of a stage's own errors (its family's)."""
        fn = graders.get(key)
        return None if fn is None else fn(key, grade)

    model = GearChainYield(chain, nominal, case.chain.lever_length_mm)
    return model, chain, units, nominal, defaults, grade_um, families


def _own_tolerances(case: Case) -> dict:
    """Stage name → its :class:`~gearte.families.StageYield`: a ``[pair]`` stage's backlash
    stack, a ``[drive]`` stage's family's own tolerances (``None`` where its description has
    none: a measured drive; such stages, and stages given by values, draw their lost motion
    from :func:`_stage_tolerances`)."""
    from gearte.families import get_family
    from gearte.families.gear_pair import pair_stage_yield

    out = {}
    for s in case.chain.stages:
        sy = None
        if s.drive is not None:
            fam = get_family(s.drive.kind)
            if fam.chain_yield is not None and s.lost_motion_max_arcmin is None:
                sy = fam.chain_yield(s.drive.validated_case, _slug(s.name))
        elif s.pair is not None and s.lost_motion_max_arcmin is None:
            sy = pair_stage_yield(s.pair, _slug(s.name))
        if sy is not None:
            out[s.name] = sy
    return out


def preflight(case: Case) -> None:
    """The checks :func:`run` makes on the built drives before any analysis (``gearte
    validate``, :func:`gearte.studies.run_case`): each ``[drive]`` stage's drive is built
    (:meth:`DriveSpec.build`) and each ``[pair]`` stage's pair, without computing a lost motion;
    the yield's tolerance keys (a pair stage's backlash-stack contributors come from its pair),
    cost keys, grades and spec quantities are checked against the yield model
    (:func:`_yield_setup`, :func:`~gearte.studies._yield.yield_inputs`) as the yield does.

    Raises
    ------
    ParameterError
        Naming the key of the first failing check.
    """
    from gearte.studies._yield import yield_inputs

    for st in case.chain.stages:
        if st.drive is not None:
            st.drive.build(st.name)
        elif st.lost_motion_max_arcmin is None and st.pair is not None:
            st.pair.build()
    sec = case.analyses.yield_ if case.analyses is not None else None
    if sec is None:
        return
    model, _, units, nominal, defaults, grade_um, families = _yield_setup(
        case, sec, _own_tolerances(case), {}
    )
    yield_inputs(
        sec,
        units,
        nominal,
        defaults,
        families=families,
        grade_um=grade_um,
        quantities=model.quantities,
    )


def _chain_yield(case: Case, stages, drives: dict, backlash: dict, options) -> AnalysisResult:
    """``[analyses.yield]``: each sample one assembled chain, combined at the joint by eq. (30).

    A pair stage (``[pair]`` or a ``gear_pair`` drive) draws every contributor of its own
    backlash stack (keys ``<stage slug>.<contributor>`` [µm]; gearte.runners.chain_yield) unless
    the section gives a law for the whole stage by its name; every other stage draws its lost
    motion from its law (:func:`_stage_tolerances`, key: the stage name [arcmin]). Yield against
    ``[analyses.yield.spec]`` (``"joint_lost_motion [arcmin]"``, ``"<slug>.lost_motion
    [arcmin]"``, ``"end_effector_error [mm]"``), contributions per tolerance.
    """
    from gearte.studies._yield import yield_analysis

    sec = case.analyses.yield_ if case.analyses is not None else None
    assert sec is not None
    own = _own_tolerances(case)
    model, chain, units, nominal, defaults, grade_um, families = _yield_setup(
        case, sec, own, _stage_tolerances(case, stages, drives, backlash)
    )

    radial = {k for s in chain if s.name in own for k in own[s.name].radial}

    def worst_case(errors) -> dict:
        """This chain with every drawn error held constant at the sample's value (a radial
        error as its projection r sin φ): ``gearte run`` on it gives that sample's outputs."""
        import math

        d = case.model_dump(mode="json", by_alias=True, exclude_none=True)
        for st, sd in zip(case.chain.stages, d["chain"]["stages"], strict=True):
            if st.drive is not None and st.drive.case is not None:
                sd["drive"]["case"] = st.drive.source  # absolute: the file moves
        tols = {}
        for key, unit in units.items():
            v = float(errors.get(key, nominal.get(key, 0.0)))
            if key in radial and f"{key}_phase_rad" in errors:
                v *= math.sin(float(errors[f"{key}_phase_rad"]))
            tols[key] = {"kind": "constant", f"tolerance_{unit}": 0.0, f"nominal_{unit}": v}
        d["analyses"] = {
            "yield": {
                "samples": 1,
                "keep_worst": 0,
                "tolerances": tols,
                "spec": d["analyses"]["yield"].get("spec", {}),
            }
        }
        return d

    res = yield_analysis(
        sec,
        model,
        units,
        nominal,
        options=options,
        worst_case=worst_case,
        references=["jiang2024"],
        defaults=defaults,
        families=families,
        grade_um=grade_um,
    )
    res.notes.append(
        "Chain yield: a pair stage draws its backlash stack contributor by contributor "
        "(eccentricities and run-out: Rayleigh magnitude, σx = t/6 as Jiang 2024, uniform "
        "direction, entering as r sin φ) → eq. (14)/(29), clipped at 0; other stages' lost "
        "motion from their law (drive spread, min/mean/max, or constant); joint = Σ stage lost "
        "motion / downstream ratios (eq. 30), sample by sample."
    )
    for st in case.chain.stages:
        if st.drive is not None and st.name in own and st.drive.kind != "gear_pair":
            res.notes.append(
                f"{st.name}: its {st.drive.kind} drive draws its own tolerances (keys "
                f"{_slug(st.name)}.<error>, its family's laws) → its lost motion by its family's "
                "model (gearte.families), sample by sample."
            )
    return res


def run(case: Case, options) -> StudyResult:
    """Run a ``gear_chain`` case: each stage's lost motion, the joint and end-effector error,
    shim and motor compensation; no I/O, no plotting.

    Parameters
    ----------
    case : Case
        The validated case.
    options : RunOptions
        Execution options (workers, scheduler, progress); the runner passes them.

    Returns
    -------
    StudyResult
        The analyses and warnings.
    """
    conf = case.analysis.confidence
    analyses: list[AnalysisResult] = []
    warnings: list[str] = []
    stages: list[StageLostMotion] = []
    backlash: dict[str, tuple] = {}

    # -- stages ----------------------------------------------------------------------------------
    stiffness: dict[str, float | None] = {}
    drives: dict[str, object] = {}
    for st in case.chain.stages:
        slug = _slug(st.name)
        stiffness[st.name] = None
        if st.drive is not None:
            drive = st.drive.build(st.name)
            drives[st.name] = drive
            stage, result = _drive_stage(st, drive, conf)
            stages.append(stage)
            stiffness[st.name] = drive.torsional_stiffness()
            analyses.append(result)
            continue
        if st.lost_motion_max_arcmin is not None:
            mx, mean, mn = _given_lost_motion(st)
            stages.append(StageLostMotion(st.name, st.ratio, mx, mean, mn, st.compensate))
            analyses.append(
                AnalysisResult(
                    name=f"{slug}_lost_motion",
                    title=f"{st.name}: return error (given)",
                    values={
                        "ratio": st.ratio,
                        "lost_motion_max [arcmin]": st.lost_motion_max_arcmin,
                        "lost_motion_mean [arcmin]": st.lost_motion_mean_arcmin,
                        "lost_motion_min [arcmin]": st.lost_motion_min_arcmin,
                    },
                    references=["jiang2024"],
                    notes=["Return error given in the case (e.g. the reducer maker's data)."],
                )
            )
            continue
        trio, d, alpha, pair = _stage_backlash_mm(st, conf)
        backlash[st.name] = (trio, d, alpha, pair)
        if pair is not None:
            stiffness[st.name] = _pair_drive(st, pair).torsional_stiffness()
        lo, mean, mx = _lost(trio, d, alpha, st.name, warnings)
        stages.append(StageLostMotion(st.name, st.ratio, mx, mean, lo, st.compensate))
        if pair is not None:
            assert st.pair is not None
            analyses += analyse_pair(
                st.pair, case.analysis, options, prefix=f"{slug}_", title_prefix=f"{st.name}: "
            )
        else:
            analyses.append(
                AnalysisResult(
                    name=f"{slug}_backlash",
                    title=f"{st.name}: normal backlash (given) and lost motion",
                    values={
                        "ratio": st.ratio,
                        "output_diameter [mm]": d,
                        "backlash_mean [um]": st.backlash_mean_um,
                        "backlash_min [um]": st.backlash_min_um,
                        "backlash_max [um]": st.backlash_max_um,
                        "lost_motion_mean [arcmin]": float(rad_to_arcmin(mean)),
                        "lost_motion_min [arcmin]": float(rad_to_arcmin(lo)),
                        "lost_motion_max [arcmin]": float(rad_to_arcmin(mx)),
                        "lost_motion_mean_dms": format_dms(mean),
                        "lost_motion_min_dms": format_dms(lo),
                        "lost_motion_max_dms": format_dms(mx),
                        # the case's limit (0: none), so that the report checks against it
                        **(
                            {"min_backlash_limit [um]": st.min_backlash_limit_um}
                            if st.min_backlash_limit_um > 0
                            else {}
                        ),
                    },
                    references=["jiang2024"],
                    notes=[
                        "Backlash values given in the case (measured or simulated elsewhere); "
                        "lost motion by eq. (14)/(29)."
                    ],
                )
            )

    # -- chain (eqs. 30, 31) ---------------------------------------------------------------------
    L = case.chain.lever_length_mm
    before = analyse_chain(stages, L)

    def chain_values(res) -> dict[str, float]:
        """Each stage's maximum return error referred to the joint [arcmin]."""
        return {
            s.name: float(rad_to_arcmin(s.max * f))
            for s, f in zip(res.stages, res.transfer, strict=True)
        }

    analyses.append(
        AnalysisResult(
            name="chain",
            title="Lost motion of the chain at the joint and the end effector (eqs. 30-31)",
            values={
                "joint_lost_motion_max [arcmin]": float(rad_to_arcmin(before.joint_max)),
                "joint_lost_motion_max_dms": format_dms(before.joint_max),
                "joint_lost_motion_mean [arcmin]": (
                    None if before.joint_mean is None else float(rad_to_arcmin(before.joint_mean))
                ),
                "end_effector_error_max [mm]": before.end_effector_max,
                "lever_length [mm]": L,
                "stage_ratio": {s.name: s.ratio for s in stages},
                "stage_lost_motion_max [arcmin]": {
                    s.name: float(rad_to_arcmin(s.max)) for s in stages
                },
                "stage_at_joint_max [arcmin]": chain_values(before),
                "stage_share [%]": {k: 100 * v for k, v in before.shares().items()},
                "joint_lost_motion_statistical_max [arcmin]": float(
                    rad_to_arcmin(_statistical_joint_max(before, conf))
                ),
                **_joint_stiffness_values(stages, stiffness),
            },
            references=["jiang2024"],
            notes=[
                "Worst case: each stage at its maximum return error, referred to the joint by "
                "the downstream ratios (eq. 30); end error = joint error × lever length (eq. 31).",
                "joint_lost_motion_statistical_max: not in the paper. Stages with a min and a max "
                "taken as independent normals with σ = (max − min)/(2z) about their mean; stages "
                "with only a maximum held at it; mean + z·σ at the same confidence.",
                "joint_torsional_stiffness: not in the paper. The stages' output stiffnesses in "
                "series, each referred to the joint by the square of the downstream ratios, "
                "1/K = Σ 1/(K_k Π_(j>k) i_j²); given only when every stage's model has a "
                "stiffness (stage_torsional_stiffness lists them, null where a model has none).",
            ],
            data={"chain": before},
        )
    )

    if case.chain.te_positions is not None:
        analyses.append(_chain_te(case, drives))
    if case.analyses is not None and case.analyses.yield_ is not None:
        analyses.append(_chain_yield(case, stages, drives, backlash, options))

    # -- shim (eq. 32) ---------------------------------------------------------------------------
    comp_stages = stages
    if case.shim is not None:
        sh = case.shim
        trio, d, alpha, pair = backlash[sh.stage]
        if isinstance(pair, BevelPair):
            sens = pair.shim_sensitivity()
            limit = pair.min_backlash_limit
        else:
            d1, d2 = deg_to_rad(sh.cone_angle_driving_deg), deg_to_rad(sh.cone_angle_driven_deg)
            sens = 2 * math.sin(alpha) * (math.sin(d1) + math.sin(d2))
            limit = float(
                um_to_mm(
                    next(s for s in case.chain.stages if s.name == sh.stage).min_backlash_limit_um
                )
            )
        target = float(um_to_mm(sh.target_min_backlash_um))
        start = (
            trio[0] if sh.current_min_backlash_um is None else um_to_mm(sh.current_min_backlash_um)
        )
        exact = shim_thickness(start, target, alpha, shim_sensitivity=sens, min_limit=limit)
        thick = _round_shim(exact, sh.rounding_mm, sh.rounding)
        red = float(shim_backlash_reduction(thick, alpha, sens))
        after = tuple(j - red for j in trio)
        if after[0] < limit:
            warnings.append(
                f"after the {thick:.4g} mm shim the minimum backlash {mm_to_um(after[0]):.1f} µm "
                f"of {sh.stage!r} is below its minimum limit {mm_to_um(limit):.1f} µm"
            )
        if sh.verified_backlash_min_um is not None:
            assert sh.verified_backlash_max_um is not None
            vmin, vmax = sh.verified_backlash_min_um, sh.verified_backlash_max_um
            vmean = sh.verified_backlash_mean_um
            if vmean is None:
                vmean = 0.5 * (vmin + vmax)
            used = tuple(float(um_to_mm(v)) for v in (vmin, vmean, vmax))
            source = "verified range given in the case"
        else:
            used = after
            source = "gearte's backlash shifted by the shim"
        lo, mean, mx = _lost(used, d, alpha, f"{sh.stage} after shim", warnings)
        k = next(i for i, s in enumerate(stages) if s.name == sh.stage)
        old = stages[k]
        shim_stages = list(stages)
        shim_stages[k] = StageLostMotion(old.name, old.ratio, mx, mean, lo, old.compensate)
        res_shim = analyse_chain(shim_stages, L)
        comp_stages = shim_stages
        vals = {
            "stage": sh.stage,
            "shim_thickness [mm]": thick,
            "shim_thickness_exact [mm]": exact,
            "shims": 2,
            "backlash_reduction [um]": float(mm_to_um(red)),
            "backlash_before_min [um]": float(mm_to_um(trio[0])),
            "backlash_before_mean [um]": float(mm_to_um(trio[1])),
            "backlash_before_max [um]": float(mm_to_um(trio[2])),
            "target_min_backlash [um]": sh.target_min_backlash_um,
            "shim_start_min_backlash [um]": float(mm_to_um(start)),
            "backlash_after_shim_min [um]": float(mm_to_um(after[0])),
            "backlash_after_shim_mean [um]": float(mm_to_um(after[1])),
            "backlash_after_shim_max [um]": float(mm_to_um(after[2])),
            "lost_motion_source": source,
            "lost_motion_after_shim_mean [arcmin]": float(rad_to_arcmin(mean)),
            "lost_motion_after_shim_max [arcmin]": float(rad_to_arcmin(mx)),
            "lost_motion_after_shim_mean_dms": format_dms(mean),
            "lost_motion_after_shim_max_dms": format_dms(mx),
            "joint_lost_motion_max_after_shim [arcmin]": float(rad_to_arcmin(res_shim.joint_max)),
            "joint_lost_motion_max_after_shim_dms": format_dms(res_shim.joint_max),
            "end_effector_error_after_shim [mm]": res_shim.end_effector_max,
            "stage_at_joint_max_after_shim [arcmin]": chain_values(res_shim),
        }
        if sh.verified_backlash_min_um is not None:
            vals["verified_backlash_after_shim_min [um]"] = mm_to_um(used[0])
            vals["verified_backlash_after_shim_mean [um]"] = mm_to_um(used[1])
            vals["verified_backlash_after_shim_max [um]"] = mm_to_um(used[2])
        analyses.append(
            AnalysisResult(
                name="shim",
                title=f"Shims under both gears of {sh.stage!r} (eq. 32)",
                values=vals,
                references=["jiang2024"],
                notes=[
                    f"Δjn = {mm_to_um(start):.4g} µm (minimum) − target; "
                    f"ΔP = Δjn / (2 sin α (sin δ1 + sin δ2)) = {exact:.5f} mm, "
                    f"rounded ({sh.rounding}) to the {sh.rounding_mm:g} mm stock: {thick:.4g} mm. "
                    "Shimming shifts the whole backlash distribution by the reduction.",
                    f"Lost motion after the shim from the {source}.",
                ],
                data={"chain": res_shim},
            )
        )

    # -- motor-angle compensation (eq. 33) -------------------------------------------------------
    if case.compensation is not None and case.compensation.enabled:
        res = analyse_chain(comp_stages, L)
        if not any(s.compensate for s in comp_stages):
            warnings.append("compensation enabled but no stage has compensate = true")
        table = compensation_table(res)
        analyses.append(
            AnalysisResult(
                name="compensation",
                title="Motor-angle compensation when the load torque reverses (eq. 33)",
                values={
                    "motor_compensation_angle [deg]": float(rad_to_deg(res.motor_compensation)),
                    "compensated_stages": [s.name for s in comp_stages if s.compensate],
                    "residual_lost_motion_max [arcmin]": {
                        s.name: float(rad_to_arcmin(r))
                        for s, r in zip(comp_stages, res.residuals, strict=True)
                    },
                    "residual_lost_motion_max_dms": {
                        s.name: format_dms(r)
                        for s, r in zip(comp_stages, res.residuals, strict=True)
                    },
                    "stage_at_joint_residual [arcmin]": {
                        s.name: float(rad_to_arcmin(r * f))
                        for s, r, f in zip(comp_stages, res.residuals, res.transfer, strict=True)
                    },
                    "joint_lost_motion_max_after_compensation [arcmin]": float(
                        rad_to_arcmin(res.joint_max_after)
                    ),
                    "joint_lost_motion_max_after_compensation_dms": format_dms(res.joint_max_after),
                    "end_effector_error_after_compensation [mm]": res.end_effector_max_after,
                    "compensation_table": table,
                    "compensation_table_csv": compensation_table_csv(table),
                },
                references=["jiang2024"],
                notes=[
                    "Δφc = Σ (Π i up to the stage) · Δφm over the compensated stages, applied at "
                    "the motor when the load torque reverses; a compensated stage keeps "
                    "max(Δφmax − Δφm, Δφm − Δφmin), the others their Δφmax."
                    + (" Acts on the chain after the shim." if case.shim is not None else ""),
                ],
                data={"chain": res},
                files={
                    "compensation.csv": compensation_table_csv(table),
                    "compensation.json": compensation_table_json(table),
                },
            )
        )
    return StudyResult(case=case, analyses=analyses, warnings=warnings)
