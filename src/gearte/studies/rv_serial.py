"""Study kind ``rv_serial``: one assembled RV serial from its measured parts (docs/metrology.md).

The design (an ``rv_reducer`` case: geometry, stiffnesses, contact law) plus the measurement
files of the parts that form this serial; the measured values replace the design's in the one
RV model (:func:`gearte.geometry.measured.apply_measurements`) and the serial's pin loads, TE
and lost motion come out of the ``rv_reducer`` analyses. The report's first table
(``measured_inputs``) says which inputs were measured (file and serials) and which are the
design's.

Case file::

    [case]     kind = "rv_serial", title
    [reducer]  case = "<rv_reducer case name or path>"     the design
    [serial]   name = "RV-0001"
               discs = ["D-0001", "D-0002"]                 disc serials, disc 1 first
               cranks = ["C-0001", "C-0002", "C-0003"]      crank at carrier position 1, 2, ...
               planets = [...], sun = "S-0001", pins = "H-0001"
    [serial.files]                                          paths relative to the case file
               disc_profile, disc_pitch, disc_bores, crank_eccentricity, bearing_clearance,
               planet_runout, sun_runout, pins
    [analyses.load_sharing] / [analyses.transmission_error] / [analyses.catalogue]
               as in ``rv_reducer``

File formats: ``docs/metrology.md``.
"""

from __future__ import annotations

from typing import Any

from pydantic import Field, ValidationInfo, field_validator, model_validator

from gearte.io.schema import StrictModel
from gearte.results import AnalysisResult, StudyResult
from gearte.studies import rv_reducer as rv
from gearte.studies._measured import MeasuredPartsCase
from gearte.studies.rv_bench import _resolve

KIND = "rv_serial"
REFERENCES = ["han2023", "hu2020"]
FIGURES = "gearte.plotting.rv_reducer"

__all__ = ["KIND", "REFERENCES", "FIGURES", "Case", "run", "build_serial"]

_FILES = (
    "disc_profile",
    "disc_pitch",
    "disc_bores",
    "crank_eccentricity",
    "bearing_clearance",
    "planet_runout",
    "sun_runout",
    "pins",
)
#: Which serial list each file needs.
_FILE_PARTS = {
    "disc_profile": "discs",
    "disc_pitch": "discs",
    "disc_bores": "discs",
    "crank_eccentricity": "cranks",
    "bearing_clearance": "cranks",
    "planet_runout": "planets",
    "sun_runout": "sun",
    "pins": "pins",
}


class FilesSection(StrictModel):
    """Measurement files (``docs/metrology.md``), relative to the case file."""

    disc_profile: str | None = Field(
        None, description="Measurement file of the discs' profiles (docs/metrology.md)."
    )
    disc_pitch: str | None = Field(
        None, description="Measurement file of the discs' cumulative pitch (docs/metrology.md)."
    )
    disc_bores: str | None = Field(
        None, description="Measurement file of the discs' crank bores (docs/metrology.md)."
    )
    crank_eccentricity: str | None = Field(
        None, description="Measurement file of the cranks' eccentricities (docs/metrology.md)."
    )
    bearing_clearance: str | None = Field(
        None, description="Measurement file of the bearing clearances (docs/metrology.md)."
    )
    planet_runout: str | None = Field(
        None, description="Measurement file of the planets' run-out (docs/metrology.md)."
    )
    sun_runout: str | None = Field(
        None, description="Measurement file of the sun's run-out (docs/metrology.md)."
    )
    pins: str | None = Field(
        None, description="Measurement file of the pin ring (docs/metrology.md)."
    )

    @field_validator(*_FILES)
    @classmethod
    def _paths(cls, v: str | None, info: ValidationInfo) -> str | None:
        return None if v is None else _resolve(v, info)


class SerialSection(StrictModel):
    name: str = Field(min_length=1, max_length=64, description="serial number of the reducer")
    discs: list[str] | None = Field(default=None, description="disc serials, disc 1 first")
    cranks: list[str] | None = Field(default=None, description="crank serials by position")
    planets: list[str] | None = Field(default=None, description="planet serials by position")
    sun: str | None = Field(None, description="Serial of the sun gear.")
    pins: str | None = Field(default=None, description="pin-ring serial")
    files: FilesSection

    @model_validator(mode="after")
    def _files_and_parts(self) -> SerialSection:
        problems = []
        for f in _FILES:
            part = _FILE_PARTS[f]
            if getattr(self.files, f) is not None and getattr(self, part) is None:
                problems.append(f"files.{f} is given but the serial names no {part}")
        for part in ("discs", "cranks", "planets", "sun", "pins"):
            if getattr(self, part) is not None and not any(
                getattr(self.files, f) is not None for f in _FILES if _FILE_PARTS[f] == part
            ):
                problems.append(f"{part} are named but no file measures them")
        if not any(getattr(self.files, f) is not None for f in _FILES):
            problems.append("files: give at least one measurement file")
        if problems:
            raise ValueError("; ".join(problems))
        return self


