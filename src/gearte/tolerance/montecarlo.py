"""Monte-Carlo tolerance simulation with a fixed seed and bounded memory.

The sample count is split into fixed-size chunks, independent of how many workers run them;
chunk ``k`` draws from its own child of ``SeedSequence(seed)`` (``spawn``), so a seed gives the
same statistics on any backend and any worker count. Each chunk is reduced on the spot to sums,
extremes, out-of-spec counts and a fixed-edge histogram, so memory does not grow with the
sample count; percentiles come from that histogram (resolution: one bin, ``16σ/n_bins``).

Linear stacks whose contributors the compiled kernel can draw (normal, uniform, Rayleigh,
Rayleigh magnitude × uniform phase — as the exactly equivalent normal, or drawn in polar form —,
empirical, constant) run in a numba kernel with its own generator
(:mod:`gearte.tolerance.rng`: xoshiro256++ streams seeded from the chunk's seed, a ziggurat
normal), generated and reduced block by block without storing samples. The independent normal
contributors form one Gaussian group: their sum is drawn as *one* normal per sample (exact, a
sum of independent normals is normal with the summed mean and variance); the others are drawn
one by one. Its plain reference, :func:`linear_stack_reference`, is a per-sample Python loop
drawing the same numbers in the same order: the two give bit-identical samples (tested).
(Before 0.1.0 the samples of a seed changed three times — when the normals were grouped, when the
kernel got its own generator and when its main stream became 16 interleaved ones; the
distribution did not change.) Per-contributor values
(contributions, variance shares) come from :mod:`gearte.tolerance.stackup`, not from these
samples. Everything else (function stacks, truncated distributions) runs vectorised in numpy
(``numpy.random.default_rng`` of the chunk's seed), contributor by contributor, chunk by chunk.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from numba import uint64

from gearte._jit import kernel
from gearte.errors import ParameterError
from gearte.execution import spawn_seeds
from gearte.tolerance.mc_result import MCResult
from gearte.tolerance.rng import (
    DRAWS,
    LANES,
    TAIL,
    Xoshiro256pp,
    ZigguratTables,
    lane_states,
    next_u64,
    reference_normal,
    stream_states,
    u64_to_unit,
    zig_fast,
    zig_slow,
    ziggurat_tables,
)
from gearte.tolerance.stackup import FunctionStack, LinearStack

__all__ = [
    "MCResult",
    "ChunkStats",
    "monte_carlo",
    "linear_stack_reference",
    "reduce_samples",
    "kernel_samples",
    "process_capability",
    "standard_normals",
]

_TWO_PI = 2.0 * math.pi
DEFAULT_CHUNK = 1_000_000
DEFAULT_BINS = 4000


# ------------------------------------------------------------------------------------------------
# compiled kernel
# ------------------------------------------------------------------------------------------------
# Streams (gearte.tolerance.rng): rows 0 … LANES−1 main — one 64-bit number per sample for the
# Gaussian group's normal, sample j from main stream j % LANES; TAIL — the ziggurat's rejections;
# DRAWS — the other contributors, in order. Each sample takes exactly one main number, so the
# kernel draws them in blocks of _BLOCK and the samples do not depend on the block size. Codes:
# see distributions.KERNEL_CODES.
_BLOCK = 1024  # a power of two ≥ 512 (the pairwise tree folds 8 and 8) and a multiple of LANES


def _group(codes: np.ndarray, params: np.ndarray, sens: np.ndarray) -> tuple[float, float, bool]:
    """Mean and standard deviation of the sum of the independent normal contributors (codes 0
    and 3) with their sensitivities, and whether there is any."""
    gmu = 0.0
    gv = 0.0
    nn = 0
    for i in range(codes.shape[0]):
        if codes[i] == 0:
            gmu += float(sens[i]) * float(params[i, 0])
            t = float(sens[i]) * float(params[i, 1])
            gv += t * t
            nn += 1
        elif codes[i] == 3:
            t = float(sens[i]) * float(params[i, 0])
            gv += t * t
            nn += 1
    return gmu, math.sqrt(gv), nn > 0


# The histogram bin of y is floor(clamp((y − lo)/width, −1, nbins)) + 1 (0 the underflow, nbins + 1
# the overflow), the formula of reduce_samples. Adding 2⁵² to that small integer puts it, exactly,
# in the low bits of the double: the bin loop stays in floating point (vectorised) and the
# histogram loop reads the index from the bits.
_BIN_OFFSET = 1.0 + 2.0**52


@kernel
def _bin(y, lo, inv_width, top):  # pragma: no cover - compiled
    """Histogram bin + 1 of ``y`` as the low bits of a double (no branch: vector registers)."""
    t = (y - lo) * inv_width
    t = t if t > -1.0 else -1.0
    t = t if t < top else top
    return math.floor(t) + _BIN_OFFSET


@kernel
def _min(a, b):  # pragma: no cover - compiled
    return a if a < b else b


@kernel
def _max(a, b):  # pragma: no cover - compiled
    return a if a > b else b


_BIN_MASK = uint64(0xFFFFFFFF)
_FLUSH = 1 << 30  # samples between additions of the int32 counts into the int64 ones


@kernel
def _linear_stack_kernel(
    states, lanes0, n, tk, tw, tf, group, base, gsd, others, params, codes, sens, pool,
    shift, lo, hi, nbins, lsl, usl, keep,
):  # pragma: no cover - compiled  # fmt: skip
    """Draw ``n`` samples block by block and reduce each block on the spot; the first ``keep``
    samples kept. No sample array beyond one block.

    Per block: the Gaussian group's normals — one number of main stream ``j % LANES`` per
    sample, the ``LANES`` generators stepped side by side (vector registers), the ziggurat's
    fast path over the whole block (branch-free: it lists the ≈ 1.2 % rejected draws, and
    counts the previous block's histogram bins in the same loop: the two scalar chains
    overlap), then the rejected ones redrawn in sample order from the tail stream
    (:func:`gearte.tolerance.rng.zig_slow`) — ``y = base + gsd·z``; then each other
    contributor in order from the draws stream (the order of :func:`linear_stack_reference`).
    ``others`` is None for a stack without other contributors: numba prunes that branch, so
    the common all-normal stack compiles without it (``docs/numba.md``). The block's code is
    written out here, not in ``inline="always"`` helpers: numba types an inlined helper again
    at its call site after deep-copying it with the caller's variable scope, which cost ~1.5 s
    of this kernel's first compile.

    Per full block of ``_BLOCK`` samples, the sums of ``y − shift`` and of its square and the
    extremes by a fixed pairwise tree (elementwise loops LLVM runs on vector registers; the
    tree depends on nothing but the block, so neither do the sums) whose first three levels
    run in registers, eight samples per step, with the histogram bins of those samples (the
    formula of :func:`reduce_samples`), and the next three levels likewise; a chunk's last,
    partial block in order. Then the counts; the out-of-spec counts (only with a finite
    limit) in a vector loop of integer sums."""
    st = states.copy()
    lanes = lanes0.copy()
    # np.empty and a fill, not np.zeros: each np.zeros dtype compiles an allocation and a
    # zero fill of its own in a cold process (~0.3 s); min() is a conditional for the same reason
    counts = np.empty(nbins + 2, np.int64)
    counts[:] = 0
    c32 = np.empty(nbins + 2, np.int32)  # half the cache lines of int64; added in every 2³⁰
    c32[:] = 0
    kept = np.empty(keep if keep < n else n)
    z = np.empty(_BLOCK)
    raw = np.empty(_BLOCK, np.uint64)
    rej = np.empty(_BLOCK, np.int64)
    ibin = np.empty(_BLOCK, np.uint64)
    fbin = ibin.view(np.float64)
    pm = 0
    inv_width = nbins / (hi - lo)
    top = float(nbins)
    specs = lsl > -np.inf or usl < np.inf
    e1 = np.empty(_BLOCK // 2)
    e2 = np.empty(_BLOCK // 2)
    emn = np.empty(_BLOCK // 2)
    emx = np.empty(_BLOCK // 2)
    s1 = 0.0
    s2 = 0.0
    mn = np.inf
    mx = -np.inf
    below = 0
    above = 0
    done = 0
    added = 0
    while done < n:
        if done - added >= _FLUSH:
            counts += c32
            c32[:] = 0
            added = done
        m = _BLOCK if n - done > _BLOCK else n - done
        if group:  # the Gaussian group's normals; the previous block's bins counted on the way
            la = lanes[0]
            lb = lanes[1]
            lc = lanes[2]
            ld = lanes[3]
            for g in range((m + LANES - 1) // LANES):  # the main numbers, LANES streams at once
                jj = g * LANES
                for i in range(LANES):
                    r, la[i], lb[i], lc[i], ld[i] = next_u64(la[i], lb[i], lc[i], ld[i])
                    raw[jj + i] = r
            nr = 0  # fast path; rej lists the rejected draws
            if pm == m:
                for j in range(m):
                    x, ok, idx, v = zig_fast(raw[j], tk, tw)
                    z[j] = x
                    rej[nr] = j
                    nr += not ok
                    c32[ibin[j] & _BIN_MASK] += 1
            else:
                for j in range(pm):
                    c32[ibin[j] & _BIN_MASK] += 1
                for j in range(m):
                    x, ok, idx, v = zig_fast(raw[j], tk, tw)
                    z[j] = x
                    rej[nr] = j
                    nr += not ok
            for i in range(nr):  # the rejected draws in sample order, from the tail stream
                j = rej[i]
                x, ok, idx, v = zig_fast(raw[j], tk, tw)
                t = st[TAIL]
                z[j], t[0], t[1], t[2], t[3] = zig_slow(
                    x, idx, v, t[0], t[1], t[2], t[3], tk, tw, tf
                )
            for j in range(m):
                z[j] = base + gsd * z[j]
        else:
            for j in range(pm):
                c32[ibin[j] & _BIN_MASK] += 1
            for j in range(m):
                z[j] = base
        if others is not None:  # pruned at compile time where others is None (all normal)
            d0, d1, d2, d3 = st[DRAWS, 0], st[DRAWS, 1], st[DRAWS, 2], st[DRAWS, 3]
            for j in range(m):
                y = z[j]
                for i in others:
                    code = codes[i]
                    p0 = params[i, 0]
                    p1 = params[i, 1]
                    if code == 1:  # uniform
                        r, d0, d1, d2, d3 = next_u64(d0, d1, d2, d3)
                        v = p0 + (p1 - p0) * u64_to_unit(r)
                    elif code == 2:  # rayleigh
                        r, d0, d1, d2, d3 = next_u64(d0, d1, d2, d3)
                        v = p0 * math.sqrt(-2.0 * math.log1p(-u64_to_unit(r)))
                    elif code == 6:  # rayleigh magnitude x sin(uniform phase), drawn so
                        r, d0, d1, d2, d3 = next_u64(d0, d1, d2, d3)
                        mag = p0 * math.sqrt(-2.0 * math.log1p(-u64_to_unit(r)))
                        r, d0, d1, d2, d3 = next_u64(d0, d1, d2, d3)
                        v = mag * math.sin(_TWO_PI * u64_to_unit(r))
                    elif code == 4:  # empirical: pool[offset + uniform integer < count]
                        c = uint64(int(p1))
                        thr = (uint64(0) - c) % c
                        r, d0, d1, d2, d3 = next_u64(d0, d1, d2, d3)
                        while r < thr:
                            r, d0, d1, d2, d3 = next_u64(d0, d1, d2, d3)
                        v = pool[int(p0) + int(r % c)]
                    else:  # constant
                        v = p0
                    y += sens[i] * v
                z[j] = y
            st[DRAWS, 0], st[DRAWS, 1], st[DRAWS, 2], st[DRAWS, 3] = d0, d1, d2, d3
        for j in range(m if keep - done > m else keep - done):
            kept[done + j] = z[j]
        if m == _BLOCK:  # pairwise (a fixed tree): elementwise loops, vector registers
            h = _BLOCK // 8
            for j in range(h):  # the first three levels in registers: samples j + i·h, i < 8
                y0, y1, y2, y3 = z[j], z[j + h], z[j + 2 * h], z[j + 3 * h]
                y4, y5, y6, y7 = z[j + 4 * h], z[j + 5 * h], z[j + 6 * h], z[j + 7 * h]
                d0, d1, d2, d3 = y0 - shift, y1 - shift, y2 - shift, y3 - shift
                d4, d5, d6, d7 = y4 - shift, y5 - shift, y6 - shift, y7 - shift
                e1[j] = ((d0 + d4) + (d2 + d6)) + ((d1 + d5) + (d3 + d7))
                e2[j] = ((d0 * d0 + d4 * d4) + (d2 * d2 + d6 * d6)) + (
                    (d1 * d1 + d5 * d5) + (d3 * d3 + d7 * d7)
                )
                emn[j] = _min(_min(_min(y0, y4), _min(y2, y6)), _min(_min(y1, y5), _min(y3, y7)))
                emx[j] = _max(_max(_max(y0, y4), _max(y2, y6)), _max(_max(y1, y5), _max(y3, y7)))
                fbin[j] = _bin(y0, lo, inv_width, top)
                fbin[j + h] = _bin(y1, lo, inv_width, top)
                fbin[j + 2 * h] = _bin(y2, lo, inv_width, top)
                fbin[j + 3 * h] = _bin(y3, lo, inv_width, top)
                fbin[j + 4 * h] = _bin(y4, lo, inv_width, top)
                fbin[j + 5 * h] = _bin(y5, lo, inv_width, top)
                fbin[j + 6 * h] = _bin(y6, lo, inv_width, top)
                fbin[j + 7 * h] = _bin(y7, lo, inv_width, top)
            h = h // 8
            for j in range(h):  # the next three levels: entries j + i·h, i < 8
                e1[j] = ((e1[j] + e1[j + 4 * h]) + (e1[j + 2 * h] + e1[j + 6 * h])) + (
                    (e1[j + h] + e1[j + 5 * h]) + (e1[j + 3 * h] + e1[j + 7 * h])
                )
                e2[j] = ((e2[j] + e2[j + 4 * h]) + (e2[j + 2 * h] + e2[j + 6 * h])) + (
                    (e2[j + h] + e2[j + 5 * h]) + (e2[j + 3 * h] + e2[j + 7 * h])
                )
                emn[j] = _min(
                    _min(_min(emn[j], emn[j + 4 * h]), _min(emn[j + 2 * h], emn[j + 6 * h])),
                    _min(_min(emn[j + h], emn[j + 5 * h]), _min(emn[j + 3 * h], emn[j + 7 * h])),
                )
                emx[j] = _max(
                    _max(_max(emx[j], emx[j + 4 * h]), _max(emx[j + 2 * h], emx[j + 6 * h])),
                    _max(_max(emx[j + h], emx[j + 5 * h]), _max(emx[j + 3 * h], emx[j + 7 * h])),
                )
            while h > 1:  # the last four levels
                h //= 2
                for j in range(h):
                    e1[j] += e1[j + h]
                    e2[j] += e2[j + h]
                    emn[j] = emn[j] if emn[j] < emn[j + h] else emn[j + h]
                    emx[j] = emx[j] if emx[j] > emx[j + h] else emx[j + h]
            s1 += e1[0]
            s2 += e2[0]
            mn = emn[0] if emn[0] < mn else mn
            mx = emx[0] if emx[0] > mx else mx
        else:  # the chunk's last, partial block: in order
            for j in range(m):
                y = z[j]
                d0 = y - shift
                s1 += d0
                s2 += d0 * d0
                mn = y if y < mn else mn
                mx = y if y > mx else mx
                fbin[j] = _bin(y, lo, inv_width, top)
        pm = m
        if specs:  # integer sums of comparisons: vector registers
            for j in range(m):
                below += z[j] < lsl
                above += z[j] > usl
        done += m
    for j in range(pm):  # the last block's counts
        c32[ibin[j] & _BIN_MASK] += 1
    counts += c32
    return s1, s2, mn, mx, below, above, counts, kept


@dataclass(frozen=True)
class _KernelInput:
    """What the kernel needs of a stack, computed once in the caller (and shipped to workers
    with the ziggurat tables, so every worker draws with the same tables)."""

    group: bool
    base: float
    gsd: float
    others: np.ndarray
    params: np.ndarray
    codes: np.ndarray
    sens: np.ndarray
    pool: np.ndarray
    tables: ZigguratTables

    @classmethod
    def of(cls, stack: LinearStack) -> _KernelInput | None:
        arrays = stack.kernel_arrays()
        if arrays is None:
            return None
        codes, params, sens, pool = arrays
        gmu, gsd, group = _group(codes, params, sens)
        others = np.array([i for i in range(codes.size) if codes[i] not in (0, 3)], np.int64)
        return cls(
            group, stack.constant + gmu, gsd, others, params, codes, sens, pool, ziggurat_tables()
        )

    def args(self) -> tuple:
        """The kernel's stack arguments; ``others`` None where there is none (a specialisation
        compiled without the other contributors' draws)."""
        t = self.tables
        return (
            t.k, t.w, t.f, self.group, self.base, self.gsd,
            self.others if self.others.size else None, self.params, self.codes, self.sens,
            self.pool,
        )  # fmt: skip


