"""Generate the bundled SYNTHETIC bench data of one RV-80E-like serial (not a measurement).

    .venv/bin/python examples/synthetic_rv_bench/make_synthetic_bench.py

Seeded (numpy default_rng(2026)): the same files every run. The serial is the reduced bench model
(gearte.models.bench_reduced) of the drive in ``hu2020_rv80e_initial_reducer`` with the KNOWN
parameters below; the bench adds Gaussian angle noise (0.3 arcsec), torque-sensor noise (0.02 %
of T_r), encoder quantisation (2^21 counts per revolution) and a rig compliance (0.1 / K_nom).
Operating points: torque 0 / 200 / 400 N·m × speed 10 / 20 rpm, oil 30-50 °C; the crank-order
amplitude grows with torque (× (1 + 0.5 T/T_r)) and the cycloid-mesh order with speed
(× (1 + speed/40 rpm)) — invented trends, so the trend plots have something to show.
Files: hysteresis.csv (0 → +T_r → −T_r → +T_r, branches marked), te/op_*.csv (4 columns,
6000 samples per output revolution and direction).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from gearte.io.case_file import load_case
from gearte.io.bench import write_hysteresis
from gearte.models.bench_reduced import parameter_names
from gearte.models.orders import rv_characteristic_orders
from gearte.runners.bench_calibration import reduced_constants, synthetic_bench
from gearte.studies.rv_reducer import build_reducer
from gearte.units import arcsec_to_rad, rad_to_arcsec, rad_to_deg

HERE = Path(__file__).resolve().parent
FAMILIES = ("output rotation", "crank rotation", "2× crank rotation", "involute mesh",
            "cycloid mesh")
TRUTH_ARCSEC = {  # amplitude A [arcsec], lag ψ [deg]: A cos(n φ − ψ) per error family (invented)
    "output rotation": (2.0, 30.0),
    "crank rotation": (6.0, -50.0),
    "2× crank rotation": (1.5, 120.0),
    "involute mesh": (0.8, 10.0),
    "cycloid mesh": (1.2, 200.0),
    "encoder eccentricity": (1.0, 75.0),
}


def main() -> None:
    reducer = build_reducer(load_case("hu2020_rv80e_initial_reducer").reducer)
    fs = reducer.first_stage
    src = rv_characteristic_orders(fs.sun_teeth, fs.planet_teeth, reducer.pins.count)
    fams = {f: int(round(src["crank rotation"] * 2 if f.startswith("2×") else src[f]))
            for f in FAMILIES}
    model = reduced_constants(reducer, fams)
    base = dict.fromkeys(parameter_names(model), 0.0)
    base.update(
        cam_bearing_clearance=0.004, carrier_bearing_clearance=0.003,
        play_transition_torque=3e3, contact_stiffness_factor=0.9,
        rig_compliance=0.1 / model.nominal_rigidity, friction_torque=8e3, angle_offset=1e-4,
        te_offset=arcsec_to_rad(3.0), running_windup=arcsec_to_rad(5.0),
    )

    def with_families(p, torque_frac=0.0, speed=10.0):
        p = dict(p)
        for f, (a, ph) in TRUTH_ARCSEC.items():
            gain = 1.0
            if f == "crank rotation":
                gain = 1.0 + 0.5 * torque_frac
            if f == "cycloid mesh":
                gain = 1.0 + speed / 40.0
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
    (HERE / "te").mkdir(exist_ok=True)
    k = 0
    for torque in (0.0, 200.0, 400.0):
        for speed in (10.0, 20.0):
            k += 1
            p = with_families(base, torque * 1e3 / model.rated_torque, speed)
            _, tr = synthetic_bench(model, p, rng, samples_per_revolution=6000, serial="SYNTH-0001")
            temp = 30.0 + 10.0 * (torque / 200.0) + (speed - 10.0) * 0.2
            lines = [
                "# serial: SYNTH-0001",
                "# SYNTHETIC data: examples/synthetic_rv_bench/make_synthetic_bench.py",
                f"# speed_rpm: {speed}", f"# torque_Nm: {torque}",
                f"# oil_temperature_C: {temp}",
                "forward_position [deg],forward_te [arcsec],backward_position [deg],"
                "backward_te [arcsec]",
            ]
            cols = [rad_to_deg(tr.forward_position), rad_to_arcsec(tr.forward_te),
                    rad_to_deg(tr.backward_position), rad_to_arcsec(tr.backward_te)]
            lines += [f"{a:.5f},{b:.3f},{c:.5f},{d:.3f}" for a, b, c, d in zip(*cols)]
            (HERE / "te" / f"op_{k:02d}_T{int(torque)}_n{int(speed)}.csv").write_text(
                "\n".join(lines) + "\n", encoding="utf-8")
    print(f"wrote {HERE}")


if __name__ == "__main__":
    main()
