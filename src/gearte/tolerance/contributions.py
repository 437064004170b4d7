"""Which tolerance dominates: contributions of each contributor to the spread of a stack.

* Linear stacks: the exact **variance share** ``sᵢ²σᵢ² / Σ sⱼ²σⱼ²`` (sums to 1).
* Any stack: **first-order Sobol indices** ``Sᵢ = Var(E[y|xᵢ]) / Var(y)`` estimated by the
  Saltelli (2010) estimator, with the Jansen (1999) estimator of the total index ``STᵢ``. For a
  linear stack ``Sᵢ = STᵢ =`` variance share, which the tests use to check the estimator.
* :func:`pareto` sorts contributions and adds the cumulative share.

Relation to 3DCS (which produced Tables 3 and 7 of Jiang et al. 2024) is discussed in
``docs/validation/jiang2024.md``.

References
----------
Saltelli A. et al. (2010) Variance based sensitivity analysis of model output. Design and
estimator for the total sensitivity index. Computer Physics Communications 181, 259–270.
doi:10.1016/j.cpc.2009.09.018
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from gearte.errors import ParameterError
from gearte.tolerance.stackup import FunctionStack, LinearStack

__all__ = [
    "variance_shares",
    "group_shares",
    "SobolResult",
    "sobol_indices",
    "pareto",
]


def variance_shares(stack: LinearStack) -> dict[str, float]:
    """Variance share of each contributor of a linear stack (fractions summing to 1)."""
    var = stack.contributor_variances()
    total = sum(var.values())
    if total <= 0:
        raise ParameterError("stack", stack.name, "has zero variance: no contributions")
    return {k: v / total for k, v in var.items()}


def group_shares(
    shares: Mapping[str, float], stack: LinearStack | FunctionStack
) -> dict[str, float]:
    """Sum ``shares`` [-] (contributor name → share) of the contributors of ``stack`` sharing a
    ``group`` (ungrouped keep their own name)."""
    out: dict[str, float] = {}
    for c in stack.contributors:
        key = c.group or c.name
        out[key] = out.get(key, 0.0) + shares[c.name]
    return out


@dataclass
class SobolResult:
    """First-order and total Sobol indices with standard errors (fractions)."""

    first_order: dict[str, float]
    total: dict[str, float]
    first_order_se: dict[str, float]
    total_se: dict[str, float]
    n: int
    variance: float


def sobol_indices(
    stack: LinearStack | FunctionStack,
    n: int = 50_000,
    *,
    seed: int = 0,
    chunk_size: int = 50_000,
) -> SobolResult:
    """First-order (Saltelli 2010) and total (Jansen) Sobol indices by Monte-Carlo.

    Parameters
    ----------
    stack : LinearStack or FunctionStack
    n : int
        Base sample size; the cost is ``n·(k + 2)`` evaluations for ``k`` contributors.
    seed : int
    chunk_size : int
        Samples per chunk (memory ``~ 8·chunk_size·(k + 2)`` bytes).

    Notes
    -----
    With matrices ``A``, ``B`` of independent samples and ``A_B⁽ⁱ⁾`` = ``A`` with column ``i``
    from ``B``::

        Sᵢ  ≈ mean(f(B)·(f(A_B⁽ⁱ⁾) − f(A))) / V
        STᵢ ≈ mean((f(A) − f(A_B⁽ⁱ⁾))²) / (2V)

    with ``V`` the variance of ``f`` over ``A`` and ``B``. Standard errors are those of the
    sample means.
    """
    if n < 100:
        raise ParameterError("n", n, "Sobol estimation needs >= 100 base samples")
    names = stack.names
    k = len(names)
    seqs = np.random.SeedSequence(seed).spawn(math.ceil(n / chunk_size))
    # running sums: for Sᵢ terms and STᵢ terms, plus f moments
    s_sum = np.zeros(k)
    s_sq = np.zeros(k)
    t_sum = np.zeros(k)
    t_sq = np.zeros(k)
    f_sum = 0.0
    f_sq = 0.0
    f_shift: float | None = None
    done = 0
    for ss in seqs:
        m = min(chunk_size, n - done)
        rng = np.random.default_rng(ss)
        a = stack.sample_inputs(rng, m)
        b = stack.sample_inputs(rng, m)
        fa = stack.evaluate(a)
        fb = stack.evaluate(b)
        if f_shift is None:
            f_shift = float(np.mean(fa))
        for i, name in enumerate(names):
            ab = dict(a)
            ab[name] = b[name]
            fab = stack.evaluate(ab)
            s_term = (fb - f_shift) * (fab - fa)
            t_term = 0.5 * (fa - fab) ** 2
            s_sum[i] += s_term.sum()
            s_sq[i] += (s_term**2).sum()
            t_sum[i] += t_term.sum()
            t_sq[i] += (t_term**2).sum()
        both = np.concatenate([fa, fb]) - f_shift
        f_sum += both.sum()
        f_sq += (both**2).sum()
        done += m
    n_f = 2 * n
    var = (f_sq - f_sum**2 / n_f) / (n_f - 1)
    if not var > 0:
        raise ParameterError("stack", stack.name, "has zero variance: no Sobol indices")
    s_mean = s_sum / n
    t_mean = t_sum / n
    s_se = np.sqrt(np.maximum(s_sq / n - s_mean**2, 0.0) / n) / var
    t_se = np.sqrt(np.maximum(t_sq / n - t_mean**2, 0.0) / n) / var
    return SobolResult(
        first_order=dict(zip(names, (s_mean / var).tolist(), strict=True)),
        total=dict(zip(names, (t_mean / var).tolist(), strict=True)),
        first_order_se=dict(zip(names, s_se.tolist(), strict=True)),
        total_se=dict(zip(names, t_se.tolist(), strict=True)),
        n=n,
        variance=float(var),
    )


def pareto(shares: Mapping[str, float]) -> list[tuple[str, float, float]]:
    """``(name, share, cumulative share)`` of ``shares`` (name → share [-]), sorted by
    decreasing share."""
    items = sorted(shares.items(), key=lambda kv: kv[1], reverse=True)
    out = []
    cum = 0.0
    for name, s in items:
        cum += s
        out.append((name, float(s), float(cum)))
    return out
