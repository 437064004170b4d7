"""Study kind ``rv_bench``: one RV serial's bench data → catalogue numbers (from the hysteresis
curve and from the load series of TE traces), labelled TE orders tracked across the series,
calibrated reduced model and the calibrated serial closed through the whole model, likely
culprit parts.

Case file::

    [case]    kind = "rv_bench", title, references
    [reducer] case = "<bundled rv_reducer case or path>"   the drive's description: tooth numbers
                                                           (order labels), rated torque, the whole
                                                           model behind the reduced one
    [data]    te = "<CSV file or folder of operating points>", hysteresis = "<CSV file>"
              (paths relative to the case file, else to the bundled examples),
              torque_noise_fraction (torque sensor, × T_r),
              columns = {gearte column = "rig's name"}, units = {column or group = "unit"},
              file_name_pattern = "{torque}Nm_{speed}rpm_{temp}C",
              te_convention ("nominal_minus_output" | "output_minus_nominal"), reference
    [analyses.catalogue]    lost_motion_fraction (0.03)
    [analyses.load_series]  temperature_step_C (5)
    [analyses.te_orders]    n_orders (12), tracked_orders (8), unexplained_fraction (0.05)
    [analyses.calibration]  families, fit, encoder_eccentricity_arcsec,
                            rig_compliance_arcsec_per_kNm
    [analyses.diagnosis]    draws, seed

Definitions: docs/bench.md. Results: per (speed, oil temperature) of a load series
``bench_torsional_rigidity [N*m/arcmin]``, ``bench_lost_motion [arcmin]``,
``bench_hysteresis [arcmin]``, ``bench_backlash [arcmin]`` with ``_ci_low``/``_ci_high``;
``angular_te_peak_to_peak_forward [arcsec]``,
``angular_te_peak_to_peak_backward [arcsec]``, ``forward_backward_difference_mean [arcsec]``,
``te_orders`` (order, ``amplitude [arcsec]``, ``phase [deg]``, source) and per operating point.
"""

from __future__ import annotations

import re
from pathlib import Path
from typing import Any, Literal

import numpy as np
from pydantic import Field, ValidationInfo, field_validator, model_validator

from gearte.io.schema import CaseBase, StrictModel
from gearte.results import AnalysisResult, StudyResult
from gearte.units import (
    ARCMIN_PER_RAD,
    ARCSEC_PER_RAD,
    DEG_PER_RAD,
    Nm_to_Nmm,
    arcsec_to_rad,
    mm_to_um,
    rad_to_deg,
)

KIND = "rv_bench"
REFERENCES = ["li2023"]
FIGURES = "gearte.plotting.rv_bench"

FamilyName = Literal[
    "output rotation", "crank rotation", "2× crank rotation", "involute mesh", "cycloid mesh",
    "input rotation", "cycloid lobes",
]  # fmt: skip
_DEFAULT_FAMILIES: list[FamilyName] = [
    "output rotation", "crank rotation", "2× crank rotation", "involute mesh", "cycloid mesh",
]  # fmt: skip


def _resolve(value: str, info: ValidationInfo) -> str:
    """A data path: absolute, or relative to the case file's folder, or (like a bundled case
    name) relative to the bundled examples."""
    from gearte.cases import examples_dir

    def exists(q: Path) -> bool:
        try:
            return q.exists()
        except (OSError, ValueError):  # a name too long, a NUL byte: not a usable path
            return False

    p = Path(value).expanduser()
    if not p.is_absolute():
        case_dir = (info.context or {}).get("case_dir")
        beside = (Path(case_dir) if case_dir else Path.cwd()) / p
        bundled = examples_dir() / p
        p = beside if exists(beside) or not exists(bundled) else bundled
    if not exists(p):
        shown = str(p) if len(str(p)) <= 200 else str(p)[:200] + "..."
        raise ValueError(f"no file or folder {shown!r}")
    return str(p)


class ReducerRef(StrictModel):
    """The drive: a bundled ``rv_reducer`` case name or a path to one."""

    case: str = Field(min_length=1, description="rv_reducer case (name or path)")

    @field_validator("case")
    @classmethod
    def _exists(cls, v: str, info: ValidationInfo) -> str:
        from gearte.cases import list_cases

        if v in list_cases() or v.removesuffix(".toml") in list_cases():
            return v
        path = _resolve(v, info)
        if not Path(path).is_file():  # a folder: not a case file
            raise ValueError(f"{path!r} is a folder, not a case file")
        return path


class DataSection(StrictModel):
    te: str | None = Field(default=None, description="TE trace CSV or a folder of them")
    hysteresis: str | None = Field(default=None, description="hysteresis CSV")
    torque_noise_fraction: float = Field(
        default=0.0, ge=0.0, le=0.05, description="torque sensor noise (std) as a fraction of T_r"
    )
    columns: dict[str, str] = Field(
        default_factory=dict,
        description='gearte column -> the rig\'s column name, e.g. {forward_te = "TE CW"} '
        "(beside the built-in aliases).",
    )
    units: dict[str, str] = Field(
        default_factory=dict,
        description="Unit of columns written without one: per gearte column, per group "
        "(position, te, angle, torque) or per file column name.",
    )
    file_name_pattern: str | None = Field(
        default=None,
        description='Operating point in the TE file names, e.g. "{torque}Nm_{speed}rpm_{temp}C" '
        "(torque [N*m], speed [rpm], oil temperature [°C]; {*} any text).",
    )
    te_convention: Literal["nominal_minus_output", "output_minus_nominal"] = Field(
        default="nominal_minus_output",
        description="The files' TE sign: gearte's nominal − output (a loaded reducer lags, "
        "TE_forward > TE_backward), or output − nominal (negated on reading).",
    )
    reference: str | None = Field(
        default=None,
        description="File name of the TE trace the single-trace analyses (orders, calibration) "
        "use; default: the least loaded, then slowest, then coolest file (stated in results).",
    )

    def import_options(self):
        """The readers' :class:`gearte.io.bench.ImportOptions` of this section."""
        from gearte.io.bench import ImportOptions

        return ImportOptions(
            columns=dict(self.columns), units=dict(self.units),
            file_name_pattern=self.file_name_pattern, te_convention=self.te_convention,
        )  # fmt: skip

    @model_validator(mode="after")
    def _options(self) -> DataSection:
        from gearte.errors import ParameterError

        try:
            self.import_options()
        except ParameterError as exc:
            raise ValueError(str(exc)) from None
        return self

    @field_validator("te", "hysteresis")
    @classmethod
    def _paths(cls, v: str | None, info: ValidationInfo) -> str | None:
        return None if v is None else _resolve(v, info)

    @model_validator(mode="after")
    def _something(self) -> DataSection:
        if self.te is None and self.hysteresis is None:
            raise ValueError("give te and/or hysteresis")
        return self


