"""Study kind ``gear_pair``: normal backlash and lost motion of one spur or bevel pair.

From gear data and tolerances (Jiang et al. 2024, Tables 1–2 and 5–6): the analytic stack
(mean, sd, min/max at a confidence level, worst case, RSS, whether the minimum stays above the
required minimum backlash), a Monte-Carlo check of it, the contribution of each tolerance
(variance shares, optionally first-order Sobol indices), and the return error of the pair at
its output gear (eqs. 14/29).

Analyses and result names (``results.json``):

* ``backlash``: ``backlash_mean [um]``, ``backlash_sd [um]``, ``backlash_min [um]``,
  ``backlash_max [um]`` (at ``analysis.confidence``, default 99.73 %), ``lost_motion_mean
  [arcmin]``, ``lost_motion_min [arcmin]``, ``lost_motion_max [arcmin]``, worst case, RSS, ...
* ``monte_carlo``: sampled statistics, percentiles, out-of-spec fraction, Cpk.
* ``contributions``: variance share of each tolerance [%] (and Sobol indices if asked).

The pair sections are shared with the ``gear_chain`` kind (a chain stage can hold a pair).
"""

from __future__ import annotations

import math
from typing import Annotated, Literal

from pydantic import Field, field_validator, model_validator

from gearte.errors import ParameterError
from gearte.io.schema import CaseBase, StrictModel, floored
from gearte.models.backlash import (
    BEVEL_SOURCES,
    SPUR_SOURCES,
    BevelGear,
    BevelPair,
    SpurGear,
    SpurPair,
    summarise_backlash,
)
from gearte.models.lost_motion import return_error
from gearte.results import AnalysisResult, StudyResult
from gearte.units import deg_to_rad, format_dms, mm_to_um, rad_to_arcmin, um_to_mm

__all__ = [
    "KIND",
    "REFERENCES",
    "FIGURES",
    "SpurGearSpec",
    "SpurPairSpec",
    "BevelGearSpec",
    "BevelPairSpec",
    "PairSpec",
    "DistributionSpec",
    "PairAnalysisSpec",
    "Case",
    "run",
    "analyse_pair",
]

KIND = "gear_pair"
REFERENCES = ["jiang2024"]
FIGURES = "gearte.plotting.gear_chain"

_UM = Field(ge=0, le=10_000)


def thickness_class_key(v: str | None) -> str | None:
    """A case key's DIN 3967 class, normalised (``"25 CD"`` → ``"cd25"``); None stays None.

    For a pydantic validator: a bad class is a ``ValueError`` with the reason (the location
    names the key)."""
    if v is None:
        return None
    from gearte.tolerance.din3967 import parse_thickness_class

    try:
        series, tol = parse_thickness_class(v)
    except ParameterError as exc:
        raise ValueError(exc.reason) from None
    return f"{series}{tol}"


def js_field_key(v: str | None) -> str | None:
    """A case key's ISO 286 js field, normalised (``"JS 7"`` → ``"js7"``); None stays None."""
    if v is None:
        return None
    from gearte.tolerance.iso286 import parse_js_field

    try:
        return f"js{parse_js_field(v)}"
    except ParameterError as exc:
        raise ValueError(f"{v!r} {exc.reason}") from None


class _ThicknessLimits(StrictModel):
    thickness_upper_um: float = Field(
        ge=-10_000, le=10_000, description="Upper tooth-thickness deviation Ess [µm]."
    )
    thickness_lower_um: float = Field(
        ge=-10_000, le=10_000, description="Lower tooth-thickness deviation Esi [µm], <= Ess."
    )

    @model_validator(mode="after")
    def _ordered(self):
        if self.thickness_lower_um > self.thickness_upper_um:
            raise ValueError(
                f"inverted limits: thickness_lower_um = {self.thickness_lower_um} must be <= "
                f"thickness_upper_um = {self.thickness_upper_um}"
            )
        return self


