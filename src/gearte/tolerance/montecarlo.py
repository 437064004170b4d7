"""Monte-Carlo tolerance simulation with a fixed seed and bounded memory.

The sample count is split into fixed-size chunks, independent of how many workers run them;
chunk ``k`` draws from its own ``numpy.random.Generator`` (``SeedSequence(seed).spawn``), so a
seed gives the same statistics on any backend. Each chunk is reduced on the spot to sums,
extremes, out-of-spec counts and a fixed-edge histogram, so memory does not grow with the
sample count; percentiles come from that histogram (resolution: one bin, ``16σ/n_bins``).

Linear stacks whose contributors the compiled kernel can draw (normal, uniform, Rayleigh,
Rayleigh magnitude × uniform phase — as the exactly equivalent normal, or drawn in polar form —,
empirical, constant) run in a numba kernel that draws from
the chunk's Generator directly and reduces without storing samples. The independent normal
contributors form one Gaussian group: their sum is drawn as *one* normal per sample (exact, a sum
of independent normals is normal with the summed mean and variance); the others are drawn one
by one. Its plain reference, :func:`linear_stack_reference`, is a per-sample Python loop making
the same Generator calls in the same order: the two give bit-identical samples (tested), so a
seed gives the same result on every backend. (Before issue 12 each normal contributor was drawn
separately: the samples of a seed changed once then, the distribution did not.) Per-contributor
values (contributions, variance shares) come from :mod:`gearte.tolerance.stackup`, not from
these samples. Everything else (function stacks, truncated distributions) runs vectorised in
numpy, contributor by contributor, chunk by chunk.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numba import njit

from gearte.errors import ParameterError
from gearte.execution import spawn_generators
from gearte.tolerance.stackup import FunctionStack, LinearStack

__all__ = [
    "MCResult",
    "ChunkStats",
    "monte_carlo",
    "linear_stack_reference",
    "reduce_samples",
    "kernel_samples",
    "process_capability",
]

_TWO_PI = 2.0 * math.pi
DEFAULT_CHUNK = 1_000_000
DEFAULT_BINS = 4000


# ------------------------------------------------------------------------------------------------
# compiled kernel
# ------------------------------------------------------------------------------------------------
# The draw of one contributor is written out inline (a helper function taking the Generator per
# draw costs a factor of ~5 in numba 0.6x); samples are drawn in blocks, then reduced.
# Codes: see distributions.KERNEL_CODES.
_BLOCK = 2048


@njit(cache=True, nogil=True)
def _normal_group(codes, params, sens):  # pragma: no cover - compiled
    """Mean and standard deviation of the sum of the independent normal contributors (codes 0
    and 3) with their sensitivities, and how many there are."""
    gmu = 0.0
    gv = 0.0
    nn = 0
    for i in range(codes.shape[0]):
        if codes[i] == 0:
            gmu += sens[i] * params[i, 0]
            t = sens[i] * params[i, 1]
            gv += t * t
            nn += 1
        elif codes[i] == 3:
            t = sens[i] * params[i, 0]
            gv += t * t
            nn += 1
    return gmu, math.sqrt(gv), nn


@njit(cache=True, nogil=True)
def _fill(rng, out, m, codes, params, sens, const, pool):  # pragma: no cover - compiled
    """Draw ``m`` samples of the stack into ``out[:m]``, sample by sample: one standard normal
    for the sum of the independent normal contributors (exact: a sum of independent normals is
    normal), then the other contributors in order (the order of
    :func:`linear_stack_reference`)."""
    k = codes.shape[0]
    gmu, gsd, nn = _normal_group(codes, params, sens)
    base = const + gmu
    if nn == k:  # every contributor normal: one draw per sample
        for j in range(m):
            out[j] = base + gsd * rng.standard_normal()
        return
    for j in range(m):
        y = base
        if nn > 0:
            y += gsd * rng.standard_normal()
        for i in range(k):
            c = codes[i]
            if c == 0 or c == 3:  # in the normal group
                continue
            elif c == 1:  # uniform
                v = rng.uniform(params[i, 0], params[i, 1])
            elif c == 2:  # rayleigh
                v = rng.rayleigh(params[i, 0])
            elif c == 6:  # rayleigh magnitude x sin(uniform phase), drawn as magnitude and phase
                r = rng.rayleigh(params[i, 0])
                v = r * math.sin(rng.uniform(0.0, _TWO_PI))
            elif c == 4:  # empirical: pool[offset + integers(0, count)]
                v = pool[int(params[i, 0]) + rng.integers(0, int(params[i, 1]))]
            else:  # constant
                v = params[i, 0]
            y += sens[i] * v
        out[j] = y


@njit(cache=True, nogil=True)
def _linear_stack_kernel(
    rng, n, codes, params, sens, const, pool, shift, lo, hi, nbins, lsl, usl, keep
):  # pragma: no cover - compiled
    counts = np.zeros(nbins + 2, np.int64)
    kept = np.empty(min(keep, n))
    buf = np.empty(_BLOCK)
    inv_width = nbins / (hi - lo)
    s1 = 0.0
    s2 = 0.0
    mn = np.inf
    mx = -np.inf
    below = 0
    above = 0
    done = 0
    while done < n:
        m = min(_BLOCK, n - done)
        _fill(rng, buf, m, codes, params, sens, const, pool)
        for j in range(m):
            y = buf[j]
            if done + j < keep:
                kept[done + j] = y
            d = y - shift
            s1 += d
            s2 += d * d
            mn = min(mn, y)
            mx = max(mx, y)
            if y < lsl:
                below += 1
            if y > usl:
                above += 1
            b = math.floor((y - lo) * inv_width)
            if b < 0:
                counts[0] += 1
            elif b >= nbins:
                counts[nbins + 1] += 1
            else:
                counts[b + 1] += 1
        done += m
    return s1, s2, mn, mx, below, above, counts, kept


@njit(cache=True, nogil=True)
def _linear_stack_samples(rng, n, codes, params, sens, const, pool):  # pragma: no cover
    out = np.empty(n)
    _fill(rng, out, n, codes, params, sens, const, pool)
    return out


def linear_stack_reference(stack: LinearStack, rng: np.random.Generator, n: int) -> np.ndarray:
    """Plain per-sample Python loop: the basic reference of the compiled kernel.

    ``n`` samples [the stack's unit] of ``stack`` drawn from ``rng``.

    Makes the same Generator calls in the same order as the kernel — per sample one standard
    normal for the sum of the independent normal contributors (mean ``Σ s_i μ_i``, standard
    deviation ``sqrt(Σ (s_i σ_i)²)``), then each other contributor in order — so its samples
    are identical to the kernel's for the same Generator state. A stack the kernel cannot draw
    is drawn contributor by contributor.
    """
    out = np.empty(n)
    contributors = stack.contributors
    arrays = stack.kernel_arrays()
    if arrays is None:
        for j in range(n):
            y = stack.constant
            for c in contributors:
                y += c.sensitivity * c.distribution.draw_one(rng)
            out[j] = y
        return out
    codes, params, sens, _ = arrays
    gmu = 0.0
    gv = 0.0
    others = []
    for i, c in enumerate(contributors):
        if codes[i] == 0:
            gmu += float(sens[i]) * float(params[i, 0])
            t = float(sens[i]) * float(params[i, 1])
            gv += t * t
        elif codes[i] == 3:
            t = float(sens[i]) * float(params[i, 0])
            gv += t * t
        else:
            others.append((float(sens[i]), c.distribution))
    gsd = math.sqrt(gv)
    grouped = len(others) < len(contributors)
    base = stack.constant + gmu
    for j in range(n):
        y = base
        if grouped:
            y += gsd * rng.standard_normal()
        for si, d in others:
            y += si * d.draw_one(rng)
        out[j] = y
    return out


def kernel_samples(stack: LinearStack, rng: np.random.Generator, n: int) -> np.ndarray:
    """``n`` samples [the stack's unit] of a linear ``stack`` drawn by the compiled kernel from
    ``rng`` (for tests and plots)."""
    arrays = stack.kernel_arrays()
    if arrays is None:
        raise ParameterError("stack", stack.name, "has contributors the kernel cannot draw")
    codes, params, sens, pool = arrays
    return _linear_stack_samples(rng, int(n), codes, params, sens, stack.constant, pool)


# ------------------------------------------------------------------------------------------------
# reductions
# ------------------------------------------------------------------------------------------------
@dataclass
class ChunkStats:
    """Sufficient statistics of one chunk (sums are of ``y − shift``)."""

    n: int
    s1: float
    s2: float
    min: float
    max: float
    below: int
    above: int
    counts: np.ndarray
    kept: np.ndarray

    def merge(self, other: ChunkStats, keep: int) -> ChunkStats:
        kept = self.kept
        if kept.size < keep and other.kept.size:
            kept = np.concatenate([kept, other.kept[: keep - kept.size]])
        return ChunkStats(
            self.n + other.n,
            self.s1 + other.s1,
            self.s2 + other.s2,
            min(self.min, other.min),
            max(self.max, other.max),
            self.below + other.below,
            self.above + other.above,
            self.counts + other.counts,
            kept,
        )


def reduce_samples(
    y: np.ndarray,
    *,
    shift: float,
    lo: float,
    hi: float,
    nbins: int,
    lsl: float,
    usl: float,
    keep: int,
) -> ChunkStats:
    """Plain-numpy twin of the kernel's reduction (same formulas, same bin edges).

    ``y`` samples [the quantity's unit]; ``shift`` [same unit] subtracted before the moments;
    histogram from ``lo`` to ``hi`` [same unit] in ``nbins`` bins; ``lsl``/``usl`` spec limits
    [same unit] for the out-of-spec count; ``keep`` samples kept.
    """
    y = np.asarray(y, dtype=float)
    d = y - shift
    b = np.floor((y - lo) * (nbins / (hi - lo)))
    idx = np.where(b < 0, 0, np.where(b >= nbins, nbins + 1, b + 1)).astype(np.int64)
    counts = np.bincount(idx, minlength=nbins + 2).astype(np.int64)
    return ChunkStats(
        int(y.size),
        float(np.sum(d)),
        float(np.sum(d * d)),
        float(np.min(y)) if y.size else math.inf,
        float(np.max(y)) if y.size else -math.inf,
        int(np.count_nonzero(y < lsl)),
        int(np.count_nonzero(y > usl)),
        counts,
        y[:keep].copy(),
    )


def process_capability(
    mean: float, sd: float, lower: float | None, upper: float | None
) -> tuple[float | None, float | None]:
    """``(Cp, Cpk)`` [-] against spec limits; Cp needs both limits, Cpk at least one.

    ``mean`` μ, ``sd`` σ, ``lower`` LSL and ``upper`` USL (None: no limit), all in the unit of
    the quantity [same unit].

    ``Cp = (USL − LSL)/(6σ)``, ``Cpk = min(USL − μ, μ − LSL)/(3σ)``.
    """
    if sd <= 0:
        return (None, None)
    cp = (upper - lower) / (6 * sd) if lower is not None and upper is not None else None
    sides = []
    if upper is not None:
        sides.append((upper - mean) / (3 * sd))
    if lower is not None:
        sides.append((mean - lower) / (3 * sd))
    return (cp, min(sides) if sides else None)


@dataclass
class MCResult:
    """Statistics of a Monte-Carlo run.

    Attributes are in the unit of the stacked quantity. ``percentiles`` maps the percent level
    (e.g. ``0.135``) to the value, read off the histogram (``hist_edges``, ``hist_counts``; the
    first and last counts are the under- and overflow). ``samples`` holds the first ``keep``
    samples for plots.
    """

    n: int
    mean: float
    sd: float
    min: float
    max: float
    percentiles: dict[float, float]
    lower_spec: float | None
    upper_spec: float | None
    below_fraction: float
    above_fraction: float
    cp: float | None
    cpk: float | None
    hist_edges: np.ndarray
    hist_counts: np.ndarray
    samples: np.ndarray
    seed: int
    chunk_size: int
    engine: str
    extra: dict[str, Any] = field(default_factory=dict)

    @property
    def std_error(self) -> float:
        """Standard error of the mean, ``sd/√n``."""
        return self.sd / math.sqrt(self.n)

    @property
    def out_of_spec_fraction(self) -> float:
        return self.below_fraction + self.above_fraction


def _percentile_from_hist(
    q: float, counts: np.ndarray, lo: float, hi: float, mn: float, mx: float
) -> float:
    nbins = counts.size - 2
    n = counts.sum()
    target = q / 100.0 * n
    edges = np.concatenate([[min(mn, lo)], np.linspace(lo, hi, nbins + 1), [max(mx, hi)]])
    cum = np.concatenate([[0], np.cumsum(counts)])
    k = int(np.searchsorted(cum, target, side="left"))
    k = min(max(k, 1), counts.size)
    c0, c1 = cum[k - 1], cum[k]
    left, right = edges[k - 1], edges[k]
    if c1 == c0:
        return float(left)
    val = left + (target - c0) / (c1 - c0) * (right - left)
    return float(min(max(val, mn), mx))


def _map_chunks(func, tasks: Sequence[Any], *, options: Any, progress: bool, description: str):
    """Run ``func`` over tasks in order through :func:`gearte.execution.map_chunks`."""
    from gearte.execution import map_chunks

    return map_chunks(
        func,
        tasks,
        workers=getattr(options, "workers", None),
        scheduler=getattr(options, "scheduler", None),
        progress=progress,
        description=description,
    )


@dataclass(frozen=True)
class _Task:
    rng: np.random.Generator
    n: int
    keep: int


class _ChunkRunner:
    """Picklable per-chunk function (kernel or numpy path)."""

    def __init__(self, stack, arrays, shift, lo, hi, nbins, lsl, usl, sub_chunk):
        self.stack = stack
        self.arrays = arrays
        self.shift, self.lo, self.hi, self.nbins = shift, lo, hi, nbins
        self.lsl, self.usl = lsl, usl
        self.sub_chunk = sub_chunk

    def __call__(self, task: _Task) -> ChunkStats:
        kw = dict(shift=self.shift, lo=self.lo, hi=self.hi, nbins=self.nbins)
        if self.arrays is not None:
            codes, params, sens, pool = self.arrays
            out = _linear_stack_kernel(
                task.rng,
                task.n,
                codes,
                params,
                sens,
                self.stack.constant,
                pool,
                self.shift,
                self.lo,
                self.hi,
                self.nbins,
                self.lsl,
                self.usl,
                task.keep,
            )
            return ChunkStats(task.n, *out)
        acc: ChunkStats | None = None
        done = 0
        while done < task.n:
            m = min(self.sub_chunk, task.n - done)
            y = self.stack.sample(task.rng, m)
            keep = max(0, task.keep - done)
            part = reduce_samples(y, lsl=self.lsl, usl=self.usl, keep=keep, **kw)
            acc = part if acc is None else acc.merge(part, task.keep)
            done += m
        assert acc is not None
        return acc


def monte_carlo(
    stack: LinearStack | FunctionStack,
    n: int,
    *,
    seed: int = 0,
    chunk_size: int = DEFAULT_CHUNK,
    lower_spec: float | None = None,
    upper_spec: float | None = None,
    percentiles: Sequence[float] = (0.135, 2.5, 50.0, 97.5, 99.865),
    keep: int = 100_000,
    nbins: int = DEFAULT_BINS,
    engine: str = "auto",
    progress: bool = False,
    options: Any = None,
) -> MCResult:
    """Monte-Carlo simulation of a stack.

    Parameters
    ----------
    stack : LinearStack or FunctionStack
    n : int
        Number of samples, ``≥ 2``.
    seed : int
        Seed of the ``SeedSequence`` the chunk generators are spawned from.
    chunk_size : int
        Samples per chunk (fixes the random streams; memory per worker ~ ``8·chunk_size`` bytes
        on the numpy path, constant on the kernel path).
    lower_spec, upper_spec : float, optional
        Specification limits [the stack's unit] for the out-of-spec fractions and Cp/Cpk.
    percentiles : sequence of float
        Percent levels to report [%].
    keep : int
        Number of leading samples kept for plots.
    nbins : int
        Histogram bins over ``mean ± 8σ`` (analytic for linear stacks, from a pilot sample
        otherwise).
    engine : {"auto", "numba", "numpy"}
        ``auto`` uses the compiled kernel when every contributor is kernel-drawable.
    progress : bool
        Show a progress bar (through :mod:`gearte.execution`).
    options : RunOptions, optional
        Passed on to :func:`gearte.execution.map_chunks` (workers, scheduler).
    """
    n = int(n)
    if n < 2:
        raise ParameterError("samples", n, "Monte-Carlo needs >= 2 samples")
    if chunk_size < 1:
        raise ParameterError("chunk_size", chunk_size, "must be >= 1")
    if engine not in ("auto", "numba", "numpy"):
        raise ParameterError("engine", engine, "must be 'auto', 'numba' or 'numpy'")
    if lower_spec is not None and upper_spec is not None and upper_spec < lower_spec:
        raise ParameterError(
            "spec_limits", (lower_spec, upper_spec), "inverted: upper spec must be >= lower spec"
        )
    arrays = stack.kernel_arrays() if isinstance(stack, LinearStack) else None
    if engine == "numba" and arrays is None:
        raise ParameterError("engine", engine, "the stack has contributors the kernel cannot draw")
    if engine == "numpy":
        arrays = None

    if isinstance(stack, LinearStack):
        centre, spread = stack.mean, stack.sd
    else:
        pilot = stack.sample(np.random.default_rng([seed, 7919]), 20_000)
        centre, spread = float(np.mean(pilot)), float(np.std(pilot))
    if not spread > 0:
        spread = max(abs(centre), 1.0) * 1e-9
    lo, hi = centre - 8 * spread, centre + 8 * spread
    lsl = -math.inf if lower_spec is None else float(lower_spec)
    usl = math.inf if upper_spec is None else float(upper_spec)

    n_chunks = math.ceil(n / chunk_size)
    rngs = spawn_generators(seed, n_chunks)
    tasks = []
    remaining_keep = keep
    for k in range(n_chunks):
        m = min(chunk_size, n - k * chunk_size)
        tasks.append(_Task(rngs[k], m, max(0, min(remaining_keep, m))))
        remaining_keep -= m
    runner = _ChunkRunner(stack, arrays, centre, lo, hi, nbins, lsl, usl, min(chunk_size, 250_000))
    parts = _map_chunks(
        runner, tasks, options=options, progress=progress, description=f"Monte-Carlo {stack.name}"
    )
    total = parts[0]
    for p in parts[1:]:
        total = total.merge(p, keep)

    mean = centre + total.s1 / total.n
    var = max(total.s2 - total.s1**2 / total.n, 0.0) / (total.n - 1)
    sd = math.sqrt(var)
    pct = {
        float(q): _percentile_from_hist(q, total.counts, lo, hi, total.min, total.max)
        for q in percentiles
    }
    cp, cpk = process_capability(mean, sd, lower_spec, upper_spec)
    return MCResult(
        n=total.n,
        mean=mean,
        sd=sd,
        min=total.min,
        max=total.max,
        percentiles=pct,
        lower_spec=lower_spec,
        upper_spec=upper_spec,
        below_fraction=total.below / total.n,
        above_fraction=total.above / total.n,
        cp=cp,
        cpk=cpk,
        hist_edges=np.linspace(lo, hi, nbins + 1),
        hist_counts=total.counts,
        samples=total.kept,
        seed=seed,
        chunk_size=chunk_size,
        engine="numba" if arrays is not None else "numpy",
    )