class CatalogueSection(StrictModel):
    lost_motion_fraction: float = Field(
        default=0.03,
        gt=0.0,
        lt=0.5,
        description="Lost motion between ±fraction × rated torque [-] (0.03 or 0.05 in "
        "catalogues).",
    )


class LoadSeriesSection(StrictModel):
    temperature_step_C: float = Field(
        default=5.0,
        gt=0.0,
        le=100.0,
        description="Operating points whose oil temperatures round to the same multiple of this "
        "step form one series [°C].",
    )


class OrdersSection(StrictModel):
    n_orders: int = Field(
        default=12, ge=1, le=200, description="Largest TE orders listed per trace."
    )
    tracked_orders: int = Field(
        default=8,
        ge=1,
        le=50,
        description="Orders tracked across the files of a series (the largest over all files).",
    )
    unexplained_fraction: float = Field(
        default=0.05,
        gt=0.0,
        le=1.0,
        description="A line no tooth number explains is reported when its amplitude reaches this "
        "share of the trace's peak-to-peak (and 4 x the spectrum's noise floor) [-].",
    )


class CalibrationSection(StrictModel):
    families: list[FamilyName] = Field(
        default_factory=lambda: list(_DEFAULT_FAMILIES),
        description="Parameter families the calibration may fit.",
    )
    fit: list[str] | None = Field(default=None, description="parameters to fit (default all)")
    encoder_eccentricity_arcsec: tuple[float, float] | None = Field(
        default=None, description="known (cos, sin) of the output encoder's eccentricity"
    )
    rig_compliance_arcsec_per_kNm: float | None = Field(
        default=None,
        ge=0.0,
        le=1e4,
        description="Known test-rig compliance [arcsec/kN·m], held fixed (default: fitted).",
    )
    max_relative_ci: float = Field(
        default=0.25,
        gt=0.0,
        le=10.0,
        description="A parameter whose 95 % half-width exceeds this fraction of its range is "
        "flagged poorly identified [-].",
    )


class DiagnosisSection(StrictModel):
    draws: int = Field(
        default=2000,
        ge=100,
        le=100_000,
        description="Parameter draws from the calibration's Gaussian.",
    )
    seed: int = Field(default=0, ge=0, description="Seed of the draws.")


class Analyses(StrictModel):
    catalogue: CatalogueSection | None = Field(
        None,
        description="Catalogue numbers from the hysteresis curve (rigidity, lost motion, "
        "backlash).",
    )
    load_series: LoadSeriesSection | None = Field(
        None,
        description="Rigidity, lost motion, hysteresis and backlash from the TE traces against "
        "torque, per speed and oil temperature (runs whenever the TE files form a series).",
    )
    te_orders: OrdersSection | None = Field(
        None, description="TE orders labelled from the drive's tooth numbers."
    )
    calibration: CalibrationSection | None = Field(
        None, description="Reduced-model calibration to this serial's data."
    )
    diagnosis: DiagnosisSection | None = Field(
        None, description="Likely culprit parts, from the calibration's uncertainty."
    )

    @model_validator(mode="after")
    def _diagnosis_needs_calibration(self) -> Analyses:
        if self.diagnosis is not None and self.calibration is None:
            raise ValueError("diagnosis reads the calibration: add [analyses.calibration]")
        return self


class Case(CaseBase):
    reducer: ReducerRef
    data: DataSection
    analyses: Analyses = Field(default_factory=Analyses)


# ---- run ----------------------------------------------------------------------------------
def _reducer(ref: ReducerRef):
    from gearte.errors import ParameterError
    from gearte.io.case_file import load_case
    from gearte.studies.rv_reducer import build_reducer

    rcase: Any = load_case(ref.case)
    if rcase.case.kind != "rv_reducer":
        raise ParameterError(
            "reducer.case", ref.case, f"is a {rcase.case.kind!r} case; need rv_reducer"
        )
    return build_reducer(rcase.reducer), rcase


def _sec(x):
    return x * ARCSEC_PER_RAD


