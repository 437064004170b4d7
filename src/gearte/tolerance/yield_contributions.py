"""Which tolerance drives the spread when the physics is non-linear: Sobol indices per
independent factor with bootstrap confidence intervals, beside the linear share of each factor.

Factors
-------
For a model of the drawn errors (:mod:`gearte.tolerance.yield_mc`), each *factor* is a set of
tolerances drawn independently of every other factor: a tolerance family (a radial error's
magnitude and phase move together; every pin of a pin list), and the families a correlated
group joins taken together (:meth:`~gearte.tolerance.yield_mc.ToleranceSet.factors`). These are
*grouped* Sobol indices (Jacques et al. 2006; Saltelli et al. 2008 §4.7): with the factors
independent, the Hoeffding–Sobol decomposition holds, first-order indices sum to ≤ 1 and
``A_B⁽ⁱ⁾`` (``A`` with factor ``i``'s columns from ``B``) is a draw of the real joint law — none
of which is true when a correlated group is split between two factors. Per-member indices of
correlated inputs (Kucherenko et al. 2012) would need a conditional sampler per member and are
not additive; a group is what a tolerance engineer changes as one (one grinding batch, one
fixture), so it is one factor here.

Estimators
----------
With two independent sample matrices ``A``, ``B`` and ``V`` the variance of ``f`` over both::

    Sᵢ  ≈ mean((f(B) − f̄)·(f(A_B⁽ⁱ⁾) − f(A))) / V       (Saltelli et al. 2010, Table 2 (b),
                                                         f(B) centred on the pooled mean f̄)
    STᵢ ≈ mean((f(A) − f(A_B⁽ⁱ⁾))²) / (2V)               (Jansen 1999; Saltelli 2010 (f))

The model runs ``n·(k + 2)`` times for ``k`` factors. ``A | B`` are the two halves of one
Owen-scrambled Sobol' point set of dimension ``2 d`` (``d`` the uniforms of one drawn drive,
:meth:`~gearte.tolerance.yield_mc.ToleranceSet.standard_from_uniform`), from
:class:`scipy.stats.qmc.Sobol` (default ``sampling="qmc"``; ``"mc"``: pseudo-random streams as
before). The point set is global: base sample ``j`` is point ``j`` of the sequence whatever the
chunk it falls in, so the indices are the same bits for any chunk size, thread, process or Dask
worker. Confidence intervals: percentile bootstrap over the base samples (the same resampled
rows for every index). For a scrambled point set the rows are not independent and the
bootstrap interval is that of plain Monte-Carlo at the same ``n`` — conservative (Owen 1997:
the scrambled-net variance is never above ~2.7× and, for smooth integrands, far below the
Monte-Carlo one). An index whose interval is wider than ``max_ci_width`` is named in
``SobolIndices.warnings``.

Linear share
------------
Beside the indices: the variance share of each factor in the least-squares linear fit of ``f``
to the drawn errors over all ``n·(k + 2)`` model runs (the columns: each error's value, a radial
error with a phase as its two components ``r cos φ``, ``r sin φ``). The linear part of ``f`` in
factor ``i``'s errors is a projection of ``E[f | xᵢ]``, so ``linear_shareᵢ ≤ Sᵢ`` (up to
sampling error), equal where ``E[f | xᵢ]`` is linear; ``Sᵢ − linear_shareᵢ`` is what is
non-linear in factor ``i`` alone, ``STᵢ − Sᵢ`` its interactions, ``linear_r2`` the share of the
variance any linear model explains. The first-order (delta-method) prediction at the nominal
drive (:func:`linear_prediction`) is kept for small tolerances about a smooth nominal; at a kink
of the model at the nominal (a peak-to-peak TE, a lost motion with pins at zero clearance) its
gradient is zero or meaningless and it predicts nothing.

References
----------
Saltelli A., Annoni P., Azzini I., Campolongo F., Ratto M., Tarantola S. (2010) Variance based
sensitivity analysis of model output. Design and estimator for the total sensitivity index.
Computer Physics Communications 181, 259–270. doi:10.1016/j.cpc.2009.09.018
Jansen M. J. W. (1999) Analysis of variance designs for model output. Computer Physics
Communications 117, 35–43. doi:10.1016/S0010-4655(98)00154-4
Jacques J., Lavergne C., Devictor N. (2006) Sensitivity analysis in presence of model
uncertainty and correlated inputs. Reliability Engineering & System Safety 91, 1126–1134.
doi:10.1016/j.ress.2005.11.047
Kucherenko S., Tarantola S., Annoni P. (2012) Estimation of global sensitivity indices for
models with dependent variables. Computer Physics Communications 183, 937–946.
doi:10.1016/j.cpc.2011.12.020
Owen A. B. (1997) Scrambled net variance for integrals of smooth functions. Annals of
Statistics 25, 1541–1562. doi:10.1214/aos/1069362388
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from gearte.errors import ParameterError
from gearte.execution import map_chunks, seeded_chunks
from gearte.tolerance.yield_mc import Model, ToleranceSet, evaluate_checked

__all__ = [
    "SobolIndices",
    "sobol_tolerances",
    "sobol_estimates",
    "linear_prediction",
    "LinearPrediction",
    "pareto_rows",
    "SAMPLINGS",
]

#: Samplers of :func:`sobol_tolerances`.
SAMPLINGS = ("qmc", "mc")


@dataclass
class SobolIndices:
    """Sobol indices of one quantity per independent factor (fractions of its variance) with
    bootstrap confidence intervals ``(low, high)``, and the linear share of each factor.

    ``factors``: factor → its tolerance families; ``linear_share``: each factor's variance share
    in the least-squares linear fit, ``linear_r2`` the fit's R²; ``non_finite``: base samples
    left out because one of their ``k + 2`` model runs gave a non-finite value (counted, named in
    ``warnings``); ``warnings``: indices whose interval is wider than the run's
    ``max_ci_width``, and non-finite samples.
    """

    quantity: str
    first: dict[str, float]
    total: dict[str, float]
    first_ci: dict[str, tuple[float, float]]
    total_ci: dict[str, tuple[float, float]]
    variance: float
    n: int
    factors: dict[str, list[str]] = field(default_factory=dict)
    sampling: str = "qmc"
    linear_share: dict[str, float] = field(default_factory=dict)
    linear_r2: float = math.nan
    non_finite: int = 0
    max_ci_width: float = 0.1
    warnings: list[str] = field(default_factory=list)


@dataclass(frozen=True)
class _SobolShared:
    model: Any
    tolset: ToleranceSet
    quantities: tuple[str, ...]
    factor_cols: tuple[tuple[int, ...], ...]
    sampling: str
    entropy: int
    chunk_size: int


def _uniform_halves(shared: _SobolShared, start: int, m: int) -> tuple[np.ndarray, np.ndarray]:
    """Points ``start … start + m`` of the run's scrambled Sobol' set, split into A and B."""
    from scipy.stats import qmc

    d = shared.tolset.uniform_dimension
    eng = qmc.Sobol(2 * d, scramble=True, seed=np.random.default_rng([shared.entropy, 7907]))
    if start:
        eng.fast_forward(start)
    with warnings.catch_warnings():  # balance needs powers of 2; any n is still a valid estimate
        warnings.simplefilter("ignore", UserWarning)
        u = eng.random(m)
    return u[:, :d], u[:, d:]


def _features(ts: ToleranceSet, values: dict[str, np.ndarray]) -> np.ndarray:
    """Columns of the linear fit, scaled by each error's spread (mean ≈ 0, σ ≈ 1): a value, or
    a radial error with a phase as ``r cos φ``, ``r sin φ``; a tolerance of width 0 none."""
    cols = []
    for t in ts.tolerances:
        if t.kind == "constant" or t.tolerance == 0:
            continue
        x = values[t.key]
        if t.phase:
            s = math.sqrt(0.5 * t.second_moment_radial) or 1.0
            ph = values[f"{t.key}_phase_rad"]
            cols += [x * np.cos(ph) / s, x * np.sin(ph) / s]
        else:
            cols.append((x - float(t.nominal)) / (t.sd or 1.0))
    return np.stack(cols, axis=1) if cols else np.zeros((len(next(iter(values.values()))), 0))


def _feature_factor(ts: ToleranceSet, factors: dict[str, list[str]]) -> list[str]:
    """The factor of each column of :func:`_features`."""
    fam_factor = {f: name for name, fams in factors.items() for f in fams}
    out = []
    for t in ts.tolerances:
        if t.kind == "constant" or t.tolerance == 0:
            continue
        out += [fam_factor[t.family_name]] * (2 if t.phase else 1)
    return out


def _sobol_chunk(chunk: Any, shared: _SobolShared) -> dict[str, Any]:
    """f(A), f(B), f(A_B⁽ⁱ⁾) of one chunk: ``{quantity: (k + 2, m)}``, and the sums of the
    linear fit (``"_fit"``)."""
    ts = shared.tolset
    m = chunk.size
    if shared.sampling == "qmc":
        ua, ub = _uniform_halves(shared, chunk.index * shared.chunk_size, m)
        za, pa = ts.standard_from_uniform(ua)
        zb, pb = ts.standard_from_uniform(ub)
    else:
        rng = chunk.rng()
        za, pa = ts.draw_standard(rng, m)
        zb, pb = ts.draw_standard(rng, m)
    k = len(shared.factor_cols)
    # stack the k + 2 matrices and call the model once; factor i = every column of its families
    z = np.concatenate([za, zb] + [za] * k)
    p = np.concatenate([pa, pb] + [pa] * k)
    for i, cols in enumerate(shared.factor_cols):
        rows = slice((2 + i) * m, (3 + i) * m)
        z[rows, list(cols)] = zb[:, list(cols)]
        p[rows, list(cols)] = pb[:, list(cols)]
    values = ts.values(z, p)
    out = evaluate_checked(shared.model, values, (k + 2) * m)
    res: dict[str, Any] = {q: out[q].reshape(k + 2, m) for q in shared.quantities}
    # sums of the linear fit over every run with finite outputs
    X = _features(ts, values)
    Y = np.stack([out[q] for q in shared.quantities], axis=1)
    ok = np.all(np.isfinite(Y), axis=1)
    X, Y = X[ok], Y[ok]
    res["_fit"] = (int(ok.sum()), X.sum(0), X.T @ X, X.T @ Y, Y.sum(0), (Y * Y).sum(0))
    return res


def sobol_estimates(
    f: np.ndarray, rows: np.ndarray | slice = slice(None)
) -> tuple[np.ndarray, np.ndarray, float]:
    """First-order and total indices of every factor from the model runs ``f``.

    Parameters
    ----------
    f : numpy.ndarray
        ``(k + 2, n)`` model outputs [unit of the quantity]: rows ``f(A)``, ``f(B)``,
        ``f(A_B⁽ⁱ⁾)``.
    rows : numpy.ndarray or slice
        Base samples to use (a bootstrap resample) [-].

    Returns
    -------
    (numpy.ndarray, numpy.ndarray, float)
        ``(S, ST, V)`` [-, -, unit²]: zeros when the variance ``V`` is 0.
    """
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


def _adjusted(r2: float, n: int, p: int) -> float:
    """R² adjusted for ``p`` fitted slopes on ``n`` distinct points, floored at 0."""
    if n - p - 1 <= 0:
        return 0.0
    return max(0.0, 1.0 - (1.0 - r2) * (n - 1) / (n - p - 1))


def _linear_shares(fit: tuple, j: int, owner: list[str], keys: list[str], n_base: int):
    """Each factor's share of the variance in the least-squares linear fit of the quantity on
    that factor's errors alone, and their sum (the R² of the linear fit on all errors).

    A factor's errors take ``2 n`` distinct values over the runs (those of ``A`` and ``B``), so
    its R² is adjusted for its slopes on ``2 n`` points (and floored at 0)."""
    cnt, sx, sxx, sxy, sy, syy = fit
    if cnt < 2 or sx.size == 0:
        return {k: 0.0 for k in keys}, math.nan
    mx = sx / cnt
    C = sxx / cnt - np.outer(mx, mx)
    c = sxy[:, j] / cnt - mx * (sy[j] / cnt)
    vy = syy[j] / cnt - (sy[j] / cnt) ** 2
    if not vy > 0:
        return {k: 0.0 for k in keys}, math.nan
    share = {}
    own = np.array(owner)
    for k in keys:
        m = own == k
        if not m.any():
            share[k] = 0.0
            continue
        b = np.linalg.lstsq(C[np.ix_(m, m)], c[m], rcond=1e-12)[0]
        share[k] = _adjusted(float(b @ c[m] / vy), 2 * n_base, int(m.sum()))
    # independent factors: the linear fit on all errors is the sum of the factors' own fits,
    # its R² the sum of their shares (a joint fit's R² is inflated by its many slopes)
    return share, float(sum(share.values()))


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
    sampling: str = "qmc",
    max_ci_width: float = 0.1,
) -> dict[str, SobolIndices]:
    """First-order and total Sobol indices of each quantity per independent factor.

    Parameters
    ----------
    model : callable
        As :func:`gearte.tolerance.yield_mc.run_yield`.
    tolerances : ToleranceSet
    quantities : sequence of str
        Model outputs to analyse.
    n : int
        Base samples; the model runs ``n·(k + 2)`` times for ``k`` factors. With
        ``sampling="qmc"`` a power of 2 keeps the Sobol' set balanced.
    seed : int
        Seed of the scrambling (``"qmc"``) or of the chunk streams (``"mc"``), and of the
        bootstrap.
    bootstrap : int
        Bootstrap resamples for the confidence intervals (0: none, intervals collapse).
    confidence : float
        Level of the intervals [-].
    chunk_size : int
        Base samples per chunk (memory ∝ ``chunk_size·(k + 2)``; with ``"qmc"`` the result
        does not depend on it).
    options : RunOptions, optional
        Workers and scheduler.
    progress : bool, optional
        Progress bar.
    sampling : {"qmc", "mc"}
        Owen-scrambled Sobol' points (default) or pseudo-random streams.
    max_ci_width : float
        An index whose interval is wider than this [-] is named in ``warnings``.

    Returns
    -------
    dict
        ``{quantity: SobolIndices}`` keyed by factor (:meth:`ToleranceSet.factors`: a family,
        or the families a correlated group joins). A quantity with zero variance gets zeros.

    Examples
    --------
    >>> from gearte.tolerance.yield_mc import Tolerance, ToleranceSet
    >>> ts = ToleranceSet((Tolerance("a", "normal", 3.0), Tolerance("b", "normal", 6.0)))
    >>> r = sobol_tolerances(lambda e: {"y": e["a"] + e["b"]}, ts, ["y"], 1024)["y"]
    >>> round(r.first["b"], 2), round(r.total["a"], 2)
    (0.8, 0.2)
    """
    if n < 50:
        raise ParameterError("n", n, "Sobol estimation needs >= 50 base samples")
    if bootstrap < 0:
        raise ParameterError("bootstrap", bootstrap, "must be >= 0")
    if sampling not in SAMPLINGS:
        raise ParameterError("sampling", sampling, f"must be one of {SAMPLINGS}")
    if not max_ci_width > 0:
        raise ParameterError("max_ci_width", max_ci_width, "must be > 0")
    quantities = tuple(quantities)
    factors = tolerances.factors()
    fam_idx = tolerances.families
    factor_cols = tuple(
        tuple(sorted(i for f in fams for i in fam_idx[f])) for fams in factors.values()
    )
    entropy = int(np.random.SeedSequence(seed).entropy)  # type: ignore[arg-type]
    shared = _SobolShared(
        model, tolerances, quantities, factor_cols, sampling, entropy, int(chunk_size)
    )
    parts = map_chunks(
        _sobol_chunk,
        seeded_chunks(int(n), int(chunk_size), seed),
        shared=shared,
        options=options,
        progress=progress,
        description=f"Sobol indices ({n} base samples)",
        unit="base samples",
    )
    keys = list(factors)
    fit = _sum_fits([p["_fit"] for p in parts])
    owner = _feature_factor(tolerances, factors)
    # bootstrap stream: its own child of the seed, so the intervals are reproducible too
    rng = np.random.default_rng([entropy, 7919])
    a = (1.0 - confidence) / 2.0
    res: dict[str, SobolIndices] = {}
    for j, q in enumerate(quantities):
        f = np.concatenate([p[q] for p in parts], axis=1)
        finite = np.all(np.isfinite(f), axis=0)
        bad = int(f.shape[1] - finite.sum())
        f = f[:, finite]
        m = f.shape[1]
        notes: list[str] = []
        if bad:
            notes.append(
                f"Sobol indices of {q}: {bad} of {n} base samples left out (a non-finite value "
                "in one of their model runs)"
            )
        if m >= 2:
            s, st, var = sobol_estimates(f)
        else:
            s, st, var = np.zeros(len(keys)), np.zeros(len(keys)), 0.0
        if bootstrap and var > 0:
            boots = rng.integers(0, m, size=(bootstrap, m))
            est = [sobol_estimates(f, b) for b in boots]
            bs = np.array([e[0] for e in est])
            bt = np.array([e[1] for e in est])
            s_lo, s_hi = np.quantile(bs, [a, 1 - a], axis=0)
            t_lo, t_hi = np.quantile(bt, [a, 1 - a], axis=0)
            wide = [
                (k, which, hi - lo)
                for i, k in enumerate(keys)
                for which, lo, hi in (("S", s_lo[i], s_hi[i]), ("ST", t_lo[i], t_hi[i]))
                if hi - lo > max_ci_width
            ]
            if wide:
                worst = max(wide, key=lambda w: w[2])
                notes.append(
                    f"Sobol indices of {q} not converged at {n} base samples: {len(wide)} "
                    f"{confidence:.0%} interval(s) wider than {max_ci_width:g} (widest: "
                    f"{worst[1]} of {worst[0]!r}, {worst[2]:.2f}); give more Sobol samples "
                    "(the width falls as 1/√n)"
                )
        else:
            s_lo = s_hi = s
            t_lo = t_hi = st
        lin, r2 = _linear_shares(fit, j, owner, keys, int(finite.sum()))
        res[q] = SobolIndices(
            quantity=q,
            first=dict(zip(keys, s.tolist(), strict=True)),
            total=dict(zip(keys, st.tolist(), strict=True)),
            first_ci={k: (float(s_lo[i]), float(s_hi[i])) for i, k in enumerate(keys)},
            total_ci={k: (float(t_lo[i]), float(t_hi[i])) for i, k in enumerate(keys)},
            variance=var,
            n=int(n),
            factors=factors,
            sampling=sampling,
            linear_share=lin,
            linear_r2=r2,
            non_finite=bad,
            max_ci_width=float(max_ci_width),
            warnings=notes,
        )
    return res


def _sum_fits(fits: list[tuple]) -> tuple:
    """The chunks' sums of the linear fit, added in chunk order (the same bits on any
    backend)."""
    acc = list(fits[0])
    for f in fits[1:]:
        acc = [x + y for x, y in zip(acc, f, strict=True)]
    return tuple(acc)


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
        A delta-method prediction whose shares to show; default: the indices' own linear share
        (the least-squares fit over the Sobol runs).
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
                "linear_share": (
                    sobol.linear_share.get(k, 0.0) if linear is None else linear.share.get(k, 0.0)
                ),
            }
        )
    return rows
