"""Study kind ``rv_dynamics``: RV reducer dynamics after Li et al. (2023), paper 004.

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

from typing import Literal

import numpy as np
from pydantic import Field, model_validator

from gearte.io.schema import CaseBase, StrictModel
from gearte.results import AnalysisResult, StudyResult

KIND = "rv_dynamics"
REFERENCES = ["li2023"]
FIGURES = "gearte.plotting.rv_dynamics"


class Reducer(StrictModel):
    """Geometry of the RV reducer (paper 004 Table 1)."""

    sun_teeth: int = Field(12, ge=6, le=200, description="z_s")
    planet_teeth: int = Field(36, ge=6, le=400, description="z_pl")
    module_mm: float = Field(1.5, gt=0, le=20, description="involute module [mm]")
    pressure_angle_deg: float = Field(20.0, gt=10, lt=35, description="α [deg]")
    crank_count: int = Field(3, ge=2, le=6, description="M, cranks/planets")
    disc_count: int = Field(2, ge=1, le=3, description="N, cycloid discs")
    pin_count: int = Field(40, ge=6, le=200, description="z_p; the disc has z_p − 1 teeth")
    pin_radius_mm: float = Field(3.0, gt=0, le=50, description="r_rp [mm]")
    pin_circle_radius_mm: float = Field(85.8, gt=0, le=2000, description="r_p [mm]")
    eccentricity_mm: float = Field(1.3, gt=0, le=50, description="e [mm]")
    face_width_mm: float = Field(12.0, gt=0, le=500, description="B [mm]")
    youngs_modulus_MPa: float = Field(2.06e5, gt=1e3, le=1e6, description="E [MPa]")  # noqa: N815
    poisson_ratio: float = Field(0.3, ge=0, lt=0.5, description="ν")

    @model_validator(mode="after")
    def _k1(self):
        k1 = self.eccentricity_mm * self.pin_count / self.pin_circle_radius_mm
        if not k1 < 1:
            raise ValueError(
                f"K1 = eccentricity_mm·pin_count/pin_circle_radius_mm = {k1:.4f} must be < 1"
            )
        return self


class Modification(StrictModel):
    """Cycloid profile modification (paper 004 §4.1: −0.01 radius, −0.05 position)."""

    pin_radius_mm: float = Field(0.0, ge=-0.5, le=0.5, description="Δr_rp [mm]")
    pin_position_mm: float = Field(0.0, ge=-0.5, le=0.5, description="Δr_p [mm]")


class Dynamics(StrictModel):
    """Table 2 masses, inertias and stiffnesses; assumed values where the paper gives none."""

    sun_mass_kg: float = Field(1.3, gt=0, le=1e3)
    planet_mass_kg: float = Field(0.88, gt=0, le=1e3)
    crank_mass_kg: float = Field(0.4, gt=0, le=1e3)
    disc_mass_kg: float = Field(2.76, gt=0, le=1e3)
    output_mass_kg: float = Field(15.33, gt=0, le=1e4)
    sun_inertia_kgm2: float = Field(4.44e-4, gt=0, le=1e3)
    planet_inertia_kgm2: float = Field(1.01e-3, gt=0, le=1e3)
    crank_inertia_kgm2: float = Field(7.56e-5, gt=0, le=1e3)
    disc_inertia_kgm2: float = Field(0.0209, gt=0, le=1e3)
    output_inertia_kgm2: float = Field(0.106, gt=0, le=1e4)
    input_torsional_stiffness_Nm_per_rad: float = Field(1.16e4, gt=0, le=1e9)  # noqa: N815
    sun_support_stiffness_N_per_m: float = Field(4.68e7, gt=0, le=1e12)  # noqa: N815
    crank_torsional_stiffness_Nm_per_rad: float = Field(6.99e4, gt=0, le=1e9)  # noqa: N815
    crank_bending_stiffness_N_per_m: float = Field(5.55e8, gt=0, le=1e12)  # noqa: N815
    crank_bearing_stiffness_N_per_m: float = Field(5.76e8, gt=0, le=1e12)  # noqa: N815
    turning_arm_bearing_stiffness_N_per_m: float = Field(2.84e8, gt=0, le=1e12)  # noqa: N815
    output_support_stiffness_N_per_m: float = Field(3.15e8, gt=0, le=1e12)  # noqa: N815
    involute_single_pair_stiffness_N_per_m: float = Field(  # noqa: N815
        1.4e8, gt=0, le=1e12, description="assumed (ISO 6336 c' × 10 mm face width)"
    )
    damping_ratio: float = Field(0.03, gt=0, lt=1, description="ζ of the lowest elastic mode")
    cycloid_stiffness: Literal["fourier", "mean"] = Field(
        "fourier", description="time-varying k_cr (Fourier) or its mean (as the paper)"
    )
    cycloid_mesh_stiffness_N_per_m: float | None = Field(  # noqa: N815
        None, gt=0, le=1e12, description="override of the mean k_cr (paper prints 2.62e8)"
    )
    cycloid_pressure_angle_deg: float | None = Field(
        None, ge=0, lt=90, description="override of the equivalent pressure angle β"
    )
    involute_harmonics: int = Field(10, ge=1, le=60)
    cycloid_harmonics: int = Field(8, ge=1, le=30)


class Operation(StrictModel):
    input_speed_rpm: float = Field(1500.0, gt=0, le=2e4)
    output_torque_Nm: float = Field(450.0, gt=0, le=1e5)  # noqa: N815


class ErrorValue(StrictModel):
    amplitude_mm: float = Field(ge=0, le=1.0)
    phase_deg: float = Field(ge=-360, le=360)


class Errors(StrictModel):
    """Table 3 errors and bearing clearances; ``placement`` says which crank/disc carries them."""

    placement: Literal["first", "all"] = Field(
        "first",
        description="'first': per-crank errors on crank 1, per-disc errors on disc 1 of crank 1; "
        "'all': the same error on every crank and disc",
    )
    sun_eccentricity: ErrorValue = ErrorValue(amplitude_mm=0.005, phase_deg=45)
    planet_eccentricity: ErrorValue = ErrorValue(amplitude_mm=0.006, phase_deg=30)
    sun_assembly: ErrorValue = ErrorValue(amplitude_mm=0.005, phase_deg=100)
    disc_hole: ErrorValue = ErrorValue(amplitude_mm=0.008, phase_deg=140)
    cam: ErrorValue = ErrorValue(amplitude_mm=0.008, phase_deg=90)
    carrier_hole: ErrorValue = ErrorValue(amplitude_mm=0.035, phase_deg=270)
    output_assembly: ErrorValue = ErrorValue(amplitude_mm=0.038, phase_deg=90)
    turning_arm_clearance_mm: float = Field(0.0, ge=0, le=0.1)
    crank_bearing_clearance_mm: float = Field(0.0, ge=0, le=0.1)
    output_bearing_clearance_mm: float = Field(0.0, ge=0, le=0.1)


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
    speed_min_rpm: float = Field(100.0, gt=0, le=2e4)
    speed_max_rpm: float = Field(3000.0, gt=0, le=2e4)
    resonance_margin: float = Field(0.1, gt=0, lt=1, description="relative band around a mode")

    @model_validator(mode="after")
    def _order(self):
        if not self.speed_max_rpm > self.speed_min_rpm:
            raise ValueError("speed_max_rpm must be > speed_min_rpm")
        return self


class DTEOptions(StrictModel):
    duration_s: float = Field(0.5, gt=0, le=60, description="simulated time after settling [s]")
    settle_s: float = Field(0.1, ge=0, le=10, description="settling time from static equilibrium")
    method: Literal["rk4", "dopri5", "scipy"] = "rk4"
    step_fraction: float = Field(0.85, gt=0, le=1, description="RK4 step / stability limit")
    record_dt_s: float = Field(1e-4, gt=0, le=0.1, description="recording interval [s]")


class SpeedSweepOptions(StrictModel):
    """DTE peak-to-peak over a range of input speeds (resonances of the mesh excitation)."""

    speed_min_rpm: float = Field(300.0, gt=0, le=2e4)
    speed_max_rpm: float = Field(3000.0, gt=0, le=2e4)
    count: int = Field(19, ge=2, le=500)
    duration_s: float = Field(0.1, gt=0, le=10, description="simulated time per speed [s]")
    settle_s: float = Field(0.1, ge=0, le=10)

    @model_validator(mode="after")
    def _order(self):
        if not self.speed_max_rpm > self.speed_min_rpm:
            raise ValueError("speed_max_rpm must be > speed_min_rpm")
        return self


class BatchOptions(StrictModel):
    samples: int = Field(16, ge=1, le=100000)
    duration_s: float = Field(0.5, gt=0, le=60)
    settle_s: float = Field(0.1, ge=0, le=10)
    seed: int = Field(0, ge=0)
    chunk_size: int = Field(4, ge=1, le=10000)
    tolerance_scale: float = Field(1.0, gt=0, le=10, description="× Table 3 amplitudes")


class Analyses(StrictModel):
    contact: ContactOptions | None = None
    modal: ModalOptions | None = None
    dte: DTEOptions | None = None
    speed_sweep: SpeedSweepOptions | None = None
    batch: BatchOptions | None = None


class Case(CaseBase):
    reducer: Reducer = Reducer()
    modification: Modification = Modification()
    dynamics: Dynamics = Dynamics()
    operation: Operation = Operation()
    errors: Errors | None = None
    analyses: Analyses = Analyses(contact=ContactOptions(), modal=ModalOptions(), dte=DTEOptions())


# --- building the domain objects -----------------------------------------------------------
def build_parameters(case: Case, **overrides):
    """RVDynamicsParameters of a case (the CLI and the API build the same object)."""
    from gearte.models.cycloid_loaded_contact import CycloidPinPair
    from gearte.models.rv_dynamics import RVDynamicsParameters

    r, mo, d, op = case.reducer, case.modification, case.dynamics, case.operation
    pair = CycloidPinPair(
        pin_count=r.pin_count,
        pin_radius_mm=r.pin_radius_mm,
        pin_circle_radius_mm=r.pin_circle_radius_mm,
        eccentricity_mm=r.eccentricity_mm,
        face_width_mm=r.face_width_mm,
        youngs_modulus_MPa=r.youngs_modulus_MPa,
        poisson_ratio=r.poisson_ratio,
        pin_radius_modification_mm=mo.pin_radius_mm,
        pin_position_modification_mm=mo.pin_position_mm,
    )
    kw = dict(
        sun_teeth=r.sun_teeth,
        planet_teeth=r.planet_teeth,
        module_mm=r.module_mm,
        pressure_angle_deg=r.pressure_angle_deg,
        crank_count=r.crank_count,
        disc_count=r.disc_count,
        pair=pair,
        input_speed_rpm=op.input_speed_rpm,
        output_torque_Nm=op.output_torque_Nm,
        **d.model_dump(),
    )
    if case.analyses.contact is not None:
        kw["contact_positions"] = case.analyses.contact.positions
    kw.update(overrides)
    return RVDynamicsParameters(**kw)


def build_errors(case: Case, scale: float = 1.0):
    """RVErrors of a case (None section → no errors)."""
    from gearte.models.rv_dynamics import RVErrors

    m, n = case.reducer.crank_count, case.reducer.disc_count
    e = case.errors
    if e is None:
        return RVErrors(crank_count=m, disc_count=n)
    mask_m = np.zeros(m)
    mask_mn = np.zeros((m, n))
    if e.placement == "first":
        mask_m[0], mask_mn[0, 0] = 1.0, 1.0
    else:
        mask_m[:], mask_mn[:] = 1.0, 1.0

    def one(v):
        return (scale * v.amplitude_mm, np.deg2rad(v.phase_deg))

    def arr(v, mask):
        return np.stack(
            [scale * v.amplitude_mm * mask, np.full(mask.shape, np.deg2rad(v.phase_deg))], -1
        )

    return RVErrors(
        crank_count=m,
        disc_count=n,
        sun_eccentricity=one(e.sun_eccentricity),
        sun_assembly=one(e.sun_assembly),
        output_assembly=one(e.output_assembly),
        planet_eccentricity=arr(e.planet_eccentricity, mask_m),
        carrier_hole=arr(e.carrier_hole, mask_m),
        disc_hole=arr(e.disc_hole, mask_mn),
        cam=arr(e.cam, mask_mn),
        turning_arm_clearance_mm=e.turning_arm_clearance_mm,
        crank_bearing_clearance_mm=e.crank_bearing_clearance_mm,
        output_bearing_clearance_mm=e.output_bearing_clearance_mm,
    )


# --- analyses --------------------------------------------------------------------------------
def _contact(case: Case, model) -> AnalysisResult:
    from gearte.models.cycloid_loaded_contact import mesh_period_contact

    c = model.contact
    pair = model.params.pair
    opts = case.analyses.contact
    t_disc = case.operation.output_torque_Nm / case.reducer.disc_count
    sweep = []
    for tq in opts.load_sweep_Nm:
        mp = mesh_period_contact(pair, tq * 1e3, min(opts.positions, 24))
        sweep.append(
            {
                "torque_per_disc [N·m]": tq,
                "equivalent_pressure_angle_mean [deg]": float(np.degrees(mp.pressure_angle_mean)),
                "equivalent_mesh_stiffness_mean [N/m]": mp.mesh_stiffness_mean * 1e3,
                "pins_in_contact_mean": float(np.mean(mp.pins_in_contact)),
            }
        )
    mean_k, a_k, b_k = model.cycloid_fourier
    beta = np.degrees(c.pressure_angle)
    values = {
        "equivalent_pressure_angle_mean [deg]": float(np.degrees(c.pressure_angle_mean)),
        "equivalent_pressure_angle_min [deg]": float(beta.min()),
        "equivalent_pressure_angle_max [deg]": float(beta.max()),
        "equivalent_mesh_stiffness_mean [N/m]": c.mesh_stiffness_mean * 1e3,
        "equivalent_mesh_stiffness_min [N/m]": float(c.mesh_stiffness.min() * 1e3),
        "equivalent_mesh_stiffness_max [N/m]": float(c.mesh_stiffness.max() * 1e3),
        "pins_in_contact_min": int(c.pins_in_contact.min()),
        "pins_in_contact_max": int(c.pins_in_contact.max()),
        "max_pin_force [N]": float(c.max_force.max()),
        "max_contact_pressure [MPa]": c.max_contact_pressure,
        "contact_law": pair.contact_law,
        "torque_per_disc [N·m]": t_disc,
        "mesh_position [deg]": np.degrees(c.mesh_position),
        "equivalent_pressure_angle [deg]": beta,
        "equivalent_mesh_stiffness [N/m]": c.mesh_stiffness * 1e3,
        "signed_resultant_pressure_angle_mean [deg]": float(
            np.degrees(
                np.mean(np.arctan2(c.contact.radial_force_signed, c.contact.tangential_force))
            )
        ),
        "stiffness_fourier_a [N/m]": a_k * 1e3,
        "stiffness_fourier_b [N/m]": b_k * 1e3,
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


def _modal(case: Case, model, warnings: list[str]) -> AnalysisResult:
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
        ],
        data={
            "modal": modal,
            "speeds_rpm": speeds,
            "mesh_lines": meshes,
            "operating_rpm": model.params.input_speed_rpm,
        },
    )


def _dte(case: Case, model, warnings: list[str]) -> AnalysisResult:
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
    resolution = 1.0 / opts.duration_s
    notes = [
        "DTE = θ_o − θ_s/i with absolute rotations, from static equilibrium; the mean (static "
        "wind-up under load) is removed before the peak-to-peak.",
        f"Spectrum resolution {resolution:.3g} Hz (Hann window); peaks labelled by the nearest "
        "harmonic of a rotation or mesh frequency, or a mesh ± rotation sideband.",
        "Paper 004 Fig 11: 0.78″ without errors, 17.25″ with errors (bench 22.56″/23.37″).",
    ]
    if case.errors is not None:
        notes.append(
            f"Table 3 errors placed '{case.errors.placement}' (see the case's [errors] section)."
        )
    if opts.duration_s * sources["output rotation"] < 0.99 and case.errors is not None:
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


def _speed_sweep(case: Case, model, options) -> AnalysisResult:
    from gearte.execution import map_chunks

    o = case.analyses.speed_sweep
    speeds = np.linspace(o.speed_min_rpm, o.speed_max_rpm, o.count)
    p2p = np.array(
        map_chunks(
            _sweep_one,
            [(model, s, o.duration_s, o.settle_s) for s in speeds],
            workers=options.workers,
            scheduler=options.scheduler,
            progress=options.progress,
            description="speed sweep",
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


def _batch(case: Case, model, options) -> AnalysisResult:
    from gearte.runners.rv_dynamics_sim import ErrorTolerances, dte_batch

    b = case.analyses.batch
    e = case.errors or Errors()
    s = b.tolerance_scale
    tol = ErrorTolerances(
        sun_eccentricity=s * e.sun_eccentricity.amplitude_mm,
        planet_eccentricity=s * e.planet_eccentricity.amplitude_mm,
        sun_assembly=s * e.sun_assembly.amplitude_mm,
        disc_hole=s * e.disc_hole.amplitude_mm,
        cam=s * e.cam.amplitude_mm,
        carrier_hole=s * e.carrier_hole.amplitude_mm,
        output_assembly=s * e.output_assembly.amplitude_mm,
    )
    samples = options.samples or b.samples
    seed = options.seed if options.seed is not None else b.seed
    clear = {}
    if case.errors is not None:
        clear = dict(
            turning_arm_clearance_mm=e.turning_arm_clearance_mm,
            crank_bearing_clearance_mm=e.crank_bearing_clearance_mm,
            output_bearing_clearance_mm=e.output_bearing_clearance_mm,
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
            "Each part's error amplitude uniform in [0, tolerance] (Table 3 amplitudes × "
            f"{s:g}), phase uniform in [0, 2π), independently per crank and disc; seed {seed}.",
            "Peak-to-peak over the simulated span after settling, reduced inside the kernel.",
        ],
        data={"rows": res["rows"]},
    )


def run(case: Case, options) -> StudyResult:
    """Run the analyses the case asks for."""
    from gearte.models.rv_dynamics import RVDynamicModel

    params = build_parameters(case)
    model = RVDynamicModel(params, build_errors(case))
    warnings: list[str] = []
    analyses = []
    a = case.analyses
    if a.contact is not None:
        analyses.append(_contact(case, model))
    if a.modal is not None:
        analyses.append(_modal(case, model, warnings))
    if a.dte is not None:
        analyses.append(_dte(case, model, warnings))
    if a.speed_sweep is not None:
        analyses.append(_speed_sweep(case, model, options))
    if a.batch is not None:
        analyses.append(_batch(case, model, options))
    return StudyResult(case=case, analyses=analyses, warnings=warnings)
