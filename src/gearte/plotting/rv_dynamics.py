"""Figures of the ``rv_dynamics`` study (paper 004 Figs 9–11 and a Campbell-style diagram).

matplotlib is imported lazily through :func:`gearte.plotting.new_figure`; nothing calls show().
"""

from __future__ import annotations

import numpy as np

from gearte.plotting import PALETTE, Figure, for_analysis, new_figure
from gearte.units import mm_to_um, rad_to_arcsec

__all__ = ["figures", "SELF_CONTAINED"]

#: Analyses whose figures read that analysis alone (:func:`gearte.plotting.self_contained`).
SELF_CONTAINED = frozenset({"contact", "dte", "modal", "speed_sweep", "batch"})


def _contact_figure(a) -> Figure:
    fig, (ax1, ax2) = new_figure(1, 2, figsize=(9.0, 3.6))
    v = a.values
    x = np.asarray(v["mesh_position [deg]"])
    ax1.plot(x, v["equivalent_pressure_angle [deg]"], color=PALETTE[0])
    ax1.set_xlabel("mesh position [deg of meshing phase]")
    ax1.set_ylabel("equivalent pressure angle β [deg]")
    ax2.plot(x, np.asarray(v["equivalent_mesh_stiffness [N/m]"]) / 1e9, color=PALETTE[1])
    ax2.set_xlabel("mesh position [deg of meshing phase]")
    ax2.set_ylabel("equivalent mesh stiffness k_cr [GN/m]")
    for ax in (ax1, ax2):
        ax.grid(alpha=0.3)
    return Figure(
        "Equivalent pressure angle and mesh stiffness over one mesh period",
        f"Paper 004 Fig 9 at {v['torque_per_disc [N·m]']:g} N·m per disc: mean β = "
        f"{v['equivalent_pressure_angle_mean [deg]']:.2f}°, mean k_cr = "
        f"{v['equivalent_mesh_stiffness_mean [N/m]']:.3g} N/m.",
        fig,
    )


def _load_figure(a) -> Figure:
    sweep = a.values["load_sweep"]
    t = [r["torque_per_disc [N·m]"] for r in sweep]
    fig, (ax1, ax2) = new_figure(1, 2, figsize=(9.0, 3.4))
    ax1.plot(t, [r["equivalent_pressure_angle_mean [deg]"] for r in sweep], "o-", color=PALETTE[0])
    ax1.set_xlabel("torque per disc [N·m]")
    ax1.set_ylabel("mean β [deg]")
    ax2.plot(
        t,
        [r["equivalent_mesh_stiffness_mean [N/m]"] / 1e9 for r in sweep],
        "o-",
        color=PALETTE[1],
    )
    ax2.set_xlabel("torque per disc [N·m]")
    ax2.set_ylabel("mean k_cr [GN/m]")
    for ax in (ax1, ax2):
        ax.grid(alpha=0.3)
    return Figure(
        "Equivalent pressure angle and mesh stiffness against load",
        "Means over one mesh period; the Hertz contact stiffens with load and, with a "
        "modification, more pins come into contact.",
        fig,
    )


