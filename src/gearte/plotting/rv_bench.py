"""Figures of the ``rv_bench`` study: hysteresis with the calibrated model, TE traces, labelled
order spectrum, trend of each labelled order across operating points, calibration residuals.
matplotlib is imported lazily (new_figure)."""

from __future__ import annotations

import numpy as np

from gearte.plotting import PALETTE, Figure, for_analysis, new_figure
from gearte.units import rad_to_arcmin, rad_to_arcsec, rad_to_deg

__all__ = ["figures", "SELF_CONTAINED", "NUMBA_FREE_RESULTS"]

#: Analyses whose figures read that analysis alone (:func:`gearte.plotting.self_contained`);
#: not the catalogue (its hysteresis figure draws the calibrated model beside the bench curve).
SELF_CONTAINED = frozenset({"te_orders", "load_series"})

#: A bench result unpickles and its figures draw without numba (the calibrated model's catalogue
#: values live in :mod:`gearte.models.rv_records`, apart from their kernels): the report process
#: is forked before the parent imports numba (tests/test_report_background.py checks it).
NUMBA_FREE_RESULTS = True


def _analysis(result, name):
    for a in result.analyses:
        if a.name == name:
            return a
    return None


def _hysteresis(cat, cal) -> Figure | None:
    if "hysteresis" not in cat.data:
        return None
    hyst, direction = cat.data["hysteresis"]
    fig, ax = new_figure(figsize=(6.0, 4.2))
    t = hyst.torque / 1e3
    for s, name, c in ((1, "ascending", PALETTE[0]), (-1, "descending", PALETTE[1])):
        m = direction == s
        ax.plot(t[m], rad_to_arcmin(hyst.angle[m]), ".", ms=2, color=c, label=f"measured, {name}")
    if cal is not None and "hysteresis" in cal.residuals:
        model = hyst.angle - cal.residuals["hysteresis"]
        ax.plot(t, rad_to_arcmin(model), "-", lw=0.8, color="k", label="calibrated model")
    ax.set_xlabel("output torque [N·m]")
    ax.set_ylabel("torsion angle [arcmin]")
    ax.legend(fontsize=8)
    v = cat.values
    return Figure(
        "Hysteresis curve",
        f"Lost motion {v.get('lost_motion [arcmin]', float('nan')):.3g} arcmin, backlash "
        f"{v.get('backlash [arcmin]', float('nan')):.3g} arcmin, rigidity "
        f"{v.get('torsional_rigidity [N·m/arcmin]', float('nan')):.4g} N·m/arcmin "
        "(definitions: docs/bench.md).",
        fig,
    )


def _traces(orders) -> Figure:
    ref = orders.data["reference"]
    fig, ax = new_figure(figsize=(7.0, 3.8))
    for k, (name, (pos, te)) in enumerate(ref.directions().items()):
        ax.plot(rad_to_deg(pos), rad_to_arcsec(te), lw=0.5, color=PALETTE[k], label=name)
    ax.set_xlabel("output position [deg]")
    ax.set_ylabel("TE [arcsec]")
    ax.legend(fontsize=8)
    return Figure("Angular transmission error", "Measured TE over one output revolution.", fig)


def _spectrum(orders) -> Figure:
    from gearte.models.orders import order_spectrum

    ref, d = orders.data["reference"], orders.data["direction"]
    pos, te = ref.directions()[d]
    o, amp, _ = order_spectrum(pos, te)
    fig, ax = new_figure(figsize=(7.0, 3.8))
    ax.semilogx(o[1:], rad_to_arcsec(amp[1:]), lw=0.6, color=PALETTE[0])
    for line in orders.values["te_orders"][:8]:
        ax.annotate(line["source"], (line["order"], line["amplitude [arcsec]"]), fontsize=7,
                    rotation=30)  # fmt: skip
    ax.set_xlabel("order [per output revolution]")
    ax.set_ylabel("amplitude [arcsec]")
    return Figure(
        "Order spectrum of the TE",
        "Largest orders labelled by their source from the drive's tooth numbers.",
        fig,
    )


