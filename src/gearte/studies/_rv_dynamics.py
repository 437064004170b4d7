"""The dynamic analyses of the ``rv_reducer`` kind (Li et al. 2023, paper 004).

Not a kind of its own: :mod:`gearte.studies.rv_reducer` validates the case and calls
:func:`run_dynamics`, which builds the lumped dynamic model from the same
:class:`~gearte.geometry.rv.RVReducer` (geometry, stiffnesses, clearances, errors) every other
RV analysis reads, plus what only the dynamics needs (``[reducer.dynamics]``: masses and inertias
— derived from geometry and density when left out —, torsional and bending stiffnesses, damping;
``[operation]``: speed and torque).

Analyses:
* ``contact``   loaded contact of the cycloid–pin pair over one mesh period (and vs load):
  equivalent pressure angle and mesh stiffness (paper Fig 9).
* ``modal``     natural frequencies, rigid-mode check, mesh frequencies over a speed range.
* ``dte``       dynamic transmission error from static equilibrium: peak-to-peak, spectrum with
  labelled peaks, trajectories and phase portraits (paper Figs 10–11).
* ``speed_sweep`` DTE peak-to-peak over a range of input speeds, with the mesh/mode crossings.
* ``batch``     DTE statistics over random error realisations drawn from tolerances (parallel).
"""

from __future__ import annotations

import contextlib
from collections.abc import Iterator
from typing import Any, Literal

import numpy as np
from pydantic import Field, model_validator

from gearte.geometry.rv import RVReducer, mass_properties
from gearte.io.schema import StrictModel
from gearte.results import AnalysisResult
from gearte.units import N_per_mm_to_N_per_m, Nm_to_Nmm, rad_to_deg

__all__ = [
    "ANALYSES",
    "ContactOptions",
    "ModalOptions",
    "DTEOptions",
    "SpeedSweepOptions",
    "BatchOptions",
    "build_dynamic_model",
    "batch_tolerances",
    "run_dynamics",
]

#: The analyses of this module, in the order they run.
ANALYSES = ("contact", "modal", "dte", "speed_sweep", "batch")


class ContactOptions(StrictModel):
    positions: int = Field(48, ge=8, le=720, description="mesh positions over one mesh period")
    load_sweep_Nm: list[float] = Field(  # noqa: N815
        default_factory=lambda: [25.0, 75.0, 150.0, 225.0, 300.0],
        description="torques per disc [N·m] for the load sweep",
    )

    @model_validator(mode="after")
    def _positive(self):
        if any(not t > 0 for t in self.load_sweep_Nm):
            raise ValueError(f"load_sweep_Nm must all be > 0 (got {self.load_sweep_Nm})")
        return self


class ModalOptions(StrictModel):
    speed_min_rpm: float = Field(
        100.0, gt=0, le=2e4, description="Lowest input speed of the Campbell diagram [rpm]."
    )
    speed_max_rpm: float = Field(
        3000.0, gt=0, le=2e4, description="Highest input speed of the Campbell diagram [rpm]."
    )
    resonance_margin: float = Field(0.1, gt=0, lt=1, description="relative band around a mode")

    @model_validator(mode="after")
    def _order(self):
        if not self.speed_max_rpm > self.speed_min_rpm:
            raise ValueError("speed_max_rpm must be > speed_min_rpm")
        return self


