"""Generate the bundled SYNTHETIC bench data of one RV-80E-like serial (not a measurement).

    .venv/bin/python examples/synthetic_rv_bench/make_synthetic_bench.py

Seeded (numpy default_rng(2026)): the same files every run. The serial is the reduced bench model
(gearte.models.bench_reduced) of the drive in ``hu2020_rv80e_initial_reducer`` with the KNOWN
parameters below; the bench adds Gaussian angle noise (0.3 arcsec), torque-sensor noise (0.02 %
of T_r), encoder quantisation (2^21 counts per revolution) and a rig compliance (0.1 / K_nom).

Files, written as a rig exports them (the case maps them, nothing is edited by hand):

* ``hysteresis.csv``: static sweep 0 → +T_r → −T_r → +T_r, branches marked.
* ``te/SN0001_{torque}Nm_{speed}rpm_{temp}C.csv``: one output revolution forward and backward
  (4000 samples each) per operating point: torques 0, 23.52 (3 % of T_r), 100, 392, 588, 784 N·m
  (the load opposing the motion, as a brake), speeds 10 and 20 rpm, oil at 20 and 40 °C. The
  columns are the rig's (``Angle CW;TE CW;Angle CCW;TE CCW``, no units: deg and arcsec, given in
  the case), no metadata lines (the operating point is in the name), and the TE is written as
  output − nominal (the other sign than gearte's; the case says so).
* ``truth.json``: the known values: parameters, and per (speed, temperature) the load-series
  quantities by their definitions (gearte.models.catalogue) on the noiseless model.

The running curve under a load T opposing the motion: θ_run(±T) = ±[F(T + T_run) + C_rig T]
with F the reduced model's play + elastic law (no friction width: the running friction enters
as the torque T_run the reducer's own friction adds to the load, larger in cold oil:
T_run = 8 N·m × (1 + (40 °C − t)/40 °C)). TE_d(φ) = o + d θ_run(T) + Σ families + encoder.
Invented trends so the plots have something to show: the crank order grows with torque
(× (1 + 0.5 T/T_r)), the cycloid-mesh order with speed (× (1 + n/40 rpm)), and a disc-lobe
order z_c = 39 and its 2nd harmonic appear with load (0.3 + 2.5 T/T_r and 0.2 + 1.2 T/T_r arcsec).
"""

from __future__ import annotations

import json
from dataclasses import replace
from pathlib import Path

import numpy as np

from gearte.io.bench import write_hysteresis
from gearte.io.case_file import load_case
from gearte.models.bench_reduced import hysteresis_angle, parameter_names, play, te_trace
from gearte.models.orders import rv_characteristic_orders
from gearte.runners.bench_calibration import reduced_constants, synthetic_bench
from gearte.studies.rv_reducer import build_reducer
from gearte.units import (
    Nm_to_Nmm,
    Nmm_per_rad_to_Nm_per_arcmin,
    arcsec_to_rad,
    rad_to_arcmin,
    rad_to_arcsec,
    rad_to_deg,
)

HERE = Path(__file__).resolve().parent
FAMILIES = ("output rotation", "crank rotation", "2× crank rotation", "cycloid mesh")
TRUTH_ARCSEC = {  # amplitude A [arcsec], lag ψ [deg]: A cos(n φ − ψ) per error family (invented)
    "output rotation": (2.0, 30.0),
    "crank rotation": (6.0, -50.0),
    "2× crank rotation": (1.5, 120.0),
    "cycloid mesh": (1.2, 200.0),
    "cycloid lobes": (0.3, 15.0),
    "2× cycloid lobes": (0.2, 80.0),
    "encoder eccentricity": (1.0, 75.0),
}
TORQUES_NM = (0.0, 23.52, 100.0, 392.0, 588.0, 784.0)
SPEEDS_RPM = (10.0, 20.0)
TEMPERATURES_C = (20.0, 40.0)
SAMPLES = 4000
LOST_MOTION_FRACTION = 0.03


def running_friction(temp_c: float) -> float:
    """Torque the reducer's own friction adds to the load while running [N·mm]."""
    return float(Nm_to_Nmm(8.0)) * (1.0 + (40.0 - temp_c) / 40.0)


def running_angle(model, p, torque, temp_c):
    """θ_run(+T) [rad]: play + elastic law at T + T_run, plus the rig's twist at T."""
    q = dict(p, friction_torque=0.0, rig_compliance=0.0, angle_offset=0.0)
    t = np.asarray(torque, dtype=float)
    law = hysteresis_angle(model, q, t + running_friction(temp_c), np.ones_like(t))
    return law + p["rig_compliance"] * t


