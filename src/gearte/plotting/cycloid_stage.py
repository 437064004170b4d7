"""Figures of the ``cycloid_stage`` study (matplotlib imported lazily, no pyplot)."""

from __future__ import annotations

from typing import Any

import numpy as np

from gearte.plotting import PALETTE, Figure, for_analysis, new_figure
from gearte.plotting.yield_figures import SELF_CONTAINED as _YIELD
from gearte.units import Nmm_to_Nm, rad_to_deg

__all__ = [
    "figures",
    "stage_figures",
    "profile_figure",
    "contact_figures",
    "sensitivity_figure",
    "pareto_figure",
    "SELF_CONTAINED",
    "NUMBA_FREE_RESULTS",
]

#: Analyses whose figures read that analysis alone (:func:`gearte.plotting.self_contained`).
SELF_CONTAINED = frozenset({"geometry", "geometric_te", "tooth_contact"}) | _YIELD

#: A result of this kind unpickles and its figures draw without numba (the tooth contact's record
#: lives in :mod:`gearte.models.cycloid_contact_record`, apart from its kernels): the report
#: process is forked before the parent imports numba and imports none of the parent's kernel
#: modules (tests/test_report_background.py checks it).
NUMBA_FREE_RESULTS = True


def _exaggeration(max_dev_mm: float, tooth_height_mm: float) -> float:
    """A round factor that makes the modification about a quarter of the tooth height."""
    if max_dev_mm <= 0:
        return 1.0
    raw = 0.25 * tooth_height_mm / max_dev_mm
    mag = 10 ** np.floor(np.log10(raw))
    return float(max(1.0, np.floor(raw / mag) * mag))


def profile_figure(stage: Any) -> Figure:
    """Modified against unmodified profile of ``stage`` over three teeth (polar, unwrapped),
    exaggerated."""
    phi = np.linspace(-3.0 * np.pi, 3.0 * np.pi, 4001)

    def polar(modified: bool, flank: int = 0) -> tuple[np.ndarray, np.ndarray]:
        x, y = stage.profile_xy(phi, modified=modified, flank=flank)
        ang = np.unwrap(np.arctan2(y, x))
        order = np.argsort(ang)
        return ang[order], np.hypot(x, y)[order]

    a0, r0 = polar(False)
    a1, r1 = polar(True, flank=2)
    dr = np.interp(a0, a1, r1) - r0
    k = _exaggeration(float(np.max(np.abs(dr))), stage.tip_radius - stage.root_radius)
    deg = rad_to_deg(a0)
    fig, ax = new_figure(figsize=(7.0, 4.0))
    ax.plot(deg, r0, color=PALETTE[7], lw=1.0, label="unmodified profile")
    ax.plot(
        deg, r0 + k * dr, color=PALETTE[1], lw=1.4, label=f"modified profile (difference × {k:g})"
    )
    ax.set_xlabel("polar angle on the disc [deg]")
    ax.set_ylabel("profile radius [mm]")
    ax.legend(loc="lower right", fontsize=8)
    ax.set_title(f"Cycloid profile over three teeth — modification exaggerated × {k:g}")
    cap = (
        f"Profile radius against polar angle for the unmodified disc (Δr_rp = Δr_p = 0) and the "
        f"modified one (Δr_rp = {stage.dr_rp:g} mm, Δr_p = {stage.dr_p:g} mm, δ_rot = "
        f"{stage.rotation:g} rad). The radial difference is drawn {k:g} times larger than it is "
        f"(largest {1e3 * np.max(np.abs(dr)):.1f} µm; at the root and tip it is Δr_p − Δr_rp = "
        f"{1e3 * (stage.dr_p - stage.dr_rp):.1f} µm)."
    )
    return Figure("Modified vs unmodified profile", cap, fig)


def contact_figures(result: Any) -> list[Figure]:
    """Clearance & deformation per pin (paper Fig 7/10), force per pin, sweep over a pitch, from
    the ``result`` of a cycloid_stage study."""
    tc = result["tooth_contact"]
    v = tc.values
    idx = np.asarray(v["pin_index"])
    phase = np.asarray(v["meshing_phase [deg]"])
    loaded = (phase > 0) & (phase < 180)
    clr = np.asarray(v["initial_clearance [mm]"], dtype=float)
    dfm = np.asarray(v["normal_deformation [mm]"], dtype=float)
    force = np.asarray(v["contact_force [N]"], dtype=float)
    inm = np.isin(idx, v["pins_in_mesh_index"])
    out = []

    fig, ax = new_figure()
    ax.plot(idx[loaded], 1e3 * clr[loaded], "o-", color=PALETTE[0], label="initial clearance Δ_i")
    ax.plot(idx[loaded], 1e3 * dfm[loaded], "s-", color=PALETTE[1], label="normal deformation δ_i")
    sel = loaded & inm
    ax.vlines(
        idx[sel],
        1e3 * clr[sel],
        1e3 * dfm[sel],
        color=PALETTE[2],
        lw=3,
        alpha=0.6,
        label="in mesh: compression δ_i − Δ_i",
    )
    ax.set_xlabel("pin i")
    ax.set_ylabel("[µm]")
    ax.legend(fontsize=8)
    ax.set_title("Initial clearance and normal deformation per pin (cf. paper Fig. 7/10)")
    out.append(
        Figure(
            "Clearance and deformation per pin",
            f"Loaded-flank pins at mesh position 0. {v['pins_in_mesh']} pins are in mesh "
            f"(δ_i > Δ_i); δ_max = {1e3 * v['max_normal_deformation [mm]']:.2f} µm.",
            fig,
        )
    )

    fig, ax = new_figure()
    ax.bar(idx[loaded], force[loaded], color=PALETTE[2])
    ax.axhline(
        v["max_contact_force [N]"],
        color=PALETTE[7],
        ls="--",
        lw=1,
        label=f"F_max = {v['max_contact_force [N]']:.1f} N",
    )
    ax.set_xlabel("pin i")
    ax.set_ylabel("contact force F_i [N]")
    ax.legend(fontsize=8)
    ax.set_title("Contact force per pin")
    out.append(
        Figure(
            "Contact force per pin",
            f"F_i = (δ_i − Δ_i)/δ_max · F_max (eq 41); torque on the disc "
            f"{Nmm_to_Nm(v['torque_on_disc [N·mm]']):.1f} N·m.",
            fig,
        )
    )

    if "mesh_angle [deg]" in v:
        fig, ax = new_figure()
        ang = np.asarray(v["mesh_angle [deg]"])
        ax.plot(ang, v["max_contact_force_over_pitch [N]"], color=PALETTE[0], label="F_max")
        ax.plot(ang, v["max_pin_force_over_pitch [N]"], color=PALETTE[2], label="largest F_i")
        ax.set_xlabel("mesh position [deg]")
        ax.set_ylabel("force [N]")
        ax2 = ax.twinx()
        ax2.step(ang, v["pins_in_mesh_over_pitch"], where="post", color=PALETTE[1], lw=1)
        ax2.set_ylabel("pins in mesh", color=PALETTE[1])
        ax.legend(fontsize=8, loc="lower left")
        ax.set_title("Load sharing over one tooth pitch")
        out.append(
            Figure(
                "Load sharing over one tooth pitch",
                f"{len(ang)} mesh positions over 360°/z_p; pins in mesh between "
                f"{v['pins_in_mesh_min']} and {v['pins_in_mesh_max']}.",
                fig,
            )
        )
    return out


