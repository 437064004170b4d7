"""Results in Jupyter: an HTML summary, pandas tables and matplotlib figures.

:class:`~gearte.results.StudyResult` and :class:`~gearte.results.AnalysisResult` delegate
``_repr_html_``, ``to_pandas`` and ``plot`` to this module. The results layer sits below the
report layer (docs/architecture.md, "Layers"), so it finds this module *by name*
(``gearte.results.DISPLAY_MODULE``), the way ``gearte.io.kinds`` finds the study kinds.

* :func:`study_html` / :func:`analysis_html`: the report's summary block (the same headline rows,
  spec checks and warnings as ``report.html``, :mod:`gearte.report.summary`) as a compact table;
* :func:`study_frame` / :func:`analysis_frame`: every scalar as a long table (analysis, quantity,
  unit, value: the rows of ``summary.csv``), or one value (a series, records, a mapping) as a
  table of its own; pandas is the optional extra ``gearte[notebooks]``;
* :func:`study_figures`: the report's figures (:mod:`gearte.plotting`), as matplotlib figures.
"""

from __future__ import annotations

import html
from typing import Any

import numpy as np

from gearte.report.summary import HeadlineRow, analysis_headlines, headlines, tradeoff_warnings
from gearte.report.tables import analysis_tables, is_series
from gearte.units import split_unit

__all__ = [
    "study_html",
    "analysis_html",
    "study_frame",
    "analysis_frame",
    "study_figures",
    "require_pandas",
]

#: Rows of an analysis's results table shown in its HTML repr (the rest: ``to_pandas()``).
MAX_ROWS = 12

_STYLE = (
    "<style>.gearte-repr table{border-collapse:collapse;font-size:12px}"
    ".gearte-repr th,.gearte-repr td{padding:2px 8px;text-align:left;"
    "border-bottom:1px solid #ddd}.gearte-repr .pass{color:#067d17}"
    ".gearte-repr .fail{color:#b00020;font-weight:bold}"
    ".gearte-repr .warn{color:#8a5a00}</style>"
)


def require_pandas() -> Any:
    """The pandas module, or an ImportError naming the extra that installs it."""
    try:
        import pandas
    except ImportError as exc:
        raise ImportError(
            "to_pandas() needs pandas, which gearte installs with its optional extra "
            "'notebooks': pip install 'gearte[notebooks]'"
        ) from exc
    return pandas


def _e(text: Any) -> str:
    return html.escape(str(text))


def _headline_table(rows: list[HeadlineRow], *, with_analysis: bool) -> str:
    if not rows:
        return ""
    spec = any(r.spec or r.status for r in rows)
    head = (["analysis"] if with_analysis else []) + ["quantity", "value"]
    head += ["spec", ""] if spec else []
    out = ["<table><tr>" + "".join(f"<th>{_e(h)}</th>" for h in head) + "</tr>"]
    prev = None
    for r in rows:
        cells = []
        if with_analysis:
            cells.append(_e(r.title) if r.analysis != prev else "")
            prev = r.analysis
        cells += [_e(r.quantity), _e(r.value)]
        if spec:
            cells += [_e(r.spec), f'<span class="{_e(r.status)}">{_e(r.status)}</span>']
        out.append("<tr>" + "".join(f"<td>{c}</td>" for c in cells) + "</tr>")
    out.append("</table>")
    return "".join(out)


def _warnings_html(warnings: list[str]) -> str:
    if not warnings:
        return ""
    items = "".join(f'<li class="warn">{_e(w)}</li>' for w in warnings)
    return f"<p><b>Warnings</b></p><ul>{items}</ul>"


def study_html(result: Any) -> str:
    """HTML summary of the study result ``result``: title, headline table with spec checks,
    warnings and the names of its analyses (``result["name"]`` shows one)."""
    title = result.case.case.title or result.name
    names = ", ".join(f"<code>{_e(a.name)}</code>" for a in result.analyses)
    warnings = list(result.warnings) + tradeoff_warnings(result)
    return (
        f'{_STYLE}<div class="gearte-repr"><p><b>{_e(title)}</b> '
        f"(<code>{_e(result.kind)}</code>, {len(result.analyses)} analyses, "
        f"{result.elapsed_s:.2f} s)</p>"
        + _headline_table(headlines(result), with_analysis=True)
        + _warnings_html(warnings)
        + f"<p>Analyses: {names}. Details: <code>result[name]</code>, "
        "<code>.to_pandas()</code>, <code>.plot()</code>.</p></div>"
    )