def _inputs(case: Case):
    """``(reducer, its case, characteristic orders, TE traces, hysteresis curve)``: the
    reducer case loaded and built, the bench files read (:mod:`gearte.io.bench`)."""
    from gearte.io.bench import read_hysteresis, read_te_folder, read_te_trace
    from gearte.models.orders import rv_tooth_orders

    reducer, rcase = _reducer(case.reducer)
    fs = reducer.first_stage
    sources = rv_tooth_orders(fs.sun_teeth, fs.planet_teeth, reducer.pins.count)
    from gearte.errors import BenchFileError, BenchFileErrors

    d = case.data
    opts = d.import_options()
    traces: list = []
    hyst = None
    problems: list[BenchFileError] = []  # every file's problems, reported together
    if d.te is not None:
        try:
            traces = (read_te_folder(d.te, options=opts) if Path(d.te).is_dir()
                      else [read_te_trace(d.te, opts)])  # fmt: skip
        except BenchFileError as exc:
            problems.append(exc)
    if d.hysteresis is not None:
        try:
            hyst = read_hysteresis(d.hysteresis, opts)
        except BenchFileError as exc:
            problems.append(exc)
    if traces and d.reference is not None:
        names = [Path(t.source).name for t in traces]
        if d.reference not in names:
            problems.append(BenchFileError(
                d.te or "", None, None,
                f"reference {d.reference!r} is not one of the TE files ({', '.join(names)})",
            ))  # fmt: skip
    if len(problems) == 1:
        raise problems[0]
    if problems:
        raise BenchFileErrors(problems)
    return reducer, rcase, sources, traces, hyst


def preflight(case: Case) -> None:
    """The checks :func:`run` makes before any analysis (``gearte validate``,
    :func:`gearte.studies.run_case`): the reducer case is loaded and built, and the bench files
    are read by the readers the run uses (:func:`_inputs`; a malformed file is one line naming
    file, line and column), without any analysis. (``run`` reads them again: a few hundred ms
    for the bundled bench.)

    Raises
    ------
    ParameterError, BenchFileError
        Naming the key or the file.
    """
    _inputs(case)


def run(case: Case, options) -> StudyResult:
    reducer, rcase, sources, traces, hyst = _inputs(case)
    ref = _reference(traces, case.data.reference) if traces else None
    why = reference_reason(traces, ref, case.data.reference) if traces else ""
    a = case.analyses
    analyses: list[AnalysisResult] = []
    warnings: list[str] = []
    analyses.append(_catalogue(reducer, traces, hyst, a.catalogue or CatalogueSection(), ref, why))
    lmf = (a.catalogue or CatalogueSection()).lost_motion_fraction
    series = _load_series(traces, reducer, a.load_series or LoadSeriesSection(), lmf, warnings)
    if series is not None:
        analyses.append(series)
    if traces:
        analyses.append(_orders(traces, sources, a.te_orders or OrdersSection(), ref, warnings))
    if a.calibration is not None:
        cal_res, cal = _calibration(
            case, reducer, rcase, sources, ref, hyst, warnings, analyses, traces
        )
        analyses.append(cal_res)
        if a.diagnosis is not None:
            analyses.append(_diagnosis(cal, analyses, a.diagnosis, a.catalogue, options))
    return StudyResult(case=case, analyses=analyses, warnings=warnings)


def _reference(traces, name: str | None = None):
    """The trace the single-trace analyses use: the file ``name`` (``[data] reference``), else
    the least loaded, then slowest, then coolest one (then the file name, for a stable choice
    among equal operating points); :func:`reference_reason` says which rule chose it."""
    if name is not None:
        for t in traces:
            if Path(t.source).name == name:
                return t
    return min(traces, key=_reference_key)


def _reference_key(t):
    return (abs(t.torque) if t.torque is not None else 0.0,
            t.speed_rpm if t.speed_rpm is not None else 0.0,
            t.oil_temperature if t.oil_temperature is not None else 0.0,
            Path(t.source).name)  # fmt: skip


def reference_reason(traces, ref, name: str | None = None) -> str:
    """Why ``ref`` is the reference trace, in words (``name``: the case's ``[data] reference``)."""
    if len(traces) == 1:
        return "the only TE file"
    if name is not None:
        return "chosen in the case ([data] reference)"
    ties = [t for t in traces if _reference_key(t)[:3] == _reference_key(ref)[:3]]
    why = "least loaded, then slowest, then coolest operating point"
    if len(ties) > 1:
        why += f" ({len(ties)} files at this operating point: the first by file name)"
    return why + "; set [data] reference to choose another"


def te_values(trace) -> dict:
    """Catalogue TE quantities of one trace [arcsec] (shared definitions)."""
    from gearte.models.catalogue import forward_backward_difference, te_peak_to_peak

    out = {}
    dirs = trace.directions()
    for name, (_, te) in dirs.items():
        out[f"angular_te_peak_to_peak_{name} [arcsec]"] = _sec(te_peak_to_peak(te))
    if len(dirs) == 2:
        diff = forward_backward_difference(*dirs["forward"], *dirs["backward"])
        out["forward_backward_difference_mean [arcsec]"] = _sec(float(diff.mean()))
        out["forward_backward_difference_peak_to_peak [arcsec]"] = _sec(float(np.ptp(diff)))
    return out


def _catalogue(reducer, traces, hyst, sec: CatalogueSection, ref=None, why="") -> AnalysisResult:
    from gearte.models.catalogue import branch_directions, hysteresis_values

    values: dict = {}
    data: dict = {}
    notes = ["Definitions in docs/bench.md (gearte.models.catalogue), shared with the virtual "
             "test of the rv_reducer kind."]  # fmt: skip
    if traces:
        ref = ref if ref is not None else _reference(traces)
        values["reference_operating_point"] = Path(ref.source).name
        values["reference_reason"] = why or reference_reason(traces, ref)
        from gearte.io.bench import TE_CONVENTION

        values["te_convention"] = TE_CONVENTION
        values["te_convention_of_files"] = ref.metadata.get("te_convention", TE_CONVENTION)
        values.update(te_values(ref))
        if len(traces) > 1:
            values["operating_points"] = [
                {"file": Path(t.source).name, "speed [rpm]": t.speed_rpm,
                 "torque [N·m]": None if t.torque is None else t.torque / float(Nm_to_Nmm(1.0)),
                 "oil_temperature [°C]": t.oil_temperature, **te_values(t)}
                for t in traces
            ]  # fmt: skip
        data["traces"] = traces
    if hyst is not None:
        direction = hyst.branch if hyst.branch is not None else branch_directions(hyst.torque)
        hv = hysteresis_values(
            hyst.torque, hyst.angle, reducer.rated_torque, direction=direction,
            lost_motion_fraction=sec.lost_motion_fraction,
        )  # fmt: skip
        per_arcmin = float(Nm_to_Nmm(1.0)) * ARCMIN_PER_RAD
        values.update({
            "torsional_rigidity [N·m/arcmin]": hv.torsional_rigidity / per_arcmin,
            "lost_motion [arcmin]": hv.lost_motion * ARCMIN_PER_RAD,
            "lost_motion_fraction": sec.lost_motion_fraction,
            "backlash [arcmin]": hv.backlash * ARCMIN_PER_RAD,
            "hysteresis_loss [arcmin]": hv.hysteresis_loss * ARCMIN_PER_RAD,
            "rated_torque [N·m]": reducer.rated_torque / float(Nm_to_Nmm(1.0)),
        })  # fmt: skip
        data["hysteresis"] = (hyst, direction)
    return AnalysisResult(
        name="catalogue", title="Catalogue quantities from the bench data", values=values,
        notes=notes, data=data,
    )  # fmt: skip


