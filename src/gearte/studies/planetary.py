"""Study kind ``planetary``: eccentricity errors of a 2K-H planetary, coupled output TE, optimal
assembly phases and Monte-Carlo of assembly strategies (Wang et al. 2013).

Case file sections: ``[gearset]`` (teeth, module, pressure angle, planets, members),
``[errors]`` (``source = "derived"`` from kinematics or ``"terms"`` as given, e.g. eq 9; error
magnitudes [µm] and angles [deg]), ``[analyses.coupled_te]``, ``[analyses.assembly]``,
``[analyses.monte_carlo]``.

Results (``results.json``): analysis ``coupled_te`` (``coupled_te_amplitude [arcsec]``,
``coupled_te_peak_to_peak [arcsec]``), ``assembly`` (``optimal_assembly_te [arcsec]``,
``paper_rule_assembly_te [arcsec]``, ``assembly_angles [deg]``), and one analysis per
Monte-Carlo scenario named ``mc_<scenario>`` with ``mc_mean [arcsec]``, ``mc_sd [arcsec]``,
``mc_min [arcsec]``, ``mc_max [arcsec]``.
"""

from __future__ import annotations

import os
from fractions import Fraction
from typing import TYPE_CHECKING, Literal, get_args

import numpy as np
from pydantic import Field, field_validator, model_validator

from gearte.errors import ParameterError
from gearte.geometry.planetary import EccentricityError, PlanetarySet, SunPlanetErrors
from gearte.io.schema import CaseBase, Sign, StrictModel
from gearte.results import AnalysisResult, StudyResult
from gearte.studies._yield import YieldSection
from gearte.units import deg_to_rad, mm_to_um, rad_to_arcsec, rad_to_deg, um_to_mm

if TYPE_CHECKING:
    from gearte.models.planetary_errors import TermSet

# the models (numba kernels) are imported where they are used: importing this module (to read
# a case, or to unpickle its result in the report process) stays free of numba

KIND = "planetary"
REFERENCES = ["wang2013"]
FIGURES = "gearte.plotting.planetary"

Member = Literal["sun", "ring", "carrier"]

#: what each derived angle means, for the assembly instructions
ANGLE_MEANING = {
    "beta_s": "sun: direction of its manufacturing eccentricity (tooth index at assembly)",
    "gamma_s": "sun: direction of its assembly eccentricity (bearing seat turned)",
    "beta_r": "ring: direction of its manufacturing eccentricity (the datum)",
    "gamma_r": "ring: direction of its assembly eccentricity",
    "gamma_c": "carrier: direction of its axis offset (bearing seat turned)",
    "beta_p": "planet: manufacturing eccentricity from its radial line",
    "gamma_p": "planet: pin-position error from its radial line",
    "beta_l": "ring (Wang's l): direction of its manufacturing eccentricity (the datum)",
}


Scenario = Literal[
    "random_assembly",
    "random_assembly_half_tolerance",
    "allocated_assembly_random_magnitudes",
    "optimal_assembly_random_magnitudes",
    "random_magnitudes_random_assembly",
]
"""The Monte-Carlo scenarios of :mod:`gearte.runners.planetary_mc` (Wang 2013 §3.2)."""


class GearSet(StrictModel):
    """``[gearset]``: a 2K-H planetary (Wang 2013 Table 1)."""

    z_sun: int = Field(ge=3, le=1000, description="sun teeth")
    z_planet: int = Field(ge=3, le=1000, description="planet teeth")
    z_ring: int = Field(ge=6, le=3000, description="ring teeth")
    module_mm: float = Field(gt=0, le=100, description="module [mm]")
    pressure_angle_deg: float = Field(gt=0, lt=45, description="working pressure angle [deg]")
    n_planets: int = Field(default=3, ge=1, le=24, description="number of planets")
    planet_angles_deg: list[float] | None = Field(
        default=None, description="planet position angles [deg], first 0; default equal spacing"
    )
    fixed: Member = Field("ring", description="The member held fixed.")
    input: Member = Field("sun", description="The input member.")
    output: Member = Field("carrier", description="The output member.")
    standard: bool = Field(default=True, description="standard gears: z_r = z_s + 2 z_p required")

    @model_validator(mode="after")
    def _check(self) -> GearSet:
        self.build()  # raises ParameterError (a ValueError) naming the field
        return self

    def build(self) -> PlanetarySet:
        return PlanetarySet(
            z_sun=self.z_sun,
            z_planet=self.z_planet,
            z_ring=self.z_ring,
            module=self.module_mm,
            pressure_angle=float(deg_to_rad(self.pressure_angle_deg)),
            n_planets=self.n_planets,
            planet_angles=None
            if self.planet_angles_deg is None
            else tuple(float(deg_to_rad(a)) for a in self.planet_angles_deg),
            fixed=self.fixed,
            input=self.input,
            output=self.output,
            standard=self.standard,
        )