class DTEOptions(StrictModel):
    duration_s: float = Field(
        0.5,
        gt=0,
        le=600,
        description="simulated time after settling [s] (memory does not grow with it: the "
        "recorded trace keeps its last record_points rows)",
    )
    settle_s: float = Field(0.1, ge=0, le=10, description="settling time from static equilibrium")
    method: Literal["rk4", "dopri5", "scipy"] = Field(
        "rk4", description="Integrator: fixed-step RK4, adaptive DOPRI5, or scipy's solve_ivp."
    )
    step_fraction: float = Field(0.85, gt=0, le=1, description="RK4 step / stability limit")
    record_dt_s: float = Field(
        1e-4,
        gt=0,
        le=0.1,
        description="recording interval [s] of the trace, the trajectories and the spectrum "
        "(rounded to a multiple of the RK4 step; below the step: every step); the spectrum "
        "reaches 1/(2 record_dt_s)",
    )
    record_points: int = Field(
        65536,  # gearte.runners.rv_dynamics_sim.RECORD_POINTS (not imported: numba at load)
        ge=0,
        le=2_000_000,
        description="most rows of recorded states kept, the last ones: trajectories and phase "
        "portraits cover the last record_points x record_dt_s seconds; peak-to-peak, RMS and "
        "the DTE envelope always cover the whole span at every step. 0 keeps every row (memory "
        "grows with duration_s)",
    )
    trace_points: int = Field(
        262144,  # gearte.runners.rv_dynamics_sim.TRACE_POINTS
        ge=0,
        le=20_000_000,
        description="most samples of the recorded DTE trace kept, the last ones: the spectrum "
        "covers the last trace_points x record_dt_s seconds (resolution 1/that). 0 keeps every "
        "sample (memory grows with duration_s)",
    )


class SpeedSweepOptions(StrictModel):
    """DTE peak-to-peak over a range of input speeds (resonances of the mesh excitation)."""

    speed_min_rpm: float = Field(
        300.0, gt=0, le=2e4, description="Lowest input speed of the sweep [rpm]."
    )
    speed_max_rpm: float = Field(
        3000.0, gt=0, le=2e4, description="Highest input speed of the sweep [rpm]."
    )
    count: int = Field(19, ge=2, le=500, description="Input speeds in the sweep [-].")
    duration_s: float = Field(0.1, gt=0, le=10, description="simulated time per speed [s]")
    settle_s: float = Field(0.1, ge=0, le=10, description="Settling time at each speed [s].")

    @model_validator(mode="after")
    def _order(self):
        if not self.speed_max_rpm > self.speed_min_rpm:
            raise ValueError("speed_max_rpm must be > speed_min_rpm")
        return self


class BatchOptions(StrictModel):
    samples: int = Field(
        16, ge=1, le=100000, description="Random error realisations simulated [-]."
    )
    duration_s: float = Field(
        0.5, gt=0, le=60, description="Simulated time per realisation after settling [s]."
    )
    settle_s: float = Field(0.1, ge=0, le=10, description="Settling time before recording [s].")
    seed: int = Field(0, ge=0, description="Seed of the random realisations.")
    chunk_size: int = Field(
        1,
        ge=1,
        le=10000,
        description="Realisations per chunk of the execution layer (1: any batch of >= 2 "
        "realisations uses every worker).",
    )
    tolerance_scale: float = Field(1.0, gt=0, le=10, description="× Table 3 amplitudes")