def main() -> None:
    reducer = build_reducer(load_case("hu2020_rv80e_initial_reducer").reducer)
    fs = reducer.first_stage
    src = rv_characteristic_orders(fs.sun_teeth, fs.planet_teeth, reducer.pins.count)
    fams = {f: int(round(src["crank rotation"] * 2 if f.startswith("2×") else src[f]))
            for f in FAMILIES}  # fmt: skip
    model = reduced_constants(reducer, fams)
    z_c = reducer.pins.count - 1
    gen = replace(model, families={**fams, "cycloid lobes": z_c, "2× cycloid lobes": 2 * z_c})
    base = dict.fromkeys(parameter_names(gen), 0.0)
    base.update(
        cam_bearing_clearance=0.004, carrier_bearing_clearance=0.003,
        play_transition_torque=3e3, contact_stiffness_factor=0.9,
        rig_compliance=0.1 / model.nominal_rigidity, friction_torque=8e3, angle_offset=1e-4,
        te_offset=arcsec_to_rad(3.0), running_windup=0.0,
    )  # fmt: skip
    tr = model.rated_torque

    def with_families(p, torque_frac=0.0, speed=10.0):
        p = dict(p)
        for f, (a, ph) in TRUTH_ARCSEC.items():
            gain = 1.0
            if f == "crank rotation":
                gain = 1.0 + 0.5 * torque_frac
            elif f == "cycloid mesh":
                gain = 1.0 + speed / 40.0
            elif f == "cycloid lobes":
                gain = 1.0 + 2.5 / 0.3 * torque_frac
            elif f == "2× cycloid lobes":
                gain = 1.0 + 1.2 / 0.2 * torque_frac
            k = f.replace(" ", "_")
            p[f"{k}_cos"] = arcsec_to_rad(gain * a * np.cos(np.radians(ph)))
            p[f"{k}_sin"] = arcsec_to_rad(gain * a * np.sin(np.radians(ph)))
        return p

    rng = np.random.default_rng(2026)
    hyst, _ = synthetic_bench(model, with_families(base), rng, serial="SYNTH-0001")
    write_hysteresis(HERE / "hysteresis.csv", hyst)
    text = (HERE / "hysteresis.csv").read_text(encoding="utf-8")
    (HERE / "hysteresis.csv").write_text(
        "# SYNTHETIC data: examples/synthetic_rv_bench/make_synthetic_bench.py\n" + text,
        encoding="utf-8",
    )
    te_dir = HERE / "te"
    te_dir.mkdir(exist_ok=True)
    for old in te_dir.glob("*.csv"):
        old.unlink()
    q = 2 * np.pi / 2**21
    noise = arcsec_to_rad(0.3)
    pos_f = 2 * np.pi * np.arange(SAMPLES) / SAMPLES
    pos_b = pos_f[::-1].copy()
    truth_series = []
    f = LOST_MOTION_FRACTION
    for temp in TEMPERATURES_C:
        for speed in SPEEDS_RPM:
            for torque in TORQUES_NM:
                t_nmm = float(Nm_to_Nmm(torque))
                p = with_families(base, t_nmm / tr, speed)
                # TE_d = o + d (β + w)/2: w such that the forward−backward spread is 2 θ_run
                p["running_windup"] = 2.0 * float(running_angle(gen, base, t_nmm, temp)) - play(
                    gen, p
                )
                cols = []
                for pos, d in ((pos_f, 1), (pos_b, -1)):
                    te = te_trace(gen, p, pos, d) + rng.normal(0.0, noise, pos.size)
                    te = q * np.round(te / q)
                    cols += [rad_to_deg(pos), -rad_to_arcsec(te)]  # the rig: output − nominal
                lines = [
                    "# SYNTHETIC data: examples/synthetic_rv_bench/make_synthetic_bench.py",
                    "Angle CW;TE CW;Angle CCW;TE CCW",
                ]
                lines += [f"{a:.2f};{b:.3f};{c:.2f};{e:.3f}" for a, b, c, e in zip(*cols, strict=True)]
                name = f"SN0001_{torque:g}Nm_{speed:g}rpm_{temp:g}C.csv"
                (te_dir / name).write_text("\n".join(lines) + "\n", encoding="utf-8")

            def d_true(t, temp=temp):
                return 2.0 * running_angle(gen, base, t, temp)

            k = tr / (d_true(tr) - d_true(0.5 * tr))
            lm = d_true(f * tr)
            truth_series.append({
                "speed [rpm]": speed, "oil_temperature [°C]": temp,
                "bench_torsional_rigidity [N*m/arcmin]": float(Nmm_per_rad_to_Nm_per_arcmin(k)),
                "bench_lost_motion [arcmin]": float(rad_to_arcmin(lm)),
                "bench_hysteresis [arcmin]": float(rad_to_arcmin(d_true(0.0))),
                "bench_backlash [arcmin]": float(rad_to_arcmin(lm - 2 * f * tr / k)),
            })  # fmt: skip
    truth = {
        "note": "SYNTHETIC: known values of examples/synthetic_rv_bench (make_synthetic_bench.py)",
        "parameters": {k: v for k, v in base.items() if v},
        "family_amplitudes [arcsec] at zero load, 10 rpm": {
            k: v[0] for k, v in TRUTH_ARCSEC.items()
        },
        "lost_motion_fraction": f,
        "load_series": truth_series,
    }
    (HERE / "truth.json").write_text(json.dumps(truth, indent=1) + "\n", encoding="utf-8")
    print(f"wrote {HERE}")


if __name__ == "__main__":
    main()