#: Largest |frequency| of a published term [x input speed].
MAX_TERM_FREQUENCY = 10_000
#: Largest denominator of a term frequency 'p/q'.
MAX_TERM_DENOMINATOR = 10_000


class TermRow(StrictModel):
    """One published term ``gain * M sin(q w_in t + phase + angle_coeff * angle)``."""

    name: str | None = Field(None, description="Label of the term (as the paper names it).")
    magnitude: str = Field(description="key into errors.magnitudes_um")
    gain: float = Field(default=1.0, description="factor on the magnitude [-]")
    frequency: float | str = Field(description="multiple of the input speed, number or 'p/q'")
    phase_deg: float = Field(description="constant phase [deg]")
    angle: str | None = Field(default=None, description="key into errors.angles_deg")
    angle_coeff: Sign = Field(1, description="Sign (-1 or 1) of the angle in the term's phase.")

    @field_validator("frequency")
    @classmethod
    def _frac(cls, v: float | str) -> float | str:
        try:
            q = Fraction(str(v).replace(" ", ""))
        except (ValueError, ZeroDivisionError):
            raise ValueError("must be a number or a fraction 'p/q'") from None
        # Bounds: the evaluation grid grows with the largest harmonic of the common period.
        if abs(q) > MAX_TERM_FREQUENCY:
            raise ValueError(f"|frequency| must be <= {MAX_TERM_FREQUENCY} x input speed")
        if q.denominator > MAX_TERM_DENOMINATOR:
            raise ValueError(
                f"is the fraction {q} (denominator {q.denominator}); the denominator must be "
                f"<= {MAX_TERM_DENOMINATOR}: write the frequency as 'p/q' (e.g. '7/8')"
            )
        return v


class Errors(StrictModel):
    """``[errors]``: magnitudes (tolerances or measured) [µm] and angles [deg]."""

    source: Literal["derived", "terms"] = Field(
        default="derived", description="'derived' from kinematics, or 'terms' as given"
    )
    planet_model: Literal["reference", "mean"] = Field(
        default="reference",
        description="derived: output follows planet 1 (Wang 2013) or the mean of all planets",
    )
    magnitudes_um: dict[str, float] = Field(description="error magnitude per key [µm]")
    angles_deg: dict[str, float] = Field(
        default_factory=dict,
        description="error angle per key [deg] (missing: 0); |angle| <= 5729577.95 deg (1e5 rad, "
        "the range of the compiled sine and cosine of the TE kernels)",
    )
    terms: list[TermRow] | None = Field(default=None, description="source='terms': the list")
    reference_angle: str | None = Field(
        default=None, description="source='terms': the angle that is the assembly datum"
    )
    overall_sign: Sign = Field(
        default=1, description="source='terms': sign in front of the sum (eq 9: -1)"
    )

    @field_validator("magnitudes_um")
    @classmethod
    def _nonneg(cls, v: dict[str, float]) -> dict[str, float]:
        for k, x in v.items():
            if not np.isfinite(x) or x < 0:
                raise ValueError(f"magnitude {k!r} = {x!r}: must be a finite number >= 0 [µm]")
            if x > 10_000:
                raise ValueError(f"magnitude {k!r} = {x!r}: must be <= 10000 µm")
        return v

    @field_validator("angles_deg")
    @classmethod
    def _bounded_angles(cls, v: dict[str, float]) -> dict[str, float]:
        from gearte.solvers.trig_extremes import SINCOS_MAX_ARG

        limit = float(rad_to_deg(SINCOS_MAX_ARG))
        for k, x in v.items():
            if not np.isfinite(x) or abs(x) > limit:
                raise ValueError(
                    f"angle {k!r} = {x!r}: must be a finite number with |angle| <= {limit:.9g} "
                    f"deg ({SINCOS_MAX_ARG:g} rad, the range of the TE kernels' sine and cosine)"
                )
        return v

    @model_validator(mode="after")
    def _terms_given(self) -> Errors:
        if self.source == "terms" and not self.terms:
            raise ValueError("source = 'terms' needs a non-empty [[errors.terms]] list")
        if self.source == "derived" and self.terms:
            raise ValueError("[[errors.terms]] is only read with source = 'terms'")
        return self


