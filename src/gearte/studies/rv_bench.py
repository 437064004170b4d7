"""Study kind ``rv_bench``: one RV serial's bench data → catalogue numbers, labelled TE orders,
calibrated reduced model, likely culprit parts (issue 17).

Case file::

    [case]    kind = "rv_bench", title, references
    [reducer] case = "<bundled rv_reducer case or path>"   the drive's description: tooth numbers
                                                           (order labels), rated torque, the whole
                                                           model behind the reduced one
    [data]    te = "<CSV file or folder of operating points>", hysteresis = "<CSV file>"
              (paths relative to the case file, else to the bundled examples),
              torque_noise_fraction (torque sensor, × T_r)
    [analyses.catalogue]    lost_motion_fraction (0.03)
    [analyses.te_orders]    n_orders (12)
    [analyses.calibration]  families, fit, encoder_eccentricity_arcsec,
                            rig_compliance_arcsec_per_kNm
    [analyses.diagnosis]    draws, seed

Definitions: docs/bench.md. Results: ``angular_te_peak_to_peak_forward [arcsec]``,
``angular_te_peak_to_peak_backward [arcsec]``, ``forward_backward_difference_mean [arcsec]``,
``te_orders`` (order, ``amplitude [arcsec]``, ``phase [deg]``, source) and per operating point.
"""

from __future__ import annotations

from pathlib import Path
from typing import Literal

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
    "input rotation",
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