def analysis_html(analysis: Any) -> str:
    """HTML summary of the AnalysisResult ``analysis``: its headline rows and its results
    table (first :data:`MAX_ROWS` rows), with the names of its other tables."""
    parts = [
        f'{_STYLE}<div class="gearte-repr"><p><b>{_e(analysis.title)}</b> '
        f"(<code>{_e(analysis.name)}</code>)</p>"
    ]
    parts.append(_headline_table(analysis_headlines(analysis), with_analysis=False))
    tables = analysis_tables(analysis)
    first = next((t for t in tables if t.key.endswith("_results")), None)
    if first is not None:
        rows = first.formatted
        body = "".join(
            "<tr>" + "".join(f"<td>{_e(c)}</td>" for c in r) + "</tr>" for r in rows[:MAX_ROWS]
        )
        parts.append(f"<details><summary>All results ({len(rows)})</summary><table>{body}</table>")
        if len(rows) > MAX_ROWS:
            parts.append(f"<p>… {len(rows) - MAX_ROWS} more: <code>.to_pandas()</code></p>")
        parts.append("</details>")
    others = [t.title for t in tables if t is not first]
    if others:
        parts.append("<p>Tables: " + "; ".join(_e(t) for t in others) + "</p>")
    parts.append("</div>")
    return "".join(parts)


def _is_scalar(v: Any) -> bool:
    return v is None or isinstance(v, str | bool | int | float | np.generic)


def _scalar_rows(analysis: Any) -> list[tuple[str, str, Any]]:
    out = []
    for k, v in analysis.values.items():
        if _is_scalar(v):
            base, unit = split_unit(k)
            out.append((base, unit, v.item() if isinstance(v, np.generic) else v))
    return out


def study_frame(result: Any) -> Any:
    """Every scalar value of every analysis of ``result`` as a pandas DataFrame with the
    columns ``analysis``, ``quantity``, ``unit`` and ``value`` (one row per value)."""
    pd = require_pandas()
    rows = [(a.name, *r) for a in result.analyses for r in _scalar_rows(a)]
    return pd.DataFrame(rows, columns=["analysis", "quantity", "unit", "value"])


def _find_key(analysis: Any, key: str) -> str:
    if key in analysis.values:
        return key
    by_base = {split_unit(k)[0]: k for k in analysis.values}
    if key in by_base:
        return by_base[key]
    raise KeyError(
        f"analysis {analysis.name!r} has no value {key!r}; its values: {list(analysis.values)}"
    )


def analysis_frame(analysis: Any, key: str | None = None) -> Any:
    """One analysis as a pandas DataFrame.

    Parameters
    ----------
    analysis : AnalysisResult
    key : str, optional
        ``None``: every scalar value (columns ``quantity``, ``unit``, ``value``). A value's name,
        with or without its unit (``"te"`` or ``"te [arcmin]"``): that value as a table —
        records (a list of mappings) one row each, a mapping one row per item, a numeric series
        one column (a 2-D array one column per row of it), together with the other series of the
        same length when ``key`` is a 1-D series (side by side, as in the CSV files).

    Raises
    ------
    KeyError
        Naming the analysis's values when ``key`` is none of them.
    """
    pd = require_pandas()
    if key is None:
        return pd.DataFrame(_scalar_rows(analysis), columns=["quantity", "unit", "value"])
    name = _find_key(analysis, key)
    v = analysis.values[name]
    if isinstance(v, list | tuple) and v and all(isinstance(x, dict) for x in v):
        return pd.DataFrame(list(v))
    if isinstance(v, dict):
        if all(isinstance(x, dict) for x in v.values()):
            return pd.DataFrame.from_dict(v, orient="index")
        if all(_is_scalar(x) for x in v.values()):
            return pd.DataFrame({"item": list(v), name: list(v.values())})
        return pd.DataFrame({"item": list(v), name: [str(x) for x in v.values()]})
    if is_series(v):
        arr = np.asarray(v, dtype=float) if not isinstance(v, np.ndarray) else v
        if arr.ndim == 1:
            same = {
                k: np.asarray(x, dtype=float)
                for k, x in analysis.values.items()
                if is_series(x) and np.ndim(np.asarray(x, dtype=object)) == 1 and len(x) == len(arr)
            }
            return pd.DataFrame(same)
        if arr.ndim == 2:
            return pd.DataFrame(arr.T, columns=[f"{name}[{i}]" for i in range(arr.shape[0])])
        return pd.DataFrame({name: arr.ravel()})
    if isinstance(v, list | tuple):
        return pd.DataFrame({name: list(v)})
    return pd.DataFrame(
        {"quantity": [split_unit(name)[0]], "unit": [split_unit(name)[1]], "value": [v]}
    )


def study_figures(result: Any, analysis: str | None = None) -> list[Any]:
    """The report's figures of ``result`` as matplotlib figures (all, or those of the analysis
    named ``analysis``), with each figure's title as its suptitle when it has none.

    Raises
    ------
    KeyError
        When ``analysis`` names no analysis of ``result``.
    """
    from gearte.plotting import figures_for

    if analysis is not None and analysis not in result:
        raise KeyError(f"no analysis {analysis!r}; have {[a.name for a in result.analyses]}")
    figs = figures_for(result)
    if analysis is not None:
        # as in the report: a figure that names no (known) analysis goes with the first one
        names = [a.name for a in result.analyses]
        figs = [f for f in figs if (f.analysis if f.analysis in names else names[0]) == analysis]
    out = []
    for f in figs:
        if f.fig.get_suptitle() == "" and f.title:
            f.fig.suptitle(f.title, fontsize=10)
        out.append(f.fig)
    return out