def _dte_figures(a) -> list[Figure]:
    r = a.data["dte"]
    out = []
    fig, ax = new_figure(figsize=(8.0, 3.4))
    if r.covers_span:
        ax.plot(r.t, r.dte, lw=0.7, color=PALETTE[0])
    else:  # the trace is the last window: draw the full-rate envelope of the whole span
        for k in (0, 1):
            ax.plot(r.envelope_t, r.envelope[:, k], lw=0.7, color=PALETTE[0])
        ax.fill_between(r.envelope_t, r.envelope[:, 0], r.envelope[:, 1], color=PALETTE[0], lw=0)
    ax.set_xlabel("time [s]")
    ax.set_ylabel("DTE − mean [arcsec]")
    ax.grid(alpha=0.3)
    out.append(
        Figure(
            "Dynamic transmission error",
            f"θ_o − θ_s/i after settling, static wind-up {r.dte_mean:.2f}″ removed; peak-to-peak "
            f"{r.peak_to_peak:.3g}″ (paper 004 Fig 11: 0.78″ without, 17.25″ with errors)"
            + (
                "."
                if r.covers_span
                else f"; min/max of every step in each of {r.envelope.shape[0]} time buckets."
            ),
            fig,
        )
    )
    freq, spec, peaks = a.data["freq"], a.data["spec"], a.data["peaks"]
    fig, ax = new_figure(figsize=(8.0, 3.6))
    ax.semilogy(freq[1:], np.maximum(spec[1:], 1e-6), lw=0.8, color=PALETTE[0])
    # label the largest peaks; neighbours in frequency get staggered heights so labels don't overlap
    for k, pk in enumerate(sorted(peaks[:8], key=lambda p: p["frequency [Hz]"])):
        f, amp = pk["frequency [Hz]"], pk["amplitude [arcsec]"]
        ax.annotate(
            f"{pk['source']}\n{f:.1f} Hz",
            (f, amp),
            xytext=(6, 8 + 24 * (k % 3)),
            textcoords="offset points",
            fontsize=7,
            color=PALETTE[1],
            # a straight leader from the peak to the label's lower left corner (relpos), not
            # from its centre clipped to its box nor shrunk (each a Bézier split: ~40 ms here)
            arrowprops={
                "arrowstyle": "-",
                "color": PALETTE[1],
                "lw": 0.5,
                "relpos": (0.0, 0.0),
                "patchA": None,
                "shrinkA": 0.0,
                "shrinkB": 0.0,
            },
        )
        ax.plot([f], [amp], "o", ms=3, color=PALETTE[1])
    ax.set_xlim(0, max(2.5 * max(a.data["sources"]["cycloid mesh"], 1.0), 10.0))
    ax.set_xlabel("frequency [Hz]")
    ax.set_ylabel("amplitude [arcsec] (log)")
    ax.set_ylim(max(1e-6, 1e-4 * spec[1:].max()), 30 * spec[1:].max())
    ax.grid(alpha=0.3)
    out.append(
        Figure(
            "DTE spectrum with labelled sources",
            "Peaks labelled by their physical source: rotations (crank relative to the carrier, "
            "input, output), involute and cycloid mesh frequencies and their sidebands.",
            fig,
        )
    )
    names = r.state_names
    bodies = []
    for n in names:
        b = n.split(".")[0]
        if b not in bodies:
            bodies.append(b)
    # a fixed grid of like panels: constrained layout measured 2 x n panels for most of its time
    fig, axes = new_figure(
        2, len(bodies), figsize=(3.0 * len(bodies), 5.6), margins_in=(0.95, 0.5, 0.35, 0.1)
    )
    axes = np.atleast_2d(axes)
    for c, b in enumerate(bodies):
        ix, iy = names.index(f"{b}.x"), names.index(f"{b}.y")
        it, iw = names.index(f"{b}.theta"), names.index(f"{b}.omega")
        s = r.states
        axes[0, c].plot(mm_to_um(s[:, ix]), mm_to_um(s[:, iy]), lw=0.5, color=PALETTE[0])
        axes[0, c].set_title(b, fontsize=9)
        axes[0, c].set_xlabel("x [µm]")
        axes[0, c].set_ylabel("y [µm]")
        th = s[:, it] - s[:, it].mean()
        axes[1, c].plot(rad_to_arcsec(th), s[:, iw], lw=0.5, color=PALETTE[2])
        axes[1, c].set_xlabel("θ − mean [arcsec]")
        axes[1, c].set_ylabel("dθ/dt [rad/s]")
    out.append(
        Figure(
            "Trajectories and phase portraits",
            "Top: centre trajectories (vibration about the nominal motion); bottom: torsional "
            "phase portraits (paper 004 Fig 10)"
            + (
                "."
                if r.states_cover_span
                else f", over the last {r.states_span:.3g} s recorded (record_points)."
            ),
            fig,
        )
    )
    return out