def _draw_other_ref(code: int, p: np.ndarray, d: Xoshiro256pp, pool: np.ndarray) -> float:
    """Plain twin of one draw of a contributor outside the Gaussian group (the ``others`` loop
    of ``_linear_stack_kernel``)."""
    if code == 1:
        return float(p[0]) + (float(p[1]) - float(p[0])) * d.unit()
    if code == 2:
        return float(p[0]) * math.sqrt(-2.0 * math.log1p(-d.unit()))
    if code == 6:
        mag = float(p[0]) * math.sqrt(-2.0 * math.log1p(-d.unit()))
        return mag * math.sin(_TWO_PI * d.unit())
    if code == 4:
        c = int(p[1])
        thr = ((1 << 64) - c) % c
        while True:
            r = d.next()
            if r >= thr:
                return float(pool[int(p[0]) + r % c])
    return float(p[0])


def linear_stack_reference(
    stack: LinearStack, seed: int | np.random.SeedSequence, n: int
) -> np.ndarray:
    """Plain per-sample Python loop: the basic reference of the compiled kernel.

    ``n`` samples [the stack's unit] of ``stack`` drawn from the chunk streams of ``seed``
    (:func:`gearte.tolerance.rng.stream_states`).

    Per sample: one standard normal for the sum of the independent normal contributors (mean
    ``Σ s_i μ_i``, standard deviation ``sqrt(Σ (s_i σ_i)²)``) from one number of the main
    stream (:func:`gearte.tolerance.rng.reference_normal`), then each other contributor in
    order from the draws stream — the kernel's numbers, so its samples are identical to the
    kernel's. A stack the kernel cannot draw is drawn contributor by contributor from
    ``numpy.random.default_rng(seed)``.
    """
    out = np.empty(n)
    ki = _KernelInput.of(stack)
    if ki is None:
        rng = np.random.default_rng(seed)
        for j in range(n):
            y = stack.constant
            for c in stack.contributors:
                y += c.sensitivity * c.distribution.draw_one(rng)
            out[j] = y
        return out
    states = stream_states(seed)
    mains = [Xoshiro256pp(row) for row in states[:LANES]]
    tail, draws = Xoshiro256pp(states[TAIL]), Xoshiro256pp(states[DRAWS])
    for j in range(n):
        y = ki.base
        if ki.group:
            y = ki.base + ki.gsd * reference_normal(mains[j % LANES], tail, ki.tables)
        for i in ki.others:
            y += float(ki.sens[i]) * _draw_other_ref(int(ki.codes[i]), ki.params[i], draws, ki.pool)
        out[j] = y
    return out