class Analyses(StrictModel):
    load_sharing: rv.LoadSharingSection | None = Field(
        None, description="Pin load sharing of this serial (as rv_reducer's)."
    )
    transmission_error: rv.TESection | None = Field(
        None, description="Loaded TE of this serial (as rv_reducer's)."
    )
    catalogue: rv.CatalogueSection | None = Field(
        None, description="Virtual torsion test of this serial (as rv_reducer's)."
    )


class Case(MeasuredPartsCase):
    serial: SerialSection
    analyses: Analyses

    def _build(self) -> Any:
        return build_serial(self)


def _pick(table: dict, serials: list[str], file: str, what: str) -> list:
    from gearte.errors import ParameterError

    missing = [s for s in serials if s not in table]
    if missing:
        raise ParameterError(
            f"serial.{what}", missing, f"not in {file} (it has {', '.join(sorted(table)[:8])} ...)"
        )
    return [table[s] for s in serials]


def build_serial(case: Case):
    """``(design_case, reducer, measured)``: the design, the serial's reducer with its measured
    values, and ``{input: "file (serials)"}`` of the measured inputs.

    Parameters
    ----------
    case : Case
        A validated ``rv_serial`` case.
    """
    import numpy as np

    from gearte.errors import ParameterError
    from gearte.geometry.measured import MeasuredDisc, apply_measurements
    from gearte.io import metrology as mt
    from gearte.studies._measured import check_measured_against_design

    design, red = case.design()
    s, f = case.serial, case.serial.files
    m, n, zc, zp = red.cranks.count, red.discs.count, red.cycloid_teeth, red.pins.count
    kw: dict = {}
    measured: dict[str, str] = {}

    def note(key: str, file: str, serials) -> None:
        names = serials if isinstance(serials, str) else ", ".join(serials)
        measured[key] = f"{file} ({names})"

    def count(name: str, serials: list[str] | None, want: int) -> list[str]:
        if serials is None or len(serials) != want:
            raise ParameterError(f"serial.{name}", serials, f"needs {want} serials (the design)")
        return serials

    if s.discs is not None:
        ds = count("discs", s.discs, n)
        prof = pitch = None
        if f.disc_profile is not None:
            prof = _pick(
                mt.read_disc_profiles(f.disc_profile, teeth=zc), ds, f.disc_profile, "discs"
            )
            note("disc flank deviation per tooth", f.disc_profile, ds)
        if f.disc_pitch is not None:
            pitch = _pick(mt.read_disc_pitch(f.disc_pitch, teeth=zc), ds, f.disc_pitch, "discs")
            note("disc cumulative pitch per tooth", f.disc_pitch, ds)
        if prof is not None or pitch is not None:
            kw["discs"] = [
                MeasuredDisc(
                    zc,
                    None if prof is None else prof[j].phase,
                    None if prof is None else prof[j].deviation,
                    None if pitch is None else pitch[j],
                    ds[j],
                )
                for j in range(n)
            ]
        if f.disc_bores is not None:
            bores = mt.read_disc_bores(f.disc_bores, bores=m)
            check_measured_against_design(red, f.disc_bores, bores=bores)
            kw["disc_bores"] = np.stack(_pick(bores, ds, f.disc_bores, "discs"))
            note("disc crank-bore positions", f.disc_bores, ds)
    if s.cranks is not None:
        cs = count("cranks", s.cranks, m)
        if f.crank_eccentricity is not None:
            read = mt.read_crank_eccentricity(f.crank_eccentricity, cams=n)
            check_measured_against_design(red, f.crank_eccentricity, cams=read)
            cams = _pick(read, cs, f.crank_eccentricity, "cranks")
            kw["cam_eccentricity"] = np.stack([c.eccentricity for c in cams])
            kw["cam_phase"] = np.stack([c.phase for c in cams])
            note("cam eccentricity and phase", f.crank_eccentricity, cs)
        if f.bearing_clearance is not None:
            cl = _pick(
                mt.read_bearing_clearances(f.bearing_clearance, cams=n),
                cs,
                f.bearing_clearance,
                "cranks",
            )
            kw["cam_clearance"] = np.array([[c[f"cam_{j + 1}"] for j in range(n)] for c in cl])
            kw["carrier_clearance"] = np.array([c["carrier"] for c in cl])
            note("bearing clearances", f.bearing_clearance, cs)
    if s.planets is not None and f.planet_runout is not None:
        ps = count("planets", s.planets, m)
        ro = _pick(mt.read_runout(f.planet_runout), ps, f.planet_runout, "planets")
        kw["planet_runout"] = np.array([[r.runout, r.phase] for r in ro])
        note("planet run-out", f.planet_runout, ps)
    if s.sun is not None and f.sun_runout is not None:
        r = _pick(mt.read_runout(f.sun_runout), [s.sun], f.sun_runout, "sun")[0]
        kw["sun_runout"] = np.array([r.runout, r.phase])
        note("sun run-out", f.sun_runout, s.sun)
    if s.pins is not None and f.pins is not None:
        pin_sets = mt.read_pins(f.pins, pins=zp)
        check_measured_against_design(red, f.pins, pins=pin_sets)
        p = _pick(pin_sets, [s.pins], f.pins, "pins")[0]
        kw.update(
            pin_diameters=p.diameter, slot_radial=p.slot_radial, slot_tangential=p.slot_tangential
        )
        note("pin diameters and pin-slot positions", f.pins, s.pins)
    return design, apply_measurements(red, **kw), measured