def _series_point(t) -> dict:
    """Forward−backward mean ``D``, mean TE and the standard error of ``D`` of one trace [rad]."""
    from gearte.models.orders import mean_standard_error, order_spectrum

    dirs = t.directions()
    means, ses = {}, {}
    for name, (pos, te) in dirs.items():
        _, amp, _ = order_spectrum(pos, te)
        means[name] = float(amp[0])
        ses[name] = mean_standard_error(amp)
    return {
        "D": means["forward"] - means["backward"],
        "mean": 0.5 * (means["forward"] + means["backward"]),
        "se": float(np.hypot(ses["forward"], ses["backward"])),
    }


def _load_series(traces, reducer, sec: LoadSeriesSection, lmf: float, warnings):
    """The load-series analysis (:func:`gearte.models.catalogue.load_series_values`) of every
    (speed, oil temperature) group with >= 2 torques; ``None`` without such a group."""
    from gearte.models.catalogue import load_series_values
    from gearte.units import Nmm_per_rad_to_Nm_per_arcmin, Nmm_to_Nm, rad_to_arcmin

    per_arcmin = Nmm_per_rad_to_Nm_per_arcmin
    usable = [t for t in traces if t.torque is not None and len(t.directions()) == 2]
    if len(usable) < 2:
        return None
    groups: dict = {}
    for t in usable:
        step = sec.temperature_step_C
        temp = None if t.oil_temperature is None else float(step * round(t.oil_temperature / step))
        groups.setdefault((t.speed_rpm, temp), []).append(t)
    rows, points = [], []
    negative = 0
    for (speed, temp), ts in sorted(groups.items(), key=lambda kv: (kv[0][0] or 0, kv[0][1] or 0)):
        pts = [_series_point(t) for t in ts]
        torque = np.array([abs(t.torque) for t in ts])
        for t, pt in zip(ts, pts, strict=True):
            negative += pt["D"] < 0
            points.append({"file": Path(t.source).name, "speed [rpm]": speed,
                           "oil_temperature [°C]": temp,
                           "torque [N*m]": float(Nmm_to_Nm(abs(t.torque))),
                           "forward_backward_difference_mean [arcsec]": _sec(pt["D"]),
                           "mean_te [arcsec]": _sec(pt["mean"]),
                           "forward_backward_difference_se [arcsec]": _sec(pt["se"])})  # fmt: skip
        if np.unique(torque).size < 2:
            continue
        v = load_series_values(
            torque, [p["D"] for p in pts], reducer.rated_torque,
            standard_error=[p["se"] for p in pts], lost_motion_fraction=lmf,
        )  # fmt: skip
        row: dict = {"speed [rpm]": speed, "oil_temperature [°C]": temp,
                     "torques [N*m]": sorted({float(Nmm_to_Nm(x)) for x in torque})}  # fmt: skip
        for name, val, conv, unit in (
            ("torsional_rigidity", v.torsional_rigidity, per_arcmin, "N*m/arcmin"),
            ("lost_motion", v.lost_motion, rad_to_arcmin, "arcmin"),
            ("hysteresis", v.hysteresis, rad_to_arcmin, "arcmin"),
            ("backlash", v.backlash, rad_to_arcmin, "arcmin"),
        ):  # fmt: skip
            lo, hi = v.ci[name]
            if name == "torsional_rigidity":
                lo, hi = hi, lo  # (low, high) of K come from the compliance's (high, low)
                lo, hi = min(lo, hi), max(lo, hi)
            fin = lambda x, c=conv: float(c(x)) if np.isfinite(x) else None  # noqa: E731
            row[f"bench_{name} [{unit}]"] = fin(val)
            row[f"bench_{name}_ci_low [{unit}]"] = fin(lo)
            row[f"bench_{name}_ci_high [{unit}]"] = fin(hi)
        row["interpolated"] = list(v.interpolated)
        row["not_available"] = dict(v.missing)
        rows.append(row)
    if not rows:
        return None
    if negative > len(points) / 2:
        warnings.append(
            f"load series: the forward−backward mean is negative in {negative} of {len(points)} "
            "files; gearte's TE convention (nominal − output) makes it positive for a lagging "
            "reducer: are the files output − nominal? (set [data] te_convention = "
            '"output_minus_nominal")'
        )
    return AnalysisResult(
        name="load_series",
        title="Load series: rigidity, lost motion, hysteresis, backlash from TE against torque",
        values={"series": rows, "operating_points": points, "lost_motion_fraction": lmf},
        notes=[
            "Definitions in docs/bench.md (gearte.models.catalogue.load_series_values): the "
            "catalogue's hysteresis definitions read on the running curve θ(+T) = mean forward "
            "TE, θ(−T) = mean backward TE; load torques oppose the motion in both directions.",
            "95 % intervals from each trace's noise (its order spectrum's floor), propagated "
            "linearly; not the repeatability between runs, nor an interpolation error (quantities "
            "read between measured torques are listed under 'interpolated').",
        ],
        data={"points": points, "series": rows},
    )