class SpurGearSpec(StrictModel):
    """One spur gear: teeth, tooth-thickness deviations (or class), radial composite tolerance."""

    teeth: int = Field(ge=5, le=10_000, description="Number of teeth z.")
    thickness_upper_um: float | None = Field(
        default=None,
        ge=-10_000,
        le=10_000,
        description="Upper tooth-thickness deviation Ess [µm]. Or give tooth_thickness_allowance.",
    )
    thickness_lower_um: float | None = Field(
        default=None,
        ge=-10_000,
        le=10_000,
        description="Lower tooth-thickness deviation Esi [µm], <= Ess.",
    )
    tooth_thickness_allowance: str | None = Field(
        default=None,
        description="DIN 3967 tooth-thickness class instead of thickness_upper_um and "
        "thickness_lower_um, e.g. 'cd25': allowance series a … h (upper allowance A_sne, "
        "Table 1) and tolerance series 21 … 30 (T_sn, Table 2) at d = m·z; Ess = A_sne, "
        "Esi = A_sne − T_sn (gearte.tolerance.din3967).",
    )
    radial_composite_tol_um: float | None = Field(
        default=None,
        gt=0,
        le=10_000,
        description="Radial composite tolerance F''i [µm]; Rayleigh σx = F''i/6. Or give grade.",
    )
    grade: int | None = Field(
        default=None,
        ge=4,
        le=11,
        description="Accuracy grade instead of radial_composite_tol_um: F''i from ISO 1328-2 "
        "(1997 formulas) at the pair's module and d = m·z (gearte.tolerance.iso1328).",
    )

    @field_validator("tooth_thickness_allowance")
    @classmethod
    def _thickness_class(cls, v: str | None) -> str | None:
        return thickness_class_key(v)

    @model_validator(mode="after")
    def _one_source(self) -> SpurGearSpec:
        if (self.radial_composite_tol_um is None) == (self.grade is None):
            raise ValueError("give exactly one of radial_composite_tol_um and grade")
        raw = (self.thickness_upper_um, self.thickness_lower_um)
        if self.tooth_thickness_allowance is not None:
            if any(v is not None for v in raw):
                raise ValueError(
                    "give either tooth_thickness_allowance or thickness_upper_um and "
                    "thickness_lower_um, not both"
                )
        elif None in raw:
            raise ValueError(
                "give thickness_upper_um and thickness_lower_um (both), or "
                "tooth_thickness_allowance (a DIN 3967 class such as 'cd25')"
            )
        elif raw[1] > raw[0]:  # type: ignore[operator]
            raise ValueError(
                f"inverted limits: thickness_lower_um = {raw[1]} must be <= "
                f"thickness_upper_um = {raw[0]}"
            )
        return self

    def thickness_limits_um(self, module_mm: float, field: str = "") -> tuple[float, float]:
        """(Ess, Esi) [µm]: as given, or from the DIN 3967 class at ``d = m·z``."""
        if self.tooth_thickness_allowance is None:
            return float(self.thickness_upper_um), float(self.thickness_lower_um)  # type: ignore[arg-type]
        from gearte.tolerance.din3967 import tooth_thickness_allowances

        t = tooth_thickness_allowances(
            self.tooth_thickness_allowance,
            module_mm * self.teeth,
            field=f"{field}tooth_thickness_allowance",
        )
        return t.upper_um, t.lower_um

    def radial_composite_um(self, module_mm: float) -> float:
        """F''i [µm]: as given, or from the grade (ISO 1328-2:1997, rounded)."""
        if self.radial_composite_tol_um is not None:
            return float(self.radial_composite_tol_um)
        from gearte.tolerance.iso1328 import radial_composite_tolerances

        assert self.grade is not None  # one of the two is given (validated)
        return radial_composite_tolerances(self.grade, module_mm, module_mm * self.teeth).F_i2


class _Clearance(StrictModel):
    bearing_clearance_min_um: float = Field(
        ge=0, le=10_000, description="Minimum bearing radial clearance bmin [µm], >= 0."
    )
    bearing_clearance_max_um: float = Field(
        ge=0, le=10_000, description="Maximum bearing radial clearance bmax [µm], >= bmin."
    )

    @model_validator(mode="after")
    def _ordered_clearance(self):
        if self.bearing_clearance_min_um > self.bearing_clearance_max_um:
            raise ValueError(
                f"inverted limits: bearing_clearance_min_um = {self.bearing_clearance_min_um} must"
                f" be <= bearing_clearance_max_um = {self.bearing_clearance_max_um}"
            )
        return self


