"""Study kind ``rv_lot``: selective assembly of a lot of measured RV parts, and pin grading
(docs/selective-assembly.md).

Given the measured disc sets and crank sets of a lot (files: ``docs/metrology.md``), choose which
disc set goes with which crank set and in which orientation so that the most reducers meet the
TE spec (or the worst reducer is best), scored by the one RV model linearised about the design's
loaded equilibrium; compare with random assembly (mean over many random assemblies) and with the
best orientation-only rule; verify the chosen reducers with the full non-linear model; write the
assembly instructions per reducer (``assembly_instructions.csv`` and the report). With
``[analyses.pin_grading]``, the pin diameter grade per reducer that brings its backlash into a
window, from the model's virtual torsion test. Method: ``docs/selective-assembly.md``.

Case file::

    [case]     kind = "rv_lot"
    [reducer]  case = "<rv_reducer case>"          the design the parts were made to
    [lot]      disc_sets = [["D-1", "D-2"], ...], crank_sets = [["C-1", "C-2", "C-3"], ...]
    [lot.files]  disc_profile, disc_pitch, disc_bores, crank_eccentricity, planet_runout
                 (a planet carries its crank's serial), bearing_clearance
    [analyses.selective_assembly]  torque_Nm, positions, te_spec_arcsec, objective
                 ("count_in_spec" | "worst"), random_assemblies, seed, verify
    [analyses.pin_grading]  grades_um (pin diameter oversizes), backlash_window_arcmin

Results (``selective_assembly``): ``reducers_in_spec`` (the optimiser's assembly),
``reducers_in_spec_random_mean``, ``reducers_in_spec_orientation_only``, the improvements, and
``reducers_in_spec_full_model`` (the optimiser's reducers re-computed with the full model).
"""

from __future__ import annotations

from typing import Any, Literal

import numpy as np
from pydantic import Field, ValidationInfo, field_validator, model_validator

from gearte.io.schema import StrictModel, floored
from gearte.results import AnalysisResult, StudyResult
from gearte.studies._measured import MeasuredPartsCase
from gearte.studies.rv_bench import _resolve

KIND = "rv_lot"
REFERENCES = ["han2023"]
FIGURES = "gearte.plotting.rv_lot"

__all__ = ["KIND", "REFERENCES", "FIGURES", "Case", "run", "build_lot"]

_FILES = (
    "disc_profile",
    "disc_pitch",
    "disc_bores",
    "crank_eccentricity",
    "planet_runout",
    "bearing_clearance",
)


class LotFiles(StrictModel):
    """Measurement files of the lot (``docs/metrology.md``), relative to the case file."""

    disc_profile: str | None = Field(
        default=None, description="disc flank deviation per tooth (format disc_profile)"
    )
    disc_pitch: str | None = Field(
        default=None, description="disc cumulative pitch per tooth (format disc_pitch)"
    )
    disc_bores: str | None = Field(
        default=None, description="crank-bore centres per disc (format disc_bores)"
    )
    crank_eccentricity: str = Field(
        description="cam eccentricity and phase per crank (format crank_eccentricity)"
    )
    planet_runout: str | None = Field(
        default=None, description="planet run-out; a planet carries its crank's serial (runout)"
    )
    bearing_clearance: str | None = Field(
        default=None, description="cam and carrier bearing clearances per crank"
    )

    @field_validator(*_FILES)
    @classmethod
    def _paths(cls, v: str | None, info: ValidationInfo) -> str | None:
        return None if v is None else _resolve(v, info)


class LotSection(StrictModel):
    disc_sets: list[list[str]] = Field(
        min_length=1, max_length=2000, description="serials of the N discs of each disc set"
    )
    crank_sets: list[list[str]] = Field(
        min_length=1, max_length=2000, description="serials of the M cranks of each crank set"
    )
    files: LotFiles

    @model_validator(mode="after")
    def _unique(self) -> LotSection:
        for name in ("disc_sets", "crank_sets"):
            seen: dict[str, int] = {}
            for k, s in enumerate(getattr(self, name)):
                for x in s:
                    if x in seen:
                        raise ValueError(
                            f"{name}[{k}]: serial {x!r} already in {name}[{seen[x]}] (a part "
                            "can go into one reducer only)"
                        )
                    seen[x] = k
        return self


