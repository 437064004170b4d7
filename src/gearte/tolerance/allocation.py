"""Tolerance allocation: the cheapest tolerance set that reaches a target yield.

Each tolerance has a cost, either a model ``cost = a + b / t^k`` (``t`` the tolerance width)
or a table of levels and prices (e.g. accuracy grades and what a supplier charges). The
search works on a ladder of widths per tolerance (the table's levels, or for a cost model the
ISO grade ladder ``t₀·(√2)^j`` around the given width) and compares tolerance sets on the
*same* drawn parts (common random numbers, :meth:`ToleranceSet.values` at other widths), so
a yield difference between two sets is the tolerances' doing, not sampling noise.

Search (greedy, then a local-optimality pass):

1. while the set misses the target, tighten the tolerance with the best yield gain per unit
   of cost by one level;
2. while some one-level loosening still meets the target, take the one saving the most;
3. the result therefore has no single one-level loosening that meets the target (checked and
   reported, :attr:`Allocation.loosening_yields`);
4. a fresh Monte-Carlo with a new seed verifies the yield (:attr:`Allocation.verified`).

"Meets the target" means the lower Wilson bound of the yield on the search sample is at least
the target, so that an independent sample is likely to meet it too.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from gearte.errors import ParameterError
from gearte.execution import map_chunks, seeded_chunks
from gearte.execution.stop import current_stop_scope
from gearte.tolerance.yield_mc import (
    Model,
    SpecLimit,
    ToleranceSet,
    YieldResult,
    evaluate_checked,
    run_yield,
    wilson_interval,
)

__all__ = ["CostModel", "PriceTable", "Allocation", "SearchStopped", "allocate"]


class SearchStopped(Exception):
    """The run was stopped (SIGINT/SIGTERM, a lost cluster) before or during :func:`allocate`:
    the search is given up (its candidates' counts would come from fewer samples than the
    search's), recorded in the run's stop scope (:mod:`gearte.execution.stop`); the caller
    reports no allocation and keeps what it computed before."""


@dataclass(frozen=True)
class CostModel:
    """``cost = a + b / t^k`` per part [currency], ``t`` the tolerance width [unit].

    ``levels``: the ladder of widths the search may use; default: ``t₀·(√2)^j`` for
    ``j = −6 … 6`` around the tolerance's given width ``t₀`` (one ISO 1328 grade per step).
    """

    a: float
    b: float
    k: float = 1.0
    levels: tuple[float, ...] | None = None

    def __post_init__(self) -> None:
        for n, v in (("a", self.a), ("b", self.b), ("k", self.k)):
            if not (math.isfinite(v) and v >= 0):
                raise ParameterError(f"cost.{n}", v, "must be finite and >= 0")

    def cost(self, t: float) -> float:
        if t <= 0:
            return math.inf
        return self.a + self.b / t**self.k

    def ladder(self, t0: float) -> list[float]:
        if self.levels is not None:
            return sorted(float(x) for x in self.levels)
        if not t0 > 0:
            raise ParameterError("tolerance", t0, "a cost-model ladder needs a width > 0")
        return [t0 * math.sqrt(2.0) ** j for j in range(-6, 7)]


@dataclass(frozen=True)
class PriceTable:
    """Discrete levels: ``widths[i]`` costs ``prices[i]`` (e.g. grade 4 … 8 of a gear)."""

    widths: tuple[float, ...]
    prices: tuple[float, ...]
    labels: tuple[str, ...] | None = None

    def __post_init__(self) -> None:
        if len(self.widths) != len(self.prices) or len(self.widths) < 2:
            raise ParameterError("price_table", self.widths, "needs >= 2 (width, price) pairs")
        if any(not (math.isfinite(w) and w > 0) for w in self.widths):
            raise ParameterError("price_table.widths", self.widths, "must be finite and > 0")

    def cost(self, t: float) -> float:
        for w, p in zip(self.widths, self.prices, strict=True):
            if math.isclose(w, t, rel_tol=1e-12):
                return float(p)
        raise ParameterError("tolerance", t, f"is not a level of the price table {self.widths}")

    def ladder(self, t0: float) -> list[float]:
        return sorted(float(w) for w in self.widths)


Cost = CostModel | PriceTable


@dataclass
class Allocation:
    """The cheapest set found: widths, cost, search-sample yield, the verification run, the
    yield of each single one-level loosening (all below target: locally optimal)."""

    widths: dict[str, float]
    cost: float
    cost_by_tolerance: dict[str, float]
    search_yield: float
    search_ci: tuple[float, float]
    target: float
    verified: YieldResult
    loosening_yields: dict[str, float | None]
    locally_optimal: bool
    evaluations: int
    history: list[dict[str, Any]] = field(default_factory=list)

    @property
    def meets_target(self) -> bool:
        return self.verified.yield_ >= self.target


@dataclass(frozen=True)
class _PassShared:
    model: Any
    tolset: ToleranceSet
    spec: tuple[SpecLimit, ...]
    candidates: tuple[tuple[tuple[str, float], ...], ...]


def _pass_chunk(chunk: Any, shared: _PassShared) -> np.ndarray:
    """Passing parts per candidate width set, on this chunk's (common) draws."""
    ts = shared.tolset
    z, ph = ts.draw_standard(chunk.rng(), chunk.size)
    counts = np.zeros(len(shared.candidates), dtype=np.int64)
    for c, widths in enumerate(shared.candidates):
        out = evaluate_checked(shared.model, ts.values(z, ph, dict(widths)), chunk.size)
        ok = np.ones(chunk.size, dtype=bool)
        for s in shared.spec:
            ok &= s.margin(out[s.quantity]) >= 0
        counts[c] = int(np.count_nonzero(ok))
    return counts


def allocate(
    model: Model,
    tolerances: ToleranceSet,
    spec: Sequence[SpecLimit],
    costs: Mapping[str, Cost],
    target: float,
    *,
    n: int = 20_000,
    seed: int | None = 0,
    verify_n: int | None = None,
    verify_seed: int | None = None,
    chunk_size: int = 5_000,
    max_steps: int = 200,
    options: Any = None,
) -> Allocation:
    """Cheapest tolerance widths reaching ``target`` yield (module docstring).

    Parameters
    ----------
    model, tolerances, spec
        As :func:`gearte.tolerance.yield_mc.run_yield`; the widths of ``tolerances`` are the
        starting point (and the centre of a cost model's ladder).
    costs : mapping
        ``{tolerance key or family: CostModel | PriceTable}`` (a family's cost is per family:
        one stated tolerance); tolerances without a cost stay fixed.
    target : float
        Required yield in (0, 1) [-].
    n, seed
        Search sample (common to every candidate).
    verify_n, verify_seed
        The independent verification run (default ``n`` samples, ``seed + 1``).
    chunk_size : int
        Samples per chunk.
    max_steps : int
        Limit of tightening and loosening steps.
    options : RunOptions, optional
        Workers and scheduler.
    """
    if not 0.0 < target < 1.0:
        raise ParameterError("target_yield", target, "must be in (0, 1)")
    spec = tuple(spec)
    if not spec:
        raise ParameterError("spec", [], "allocation needs at least one spec limit")
    fams = tolerances.families
    for key in costs:
        if key not in fams:
            raise ParameterError(f"costs.{key}", key, "is not a tolerance key or family")
    keys = [k for k in fams if k in costs]
    # a family's width: that of its first member
    t0 = {k: float(tolerances.tolerances[fams[k][0]].tolerance) for k in keys}
    ladders = {k: costs[k].ladder(t0[k]) for k in keys}
    # start at the ladder level closest to the given width
    level = {k: int(np.argmin([abs(w - t0[k]) for w in ladders[k]])) for k in keys}
    chunks = seeded_chunks(int(n), int(chunk_size), seed)
    scope = current_stop_scope()
    cache: dict[tuple[int, ...], int] = {}
    evaluations = 0

    def widths_of(lv: Mapping[str, int]) -> dict[str, float]:
        return {k: ladders[k][lv[k]] for k in keys}

    def passed(cands: list[dict[str, int]]) -> list[int]:
        nonlocal evaluations
        todo = [c for c in cands if tuple(c[k] for k in keys) not in cache]
        uniq: dict[tuple[int, ...], dict[str, int]] = {}
        for c in todo:
            uniq.setdefault(tuple(c[k] for k in keys), c)
        if uniq:
            shared = _PassShared(
                model,
                tolerances,
                spec,
                tuple(tuple(widths_of(c).items()) for c in uniq.values()),
            )
            counts = map_chunks(
                _pass_chunk,
                chunks,
                shared=shared,
                reduce=lambda a, b: a + b,
                options=options,
                progress=False,
            )
            if scope is not None and scope.stopped:  # counts of a prefix of the chunks only
                scope.cut.append(
                    f"allocation search: stopped after {evaluations} evaluations, not reported"
                )
                raise SearchStopped("the run was stopped during the allocation search")
            for key, cnt in zip(uniq, counts, strict=True):
                cache[key] = int(cnt)
            evaluations += len(uniq)
        return [cache[tuple(c[k] for k in keys)] for c in cands]

    def meets(count: int) -> bool:
        return wilson_interval(count, int(n))[0] >= target

    def total_cost(lv: Mapping[str, int]) -> float:
        return sum(costs[k].cost(ladders[k][lv[k]]) for k in keys)

    def search() -> Allocation:
        history: list[dict[str, Any]] = []
        cur = dict(level)
        (cnt,) = passed([cur])
        steps = 0
        while not meets(cnt):
            steps += 1
            if steps > max_steps:
                raise ParameterError("max_steps", max_steps, "allocation did not converge")
            cands = []
            for k in keys:
                if cur[k] > 0:
                    c = dict(cur)
                    c[k] -= 1
                    cands.append((k, c))
            if not cands:
                raise ParameterError(
                    "target_yield",
                    target,
                    "cannot be reached even with every tolerance at its tightest level",
                )
            counts = passed([c for _, c in cands])
            base_cost = total_cost(cur)
            best = max(
                range(len(cands)),
                key=lambda i: (counts[i] - cnt) / max(total_cost(cands[i][1]) - base_cost, 1e-12),
            )
            cur = cands[best][1]
            cnt = counts[best]
            history.append({"step": "tighten", "tolerance": cands[best][0], "passed": cnt})
        while True:
            steps += 1
            if steps > max_steps:
                raise ParameterError("max_steps", max_steps, "allocation did not converge")
            cands = []
            for k in keys:
                if cur[k] < len(ladders[k]) - 1:
                    c = dict(cur)
                    c[k] += 1
                    cands.append((k, c))
            counts = passed([c for _, c in cands])
            ok = [i for i in range(len(cands)) if meets(counts[i])]
            if not ok:
                break
            base_cost = total_cost(cur)
            best = max(ok, key=lambda i: base_cost - total_cost(cands[i][1]))
            cur = cands[best][1]
            cnt = counts[best]
            history.append({"step": "loosen", "tolerance": cands[best][0], "passed": cnt})
        # local optimality: every single one-level loosening misses the target
        loosen: dict[str, float | None] = {}
        for k in keys:
            if cur[k] < len(ladders[k]) - 1:
                c = dict(cur)
                c[k] += 1
                (lc,) = passed([c])
                loosen[k] = lc / n
            else:
                loosen[k] = None  # already at the loosest level
        locally_optimal = all(v is None or not meets(int(round(v * n))) for v in loosen.values())
        widths = widths_of(cur)
        final = tolerances.with_tolerances(widths)
        vseed = (0 if seed is None else int(seed)) + 1 if verify_seed is None else verify_seed
        verified = run_yield(
            model,
            final,
            spec,
            int(verify_n or n),
            seed=vseed,
            chunk_size=chunk_size,
            options=options,
        )
        return Allocation(
            widths=widths,
            cost=total_cost(cur),
            cost_by_tolerance={k: costs[k].cost(widths[k]) for k in keys},
            search_yield=cnt / n,
            search_ci=wilson_interval(cnt, int(n)),
            target=target,
            verified=verified,
            loosening_yields=loosen,
            locally_optimal=locally_optimal,
            evaluations=evaluations,
            history=history,
        )

    if scope is not None and scope.stopped:
        scope.cut.append("allocation search: not run (after the stop)")
        raise SearchStopped("the run was stopped before the allocation search")
    try:
        return search()
    except KeyboardInterrupt as exc:
        if scope is None or scope.stopped:
            raise
        # stopped inside the search (between its Monte-Carlo calls, or in one before any chunk
        # finished): the search is given up, what the run computed before it is kept
        scope.cause = exc
        scope.cut.append(
            f"allocation search: stopped after {evaluations} evaluations, not reported"
        )
        raise SearchStopped("the run was stopped during the allocation search") from None
