"""Figures of the ``planetary`` study: group phasors, TE over the common period, MC histograms.

matplotlib is imported lazily through :func:`gearte.plotting.new_figure`; nothing calls show().
"""

from __future__ import annotations

from typing import Any

import numpy as np

from gearte.labels import label
from gearte.plotting import PALETTE, Figure, new_figure
from gearte.plotting.yield_figures import SELF_CONTAINED as _YIELD
from gearte.units import rad_to_arcsec

_OPT = "optimal_assembly_te [arcsec]"

__all__ = [
    "figures",
    "phasor_figure",
    "te_period_figure",
    "mc_histograms_figure",
    "SELF_CONTAINED",
    "NUMBA_FREE_RESULTS",
    "OTHERS_READ_ALONE",
]

#: Analyses whose figures read that analysis alone (:func:`gearte.plotting.self_contained`): the
#: coupled TE's figures are drawn while the Monte-Carlo runs (its analysis carries the optimal
#: assembly's curve where the case asks for the assembly analysis); terms and assembly have none.
SELF_CONTAINED = frozenset({"terms", "coupled_te", "assembly"}) | _YIELD

#: A result of this kind unpickles and its figures draw without numba (its records live in
#: numba-free modules: :mod:`gearte.models.planetary_terms`, the runners import their kernels
#: where they use them): the report process does not import the parent's numba-using modules
#: (~0.5 s CPU on the core beside the analyses; tests/test_report_background.py checks it).
NUMBA_FREE_RESULTS = True

#: The Monte-Carlo histogram reads the Monte-Carlo analyses alone (none of SELF_CONTAINED): once
#: the final result comes, the report process builds only it
#: (:func:`gearte.plotting.others_read_alone`).
OTHERS_READ_ALONE = True


def phasor_figure(result: Any) -> Figure | None:
    """Group phasors (one arrow per same-frequency group) at the coupled-TE assembly.

    Parameters
    ----------
    result : StudyResult
        A ``planetary`` result (its coupled-TE assembly analysis is read).

    Returns
    -------
    Figure or None
        The figure, or ``None`` when the result lacks that analysis.
    """
    if "coupled_te" not in result:
        return None
    te = result["coupled_te"].data["te"]
    fig, ax = new_figure(figsize=(5.5, 5.0))
    scale = 1e3  # mm -> µm
    lim = 1e-9
    for k, (f, z) in enumerate(zip(te.frequencies, te.phasors, strict=True)):
        z = z * scale
        ax.annotate(
            "",
            xy=(z.real, z.imag),
            xytext=(0, 0),
            arrowprops={"arrowstyle": "->", "color": PALETTE[k % len(PALETTE)], "lw": 2},
        )
        ax.plot([], [], color=PALETTE[k % len(PALETTE)], label=f"q = {f} (|Z| = {abs(z):.2f} µm)")
        lim = max(lim, abs(z))
    if te.constant:
        c = te.constant * scale
        ax.plot([0], [c], "ks", label=f"constant {c:.2f} µm")
        lim = max(lim, abs(c))
    ax.set_xlim(-1.1 * lim, 1.1 * lim)
    ax.set_ylim(-1.1 * lim, 1.1 * lim)
    ax.set_aspect("equal")
    ax.axhline(0, color="0.8", lw=0.8)
    ax.axvline(0, color="0.8", lw=0.8)
    ax.set_xlabel("Re Z [µm]")
    ax.set_ylabel("Im Z [µm]")
    ax.legend(fontsize=8, loc="upper left")
    return Figure(
        "Same-frequency groups (phasors)",
        "Each arrow is the exact phasor sum of the mesh-error terms of one frequency (multiple q "
        "of the input speed) at the assembly of the coupled-TE analysis.",
        fig,
    )


def _output_te_arcsec(te: Any, u: np.ndarray) -> np.ndarray:
    """Σe(u) of a coupled TE converted to output TE [arcsec]."""
    return rad_to_arcsec(te.signal(u) * abs(te.scale))