class SelectiveAssemblySection(StrictModel):
    torque_Nm: float = floored(
        "load_torque", ..., le=1e6, description="output torque of the TE spec"
    )
    positions: int = Field(default=360, ge=16, le=7200, description="output angles per rev")
    te_spec_arcsec: float = Field(gt=0, le=3600, description="total TE peak-to-peak spec")
    objective: Literal["count_in_spec", "worst"] = Field(
        default="count_in_spec",
        description="most reducers in spec, or the smallest worst TE (docs/selective-assembly.md)",
    )
    planet_indexings: int = Field(
        default=1,
        ge=1,
        le=360,
        description="spline positions Q a planet can be mounted in on its crank (planet "
        "phasing, the same for the reducer's planets); 1: as measured",
    )
    random_assemblies: int = Field(
        default=200, ge=100, le=100000, description="random assemblies of the comparison"
    )
    seed: int = Field(default=1, ge=0, description="seed of the random assemblies")
    verify: bool = Field(
        default=True,
        description="re-score the chosen reducers with the full model and re-assign until stable",
    )


class PinGradingSection(StrictModel):
    grades_um: list[float] = Field(min_length=1, max_length=50, description="diameter oversizes")
    backlash_window_arcmin: tuple[float, float] = Field(
        description="[lower, upper] backlash a graded reducer must meet"
    )

    @model_validator(mode="after")
    def _window(self) -> PinGradingSection:
        lo, hi = self.backlash_window_arcmin
        if not 0 <= lo < hi <= 60:
            raise ValueError(f"backlash_window_arcmin needs 0 <= lower < upper <= 60, got {lo, hi}")
        if any(abs(g) > 100 for g in self.grades_um) or len(set(self.grades_um)) != len(
            self.grades_um
        ):
            raise ValueError("grades_um: distinct values within +-100 um")
        return self


class Analyses(StrictModel):
    selective_assembly: SelectiveAssemblySection = Field(
        description="which parts form each reducer, in which orientation"
    )
    pin_grading: PinGradingSection | None = Field(
        default=None, description="pin diameter grade per reducer for a backlash window"
    )


class Case(MeasuredPartsCase):
    lot: LotSection
    analyses: Analyses

    def _build(self) -> Any:
        return build_lot(self)


def build_lot(case: Case):
    """``(design reducer, Lot)`` of a validated ``rv_lot`` case (reads the measurement files).

    Parameters
    ----------
    case : Case
        A validated ``rv_lot`` case.
    """
    from gearte.errors import ParameterError
    from gearte.geometry.measured import MeasuredDisc
    from gearte.io import metrology as mt
    from gearte.runners.selective_assembly import Lot
    from gearte.studies._measured import check_measured_against_design

    _, red = case.design()
    m, n, zc = red.cranks.count, red.discs.count, red.cycloid_teeth
    lot, f = case.lot, case.lot.files
    for name, size in (("disc_sets", n), ("crank_sets", m)):
        for k, s in enumerate(getattr(lot, name)):
            if len(s) != size:
                raise ParameterError(f"lot.{name}[{k}]", s, f"needs {size} serials (the design)")

    def pick(table: dict, serials: list[str], file: str, what: str) -> list:
        missing = [s for s in serials if s not in table]
        if missing:
            raise ParameterError(f"lot.{what}", missing[:5], f"not in {file}")
        return [table[s] for s in serials]

    discs_flat = [s for ds in lot.disc_sets for s in ds]
    cranks_flat = [s for cs in lot.crank_sets for s in cs]
    prof = pitch = None
    if f.disc_profile is not None:
        prof = pick(
            mt.read_disc_profiles(f.disc_profile, teeth=zc), discs_flat, f.disc_profile, "disc_sets"
        )
    if f.disc_pitch is not None:
        pitch = pick(
            mt.read_disc_pitch(f.disc_pitch, teeth=zc), discs_flat, f.disc_pitch, "disc_sets"
        )
    measured = [
        None
        if prof is None and pitch is None
        else MeasuredDisc(
            zc,
            None if prof is None else prof[i].phase,
            None if prof is None else prof[i].deviation,
            None if pitch is None else pitch[i],
            s,
        )
        for i, s in enumerate(discs_flat)
    ]
    kd, kc = len(lot.disc_sets), len(lot.crank_sets)
    bores = None
    if f.disc_bores is not None:
        read_bores = mt.read_disc_bores(f.disc_bores, bores=m)
        check_measured_against_design(red, f.disc_bores, bores=read_bores)
        b = pick(read_bores, discs_flat, f.disc_bores, "disc_sets")
        bores = np.asarray(b).reshape(kd, n, m, 2)
    read_cams = mt.read_crank_eccentricity(f.crank_eccentricity, cams=n)
    check_measured_against_design(red, f.crank_eccentricity, cams=read_cams)
    cams = pick(read_cams, cranks_flat, f.crank_eccentricity, "crank_sets")
    ecc = np.asarray([c.eccentricity for c in cams]).reshape(kc, m, n)
    phase = np.asarray([c.phase for c in cams]).reshape(kc, m, n)
    planets = None
    if f.planet_runout is not None:
        ro = pick(mt.read_runout(f.planet_runout), cranks_flat, f.planet_runout, "crank_sets")
        planets = np.asarray([[r.runout, r.phase] for r in ro]).reshape(kc, m, 2)
    cam_c = car_c = None
    if f.bearing_clearance is not None:
        cl = pick(
            mt.read_bearing_clearances(f.bearing_clearance, cams=n),
            cranks_flat,
            f.bearing_clearance,
            "crank_sets",
        )
        cam_c = np.asarray([[c[f"cam_{j + 1}"] for j in range(n)] for c in cl]).reshape(kc, m, n)
        car_c = np.asarray([c["carrier"] for c in cl]).reshape(kc, m)
    out = Lot(
        [tuple(s) for s in lot.disc_sets],
        [tuple(measured[k * n : (k + 1) * n]) for k in range(kd)],
        bores,
        [tuple(s) for s in lot.crank_sets],
        ecc,
        phase,
        planets,
        cam_c,
        car_c,
    )
    out.check(red)
    return red, out