def _trend(orders) -> Figure | None:
    """Amplitude of each tracked order against torque, one line per (speed, temperature)."""
    trend = orders.data.get("trend") or {}
    rows = trend.get("rows") or []
    labels = list(trend.get("labels") or [])
    if len(rows) < 2 or not labels:
        return None
    by_torque = all(r["torque [N·m]"] is not None for r in rows)
    groups: dict = {}
    for r in rows:
        groups.setdefault((r["speed [rpm]"], r["oil_temperature [°C]"]), []).append(r)
    ncol = min(4, len(labels))
    nrow = (len(labels) + ncol - 1) // ncol
    fig, axes = new_figure(nrow, ncol, figsize=(3.3 * ncol, 2.8 * nrow), squeeze=False)
    for j, lab in enumerate(labels):
        ax = axes[j // ncol, j % ncol]
        for k, ((speed, temp), rs) in enumerate(groups.items()):
            if by_torque:
                rs = sorted(rs, key=lambda r: r["torque [N·m]"])
                x = [r["torque [N·m]"] for r in rs]
            else:
                x = list(range(len(rs)))
            y = [r["amplitude [arcsec]"][lab] for r in rs]
            ax.plot(x, y, "o-", ms=3, lw=0.8, color=PALETTE[k % len(PALETTE)],
                    label=_group_label(speed, temp))  # fmt: skip
        ax.set_title(f"order {lab}", fontsize=8)
        ax.set_xlabel("load torque [N·m]" if by_torque else "file")
        ax.set_ylabel("amplitude [arcsec]")
    for j in range(len(labels), nrow * ncol):
        axes[j // ncol, j % ncol].set_visible(False)
    axes[0, 0].legend(fontsize=6)
    return Figure(
        "Each order tracked across the files of the series",
        "Amplitude of the largest orders (over all files) in every file, against the load "
        "torque, one line per speed and oil temperature: a line that grows with load points to "
        "a load-dependent source (labels from the drive's tooth numbers).",
        fig,
    )


def _group_label(speed, temp) -> str:
    parts = []
    if speed is not None:
        parts.append(f"{speed:g} rpm")
    if temp is not None:
        parts.append(f"{temp:g} °C")
    return ", ".join(parts) or "all files"


def _series_curves(ls) -> Figure:
    """Forward−backward mean and mean TE against torque, one line per (speed, temperature)."""
    points = ls.data["points"]
    groups: dict = {}
    for p in points:
        groups.setdefault((p["speed [rpm]"], p["oil_temperature [°C]"]), []).append(p)
    fig, axes = new_figure(1, 2, figsize=(9.0, 3.8), squeeze=False)
    for k, ((speed, temp), ps) in enumerate(groups.items()):
        ps = sorted(ps, key=lambda p: p["torque [N*m]"])
        t = [p["torque [N*m]"] for p in ps]
        c = PALETTE[k % len(PALETTE)]
        lab = _group_label(speed, temp)
        axes[0, 0].errorbar(
            t, [p["forward_backward_difference_mean [arcsec]"] / 60.0 for p in ps],
            yerr=[1.96 * p["forward_backward_difference_se [arcsec]"] / 60.0 for p in ps],
            fmt="o-", ms=3, lw=0.8, color=c, label=lab,
        )  # fmt: skip
        axes[0, 1].plot(t, [p["mean_te [arcsec]"] for p in ps], "o-", ms=3, lw=0.8, color=c,
                        label=lab)  # fmt: skip
    axes[0, 0].set_xlabel("load torque [N·m]")
    axes[0, 0].set_ylabel("forward − backward mean TE [arcmin]")
    axes[0, 1].set_xlabel("load torque [N·m]")
    axes[0, 1].set_ylabel("mean of forward and backward TE [arcsec]")
    axes[0, 0].legend(fontsize=7)
    return Figure(
        "Load series: forward − backward and mean TE against torque",
        "Left: D(T), the running curve's spread (its slope gives the rigidity, its value at "
        "f T_r the lost motion, at zero load the hysteresis), with 95 % noise intervals; right: "
        "the mean of both directions (an asymmetry of the reducer or the rig). Definitions: "
        "docs/bench.md.",
        fig,
    )


def _series_trends(ls) -> Figure | None:
    """The four catalogue quantities with their intervals against speed, one marker per oil
    temperature."""
    rows = ls.values["series"]
    if len(rows) < 2:
        return None
    names = [("bench_torsional_rigidity", "N*m/arcmin", "torsional rigidity [N·m/arcmin]"),
             ("bench_lost_motion", "arcmin", "lost motion [arcmin]"),
             ("bench_hysteresis", "arcmin", "hysteresis [arcmin]"),
             ("bench_backlash", "arcmin", "backlash [arcmin]")]  # fmt: skip
    fig, axes = new_figure(1, 4, figsize=(13.0, 3.4), squeeze=False)
    temps = sorted({r["oil_temperature [°C]"] for r in rows}, key=lambda x: (x is None, x or 0))
    for j, (name, unit, ylabel) in enumerate(names):
        ax = axes[0, j]
        for k, temp in enumerate(temps):
            rs = sorted((r for r in rows if r["oil_temperature [°C]"] == temp),
                        key=lambda r: r["speed [rpm]"] or 0.0)  # fmt: skip
            x = np.array([r["speed [rpm]"] or 0.0 for r in rs], dtype=float)
            y = np.array([np.nan if r[f"{name} [{unit}]"] is None else r[f"{name} [{unit}]"]
                          for r in rs])  # fmt: skip
            lo = np.array([np.nan if r[f"{name}_ci_low [{unit}]"] is None
                           else r[f"{name}_ci_low [{unit}]"] for r in rs])  # fmt: skip
            hi = np.array([np.nan if r[f"{name}_ci_high [{unit}]"] is None
                           else r[f"{name}_ci_high [{unit}]"] for r in rs])  # fmt: skip
            err = np.nan_to_num(np.vstack([y - lo, hi - y]), nan=0.0)
            ax.errorbar(x, y, yerr=err, fmt="o-", ms=4, lw=0.8, capsize=3,
                        color=PALETTE[k % len(PALETTE)],
                        label="oil " + ("?" if temp is None else f"{temp:g} °C"))  # fmt: skip
        ax.set_xlabel("output speed [rpm]")
        ax.set_ylabel(ylabel)
    axes[0, 0].legend(fontsize=7)
    return Figure(
        "Load series: trends over speed and oil temperature",
        "Torsional rigidity, lost motion, hysteresis and backlash of each (speed, oil "
        "temperature) series with 95 % intervals (noise of the traces only).",
        fig,
    )


def figures(result) -> list[Figure]:
    """The figures of an ``rv_bench`` result: hysteresis with the calibrated model, TE traces,
    order spectrum and order trend (each where its analysis ran).

    Parameters
    ----------
    result : StudyResult
        An ``rv_bench`` result.

    Returns
    -------
    list of Figure
        Titled figures for the report.
    """
    cat = _analysis(result, "catalogue")
    orders = _analysis(result, "te_orders")
    ls = _analysis(result, "load_series")
    cal_a = _analysis(result, "calibration")
    cal = cal_a.data["calibration"] if cal_a is not None else None
    out: list[Figure] = []
    if cat is not None:
        out += for_analysis("catalogue", [f for f in [_hysteresis(cat, cal)] if f is not None])
    if ls is not None:
        figs = [f for f in (_series_curves(ls), _series_trends(ls)) if f is not None]
        out += for_analysis("load_series", figs)
    if orders is not None:
        figs = [f for f in (_traces(orders), _spectrum(orders), _trend(orders)) if f is not None]
        out += for_analysis("te_orders", figs)
    return out