# --- building the dynamic model from the one description -------------------------------------
def build_dynamic_model(case, red: RVReducer):
    """The :class:`~gearte.models.rv_dynamics.RVDynamicModel` of an ``rv_reducer`` case.

    Geometry, stiffnesses, clearances and errors come from ``red`` (the description every RV
    analysis reads); masses and inertias from ``[reducer.dynamics]`` or, when left out, from
    geometry and density (:func:`gearte.geometry.rv.mass_properties`).

    Returns
    -------
    (RVDynamicModel, MassProperties)
    """
    from gearte.models.rv_dynamics import (
        RVDynamicModel,
        errors_from_reducer,
        parameters_from_reducer,
    )

    d, op = case.reducer.dynamics, case.operation
    mp = mass_properties(red, case.reducer.density, d.given("mass"), d.given("inertia"))
    kw: dict[str, Any] = {f"{b}_mass_kg": v for b, v in mp.mass_kg.items()}
    kw.update({f"{b}_inertia_kgm2": v for b, v in mp.inertia_kgm2.items()})
    kw.update(
        input_torsional_stiffness_Nm_per_rad=d.input_torsional_stiffness_Nm_per_rad,
        crank_torsional_stiffness_Nm_per_rad=d.crank_torsional_stiffness_Nm_per_rad,
        crank_bending_stiffness_N_per_m=N_per_mm_to_N_per_m(d.crank_bending_stiffness_N_per_mm),
        damping_ratio=d.damping_ratio,
        cycloid_stiffness=d.cycloid_stiffness,
        cycloid_mesh_stiffness_N_per_m=None
        if d.cycloid_mesh_stiffness_N_per_mm is None
        else N_per_mm_to_N_per_m(d.cycloid_mesh_stiffness_N_per_mm),
        cycloid_pressure_angle_deg=d.cycloid_pressure_angle_deg,
        involute_harmonics=d.involute_harmonics,
        cycloid_harmonics=d.cycloid_harmonics,
        input_speed_rpm=op.input_speed_rpm,
        output_torque_Nm=op.output_torque_Nm,
    )
    if case.analyses.contact is not None:
        kw["contact_positions"] = case.analyses.contact.positions
    params = parameters_from_reducer(red, **kw)
    e = red.error_set

    def polar(v):
        return (float(np.hypot(v[0], v[1])), float(np.arctan2(v[1], v[0])))

    errors = errors_from_reducer(
        red,
        sun_eccentricity=(e.first_stage.sun.amplitude, e.first_stage.sun.phase),
        sun_assembly=(e.first_stage.sun_assembly.amplitude, e.first_stage.sun_assembly.phase),
        output_assembly=polar(e.output_seat),
        output_bearing_clearance_mm=red.supports.main_bearing_clearance,
        output_torque_Nm=op.output_torque_Nm,
    )
    try:
        with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
            model = RVDynamicModel(params, errors)
    except (IndexError, FloatingPointError, OverflowError, np.linalg.LinAlgError) as exc:
        # found by fuzzing: a mass, inertia or length such as 1e-300 passes its schema bound
        # (> 0) and leaves no finite elastic mode (the damping's ω1 does not exist)
        from gearte.errors import ParameterError

        raise ParameterError(
            "reducer.dynamics",
            type(exc).__name__,
            "the 30-DOF model has no finite elastic mode: a mass, inertia, stiffness or length "
            "of the reducer is out of physical proportion (e.g. 1e-300)",
        ) from None
    return model, mp


def batch_tolerances(red: RVReducer, scale: float = 1.0):
    """Error tolerances of a random batch: ``scale`` × the largest of the reducer's errors of each
    part (:class:`gearte.runners.rv_dynamics_sim.ErrorTolerances`, [mm]).

    Parameters
    ----------
    red : RVReducer
        The reducer whose ``[[reducer.errors]]`` give the amplitudes.
    scale : float
        Factor on every amplitude [-].
    """
    from gearte.runners.rv_dynamics_sim import ErrorTolerances

    amp = red.error_set.amplitudes()
    return ErrorTolerances(
        sun_eccentricity=scale * amp["sun_eccentricity"],
        planet_eccentricity=scale * amp["planet_eccentricity"],
        sun_assembly=scale * amp["sun_assembly"],
        disc_hole=scale * amp["disc_crank_bore"],
        cam=scale * amp["cam"],
        carrier_hole=scale * amp["carrier_crank_bore"],
        output_assembly=scale * amp["output_assembly"],
    )


def _has_errors(red: RVReducer) -> bool:
    from gearte.models.rv_dynamics.excitation import has_pin_errors

    return any(v > 0 for v in red.error_set.amplitudes().values()) or has_pin_errors(red)


