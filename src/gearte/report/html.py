"""Render a study result as one self-contained HTML page (jinja2, plots embedded as PNG)."""

from __future__ import annotations

import base64
import datetime as _dt
import io
import json
from importlib import resources
from typing import Any

import numpy as np

__all__ = ["render_report", "figure_to_png_base64"]


def figure_to_png_base64(fig: Any, dpi: int = 110) -> str:
    """PNG of a matplotlib figure, base64 encoded."""
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=dpi)
    return base64.b64encode(buf.getvalue()).decode("ascii")


def _fmt(v: Any) -> str:
    if isinstance(v, bool | np.bool_):
        return str(bool(v))
    if isinstance(v, int | np.integer):
        return str(int(v))
    if isinstance(v, float | np.floating):
        f = float(v)
        if f == 0 or 1e-3 <= abs(f) < 1e6:
            return f"{f:.6g}"
        return f"{f:.4e}"
    return str(v)


Rows = list[tuple[str, str]]


def _rows(
    values: dict[str, Any],
) -> tuple[Rows, list[tuple[str, Rows]], list[tuple[str, str, str]]]:
    """Split values into scalar rows, mapping tables and array summaries."""
    scalars: list[tuple[str, str]] = []
    mappings: list[tuple[str, list[tuple[str, str]]]] = []
    arrays: list[tuple[str, str, str]] = []
    for k, v in values.items():
        if isinstance(v, dict):
            rows = []
            for a, b in v.items():
                nested = isinstance(b, dict | list | tuple | np.ndarray)
                rows.append((str(a), json.dumps(_plain(b)) if nested else _fmt(b)))
            mappings.append((k, rows))
        elif isinstance(v, list | tuple | np.ndarray):
            arr = np.asarray(v, dtype=object)
            flat = [x for x in arr.ravel() if isinstance(x, int | float | np.integer | np.floating)]
            summary = f"{arr.shape[0] if arr.ndim else 1} values"
            if arr.ndim > 1:
                summary = "×".join(str(s) for s in arr.shape) + " values"
            if flat:
                fl = np.asarray(flat, dtype=float)
                summary += f", min {_fmt(fl.min())}, max {_fmt(fl.max())}"
            text = ", ".join(_fmt(x) for x in arr.ravel()[:400])
            if arr.size > 400:
                text += ", …"
            arrays.append((k, summary, text))
        else:
            scalars.append((k, _fmt(v)))
    return scalars, mappings, arrays


def _plain(v: Any) -> Any:
    from gearte.results import to_jsonable

    return to_jsonable(v)


def render_report(result: Any) -> str:
    """HTML text of the report of a :class:`~gearte.results.StudyResult`."""
    import jinja2

    from gearte._version import __version__
    from gearte.plotting import figures_for
    from gearte.references import REFERENCES

    figs = []
    for f in figures_for(result):
        figs.append({"title": f.title, "caption": f.caption, "png": figure_to_png_base64(f.fig)})
    analyses = []
    for a in result.analyses:
        scalars, mappings, arrays = _rows(a.values)
        analyses.append(
            {
                "name": a.name,
                "title": a.title,
                "notes": a.notes,
                "scalars": scalars,
                "mappings": mappings,
                "arrays": arrays,
            }
        )
    env = jinja2.Environment(autoescape=True, undefined=jinja2.StrictUndefined)
    template = resources.files("gearte.report").joinpath("report.html.j2").read_text("utf-8")
    return env.from_string(template).render(
        title=result.case.case.title or result.name,
        name=result.name,
        kind=result.kind,
        version=__version__,
        date=_dt.datetime.now(_dt.UTC).strftime("%Y-%m-%d %H:%M UTC"),
        elapsed=f"{result.elapsed_s:.2f}",
        description=result.case.case.description,
        warnings=result.warnings,
        analyses=analyses,
        figures=figs,
        references=[(k, REFERENCES.get(k, k)) for k in result.references],
        case_json=json.dumps(
            _plain(result.case.model_dump(mode="json")), indent=1, ensure_ascii=False
        ),
    )
