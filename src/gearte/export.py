"""Exports for CAD and grinding: the modified cycloid profile (DXF, CSV) and the compensation
tables (CSV) of a ``cycloid_stage`` or ``rv_reducer`` case.

``gearte export CASE --format dxf --format csv --chordal-tolerance-um 1 --out DIR`` is a thin
layer over :func:`export_case`:

>>> from gearte.export import export_case                                   # doctest: +SKIP
>>> export_case("hu2020_rv80e_initial", "out/export", chordal_tolerance_um=1.0)  # doctest: +SKIP

Files written (as one set, like every gearte output folder; see docs/export.md):

* ``profile.dxf`` — the whole disc (every tooth, every modification) as one closed LWPOLYLINE on
  layer ``PROFILE``, drawing units mm (``$INSUNITS = 4``), written with ezdxf;
* ``profile.csv`` — the same vertices, ``x [mm],y [mm]``, in polyline order (closed: the last
  vertex joins the first);
* ``compensation_*.csv`` and ``cycloid_compensation_*.csv`` — the compensation analyses of the
  case (``[analyses.compensation]``; for an RV reducer also ``[analyses.cycloid_compensation]``):
  their scalars and tables, the numbers unformatted;
* ``export.json`` — what was written: case, stage, tolerance asked for, deviation measured,
  point counts.

The point spacing follows :func:`gearte.geometry.outline.disc_outline`: adaptive, so that no
chord is farther than the tolerance from the profile.
"""

from __future__ import annotations

import csv
import io
import json
import os
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from gearte.errors import ParameterError

__all__ = [
    "FORMATS",
    "PROFILE_KINDS",
    "stage_of",
    "profile_outline",
    "outline_dxf",
    "outline_csv",
    "compensation_csv",
    "export_case",
]

#: Formats of the profile export.
FORMATS = ("dxf", "csv")
#: Kinds of case that describe a cycloid disc.
PROFILE_KINDS = ("cycloid_stage", "rv_reducer")
#: Compensation analyses by kind (the ``[analyses.*]`` tables).
_COMPENSATION = {
    "cycloid_stage": ("compensation",),
    "rv_reducer": ("compensation", "cycloid_compensation"),
}


def _load(case: Any) -> Any:
    if hasattr(case, "case") and hasattr(case, "model_dump"):
        return case
    from gearte.io.case_file import load_case

    return load_case(case)


def stage_of(case: Any) -> Any:
    """The :class:`~gearte.geometry.cycloid.CycloidStage` of a case (path, bundled name, dict or
    validated ``Case``) of kind ``cycloid_stage`` or ``rv_reducer``.

    Raises
    ------
    ParameterError
        The case's kind has no cycloid disc.
    """
    c = _load(case)
    kind = str(c.case.kind)
    if kind == "cycloid_stage":
        from gearte.studies.cycloid_stage import build_stage

        return build_stage(c.stage)
    if kind == "rv_reducer":
        from gearte.studies.cycloid_stage import build_stage
        from gearte.studies.rv_reducer import build_stage_case

        return build_stage(build_stage_case(c).stage)
    raise ParameterError(
        "case.kind",
        kind,
        "has no cycloid profile to export; `gearte export` works for "
        f"{' and '.join(PROFILE_KINDS)} cases",
    )


def profile_outline(case: Any, chordal_tolerance_um: float) -> Any:
    """The whole modified disc of ``case`` as a closed polyline
    (:class:`~gearte.geometry.outline.Outline`) within ``chordal_tolerance_um`` [µm]."""
    from gearte.geometry.outline import disc_outline
    from gearte.units import um_to_mm

    _check_tolerance(chordal_tolerance_um)
    return disc_outline(stage_of(case), float(um_to_mm(float(chordal_tolerance_um))))


def _check_tolerance(tol_um: Any) -> None:
    import math

    if isinstance(tol_um, bool) or not isinstance(tol_um, int | float):
        raise ParameterError("--chordal-tolerance-um", tol_um, "must be a number [µm]")
    if not (math.isfinite(tol_um) and 0.001 <= tol_um <= 1000.0):
        raise ParameterError(
            "--chordal-tolerance-um",
            tol_um,
            "must be between 0.001 and 1000 µm (finer than 1 nm is below the float precision "
            "of the coordinates; coarser than 1 mm is no longer the profile)",
        )


def outline_dxf(outline: Any, *, title: str = "") -> bytes:
    """The outline as a DXF drawing (R2010, units mm): one closed LWPOLYLINE on layer
    ``PROFILE``.

    Parameters
    ----------
    outline : Outline
        From :func:`profile_outline` (vertices [mm]).
    title : str
        Stored as the drawing's ``$PROJECTNAME``.
    """
    import ezdxf

    doc = ezdxf.new("R2010", units=4)  # 4 = millimetres
    doc.layers.add("PROFILE", color=7)
    if title:
        doc.header["$PROJECTNAME"] = title[:200]
    msp = doc.modelspace()
    points = list(zip(outline.x.tolist(), outline.y.tolist(), strict=True))
    msp.add_lwpolyline(points, format="xy", close=True, dxfattribs={"layer": "PROFILE"})
    buf = io.StringIO()
    doc.write(buf)
    return buf.getvalue().encode("utf-8")