def kernel_samples(stack: LinearStack, seed: int | np.random.SeedSequence, n: int) -> np.ndarray:
    """``n`` samples [the stack's unit] of a linear ``stack`` drawn by the compiled kernel from
    the chunk streams of ``seed`` (for tests and plots)."""
    ki = _KernelInput.of(stack)
    if ki is None:
        raise ParameterError("stack", stack.name, "has contributors the kernel cannot draw")
    return _kept_samples(stream_states(seed), int(n), ki.args())


def _kept_samples(states: np.ndarray, n: int, args: tuple) -> np.ndarray:
    """The ``n`` samples of the kernel run with stack ``args``, all kept (a dummy reduction)."""
    red = (0.0, -1.0, 1.0, 1, -np.inf, np.inf, n)
    return _linear_stack_kernel(*(states, lane_states(states), n, *args, *red))[7]


def compile_general_kernel() -> None:
    """Compile (or load from numba's cache) the kernel for stacks with a contributor outside the
    Gaussian group (uniform, Rayleigh, polar, empirical, constant).

    A stack of normal contributors only runs a specialisation without their draws
    (``others=None``), and every bundled case's stacks are such; ``gearte warm-cache`` calls
    this so that a case with a ``[distributions]`` override finds the other one compiled too.
    """
    from gearte.tolerance.distributions import Uniform
    from gearte.tolerance.stackup import Contributor

    kernel_samples(LinearStack([Contributor("u", Uniform(0.0, 1.0), 1.0)]), 0, 2)