def _campbell_figure(a) -> Figure:
    fig, ax = new_figure(figsize=(7.0, 4.2))
    speeds = a.data["speeds_rpm"]
    freqs = np.asarray(a.values["natural_frequencies [Hz]"])
    fmax = 0.0
    for k, (name, line) in enumerate(a.data["mesh_lines"].items()):
        line = np.asarray(line)
        ax.plot(speeds, line, color=PALETTE[(k + 1) % len(PALETTE)], label=name)
        if "mesh" in name:
            ax.plot(speeds, 2 * line, ls="--", color=PALETTE[(k + 1) % len(PALETTE)], lw=0.8)
        fmax = max(fmax, 2 * line.max())
    for f in freqs[freqs <= 1.1 * fmax]:
        ax.axhline(f, color="0.6", lw=0.6)
    op = a.data.get("operating_rpm")
    if op is not None:
        ax.axvline(op, color="k", ls=":", lw=1.0, label="operating speed")
    ax.set_xlabel("input speed [rpm]")
    ax.set_ylabel("frequency [Hz]")
    ax.set_ylim(0, 1.1 * fmax)
    ax.legend(fontsize=8)
    ax.grid(alpha=0.2)
    return Figure(
        "Natural frequencies against excitation frequencies (Campbell diagram)",
        "Grey: natural frequencies at mean mesh stiffness; solid: mesh and rotation frequencies, "
        "dashed: second mesh harmonics. A crossing near the operating speed is a resonance.",
        fig,
    )


def _sweep_figure(a) -> Figure:
    fig, ax = new_figure(figsize=(7.0, 3.6))
    v = a.values
    ax.plot(v["input_speed [rpm]"], v["dte_peak_to_peak [arcsec]"], "o-", color=PALETTE[0])
    for c in a.data["crossings"]:
        col = PALETTE[1] if "cycloid" in c["source"] else PALETTE[2]
        ax.axvline(c["input_speed [rpm]"], color=col, ls=":", lw=0.9)
    ax.set_xlabel("input speed [rpm]")
    ax.set_ylabel("DTE peak-to-peak [arcsec]")
    ax.grid(alpha=0.3)
    return Figure(
        "DTE peak-to-peak against input speed",
        "Dotted: speeds where the cycloid (orange) or involute (green) mesh frequency equals one "
        "of the lowest natural frequencies.",
        fig,
    )


def _batch_figure(a) -> Figure:
    fig, ax = new_figure(figsize=(6.0, 3.4))
    rows = a.data["rows"]
    from gearte.plotting.display import distribution

    drawn = distribution(ax, rows[:, 0], color=PALETTE[0])
    ax.set_xlabel("DTE peak-to-peak [arcsec]")
    ax.set_ylabel("realisations" if drawn == "histogram" else "")
    return Figure(
        "DTE peak-to-peak over random error realisations",
        f"{rows.shape[0]} realisations, mean {rows[:, 0].mean():.3g}″.",
        fig,
    )


def figures(result) -> list[Figure]:
    """All figures of an ``rv_dynamics`` result."""
    out: list[Figure] = []
    if "contact" in result:
        out += for_analysis("contact", [_contact_figure(result["contact"])])
        if result["contact"].values.get("load_sweep"):
            out += for_analysis("contact", [_load_figure(result["contact"])])
    if "dte" in result:
        out += for_analysis("dte", _dte_figures(result["dte"]))
    if "modal" in result:
        out += for_analysis("modal", [_campbell_figure(result["modal"])])
    if "speed_sweep" in result:
        out += for_analysis("speed_sweep", [_sweep_figure(result["speed_sweep"])])
    if "batch" in result:
        out += for_analysis("batch", [_batch_figure(result["batch"])])
    return out