class CoupledTEOptions(StrictModel):
    """``[analyses.coupled_te]``: which assembly the coupled TE is evaluated at."""

    assembly: Literal["given", "paper_rule", "optimal"] = Field(
        default="given", description="angles of errors.angles_deg, the paper's rule, or optimal"
    )


class AssemblyOptions(StrictModel):
    """``[analyses.assembly]``: global optimisation settings."""

    starts: int = Field(default=4096, ge=16, le=1_000_000, description="quasi-random starts")
    polish: int = Field(default=8, ge=1, le=200, description="starts refined by Nelder-Mead")
    seed: int = Field(default=20130808, ge=0, description="Seed of the quasi-random starts.")


class MonteCarloOptions(StrictModel):
    """``[analyses.monte_carlo]``: Wang 2013 §3.2 scenarios."""

    samples: int = Field(
        default=50_000, ge=1, le=100_000_000, description="Assemblies drawn per scenario [-]."
    )
    seed: int = Field(default=2013, ge=0, description="Seed of the random streams.")
    chunk_size: int = Field(
        default=10_000,
        ge=100,
        le=10_000_000,
        description="Samples per chunk of the execution layer.",
    )
    scenarios: list[Scenario] = Field(
        default_factory=lambda: list(get_args(Scenario)),
        description="Scenarios of Wang 2013 §3.2 to run (default: all).",
    )
    rayleigh_sigma_fraction: float = Field(
        default=0.5, gt=0, le=10, description="Rayleigh scale / tolerance (0.5: tol = 2 sigma)"
    )
    bins: int = Field(
        default=120, ge=5, le=10_000, description="Histogram bins of the TE amplitude."
    )


class Analyses(StrictModel):
    coupled_te: CoupledTEOptions | None = Field(default_factory=CoupledTEOptions)
    assembly: AssemblyOptions | None = Field(default_factory=AssemblyOptions)
    monte_carlo: MonteCarloOptions | None = None
    yield_: YieldSection | None = Field(
        default=None,
        alias="yield",
        description="production yield (gearte.studies._yield); a gear's eccentricity E_s, "
        "E_p<i>, E_r takes grade = N: F_rT/2 of its ISO 1328-1:2013 class",
    )


class Case(CaseBase):
    """A ``planetary`` case file."""

    gearset: GearSet
    errors: Errors
    analyses: Analyses = Field(default_factory=Analyses)

    @model_validator(mode="after")
    def _keys(self) -> Case:
        terms, _, _ = build_terms(self)  # unknown/missing keys raise ParameterError (ValueError)
        _check_resources(self, terms)
        return self


def _check_resources(case: Case, terms: TermSet) -> None:
    """Memory and time of the extremes over the common period, estimated before any work.

    The dense stage of :func:`gearte.solvers.trig_extremes.exact_extremes` holds ``2 G + 1`` rows
    of ``8 n_max`` nodes per worker (``G`` harmonics, ``n_max`` the largest harmonic number of the
    common period); each evaluation costs about ``8 n_max G`` sine-table products.
    """
    from gearte.limits import check_memory, check_time
    from gearte.models.planetary_errors import frequency_basis
    from gearte.solvers.trig_extremes import grid_points

    _, harm, _ = frequency_basis(terms)
    if not harm:
        return
    nodes, g = grid_points(harm), len(harm)
    cores = os.cpu_count() or 1
    field = "errors.terms.frequency" if case.errors.source == "terms" else "gearset (teeth)"
    what = f"the common period's grid ({nodes} nodes, largest harmonic {max(harm)})"
    check_memory(field, f"largest harmonic {max(harm)}", 8.0 * nodes * (2 * g + 1) * cores, what)
    a = case.analyses
    evaluations = 1
    if a.assembly is not None:
        evaluations += a.assembly.starts * (1 + a.assembly.polish)
    if a.monte_carlo is not None:
        evaluations += a.monte_carlo.samples * len(a.monte_carlo.scenarios)
    seconds = evaluations * nodes * g * 2e-9 / cores
    check_time(
        field, f"largest harmonic {max(harm)}", seconds, f"{evaluations} evaluations of {what}"
    )


# --------------------------------------------------------------------------- building
def _expand_planet_keys(values: dict[str, float], n: int, prefixes: tuple[str, ...]) -> dict:
    """``E_p`` → ``E_p1..E_pN`` (shorthand for identical planets)."""
    out = dict(values)
    for pre in prefixes:
        if pre in out:
            v = out.pop(pre)
            for i in range(1, n + 1):
                out.setdefault(f"{pre}{i}", v)
    return out