def _design_case(case: Case, design):
    """The ``rv_reducer`` case whose analyses run on the serial: the design with this case's
    analyses."""
    a = case.analyses
    return design.model_copy(
        update={
            "analyses": rv.Analyses(
                load_sharing=a.load_sharing,
                transmission_error=a.transmission_error,
                catalogue=a.catalogue,
            )
        }
    )


def preflight(case: Case) -> None:
    """The checks :func:`run` makes before any analysis (``gearte validate``,
    :func:`gearte.studies.run_case`): the serial's reducer built from the design and the
    measurement files (:func:`build_serial`; validating the case already built it, kept for the
    run) and the ``rv_reducer`` pre-flight of the analyses it runs on it
    (:func:`gearte.studies.rv_reducer.preflight`).

    Raises
    ------
    ParameterError, MeasurementFileError
        Naming the key or the file.
    """
    from gearte.errors import ParameterError
    from gearte.io.plausibility import implausible_values

    if case._built is None:
        case._built = build_serial(case)
    design = _design_case(case, case._built[0])
    # the torques of this case's analyses against the design's size, as `validate` checks an
    # rv_reducer case's (a torque in N·mm where N·m is asked ended as "no equilibrium" in run);
    # the design's own torques were checked when the design was validated
    for field, value, reason in implausible_values("rv_reducer", design):
        if field.startswith("analyses."):
            raise ParameterError(field, value, reason)
    rv.preflight(design)


def run(case: Case, options=None) -> StudyResult:
    """The serial's pin loads, TE and lost motion with its measured parts.

    Parameters
    ----------
    case : Case
        A validated ``rv_serial`` case.
    options : gearte.studies.RunOptions, optional
        Passed to the ``rv_reducer`` analyses.
    """
    design, red, measured = case._built if case._built is not None else build_serial(case)
    dcase = _design_case(case, design)
    res = rv.run(dcase, options, reducer=red)
    design_inputs = [
        k
        for k in (
            "disc flank deviation per tooth",
            "disc cumulative pitch per tooth",
            "disc crank-bore positions",
            "cam eccentricity and phase",
            "bearing clearances",
            "planet run-out",
            "sun run-out",
            "pin diameters and pin-slot positions",
        )
        if k not in measured
    ]
    table = AnalysisResult(
        name="measured_inputs",
        title=f"Serial {case.serial.name}: measured inputs",
        values={
            "serial": case.serial.name,
            "measured_inputs": len(measured),
            "inputs_from_design": len(design_inputs),
            "measured": dict(measured),
            "from_design": {k: f"design ({case.reducer.case})" for k in design_inputs},
        },
        references=[],
        notes=[
            "Measured values enter the model as they are (docs/metrology.md); the inputs under "
            "'from_design' are the design case's (its errors, if any, kept).",
        ],
    )
    return StudyResult(case=case, analyses=[table, *res.analyses], warnings=list(res.warnings))