def sensitivity_figure(result: Any) -> Figure:
    """Bar chart of the sensitivity indices (Table 2) of a cycloid_stage ``result``."""
    v = result["geometric_te"].values
    names = list(v["sensitivity_index"])
    vals = np.array([v["sensitivity_index"][k] for k in names])
    fig, ax = new_figure(figsize=(7.0, 4.2))
    colors = [PALETTE[1] if x < 0 else PALETTE[0] for x in vals]
    ax.barh(range(len(names)), vals, color=colors)
    ax.set_yticks(range(len(names)), [n.replace("_", " ") for n in names], fontsize=8)
    ax.invert_yaxis()
    ax.axvline(0, color="k", lw=0.8)
    ax.set_xlabel("sensitivity index S_j = g_j / g_0")
    ax.set_title("Error sensitivity indices (cf. paper Table 2)")
    return Figure(
        "Sensitivity indices",
        "Negative indices (orange) reduce the TE when the error grows: the factors the paper "
        "uses for compensation. The eccentricity's linear index is 0 (derived; see notes).",
        fig,
    )


def pareto_figure(result: Any) -> Figure:
    """Pareto of the factors' TE contributions (mean) and tolerance shares of a ``result``."""
    v = result["geometric_te"].values
    contrib = v["contribution [arcmin]"]
    tol = v["tolerance_contribution [arcmin]"]
    fig, (ax1, ax2) = new_figure(1, 2, figsize=(9.0, 4.2))
    items = sorted(contrib.items(), key=lambda kv: -abs(kv[1]))
    names = [k.replace("_", " ") for k, _ in items]
    vals = np.array([x for _, x in items])
    ax1.barh(range(len(vals)), vals, color=[PALETTE[1] if x < 0 else PALETTE[0] for x in vals])
    ax1.set_yticks(range(len(vals)), names, fontsize=7)
    ax1.invert_yaxis()
    ax1.axvline(0, color="k", lw=0.8)
    ax1.set_xlabel("contribution to mean TE [arcmin]")
    ax1.set_title(f"mean {v['geometric_te_mean [arcmin]']:.3f}′", fontsize=9)
    titems = sorted(tol.items(), key=lambda kv: -kv[1])
    tv = np.array([x for _, x in titems])
    share = tv**2 / max(float(np.sum(tv**2)), 1e-300)
    ax2.bar(range(len(tv)), 100 * share, color=PALETTE[2])
    ax2.plot(range(len(tv)), 100 * np.cumsum(share), "o-", color=PALETTE[7], ms=3)
    ax2.set_xticks(
        range(len(tv)),
        [k.replace("_", " ") for k, _ in titems],
        rotation=60,
        ha="right",
        fontsize=7,
    )
    ax2.set_ylabel("share of RSS tolerance² [%]")
    ax2.set_title(f"tolerance {v['geometric_te_tolerance [arcmin]']:.3f}′", fontsize=9)
    return Figure(
        "TE contribution Pareto",
        "Left: each factor's contribution to the mean geometric TE (modifications and mean "
        "errors). Right: each error's share of the squared RSS tolerance, with the cumulative "
        "share.",
        fig,
    )


def figures(result: Any) -> list[Figure]:
    """All figures of a ``cycloid_stage`` result."""
    from gearte.plotting.yield_figures import yield_figures

    return stage_figures(result) + yield_figures(result)


def stage_figures(result: Any) -> list[Figure]:
    """The figures of the cycloid stage's analyses (geometry, geometric TE, tooth contact) of a
    ``cycloid_stage`` or ``rv_reducer`` result, each where its analysis ran."""
    out: list[Figure] = []
    if "geometry" in result:
        out += for_analysis("geometry", [profile_figure(result["geometry"].data["stage"])])
    if "geometric_te" in result:
        out += for_analysis("geometric_te", [sensitivity_figure(result), pareto_figure(result)])
    if "tooth_contact" in result:
        out += for_analysis("tooth_contact", contact_figures(result))
    return out