class DistributionSpec(StrictModel):
    """Replaces the paper's distribution of one source (values of the source itself, in µm).

    ``normal``: between ``lower_um`` and ``upper_um`` with σ = range/6; ``truncated_normal``: the
    same, cut at the limits (parts outside scrapped); ``uniform``: on [lower_um, upper_um];
    ``rayleigh``: scale ``scale_um`` (eccentricities: the magnitude; the phase stays uniform);
    ``empirical``: ``values_um`` measured on real parts (resampled). For an eccentricity or a
    runout the distribution is that of the magnitude ``e ≥ 0``.
    """

    kind: Literal["normal", "truncated_normal", "uniform", "rayleigh", "empirical"] = Field(
        description="Law of the source: normal (σ = range/6), truncated_normal, uniform, rayleigh "
        "(a magnitude) or empirical (values_um resampled)."
    )
    lower_um: float | None = Field(
        default=None,
        ge=-100_000,
        le=100_000,
        description="Lower limit of the source [µm] (normal, truncated_normal, uniform).",
    )
    upper_um: float | None = Field(
        default=None,
        ge=-100_000,
        le=100_000,
        description="Upper limit of the source [µm] (normal, truncated_normal, uniform).",
    )
    scale_um: float | None = Field(
        default=None, gt=0, le=100_000, description="Rayleigh scale σ of the magnitude [µm]."
    )
    values_um: list[float] | None = Field(
        default=None,
        min_length=2,
        max_length=10_000_000,
        description="empirical: values measured on real parts [µm], resampled.",
    )

    @model_validator(mode="after")
    def _fields_of_kind(self):
        if self.kind in ("normal", "truncated_normal", "uniform"):
            if self.lower_um is None or self.upper_um is None:
                raise ValueError(f"kind = {self.kind!r} needs lower_um and upper_um")
            if self.lower_um > self.upper_um or (
                self.kind != "normal" and self.lower_um == self.upper_um
            ):
                raise ValueError(
                    f"inverted limits: lower_um = {self.lower_um} must be < upper_um = "
                    f"{self.upper_um}"
                )
        if self.kind == "rayleigh" and self.scale_um is None:
            raise ValueError("kind = 'rayleigh' needs scale_um > 0")
        if self.kind == "empirical" and self.values_um is None:
            raise ValueError("kind = 'empirical' needs values_um (at least 2 measurements)")
        return self

    def build(self):
        from gearte.tolerance.distributions import (
            Empirical,
            Normal,
            Rayleigh,
            Truncated,
            Uniform,
        )

        mm = 1e-3
        if self.kind == "normal":
            return Normal.from_limits(self.lower_um * mm, self.upper_um * mm)  # type: ignore[operator]
        if self.kind == "truncated_normal":
            lo, hi = self.lower_um * mm, self.upper_um * mm  # type: ignore[operator]
            return Truncated(Normal.from_limits(lo, hi), lo, hi)
        if self.kind == "uniform":
            return Uniform(self.lower_um * mm, self.upper_um * mm)  # type: ignore[operator]
        if self.kind == "rayleigh":
            return Rayleigh(self.scale_um * mm)  # type: ignore[operator]
        return Empirical([v * mm for v in self.values_um])  # type: ignore[union-attr]


class _Distributions(StrictModel):
    distributions: dict[str, DistributionSpec] = Field(
        default_factory=dict,
        description="Per-source distribution replacing the paper's (keys: source names).",
    )

    def backlash_stack(self):
        """The pair's normal-backlash stack [mm] with the distribution overrides applied."""
        from gearte.tolerance.distributions import RadialPhase
        from gearte.tolerance.stackup import Contributor, LinearStack

        base = self.build().backlash_stack()  # type: ignore[attr-defined]
        if not self.distributions:
            return base
        cs = []
        for c in base.contributors:
            spec = self.distributions.get(c.name)
            if spec is None:
                cs.append(c)
                continue
            d = spec.build()
            if isinstance(c.distribution, RadialPhase):
                d = RadialPhase(d)
            cs.append(Contributor(c.name, d, c.sensitivity, c.group))
        return LinearStack(cs, base.constant, name=base.name, unit=base.unit)

    @model_validator(mode="after")
    def _known_sources(self):
        known = SPUR_SOURCES if getattr(self, "type", "") == "spur" else BEVEL_SOURCES
        unknown = sorted(set(self.distributions) - set(known))
        if unknown:
            raise ValueError(
                f"distributions: unknown source(s) {unknown}; sources of this pair: {list(known)}"
            )
        return self

    @model_validator(mode="after")
    def _assemblable(self):
        """Refuse a pair whose mean normal backlash is negative: most pairs of the lot jam."""
        from gearte.units import mm_to_um

        stack = self.backlash_stack()
        if stack.mean < 0:
            lo, hi = (float(mm_to_um(v)) for v in stack.worst_case())
            raise ValueError(
                f"the pair cannot be assembled: mean normal backlash "
                f"{float(mm_to_um(stack.mean)):.1f} µm < 0 (worst case {lo:.1f} to {hi:.1f} µm); "
                "the tooth-thickness deviations leave no clearance (make them more negative)"
            )
        return self


