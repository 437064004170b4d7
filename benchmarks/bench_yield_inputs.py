"""Benchmark: the per-sample CPU of the batched RV yield model before and after vectorising
the disc-modification term of ``batch_inputs``.

``han2023_rv110e_yield`` (its tolerance set: every error family drawn, the per-disc
equidistant and shifted modification errors among them) on one chunk of samples. The
modification errors enter each contact's clearance non-linearly
(:func:`gearte.geometry.cycloid.normal_clearance_unclosed`); ``batch_inputs`` evaluated that
term in a Python loop over the samples (kept here as ``batch_inputs_loop``, the code before,
with the clearance function as it was: the normal arm's term computed also at zero rotation);
it now broadcasts the samples against the (positions, pins) phases in one call, and the
clearance skips the arm's term where the rotation modification is 0. Printed: CPU
per sample of ``batch_inputs`` and of the whole model call (``batch_quantities``) with each,
best of ``--repeat`` (``time.thread_time``, one thread), their ratio, and the largest
difference of the clearances (round-off only).

    PYTHONPATH=src python benchmarks/bench_yield_inputs.py [--samples 250] [--repeat 5]
"""

from __future__ import annotations

import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
os.environ.setdefault("OMP_NUM_THREADS", "1")

import argparse  # noqa: E402
import time  # noqa: E402
from unittest import mock  # noqa: E402

import numpy as np  # noqa: E402


def normal_clearance_unclosed(phi, *, z_p, r_p, a, dr_rp=0.0, dr_p=0.0, rotation=0.0):
    """``gearte.geometry.cycloid.normal_clearance_unclosed`` as it was (the normal arm's term
    computed also at zero rotation)."""
    from gearte.geometry.cycloid import _S, _k1, normal_arm

    phi = np.asarray(phi, dtype=float)
    K1 = _k1(z_p, r_p, a, dr_p, "ground")
    S = _S(K1, phi)
    l_abs = np.abs(normal_arm(phi, z_p=z_p, a=a, K1=K1))
    return dr_rp - dr_p * (1.0 - K1 * np.cos(phi)) / S + l_abs * rotation


def batch_inputs_loop(model, p, errors, n):
    """``rv_yield_batch.batch_inputs`` as it was: the modification term per sample."""
    from gearte.runners.rv_yield_batch import component_matrix

    X = component_matrix(p, errors, n)
    G, nd = p.h0.shape
    h = p.h0[None] + (X @ p.h_map).reshape(n, G, nd)
    en = p.en0[None] + (X @ p.en_map).reshape((n,) + p.en0.shape)
    gap = p.gap0[None] + (X @ p.gap_map).reshape((n,) + p.gap0.shape)
    red = model.reducer
    zp = red.pins.count
    for j, ((ke, ks), (b_rp, b_p)) in enumerate(p.modification):
        if ke is None and ks is None:
            continue
        d_rp = np.full(n, b_rp) if ke is None else np.asarray(errors[ke], dtype=float) * 1e-3
        d_p = np.full(n, b_p) if ks is None else np.asarray(errors[ks], dtype=float) * 1e-3
        phi = p.phase[:, j * zp : (j + 1) * zp]
        kw = {"z_p": zp, "r_p": red.pins.circle_radius, "a": red.cranks.eccentricity}
        nominal = normal_clearance_unclosed(
            phi,
            dr_rp=red.discs.equidistant_modification + b_rp,
            dr_p=red.discs.shift_modification + b_p,
            **kw,
        )
        for s in range(n):
            new = normal_clearance_unclosed(
                phi,
                dr_rp=red.discs.equidistant_modification + d_rp[s],
                dr_p=red.discs.shift_modification + d_p[s],
                **kw,
            )
            gap[s, :, j * zp : (j + 1) * zp] += new - nominal
    return h, en, gap


def _best(f, repeat: int) -> float:
    best = float("inf")
    for _ in range(repeat):
        t = time.thread_time()
        f()
        best = min(best, time.thread_time() - t)
    return best


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--samples", type=int, default=250)
    ap.add_argument("--repeat", type=int, default=5)
    args = ap.parse_args()
    from gearte.io.case_file import load_case
    from gearte.runners import rv_yield_batch as rb
    from gearte.studies import rv_reducer as rv
    from gearte.studies._yield import yield_inputs

    case = load_case("han2023_rv110e_yield")
    red = rv.build_reducer(case.reducer)
    sec = case.analyses.yield_
    model, _ = rv._yield_model(case, red, sec)
    families, defaults, units = rv._yield_keys(case, red, sec)
    ts, _ = yield_inputs(sec, units, {}, defaults, families, rv._grade_um(case))
    n = args.samples
    errs = ts.sample(np.random.default_rng(1), n)
    p = rb.cached_plan(model, list(errs))
    model(errs)  # compile / load the kernels, build the plan
    old = batch_inputs_loop(model, p, errs, n)
    new = rb.batch_inputs(model, p, errs, n)
    diff = max(float(np.max(np.abs(a - b), initial=0.0)) for a, b in zip(old, new, strict=True))
    t_old = _best(lambda: batch_inputs_loop(model, p, errs, n), args.repeat)
    t_new = _best(lambda: rb.batch_inputs(model, p, errs, n), args.repeat)
    m_new = _best(lambda: model(errs), args.repeat)
    with mock.patch.object(rb, "batch_inputs", batch_inputs_loop):
        m_old = _best(lambda: model(errs), args.repeat)
    us = 1e6 / n
    print(f"han2023_rv110e_yield, {n} samples, {len(ts.tolerances)} tolerances, best of "
          f"{args.repeat} (CPU, one thread); clearances differ by {diff:.1e} mm")  # fmt: skip
    print(f"batch_inputs:      loop {t_old * us:8.1f} µs/sample   vectorised {t_new * us:8.1f} "
          f"µs/sample   ratio {t_old / t_new:5.1f}x")  # fmt: skip
    print(f"model per sample:  before {m_old * us:8.1f} µs   after {m_new * us:8.1f} µs   "
          f"ratio {m_old / m_new:5.2f}x (inputs were {t_old / m_old:.0%} of it, now "
          f"{t_new / m_new:.0%})")  # fmt: skip


if __name__ == "__main__":
    main()