def order_list(trace, direction: str, sources, n_orders: int) -> list[dict]:
    from gearte.models.orders import labelled_orders, order_spectrum

    pos, te = trace.directions()[direction]
    o, amp, ph = order_spectrum(pos, te)
    return [
        {"order": x["order"], "amplitude [arcsec]": _sec(x["amplitude"]),
         "phase [deg]": x["phase"] * DEG_PER_RAD, "source": x["source"]}
        for x in labelled_orders(o, amp, ph, sources, n_orders)
    ]  # fmt: skip


def _orders(traces, sources, sec: OrdersSection, ref=None, warnings=None) -> AnalysisResult:
    from gearte.models.orders import (
        label_order,
        labelled_orders,
        order_spectrum,
        unexplained_lines,
    )

    ref = ref if ref is not None else _reference(traces)
    dirs = ref.directions()
    first = "forward" if "forward" in dirs else "backward"
    values: dict = {
        "characteristic_orders": {k: float(v) for k, v in sources.items()},
        "te_orders": order_list(ref, first, sources, sec.n_orders),
    }
    if "backward" in dirs and first == "forward":
        values["te_orders_backward"] = order_list(ref, "backward", sources, sec.n_orders)
    # every file: its spectrum, its unexplained lines (arcsec, relative to its own trace)
    spectra = []
    unexplained: dict[int, list] = {}
    for t in traces:
        d = first if first in t.directions() else next(iter(t.directions()))
        pos, te = t.directions()[d]
        o, amp, ph = order_spectrum(pos, te)
        spectra.append(amp)
        lines = labelled_orders(o, amp, ph, sources, sec.n_orders)
        p2p = float(np.ptp(te))
        floor = float(np.median(amp[1:]))
        for x in unexplained_lines(lines, p2p, floor, fraction=sec.unexplained_fraction):
            unexplained.setdefault(x["order"], []).append(
                (Path(t.source).name, x["amplitude"], p2p)
            )
    rows_u = []
    for n, hits in sorted(unexplained.items()):
        top = max(hits, key=lambda h: h[1])
        rows_u.append({"order": n, "files": len(hits), "largest_amplitude [arcsec]": _sec(top[1]),
                       "share_of_peak_to_peak": top[1] / top[2], "file": top[0]})  # fmt: skip
        if warnings is not None:
            warnings.append(
                f"TE orders: order {n} matches no order of this drive's tooth numbers and carries "
                f"up to {_sec(top[1]):.3g}″ ({100 * top[1] / top[2]:.0f} % of the trace's "
                f"{_sec(top[2]):.3g}″ peak-to-peak; {len(hits)} of {len(traces)} file(s), largest "
                f"in {top[0]}): the rig, or a part not modelled"
            )
    values["unexplained_lines"] = rows_u
    _, ref_amp, _ = order_spectrum(*dirs[first])
    ref_limit = max(sec.unexplained_fraction * float(np.ptp(dirs[first][1])),
                    4.0 * float(np.median(ref_amp[1:])))  # fmt: skip
    trend: dict = {}
    if len(traces) > 1:
        size = min(a.size for a in spectra)
        peak = np.max(np.vstack([a[:size] for a in spectra]), axis=0)
        peak[0] = 0.0
        floor = float(np.median(np.vstack([a[1:size] for a in spectra])))
        tracked = [int(i) for i in np.argsort(peak)[::-1][: sec.tracked_orders]
                   if peak[i] >= 4.0 * floor]  # fmt: skip
        labels = {f"{n}: {label_order(n, sources)}": n for n in sorted(tracked)}
        rows = []
        for t, amp in zip(traces, spectra, strict=True):
            rows.append({
                "file": Path(t.source).name, "speed [rpm]": t.speed_rpm,
                "torque [N·m]": None if t.torque is None else t.torque / float(Nm_to_Nmm(1.0)),
                "oil_temperature [°C]": t.oil_temperature,
                "amplitude [arcsec]": {k: _sec(float(amp[n])) for k, n in labels.items()},
            })  # fmt: skip
        values["order_trend"] = rows
        trend = {"rows": rows, "labels": labels}
    return AnalysisResult(
        name="te_orders", title="Order spectrum of the measured TE (per output revolution)",
        values=values,
        notes=[f"{first} trace of {Path(ref.source).name}; amplitude of TE = mean + Σ A cos(kφ + "
               "phase); orders labelled from the drive's tooth numbers, their harmonics and "
               "sidebands (gearte.models.orders.label_order); order_trend: the largest orders "
               "over all files, tracked in every file."],
        data={"reference": ref, "direction": first, "sources": sources, "trend": trend,
              "unexplained_limit": ref_limit},
    )  # fmt: skip


