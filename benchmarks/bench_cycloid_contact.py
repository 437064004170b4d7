"""Benchmark: tooth contact analysis at 1000 mesh positions over one tooth pitch, both laws.

gearte's compiled tooth contact (``tooth_contact``: one numba kernel per law doing the pin
geometry, the solve and the forces/pressures, positions in order with warm starts) against, in
the same run:

* the **strong baseline** a competent numpy user would write: every pin and position as one
  array (phases, S, arms, eq 32 clearances, eq 40 curvatures through gearte's numpy geometry),
  a vectorised Newton iteration over all positions at once for the same law to the same
  tolerance (1e-12 relative), warm-started from the solution of the first position, then the
  forces and Hertz pressures in numpy. ``"hu2020"``: Newton on eq 44's residual g(F_max) with
  its analytic derivative. ``"line_contact"``: Newton on the disc rotation (dT/dΔφ = Σ k_t l²),
  each pin's force from its own law by an inner Newton on ln F started from the previous outer
  step's value;
* the **weak baseline** this benchmark printed before: gearte's plain twin (``implementation=
  "plain"``: per-pin Python loops with bisection for ``"hu2020"``; the numpy solver that inverts
  every pin's law from scratch at each step for ``"line_contact"``).

Times are CPU seconds (``time.process_time``, best of several repeats), less sensitive to the load
of a shared machine than wall time; the load average is printed. One summary line per goal:
gearte ≥ 8× the numpy Newton (issue 12).

    .venv/bin/python benchmarks/bench_cycloid_contact.py [--positions 1000]
"""

from __future__ import annotations

import argparse
import math
import os
import time

import numpy as np

from gearte.geometry.cycloid import CycloidStage
from gearte.models.contact_law import log_law_coefficients, max_contact_pressure
from gearte.models.cycloid_contact import compliance_constants, start_force, tooth_contact

GOAL = 8.0
RTOL = 1e-12


def _cpu_best(fn, repeat: int) -> float:
    best = float("inf")
    for _ in range(repeat):
        t0 = time.process_time()
        fn()
        best = min(best, time.process_time() - t0)
    return best


def _geometry(stage: CycloidStage, theta: np.ndarray):
    """Pin phases, arm ratio, eq 32 clearance, eq 40 curvature: numpy over positions × pins."""
    phase = stage.pin_phases(theta)
    K1 = stage.K1
    S = np.sqrt(1.0 + K1 * K1 - 2.0 * K1 * np.cos(phase))
    lr = np.sin(phase) / S
    loaded = lr > 1e-12
    clr = np.where(loaded, stage.initial_clearance(phase), np.inf)
    return phase, lr, loaded, clr, stage.curvature_radius(phase)


def numpy_hu2020(stage, T_c, E, mu, theta):
    """Vectorised Newton on g(F) = r_c (F/δ(F)) Σ max(l_i δ − Δ_i, 0) l_i − T_c (eq 41–44)."""
    phase, lr, loaded, clr, rho_i = _geometry(stage, theta)
    A, B = compliance_constants(stage.rho0, stage.r, E, mu, stage.b, law="hu2020")
    lnB = math.log(B)
    r_c = stage.r_c
    lrp = np.where(loaded, lr, 0.0)

    def newton(F, lrp, clr):
        for _ in range(100):
            lnF = np.log(F)
            d = A * F * (2.0 / 3.0 + lnB - lnF)  # eq 38
            dd = A * (lnB - lnF - 1.0 / 3.0)  # dδ/dF
            e = lrp * d[:, None] - clr
            act = e > 0.0
            s = np.sum(np.where(act, e * lrp, 0.0), axis=1)
            s1 = np.sum(np.where(act, lrp * lrp, 0.0), axis=1)
            g = r_c * F / d * s - T_c
            dg = r_c * ((1.0 / d - F * dd / (d * d)) * s + F / d * s1 * dd)
            step = g / dg
            F_new = np.where(F - step > 0.0, F - step, 0.5 * F)
            if np.all(np.abs(F_new - F) <= RTOL * F_new):
                return F_new
            F = F_new
        raise RuntimeError("numpy Newton did not converge")

    # warm start: the first position from eq 45, every position from its solution
    F1 = newton(np.array([start_force(T_c, stage.K1, stage.z_c, stage.r_p)]), lrp[:1], clr[:1])
    F = newton(np.full(theta.shape, F1[0]), lrp, clr)
    k_sec = 1.0 / (A * (2.0 / 3.0 + lnB - np.log(F)))
    dmax = F / k_sec
    approach = lr * dmax[:, None]
    in_mesh = loaded & (approach > clr)
    force = np.where(in_mesh, (approach - clr) * k_sec[:, None], 0.0)
    pressure = max_contact_pressure(force, rho_i, stage.r, E, mu, stage.b)
    return F, force, pressure