# --- analyses --------------------------------------------------------------------------------
def _contact(case, model) -> AnalysisResult:
    from gearte.models.cycloid_loaded_contact import mesh_period_contact

    c = model.contact
    pair = model.params.pair
    opts = case.analyses.contact
    t_disc = case.operation.output_torque_Nm / case.reducer.discs.count
    sweep = []
    for tq in opts.load_sweep_Nm:
        mp = mesh_period_contact(pair, Nm_to_Nmm(tq), min(opts.positions, 24))
        sweep.append(
            {
                "torque_per_disc [N·m]": tq,
                "equivalent_pressure_angle_mean [deg]": float(rad_to_deg(mp.pressure_angle_mean)),
                "equivalent_mesh_stiffness_mean [N/m]": N_per_mm_to_N_per_m(mp.mesh_stiffness_mean),
                "pins_in_contact_mean": float(np.mean(mp.pins_in_contact)),
            }
        )
    mean_k, a_k, b_k = model.cycloid_fourier
    beta = rad_to_deg(c.pressure_angle)
    values = {
        "equivalent_pressure_angle_mean [deg]": float(rad_to_deg(c.pressure_angle_mean)),
        "equivalent_pressure_angle_min [deg]": float(beta.min()),
        "equivalent_pressure_angle_max [deg]": float(beta.max()),
        "equivalent_mesh_stiffness_mean [N/m]": N_per_mm_to_N_per_m(c.mesh_stiffness_mean),
        "equivalent_mesh_stiffness_min [N/m]": float(N_per_mm_to_N_per_m(c.mesh_stiffness.min())),
        "equivalent_mesh_stiffness_max [N/m]": float(N_per_mm_to_N_per_m(c.mesh_stiffness.max())),
        "pins_in_contact_min": int(c.pins_in_contact.min()),
        "pins_in_contact_max": int(c.pins_in_contact.max()),
        "max_pin_force [N]": float(c.max_force.max()),
        "max_contact_pressure [MPa]": c.max_contact_pressure,
        "contact_law": pair.contact_law,
        "torque_per_disc [N·m]": t_disc,
        "mesh_position [deg]": rad_to_deg(c.mesh_position),
        "equivalent_pressure_angle [deg]": beta,
        "equivalent_mesh_stiffness [N/m]": N_per_mm_to_N_per_m(c.mesh_stiffness),
        "signed_resultant_pressure_angle_mean [deg]": float(
            rad_to_deg(
                np.mean(np.arctan2(c.contact.radial_force_signed, c.contact.tangential_force))
            )
        ),
        "stiffness_fourier_a [N/m]": N_per_mm_to_N_per_m(a_k),
        "stiffness_fourier_b [N/m]": N_per_mm_to_N_per_m(b_k),
        "load_sweep": sweep,
    }
    notes = [
        "Paper 004 Fig 9 (225 N·m per disc): unmodified β = 31.9°, k = 1.24e9 N/m; modified "
        "β = 3.8°, k = 2.62e8 N/m. β uses the paper's unsigned radial sum (eq 5); the signed "
        "resultant's angle is given beside it.",
        "k_cr = F_cr / (r_c Δφ_c cos β) (eq 7 read so the single spring reproduces T/Δφ_c).",
        f"|ρ_c| capped at {pair.rho_cap_mm:.2f} mm in the Hertz logarithm (profile inflection).",
    ]
    return AnalysisResult(
        name="contact",
        title="Loaded contact of the cycloid–pin pair over one mesh period",
        values=values,
        references=["li2023"],
        notes=notes,
        data={"contact": c},
    )