class SpurPairSpec(_Clearance, _Distributions):
    """A spur pair and its mounting (Jiang et al. 2024, Tables 1–2)."""

    type: Literal["spur"] = Field("spur", description="Pair type: a spur pair.")
    module_mm: float = Field(
        ge=0.05, le=100, description="Module m [mm] (0.05 mm: the finest instrument gears)."
    )
    pressure_angle_deg: float = Field(default=20.0, gt=0, lt=45, description="Pressure angle α.")
    centre_distance_tol_um: float | None = Field(
        default=None,
        ge=0,
        le=10_000,
        description="Centre-distance limit deviation fa [µm] (±fa). Or give "
        "centre_distance_allowance.",
    )
    centre_distance_allowance: str | None = Field(
        default=None,
        description="ISO 286 field of the centre distance a = m(z1 + z2)/2 instead of "
        "centre_distance_tol_um (DIN 3964), js5 … js11: fa = IT/2 (gearte.tolerance.iso286).",
    )
    runout_um: float = Field(
        gt=0, le=10_000, description="Runout S of the shaft carrying the driving gear [µm]."
    )
    min_backlash_limit_um: float = Field(
        default=0.0, ge=0, le=10_000, description="Minimum limit normal backlash [µm]."
    )
    face_width_mm: float | None = floored(
        "part_length",
        None,
        le=1000,
        description="Face width b [mm]; only for the pair's mesh stiffness as a drive (optional).",
    )
    driving: SpurGearSpec
    driven: SpurGearSpec

    @field_validator("centre_distance_allowance")
    @classmethod
    def _js_field(cls, v: str | None) -> str | None:
        return js_field_key(v)

    @model_validator(mode="after")
    def _one_centre_distance(self) -> SpurPairSpec:
        if (self.centre_distance_tol_um is None) == (self.centre_distance_allowance is None):
            raise ValueError(
                "give exactly one of centre_distance_tol_um and centre_distance_allowance"
            )
        return self

    @model_validator(mode="after")
    def _grades_in_range(self) -> SpurPairSpec:
        for name, g in (("driving", self.driving), ("driven", self.driven)):
            g.radial_composite_um(self.module_mm)  # ParameterError naming the field if outside
            g.thickness_limits_um(self.module_mm, field=f"{name}.")
        self.centre_distance_fa_um()
        return self

    @property
    def centre_distance_mm(self) -> float:
        """Standard centre distance ``a = m(z1 + z2)/2`` [mm]."""
        return 0.5 * self.module_mm * (self.driving.teeth + self.driven.teeth)

    def centre_distance_fa_um(self) -> float:
        """fa [µm]: as given, or IT/2 of the js field at the standard centre distance."""
        if (self.centre_distance_tol_um is None) == (self.centre_distance_allowance is None):
            raise ValueError(
                "give exactly one of centre_distance_tol_um and centre_distance_allowance"
            )
        if self.centre_distance_allowance is None:
            return float(self.centre_distance_tol_um)  # type: ignore[arg-type]
        from gearte.tolerance.iso286 import js_allowances_um

        return js_allowances_um(
            self.centre_distance_allowance, self.centre_distance_mm, "centre_distance_allowance"
        )[0]

    def allowance_backlash_um(self) -> dict[str, float]:
        """Backlash limits of the tooth-thickness and centre-distance allowances alone [µm]
        (``gearte.tolerance.din3967.pair_backlash_limits`` at the pressure angle)."""
        from gearte.tolerance.din3967 import pair_backlash_limits

        (u1, l1), (u2, l2) = (
            self.driving.thickness_limits_um(self.module_mm),
            self.driven.thickness_limits_um(self.module_mm),
        )
        fa = self.centre_distance_fa_um()
        u1, l1, u2, l2, a_e, a_i = (float(um_to_mm(v)) for v in (u1, l1, u2, l2, fa, -fa))
        b = pair_backlash_limits(
            u1, l1, u2, l2, a_e, a_i, float(deg_to_rad(self.pressure_angle_deg))
        )
        names = ("normal_min", "normal_max", "circumferential_min", "circumferential_max")
        return {
            f"allowance_backlash_{n} [um]": float(mm_to_um(float(getattr(b, n)))) for n in names
        }

    def build(self) -> SpurPair:
        def gear(g: SpurGearSpec) -> SpurGear:
            upper, lower = g.thickness_limits_um(
                self.module_mm, field="driving." if g is self.driving else "driven."
            )
            return SpurGear(
                g.teeth,
                float(um_to_mm(upper)),
                float(um_to_mm(lower)),
                float(um_to_mm(g.radial_composite_um(self.module_mm))),
            )

        return SpurPair(
            gear(self.driving),
            gear(self.driven),
            self.module_mm,
            float(deg_to_rad(self.pressure_angle_deg)),
            float(um_to_mm(self.centre_distance_fa_um())),
            (
                float(um_to_mm(self.bearing_clearance_min_um)),
                float(um_to_mm(self.bearing_clearance_max_um)),
            ),
            float(um_to_mm(self.runout_um)),
            float(um_to_mm(self.min_backlash_limit_um)),
        )