def standard_normals(seed: int | np.random.SeedSequence, n: int) -> np.ndarray:
    """``n`` standard normal numbers [-] from the chunk streams of ``seed`` (compiled): the
    Gaussian group of the kernel for a stack of one standard normal contributor; its plain
    twin is :func:`gearte.tolerance.rng.reference_normals` (moved here from ``rng``, which
    ``montecarlo`` imports: the block loop is written once, in the kernel).

    Parameters
    ----------
    seed : int or SeedSequence
        Seed of the streams (:func:`gearte.tolerance.rng.stream_states`).
    n : int
        How many numbers [-].
    """
    t = ziggurat_tables()
    none = np.zeros(0, np.int64)
    args = (t.k, t.w, t.f, True, 0.0, 1.0, None, np.zeros((0, 2)), none, np.zeros(0), np.zeros(0))
    return _kept_samples(stream_states(seed), int(n), args)


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


def _percentiles_from_hist(
    qs: Sequence[float], counts: np.ndarray, lo: float, hi: float, mn: float, mx: float
) -> dict[float, float]:
    """The values at the percent levels ``qs``, interpolated in the histogram (edges and
    cumulative counts built once, every level located by one ``searchsorted``)."""
    nbins = counts.size - 2
    edges = np.concatenate([[min(mn, lo)], np.linspace(lo, hi, nbins + 1), [max(mx, hi)]])
    cum = np.concatenate([[0], np.cumsum(counts)])
    target = np.asarray(qs, dtype=float) / 100.0 * cum[-1]
    k = np.clip(np.searchsorted(cum, target, side="left"), 1, counts.size)
    c0, c1 = cum[k - 1], cum[k]
    left, right = edges[k - 1], edges[k]
    with np.errstate(invalid="ignore", divide="ignore"):
        val = np.clip(left + (target - c0) / (c1 - c0) * (right - left), mn, mx)
    val = np.where(c1 == c0, left, val)
    return {float(q): float(v) for q, v in zip(qs, val, strict=True)}


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
        sizes=[t.n for t in tasks],
    )