def _modal(case, model, mp, warnings: list[str]) -> AnalysisResult:
    opts = case.analyses.modal
    modal = model.modal()
    free = model.modal(input_shaft=False)
    v = free.shapes[:, 0]
    v = v / v[-1]
    i_s, i_c = 2, model.body("disc1") + 2
    rigid_ratio = float(v[i_s])
    speeds = np.linspace(opts.speed_min_rpm, opts.speed_max_rpm, 60)
    per_rpm = {k: f / model.params.input_speed_rpm for k, f in model.params.frequencies().items()}
    meshes = {
        name: per_rpm[name] * speeds
        for name in ("involute mesh", "cycloid mesh", "crank rotation", "input rotation")
    }
    res_msgs = model.resonance_warnings(opts.resonance_margin)
    warnings.extend(res_msgs)
    freqs = modal.frequencies
    shapes = []
    sq = np.sqrt(model.mass)
    for k in range(min(12, freqs.size)):
        e = (modal.shapes[:, k] * sq) ** 2
        e = e / e.sum()
        top = np.argsort(e)[::-1][:3]
        shapes.append(
            {
                "frequency [Hz]": float(freqs[k]),
                "dominant_dofs": {model.dof_names[i]: round(float(e[i]), 3) for i in top},
            }
        )
    values = {
        "natural_frequencies [Hz]": freqs,
        "mode_shapes": shapes,
        "rigid_mode_ratio": rigid_ratio,
        "rigid_mode_disc_over_output": float(v[i_c]),
        "lowest_elastic_frequency_without_input_shaft [Hz]": float(free.frequencies[1]),
        "mesh_frequencies [Hz]": model.params.frequencies(),
        "damping_coefficient [s]": model.damping_coefficient,
        "resonance_warnings": res_msgs,
        "mass [kg]": mp.mass_kg,
        "inertia [kg*m^2]": mp.inertia_kgm2,
        "derived_mass_properties": list(mp.derived),
    }
    return AnalysisResult(
        name="modal",
        title="Natural frequencies, rigid mode and mesh frequencies",
        values=values,
        references=["li2023"],
        notes=[
            "Undamped modes at mean mesh stiffness, configuration at t = 0; mode_shapes lists "
            "each mode's three DOFs with the largest share of kinetic energy.",
            "Rigid mode computed with the input shaft spring removed: θ_s/θ_o must equal the "
            "ratio and the disc must rotate with the output.",
            f"Stiffness-proportional damping c = β_R k with β_R = 2ζ/ω_1, ζ = "
            f"{model.params.damping_ratio:g}.",
            "Masses and inertias of "
            + (", ".join(mp.derived) if mp.derived else "no body")
            + " derived from geometry and density (solid bodies of revolution, "
            "gearte.geometry.rv.mass_properties); the others as the case gives them.",
        ],
        data={
            "modal": modal,
            "speeds_rpm": speeds,
            "mesh_lines": meshes,
            "operating_rpm": model.params.input_speed_rpm,
        },
    )