def numpy_line_contact(stage, T_c, E, mu, theta):
    """Vectorised Newton on the disc rotation, inner Newton on ln F per pin (warm-started)."""
    phase, lr, loaded, clr, rho_i = _geometry(stage, theta)
    cap = stage.curvature_cap
    a0, a1 = log_law_coefficients("line_contact", rho_i, stage.r, E, mu, stage.b, rho_cap=cap)
    arm = np.where(loaded, lr * stage.r_c, 0.0)
    c = np.where(loaded, clr, 0.0)

    def forces(rot, u, arm, c, a0, a1):
        d = rot[:, None] * arm - c
        pos = (arm > 0.0) & (d > 0.0)
        dd = np.where(pos, d, 1.0)
        fresh = ~np.isfinite(u)
        u = np.where(fresh, np.log(dd) - np.log(a0), u)  # start where no warm value
        for _ in range(100):
            f = np.exp(u)
            g = a0 - a1 * u
            du = (f * g - dd) / (f * (g - a1))
            u = u - du
            if np.all(np.abs(np.where(pos, du, 0.0)) <= RTOL):
                break
        f = np.where(pos, np.exp(u), 0.0)
        kt = np.where(pos, 1.0 / (a0 - a1 * u - a1), 0.0)
        return f, kt, np.where(pos, u, np.nan)

    def newton(rot, arm, c, a0, a1):
        u = np.full(arm.shape, np.nan)
        for _ in range(100):
            f, kt, u = forces(rot, u, arm, c, a0, a1)
            t = np.sum(f * arm, axis=1)
            slope = np.sum(kt * arm * arm, axis=1)
            new = np.where(slope > 0.0, rot - (t - T_c) / np.where(slope > 0, slope, 1.0), 2 * rot)
            new = np.where(new > 0.0, new, 0.5 * rot)
            if np.all(np.abs(new - rot) <= RTOL * new):
                return new, forces(new, u, arm, c, a0, a1)[0]
            rot = new
        raise RuntimeError("numpy Newton did not converge")

    r1, _ = newton(np.array([1e-6]), arm[:1], c[:1], a0[:1], a1[:1])
    rot, f = newton(np.full(theta.shape, r1[0]), arm, c, a0, a1)
    dmax = stage.r_c * rot
    in_mesh = loaded & (lr * dmax[:, None] > clr)
    force = np.where(in_mesh, f, 0.0)
    pressure = max_contact_pressure(force, rho_i, stage.r, E, mu, stage.b)
    return rot, force, pressure


def main() -> None:
    np.seterr(all="ignore")  # the baselines' masked lanes overflow harmlessly
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--positions", type=int, default=1000, help="mesh positions over one pitch")
    ap.add_argument("--repeat", type=int, default=9, help="repeats of the fast runs (best)")
    args = ap.parse_args()
    stage = CycloidStage(z_p=40, r_p=76.0, r_rp=3.0, a=1.5, b=11.0, dr_rp=-0.022, dr_p=-0.0437)
    torque = 1011.5e3  # N·mm (fitted to Hu et al.'s Tables 4-5, examples/hu2020_rv80e_initial.toml)
    paper = dict(disc_share=0.55, E=2.06e5, mu=0.3)  # Hu et al. 2020 section 4
    T_c = paper["disc_share"] * torque
    theta = np.arange(args.positions) * (2 * np.pi / stage.z_p) / args.positions
    print(
        f"tooth contact, {args.positions} mesh positions over one pitch, z_p = {stage.z_p}, "
        f"Hu 2020 Table 3 stage; CPU times, best of {args.repeat}; load average "
        f"{', '.join(f'{x:.1f}' for x in os.getloadavg())}"
    )
    summary = []
    for law, strong in (("hu2020", numpy_hu2020), ("line_contact", numpy_line_contact)):

        def fast(law=law):
            return tooth_contact(stage, torque, **paper, mesh_angle=theta, contact_law=law)

        def plain(law=law):
            return tooth_contact(
                stage, torque, **paper, mesh_angle=theta, contact_law=law, implementation="plain"
            )

        t0 = time.process_time()
        res = fast()  # compile (or load the cache) and warm up
        t_first = time.process_time() - t0
        strong_out = strong(stage, T_c, paper["E"], paper["mu"], theta)
        t_fast = _cpu_best(fast, args.repeat)
        t_strong = _cpu_best(lambda s=strong: s(stage, T_c, paper["E"], paper["mu"], theta), 5)
        t_weak = _cpu_best(plain, 1)
        ref = plain()
        err = float(np.max(np.abs(res.F_max - ref.F_max) / ref.F_max))
        err_force = float(np.max(np.abs(res.force - strong_out[1])) / np.max(res.force))
        r_strong, r_weak = t_strong / t_fast, t_weak / t_fast
        print(f"\n[{law}]")
        rows = [
            ("first call (compile/cache load)", f"{t_first * 1e3:9.1f} ms CPU"),
            ("gearte (compiled kernel, warm)", f"{t_fast * 1e3:9.2f} ms CPU"),
            ("strong: numpy vectorised Newton", f"{t_strong * 1e3:9.2f} ms CPU -> {r_strong:.1f}x"),
            ("weak: gearte's plain twin", f"{t_weak * 1e3:9.1f} ms CPU -> {r_weak:.1f}x"),
            ("max rel. difference F_max vs twin", f"{err:9.2e}"),
            ("max difference pin forces vs numpy", f"{err_force:9.2e} (of the largest)"),
        ]
        for label, value in rows:
            print(f"  {label + ':':<36} {value}")
        print(
            f"  F_max over the pitch: {np.min(res.F_max):.1f} .. {np.max(res.F_max):.1f} N, "
            f"pins in mesh {res.pins_in_mesh.min()} .. {res.pins_in_mesh.max()}"
        )
        summary.append(
            f"{law}: goal >= {GOAL:.0f}x the numpy Newton: measured {r_strong:.1f}x — "
            f"{'met' if r_strong >= GOAL else 'NOT met'} (weak baseline: {r_weak:.0f}x)"
        )
    print()
    for line in summary:
        print(line)


if __name__ == "__main__":
    main()