def _calibration(case, reducer, rcase, sources, ref_trace, hyst, warnings, analyses, traces):
    from gearte.runners.bench_calibration import (
        Z95,
        calibrate,
        reduced_constants,
    )

    sec = case.analyses.calibration
    fams = {}
    for f in sec.families:
        n = sources["crank rotation"] * 2 if f == "2× crank rotation" else sources[f]
        if abs(n - round(n)) > 1e-9:
            warnings.append(f"calibration: family {f!r} has the non-integer order {n:.4g} per "
                            "output revolution and is left out")  # fmt: skip
            continue
        fams[f] = int(round(n))
    model = reduced_constants(reducer, fams)
    fixed = {}
    if sec.encoder_eccentricity_arcsec is not None:
        fixed["encoder_eccentricity_cos"] = arcsec_to_rad(sec.encoder_eccentricity_arcsec[0])
        fixed["encoder_eccentricity_sin"] = arcsec_to_rad(sec.encoder_eccentricity_arcsec[1])
    if sec.rig_compliance_arcsec_per_kNm is not None:
        fixed["rig_compliance"] = arcsec_to_rad(sec.rig_compliance_arcsec_per_kNm) / float(
            Nm_to_Nmm(1000.0)
        )
    ref = [ref_trace] if ref_trace is not None else []
    cal = calibrate(
        model, hyst, ref, fit=sec.fit, fixed=fixed, max_relative_ci=sec.max_relative_ci,
        torque_noise=case.data.torque_noise_fraction,
    )  # fmt: skip
    params = reported_parameters(cal)
    families = {}
    fitted = list(cal.fitted)
    for fam in (*fams, "encoder eccentricity"):
        kc, ks = (f"{fam.replace(' ', '_')}_{x}" for x in ("cos", "sin"))
        if kc not in fitted or ks not in fitted:
            continue
        a, b = cal.params[kc], cal.params[ks]
        amp = float(np.hypot(a, b))
        ident = kc not in cal.flags and ks not in cal.flags
        ci = None
        if ident and amp > 0:
            i, j = fitted.index(kc), fitted.index(ks)
            g = np.array([a, b]) / amp
            cov = cal.covariance[np.ix_([i, j], [i, j])]
            ci = _sec(Z95 * float(np.sqrt(max(g @ cov @ g, 0.0))))
        families[fam] = {
            "amplitude [arcsec]": _sec(amp), "phase [deg]": float(rad_to_deg(np.arctan2(-b, a))),
            "amplitude_ci95 [arcsec]": ci, "identified": ident,
        }  # fmt: skip
    values = {
        "error_families": families,
        "parameters": params,
        "unidentifiable_groups": [list(g) for g in cal.groups],
        "jacobian_rank": cal.rank,
        "parameters_fitted": len(cal.fitted),
        "jacobian_condition": cal.condition if np.isfinite(cal.condition) else None,
        "residual_rms [arcsec]": {k: _sec(v) for k, v in cal.residual_rms.items()},
        "correlation": {"names": list(cal.fitted),
                        "matrix": np.round(np.nan_to_num(cal.correlation), 4).tolist()},
        "model_constants": {
            "nominal_rigidity [N·m/arcmin]": model.nominal_rigidity
            / (float(Nm_to_Nmm(1.0)) * ARCMIN_PER_RAD),
            "backlash_per_clearance [arcmin/um]": [
                g * ARCMIN_PER_RAD / float(mm_to_um(1.0)) for g in model.backlash_per_clearance
            ],
            "family_orders": fams,
        },
        "solver": cal.message,
    }  # fmt: skip
    lmf = (case.analyses.catalogue or CatalogueSection()).lost_motion_fraction
    noise = _noise(hyst, [ref_trace] if ref_trace is not None else [])
    values["data_noise [arcsec]"] = {k: _sec(v) for k, v in noise.items()}
    for k, r in cal.residual_rms.items():
        if k in noise and noise[k] > 0 and r > RESIDUAL_WARNING * noise[k]:
            warnings.append(
                f"calibration: the {k} residual ({_sec(r):.3g}″ rms) is {r / noise[k]:.1f}× the "
                f"data's noise ({_sec(noise[k]):.3g}″): the reduced model does not describe this "
                "serial (a law or an error family missing); its intervals understate the "
                "uncertainty"
            )
    closed, record = _close_loop(case, reducer, cal, analyses, lmf, warnings)
    values["round_trip"] = record["round_trip"]
    values["calibrated_serial"] = {
        k: v for k, v in record.items() if k not in ("round_trip", "parameters")
    }
    res = AnalysisResult(
        name="calibration",
        title="Calibrated reduced model of this serial (bounded least squares)",
        values=values,
        notes=[
            "Reduced model and its derivation from the rv_reducer model: docs/bench.md. "
            "Intervals: 95 %, from the Jacobian; 'identified' false where the data see only a "
            "combination of parameters (null space of J) or the interval is huge.",
        ],
        data={"calibration": cal, "closed_loop": closed},
        files={"calibrated_serial.toml": calibrated_case_text(rcase, cal, case, closed, record)},
    )
    return res, cal


def reported_parameters(cal) -> dict:
    """Every fitted parameter as reported: value, 95 % half-width (None where not identified),
    unit, identified, note. A parameter estimated by its definition on the data
    (:meth:`gearte.runners.bench_calibration.CalibrationResult.estimate`) is reported so, and its
    note gives the reduced law's fitted value beside it."""
    from gearte.runners.bench_calibration import parameter_specs

    specs = parameter_specs(cal.model)
    out = {}
    for n in cal.fitted:
        value, ci = cal.estimate(n)
        note = cal.flags.get(n, "")
        if n in cal.by_definition:
            d = cal.by_definition[n]
            note = (f"{d.note} (the reduced law's fitted factor {d.fit_value:.5g} ± "
                    f"{d.fit_ci:.2g} shapes the model's curve)")  # fmt: skip
        out[n] = {
            "value": float(value), "ci95": float(ci) if np.isfinite(ci) else None,
            "unit": specs[n].unit, "identified": n not in cal.flags, "note": note,
        }  # fmt: skip
    return out


RESIDUAL_WARNING = 3.0
"""A calibration block whose rms residual exceeds this multiple of the data's own noise is a
warning [-]."""