def _first_stage(mags_um: dict[str, float], angs_deg: dict[str, float], n: int) -> SunPlanetErrors:
    """Wang's named sun/planet magnitudes [µm] and angles [deg] (planet keys expanded) as the
    shared :class:`SunPlanetErrors` [mm, rad]; a missing angle is 0, a missing magnitude 0."""
    for k in list(mags_um) + list(angs_deg):
        base = k.rstrip("0123456789")
        if (
            base in ("E_p", "A_p", "beta_p", "gamma_p")
            and base != k
            and not 1 <= int(k[len(base) :]) <= n
        ):
            where = "magnitudes_um" if k in mags_um else "angles_deg"
            raise ParameterError(
                f"errors.{where}.{k}",
                mags_um.get(k, angs_deg.get(k)),
                f"no such planet: one eccentricity per planet, gearset.n_planets = {n}",
            )

    def ecc(mag: str, ang: str) -> EccentricityError:
        return EccentricityError(
            float(um_to_mm(mags_um.get(mag, 0.0))),
            float(deg_to_rad(angs_deg.get(ang, 0.0))),
            f"errors.magnitudes_um.{mag}",
        )

    return SunPlanetErrors(
        tuple(ecc(f"E_p{i}", f"beta_p{i}") for i in range(1, n + 1)),
        ecc("E_s", "beta_s"),
        ecc("A_s", "gamma_s"),
    )


def first_stage_errors(case: Case) -> SunPlanetErrors:
    """The sun and planet eccentricities of a ``planetary`` case as the eccentricity-error object
    shared with the RV first stage.

    Parameters
    ----------
    case : Case
        A ``planetary`` case with ``errors.source = "derived"``; reads ``E_s, beta_s`` (sun),
        ``A_s, gamma_s`` (sun assembly) and ``E_p<i>, beta_p<i>`` (or ``E_p, beta_p`` for every
        planet) [µm, deg].

    Returns
    -------
    SunPlanetErrors
        Amplitudes [mm] and phases [rad]; one planet entry per ``gearset.n_planets``.

    Raises
    ------
    ParameterError
        ``errors.source`` is not ``"derived"`` (terms as given name no parts), or a planet key
        beyond ``gearset.n_planets``.

    References
    ----------
    Wang C. et al. (2013), Trans. CSAM 44(8), 287-292, Table 1.
    doi:10.6041/j.issn.1000-1298.2013.08.049
    """
    if case.errors.source != "derived":
        raise ParameterError(
            "errors.source", case.errors.source, "first-stage errors need source = 'derived'"
        )
    n = case.gearset.n_planets
    mags = _expand_planet_keys(case.errors.magnitudes_um, n, ("E_p", "A_p"))
    angs = _expand_planet_keys(case.errors.angles_deg, n, ("beta_p", "gamma_p"))
    return _first_stage(mags, angs, n)


def build_terms(case: Case) -> tuple[TermSet, dict[str, float], dict[str, float]]:
    """The term set, magnitudes [mm] and angles [rad] of a case (keys checked)."""
    from gearte.models.planetary_errors import derive_terms, first_stage_keys, terms_from_table

    pset = case.gearset.build()
    e = case.errors
    if e.source == "derived":
        terms = derive_terms(pset, e.planet_model)
        mags = _expand_planet_keys(e.magnitudes_um, pset.n_planets, ("E_p", "A_p"))
        angs = _expand_planet_keys(e.angles_deg, pset.n_planets, ("beta_p", "gamma_p"))
        # A_r (ring assembly) defaults to 0: the fixed ring is the datum (Wang 2013 Table 1)
        mags.setdefault("A_r", 0.0)
        # keys of planets not in the model (reference model: only planet 1) are accepted
        known_m = set(terms.magnitudes) | {
            f"{p}{i}" for p in ("E_p", "A_p") for i in range(1, pset.n_planets + 1)
        }
        known_a = set(terms.angles) | {
            f"{p}{i}" for p in ("beta_p", "gamma_p") for i in range(1, pset.n_planets + 1)
        }
    else:
        assert e.terms is not None
        rows = [
            {
                "name": r.name or f"e{k + 1}",
                "magnitude": r.magnitude,
                "gain": r.gain,
                "frequency": str(r.frequency),
                "phase": float(deg_to_rad(r.phase_deg)),
                "angle": r.angle,
                "angle_coeff": r.angle_coeff,
            }
            for k, r in enumerate(e.terms)
        ]
        terms = terms_from_table(rows, e.overall_sign * pset.output_scale(), e.reference_angle)
        mags, angs = dict(e.magnitudes_um), dict(e.angles_deg)
        known_m, known_a = set(terms.magnitudes), set(terms.angles)
    for k in mags:
        if k not in known_m:
            raise ParameterError(
                f"errors.magnitudes_um.{k}", mags[k], f"unknown key; known: {sorted(known_m)}"
            )
    for k in angs:
        if k not in known_a:
            raise ParameterError(
                f"errors.angles_deg.{k}", angs[k], f"unknown key; known: {sorted(known_a)}"
            )
    missing = [k for k in terms.magnitudes if k not in mags]
    if missing:
        raise ParameterError("errors.magnitudes_um", sorted(mags), f"missing keys {missing}")
    mags_mm = {k: float(um_to_mm(v)) for k, v in mags.items() if k in terms.magnitudes}
    angs_rad = {k: float(deg_to_rad(v)) for k, v in angs.items() if k in terms.angles}
    if e.source == "derived":
        # the sun and planet eccentricities reach the model through the object the RV first
        # stage shares (the keys given stay the keys read: a missing angle stays free)
        fs_mags, fs_angs = first_stage_keys(_first_stage(mags, angs, pset.n_planets))
        mags_mm.update({k: v for k, v in fs_mags.items() if k in mags_mm})
        angs_rad.update({k: v for k, v in fs_angs.items() if k in angs_rad})
    return terms, mags_mm, angs_rad


