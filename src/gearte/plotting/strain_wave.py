"""Figures of the ``strain_wave`` study: the torsion curve with its hysteresis loop, the
transmission error over one output revolution, and the yield's figures.

matplotlib is imported lazily through :func:`gearte.plotting.new_figure`; nothing calls show().
"""

from __future__ import annotations

from typing import Any

import numpy as np

from gearte.plotting import PALETTE, Figure, new_figure
from gearte.plotting.yield_figures import SELF_CONTAINED as _YIELD

__all__ = ["figures", "stiffness_figure", "te_figure", "SELF_CONTAINED", "NUMBA_FREE_RESULTS"]

#: Each figure reads its own analysis only.
SELF_CONTAINED = frozenset({"stiffness", "transmission_error"}) | _YIELD

#: A strain-wave result unpickles and its figures draw without numba: the report process is
#: forked before the parent imports numba (tests/test_report_background.py checks it).
NUMBA_FREE_RESULTS = True


def stiffness_figure(result: Any) -> Figure | None:
    """Torsion φ(T) ∓ H/2 against output torque, with T1, T2 and the lost-motion test torque.

    Parameters
    ----------
    result : StudyResult
        A ``strain_wave`` result (its ``stiffness`` analysis is read).
    """
    if "stiffness" not in result:
        return None
    a = result["stiffness"]
    v = a.values
    fig, ax = new_figure()
    t = np.asarray(v["torque [N*m]"])
    ax.plot(t, v["torsion_loading [arcmin]"], color=PALETTE[0], lw=1.5, label="loading")
    ax.plot(t, v["torsion_unloading [arcmin]"], color=PALETTE[1], lw=1.5, label="unloading")
    tl = v["lost_motion_torque [N*m]"]
    for x in (-tl, tl):
        ax.axvline(x, color=PALETTE[2], lw=0.8, ls="--")
    ax.set_xlabel("output torque [N·m]")
    ax.set_ylabel("torsion [arcmin]")
    ax.legend(fontsize=8)
    return Figure(
        "Torsion curve and hysteresis loop",
        f"Three-segment catalogue model; the loop's width at zero torque is the hysteresis loss "
        f"({v['hysteresis_loss [arcmin]']:.3g}′); dashed: the lost-motion test torque ±{tl:g} N·m "
        f"(lost motion {v['lost_motion [arcmin]']:.3g}′).",
        fig,
        "stiffness",
    )


def te_figure(result: Any) -> Figure | None:
    """TE over one output revolution.

    Parameters
    ----------
    result : StudyResult
        A ``strain_wave`` result (its ``transmission_error`` analysis is read).
    """
    if "transmission_error" not in result:
        return None
    v = result["transmission_error"].values
    fig, ax = new_figure()
    ax.plot(v["output_angle [deg]"], v["te [arcsec]"], color=PALETTE[0], lw=0.8)
    ax.set_xlabel("output angle [deg]")
    ax.set_ylabel("transmission error [arcsec]")
    return Figure(
        "Transmission error over one output revolution",
        f"Peak-to-peak {v['te_peak_to_peak [arcsec]']:.3g}″; once per wave-generator revolution "
        f"{v['te_once_per_wg_revolution [arcsec]']:.3g}″, twice per revolution "
        f"{v['te_twice_per_wg_revolution [arcsec]']:.3g}″ (amplitudes).",
        fig,
        "transmission_error",
    )


def figures(result: Any) -> list[Figure]:
    """All figures of a ``strain_wave`` result."""
    from gearte.plotting.yield_figures import yield_figures

    out = [stiffness_figure(result), te_figure(result)]
    return [f for f in out if f is not None] + yield_figures(result)
