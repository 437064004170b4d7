"""Generate the bundled SYNTHETIC lot of RV-110E-like parts (issue 16).

    python examples/lots/make_synthetic_lot.py            # rewrites examples/lots/synthetic_rv110e/

The parts are drawn, with a fixed seed, from the tolerances below around the design of the
bundled case ``han2023_rv110e_no_errors`` (40 pins, 39 teeth, 3 cranks, 2 discs, e = 1.5 mm,
crank circle 45 mm). They are SYNTHETIC: no measured lot was available; the tolerances are
ASSUMED, chosen as typical of precision-ground RV parts (a few micrometres):

=====================================  ========================================================
disc flank (normal deviation)          size offset per disc N(-6, 2) µm (grinding size scatter)
                                       + form per point N(0, 0.8) µm, 11 points per tooth
                                       (profile parameter -150° ... 150°)
disc cumulative pitch                  one sine per revolution, amplitude U(0, 4) µm, random
                                       phase, + single pitch noise N(0, 1) µm; tooth 1 = 0
disc crank-bore centres                nominal + N(0, 4) µm per coordinate
cam eccentricity                       1.5 mm + N(0, 4) µm; phase N(0, 3e-3) rad
planet run-out (TIR)                   2 × Rayleigh(4 µm), uniform angle
bearing clearances                     cam bearings U(2, 8) µm, carrier bearings U(1, 5) µm
=====================================  ========================================================

Files (formats: docs/metrology.md): disc_profile.csv, disc_pitch.csv, disc_bores.csv,
crank_eccentricity.csv, planet_runout.csv (a planet carries the serial of the crank it is
mounted on), bearing_clearance.csv; and the bundled cases examples/synthetic_rv110e_lot.toml
(the lot: disc sets and crank sets as they come off the line) and
examples/synthetic_rv110e_serial.toml (the first reducer as one serial).
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

from gearte.io import metrology as mt

SEED = 20261125
REDUCERS = 24
TEETH, CRANKS, DISCS = 39, 3, 2
ECCENTRICITY_MM, CRANK_CIRCLE_MM = 1.5, 45.0
PROFILE_POINTS_DEG = np.arange(-150.0, 151.0, 30.0)


def make(folder: Path, reducers: int = REDUCERS, seed: int = SEED) -> None:
    """Write the lot's files into ``folder``."""
    rng = np.random.default_rng(seed)
    folder.mkdir(parents=True, exist_ok=True)
    um = 1e-3
    phi = np.radians(PROFILE_POINTS_DEG)
    discs = [f"D-{k + 1:04d}" for k in range(DISCS * reducers)]
    cranks = [f"C-{k + 1:04d}" for k in range(CRANKS * reducers)]
    profiles, pitch, bores = {}, {}, {}
    ang = 2 * np.pi * np.arange(CRANKS) / CRANKS
    nominal = CRANK_CIRCLE_MM * np.stack([np.cos(ang), np.sin(ang)], -1)
    for s in discs:
        size = rng.normal(-6.0, 2.0) * um
        dev = tuple(np.round(size + rng.normal(0, 0.8, phi.size) * um, 5) for _ in range(TEETH))
        profiles[s] = mt.DiscProfile(tuple([phi] * TEETH), dev)
        amp, ph = rng.uniform(0, 4.0) * um, rng.uniform(0, 2 * np.pi)
        cp = amp * np.sin(2 * np.pi * np.arange(TEETH) / TEETH - ph) + rng.normal(0, um, TEETH)
        pitch[s] = np.round(cp - cp[0], 5)
        bores[s] = np.round(nominal + rng.normal(0, 4.0 * um, (CRANKS, 2)), 5)
    cams, runout, clear = {}, {}, {}
    for s in cranks:
        cams[s] = mt.CrankCams(
            np.round(ECCENTRICITY_MM + rng.normal(0, 4.0 * um, DISCS), 5),
            np.round(rng.normal(0, 3e-3, DISCS), 6),
        )
        runout[s] = mt.Runout(
            round(2 * rng.rayleigh(4.0 * um), 5), round(rng.uniform(-np.pi, np.pi), 4)
        )
        clear[s] = {f"cam_{j + 1}": round(rng.uniform(2, 8) * um, 5) for j in range(DISCS)}
        clear[s]["carrier"] = round(rng.uniform(1, 5) * um, 5)
    mt.write_disc_profiles(folder / "disc_profile.csv", profiles)
    mt.write_disc_pitch(folder / "disc_pitch.csv", pitch)
    mt.write_disc_bores(folder / "disc_bores.csv", bores)
    mt.write_crank_eccentricity(folder / "crank_eccentricity.csv", cams)
    mt.write_runout(folder / "planet_runout.csv", runout)
    mt.write_bearing_clearances(folder / "bearing_clearance.csv", clear)
    disc_sets = [discs[DISCS * k : DISCS * (k + 1)] for k in range(reducers)]
    crank_sets = [cranks[CRANKS * k : CRANKS * (k + 1)] for k in range(reducers)]

    def toml_list(sets):
        return "\n".join("  [" + ", ".join(f'"{x}"' for x in s) + "]," for s in sets)

    rel = f"lots/{folder.name}"
    case = LOT_CASE.format(
        seed=seed,
        reducers=reducers,
        rel=rel,
        disc_sets=toml_list(disc_sets),
        crank_sets=toml_list(crank_sets),
    )
    (folder.parent.parent / f"{folder.name}_lot.toml").write_text(case, encoding="utf-8")
    serial = SERIAL_CASE.format(
        rel=rel,
        discs=", ".join(f'"{x}"' for x in disc_sets[0]),
        cranks=", ".join(f'"{x}"' for x in crank_sets[0]),
    )
    (folder.parent.parent / f"{folder.name}_serial.toml").write_text(serial, encoding="utf-8")