def _arcsec(x: float) -> float:
    return float(rad_to_arcsec(x))


def _deg_map(angles: dict[str, float], keys: tuple[str, ...] | list[str]) -> dict[str, float]:
    return {k: round(float(np.mod(rad_to_deg(angles[k]), 360.0)), 6) for k in keys}


def _meaning(key: str) -> str:
    base = key.rstrip("0123456789")
    text = ANGLE_MEANING.get(base, key)
    if base != key:
        text = text.replace("planet:", f"planet {key[len(base) :]}:")
    return text


# --------------------------------------------------------------------------- run
def preflight(case: Case) -> None:
    """The checks :func:`run` makes on the built terms before any analysis (``gearte validate``,
    :func:`gearte.studies.run_case`): the paper-rule phase allocation every run makes
    (:func:`~gearte.runners.planetary_assembly.paper_rule_angles`; an angle that enters one
    frequency group with both signs is refused) and the yield's tolerance and cost keys
    (:func:`~gearte.studies._yield.yield_inputs`), without evaluating any TE.

    Raises
    ------
    ParameterError
        Naming the key (``terms`` and the angle, ``analyses.yield...``).
    """
    from gearte.runners.planetary_assembly import paper_rule_angles

    terms, mags, angs = build_terms(case)
    paper_rule_angles(terms, mags, angs)
    if case.analyses.yield_ is not None:
        from gearte.runners.yield_models import PlanetaryCoupledTE
        from gearte.studies._yield import yield_inputs

        units, nominal = _yield_keys(terms, mags, angs)
        families = _planet_families(case, units)
        yield_inputs(
            case.analyses.yield_,
            units,
            nominal,
            families=families,
            grade_um=_grade_um(case),
            quantities=PlanetaryCoupledTE.quantities,
        )