class _NoBevelGrade(StrictModel):
    """``grade`` on a bevel gear or pair: an error naming the key and saying why (not the
    unknown-key error, whose "did you mean" pointed at the spur gear's field)."""

    grade: None = Field(
        default=None,
        description="Not accepted: bevel gears take no accuracy grade (ISO 1328-1 is for "
        "cylindrical gears; ISO 17485, the bevel standard, is not implemented). Give the "
        "tolerances in µm.",
    )

    @field_validator("grade", mode="before")
    @classmethod
    def _no_grade(cls, v):
        if v is None:  # the default (TOML has no null: a file never gives None)
            return v
        from gearte.tolerance.iso1328 import BEVEL_GRADE_REASON

        raise ValueError(BEVEL_GRADE_REASON)


class BevelGearSpec(_NoBevelGrade, _ThicknessLimits, _Clearance):
    """One bevel gear with its bearing and locating faces."""

    teeth: int = Field(ge=5, le=10_000, description="Number of teeth z.")
    face_profile_tol_um: float = Field(
        ge=0, le=10_000, description="Profile tolerance P of the gear's locating face [µm]."
    )
    seat_profile_tol_um: float = Field(
        ge=0,
        le=10_000,
        description="Profile tolerance P of the housing face locating the gear [µm].",
    )


class BevelPairSpec(_NoBevelGrade, _Distributions):
    """A straight bevel pair and its mounting (Jiang et al. 2024, Tables 5–6)."""

    type: Literal["bevel"] = Field("bevel", description="Pair type: a bevel pair.")
    module_mm: float = Field(
        ge=0.05, le=100, description="Outer transverse module m [mm] (0.05 mm: the finest gears)."
    )
    pressure_angle_deg: float = Field(default=20.0, gt=0, lt=45, description="Pressure angle α.")
    face_width_mm: float = floored("part_length", ..., le=1000, description="Face width B [mm].")
    shaft_angle_deg: float = Field(default=90.0, gt=0, lt=180, description="Shaft angle Σ.")
    shaft_distance_tol_um: float = Field(
        ge=0, le=10_000, description="Shaft-distance limit deviation fa [µm] (±fa)."
    )
    shaft_angle_tol_um: float = Field(
        ge=0, le=10_000, description="Shaft-angle limit deviation EΣ (arc at mean cone) [µm]."
    )
    composite_tol_um: float = Field(
        gt=0, le=10_000, description="Shaft-angle composite deviation F''iΣ [µm]; σx = √2F''iΣ/6."
    )
    min_backlash_limit_um: float = Field(
        default=0.0, ge=0, le=10_000, description="Minimum limit normal backlash j''n min [µm]."
    )
    driving: BevelGearSpec
    driven: BevelGearSpec

    def build(self) -> BevelPair:
        def gear(g: BevelGearSpec) -> BevelGear:
            return BevelGear(
                g.teeth,
                float(um_to_mm(g.thickness_upper_um)),
                float(um_to_mm(g.thickness_lower_um)),
                (
                    float(um_to_mm(g.bearing_clearance_min_um)),
                    float(um_to_mm(g.bearing_clearance_max_um)),
                ),
                float(um_to_mm(g.face_profile_tol_um)),
                float(um_to_mm(g.seat_profile_tol_um)),
            )

        return BevelPair(
            gear(self.driving),
            gear(self.driven),
            self.module_mm,
            float(deg_to_rad(self.pressure_angle_deg)),
            self.face_width_mm,
            float(um_to_mm(self.shaft_distance_tol_um)),
            float(um_to_mm(self.shaft_angle_tol_um)),
            float(um_to_mm(self.composite_tol_um)),
            float(deg_to_rad(self.shaft_angle_deg)),
            float(um_to_mm(self.min_backlash_limit_um)),
        )