def _dte(case, red, model, warnings: list[str]) -> AnalysisResult:
    from gearte.runners.rv_dynamics_sim import default_step, dte_spectrum, simulate_dte

    opts = case.analyses.dte
    dt = default_step(model, opts.step_fraction) if opts.method == "rk4" else None
    r = simulate_dte(
        model,
        opts.duration_s,
        settle_s=opts.settle_s,
        method=opts.method,
        dt=dt,
        record_dt=opts.record_dt_s,
        record_points=opts.record_points or None,
        trace_points=opts.trace_points or None,
    )
    sources = model.params.frequencies()
    freq, spec, peaks = dte_spectrum(r.t, r.dte, sources)
    dominant = peaks[0]["frequency [Hz]"] if peaks else float("nan")
    values = {
        "dte_peak_to_peak [arcsec]": r.peak_to_peak,
        "dte_rms [arcsec]": r.rms,
        "dte_static_windup [arcsec]": r.dte_mean,
        "dominant_dte_frequency [Hz]": dominant,
        "dominant_dte_source": peaks[0]["source"] if peaks else "",
        "paper_dte_peak_to_peak [arcsec]": {
            "Fig 11a, without errors": 0.78,
            "Fig 11b, with errors": 17.25,
            "Fig 12, bench forward/reverse": [22.56, 23.37],
        },
        "spectrum_peaks": peaks,
        "time_step [s]": r.dt,
        "simulated_time [s]": opts.duration_s + opts.settle_s,
        "rhs_evaluations": r.solver.n_rhs,
        "solver_wall_time [s]": r.solver.wall_time,
    }
    window = r.recorded_span
    resolution = 1.0 / window
    values["spectrum_window [s]"] = window
    values["spectrum_nyquist [Hz]"] = 0.5 / r.record_dt
    notes = [
        "DTE = θ_o − θ_s/i with absolute rotations, from static equilibrium; the mean (static "
        "wind-up under load) is removed before the peak-to-peak.",
        f"Spectrum resolution {resolution:.3g} Hz (Hann window); peaks labelled by the nearest "
        "harmonic of a rotation or mesh frequency, or a mesh ± rotation sideband.",
        f"Peak-to-peak and RMS from every step over the whole span (DOPRI5, scipy: every "
        f"recording instant); the spectrum from the DTE recorded every {r.record_dt:.3g} s "
        + (
            "over the whole span"
            if r.covers_span
            else f"over the last {window:.3g} s ({r.t.size} samples, trace_points; the DTE plot "
            "draws the full-rate envelope of the whole span)"
        )
        + "; the trajectories "
        + (
            "over the whole span."
            if r.states_cover_span
            else f"over the last {r.states_span:.3g} s ({r.states_t.size} rows, record_points)."
        ),
        "Paper 004 Fig 11: 0.78″ without errors, 17.25″ with errors (bench 22.56″/23.37″).",
    ]
    if _has_errors(red):
        notes.append(
            "Errors: the case's [[reducer.errors]] and per-pin errors, the same the "
            "quasi-static model reads; pin, disc run-out, cumulative pitch and per-disc "
            "modification errors act as each disc's loaded rotation shift computed from the "
            "same pin clearances (gearte.models.rv_dynamics.excitation)."
        )
    if opts.duration_s * sources["output rotation"] < 0.99 and _has_errors(red):
        warnings.append(
            "dte: the simulated span is shorter than one output revolution; errors that rotate "
            "with the output are not fully sampled by the peak-to-peak"
        )
    return AnalysisResult(
        name="dte",
        title="Dynamic transmission error",
        values=values,
        references=["li2023"],
        notes=notes,
        data={"dte": r, "freq": freq, "spec": spec, "peaks": peaks, "sources": sources},
    )


def _sweep_one(task) -> float:
    model, rpm, duration, settle = task
    from gearte.runners.rv_dynamics_sim import simulate_dte

    m = model.with_params(input_speed_rpm=float(rpm))
    return simulate_dte(m, duration, settle_s=settle, record_dt=None).peak_to_peak


def _speed_sweep(case, model, options) -> AnalysisResult:
    from gearte.execution import map_chunks
    from gearte.studies import sample_cap

    o = case.analyses.speed_sweep
    speeds = np.linspace(o.speed_min_rpm, o.speed_max_rpm, sample_cap(o, "count", options))
    p2p = np.array(
        map_chunks(
            _sweep_one,
            [(model, s, o.duration_s, o.settle_s) for s in speeds],
            workers=options.workers,
            scheduler=options.scheduler,
            progress=options.progress,
            description="speed sweep",
            unit="speeds",
        )
    )
    per_rpm = {
        k: f / model.params.input_speed_rpm
        for k, f in model.params.frequencies().items()
        if "mesh" in k
    }
    freqs = model.modal().frequencies
    crossings = []
    for name, per in per_rpm.items():
        for f in freqs[:6]:
            rpm = f / per
            if o.speed_min_rpm <= rpm <= o.speed_max_rpm:
                crossings.append(
                    {"source": name, "mode [Hz]": float(f), "input_speed [rpm]": float(rpm)}
                )
    i = int(np.argmax(p2p))
    return AnalysisResult(
        name="speed_sweep",
        title="DTE peak-to-peak against input speed",
        values={
            "input_speed [rpm]": speeds,
            "dte_peak_to_peak [arcsec]": p2p,
            "worst_speed [rpm]": float(speeds[i]),
            "worst_dte_peak_to_peak [arcsec]": float(p2p[i]),
            "mesh_mode_crossings": crossings,
        },
        references=["li2023"],
        notes=[
            f"{o.duration_s:g} s simulated after {o.settle_s:g} s settling per speed, from static "
            "equilibrium; crossings are the speeds where a mesh frequency equals one of the six "
            "lowest natural frequencies.",
        ],
        data={"crossings": crossings},
    )


