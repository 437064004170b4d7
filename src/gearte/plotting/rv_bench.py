"""Figures of the ``rv_bench`` study: hysteresis with the calibrated model, TE traces, labelled
order spectrum, trend of each labelled order across operating points, calibration residuals.
matplotlib is imported lazily (new_figure)."""

from __future__ import annotations

import numpy as np

from gearte.plotting import PALETTE, Figure, for_analysis, new_figure
from gearte.units import rad_to_arcmin, rad_to_arcsec, rad_to_deg

__all__ = ["figures", "SELF_CONTAINED"]

#: Analyses whose figures read that analysis alone (:func:`gearte.plotting.self_contained`);
#: not the catalogue (its hysteresis figure draws the calibrated model beside the bench curve).
SELF_CONTAINED = frozenset({"te_orders"})


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
    trend = orders.data.get("trend") or {}
    rows = trend.get("rows") or []
    if len(rows) < 2:
        return None
    keys = [("torque [N·m]", "torque [N·m]"), ("speed [rpm]", "speed [rpm]"),
            ("oil_temperature [°C]", "oil temperature [°C]")]  # fmt: skip
    keys = [k for k in keys if all(r[k[0]] is not None for r in rows)]
    if not keys:
        return None
    fig, axes = new_figure(1, len(keys), figsize=(4.0 * len(keys), 3.6), squeeze=False)
    labels = list(trend["labels"])
    for j, (key, xlabel) in enumerate(keys):
        ax = axes[0, j]
        x = np.array([r[key] for r in rows], dtype=float)
        for k, lab in enumerate(labels):
            y = np.array([r["amplitude [arcsec]"][lab] or np.nan for r in rows], dtype=float)
            ax.plot(x, y, "o", ms=3, color=PALETTE[k % len(PALETTE)], label=lab)
        ax.set_xlabel(xlabel)
        ax.set_ylabel("amplitude [arcsec]")
    axes[0, 0].legend(fontsize=7)
    return Figure(
        "Trend of each labelled order across operating points",
        "Amplitude of every characteristic order in each operating-point file.",
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
    cal_a = _analysis(result, "calibration")
    cal = cal_a.data["calibration"] if cal_a is not None else None
    out: list[Figure] = []
    if cat is not None:
        out += for_analysis("catalogue", [f for f in [_hysteresis(cat, cal)] if f is not None])
    if orders is not None:
        figs = [f for f in (_traces(orders), _spectrum(orders), _trend(orders)) if f is not None]
        out += for_analysis("te_orders", figs)
    return out