class OrdersSection(StrictModel):
    n_orders: int = Field(
        default=12, ge=1, le=200, description="Largest TE orders listed per trace."
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

    rcase = load_case(ref.case)
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
    from gearte.models.orders import rv_characteristic_orders

    reducer, rcase = _reducer(case.reducer)
    fs = reducer.first_stage
    sources = rv_characteristic_orders(fs.sun_teeth, fs.planet_teeth, reducer.pins.count)
    d = case.data
    traces = []
    if d.te is not None:
        traces = read_te_folder(d.te) if Path(d.te).is_dir() else [read_te_trace(d.te)]
    hyst = read_hysteresis(d.hysteresis) if d.hysteresis is not None else None
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
    a = case.analyses
    analyses: list[AnalysisResult] = []
    warnings: list[str] = []
    analyses.append(_catalogue(reducer, traces, hyst, a.catalogue or CatalogueSection()))
    if traces:
        analyses.append(_orders(traces, sources, a.te_orders or OrdersSection()))
    if a.calibration is not None:
        cal_res, cal = _calibration(case, reducer, rcase, sources, traces, hyst, warnings)
        analyses.append(cal_res)
        if a.diagnosis is not None:
            analyses.append(_diagnosis(cal, analyses, a.diagnosis, a.catalogue, options))
    return StudyResult(case=case, analyses=analyses, warnings=warnings)


def _reference(traces):
    """The trace the headline numbers and the calibration use: the least loaded one."""
    return min(traces, key=lambda t: abs(t.torque) if t.torque is not None else 0.0)


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


def _catalogue(reducer, traces, hyst, sec: CatalogueSection) -> AnalysisResult:
    from gearte.models.catalogue import branch_directions, hysteresis_values

    values: dict = {}
    data: dict = {}
    notes = ["Definitions in docs/bench.md (gearte.models.catalogue), shared with the virtual "
             "test of the rv_reducer kind."]  # fmt: skip
    if traces:
        ref = _reference(traces)
        values["reference_operating_point"] = Path(ref.source).name
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


def order_list(trace, direction: str, sources, n_orders: int) -> list[dict]:
    from gearte.models.orders import labelled_orders, order_spectrum

    pos, te = trace.directions()[direction]
    o, amp, ph = order_spectrum(pos, te)
    return [
        {"order": x["order"], "amplitude [arcsec]": _sec(x["amplitude"]),
         "phase [deg]": x["phase"] * DEG_PER_RAD, "source": x["source"]}
        for x in labelled_orders(o, amp, ph, sources, n_orders)
    ]  # fmt: skip


def _orders(traces, sources, sec: OrdersSection) -> AnalysisResult:
    from gearte.models.orders import order_spectrum

    ref = _reference(traces)
    dirs = ref.directions()
    first = "forward" if "forward" in dirs else "backward"
    values: dict = {
        "characteristic_orders": {k: float(v) for k, v in sources.items()},
        "te_orders": order_list(ref, first, sources, sec.n_orders),
    }
    if "backward" in dirs and first == "forward":
        values["te_orders_backward"] = order_list(ref, "backward", sources, sec.n_orders)
    trend: dict = {}
    if len(traces) > 1:
        labels = {}
        for name, n in sources.items():
            if abs(n - round(n)) < 1e-9:
                labels[name] = int(round(n))
        rows = []
        for t in traces:
            pos, te = t.directions()[first]
            _, amp, _ = order_spectrum(pos, te)
            rows.append({
                "file": Path(t.source).name, "speed [rpm]": t.speed_rpm,
                "torque [N·m]": None if t.torque is None else t.torque / float(Nm_to_Nmm(1.0)),
                "oil_temperature [°C]": t.oil_temperature,
                "amplitude [arcsec]": {k: _sec(float(amp[n])) if n < amp.size else None
                                       for k, n in labels.items()},
            })  # fmt: skip
        values["order_trend"] = rows
        trend = {"rows": rows, "labels": labels}
    return AnalysisResult(
        name="te_orders", title="Order spectrum of the measured TE (per output revolution)",
        values=values,
        notes=[f"{first} trace of {Path(ref.source).name}; amplitude of TE = mean + Σ A cos(kφ + "
               "phase); orders labelled from the drive's tooth numbers (gearte.models.orders)."],
        data={"reference": ref, "direction": first, "sources": sources, "trend": trend},
    )  # fmt: skip


def _calibration(case, reducer, rcase, sources, traces, hyst, warnings):
    from gearte.runners.bench_calibration import (
        Z95,
        calibrate,
        parameter_specs,
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
    ref = [_reference(traces)] if traces else []
    cal = calibrate(
        model, hyst, ref, fit=sec.fit, fixed=fixed, max_relative_ci=sec.max_relative_ci,
        torque_noise=case.data.torque_noise_fraction,
    )  # fmt: skip
    specs = parameter_specs(model)
    params = {}
    for n in cal.fitted:
        unit = specs[n].unit
        params[n] = {
            "value": cal.params[n], "ci95": cal.ci[n] if np.isfinite(cal.ci[n]) else None,
            "unit": unit, "identified": n not in cal.flags, "note": cal.flags.get(n, ""),
        }  # fmt: skip
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
    res = AnalysisResult(
        name="calibration",
        title="Calibrated reduced model of this serial (bounded least squares)",
        values=values,
        notes=[
            "Reduced model and its derivation from the rv_reducer model: docs/bench.md. "
            "Intervals: 95 %, from the Jacobian; 'identified' false where the data see only a "
            "combination of parameters (null space of J) or the interval is huge.",
        ],
        data={"calibration": cal},
        files={"calibrated_serial.toml": calibrated_case_text(rcase, cal, case)},
    )
    return res, cal


def _diagnosis(cal, analyses, sec: DiagnosisSection, cat_sec, options) -> AnalysisResult:
    from gearte.runners.bench_diagnosis import diagnose

    spectrum = None
    for a in analyses:
        if a.name == "te_orders":
            spectrum = [
                {**x, "amplitude": arcsec_to_rad(x["amplitude [arcsec]"])}
                for x in a.values["te_orders"]
            ]
    lmf = (cat_sec or CatalogueSection()).lost_motion_fraction
    from gearte.studies import sample_cap

    draws = sample_cap(sec, "draws", options)
    dg = diagnose(cal, spectrum, lost_motion_fraction=lmf, draws=draws, seed=sec.seed)

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


def _toml(d: dict, prefix: str = "") -> list[str]:
    """Minimal TOML writer: scalars and lists inline, nested mappings as dotted tables."""
    lines = [f"[{prefix}]"] if prefix else []
    tables = {}
    for k, v in d.items():
        if isinstance(v, dict):
            tables[k] = v
        elif v is not None:
            lines.append(f"{k} = {_toml_value(v)}")
    for k, v in tables.items():
        lines.append("")
        lines += _toml(v, f"{prefix}.{k}" if prefix else k)
    return lines


def calibrated_case_text(rcase, cal, case) -> str:
    """The serial as an ``rv_reducer`` case: the drive's case with the calibrated bearing
    clearances (where identified) and the calibration recorded in the header."""
    data = rcase.model_dump(mode="json", exclude_none=True)
    cranks = data["reducer"]["cranks"]
    notes = []
    names = ("cam_bearing_clearance", "carrier_bearing_clearance")
    clear = [cal.params[n] for n in names]
    if all(n in cal.fitted for n in names) and any(n in cal.flags for n in names):
        # only the play g_cam c_cam + g_car c_car is seen: split it as one common clearance
        g = cal.model.backlash_per_clearance
        common = (g[0] * clear[0] + g[1] * clear[1]) / (g[0] + g[1])
        clear = [common, common]
        notes.append("the bench sees only the play of both crank bearings together: written as "
                     "one common radial clearance that gives the calibrated play")  # fmt: skip
    for key, name, c in zip(("cam_bearing", "carrier_bearing"), names, clear, strict=True):
        if name in cal.fitted:
            cranks[key]["radial_clearance_um"] = float(mm_to_um(c))
    data["case"]["title"] = f"Calibrated serial: {case.case.title or case.case.name}"
    data["case"].pop("name", None)
    head = [
        "# Calibrated serial written by gearte (kind rv_bench) from bench data; the reduced",
        "# model's estimates (gearte units: mm, N·mm, rad) with 95 % half-widths:",
    ]
    for n in cal.fitted:
        ci = cal.ci[n]
        head.append(f"#   {n} = {cal.params[n]:.6g} ± {ci:.3g}" + (
            f"  ({cal.flags[n]})" if n in cal.flags else ""))  # fmt: skip
    head += [f"# {x}" for x in notes]
    return "\n".join([*head, "", *_toml(data)]) + "\n"