def _noise(hyst, traces) -> dict:
    """The data's own noise [rad], independent of any model: hysteresis from the second
    differences along each run of the sweep
    (:func:`gearte.runners.bench_calibration.hysteresis_noise`), TE from the median line of each
    trace's order spectrum (:func:`gearte.models.orders.mean_standard_error` × √N)."""
    from gearte.models.orders import mean_standard_error, order_spectrum
    from gearte.runners.bench_calibration import hysteresis_noise

    out = {}
    sigma = hysteresis_noise(hyst) if hyst is not None else None
    if sigma is not None:
        out["hysteresis"] = sigma
    te = []
    for t in traces:
        for pos, y in t.directions().values():
            _, amp, _ = order_spectrum(pos, y)
            te.append(mean_standard_error(amp) * np.sqrt(y.size))
    if te:
        out["te"] = float(np.sqrt(np.mean(np.square(te))))
    return out


def _bench_targets(analyses) -> dict | None:
    """The bench's catalogue numbers the calibrated serial must reproduce [N·mm/rad, rad]: from
    the hysteresis curve, else from the first load series that gives them."""
    from gearte.units import arcmin_to_rad

    per_arcmin = float(Nm_to_Nmm(1.0)) * ARCMIN_PER_RAD
    for a in analyses:
        v = a.values
        if a.name == "catalogue" and "torsional_rigidity [N·m/arcmin]" in v:
            return {"source": "hysteresis curve",
                    "torsional_rigidity": v["torsional_rigidity [N·m/arcmin]"] * per_arcmin,
                    "lost_motion": arcmin_to_rad(v["lost_motion [arcmin]"]),
                    "backlash": arcmin_to_rad(v["backlash [arcmin]"])}  # fmt: skip
    for a in analyses:
        if a.name == "load_series":
            for row in a.values["series"]:
                keys = ("bench_torsional_rigidity [N*m/arcmin]", "bench_lost_motion [arcmin]",
                        "bench_backlash [arcmin]")  # fmt: skip
                if all(row[k] is not None for k in keys):
                    return {"source": f"load series at {row['speed [rpm]']} rpm, "
                                      f"{row['oil_temperature [°C]']} °C",
                            "torsional_rigidity": row[keys[0]] * per_arcmin,
                            "lost_motion": arcmin_to_rad(row[keys[1]]),
                            "backlash": arcmin_to_rad(row[keys[2]])}  # fmt: skip
    return None


def _close_loop(case, reducer, cal, analyses, lmf, warnings):
    """The calibrated serial through the whole model: stiffness scale and clearances with which
    the whole model (plus the calibrated rig's twist) gives the bench's rigidity and backlash
    (:func:`gearte.runners.bench_calibration.close_loop`); its lost motion is the check. Returns
    ``(ClosedLoop or None, record)`` — the record is the calibrated serial's
    ``[bench_calibration]`` section."""
    from gearte.runners.bench_calibration import close_loop

    record: dict = {
        "source": f"rv_bench case {case.case.title or case.case.name}",
        "stiffness_scale": 1.0,
        "parameters": reported_parameters(cal),
        "round_trip": {},
        "not_written": [],
    }
    p = cal.params

    def known(n):
        return n in cal.fixed or (n in cal.fitted and n not in cal.flags)

    if known("contact_stiffness_factor"):
        record["contact_stiffness_factor"] = cal.estimate("contact_stiffness_factor")[0]
    if known("friction_torque"):
        record["friction_torque_Nm"] = float(p["friction_torque"]) / float(Nm_to_Nmm(1.0))
    c_rig = 0.0
    if known("rig_compliance"):
        c_rig = float(p["rig_compliance"])
        record["rig_compliance_arcsec_per_kNm"] = _sec(c_rig) * float(Nm_to_Nmm(1000.0))
    else:
        record["not_written"].append(
            "rig compliance: not identified (it cannot be told from the reducer's stiffness): "
            "the whole compliance is attributed to the reducer"
        )
    clear = ("cam_bearing_clearance", "carrier_bearing_clearance")
    play_known = all(n in cal.fitted for n in clear) and not any(
        "no data" in cal.flags.get(n, "") or "at a bound" in cal.flags.get(n, "") for n in clear
    )
    record["clearances_identified"] = play_known and not any(n in cal.flags for n in clear)
    targets = _bench_targets(analyses)
    if targets is None:
        record["not_written"].append(
            "clearances and stiffness: no bench catalogue numbers (a hysteresis curve or a load "
            "series at zero load, f T_r, T_r/2 and T_r) to reproduce; the design's kept"
        )
        return None, record
    k_bench = targets["torsional_rigidity"]
    k_target = 1.0 / (1.0 / k_bench - c_rig) if 1.0 / k_bench > c_rig else k_bench
    if k_target == k_bench and c_rig > 0:
        record["not_written"].append(
            "rig compliance exceeds the bench's whole compliance: ignored for the reducer"
        )
        c_rig = 0.0
    c0 = reducer.cranks
    start: tuple[float, float] = (
        (float(p[clear[0]]), float(p[clear[1]])) if record["clearances_identified"]
        else (c0.cam_bearing_clearance, c0.carrier_bearing_clearance)
    )  # fmt: skip
    if not record["clearances_identified"]:
        mean = 0.5 * (start[0] + start[1])
        start = (mean, mean)
        record["not_written"].append(
            "cam and carrier bearing clearance: the bench sees only their common play; one "
            "common clearance written that gives it"
        )
    closed = close_loop(reducer, k_target, targets["backlash"], start_clearances=start,
                        lost_motion_fraction=lmf)  # fmt: skip
    record["stiffness_scale"] = float(closed.stiffness_scale)
    record["not_written"] += closed.notes
    tr = reducer.rated_torque
    cv = closed.values
    system = {
        "torsional_rigidity": 1.0 / (1.0 / cv.torsional_rigidity + c_rig),
        "lost_motion": cv.lost_motion + 2.0 * lmf * tr * c_rig,
        "backlash": cv.backlash,
    }
    per_arcmin = float(Nm_to_Nmm(1.0)) * ARCMIN_PER_RAD
    for name, unit, conv in (("torsional_rigidity", "N*m/arcmin", 1.0 / per_arcmin),
                             ("lost_motion", "arcmin", ARCMIN_PER_RAD),
                             ("backlash", "arcmin", ARCMIN_PER_RAD)):  # fmt: skip
        b, m = targets[name], system[name]
        rel = (m - b) / b if b else None
        record["round_trip"][f"{name} [{unit}]"] = {
            "bench": b * conv, "serial_whole_model": m * conv, "relative_difference": rel,
        }  # fmt: skip
        if rel is None or abs(rel) > 0.05:
            warnings.append(
                f"calibration: the calibrated serial through the whole model gives {name} "
                f"{m * conv:.4g} {unit} against the bench's {b * conv:.4g} ("
                + ("n/a" if rel is None else f"{100 * rel:+.1f} %")
                + ")"
            )
    record["round_trip_source"] = targets["source"]
    if not closed.converged:
        warnings.append(
            f"calibration: the whole model did not reach the bench's rigidity and backlash in "
            f"{closed.iterations} evaluations"
        )
    return closed, record


