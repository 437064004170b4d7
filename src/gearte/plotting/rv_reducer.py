"""Figures of the ``rv_reducer`` study: pin-load map, peak pin load with/without errors, TE split,
hysteresis curve with lost motion and rigidity, compliance breakdown of the stiffness chain.
matplotlib is imported lazily (new_figure)."""

from __future__ import annotations

import numpy as np

from gearte.plotting import PALETTE, Figure, cycloid_stage, for_analysis, new_figure, rv_dynamics
from gearte.plotting.yield_figures import SELF_CONTAINED as _YIELD
from gearte.units import (
    Nm_to_Nmm,
    Nmm_per_rad_to_Nm_per_arcmin,
    format_quantity,
    rad_to_arcmin,
    rad_to_arcsec,
    rad_to_deg,
)

__all__ = ["figures", "SELF_CONTAINED", "NUMBA_FREE_RESULTS"]

#: Analyses whose figures read that analysis alone (:func:`gearte.plotting.self_contained`):
#: this kind's own, the cycloid stage's, the dynamics' and the yield's. ``cycloid_compensation``
#: has no figure: listed, it does not make the report process build every figure again once
#: the final result comes (~0.1 s on hu2020_rv80e_initial_reducer's critical path).
SELF_CONTAINED = (
    frozenset(
        {"load_sharing", "transmission_error", "catalogue", "compensation", "cycloid_compensation"}
    )
    | cycloid_stage.SELF_CONTAINED
    | rv_dynamics.SELF_CONTAINED
    | _YIELD
)

#: A result of the ``rv_reducer`` and ``rv_serial`` kinds unpickles and its figures draw without
#: numba (its records live in :mod:`gearte.models.rv_records`,
#: :mod:`gearte.models.cycloid_loaded_contact_record`, :mod:`gearte.solvers.ode_result` and
#: :mod:`gearte.runners.rv_records`, apart from their kernels): the report process is forked
#: before the parent imports numba and imports none of the parent's kernel modules
#: (tests/test_report_background.py checks it for every bundled case of both kinds).
NUMBA_FREE_RESULTS = True


#: Width of the pin-load maps' colorbar and its gap to the last map [inch].
_CBAR_IN, _CBAR_GAP_IN = 0.14, 0.12


def _pin_map(ls, title: str) -> Figure:
    from matplotlib.ticker import MaxNLocator

    n_discs = ls.pin_force.shape[1]
    # a fixed grid (no layout engine: the slowest RV figure drew in ~0.33 s CPU, ~45 % of it
    # constrained layout measuring labels): the labels' sizes are known — pin numbers of up to
    # three digits, angles 0-360, a title "disc j" — and the right margin holds the colorbar
    # (_CBAR_IN) with tick labels of up to seven digits and its label
    width = 4.0 * n_discs + 1.0
    fig, axes = new_figure(
        1, n_discs, figsize=(width, 4.0), squeeze=False, margins_in=(0.62, 0.56, 0.32, 1.25)
    )
    deg = rad_to_deg(ls.theta)
    vmax = float(ls.pin_force.max()) or 1.0
    im = None
    for j in range(n_discs):
        ax = axes[0, j]
        im = ax.imshow(
            ls.pin_force[:, j, :].T,
            aspect="auto",
            origin="lower",
            extent=(deg[0], deg[-1] + (deg[1] - deg[0] if deg.size > 1 else 1.0), 0.5,
                    ls.pin_force.shape[2] + 0.5),
            vmin=0.0,
            vmax=vmax,
            cmap="viridis",
        )  # fmt: skip
        ax.set_xlabel("output angle [deg]")
        ax.set_ylabel("pin")
        ax.yaxis.set_major_locator(MaxNLocator(integer=True))  # pin numbers
        ax.set_title(f"disc {j + 1}")
    box = axes[0, -1].get_position()  # figure fractions
    cax = fig.add_axes((box.x1 + _CBAR_GAP_IN / width, box.y0, _CBAR_IN / width, box.height))
    fig.colorbar(im, cax=cax, label="pin load [N]")
    return Figure(
        title,
        "Load of every pin on each disc over one output revolution (quasi-static equilibrium "
        "of the whole reducer). Bright diagonal bands: the loaded flank travelling round the "
        "pin ring z_c times per revolution.",
        fig,
    )


def _peak(ls, ls0) -> Figure:
    fig, ax = new_figure()
    deg = rad_to_deg(ls.theta)
    ax.plot(deg, ls.pin_force.max(axis=(1, 2)), color=PALETTE[1], label="with errors")
    if ls0 is not None:
        ax.plot(deg, ls0.pin_force.max(axis=(1, 2)), color=PALETTE[0], label="without errors")
    ax.set_xlabel("output angle [deg]")
    ax.set_ylabel("largest pin load [N]")
    ax.legend(fontsize=8)  # the report puts it below the axes (plotting.display.polish)
    return Figure(
        "Peak pin load over one output revolution",
        "Largest pin load of both discs at each output angle, with and without the measured "
        "manufacturing errors (Han et al. 2023, Fig 6 style).",
        fig,
    )


def _te(te) -> Figure:
    fig, ax = new_figure()
    deg = rad_to_deg(te.theta)
    ax.plot(deg, rad_to_arcsec(te.total), color=PALETTE[7], label="total (loaded)")
    ax.plot(deg, rad_to_arcsec(te.geometric), color=PALETTE[0], label="geometric (zero load)")
    ax.plot(deg, rad_to_arcsec(te.elastic), color=PALETTE[1], label="elastic = total - geometric")
    ax.set_xlabel("output angle [deg]")
    ax.set_ylabel("output angle error [arcsec]")
    ax.legend(fontsize=8)  # the report puts it below the axes (plotting.display.polish)
    return Figure(
        "Transmission error over one output revolution",
        "Output angle error (actual - nominal, negative = lag) with the input held, split into "
        "its geometric part (errors and clearances, zero load) and its elastic part.",
        fig,
    )