@dataclass(frozen=True)
class _Task:
    seed: np.random.SeedSequence
    n: int
    keep: int
    states: np.ndarray | None = None  # the kernel's stream states of this chunk's seed


class _ChunkRunner:
    """Picklable per-chunk function (kernel or numpy path)."""

    def __init__(self, stack, kernel, shift, lo, hi, nbins, lsl, usl, sub_chunk):
        self.stack = stack
        self.kernel = kernel
        self.shift, self.lo, self.hi, self.nbins = shift, lo, hi, nbins
        self.lsl, self.usl = lsl, usl
        self.sub_chunk = sub_chunk

    def __call__(self, task: _Task) -> ChunkStats:
        kw = dict(shift=self.shift, lo=self.lo, hi=self.hi, nbins=self.nbins)
        if self.kernel is not None:
            reduction = (self.shift, self.lo, self.hi, self.nbins, self.lsl, self.usl, task.keep)
            st = stream_states(task.seed) if task.states is None else task.states
            args = (st, lane_states(st), task.n, *self.kernel.args(), *reduction)
            out = _linear_stack_kernel(*args)
            return ChunkStats(task.n, *out)
        rng = np.random.default_rng(task.seed)
        acc: ChunkStats | None = None
        done = 0
        while done < task.n:
            m = min(self.sub_chunk, task.n - done)
            y = self.stack.sample(rng, m)
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
    kernel = _KernelInput.of(stack) if isinstance(stack, LinearStack) else None
    if engine == "numba" and kernel is None:
        raise ParameterError("engine", engine, "the stack has contributors the kernel cannot draw")
    if engine == "numpy":
        kernel = None

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
    seeds = spawn_seeds(seed, n_chunks)
    tasks = []
    remaining_keep = keep
    for k in range(n_chunks):
        m = min(chunk_size, n - k * chunk_size)
        # The kernel's stream states, seeded here for every chunk in a row: seeding in the
        # chunk, right after the previous chunk's kernel, found the caches cold and took ~4×
        # as long (0.2 ns per sample at 10⁶-sample chunks). Same states, same results.
        states = stream_states(seeds[k]) if kernel is not None else None
        tasks.append(_Task(seeds[k], m, max(0, min(remaining_keep, m)), states))
        remaining_keep -= m
    runner = _ChunkRunner(stack, kernel, centre, lo, hi, nbins, lsl, usl, min(chunk_size, 250_000))
    parts = _map_chunks(
        runner, tasks, options=options, progress=progress, description=f"Monte-Carlo {stack.name}"
    )
    total = parts[0]
    for p in parts[1:]:
        total = total.merge(p, keep)

    mean = centre + total.s1 / total.n
    var = max(total.s2 - total.s1**2 / total.n, 0.0) / (total.n - 1)
    sd = math.sqrt(var)
    pct = _percentiles_from_hist(percentiles, total.counts, lo, hi, total.min, total.max)
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
        engine="numba" if kernel is not None else "numpy",
    )