LOT_CASE = """# SYNTHETIC lot of {reducers} RV-110E-like reducers' parts, written by
# examples/lots/make_synthetic_lot.py (seed {seed}; the tolerances it assumes are in its docstring).
# Which disc set goes with which crank set, in which orientation, so that most reducers meet the
# TE spec; pin diameter grade per reducer for a backlash window. Method: docs/selective-assembly.md

[case]
kind = "rv_lot"
title = "Selective assembly of a synthetic lot of {reducers} RV-110E-like reducers"
references = ["han2023"]
description = "SYNTHETIC parts (seeded script); design of han2023_rv110e_no_errors."

[reducer]
case = "han2023_rv110e_no_errors"

[lot]
disc_sets = [
{disc_sets}
]
crank_sets = [
{crank_sets}
]

[lot.files]
disc_profile = "{rel}/disc_profile.csv"
disc_pitch = "{rel}/disc_pitch.csv"
disc_bores = "{rel}/disc_bores.csv"
crank_eccentricity = "{rel}/crank_eccentricity.csv"
planet_runout = "{rel}/planet_runout.csv"
bearing_clearance = "{rel}/bearing_clearance.csv"

[analyses.selective_assembly]
torque_Nm = 1078.0
positions = 360
te_spec_arcsec = 15.0
objective = "count_in_spec"
planet_indexings = 4     # ASSUMED: a planet can be mounted in 4 spline positions on its crank
random_assemblies = 200
seed = 1

[analyses.pin_grading]
grades_um = [-10.0, -8.0, -6.0, -4.0, -2.0, 0.0, 2.0, 4.0, 6.0]
backlash_window_arcmin = [0.2, 0.6]
"""

SERIAL_CASE = """# One SYNTHETIC serial built from the first disc set and crank set of the lot
# (examples/lots/make_synthetic_lot.py): its model from the measurement files, paths relative to
# this file. Formats: docs/metrology.md.

[case]
kind = "rv_serial"
title = "Serial RV-0001 of the synthetic RV-110E-like lot, from its measured parts"
references = ["han2023"]
description = "SYNTHETIC measured parts; design of han2023_rv110e_no_errors."

[reducer]
case = "han2023_rv110e_no_errors"

[serial]
name = "RV-0001"
discs = [{discs}]
cranks = [{cranks}]
planets = [{cranks}]

[serial.files]
disc_profile = "{rel}/disc_profile.csv"
disc_pitch = "{rel}/disc_pitch.csv"
disc_bores = "{rel}/disc_bores.csv"
crank_eccentricity = "{rel}/crank_eccentricity.csv"
bearing_clearance = "{rel}/bearing_clearance.csv"
planet_runout = "{rel}/planet_runout.csv"

[analyses.load_sharing]
torque_Nm = 1078.0
positions = 360

[analyses.transmission_error]
torque_Nm = 1078.0
positions = 360
# geometric TE at 1 % of the torque: with the measured bearing clearances the solver finds no
# equilibrium at the default 0.1 % near some positions (the parts float in their clearances)
zero_load_fraction = 0.01

[analyses.catalogue]
lost_motion_fraction = 0.03
"""

if __name__ == "__main__":
    out = Path(sys.argv[1]) if len(sys.argv) > 1 else Path(__file__).parent / "synthetic_rv110e"
    make(out)
    print(f"wrote {out}")