def _hysteresis(cat, rated: float) -> Figure:
    fig, ax = new_figure()
    T = cat.curve.torque / rated * 100.0
    ang = rad_to_arcmin(cat.curve.angle)
    ax.plot(T, ang, "-o", ms=2.5, color=PALETTE[0], label="virtual test (input locked)")
    # rigidity line through the 50 % and 100 % points of the positive branch
    k = cat.torsional_rigidity  # N·mm/rad
    pos = T > 0
    if np.any(pos):
        i100 = np.argmin(np.abs(T - 100.0))
        t = np.array([50.0, 100.0])
        ax.plot(
            t,
            ang[i100] + rad_to_arcmin((t - 100.0) / 100.0 * rated / k),
            color=PALETTE[1],
            lw=2,
            label=f"rigidity {format_quantity(Nmm_per_rad_to_Nm_per_arcmin(k), 'N*m/arcmin')}",
        )
    lost = format_quantity(rad_to_arcmin(cat.lost_motion), "arcmin")
    ax.axvspan(-3.0, 3.0, color=PALETTE[2], alpha=0.2, label=f"±3 %: lost motion {lost}")
    ax.axvline(0.0, color="k", lw=0.5)
    ax.set_xlabel("output torque [% rated]")
    ax.set_ylabel("output torsion angle [arcmin]")
    ax.set_title(f"backlash {format_quantity(rad_to_arcmin(cat.backlash), 'arcmin')}")
    ax.legend(fontsize=8)
    return Figure(
        "Hysteresis curve",
        "Output torsion angle against output torque swept through ± rated torque with the input "
        "locked; torsional rigidity from the 50-100 % points, lost motion between ±3 %, backlash "
        "= jump at zero torque. The model is frictionless, so the branches coincide.",
        fig,
    )


def _compliance_shares(chain) -> Figure:
    fig, ax = new_figure(figsize=(6.0, 3.6))
    names = list(chain.shares)
    shares = np.array([chain.shares[n] for n in names]) * 100.0
    y = np.arange(len(names))[::-1]
    ax.barh(y, shares, color=PALETTE[0])
    ax.set_yticks(y, names)
    for yi, v in zip(y, shares, strict=True):
        ax.text(v, yi, f" {v:.1f} %", va="center", fontsize=7)
    ax.set_xlabel("share of the output torsional compliance [%]")
    ax.set_xlim(0.0, max(float(shares.max()) * 1.2, 1.0))
    rig = format_quantity(Nmm_per_rad_to_Nm_per_arcmin(chain.rigidity), "N*m/arcmin")
    ax.set_title(f"tangent rigidity at rated torque {rig}", fontsize=9)
    left = ", ".join(chain.left_out) if chain.left_out else "none"
    return Figure(
        "Compliance breakdown",
        "Share of each element of the stiffness chain in the output torsional compliance at "
        "rated torque (its share of the strain energy of a torque increment; the shares sum to "
        f"1). Left out (rigid, not described by the case): {left}.",
        fig,
    )


def _compensation(comp) -> Figure:
    fig, axes = new_figure(1, 3, figsize=(9.0, 3.2))
    labels = ["before", "after"]
    pts = [comp.before, comp.after]
    axes[0].bar(labels, [rad_to_arcsec(p.total_te_peak_to_peak) for p in pts], color=PALETTE[:2])
    axes[0].set_ylabel("total TE p-p [arcsec]")
    axes[1].bar(labels, [rad_to_arcmin(p.mean_lag) for p in pts], color=PALETTE[:2])
    axes[1].set_ylabel("mean loaded lag [arcmin]")
    axes[2].bar(labels, [p.peak_pin_load for p in pts], color=PALETTE[:2])
    axes[2].set_ylabel("peak pin load [N]")
    return Figure(
        "Compensation before/after",
        "Total TE, loaded output lag and peak pin load before and after the design change "
        f"found by the model (objective {comp.objective}).",
        fig,
    )


def figures(result) -> list[Figure]:
    """All figures of an ``rv_reducer`` study result."""
    out: list[Figure] = []
    if "load_sharing" in result:
        a = result["load_sharing"]
        ls, ls0 = a.data["load"], a.data.get("load_without_errors")
        figs = [_pin_map(ls, "Pin-load map")]
        if ls0 is not None:
            figs.append(_pin_map(ls0, "Pin-load map without errors"))
        out += for_analysis("load_sharing", [*figs, _peak(ls, ls0)])
    if "transmission_error" in result:
        out += for_analysis("transmission_error", [_te(result["transmission_error"].data["te"])])
    if "catalogue" in result:
        cat = result["catalogue"].data["catalogue"]
        rated = Nm_to_Nmm(result["catalogue"]["rated_torque [N*m]"])
        figs = [_hysteresis(cat, rated)]
        chain = result["catalogue"].data.get("stiffness_chain")
        if chain is not None:
            figs.append(_compliance_shares(chain))
        out += for_analysis("catalogue", figs)
    if "compensation" in result:
        comp = result["compensation"].data["compensation"]
        out += for_analysis("compensation", [_compensation(comp)])
    out += cycloid_stage.stage_figures(result)  # its cycloid stage's analyses, where they ran
    out += rv_dynamics.figures(result)
    from gearte.plotting.yield_figures import yield_figures

    out += yield_figures(result)
    return out
