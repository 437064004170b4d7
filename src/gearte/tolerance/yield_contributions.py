"""Which tolerance drives the spread when the physics is non-linear: Sobol indices per
tolerance with bootstrap confidence intervals, beside the linear (sensitivity × σ) prediction.

For a model of the drawn errors (:mod:`gearte.tolerance.yield_mc`), each *tolerance* is one
input factor — a radial error's magnitude and phase move together. With two independent
sample matrices ``A``, ``B`` (standard normals and phases) and ``A_B⁽ⁱ⁾`` = ``A`` with the
columns of tolerance ``i`` from ``B``::

    Sᵢ  ≈ mean(f(B)·(f(A_B⁽ⁱ⁾) − f(A))) / V           (Saltelli et al. 2010, Table 2 (b))
    STᵢ ≈ mean((f(A) − f(A_B⁽ⁱ⁾))²) / (2V)             (Jansen 1999; Saltelli 2010 (f))

``V`` is the variance of ``f`` over ``A`` and ``B``. Confidence intervals: percentile
bootstrap over the rows (the same resampled rows for every index). The linear prediction is
the first-order (delta-method) variance ``Σ (∂f/∂xᵢ)² σᵢ²`` from central differences at the
nominal drive; a radial error with a uniform phase counts ``(g_x² + g_y²)·E[r²]/2``. Where
``Sᵢ`` and the linear share disagree, the physics is non-linear there (clearances, contact
loss, the |·| of an amplitude).

References
----------
Saltelli A., Annoni P., Azzini I., Campolongo F., Ratto M., Tarantola S. (2010) Variance based
sensitivity analysis of model output. Design and estimator for the total sensitivity index.
Computer Physics Communications 181, 259–270. doi:10.1016/j.cpc.2009.09.018
Jansen M. J. W. (1999) Analysis of variance designs for model output. Computer Physics
Communications 117, 35–43. doi:10.1016/S0010-4655(98)00154-4
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from gearte.errors import ParameterError
from gearte.execution import map_chunks, seeded_chunks
from gearte.tolerance.yield_mc import Model, ToleranceSet, evaluate_checked

__all__ = [
    "SobolIndices",
    "sobol_tolerances",
    "linear_prediction",
    "LinearPrediction",
    "pareto_rows",
]


@dataclass
class SobolIndices:
    """Sobol indices of one quantity per tolerance (fractions of its variance) with
    bootstrap confidence intervals ``(low, high)``."""

    quantity: str
    first: dict[str, float]
    total: dict[str, float]
    first_ci: dict[str, tuple[float, float]]
    total_ci: dict[str, tuple[float, float]]
    variance: float
    n: int


@dataclass(frozen=True)
class _SobolShared:
    model: Any
    tolset: ToleranceSet
    quantities: tuple[str, ...]


def _sobol_chunk(chunk: Any, shared: _SobolShared) -> dict[str, np.ndarray]:
    """f(A), f(B), f(A_B⁽ⁱ⁾) of one chunk: ``{quantity: (k + 2, m)}``."""
    rng = chunk.rng()
    ts = shared.tolset
    m = chunk.size
    za, pa = ts.draw_standard(rng, m)
    zb, pb = ts.draw_standard(rng, m)
    fams = list(ts.families.values())
    k = len(fams)
    # stack the k + 2 matrices and call the model once; factor i = every column of family i
    z = np.concatenate([za, zb] + [za] * k)
    p = np.concatenate([pa, pb] + [pa] * k)
    for i, cols in enumerate(fams):
        rows = slice((2 + i) * m, (3 + i) * m)
        z[rows, cols] = zb[:, cols]
        p[rows, cols] = pb[:, cols]
    out = evaluate_checked(shared.model, ts.values(z, p), (k + 2) * m)
    return {q: out[q].reshape(k + 2, m) for q in shared.quantities}


def _indices(f: np.ndarray, rows: np.ndarray | slice) -> tuple[np.ndarray, np.ndarray, float]:
    fa, fb, fab = f[0, rows], f[1, rows], f[2:, rows]
    both = np.concatenate([fa, fb])
    var = float(np.var(both, ddof=1))
    if not var > 0:
        return np.zeros(f.shape[0] - 2), np.zeros(f.shape[0] - 2), 0.0
    # f_B centred on the pooled mean: the same expectation (E[f_AB − f_A] = 0), far less
    # estimator noise when the quantity's mean is large against its σ (Saltelli 2010, §3)
    s = np.mean((fb - np.mean(both)) * (fab - fa), axis=1) / var
    st = 0.5 * np.mean((fa - fab) ** 2, axis=1) / var
    return s, st, var


def sobol_tolerances(
    model: Model,
    tolerances: ToleranceSet,
    quantities: Sequence[str],
    n: int = 4_000,
    *,
    seed: int | None = 0,
    bootstrap: int = 200,
    confidence: float = 0.95,
    chunk_size: int = 1_000,
    options: Any = None,
    progress: bool | None = False,
) -> dict[str, SobolIndices]:
    """First-order and total Sobol indices of each quantity per tolerance.

    Parameters
    ----------
    model : callable
        As :func:`gearte.tolerance.yield_mc.run_yield`.
    tolerances : ToleranceSet
    quantities : sequence of str
        Model outputs to analyse.
    n : int
        Base samples; the model runs ``n·(k + 2)`` times for ``k`` tolerances.
    seed : int
    bootstrap : int
        Bootstrap resamples for the confidence intervals (0: none, intervals collapse).
    confidence : float
        Level of the intervals [-].
    chunk_size : int
        Base samples per chunk (memory ∝ ``chunk_size·(k + 2)``).
    options : RunOptions, optional
        Workers and scheduler.
    progress : bool, optional
        Progress bar.

    Returns
    -------
    dict
        ``{quantity: SobolIndices}`` keyed by tolerance family (a key that has no family is
        its own). A quantity with zero variance gets zeros.
    """
    if n < 50:
        raise ParameterError("n", n, "Sobol estimation needs >= 50 base samples")
    if bootstrap < 0:
        raise ParameterError("bootstrap", bootstrap, "must be >= 0")
    quantities = tuple(quantities)
    shared = _SobolShared(model, tolerances, quantities)
    parts = map_chunks(
        _sobol_chunk,
        seeded_chunks(int(n), int(chunk_size), seed),
        shared=shared,
        options=options,
        progress=progress,
        description=f"Sobol indices ({n} base samples)",
        unit="base samples",
    )
    keys = list(tolerances.families)
    # bootstrap stream: its own child of the seed, so the intervals are reproducible too
    rng = np.random.default_rng(None if seed is None else [int(seed), 7919])
    a = (1.0 - confidence) / 2.0
    boots = [rng.integers(0, n, n) for _ in range(bootstrap)]
    res: dict[str, SobolIndices] = {}
    for q in quantities:
        f = np.concatenate([p[q] for p in parts], axis=1)
        s, st, var = _indices(f, slice(None))
        if bootstrap and var > 0:
            bs = np.array([_indices(f, b)[0] for b in boots])
            bt = np.array([_indices(f, b)[1] for b in boots])
            s_lo, s_hi = np.quantile(bs, [a, 1 - a], axis=0)
            t_lo, t_hi = np.quantile(bt, [a, 1 - a], axis=0)
        else:
            s_lo = s_hi = s
            t_lo = t_hi = st
        res[q] = SobolIndices(
            quantity=q,
            first=dict(zip(keys, s.tolist(), strict=True)),
            total=dict(zip(keys, st.tolist(), strict=True)),
            first_ci={k: (float(s_lo[i]), float(s_hi[i])) for i, k in enumerate(keys)},
            total_ci={k: (float(t_lo[i]), float(t_hi[i])) for i, k in enumerate(keys)},
            variance=var,
            n=int(n),
        )
    return res


@dataclass
class LinearPrediction:
    """First-order prediction of one quantity: nominal value, σ and the variance share of
    each tolerance family (fractions); ``sensitivity`` ∂f/∂x per tolerance key [quantity unit /
    error unit] (a radial error with phase: the gradient's length ``√(g_x² + g_y²)``)."""

    quantity: str
    nominal: float
    sd: float
    share: dict[str, float]
    sensitivity: dict[str, float]


def linear_prediction(
    model: Model,
    tolerances: ToleranceSet,
    quantities: Sequence[str],
    *,
    step: float = 1e-3,
) -> dict[str, LinearPrediction]:
    """Sensitivity × σ prediction of each quantity's spread at the nominal drive.

    Central differences with step ``step × tolerance`` (tolerances of width 0 contribute
    nothing); every perturbed drive is evaluated in one vectorised model call.

    Parameters
    ----------
    model, tolerances
        As :func:`sobol_tolerances`.
    quantities : sequence of str
        Model outputs to predict.
    step : float
        Relative finite-difference step [-] (fraction of each tolerance).
    """
    ts = tolerances
    rows: list[dict[str, float]] = []
    nom = {k: float(v[0]) for k, v in ts.nominal_values(1).items()}
    plan: list[tuple[str, str, float]] = []  # (key, "lin"|"radial", h)
    for t in ts.tolerances:
        if t.tolerance == 0 or t.kind == "constant":
            continue
        h = step * float(t.tolerance)
        if t.phase:
            ph = f"{t.key}_phase_rad"
            for ang in (0.0, math.pi, 0.5 * math.pi, 1.5 * math.pi):
                rows.append({**nom, t.key: float(t.nominal) + h, ph: ang})
            plan.append((t.key, "radial", h))
        else:
            rows.append({**nom, t.key: float(t.nominal) + h})
            rows.append({**nom, t.key: float(t.nominal) - h})
            plan.append((t.key, "lin", h))
    rows.insert(0, dict(nom))
    cols = {c: np.array([r[c] for r in rows]) for c in nom}
    out = evaluate_checked(model, cols, len(rows))
    res: dict[str, LinearPrediction] = {}
    for q in quantities:
        y = out[q]
        var: dict[str, float] = {}
        sens: dict[str, float] = {}
        i = 1
        for key, how, h in plan:
            t = ts[key]
            if how == "radial":
                gx = (y[i] - y[i + 1]) / (2 * h)
                gy = (y[i + 2] - y[i + 3]) / (2 * h)
                g2 = gx * gx + gy * gy
                var[key] = g2 * t.second_moment_radial / 2.0
                sens[key] = math.sqrt(g2)
                i += 4
            else:
                g = (y[i] - y[i + 1]) / (2 * h)
                var[key] = g * g * t.sd**2
                sens[key] = float(g)
                i += 2
        tot = sum(var.values())
        fam_var: dict[str, float] = {}
        for t in ts.tolerances:
            fam_var[t.family_name] = fam_var.get(t.family_name, 0.0) + var.get(t.key, 0.0)
        res[q] = LinearPrediction(
            quantity=q,
            nominal=float(y[0]),
            sd=math.sqrt(tot),
            share={k: (v / tot if tot > 0 else 0.0) for k, v in fam_var.items()},
            sensitivity=sens,
        )
    return res


def pareto_rows(
    sobol: SobolIndices, linear: LinearPrediction | None = None
) -> list[dict[str, Any]]:
    """Rows of a contribution Pareto sorted by total index: name, S, ST, CIs, cumulative ST
    share and the linear share beside them.

    Parameters
    ----------
    sobol : SobolIndices
    linear : LinearPrediction, optional
    """
    tot = sum(max(v, 0.0) for v in sobol.total.values()) or 1.0
    rows = []
    cum = 0.0
    for k in sorted(sobol.total, key=lambda k: sobol.total[k], reverse=True):
        cum += max(sobol.total[k], 0.0) / tot
        rows.append(
            {
                "tolerance": k,
                "sobol_first": sobol.first[k],
                "sobol_first_ci": sobol.first_ci[k],
                "sobol_total": sobol.total[k],
                "sobol_total_ci": sobol.total_ci[k],
                "cumulative_total_share": cum,
                "linear_share": None if linear is None else linear.share.get(k, 0.0),
            }
        )
    return rows
