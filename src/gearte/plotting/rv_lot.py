"""Figures of the ``rv_lot`` study: the reducers' TE of the optimiser's assembly beside the
orientation-only rule, and the spread of reducers in spec over the random assemblies.
matplotlib is imported lazily (new_figure)."""

from __future__ import annotations

import numpy as np

from gearte.plotting import PALETTE, Figure, for_analysis, new_figure
from gearte.units import rad_to_arcsec

__all__ = ["figures", "NUMBA_FREE_RESULTS"]

#: A lot's result unpickles and its figures draw without numba (the lot, its score table and
#: assembly live in :mod:`gearte.runners.rv_records`, apart from the solvers): the report process
#: is forked before the parent imports numba (tests/test_report_background.py checks it).
NUMBA_FREE_RESULTS = True


def figures(result) -> list[Figure]:
    """The figures of an ``rv_lot`` result.

    Parameters
    ----------
    result : gearte.results.StudyResult
        An ``rv_lot`` result.
    """
    if "selective_assembly" not in result:
        return []
    a = result["selective_assembly"]
    d = a.data
    limit = rad_to_arcsec(d["limit"])
    fig, ax = new_figure(figsize=(7.0, 3.8))
    opt = np.sort(rad_to_arcsec(d["best"].pp))
    ori = np.sort(rad_to_arcsec(d["orientation_only"].pp))
    x = np.arange(1, opt.size + 1)
    ax.plot(x, opt, "o-", ms=3, color=PALETTE[0], label="optimised assembly")
    ax.plot(x, ori, "s-", ms=3, color=PALETTE[1], label="orientation only")
    if np.all(np.isfinite(d["full"])):
        ax.plot(x, np.sort(rad_to_arcsec(d["full"])), "x", ms=4, color="k", label="full model")
    ax.axhline(limit, color="0.4", lw=0.8, ls="--", label="spec")
    ax.set_xlabel("reducer (sorted by TE)")
    ax.set_ylabel("TE peak-to-peak [arcsec]")
    ax.legend(fontsize=8)
    f1 = Figure(
        "TE of the lot's reducers",
        f"Loaded TE peak-to-peak of every reducer, sorted; spec {limit:.4g} arcsec.",
        fig,
    )
    fig2, ax2 = new_figure(figsize=(6.0, 3.4))
    counts = d["random"]
    bins = np.arange(counts.min(), counts.max() + 2) - 0.5
    ax2.hist(counts, bins=bins, color=PALETTE[2], label="random assemblies")
    ax2.axvline(a["reducers_in_spec"], color=PALETTE[0], lw=1.5, label="optimised")
    ax2.axvline(a["reducers_in_spec_orientation_only"], color=PALETTE[1], lw=1.5, ls=":",
                label="orientation only")  # fmt: skip
    ax2.set_xlabel("reducers in spec")
    ax2.set_ylabel("random assemblies")
    ax2.legend(fontsize=8)
    f2 = Figure(
        "Reducers in spec: optimised, orientation only and random",
        f"Histogram over {counts.size} random assemblies (random pairing and orientation).",
        fig2,
    )
    return for_analysis("selective_assembly", [f1, f2])