def _diagnosis(cal, analyses, sec: DiagnosisSection, cat_sec, options) -> AnalysisResult:
    from gearte.runners.bench_diagnosis import diagnose

    spectrum = None
    limit = None
    for a in analyses:
        if a.name == "te_orders":
            spectrum = [
                {**x, "amplitude": arcsec_to_rad(x["amplitude [arcsec]"])}
                for x in a.values["te_orders"]
            ]
            limit = a.data.get("unexplained_limit")
    lmf = (cat_sec or CatalogueSection()).lost_motion_fraction
    from gearte.studies import sample_cap

    draws = sample_cap(sec, "draws", options)
    dg = diagnose(
        cal, spectrum, lost_motion_fraction=lmf, draws=draws, seed=sec.seed,
        unexplained_limit=limit,
    )  # fmt: skip

    def conv(rows, key):
        return [
            {k: v for k, v in r.items() if k not in ("contribution", "contribution_ci")}
            | {f"{key} [arcsec]": _sec(r["contribution"]),
               f"{key}_ci95 [arcsec]": _sec(r["contribution_ci"])}
            for r in rows
        ]  # fmt: skip

    return AnalysisResult(
        name="diagnosis", title="Most likely culprits",
        values={
            "te_culprits": conv(dg.te, "amplitude"),
            "lost_motion_culprits": conv(dg.lost_motion, "lost_motion_share"),
            "statements": dg.statements,
        },
        notes=["probability_largest: share of parameter draws from the calibration's Gaussian "
               "in which the candidate contributes most."],
    )  # fmt: skip


# ---- calibrated serial as a case file -------------------------------------------------------
def _toml_value(v) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, int | float):
        return repr(float(v)) if isinstance(v, float) else str(v)
    if isinstance(v, str):
        return '"' + v.replace("\\", "\\\\").replace('"', '\\"').replace("\n", "\\n") + '"'
    if isinstance(v, list | tuple):
        return "[" + ", ".join(_toml_value(x) for x in v) + "]"
    if isinstance(v, dict):
        return "{ " + ", ".join(f"{k} = {_toml_value(x)}" for k, x in v.items()) + " }"
    raise TypeError(type(v))


def _key(k: str) -> str:
    """A TOML key: bare where it may be, else quoted."""
    return k if re.fullmatch(r"[A-Za-z0-9_-]+", k) else _toml_value(k)


def _toml(d: dict, prefix: str = "") -> list[str]:
    """Minimal TOML writer: scalars and lists inline, nested mappings as dotted tables."""
    lines = [f"[{prefix}]"] if prefix else []
    tables = {}
    for k, v in d.items():
        if isinstance(v, dict):
            tables[k] = v
        elif v is not None:
            lines.append(f"{_key(k)} = {_toml_value(v)}")
    for k, v in tables.items():
        lines.append("")
        lines += _toml(v, f"{prefix}.{_key(k)}" if prefix else _key(k))
    return lines


def calibrated_case_text(rcase, cal, case, closed=None, record=None) -> str:
    """The serial as an ``rv_reducer`` case: the drive's case with the clearances and the
    stiffness scale that reproduce the bench (``closed``, :func:`_close_loop`) as values of
    ``[reducer]``, and every estimate of the calibration as values of ``[bench_calibration]``."""
    from gearte.runners.bench_calibration import serial_reducer
    from gearte.studies.rv_reducer import build_reducer, reducer_section, with_case_keys

    data = rcase.model_dump(mode="json", exclude_none=True)
    if closed is not None:
        # the serial as the whole model runs it (the design built, every stiffness of its load
        # path scaled, the clearances set), written back by the reducer's one inverse of
        # build_reducer: derived stiffnesses (Palmgren bearings, the stiffness chain, the ISO
        # 6336 mesh) become given values; the keys the object does not hold stay the case's
        serial = serial_reducer(
            build_reducer(rcase.reducer), closed.stiffness_scale, closed.clearances
        )
        data["reducer"] = with_case_keys(reducer_section(serial), data["reducer"])
    if record is not None:
        data["bench_calibration"] = {
            k: v for k, v in record.items() if k != "round_trip_source" and v is not None
        }
    data["case"]["title"] = f"Calibrated serial: {case.case.title or case.case.name}"
    data["case"].pop("name", None)
    head = [
        "# Calibrated serial written by gearte (kind rv_bench) from bench data. [reducer] holds",
        "# the clearances and the stiffness scale with which the whole model reproduces the",
        "# bench's rigidity and backlash; [bench_calibration] every estimate with its interval.",
    ]
    return "\n".join([*head, "", *_toml(data)]) + "\n"