PairSpec = Annotated[SpurPairSpec | BevelPairSpec, Field(discriminator="type")]


#: Fewest base samples of the stack's Sobol estimate (``tolerance.contributions``).
PAIR_SOBOL_MIN_SAMPLES = 100


class PairAnalysisSpec(StrictModel):
    """How to analyse a pair."""

    confidence: float = Field(
        default=0.9973, gt=0.5, lt=1.0, description="Confidence of the min/max range (0.9973: ±3σ)."
    )
    monte_carlo_samples: int = Field(
        default=1_000_000, ge=0, le=10**10, description="Monte-Carlo samples (0: skip)."
    )
    seed: int = Field(default=2024, ge=0, description="Seed of the Monte-Carlo streams.")
    chunk_size: int = Field(
        default=1_000_000,
        ge=1000,
        le=50_000_000,
        description="Monte-Carlo samples per chunk of the execution layer.",
    )
    sobol_samples: int = Field(
        default=0, ge=0, le=10**7, description="Base samples for Sobol indices (0: skip)."
    )
    max_backlash_limit_um: float | None = Field(
        default=None,
        gt=0,
        le=100_000,
        description="Optional upper spec of the normal backlash [µm] (for Cp and out-of-spec).",
    )

    @model_validator(mode="after")
    def _sobol_can_run(self) -> PairAnalysisSpec:
        if 0 < self.sobol_samples < PAIR_SOBOL_MIN_SAMPLES:
            raise ValueError(
                f"sobol_samples = {self.sobol_samples}: Sobol estimation needs 0 (none) or >= "
                f"{PAIR_SOBOL_MIN_SAMPLES} base samples"
            )
        return self


class Case(CaseBase):
    pair: PairSpec
    analysis: PairAnalysisSpec = PairAnalysisSpec()

    @model_validator(mode="after")
    def _spec_limits(self):
        hi = self.analysis.max_backlash_limit_um
        if hi is not None and hi <= self.pair.min_backlash_limit_um:
            raise ValueError(
                f"analysis.max_backlash_limit_um = {hi} must be above "
                f"pair.min_backlash_limit_um = {self.pair.min_backlash_limit_um}"
            )
        return self


