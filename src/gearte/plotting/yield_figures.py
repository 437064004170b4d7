"""Figures of a production-yield analysis (``[analyses.yield]``, any study kind).

* the distribution of each specified quantity with its spec limits, yield and Cpk;
* the contribution Pareto: total Sobol index per tolerance (bar, with its bootstrap interval),
  the first-order index (dot) and the linear sensitivity × σ share (cross) beside it, the
  cumulative share (line) — where the linear share and the Sobol index differ, the physics is
  non-linear.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from gearte.plotting import PALETTE, Figure, for_analysis, new_figure

__all__ = ["yield_figures", "SELF_CONTAINED"]

#: Analyses whose figures read that analysis alone (:func:`gearte.plotting.self_contained`).
SELF_CONTAINED = frozenset({"yield"})


def _histograms(a: Any) -> Figure | None:
    res = a.data.get("yield")
    if res is None or not res.spec:
        return None
    specs = [s for s in res.spec if s.quantity in res.head and res.head[s.quantity].size]
    if not specs:
        return None
    fig, axes = new_figure(1, len(specs), figsize=(4.2 * len(specs), 3.4), squeeze=False)
    for ax, s in zip(axes[0], specs, strict=True):
        y = res.head[s.quantity]
        y = y[np.isfinite(y)]
        ax.hist(y, bins=40, color=PALETTE[0], alpha=0.8)
        for lim in (s.lower, s.upper):
            if lim is not None:
                ax.axvline(lim, color=PALETTE[1], lw=1.5)
        q = res.quantities[s.quantity]
        cpk = "—" if q.cpk is None else f"{q.cpk:.2f}"
        ax.set_title(f"fails {100 * (q.fail_fraction or 0):.2f} %, Cpk {cpk}", fontsize=9)
        ax.set_xlabel(s.quantity)
        ax.set_ylabel("samples")
    return Figure(
        "Yield: specified quantities",
        f"Distribution of each specified quantity over the first {res.head[specs[0].quantity].size}"
        f" samples, spec limits in orange. Yield {100 * res.yield_:.2f} % "
        f"({100 * res.ci[0]:.2f}–{100 * res.ci[1]:.2f} %, {res.confidence:.0%} {res.ci_method}) "
        f"of {res.n} drawn drives.",
        fig,
    )


def _pareto(a: Any) -> Figure | None:
    rows = a.data.get("pareto")
    if not rows:
        return None
    names = [r["tolerance"] for r in rows]
    x = np.arange(len(rows))
    st = np.array([r["sobol_total"] for r in rows])
    lo = np.array([r["sobol_total_ci"][0] for r in rows])
    hi = np.array([r["sobol_total_ci"][1] for r in rows])
    s1 = np.array([r["sobol_first"] for r in rows])
    lin = np.array([r["linear_share"] or 0.0 for r in rows])
    fig, ax = new_figure(figsize=(max(6.0, 0.6 * len(rows) + 3), 3.8))
    ax.bar(x, st, color=PALETTE[0], alpha=0.8, label="total Sobol index")
    ax.errorbar(
        x,
        st,
        yerr=[np.maximum(st - lo, 0), np.maximum(hi - st, 0)],
        fmt="none",
        ecolor="k",
        capsize=3,
        lw=1,
    )
    ax.plot(x, s1, "o", color=PALETTE[2], label="first-order Sobol index")
    ax.plot(x, lin, "x", color=PALETTE[1], ms=8, mew=2, label="linear share (least squares)")
    ax.plot(
        x,
        [r["cumulative_total_share"] for r in rows],
        "-",
        color=PALETTE[3],
        label="cumulative share of Σ total",
    )
    ax.set_xticks(x, names, rotation=30, ha="right", fontsize=8)
    ax.set_ylabel("share of the variance")
    ax.set_ylim(bottom=min(0.0, float(np.min(s1)) - 0.05))
    ax.legend(fontsize=8)
    return Figure(
        "Which tolerance drives the spread",
        f"Contribution Pareto of {a.values.get('sobol_quantity')}: total Sobol index per "
        "independent factor (a tolerance family, or the families a correlated group joins; "
        "bars, bootstrap interval), first-order index (dots) and the linear share (crosses, "
        "the factor's share in the least-squares linear fit). A cross below its dot is what "
        "is non-linear in that factor alone (clearances, contact loss, amplitudes); a bar "
        "above its dot, its interactions with the others.",
        fig,
    )


def yield_figures(result: Any) -> list[Figure]:
    """Figures of the ``yield`` analysis of a study result (none without one)."""
    out: list[Figure] = []
    for a in result.analyses:
        if a.name != "yield":
            continue
        out += for_analysis(a.name, [f for f in (_histograms(a), _pareto(a)) if f is not None])
    return out