def run(case: Case, options) -> StudyResult:
    """Derive (or read) the terms, then coupled TE, assembly phases and Monte-Carlo."""
    from gearte.models.planetary_errors import coupled_te, frequency_basis
    from gearte.runners.planetary_assembly import (
        optimal_assembly,
        paper_rule_assembly,
        relevant_angles,
    )

    terms, mags, angs = build_terms(case)
    pset = case.gearset.build()
    q0, harm, _ = frequency_basis(terms)
    analyses: list[AnalysisResult] = []
    warnings: list[str] = []
    if case.errors.source == "derived" and case.errors.planet_model == "reference":
        unused = sorted(
            k
            for k in list(case.errors.magnitudes_um) + list(case.errors.angles_deg)
            if k.rstrip("0123456789") in ("E_p", "A_p", "beta_p", "gamma_p")
            and k[-1].isdigit()
            and k.rstrip("0123456789") + "1" != k
        )
        if unused:
            warnings.append(
                f"planet_model = 'reference' uses planet 1 only; values of {unused} are unused "
                "(set planet_model = 'mean' to use every planet)"
            )

    # ---- the terms, one row each
    rows = []
    for t in terms.terms:
        rows.append(
            {
                "name": t.name,
                "line": t.line,
                "amplitude [um]": float(mm_to_um(abs(t.gain) * mags[t.magnitude])),
                "frequency [x input]": str(t.frequency),
                "phase [deg]": round(float(rad_to_deg(t.phase)), 6),
                "angle": t.angle,
                "angle_coeff": t.angle_coeff,
                "sign": 1 if t.gain >= 0 else -1,
            }
        )
    speeds = {k: str(v) for k, v in pset.speed_ratios().items()}
    analyses.append(
        AnalysisResult(
            name="terms",
            title="Equivalent mesh-error terms on the lines of action",
            values={
                "source": case.errors.source,
                "terms": rows,
                "speeds [x input]": speeds,
                "ratio": pset.ratio,
                "output_scale [arcsec/um]": _arcsec(
                    terms.scale * um_to_mm(1.0)
                ),  # [rad/mm]·[mm/µm]
                "common_period [input rev]": str(1 / q0),
                "harmonics": list(harm),
            },
            references=["wang2013"],
            notes=[
                "Each term is gain * M * sin(q w_in t + phase + angle_coeff * angle); "
                "Σ terms times output_scale is the output rotation error.",
                "Derived sign convention: positive = driving flank ahead (Wang's is the opposite,"
                " which flips every term and changes no amplitude).",
            ],
        )
    )

    # ---- assemblies
    paper = paper_rule_assembly(terms, mags, angs)
    a_opts = case.analyses.assembly
    optimal = None
    if (
        a_opts is not None
        or (case.analyses.coupled_te is not None and case.analyses.coupled_te.assembly == "optimal")
        or (
            case.analyses.monte_carlo is not None
            and "optimal_assembly_random_magnitudes" in case.analyses.monte_carlo.scenarios
        )
    ):
        from gearte.studies import sample_cap

        ao = a_opts or AssemblyOptions()
        optimal = optimal_assembly(
            terms,
            mags,
            reference_value=angs.get(terms.reference_angle, 0.0) if terms.reference_angle else 0.0,
            starts=sample_cap(ao, "starts", options),
            polish=sample_cap(ao, "polish", options),
            seed=ao.seed,
            extra_starts=[paper.angles],
            workers=options.workers,
        )

    # ---- coupled TE at the chosen assembly
    if case.analyses.coupled_te is not None:
        which = case.analyses.coupled_te.assembly
        given = {a: angs.get(a, 0.0) for a in terms.angles}
        at = {"given": given, "paper_rule": paper.angles}.get(which)
        if which == "optimal":
            assert optimal is not None
            at = optimal.angles
        assert at is not None
        r = coupled_te(terms, mags, at)
        u = np.linspace(0, 2 * np.pi, 2001)
        figure_data: dict = {"te": r, "u": u, "signal_um": mm_to_um(r.signal(u))}
        if a_opts is not None:  # its figure draws the optimum too: it reads this analysis alone
            assert optimal is not None
            figure_data["optimal_te"] = coupled_te(terms, mags, optimal.angles)
            figure_data["optimal_assembly_te [arcsec]"] = _arcsec(optimal.amplitude)
        analyses.append(
            AnalysisResult(
                name="coupled_te",
                title=f"Coupled output transmission error ({which} assembly)",
                values={
                    "coupled_te_amplitude [arcsec]": _arcsec(r.amplitude),
                    "coupled_te_peak_to_peak [arcsec]": _arcsec(r.peak_to_peak),
                    "coupled_te_amplitude_sum [arcsec]": _arcsec(r.amplitude_sum),
                    "constant_part [um]": float(mm_to_um(r.constant)),
                    "group_amplitude [um]": {
                        str(f): float(mm_to_um(abs(z)))
                        for f, z in zip(r.frequencies, r.phasors, strict=True)
                    },
                    "group_phase [deg]": {
                        str(f): float(rad_to_deg(np.angle(z)))
                        for f, z in zip(r.frequencies, r.phasors, strict=True)
                    },
                    "angles [deg]": _deg_map(at, list(terms.angles)),
                },
                references=["wang2013"],
                notes=[
                    "Amplitude = max over the common period of |Σ e(t)| (exact: dense grid, "
                    "pruning bound and Newton refinement; 1e-9 relative); peak-to-peak = "
                    "max - min of Σ e(t).",
                    "coupled_te_amplitude_sum = |constant| + Σ |group phasor| (Wang 2013's "
                    "lambda = 1 rule across frequencies; an upper bound).",
                ],
                data=figure_data,
            )
        )

    if a_opts is not None:
        assert optimal is not None
        rel = relevant_angles(terms, mags)
        instr = [
            f"{k} = {np.mod(rad_to_deg(optimal.angles[k]), 360):.2f} deg: {_meaning(k)}"
            for k in rel
        ]
        analyses.append(
            AnalysisResult(
                name="assembly",
                title="Assembly phases: global optimum vs Wang 2013's rule",
                values={
                    "optimal_assembly_te [arcsec]": _arcsec(optimal.amplitude),
                    "optimal_assembly_te_peak_to_peak [arcsec]": _arcsec(optimal.peak_to_peak),
                    "assembly_angles [deg]": _deg_map(optimal.angles, rel),
                    "paper_rule_assembly_te [arcsec]": _arcsec(paper.amplitude_sum),
                    "paper_rule_assembly_te_exact [arcsec]": _arcsec(paper.amplitude),
                    "paper_rule_angles [deg]": _deg_map(paper.angles, list(paper.set_by_rule)),
                    "paper_rule_arbitrary_angles": [a for a in rel if a not in paper.set_by_rule],
                    "reference_angle": terms.reference_angle,
                    "assembly_instructions": instr,
                },
                references=["wang2013"],
                notes=[
                    "Angles are measured counter-clockwise from the reference angle "
                    f"({terms.reference_angle}) at t = 0 (planet 1 on the x axis).",
                    "optimal_assembly_te: global minimum of the exact amplitude max|Σe(t)| over "
                    "every free angle (quasi-random starts + Nelder-Mead).",
                    "paper_rule_assembly_te: Wang's own measure |c| + Σ|group amplitude| at his "
                    "±1 rule (eq 6, Table 3); paper_rule_assembly_te_exact: exact amplitude at "
                    "those angles with the rule's 'arbitrary' angles at their given values.",
                ],
                data={"optimal": optimal, "paper": paper, "terms": terms, "mags": mags},
            )
        )

    if case.analyses.yield_ is not None:
        analyses.append(_yield(case, terms, mags, angs, options))

    # ---- Monte-Carlo
    mc = case.analyses.monte_carlo
    if mc is not None:
        from gearte.runners.planetary_mc import run_scenario

        samples = options.samples if options.samples is not None else mc.samples
        seed = options.seed if options.seed is not None else mc.seed
        for k, sc in enumerate(mc.scenarios):
            fixed = None
            if sc == "allocated_assembly_random_magnitudes":
                fixed = {a: paper.angles[a] for a in paper.set_by_rule}
            elif sc == "optimal_assembly_random_magnitudes":
                assert optimal is not None
                fixed = dict(optimal.angles)
            res = run_scenario(
                terms,
                sc,
                mags,
                samples=samples,
                seed=None if seed is None else seed + k,
                chunk_size=mc.chunk_size,
                assembly_angles=fixed,
                rayleigh_sigma_fraction=mc.rayleigh_sigma_fraction,
                bins=mc.bins,
                workers=options.workers,
                scheduler=options.scheduler,
                progress=options.progress,
            )
            s, p = res.stats, res.stats_p2p
            analyses.append(
                AnalysisResult(
                    name=f"mc_{sc}",
                    title=f"Monte-Carlo: {sc.replace('_', ' ')}",
                    values={
                        "mc_mean [arcsec]": _arcsec(s.mean),
                        "mc_sd [arcsec]": _arcsec(s.sd),
                        "mc_min [arcsec]": _arcsec(s.min),
                        "mc_max [arcsec]": _arcsec(s.max),
                        "mc_standard_error [arcsec]": _arcsec(s.standard_error),
                        "mc_p2p_mean [arcsec]": _arcsec(p.mean),
                        "samples": s.count,
                        "seed": None if seed is None else seed + k,
                    },
                    references=["wang2013"],
                    notes=[
                        "TE per sample = exact max over the common period of |Σe(t)|.",
                        "Magnitudes are the given values (tolerances); Rayleigh scenarios draw "
                        f"sigma = {mc.rayleigh_sigma_fraction} x value, truncated at the value.",
                    ],
                    data={"edges [arcsec]": rad_to_arcsec(res.edges), "hist": res.hist},
                )
            )
    return StudyResult(case=case, analyses=analyses, warnings=warnings)