def preflight(case: Case) -> None:
    """The checks :func:`run` makes before any analysis (``gearte validate``,
    :func:`gearte.studies.run_case`): the design and the lot built from the measurement files
    and checked against the design (:func:`build_lot`, :meth:`Lot.check`). Validating the case
    already built it (kept for the run); a case built without validation is built here. The
    selective-assembly settings the runners check again (indexings, spec, objective, grading
    window) are bounded by the schema.

    Raises
    ------
    ParameterError, MeasurementFileError
        Naming the key or the file.
    """
    if case._built is None:
        case._built = build_lot(case)


def run(case: Case, options=None) -> StudyResult:
    """Selective assembly of the lot (and pin grading when asked).

    Parameters
    ----------
    case : Case
        A validated ``rv_lot`` case.
    options : gearte.studies.RunOptions, optional
        ``seed`` overrides the random assemblies' seed.
    """
    import time

    from gearte.models.rv_load_sharing import output_positions
    from gearte.runners import selective_assembly as sa
    from gearte.units import Nm_to_Nmm, arcmin_to_rad, arcsec_to_rad, rad_to_arcmin, rad_to_arcsec

    sec = case.analyses.selective_assembly
    red, lot = case._built if case._built is not None else build_lot(case)
    torque = float(Nm_to_Nmm(sec.torque_Nm))
    theta = output_positions(sec.positions)
    limit = float(arcsec_to_rad(sec.te_spec_arcsec))
    t0 = time.perf_counter()
    model = sa.linear_te_model(red, torque, theta)
    table = sa.score_lot(red, lot, model, sec.planet_indexings)
    t_score = time.perf_counter() - t0
    from gearte.execution import map_chunks
    from gearte.units import um_to_mm

    t_full = [0.0]

    def full_te(keys):
        """Full-model TE of pairings (disc set, disc orientation, crank set, crank
        orientation), on the local cores (or the run's scheduler)."""
        t = time.perf_counter()
        tasks = []
        for d, od, c, oc in keys:
            o = table.orientation(od, oc)
            tasks.append((sa.assembled_reducer(red, lot, d, c, o), torque, theta, True, None, None))
        done = map_chunks(
            sa.check_reducer, tasks, options=options, description="full model", unit="reducers"
        )
        t_full[0] += time.perf_counter() - t
        return np.array([x[0] for x in done])

    if sec.verify:
        rescored = sa.assign_rescored(table, limit, full_te, sec.objective)
        best, first = rescored.assembly, rescored.first
    else:
        rescored = None
        best = first = sa.assign(table, limit, sec.objective)
    t_assign = time.perf_counter() - t0 - t_score - t_full[0]
    seed = sec.seed if options is None or getattr(options, "seed", None) is None else options.seed
    rng = np.random.default_rng(seed)
    from gearte.studies import sample_cap

    n_random = sample_cap(sec, "random_assemblies", options)
    random_counts = sa.random_assemblies(table, limit, n_random, rng)
    orient = sa.orientation_only(table)
    n_red = best.disc_set.size
    grading = case.analyses.pin_grading
    grades = window = None
    if grading is not None:
        grades = np.asarray(grading.grades_um, dtype=float)
        window = tuple(float(arcmin_to_rad(v)) for v in grading.backlash_window_arcmin)
    tasks = []
    for r in range(n_red):
        o = table.orientation(int(best.disc_orientation[r]), int(best.crank_orientation[r]))
        reducer = sa.assembled_reducer(red, lot, int(best.disc_set[r]), int(best.crank_set[r]), o)
        tasks.append(
            (
                reducer,
                torque,
                theta,
                False,  # the full model's TE is known (rescored) or not asked for
                None if grades is None else um_to_mm(grades),
                window,
            )
        )
    # the pin grading of every reducer, on the local cores (or the scheduler of the run options)
    checked: list = (
        map_chunks(
            sa.check_reducer, tasks, options=options, description="reducers", unit="reducers"
        )
        if grading is not None
        else [(np.nan, None, None)] * n_red
    )
    full = best.pp if rescored is not None else np.full(n_red, np.nan)
    lin = rescored.linearised if rescored is not None else best.pp
    values: dict = {
        "reducers": n_red,
        "te_spec [arcsec]": sec.te_spec_arcsec,
        "reducers_in_spec": best.in_spec(limit),
        "reducers_in_spec_random_mean": float(random_counts.mean()),
        "reducers_in_spec_random_min": int(random_counts.min()),
        "reducers_in_spec_random_max": int(random_counts.max()),
        "reducers_in_spec_orientation_only": orient.in_spec(limit),
        "improvement_over_random": float(best.in_spec(limit) - random_counts.mean()),
        "improvement_over_orientation_only": best.in_spec(limit) - orient.in_spec(limit),
        "worst_te_peak_to_peak [arcsec]": float(rad_to_arcsec(best.pp.max())),
        "worst_te_peak_to_peak_orientation_only [arcsec]": float(rad_to_arcsec(orient.pp.max())),
        "random_assemblies": n_random,
        "objective": sec.objective,
        "pairings_scored": int(table.pp.size),
        "scoring_time [s]": t_score,
        "assignment_time [s]": t_assign,
        "rescoring_time [s]": t_full[0],
    }
    if rescored is not None:
        err = lin - full
        values["reducers_in_spec_full_model"] = int(np.sum(full <= limit))
        values["reducers_in_spec_linearised_only"] = first.in_spec(limit)
        values["linearised_minus_full_max [arcsec]"] = float(rad_to_arcsec(np.max(np.abs(err))))
        values["linearisation_error_mean [arcsec]"] = float(rad_to_arcsec(np.mean(err)))
        values["rescoring_rounds"] = rescored.rounds
        values["rescoring_stable"] = rescored.stable
        values["rescoring_certified"] = rescored.certified
        values["linearisation_margin [arcsec]"] = float(rad_to_arcsec(rescored.margin))
        values["full_model_evaluations"] = len(rescored.full)
    chosen = backlash = None
    if grading is not None:
        chosen = [c[1] for c in checked]
        backlash = [c[2] for c in checked]
    rows = []
    for r in range(n_red):
        d, c = int(best.disc_set[r]), int(best.crank_set[r])
        o = table.orientation(int(best.disc_orientation[r]), int(best.crank_orientation[r]))
        ds, cs = lot.disc_serials[d], lot.crank_serials[c]
        n, m = len(ds), len(cs)
        row: dict[str, object] = {"reducer": f"R-{r + 1:04d}"}
        for j in range(n):
            row[f"disc_slot_{j + 1}"] = ds[(j + o.disc_shift) % n]
        row["disc_bore_1_on_crank_position"] = 1 + o.disc_index
        for i in range(m):
            row[f"crank_position_{i + 1}"] = cs[(i - o.crank_shift) % m]
        if sec.planet_indexings > 1 and lot.planet_runout is not None:
            row["planet_spline_index"] = o.planet_index
        row["te_peak_to_peak [arcsec]"] = round(float(rad_to_arcsec(best.pp[r])), 3)
        if rescored is not None:
            row["te_peak_to_peak_full_model [arcsec]"] = round(float(rad_to_arcsec(full[r])), 3)
            row["te_peak_to_peak_linearised [arcsec]"] = round(float(rad_to_arcsec(lin[r])), 3)
            row["linearisation_error [arcsec]"] = round(float(rad_to_arcsec(lin[r] - full[r])), 3)
        row["in_spec"] = bool(best.pp[r] <= limit)
        if grading is not None and grades is not None and chosen and backlash is not None:
            g = chosen[r]
            row["pin_grade [um]"] = None if g is None else float(grades[g])
            row["backlash [arcmin]"] = (
                None if g is None else round(float(rad_to_arcmin(backlash[r][g])), 4)
            )
        rows.append(row)
    csv = _csv(rows)
    notes = [
        "Scores: loaded TE peak-to-peak over one output revolution of every disc set × "
        "orientation × crank set × orientation from the one RV model linearised about the "
        "design's loaded equilibrium (part errors enter exactly linearly; the contact set and "
        "stiffness are the design's); random and orientation-only use these scores. "
        + (
            "The optimiser's chosen pairings re-scored with the full non-linear model "
            "(measured bearing clearances included) and the assignment solved again on the "
            "corrected scores until it chose only pairings the full model had scored "
            f"({values['rescoring_rounds']} rounds, {values['full_model_evaluations']} "
            "pairings solved by the full model), then once more with the pairings not scored "
            "counted at their linearised TE less the largest over-estimate seen "
            f"({values['linearisation_margin [arcsec]']:.2f}″; certified: "
            f"{'yes' if rescored.certified else 'no, round limit'}); the assembly best by the "
            "full model is kept. reducers_in_spec and each reducer's TE are the full model's; "
            "reducers_in_spec_linearised_only is the first round's claim, "
            "linearisation_error [arcsec] per reducer the linearised minus the full TE."
            if rescored is not None
            else "verify = false: reducers_in_spec and the TE are the linearised scores."
        ),
        f"Assignment: {sec.objective} solved exactly on the scores (scipy "
        "linear_sum_assignment; bottleneck "
        "bisection for 'worst'); random: random pairing and random orientation, mean over "
        f"{n_random} assemblies (seed {seed}); orientation-only: disc set k with "
        "crank set k, each in its best orientation.",
        f"The optimiser puts {values['reducers_in_spec']} of {n_red} reducers in spec against "
        f"{values['reducers_in_spec_random_mean']:.2f} for random assembly and "
        f"{values['reducers_in_spec_orientation_only']} for orientation only.",
    ]
    out = [
        AnalysisResult(
            name="selective_assembly",
            title="Selective assembly of the lot",
            values=values | {"assembly_instructions": rows},
            references=[],
            notes=notes,
            data={
                "table": table,
                "best": best,
                "orientation_only": orient,
                "random": random_counts,
                "full": full,
                "limit": limit,
            },  # fmt: skip
            files={"assembly_instructions.csv": csv},
        )
    ]
    if grading is not None and chosen is not None and backlash is not None and grades is not None:
        lo, hi = grading.backlash_window_arcmin
        out.append(
            AnalysisResult(
                name="pin_grading",
                title="Pin diameter grade per reducer for the backlash window",
                values={
                    "backlash_window [arcmin]": [lo, hi],
                    "reducers_graded": int(sum(g is not None for g in chosen)),
                    "reducers_without_grade": int(sum(g is None for g in chosen)),
                    "pin_grades": [
                        {
                            "reducer": f"R-{r + 1:04d}",
                            "grade [um]": None if chosen[r] is None else float(grades[chosen[r]]),
                            **{
                                f"backlash_at_{g:+g}um [arcmin]": round(
                                    float(rad_to_arcmin(backlash[r][i])), 4
                                )
                                for i, g in enumerate(grades)
                            },
                        }
                        for r in range(n_red)
                    ],
                },
                references=[],
                notes=[
                    "Backlash of each assembled reducer from the model's virtual torsion test "
                    "(catalogue definition θ(0+) − θ(0−) at output angle 0) with every pin "
                    "diameter grade added to all its pins; the grade inside the window nearest "
                    "its centre is chosen (none where no grade fits)."
                ],
            )
        )
    warnings = []
    if rescored is not None and not rescored.stable:
        warnings.append(
            f"the re-scored assignment did not settle in {rescored.rounds} rounds: its last "
            "choice is reported with the full model's TE, but a better one may exist"
        )
    return StudyResult(case=case, analyses=out, warnings=warnings)


def _csv(rows: list[dict]) -> str:
    keys = list(rows[0])
    lines = [",".join(keys)]
    for r in rows:
        lines.append(",".join("" if r[k] is None else str(r[k]) for k in keys))
    return "\n".join(lines) + "\n"