def _batch(case, red, model, options) -> AnalysisResult:
    from gearte.runners.rv_dynamics_sim import dte_batch

    b = case.analyses.batch
    s = b.tolerance_scale
    tol = batch_tolerances(red, s)
    samples = options.samples or b.samples
    seed = options.seed if options.seed is not None else b.seed
    clear = dict(
        turning_arm_clearance_mm=red.cranks.cam_bearing_clearance,
        crank_bearing_clearance_mm=red.cranks.carrier_bearing_clearance,
        output_bearing_clearance_mm=red.supports.main_bearing_clearance,
    )
    res = dte_batch(
        model,
        samples,
        tolerances=tol,
        seed=seed,
        duration_s=b.duration_s,
        settle_s=b.settle_s,
        chunk_size=b.chunk_size,
        workers=options.workers,
        scheduler=options.scheduler,
        progress=options.progress,
        clearances=clear,
    )
    values = {
        "samples": samples,
        "dte_peak_to_peak_mean [arcsec]": res["peak_to_peak_mean"],
        "dte_peak_to_peak_sd [arcsec]": res["peak_to_peak_sd"],
        "dte_peak_to_peak_min [arcsec]": res["peak_to_peak_min"],
        "dte_peak_to_peak_max [arcsec]": res["peak_to_peak_max"],
        "dte_peak_to_peak_p95 [arcsec]": res["peak_to_peak_p95"],
        "simulated_seconds_per_wall_second": res["simulated_s"] / res["wall_s"],
    }
    return AnalysisResult(
        name="batch",
        title="DTE over random error realisations",
        values=values,
        references=["li2023"],
        notes=[
            "Each part's error amplitude uniform in [0, tolerance] (the largest of the case's "
            f"errors of that part × {s:g}), phase uniform in [0, 2π), independently per crank "
            f"and disc; seed {seed}. Pin and disc-profile errors are not drawn.",
            "Peak-to-peak over the simulated span after settling, reduced inside the kernel.",
        ],
        data={"rows": res["rows"]},
    )


def preflight_dynamics(case, red: RVReducer) -> None:
    """The checks of :func:`run_dynamics` that need the built model, without running an analysis
    (``gearte validate`` and ``gearte run`` before any analysis): the masses and inertias
    derived from geometry and density (:func:`build_dynamic_model`: a derived body needs
    ``reducer.density_kg_per_m3``), a finite elastic mode, and the RK4 step count of each
    fixed-step integration against the time budget (:func:`gearte.solvers.ode.check_rk4_steps`,
    at the default step of the base model; a speed of the sweep is checked again when it runs).

    Raises
    ------
    ParameterError
        The first failing check, naming its key.
    """
    from gearte.errors import ParameterError
    from gearte.runners.rv_dynamics_sim import default_step
    from gearte.solvers.ode import check_rk4_steps, check_span

    model, _ = build_dynamic_model(case, red)
    a = case.analyses
    for name in ("dte", "speed_sweep", "batch"):
        o = getattr(a, name)
        if o is None:
            continue
        try:  # the span each of its integrations gets: (0, settle + duration), settling first
            check_span((0.0, o.settle_s + o.duration_s), o.settle_s)
        except ParameterError as exc:
            raise ParameterError(
                f"analyses.{name}.duration_s",
                o.duration_s,
                f"leaves no simulated time after settle_s = {o.settle_s:g} s (settle_s + "
                f"duration_s = {o.settle_s + o.duration_s:g} s in double precision; the "
                f"integrator: {exc})",
            ) from None
    if a.dte is not None:  # the spectrum needs 8 samples of the recorded trace
        rec = a.dte.record_dt_s
        if a.dte.method == "rk4":  # the trace is recorded every round(record_dt / step) steps
            step = default_step(model, a.dte.step_fraction)
            rec = max(1, round(rec / step)) * step
        rounded = ", rounded to a multiple of the RK4 step" if a.dte.method == "rk4" else ""
        if a.dte.duration_s < 8.0 * rec:
            raise ParameterError(
                "analyses.dte.duration_s",
                a.dte.duration_s,
                f"is shorter than 8 recording intervals of {rec:.4g} s (record_dt_s{rounded}); "
                f"the DTE spectrum needs at least 8 samples: give duration_s >= "
                f"{8.0 * rec:.4g} s",
            )
    spans = []
    if a.dte is not None and a.dte.method == "rk4":
        spans.append((a.dte.step_fraction, a.dte.duration_s + a.dte.settle_s))
    for o in (a.speed_sweep, a.batch):
        if o is not None:
            spans.append((0.85, o.duration_s + o.settle_s))
    for fraction, span in spans:
        check_rk4_steps(default_step(model, fraction), span)