def analyse_pair(
    spec: SpurPairSpec | BevelPairSpec,
    analysis: PairAnalysisSpec,
    options,
    *,
    prefix: str = "",
    title_prefix: str = "",
) -> list[AnalysisResult]:
    """Backlash, Monte-Carlo and contribution analyses of one pair (shared with gear_chain).

    Parameters
    ----------
    spec : SpurPairSpec or BevelPairSpec
        The pair and its tolerances.
    analysis : PairAnalysisSpec
        What to compute (confidence, Monte-Carlo samples, seed).
    options : RunOptions
        Execution options (workers, scheduler, progress); the runner passes them.
    prefix : str
        Prefix of the analysis names (a chain's stage).
    title_prefix : str
        Prefix of the analysis titles.

    Returns
    -------
    list of AnalysisResult
        Backlash, Monte-Carlo and contribution analyses.
    """
    from gearte.tolerance.contributions import group_shares, sobol_indices, variance_shares
    from gearte.tolerance.montecarlo import monte_carlo

    pair = spec.build()
    stack = spec.backlash_stack()
    alpha = pair.pressure_angle
    d_out = pair.output_diameter
    summ = summarise_backlash(
        stack, confidence=analysis.confidence, min_limit=pair.min_backlash_limit
    )
    wc = stack.worst_case()
    rss = stack.rss()

    def lm(jn: float) -> float:
        return rad_to_arcmin(float(return_error(jn, d_out, alpha)))

    um = mm_to_um
    kind = "spur" if isinstance(spec, SpurPairSpec) else "bevel"
    values = {
        "pair_type": kind,
        "ratio": pair.ratio,
        "output_diameter [mm]": d_out,
        "backlash_mean [um]": float(um(summ.mean)),
        "backlash_sd [um]": float(um(summ.sd)),
        "backlash_min [um]": float(um(summ.min)),
        "backlash_max [um]": float(um(summ.max)),
        "confidence": analysis.confidence,
        "backlash_worst_case_min [um]": float(um(wc[0])),
        "backlash_worst_case_max [um]": float(um(wc[1])),
        "backlash_rss_min [um]": float(um(rss[0])),
        "backlash_rss_max [um]": float(um(rss[1])),
        "min_backlash_limit [um]": float(um(pair.min_backlash_limit)),
        "meets_min_backlash_limit": bool(summ.meets_min_limit),
        "lost_motion_mean [arcmin]": lm(summ.mean),
        "lost_motion_min [arcmin]": lm(summ.min),
        "lost_motion_max [arcmin]": lm(summ.max),
        "lost_motion_mean_dms": format_dms(float(return_error(summ.mean, d_out, alpha))),
        "lost_motion_max_dms": format_dms(float(return_error(summ.max, d_out, alpha))),
        "backlash_mean_by_source [um]": {
            k: float(um(v)) for k, v in stack.contributor_means().items()
        },
        "backlash_variance_by_source [um2]": {
            k: float(um(um(v))) for k, v in stack.contributor_variances().items()
        },
    }
    notes = [
        "Normal backlash jn; min/max = mean ∓ z·sd at the stated confidence (the paper's 6σ "
        "range at 99.73 %). Lost motion = 2 jn / (d cos α) at the driven gear (eq. 14/29), "
        f"d = {d_out:.4g} mm.",
    ]
    if kind == "bevel":
        d1, d2 = pair.cone_angles  # type: ignore[union-attr]
        notes.append(
            f"Bevel pair through its equivalent cylindrical pair on the back cone; pitch-cone "
            f"angles {math.degrees(d1):.2f}°/{math.degrees(d2):.2f}°; output diameter = mean "
            "diameter dm of the driven gear."
        )
    if isinstance(spec, SpurPairSpec) and (
        spec.centre_distance_allowance is not None
        or spec.driving.tooth_thickness_allowance is not None
        or spec.driven.tooth_thickness_allowance is not None
    ):
        classes = {
            "driving": spec.driving.tooth_thickness_allowance,
            "driven": spec.driven.tooth_thickness_allowance,
            "centre_distance": spec.centre_distance_allowance,
        }
        values["tolerance_classes"] = {k: v for k, v in classes.items() if v is not None}
        values["thickness_limits [um]"] = {
            name: list(g.thickness_limits_um(spec.module_mm))
            for name, g in (("driving", spec.driving), ("driven", spec.driven))
        }
        values["centre_distance_fa [um]"] = spec.centre_distance_fa_um()
        values.update(spec.allowance_backlash_um())
        notes.append(
            "Tooth-thickness classes (DIN 3967 Tables 1-2 at d = m·z) and js fields (ISO 286-1, "
            "fa = IT/2 at a = m(z1 + z2)/2) as given; allowance_backlash_* are the limits of "
            "these allowances alone (j_t = −(A_s1 + A_s2) + 2 A_a tan α, j_n = j_t cos α), "
            "without eccentricity, bearing clearance and run-out (docs/tolerance_grades.md)."
        )
    if not summ.meets_min_limit:
        notes.append("WARNING: the minimum backlash falls below the minimum limit backlash.")
    out = [
        AnalysisResult(
            name=f"{prefix}backlash",
            title=f"{title_prefix}Normal backlash and lost motion ({kind} pair, analytic stack)",
            values=values,
            references=["jiang2024"],
            notes=notes,
            data={"stack": stack, "summary": summ, "pair": pair, "kind": kind},
        )
    ]

    n_mc = (
        options.samples
        if getattr(options, "samples", None) is not None
        else (analysis.monte_carlo_samples)
    )
    seed = options.seed if getattr(options, "seed", None) is not None else analysis.seed
    upper = None
    if analysis.max_backlash_limit_um is not None:
        if analysis.max_backlash_limit_um <= float(mm_to_um(pair.min_backlash_limit)):
            raise ParameterError(
                "analysis.max_backlash_limit_um",
                analysis.max_backlash_limit_um,
                "must be above the pair's min_backlash_limit_um",
            )
        upper = float(um_to_mm(analysis.max_backlash_limit_um))
    if n_mc and n_mc >= 2:
        mc = monte_carlo(
            stack,
            n_mc,
            seed=seed,
            chunk_size=analysis.chunk_size,
            lower_spec=pair.min_backlash_limit if pair.min_backlash_limit > 0 else None,
            upper_spec=upper,
            percentiles=(
                round(50 * (1 - analysis.confidence), 10),
                50.0,
                round(100 - 50 * (1 - analysis.confidence), 10),
            ),
            progress=getattr(options, "progress", False),
            options=options,
        )
        qs = sorted(mc.percentiles)
        mean_err_se = (mc.mean - stack.mean) / mc.std_error
        out.append(
            AnalysisResult(
                name=f"{prefix}monte_carlo",
                title=f"{title_prefix}Monte-Carlo tolerance simulation ({kind} pair)",
                values={
                    "samples": mc.n,
                    "seed": seed,
                    "engine": mc.engine,
                    "mc_backlash_mean [um]": float(um(mc.mean)),
                    "mc_backlash_sd [um]": float(um(mc.sd)),
                    "mc_backlash_sampled_min [um]": float(um(mc.min)),
                    "mc_backlash_sampled_max [um]": float(um(mc.max)),
                    "mc_backlash_low_percentile [um]": float(um(mc.percentiles[qs[0]])),
                    "mc_backlash_median [um]": float(um(mc.percentiles[qs[1]])),
                    "mc_backlash_high_percentile [um]": float(um(mc.percentiles[qs[2]])),
                    "percentile_levels [%]": qs,
                    "fraction_below_min_limit": mc.below_fraction,
                    "cpk": mc.cpk,
                    "fraction_above_max_limit": mc.above_fraction,
                    "out_of_spec_fraction": mc.out_of_spec_fraction,
                    "cp": mc.cp,
                    "mean_difference_in_standard_errors": float(mean_err_se),
                    "sd_relative_difference": float(mc.sd / stack.sd - 1.0),
                },
                references=["jiang2024"],
                notes=[
                    f"{mc.n} samples in chunks of {mc.chunk_size}, seed {seed}; each contributor "
                    "drawn from its own distribution (eccentricities as Rayleigh magnitude × "
                    "uniform phase). Percentiles from a 4000-bin histogram over mean ± 8σ.",
                ],
                data={"mc": mc},
            )
        )

    shares = variance_shares(stack)
    cvals: dict = {
        "variance_share [%]": {k: 100 * v for k, v in shares.items()},
        "variance_share_grouped [%]": {k: 100 * v for k, v in group_shares(shares, stack).items()},
    }
    cnotes = [
        "Variance share sᵢ²σᵢ²/Σ of each tolerance (exact for this linear stack; equals the "
        "first-order Sobol index). See docs/validation/jiang2024.md for how it relates to the "
        "3DCS contributions of the paper's Tables 3 and 7."
    ]
    from gearte.studies import sample_cap

    sobol_n = analysis.sobol_samples and sample_cap(
        analysis, "sobol_samples", options, low=PAIR_SOBOL_MIN_SAMPLES
    )
    if sobol_n:
        sob = sobol_indices(stack, sobol_n, seed=seed)
        cvals["sobol_first_order [%]"] = {k: 100 * v for k, v in sob.first_order.items()}
        cvals["sobol_total [%]"] = {k: 100 * v for k, v in sob.total.items()}
    out.append(
        AnalysisResult(
            name=f"{prefix}contributions",
            title=f"{title_prefix}Contribution of each tolerance ({kind} pair)",
            values=cvals,
            references=["jiang2024"],
            notes=cnotes,
            data={"shares": shares},
        )
    )
    return out


def preflight(case: Case) -> None:
    """The checks :func:`run` makes before any analysis (``gearte validate``,
    :func:`gearte.studies.run_case`): the pair and its backlash stack are built as
    :func:`analyse_pair` builds them (the schema already built them to check the pair can be
    assembled, so this is a second call of the same functions, nothing computed).

    Raises
    ------
    ParameterError
        Naming the key.
    """
    case.pair.build()
    case.pair.backlash_stack()


def run(case: Case, options) -> StudyResult:
    """Run a ``gear_pair`` case (:func:`analyse_pair` on its pair); no I/O, no plotting.

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
    analyses = analyse_pair(case.pair, case.analysis, options)
    warnings = []
    if not analyses[0].values["meets_min_backlash_limit"]:
        warnings.append("minimum backlash below the minimum limit normal backlash")
    return StudyResult(case=case, analyses=analyses, warnings=warnings)