def outline_csv(outline: Any) -> str:
    """The outline's vertices as CSV, header ``x [mm],y [mm]``, full float precision."""
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(["x [mm]", "y [mm]"])
    w.writerows(zip(map(repr, outline.x.tolist()), map(repr, outline.y.tolist()), strict=True))
    return buf.getvalue()


def compensation_csv(case: Any, options: Any = None) -> dict[str, str]:
    """CSV files of the compensation analyses the case asks for (file name → text); ``{}`` when
    it asks for none. Only those analyses run (not the rest of the case).

    Parameters
    ----------
    case : path, bundled case name, dict or validated Case
        A ``cycloid_stage`` or ``rv_reducer`` case.
    options : RunOptions, optional
        How the analyses run (default: no progress bar, local cores).
    """
    from gearte.io.case_file import load_case_dict
    from gearte.report.tables import csv_files
    from gearte.studies import RunOptions, run_case

    c = _load(case)
    names = _COMPENSATION.get(str(c.case.kind), ())
    data = c.model_dump(mode="json", by_alias=True, exclude_none=True)
    wanted = {k: v for k, v in data.get("analyses", {}).items() if k in names}
    if not wanted:
        return {}
    data["analyses"] = wanted
    result = run_case(load_case_dict(data), options or RunOptions(progress=False))
    import dataclasses

    only = dataclasses.replace(result, analyses=[a for a in result.analyses if a.name in names])
    out = {}
    for fname, text in csv_files(only).items():
        own = any(fname.startswith(n) for n in names)
        out[fname if own else f"compensation_{fname}"] = text
    for a in only.analyses:
        for fname, text in a.files.items():
            out.setdefault(f"{a.name}_{fname}", text)
    return out


def export_case(
    case: Any,
    out_dir: str | os.PathLike[str],
    *,
    formats: Sequence[str] = FORMATS,
    chordal_tolerance_um: float = 1.0,
    compensation: bool = True,
    options: Any = None,
) -> dict[str, Path]:
    """Write the profile (``formats``) and the compensation tables of ``case`` to ``out_dir``.

    Parameters
    ----------
    case : path, bundled case name, dict or validated Case
        A ``cycloid_stage`` or ``rv_reducer`` case.
    out_dir : path
        Output folder, replaced as a whole by the new set (as ``gearte run`` does).
    formats : sequence of {"dxf", "csv"}
        Profile formats.
    chordal_tolerance_um : float
        Largest distance between a chord of the polyline and the profile [µm], 0.001–1000.
    compensation : bool
        Also run the case's compensation analyses and write their tables.
    options : RunOptions, optional
        For the compensation analyses (seed, workers, ...).

    Returns
    -------
    dict
        File name → path written.

    Raises
    ------
    ParameterError
        A kind without a cycloid disc, an unknown format, a tolerance out of range.
    CaseFileError
        The case does not validate.
    """
    from gearte.report.outputs import check_output_dir, write_file_set

    fmts = list(dict.fromkeys(str(f).lower() for f in formats))
    unknown = [f for f in fmts if f not in FORMATS]
    if unknown or not fmts:
        raise ParameterError("--format", unknown or fmts, f"choose from {', '.join(FORMATS)}")
    c = _load(case)
    outline = profile_outline(c, chordal_tolerance_um)
    check_output_dir(out_dir)
    files: dict[str, bytes] = {}
    if "dxf" in fmts:
        files["profile.dxf"] = outline_dxf(outline, title=str(c.case.title or c.case.name))
    if "csv" in fmts:
        files["profile.csv"] = outline_csv(outline).encode("utf-8")
    comp = compensation_csv(c, options) if compensation else {}
    files |= {k: v.encode("utf-8") for k, v in comp.items()}
    st = stage_of(c)
    from gearte._version import __version__
    from gearte.units import mm_to_um, rad_to_arcmin

    manifest = {
        "gearte_version": __version__,
        "case": {"name": c.case.name, "kind": c.case.kind, "title": c.case.title},
        "stage": {
            "pins": st.z_p,
            "cycloid_teeth": st.z_c,
            "pin_circle_radius_mm": st.r_p,
            "pin_radius_mm": st.r_rp,
            "eccentricity_mm": st.a,
            "equidistant_modification_mm": st.dr_rp,
            "shifted_modification_mm": st.dr_p,
            "rotation_modification_arcmin": float(rad_to_arcmin(st.rotation)),
        },
        "profile": {
            "chordal_tolerance [um]": float(chordal_tolerance_um),
            "max_chord_deviation_measured [um]": float(mm_to_um(outline.deviation)),
            "points": len(outline.x),
            "points_per_tooth": outline.points_per_tooth,
            "closed": True,
            "units": "mm",
        },
        "files": sorted([*files, "export.json"]),
        "compensation": sorted(comp) if compensation else "not asked (--no-compensation)",
    }
    files["export.json"] = json.dumps(manifest, indent=1, ensure_ascii=False).encode("utf-8")
    return write_file_set(out_dir, files)