def run_dynamics(case, red: RVReducer, options) -> tuple[list[AnalysisResult], list[str]]:
    """Run the dynamic analyses an ``rv_reducer`` case asks for.

    Parameters
    ----------
    case : gearte.studies.rv_reducer.Case
        The validated case.
    red : RVReducer
        Its reducer (:func:`gearte.studies.rv_reducer.build_reducer`).
    options : gearte.studies.RunOptions
        Execution options (workers, scheduler, seed, samples, progress).
    """
    model, mp = build_dynamic_model(case, red)
    warnings: list[str] = []
    analyses = []
    a = case.analyses
    with _naming_the_inputs(case, "contact"):
        if a.contact is not None:
            analyses.append(_contact(case, model))
    with _naming_the_inputs(case, "modal"):
        if a.modal is not None:
            analyses.append(_modal(case, model, mp, warnings))
    with _naming_the_inputs(case, "dte"):
        if a.dte is not None:
            analyses.append(_dte(case, red, model, warnings))
    with _naming_the_inputs(case, "speed_sweep"):
        if a.speed_sweep is not None:
            analyses.append(_speed_sweep(case, model, options))
    with _naming_the_inputs(case, "batch"):
        if a.batch is not None:
            analyses.append(_batch(case, red, model, options))
    return analyses, warnings


def _clearance_inputs(case) -> list[str]:
    """``key = value`` of the case's non-zero bearing clearances (the inputs that make the
    dynamics' static equilibrium slow or singular)."""
    c, s = case.reducer.cranks, case.reducer.supports
    pairs = [
        ("reducer.cranks.cam_bearing.radial_clearance_um", c.cam_bearing.radial_clearance_um),
        (
            "reducer.cranks.carrier_bearing.radial_clearance_um",
            c.carrier_bearing.radial_clearance_um,
        ),
        ("reducer.supports.main_bearing_clearance_um", s.main_bearing_clearance_um),
    ]
    return [f"{k} = {v:g}" for k, v in pairs if v]


@contextlib.contextmanager
def _naming_the_inputs(case, analysis: str) -> Iterator[None]:
    """A solver of the dynamic analysis ``analysis`` that does not converge ends with a
    :class:`~gearte.errors.ConvergenceError` naming the analysis and the inputs that decide
    it (the bearing clearances, the load torque) beside the solver's own line."""
    from gearte.errors import ConvergenceError

    try:
        yield
    except ConvergenceError as exc:
        keys = _clearance_inputs(case)
        torque = f"operation.output_torque_Nm = {case.operation.output_torque_Nm:g}"
        why = (
            f"with {', '.join(keys)} and {torque}: parts float in their bearing clearances; "
            "a smaller clearance or a larger load torque holds them"
            if keys
            else f"with {torque}"
        )
        raise ConvergenceError(f"analyses.{analysis}: {exc} — {why}") from None