def _yield_keys(terms: TermSet, mags: dict, angs: dict) -> tuple[dict, dict]:
    """The error keys of the yield (magnitudes in µm, angles in deg) and their nominal values."""
    mag_um = {k: float(mm_to_um(v)) for k, v in mags.items()}
    ang_deg = {k: float(rad_to_deg(v)) for k, v in angs.items()}
    units = {k: "um" for k in terms.magnitudes} | {k: "deg" for k in terms.angles}
    nominal = {
        **{k: mag_um.get(k, 0.0) for k in terms.magnitudes},
        **{k: ang_deg.get(k, 0.0) for k in terms.angles},
    }
    return units, nominal


def _planet_families(case: Case, units: dict[str, str]) -> dict[str, list[str]]:
    """With ``errors.source = "derived"``: ``E_p``, ``A_p``, ``beta_p``, ``gamma_p`` as families
    of the planets' keys (``E_p`` → ``E_p1`` … as the model has them), so one tolerance — or one
    grade — covers every planet, each drawn on its own, as ``[errors]`` accepts ``E_p`` for
    every planet. ``units`` gains the family keys."""
    if case.errors.source != "derived":
        return {}
    families: dict[str, list[str]] = {}
    for base in ("E_p", "A_p", "beta_p", "gamma_p"):
        inst = sorted(
            (k for k in units if k.rstrip("0123456789") == base and k != base),
            key=lambda k: int(k[len(base) :]),
        )
        if inst:
            families[base] = inst
            units[base] = units[inst[0]]
    return families


