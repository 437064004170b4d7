"""Figures of the ``gear_pair`` and ``gear_chain`` study kinds.

* backlash histogram of the Monte-Carlo samples with the analytic normal overlaid;
* contribution Pareto of each pair (variance shares, cumulative line);
* chain diagram with each stage's share of the joint's return error;
* return error at the joint and end error before/after shim and motor compensation;
* transmission error at the joint from the drives that model one (``chain_te``).

matplotlib is imported lazily (through :func:`gearte.plotting.new_figure`); nothing calls show().
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from gearte.plotting import PALETTE, Figure, new_figure
from gearte.units import mm_to_um

__all__ = [
    "figures",
    "backlash_histogram",
    "contribution_pareto",
    "chain_diagram",
    "compensation",
    "joint_te",
    "NUMBA_FREE_RESULTS",
]

#: A gear pair's or gear chain's result unpickles and its figures draw without numba (the
#: Monte-Carlo record lives in :mod:`gearte.tolerance.mc_result`, apart from its kernels; a
#: chain's RV, cycloid and strain-wave stages keep plain values): the report process is forked
#: before the parent imports numba and imports none of the parent's kernel modules
#: (tests/test_report_background.py checks it for every bundled case of both kinds).
NUMBA_FREE_RESULTS = True


def backlash_histogram(backlash: Any, mc: Any, title: str) -> Figure:
    """Histogram of sampled normal backlash [µm] with the analytic normal density overlaid.

    Parameters
    ----------
    backlash : AnalysisResult
        The pair's backlash analysis (``backlash_mean [um]``, ``backlash_sd [um]``).
    mc : object
        Monte-Carlo result whose ``samples`` are the normal backlash [mm].
    title : str
        Figure title.

    Returns
    -------
    Figure
        The matplotlib figure (never shown).
    """
    v = backlash.values
    mean, sd = v["backlash_mean [um]"], v["backlash_sd [um]"]
    samples = mm_to_um(np.asarray(mc.samples))
    fig, ax = new_figure()
    from gearte.plotting.display import STRIP_BELOW, distribution

    drawn = distribution(ax, samples, color=PALETTE[5], label="Monte-Carlo", density=True, bins=80)
    x = np.linspace(mean - 4.5 * sd, mean + 4.5 * sd, 300)
    dens = ax if drawn == "histogram" else ax.twinx()
    dens.plot(
        x,
        np.exp(-0.5 * ((x - mean) / sd) ** 2) / (sd * math.sqrt(2 * math.pi)),
        color=PALETTE[1],
        lw=2,
        label=f"analytic N({mean:.1f}, {sd:.2f}²)",
    )
    for key, ls in (("backlash_min [um]", "--"), ("backlash_max [um]", "--")):
        ax.axvline(v[key], color=PALETTE[0], ls=ls, lw=1)
    lim = v.get("min_backlash_limit [um]", 0.0)
    if lim:
        ax.axvline(lim, color=PALETTE[7], ls=":", lw=1.5, label=f"minimum limit {lim:g} µm")
    ax.set_xlabel("normal backlash [µm]")
    ax.set_ylabel("probability density [1/µm]" if len(samples) >= STRIP_BELOW else "samples")
    ax.legend(loc="upper left", fontsize=8)
    return Figure(
        title,
        f"{len(samples)} of the Monte-Carlo samples; dashed lines: analytic min/max at "
        f"{100 * v['confidence']:.2f} % ({v['backlash_min [um]']:.1f}–"
        f"{v['backlash_max [um]']:.1f} µm).",
        fig,
    )


def contribution_pareto(contrib: Any, title: str) -> Figure:
    """Pareto chart of variance shares [%] with the cumulative share.

    Parameters
    ----------
    contrib : AnalysisResult
        The contribution analysis (``variance_share [%]`` per tolerance).
    title : str
        Figure title.

    Returns
    -------
    Figure
        The matplotlib figure (never shown).
    """
    shares = contrib.values["variance_share [%]"]
    items = sorted(shares.items(), key=lambda kv: kv[1], reverse=True)
    names = [k for k, _ in items]
    vals = np.array([s for _, s in items])
    fig, ax = new_figure(figsize=(7.0, 4.2))
    ax.bar(range(len(vals)), vals, color=PALETTE[0])
    ax.set_xticks(range(len(vals)), names, rotation=35, ha="right", fontsize=8)
    ax.set_ylabel("variance share [%]")
    ax2 = ax.twinx()
    ax2.plot(range(len(vals)), np.cumsum(vals), color=PALETTE[1], marker="o")
    ax2.set_ylim(0, 105)
    ax2.set_ylabel("cumulative [%]")
    return Figure(title, "Share of the backlash variance of each tolerance, largest first.", fig)


def chain_diagram(chain: Any) -> Figure:
    """Stages from motor to joint as boxes; each labelled with its share of the joint error.

    Parameters
    ----------
    chain : AnalysisResult
        The ``chain`` analysis (``stage_share [%]``, ``stage_ratio``).

    Returns
    -------
    Figure
        The matplotlib figure (never shown).
    """
    from matplotlib.patches import FancyBboxPatch

    v = chain.values
    shares = v["stage_share [%]"]
    ratios = v["stage_ratio"]
    fig, ax = new_figure(figsize=(8.0, 2.8))
    names = list(shares)
    n = len(names) + 2
    ax.set_xlim(-0.5, n - 0.5)
    ax.set_ylim(-1.2, 1.2)
    ax.axis("off")
    labels = ["motor"] + names + ["joint"]
    for k, lab in enumerate(labels):
        is_stage = 0 < k < n - 1
        share = shares[lab] if is_stage else None
        colour = PALETTE[(k - 1) % len(PALETTE)] if is_stage else "#dddddd"
        ax.add_patch(
            FancyBboxPatch(
                (k - 0.4, -0.45), 0.8, 0.9, boxstyle="round,pad=0.02", fc=colour, alpha=0.35
            )
        )
        ax.text(k, 0.15, lab, ha="center", va="center", fontsize=8, wrap=True)
        if is_stage:
            ax.text(k, -0.2, f"i = {ratios[lab]:.4g}", ha="center", fontsize=7)
            ax.text(k, -0.75, f"{share:.1f} %", ha="center", fontsize=9, weight="bold")
        if k < n - 1:
            ax.annotate("", (k + 0.6, 0), (k + 0.4, 0), arrowprops={"arrowstyle": "->"})
    ax.text(
        (n - 1) / 2,
        1.0,
        f"joint lost motion max {v['joint_lost_motion_max [arcmin]']:.3f}′ "
        f"→ end error {v['end_effector_error_max [mm]']:.3f} mm",
        ha="center",
        fontsize=9,
    )
    return Figure(
        "Gear chain and each stage's share of the joint lost motion",
        "Percentages: stage k's maximum return error referred to the joint (Δφk / Πi downstream, "
        "eq. 30) over the chain's maximum.",
        fig,
    )


def compensation(result: Any) -> Figure:
    """Stage contributions at the joint [arcmin] before, after shim and after compensation.

    Parameters
    ----------
    result : StudyResult
        A ``gear_chain`` result (its ``chain``, ``shim`` and ``compensation`` analyses).

    Returns
    -------
    Figure
        The matplotlib figure (never shown).
    """
    chain = result["chain"]
    stages = list(chain.values["stage_share [%]"])
    cols = [("before", chain.values["stage_at_joint_max [arcmin]"])]
    end = [chain.values["end_effector_error_max [mm]"]]
    if "shim" in result:
        cols.append(("after shim", result["shim"].values["stage_at_joint_max_after_shim [arcmin]"]))
        end.append(result["shim"].values["end_effector_error_after_shim [mm]"])
    if "compensation" in result:
        comp = result["compensation"].values
        cols.append(("after motor compensation", comp["stage_at_joint_residual [arcmin]"]))
        end.append(comp["end_effector_error_after_compensation [mm]"])
    fig, (ax, ax2) = new_figure(1, 2, figsize=(8.5, 3.8), width_ratios=[3, 1.3])
    bottom = np.zeros(len(cols))
    for k, s in enumerate(stages):
        h = np.array([c[1][s] for c in cols])
        ax.bar(range(len(cols)), h, bottom=bottom, color=PALETTE[k % len(PALETTE)], label=s)
        bottom += h
    for x, b in enumerate(bottom):
        ax.text(x, b, f"{b:.2f}′", ha="center", va="bottom", fontsize=8)
    ax.set_xticks(range(len(cols)), [c[0] for c in cols], fontsize=8)
    ax.set_ylabel("return error at the joint [arcmin]")
    ax.legend(fontsize=7)
    ax2.bar(range(len(end)), end, color=PALETTE[2])
    for x, e in enumerate(end):
        ax2.text(x, e, f"{e:.2f}", ha="center", va="bottom", fontsize=8)
    short = {"before": "before", "after shim": "shim", "after motor compensation": "motor comp."}
    ax2.set_xticks(range(len(end)), [short[c[0]] for c in cols], fontsize=8)
    ax2.set_ylabel("end-effector error [mm]")
    return Figure(
        "Lost motion before and after compensation",
        "Maximum return error of each stage referred to the joint, stacked (worst case, eq. 30), "
        "and the end-effector error (eq. 31).",
        fig,
    )


def joint_te(chain_te: Any) -> Figure:
    """Transmission error at the joint [arcsec] over one joint turn (``chain_te`` analysis)."""
    v = chain_te.values
    fig, ax = new_figure()
    ax.plot(
        np.asarray(v["joint_angle [deg]"]), np.asarray(v["joint_te [arcsec]"]), color=PALETTE[0]
    )
    ax.set_xlabel("joint angle [deg]")
    ax.set_ylabel("TE at the joint [arcsec]")
    ax.set_title("Transmission error at the joint")
    return Figure(
        "Transmission error at the joint",
        f"From the drives with a TE model ({', '.join(v['stages_with_te']) or 'none'}); "
        f"peak to peak {v['joint_te_peak_to_peak_sampled [arcsec]']:.2f}″ at the sampled "
        "positions.",
        fig,
    )


def figures(result: Any) -> list[Figure]:
    """All figures of a gear_pair or gear_chain result."""
    figs: list[Figure] = []
    for a in result.analyses:
        if a.name.endswith("backlash") and "kind" in a.data:
            prefix = a.name[: -len("backlash")]
            label = a.title.split("Normal backlash")[0]
            mc_name = f"{prefix}monte_carlo"
            if mc_name in result:
                f = backlash_histogram(
                    a, result[mc_name].data["mc"], f"{label}{a.data['kind']} pair backlash"
                )
                f.analysis = mc_name
                figs.append(f)
            c_name = f"{prefix}contributions"
            if c_name in result:
                f = contribution_pareto(result[c_name], f"{label}{a.data['kind']} pair Pareto")
                f.analysis = c_name
                figs.append(f)
    if "chain" in result:
        f = chain_diagram(result["chain"])
        f.analysis = "chain"
        figs.append(f)
        f = compensation(result)
        f.analysis = "compensation" if "compensation" in result else "chain"
        figs.append(f)
    if "chain_te" in result:
        f = joint_te(result["chain_te"])
        f.analysis = "chain_te"
        figs.append(f)
    return figs
