"""``[analyses.yield]``: the production-yield analysis any study kind can offer.

A kind that has a yield model of its drive (:mod:`gearte.runners.yield_models`) adds
``yield: YieldSection | None`` to its analyses and calls :func:`yield_analysis`. The section::

    [analyses.yield]
    samples = 20_000            # assembled drives drawn
    seed = 14
    confidence = 0.95           # of the yield's interval
    ci_method = "wilson"        # or "clopper-pearson"
    sobol_samples = 2_048       # 0: none (a power of 2 keeps the Sobol' set balanced)
    sobol_sampling = "qmc"      # scrambled Sobol' points; "mc": pseudo-random
    bootstrap = 100
    keep_worst = 3              # worst samples written as case files

    [analyses.yield.tolerances.<error key>]   # keys: the drive's error keys
    kind = "normal"     # normal | truncated_normal | uniform | rayleigh | empirical | constant
    tolerance_um = 8.0          # or tolerance_deg for an angle key, or grade = N for a gear's
                                # eccentricity (ISO 1328-1:2013: tolerance = F_rT/2)
    nominal_um = 0.0            # default: the case's value of that error
    sigmas = 3.0                # optional: σ = tolerance / sigmas
    phase = false               # rayleigh: also a uniform direction
    values_um = [...]           # empirical: measured deviations

    [[analyses.yield.groups]]   # correlated errors (one batch): one factor of the Sobol
    name = "pins"; keys = ["pin_radius_error", "pin_circle_radius_error"]; rho = 0.8
                                # indices ("pins"), the two tolerances' joint share

    [analyses.yield.spec."geometric_te [arcmin]"]
    upper = 1.0                 # and/or lower

    [analyses.yield.allocation]           # optional: cheapest tolerances for a target yield
    target_yield = 0.99
    costs.<error key> = {a = 1.0, b = 8.0, k = 1.0}

Result (analysis ``yield``): ``yield``, ``yield_ci_low``, ``yield_ci_high``, ``cpk``,
per-quantity statistics (``non_finite_samples`` counted), ``sobol_first`` / ``sobol_total`` per
independent factor (a tolerance family, or the families a correlated group joins:
``sobol_factors``) with CIs, beside ``linear_share`` (each factor's share in the least-squares
linear fit, ≤ its first-order index) and ``linear_r2``, the worst samples (their drawn errors),
``allocation``, and, for a drive read on a grid of output positions,
``te_discretisation_error [arcsec]`` and ``discretisation_error``; ``statistics_warnings``
(a Sobol interval wider than 0.1, non-finite samples, a grid error above 2 %) are also the
run's warnings.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence
from typing import Any, Literal, NamedTuple

import numpy as np
from pydantic import Field, model_validator

from gearte.io.schema import StrictModel, floored
from gearte.results import AnalysisResult

__all__ = [
    "YieldSection",
    "ToleranceEntry",
    "GradeTolerance",
    "eccentricity_grade_tolerance",
    "yield_analysis",
    "to_toml",
    "GridCheck",
    "grid_error",
]


class GradeTolerance(NamedTuple):
    """What ``grade = N`` gives one error: the tolerance [µm] and how it was derived (the
    standard, the class and the gear's size), reported beside the tolerance in the result."""

    tolerance_um: float
    derivation: str


def eccentricity_grade_tolerance(
    field: str, grade: int, gear: str, teeth: int, module_mm: float, stage: str = ""
) -> GradeTolerance:
    """A gear's eccentricity tolerance from its ISO 1328-1:2013 class: ``F_rT / 2`` (run-out
    ``F_rT = 0.9 F_pT``, rounded as §5.2.3, is twice the eccentricity) at ``d = m z``.

    Parameters
    ----------
    field : str
        The case key of the grade, named in the error.
    grade : int
        ISO 1328-1 flank tolerance class [-].
    gear : str
        The gear as the derivation names it (``"sun"``, ``"planet 2"`` …).
    teeth : int
        Its number of teeth [-].
    module_mm : float
        Its normal module [mm].
    stage : str, optional
        Words in front of the gear in the error (``"first stage's "``).

    Returns
    -------
    GradeTolerance
        The tolerance [µm] and its derivation.

    Raises
    ------
    ParameterError
        Naming ``field`` where the gear is outside the standard's range of application.

    References
    ----------
    ISO 1328-1:2013 Cylindrical gears — ISO system of flank tolerance classification — Part 1,
    eq. (6) and §5.2.3 (:func:`gearte.tolerance.iso1328.runout_tolerance`).
    """
    from gearte.errors import ParameterError
    from gearte.tolerance.iso1328 import runout_tolerance

    m, d = module_mm, module_mm * teeth
    where = f"{gear}: z = {teeth}, m_n = {m:g} mm, d = m_n z = {d:g} mm"
    try:
        f_rt = runout_tolerance(grade, m, d, teeth=teeth)
    except ParameterError as exc:
        raise ParameterError(
            field,
            grade,
            f"the {stage}{where} is outside ISO 1328-1:2013's range of application "
            f"({exc.field} = {exc.value:g}: {exc.reason}): give tolerance_um",
        ) from None
    return GradeTolerance(
        0.5 * f_rt,
        f"ISO 1328-1:2013 class {grade}, {where}: run-out F_rT = 0.9 F_pT = {f_rt:g} µm "
        f"(rounded as §5.2.3), eccentricity tolerance F_rT/2 = {0.5 * f_rt:g} µm",
    )


#: ``grade_um(key, grade)``: the tolerance a grade gives an error (``None``: no grade applies;
#: it may raise a ParameterError naming ``analyses.yield.tolerances.<key>.grade`` with why).
GradeReader = Callable[[str, int], "float | GradeTolerance | None"]


class ToleranceEntry(StrictModel):
    """One error's tolerance; lengths in µm, angles in deg (as the error key's unit)."""

    kind: Literal["normal", "truncated_normal", "uniform", "rayleigh", "empirical", "constant"] = (
        Field(
            "normal",
            description="Law of the error: normal (σ = tolerance / sigmas), truncated_normal (cut "
            "at ±tolerance), uniform, rayleigh (a magnitude), empirical (values_um resampled) or "
            "constant.",
        )
    )
    tolerance_um: float | None = Field(
        default=None,
        ge=0,
        le=100_000,
        description="Tolerance t of a length error [µm]: nominal ± t (3σ by default).",
    )
    tolerance_deg: float | None = Field(
        default=None, ge=0, le=360, description="Tolerance of an angle error [deg]."
    )
    tolerance_arcmin: float | None = Field(
        default=None,
        ge=0,
        le=21_600,
        description="Tolerance of an angle in arcmin (a gear_chain stage's lost motion) [arcmin].",
    )
    grade: int | None = Field(
        default=None,
        ge=1,
        le=11,
        description="ISO 1328-1:2013 class instead of tolerance_um, where the error is a gear's "
        "eccentricity: tolerance = F_rT / 2",
    )
    nominal_um: float | None = Field(
        default=None,
        ge=-100_000,
        le=100_000,
        description="Mean of a length error [µm]; default: the case's value of that error.",
    )
    nominal_deg: float | None = Field(
        default=None,
        ge=-360,
        le=360,
        description="Mean of an angle error [deg]; default: the case's value of that error.",
    )
    nominal_arcmin: float | None = Field(
        default=None,
        ge=-21_600,
        le=21_600,
        description="Mean of an angle in arcmin [arcmin]; default: the case's value.",
    )
    sigmas: float | None = floored(
        "tolerance_sigmas",
        None,
        le=100,
        description="σ = tolerance / sigmas [-] (default 3; rayleigh 3.44, 99.73 % inside).",
    )
    phase: bool = Field(
        False, description="rayleigh only: also draw a uniform direction of the error."
    )
    values_um: list[float] | None = Field(
        default=None,
        min_length=2,
        max_length=1_000_000,
        description="empirical only: measured deviations [µm], resampled.",
    )

    @model_validator(mode="after")
    def _one_unit(self) -> ToleranceEntry:
        given = [self.tolerance_um, self.tolerance_deg, self.tolerance_arcmin, self.grade]
        if sum(v is not None for v in given) != 1:
            raise ValueError(
                "give exactly one of tolerance_um, tolerance_deg, tolerance_arcmin and grade"
            )
        if self.phase and self.kind != "rayleigh":
            raise ValueError("phase = true goes with kind = 'rayleigh' only")
        if self.kind == "empirical" and self.values_um is None:
            raise ValueError("kind = 'empirical' needs values_um (>= 2 measurements)")
        return self

    @property
    def unit(self) -> str:
        if self.tolerance_deg is not None:
            return "deg"
        return "arcmin" if self.tolerance_arcmin is not None else "um"


class GroupEntry(StrictModel):
    """Correlated errors (one grinding batch, one fixture)."""

    name: str = Field(
        min_length=1,
        max_length=100,
        description="Name of the correlated group (a grinding batch, a fixture).",
    )
    keys: list[str] = Field(min_length=1, max_length=1000, description="keys or families")
    rho: float = Field(ge=0, le=1, description="correlation of the members' standard normals")


class SpecEntry(StrictModel):
    """``lower <= quantity <= upper``."""

    lower: float | None = Field(
        None, description="Lower spec limit, in the quantity's unit (the key's brackets)."
    )
    upper: float | None = Field(
        None, description="Upper spec limit, in the quantity's unit (the key's brackets)."
    )

    @model_validator(mode="after")
    def _limits(self) -> SpecEntry:
        if self.lower is None and self.upper is None:
            raise ValueError("give lower, upper or both")
        if self.lower is not None and self.upper is not None and self.upper < self.lower:
            raise ValueError(f"inverted limits: upper {self.upper} < lower {self.lower}")
        return self


class CostEntry(StrictModel):
    """``cost = a + b / t^k`` (t in the error's unit) or a table of widths and prices."""

    a: float = Field(
        default=0.0,
        ge=0,
        le=1e12,
        description="Fixed cost per part in cost = a + b / t^k (any currency).",
    )
    b: float | None = Field(
        default=None,
        ge=0,
        le=1e12,
        description="Cost coefficient b of cost = a + b / t^k, t the tolerance in the error's "
        "unit; or give widths and prices.",
    )
    k: float = Field(default=1.0, ge=0, le=10, description="Exponent k of cost = a + b / t^k [-].")
    widths: list[float] | None = Field(
        default=None,
        min_length=2,
        max_length=100,
        description="Tolerance widths of a price table, in the error's unit (with prices).",
    )
    prices: list[float] | None = Field(
        default=None,
        min_length=2,
        max_length=100,
        description="Price per part at each of widths (same length).",
    )

    @model_validator(mode="after")
    def _one_form(self) -> CostEntry:
        table = self.widths is not None or self.prices is not None
        if table == (self.b is not None):
            raise ValueError("give either b (cost model a + b/t^k) or widths and prices")
        if table and (
            self.widths is None or self.prices is None or len(self.widths) != len(self.prices)
        ):
            raise ValueError("widths and prices must have the same length")
        return self


class AllocationEntry(StrictModel):
    target_yield: float = Field(
        gt=0, lt=1, description="Yield the cheapest tolerance set must reach [-] (0.99: 99 %)."
    )
    costs: dict[str, CostEntry] = Field(min_length=1)
    samples: int | None = Field(
        default=None,
        ge=100,
        le=10**8,
        description="Samples per candidate tolerance set (default: the section's samples).",
    )


#: Fewest base samples of a Sobol estimate (``sobol_tolerances``).
SOBOL_MIN_SAMPLES = 50
#: Two-sided 95 % normal quantile of the allocation search's Wilson bound (``allocate``).
_Z95 = 1.959963984540054


def allocation_min_samples(target_yield: float) -> int:
    """Fewest search samples that can show ``target_yield`` [-]: the 95 % Wilson lower bound of
    ``n`` passes in ``n`` draws is ``n / (n + z²)``, so ``n >= t z² / (1 - t)``."""
    return math.ceil(target_yield * _Z95**2 / (1.0 - target_yield) - 1e-9)


class YieldSection(StrictModel):
    """``[analyses.yield]`` (module docstring)."""

    samples: int = Field(default=20_000, ge=1, le=10**9, description="Assembled drives drawn [-].")
    seed: int = Field(
        default=0,
        ge=0,
        description="Seed of the random streams (same seed, same result on any backend).",
    )
    chunk_size: int = Field(
        default=2_000, ge=1, le=10**7, description="Samples per chunk of the execution layer."
    )
    confidence: float = Field(
        default=0.95, gt=0.5, lt=1, description="Confidence level of the yield's interval [-]."
    )
    ci_method: Literal["wilson", "clopper-pearson"] = Field(
        "wilson", description="Interval of the yield: Wilson score or exact Clopper–Pearson."
    )
    sobol_samples: int = Field(
        default=0,
        ge=0,
        le=10**7,
        description="Base samples for Sobol indices per tolerance (0: none).",
    )
    sobol_sampling: Literal["qmc", "mc"] = Field(
        "qmc",
        description="Points of the Sobol estimate: Owen-scrambled Sobol' (qmc) or pseudo-random "
        "(mc).",
    )
    bootstrap: int = Field(
        default=100,
        ge=0,
        le=10_000,
        description="Bootstrap resamples for the Sobol indices' intervals (0: none).",
    )
    keep_worst: int = Field(
        default=3, ge=0, le=100, description="Worst samples kept and written as case files."
    )
    tolerances: dict[str, ToleranceEntry] = Field(default_factory=dict)
    groups: list[GroupEntry] = Field(default_factory=list)
    spec: dict[str, SpecEntry] = Field(default_factory=dict)
    allocation: AllocationEntry | None = Field(
        None, description="Optional: the cheapest tolerances for a target yield."
    )

    @model_validator(mode="after")
    def _sample_counts_can_run(self) -> YieldSection:
        if self.allocation is not None and not self.spec:
            raise ValueError("allocation needs at least one spec limit (analyses.yield.spec)")
        if 0 < self.sobol_samples < SOBOL_MIN_SAMPLES:
            raise ValueError(
                f"sobol_samples = {self.sobol_samples}: Sobol estimation needs 0 (none) or >= "
                f"{SOBOL_MIN_SAMPLES} base samples"
            )
        if self.allocation is None:
            return self
        n = self.allocation.samples or self.samples
        need = allocation_min_samples(self.allocation.target_yield)
        if n < need:
            which = "allocation.samples" if self.allocation.samples else "samples"
            raise ValueError(
                f"{which} = {n} cannot show allocation.target_yield = "
                f"{self.allocation.target_yield}: even with every sample passing the 95 % "
                f"Wilson lower bound is {n / (n + _Z95**2):.4g}; give allocation.samples >= "
                f"{need}"
            )
        return self


def _tolerances(
    section: YieldSection,
    units: Mapping[str, str],
    nominal: Mapping[str, float],
    defaults: Mapping[str, ToleranceEntry],
    families: Mapping[str, list[str]],
    grade_um: GradeReader | None = None,
    derived: dict[str, dict[str, Any]] | None = None,
):
    """The :class:`~gearte.tolerance.yield_mc.ToleranceSet` of a section; a tolerance read from
    a grade is recorded in ``derived`` (``{key: {"grade", "derived_from"}}``) when given."""
    from gearte.errors import ParameterError
    from gearte.tolerance.yield_mc import CorrelatedGroup, Tolerance, ToleranceSet

    given = {**defaults, **section.tolerances}
    # a family's tolerance stands for each of its instances (an instance may be given itself)
    expanded: dict[str, tuple[ToleranceEntry, str | None]] = {}
    for key, t in given.items():
        if key in families and list(families[key]) != [key]:  # (a one-instance family is a key)
            for inst in families[key]:
                if inst not in given:
                    expanded[inst] = (t, key)
        else:
            expanded[key] = (t, None)
    tols = []
    for key, (t, fam) in expanded.items():
        ukey = fam or key
        if ukey not in units:
            raise ParameterError(
                f"analyses.yield.tolerances.{ukey}",
                ukey,
                f"is not an error key or family; known: {sorted(units)}",
            )
        if t.unit != units[ukey]:
            raise ParameterError(
                f"analyses.yield.tolerances.{ukey}",
                t.unit,
                f"this error is in {units[ukey]}: give tolerance_{units[ukey]}",
            )
        tol = {"um": t.tolerance_um, "deg": t.tolerance_deg, "arcmin": t.tolerance_arcmin}[t.unit]
        if t.grade is not None:
            read = None if grade_um is None else grade_um(ukey, t.grade)
            if read is None:
                raise ParameterError(
                    f"analyses.yield.tolerances.{ukey}.grade",
                    t.grade,
                    "this error is not a gear's eccentricity: give tolerance_um",
                )
            tol = float(read.tolerance_um if isinstance(read, GradeTolerance) else read)
            if derived is not None:
                how = read.derivation if isinstance(read, GradeTolerance) else None
                derived[ukey] = {"grade": t.grade, "derived_from": how or f"grade {t.grade}"}
        nom = {"um": t.nominal_um, "deg": t.nominal_deg, "arcmin": t.nominal_arcmin}[t.unit]
        tols.append(
            Tolerance(
                key,
                t.kind,
                float(tol),  # type: ignore[arg-type]
                nominal=float(nominal.get(key, 0.0) if nom is None else nom),
                sigmas=t.sigmas,
                phase=t.phase,
                values=None if t.values_um is None else tuple(t.values_um),
                family=fam,
            )
        )
    groups = tuple(CorrelatedGroup(g.name, tuple(g.keys), g.rho) for g in section.groups)
    return ToleranceSet(tuple(tols), groups)


def to_toml(data: Mapping[str, Any], _prefix: str = "") -> str:
    """A minimal TOML writer for case dictionaries (tables, scalars, lists of scalars or of
    tables).

    Parameters
    ----------
    data : mapping
        The case dictionary.
    _prefix : str
        Dotted name of the enclosing table (recursion).
    """

    def scalar(v: Any) -> str:
        if isinstance(v, bool):
            return "true" if v else "false"
        if isinstance(v, int):
            return str(v)
        if isinstance(v, float):
            return repr(v) if math.isfinite(v) else "nan"
        if isinstance(v, str):
            return '"' + v.replace("\\", "\\\\").replace('"', '\\"').replace("\n", "\\n") + '"'
        if isinstance(v, list | tuple):
            return "[" + ", ".join(scalar(x) for x in v) + "]"
        if isinstance(v, Mapping):
            return "{" + ", ".join(f"{_key(k)} = {scalar(x)}" for k, x in v.items()) + "}"
        raise TypeError(f"cannot write {type(v).__name__} to TOML")

    def _key(k: str) -> str:
        return k if k.replace("_", "").replace("-", "").isalnum() else scalar(str(k))

    lines: list[str] = []
    tables: list[tuple[str, Mapping[str, Any]]] = []
    arrays: list[tuple[str, list[Mapping[str, Any]]]] = []
    for k, v in data.items():
        if v is None:
            continue
        name = f"{_prefix}.{_key(k)}" if _prefix else _key(k)
        if isinstance(v, Mapping):
            tables.append((name, v))
        elif isinstance(v, list) and v and all(isinstance(x, Mapping) for x in v):
            arrays.append((name, v))
        else:
            lines.append(f"{_key(k)} = {scalar(v)}")
    out = "\n".join(lines) + ("\n" if lines else "")
    for name, v in tables:
        body = to_toml(v, name)
        out += f"\n[{name}]\n{body}"
    for name, items in arrays:
        for item in items:
            out += f"\n[[{name}]]\n" + to_toml(item, name)
    return out


class GridCheck(NamedTuple):
    """How to estimate the error of a yield model's grid of output positions.

    ``refined``: the same drive's model on the refined grid (``refined_positions``, a multiple
    of ``positions``, so the grid holds every position of the default one); ``samples``: how
    many of the run's first samples are evaluated on both grids (0: no check); ``quantities``:
    the outputs read on the grid; ``te``: the one reported as ``te_discretisation_error
    [arcsec]`` (an angle in arcmin)."""

    refined: Callable
    positions: int
    refined_positions: int
    samples: int
    quantities: tuple[str, ...]
    te: str | None = None


#: A grid whose mean relative error exceeds this [-] is named in the statistics warnings.
GRID_WARN_RELATIVE = 0.02


def grid_error(
    grid: GridCheck, model: Callable, ts: Any, *, n: int, seed: int, chunk_size: int
) -> dict[str, Any]:
    """The grid's error on the run's first ``grid.samples`` samples (the same draws as the
    run: its first chunks' streams): each grid quantity's mean and largest change from the
    default grid to the refined one, in its unit and relative to its mean.

    Returns ``{"quantities": {q: {...}}, "te_arcsec": float | None, "note": str,
    "warnings": [str]}``. The refined grid holds the default one's positions, so a
    peak-to-peak can only grow: the change is a lower bound of the default grid's error (the
    refined grid misses its own part).

    Parameters
    ----------
    grid : GridCheck
        The refined model, the grids and the samples to check.
    model : callable
        The yield model on the default grid.
    ts : ToleranceSet
        The run's tolerances.
    n : int
        The run's samples [-].
    seed : int
        The run's seed.
    chunk_size : int
        The run's samples per chunk [-].
    """
    from gearte.execution import seeded_chunks
    from gearte.tolerance.yield_mc import evaluate_checked
    from gearte.units import arcmin_to_rad, rad_to_arcsec

    m = min(int(grid.samples), int(n))
    parts: list[dict[str, np.ndarray]] = []
    for c in seeded_chunks(int(n), int(chunk_size), seed)[: -(-m // int(chunk_size))]:
        parts.append(ts.sample(c.rng(), c.size))
    errs = {k: np.concatenate([p[k] for p in parts])[:m] for k in parts[0]}
    a = evaluate_checked(model, errs, m)
    b = evaluate_checked(grid.refined(), errs, m)
    out: dict[str, dict[str, float]] = {}
    warn: list[str] = []
    for q in grid.quantities:
        d = b[q] - a[q]
        mean_ref = float(np.mean(b[q]))
        rel = float(np.mean(d) / mean_ref) if mean_ref != 0 else 0.0
        out[q] = {
            "mean": float(np.mean(d)),
            "max": float(np.max(np.abs(d))),
            "relative_mean": rel,
            "positions": grid.positions,
            "refined_positions": grid.refined_positions,
            "samples": m,
        }
        if abs(rel) > GRID_WARN_RELATIVE:
            warn.append(
                f"{q}: {grid.positions} output positions under-estimate it by {abs(rel):.1%} "
                f"on average against {grid.refined_positions} ({m} samples); raise positions"
            )
    te = None
    if grid.te is not None and grid.te in out:
        te = float(rad_to_arcsec(arcmin_to_rad(out[grid.te]["mean"])))
    note = (
        f"Grid of output positions: the run's first {m} samples again at "
        f"{grid.refined_positions} positions (a superset of the {grid.positions}); the "
        "mean change is the default grid's discretisation error (a lower bound)"
        + (f": {grid.te} +{te:.3g}″" if te is not None else "")
        + "."
    )
    return {"quantities": out, "te_arcsec": te, "note": note, "warnings": warn}


def yield_inputs(
    section: YieldSection,
    units: Mapping[str, str],
    nominal: Mapping[str, float],
    defaults: Mapping[str, ToleranceEntry] | None = None,
    families: Mapping[str, list[str]] | None = None,
    grade_um: GradeReader | None = None,
    quantities: Sequence[str] | None = None,
    derived: dict[str, dict[str, Any]] | None = None,
) -> tuple[Any, dict[str, Any]]:
    """The tolerance set and allocation cost models of a yield section, checked against the
    drive's error keys (arguments as :func:`yield_analysis`), and its spec against the yield
    model's ``quantities`` (its output names; not checked when ``None``). :func:`yield_analysis`
    calls it before any sample and the kinds' pre-flight (``gearte validate``) calls it without
    running. ``derived``, when given, receives the tolerances read from a grade (key → its
    ``grade`` and ``derived_from``).

    Returns
    -------
    (ToleranceSet, dict)
        The tolerances and ``{error key: CostModel or PriceTable}``.

    Raises
    ------
    ParameterError
        A tolerance or cost naming a key the drive does not have
        (``analyses.yield.tolerances.<key>``, ``analyses.yield.allocation.costs.<key>``), a
        tolerance in the wrong unit, a grade on an error that is not a gear's eccentricity, a
        spec on a quantity the model does not give (``analyses.yield.spec.<quantity>``).
    """
    from gearte.errors import ParameterError
    from gearte.tolerance.allocation import CostModel, PriceTable

    if quantities is not None:
        for q in section.spec:
            if q not in quantities:
                raise ParameterError(
                    f"analyses.yield.spec.{q}",
                    q,
                    f"is not a quantity of the model {sorted(quantities)}",
                )

    ts = _tolerances(
        section, units, nominal, dict(defaults or {}), dict(families or {}), grade_um, derived
    )
    costs: dict[str, CostModel | PriceTable] = {}
    for key, c in (section.allocation.costs if section.allocation else {}).items():
        if key not in ts.families:
            raise ParameterError(
                f"analyses.yield.allocation.costs.{key}", key, "has no tolerance to allocate"
            )
        if c.b is not None:
            costs[key] = CostModel(c.a, c.b, c.k)
        else:
            costs[key] = PriceTable(tuple(c.widths or ()), tuple(c.prices or ()))
    return ts, costs


def yield_analysis(
    section: YieldSection,
    model: Callable,
    units: Mapping[str, str],
    nominal: Mapping[str, float],
    *,
    options: Any = None,
    worst_case: Callable[[Mapping[str, float]], dict] | None = None,
    references: list[str] | None = None,
    defaults: Mapping[str, ToleranceEntry] | None = None,
    families: Mapping[str, list[str]] | None = None,
    grade_um: GradeReader | None = None,
    grid: GridCheck | None = None,
) -> AnalysisResult:
    """Run the yield analysis of a drive.

    Parameters
    ----------
    section : YieldSection
    model : callable
        The drive's yield model (errors in the keys' units → quantities).
    units : mapping
        Error key → ``"um"`` or ``"deg"`` (the keys a tolerance may name).
    nominal : mapping
        Error key → the case's value [unit of the key] (the nominal of a tolerance that gives
        none).
    options : RunOptions, optional
        ``seed``/``samples`` override the section's; workers, scheduler, progress.
    worst_case : callable, optional
        Drawn errors [units of the keys] → a case dictionary that reproduces that drive alone.
    references : list of str, optional
        Reference keys of the analysis.
    defaults : mapping, optional
        Tolerances the drive's own description implies (e.g. a cycloid stage's error bands);
        the section's entries replace them key by key.
    families : mapping, optional
        Family key → its instance keys (e.g. ``cam`` → ``cam.c1.d1`` …): a tolerance on a
        family applies to each instance, drawn independently (a correlated group may name it).
    grade_um : callable, optional
        ``(key, grade) -> tolerance [µm]`` (a number or a :class:`GradeTolerance` naming its
        derivation) for errors that are a gear's eccentricity (``None`` for the others): how
        ``grade = N`` reads for this drive. A tolerance read from a grade is reported with its
        ``grade`` and ``derived_from`` under ``tolerances`` in the result.
    grid : GridCheck, optional
        A drive whose quantities are read on a grid of output positions: the same model on a
        refined grid, run on the run's first samples to estimate the grid's error
        (``te_discretisation_error [arcsec]`` and ``discretisation_error``).
    """
    from gearte.studies import sample_cap
    from gearte.tolerance.allocation import SearchStopped, allocate
    from gearte.tolerance.yield_contributions import pareto_rows, sobol_tolerances
    from gearte.tolerance.yield_mc import SpecLimit, run_yield

    seed = section.seed if getattr(options, "seed", None) is None else int(options.seed)
    n = section.samples if getattr(options, "samples", None) is None else int(options.samples)
    derived: dict[str, dict[str, Any]] = {}
    ts, costs = yield_inputs(
        section,
        units,
        nominal,
        defaults,
        families,
        grade_um,
        getattr(model, "quantities", None),
        derived,
    )
    spec = [SpecLimit(q, s.lower, s.upper) for q, s in section.spec.items()]
    progress = getattr(options, "progress", False)
    res = run_yield(
        model,
        ts,
        spec,
        n,
        seed=seed,
        chunk_size=section.chunk_size,
        confidence=section.confidence,
        ci_method=section.ci_method,
        keep_worst=sample_cap(section, "keep_worst", options),
        options=options,
        progress=progress,
    )
    quantities = {
        q: {
            "mean": st.stats.mean,
            "sd": st.stats.sd,
            "min": st.stats.min,
            "max": st.stats.max,
            "cpk": st.cpk,
            "fail_fraction": st.fail_fraction,
            "non_finite_samples": st.non_finite,
        }
        for q, st in res.quantities.items()
    }
    stat_warnings: list[str] = list(res.warnings)
    values: dict[str, Any] = {
        "yield": res.yield_,
        "yield_ci_low": res.ci[0],
        "yield_ci_high": res.ci[1],
        "cpk": res.cpk,
        "samples": res.n,
        "non_finite_samples": res.non_finite_samples,
        "seed": seed,
        "spec": {s.quantity: {"lower": s.lower, "upper": s.upper} for s in spec},
        "quantities": quantities,
        "tolerances": {
            t.family_name: {"kind": t.kind, "tolerance": t.tolerance, "nominal": t.nominal}
            | derived.get(t.family_name, {})
            for t in ts.tolerances
        },
    }
    notes = [
        f"{res.n} assembled drives drawn (seed {seed}, chunks of {section.chunk_size}); yield = "
        f"share meeting every spec limit, {section.confidence:.0%} {section.ci_method} interval.",
        "Tolerance meaning: normal ±t with σ = t/3 unless sigmas is given; rayleigh: 99.73 % of "
        "magnitudes ≤ t; uniform on ±t around the nominal.",
    ]
    for key, d in derived.items():
        notes.append(f"{key}: tolerance derived from its accuracy grade — {d['derived_from']}.")
    data: dict[str, Any] = {"yield": res}
    files: dict[str, str] = {}
    sobol_q = spec[0].quantity if spec else next(iter(res.quantities), None)
    sobol_n = section.sobol_samples and sample_cap(
        section, "sobol_samples", options, low=SOBOL_MIN_SAMPLES
    )
    if sobol_n and sobol_q is not None and ts.tolerances:
        sob = sobol_tolerances(
            model,
            ts,
            [sobol_q],
            sobol_n,
            seed=seed + 1,
            bootstrap=sample_cap(section, "bootstrap", options),
            options=options,
            progress=progress,
            sampling=section.sobol_sampling,
        )[sobol_q]
        values.update(
            {
                "sobol_quantity": sobol_q,
                "sobol_samples": sob.n,
                "sobol_sampling": sob.sampling,
                "sobol_factors": sob.factors,
                "sobol_first": sob.first,
                "sobol_total": sob.total,
                "sobol_first_ci": {k: list(v) for k, v in sob.first_ci.items()},
                "sobol_total_ci": {k: list(v) for k, v in sob.total_ci.items()},
                "sobol_non_finite_samples": sob.non_finite,
                "linear_share": sob.linear_share,
                "linear_r2": sob.linear_r2,
                "monte_carlo_sd": res.quantities[sobol_q].stats.sd,
            }
        )
        stat_warnings += sob.warnings
        data["pareto"] = pareto_rows(sob)
        joined = "; ".join(f"{k} = {' + '.join(v)}" for k, v in sob.factors.items() if len(v) > 1)
        points = "a scrambled Sobol' set" if sob.sampling == "qmc" else "pseudo-random draws"
        notes.append(
            "Sobol indices per independent factor (a tolerance family; the families a "
            "correlated group joins are one factor"
            + (f": {joined}" if joined else "")
            + f"), {sob.n} base samples on {points}"
            + "; first order Saltelli 2010, total Jansen 1999, percentile-bootstrap "
            "intervals. Beside them the linear share: each factor's share of the variance in "
            "the least-squares linear fit over the Sobol runs (≤ S; S − linear share is what is "
            "non-linear in that factor alone, ST − S its interactions; linear_r2 the fit's R²)."
        )
    worst = []
    for i, w in enumerate(res.worst):
        worst.append(
            {
                "sample": w["sample"],
                "margin": w["margin"],
                "errors": w["errors"],
                "values": w["values"],
            }
        )
        if worst_case is not None:
            case = worst_case(w["errors"])
            header = (
                f"# worst sample {i + 1}: sample {w['sample']} of seed {seed} "
                f"(chunk size {section.chunk_size}); run it with `gearte run` on its own.\n"
            )
            files[f"worst_sample_{i + 1}.toml"] = header + to_toml(case)
    values["worst_samples"] = worst
    if grid is not None and grid.samples > 0:
        g = grid_error(grid, model, ts, n=n, seed=seed, chunk_size=section.chunk_size)
        values["discretisation_error"] = g["quantities"]
        if g["te_arcsec"] is not None:
            values["te_discretisation_error [arcsec]"] = g["te_arcsec"]
        notes.append(g["note"])
        stat_warnings += g["warnings"]
    al = None
    if section.allocation is not None:
        # under --samples: capped, but never below what can show the target (validated above)
        alloc_n = sample_cap(section.allocation, "samples", options) or n
        if getattr(options, "samples", None) is not None:
            alloc_n = max(alloc_n, allocation_min_samples(section.allocation.target_yield))
        try:
            al = allocate(
                model,
                ts,
                spec,
                costs,
                section.allocation.target_yield,
                n=alloc_n,
                seed=seed + 2,
                chunk_size=section.chunk_size,
                options=options,
            )
        except SearchStopped:  # the run was stopped: keep the yield, report no allocation
            al = None
            notes.append("No allocation: the run was stopped before its search finished.")
    if section.allocation is not None and al is not None:
        values["allocation"] = {
            "target_yield": al.target,
            "tolerances": al.widths,
            "cost": al.cost,
            "cost_by_tolerance": al.cost_by_tolerance,
            "search_yield": al.search_yield,
            "verified_yield": al.verified.yield_,
            "verified_yield_ci_low": al.verified.ci[0],
            "verified_yield_ci_high": al.verified.ci[1],
            "verified_seed": al.verified.seed,
            "meets_target": al.meets_target,
            "locally_optimal": al.locally_optimal,
            "yield_if_loosened_one_step": al.loosening_yields,
        }
    values["statistics_warnings"] = stat_warnings
    return AnalysisResult(
        name="yield",
        title="Production yield: tolerance Monte-Carlo through the physics",
        values=values,
        references=references or [],
        notes=notes,
        data=data,
        files=files,
    )