def _yield(case: Case, terms: TermSet, mags: dict, angs: dict, options) -> AnalysisResult:
    """``[analyses.yield]``: magnitudes [µm] and directions [deg] as tolerances (e.g. Wang's
    random assembly: each direction ``uniform``, ``nominal_deg = 180``, ``tolerance_deg =
    180``) → yield of the coupled TE."""
    from gearte.runners.yield_models import PlanetaryCoupledTE
    from gearte.studies._yield import yield_analysis

    units, nominal = _yield_keys(terms, mags, angs)
    families = _planet_families(case, units)
    mag_um = {k: float(mm_to_um(v)) for k, v in mags.items()}
    ang_deg = {k: float(rad_to_deg(v)) for k, v in angs.items()}

    def worst_case(errors):
        d = case.model_dump(mode="json", by_alias=True, exclude_none=True)
        d.pop("name", None)
        d["errors"]["magnitudes_um"] = {
            **d["errors"]["magnitudes_um"],
            **{k: errors[k] for k in terms.magnitudes if k in errors},
        }
        d["errors"]["angles_deg"] = {
            **d["errors"].get("angles_deg", {}),
            **{k: errors[k] for k in terms.angles if k in errors},
        }
        d["analyses"] = {"coupled_te": {"assembly": "given"}}
        return d

    return yield_analysis(
        case.analyses.yield_,  # type: ignore[arg-type]
        PlanetaryCoupledTE(terms, mag_um, ang_deg),
        units,
        nominal,
        options=options,
        worst_case=worst_case,
        references=["wang2013"],
        families=families,
        grade_um=_grade_um(case),
    )


#: The assembly eccentricities of the derived model: what each one is (no accuracy grade
#: bounds them — they are seats and bores, not teeth).
_ASSEMBLY_KEYS = {
    "A_s": "the sun's assembly eccentricity (its bearing seat)",
    "A_r": "the ring's assembly eccentricity (its seat in the housing)",
    "A_c": "the carrier's assembly eccentricity (its bearing seat)",
    "A_p": "a planet's assembly eccentricity (its pin-hole position in the carrier)",
}


def _grade_um(case: Case):
    """The ``grade_um(key, grade)`` of the planetary yield
    (:func:`~gearte.studies._yield.yield_analysis`): a gear's manufacturing eccentricity —
    ``E_s`` (sun), ``E_p<i>`` (planet ``i``; ``E_p``: every planet), ``E_r`` (ring, an internal
    gear) — takes the
    eccentricity tolerance ``F_rT / 2`` of its ISO 1328-1:2013 class, from the gear's module
    and teeth of ``[gearset]`` (``d = m z``; run-out needs no face width). Any other key is an
    error naming it and saying why.
    """
    from gearte.studies._yield import GradeTolerance, eccentricity_grade_tolerance

    gs = case.gearset
    gears = {"E_s": ("sun", gs.z_sun), "E_r": ("ring (internal gear)", gs.z_ring)}

    def grade_um(key: str, grade: int) -> GradeTolerance | None:
        field = f"analyses.yield.tolerances.{key}.grade"
        if case.errors.source != "derived":
            raise ParameterError(
                field,
                grade,
                "with errors.source = 'terms' the magnitudes are the terms' own keys and name "
                "no gear, so no gear's size is known to read a grade with: give tolerance_um "
                "(or describe the stage with errors.source = 'derived')",
            )
        base = key.rstrip("0123456789")
        if base == "E_p":
            i = key[len(base) :]
            name, z = (f"planet {i}" if i else "each planet"), gs.z_planet
        elif key in gears:
            name, z = gears[key]
        elif base in _ASSEMBLY_KEYS:
            raise ParameterError(
                field,
                grade,
                f"{key} is {_ASSEMBLY_KEYS[base]}, not a gear's tooth run-out, so no ISO "
                "1328-1 class bounds it: give tolerance_um",
            )
        else:
            return None
        return eccentricity_grade_tolerance(field, grade, name, z, gs.module_mm)

    return grade_um