def te_period_figure(result: Any) -> Figure | None:
    """Σe(t) converted to output TE over one common period.

    Parameters
    ----------
    result : StudyResult
        A ``planetary`` result (its coupled TE analysis is read).

    Returns
    -------
    Figure or None
        The figure, or ``None`` when the result lacks that analysis.
    """
    if "coupled_te" not in result:
        return None
    a = result["coupled_te"]
    te = a.data["te"]
    u = a.data["u"]
    revs = u / (2 * np.pi) * float(1 / te.q0)  # input revolutions (1 / q0 per common period)
    fig, ax = new_figure()
    ax.plot(revs, _output_te_arcsec(te, u), color=PALETTE[0], lw=1.2, label="Σ e(t) (coupled)")
    amp = a["coupled_te_amplitude [arcsec]"]
    ax.axhline(amp, color=PALETTE[1], ls="--", lw=1, label=f"± amplitude {amp:.1f}″")
    ax.axhline(-amp, color=PALETTE[1], ls="--", lw=1)
    s = a["coupled_te_amplitude_sum [arcsec]"]
    ax.axhline(s, color=PALETTE[2], ls=":", lw=1, label=f"Σ group amplitudes {s:.1f}″")
    opt, opt_amp = a.data.get("optimal_te"), a.data.get(_OPT)  # where the case asks for it
    if opt is None and "assembly" in result:  # a result from before coupled_te kept it
        from gearte.models.planetary_errors import coupled_te

        d = result["assembly"].data
        opt = d.get("optimal_te")
        if opt is None:
            opt = coupled_te(d["terms"], d["mags"], d["optimal"].angles)
        opt_amp = result["assembly"][_OPT]
    if opt is not None:
        ax.plot(
            revs,
            _output_te_arcsec(opt, u),
            color=PALETTE[3],
            lw=1.0,
            label=f"optimal assembly (amplitude {opt_amp:.1f}″)",
        )
    ax.set_xlabel("input revolutions")
    ax.set_ylabel("output TE [arcsec]")
    ax.legend(fontsize=8)
    return Figure(
        "Coupled transmission error over one common period",
        "Output TE over the common period of all terms at the coupled-TE assembly; dashed: its "
        "exact amplitude max|Σe|; dotted: the sum of group amplitudes (Wang's lambda = 1 "
        "rule); purple: the globally optimal assembly.",
        fig,
    )


def mc_histograms_figure(result: Any) -> Figure | None:
    """Histogram of the coupled TE per Monte-Carlo scenario.

    Parameters
    ----------
    result : StudyResult
        A ``planetary`` result (its Monte-Carlo scenarios analysis is read).

    Returns
    -------
    Figure or None
        The figure, or ``None`` when the result lacks that analysis.
    """
    mcs = [a for a in result.analyses if a.name.startswith("mc_")]
    if not mcs:
        return None
    fig, ax = new_figure(figsize=(7.5, 4.5))
    for k, a in enumerate(mcs):
        e = np.asarray(a.data["edges [arcsec]"])
        h = np.asarray(a.data["hist"], dtype=float)
        w = np.diff(e)
        dens = h / max(h.sum(), 1) / w
        ax.stairs(
            dens,
            e,
            color=PALETTE[k % len(PALETTE)],
            lw=1.4,
            label=f"{label(a.name).removeprefix('Monte-Carlo: ')}: mean "
            f"{a['mc_mean [arcsec]']:.0f}″, sd {a['mc_sd [arcsec]']:.0f}″",
        )
    ax.set_xlabel("coupled TE amplitude [arcsec]")
    ax.set_ylabel("probability density [1/arcsec]")
    ax.legend(fontsize=7)
    return Figure(
        "Monte-Carlo of assembly strategies",
        "Distribution of the exact coupled TE per scenario (Wang 2013 Figs 2-5).",
        fig,
    )


def figures(result: Any) -> list[Figure]:
    """All figures of a ``planetary`` result."""
    from gearte.plotting.yield_figures import yield_figures

    out = [phasor_figure(result), te_period_figure(result), mc_histograms_figure(result)]
    names = [
        "coupled_te",
        "coupled_te",
        next((a.name for a in result.analyses if a.name.startswith("mc_")), ""),
    ]
    for f, name in zip(out, names, strict=True):
        if f is not None:
            f.analysis = name
    return [f for f in out if f is not None] + yield_figures(result)
