"""Compiled random streams for the Monte-Carlo kernels: xoshiro256++ and a ziggurat normal.

The linear-stack kernel of :mod:`gearte.tolerance.montecarlo` draws its numbers here rather than
through ``numpy.random.Generator``: a numba kernel calling a Generator pays an indirect call per
number, which cost about as much as the whole rest of a sample. Here the generator state lives
in registers inside the kernel.

* **Generator**: xoshiro256++ (Blackman & Vigna 2021), 256 bits of state, period 2²⁵⁶ − 1,
  64-bit outputs that pass BigCrush and PractRand. Each chunk of a Monte-Carlo run seeds its
  streams from its own ``SeedSequence`` child (:func:`stream_states`), so a seed gives the same
  numbers whatever the backend or the number of workers. The normals' main numbers come from
  ``LANES`` = 16 streams stepped side by side (sample ``j`` of a chunk from main stream
  ``j % 16``): one xoshiro step has a chain of dependent shifts and xors, and sixteen
  independent ones fill the CPU's vector registers (0.42 against 1.0 ns of CPU per number
  in a micro-benchmark on the 2-core development machine).
* **Uniform** ``[0, 1)``: the top 53 bits of an output times 2⁻⁵³ (every double of the form
  ``k·2⁻⁵³``).
* **Standard normal**: the ziggurat of Marsaglia & Tsang (2000) with 256 layers, the layout of
  numpy's ``Generator.standard_normal``: one 64-bit output gives the layer (low 8 bits) and a
  signed 53-bit integer ``v`` (the top 53 bits); ``x = v·x_i/2⁵²`` is accepted when
  ``|v| < k_i`` (≈ 98.8 % of draws, no transcendental function). Rejected draws go to the wedge
  test or, in the base layer, to Marsaglia's exact tail method beyond ``r = 3.6541528853610088``,
  drawing from a second stream (the *tail* stream): so every sample takes exactly one number of
  its main stream, which lets the kernel draw the main numbers in blocks.

Exactness: the ziggurat is an exact rejection method (up to the 2⁻⁵² resolution of ``v``); the
tests check the moments, a Kolmogorov–Smirnov test against the normal CDF and the tail masses.

:class:`Xoshiro256pp`, :func:`reference_normal` and :func:`reference_normals` are the plain
Python twins (Python integers, one sample at a time): they give bit-identical numbers (tested).

References
----------
D. Blackman, S. Vigna, "Scrambled linear pseudorandom number generators", ACM Trans. Math.
Softw. 47(4) 36 (2021), https://doi.org/10.1145/3460772.
G. Marsaglia, W. W. Tsang, "The ziggurat method for generating random variables", J. Stat.
Softw. 5(8) (2000), https://doi.org/10.18637/jss.v005.i08.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
from numba import int64, njit, uint64

from gearte._jit import kernel

__all__ = [
    "ZigguratTables",
    "ziggurat_tables",
    "stream_states",
    "Xoshiro256pp",
    "reference_normal",
    "STREAMS",
    "LANES",
    "TAIL",
    "DRAWS",
    "lane_states",
    "reference_normals",
]

#: Interleaved main streams: sample ``j`` of a chunk takes its main number from main stream
#: ``j % LANES`` (the compiled kernel steps the ``LANES`` generators side by side, in SIMD
#: registers).
LANES = 16
#: Row of the tail stream (the ziggurat's rejections) in :func:`stream_states`.
TAIL = LANES
#: Row of the draws stream (contributors other than the Gaussian group).
DRAWS = LANES + 1
#: Streams per chunk: rows ``0 … LANES−1`` main, then tail, then draws.
STREAMS = LANES + 2
_MASK = (1 << 64) - 1
ZIG_R = 3.6541528853610088  # right edge of the last layer, Marsaglia & Tsang (2000)
ZIG_V = 0.00492867323399  # area of each layer
_INV_2_53 = 1.0 / 9007199254740992.0


class ZigguratTables(NamedTuple):
    """The 256-layer ziggurat: ``k`` acceptance thresholds on ``|v|`` [-] (int64), ``w`` layer
    widths per unit of ``v`` [-], ``f`` the density ``exp(−x²/2)`` at the layer edges [-]."""

    k: np.ndarray
    w: np.ndarray
    f: np.ndarray


def _compute_tables() -> ZigguratTables:
    """The tables of :func:`ziggurat_tables`, computed (a Python loop over the layers)."""
    m = 2.0**52
    dn = ZIG_R
    tn = dn
    q = ZIG_V / math.exp(-0.5 * dn * dn)
    k = np.zeros(256, np.int64)
    w = np.zeros(256)
    f = np.zeros(256)
    k[0] = int((dn / q) * m)
    k[1] = 0
    w[0] = q / m
    w[255] = dn / m
    f[0] = 1.0
    f[255] = math.exp(-0.5 * dn * dn)
    for i in range(254, 0, -1):
        dn = math.sqrt(-2.0 * math.log(ZIG_V / dn + math.exp(-0.5 * dn * dn)))
        k[i + 1] = int((dn / tn) * m)
        tn = dn
        f[i] = math.exp(-0.5 * dn * dn)
        w[i] = dn / m
    return ZigguratTables(k, w, f)


_TABLES: ZigguratTables | None = None


def ziggurat_tables() -> ZigguratTables:
    """The ziggurat tables of Marsaglia & Tsang (2000), 256 layers, for 52-bit ``|v|``.

    Layer 0 is the base strip (width ``v/f(r)``, its part beyond ``r`` is the tail); layer 1
    the top one; layer ``i`` spans ``[0, x_i]``. Computed once per process (0.5 ms, which
    every Monte-Carlo call paid before); each call returns fresh copies.
    """
    global _TABLES
    if _TABLES is None:
        _TABLES = _compute_tables()
    return ZigguratTables(*(a.copy() for a in _TABLES))


def stream_states(seed: int | np.random.SeedSequence, streams: int = STREAMS) -> np.ndarray:
    """The xoshiro256++ states of one chunk: ``(streams, 4)`` uint64 from a seed sequence.

    A state of all zeros (probability 2⁻²⁵⁶) would stay zero; its first word is set to 1.

    Parameters
    ----------
    seed : int or SeedSequence
        The chunk's seed (a child of the study's ``SeedSequence``).
    streams : int
        Number of independent streams [-].
    """
    ss = seed if isinstance(seed, np.random.SeedSequence) else np.random.SeedSequence(seed)
    st = ss.generate_state(4 * streams, np.uint64).reshape(streams, 4)
    st[~st.any(axis=1), 0] = 1  # probability 2**-256 per row
    return st


# ------------------------------------------------------------------------------------------------
# compiled draws (state as four uint64 locals), called by the Monte-Carlo kernel
# (gearte.tolerance.montecarlo), which steps the interleaved main streams block by block. The
# small ones are plain kernels, which LLVM inlines into their callers; numba's inline="always"
# typed a copy at each of their ~40 call sites and cost the Monte-Carlo kernel ~4 s of its first
# compile (docs/numba.md). zig_slow, with one call site, stays inlined.
# ------------------------------------------------------------------------------------------------
@kernel
def _rotl(x, k):  # pragma: no cover - compiled
    """``x`` rotated left by ``k`` bits (both uint64: one signature, no literal ints)."""
    return (x << k) | (x >> (uint64(64) - k))


@kernel
def next_u64(s0, s1, s2, s3):  # pragma: no cover - compiled
    """xoshiro256++: ``(output, s0, s1, s2, s3)``."""
    r = _rotl(s0 + s3, uint64(23)) + s0
    t = s1 << uint64(17)
    s2 ^= s0
    s3 ^= s1
    s1 ^= s2
    s0 ^= s3
    s2 ^= t
    s3 = _rotl(s3, uint64(45))
    return r, s0, s1, s2, s3


@kernel
def u64_to_unit(r):  # pragma: no cover - compiled
    """Uniform ``[0, 1)`` from the top 53 bits."""
    return float(r >> uint64(11)) * _INV_2_53


@kernel
def zig_fast(r, k, w):  # pragma: no cover - compiled
    """Fast path of the ziggurat: ``(x, accepted, layer, v)`` from one 64-bit output."""
    idx = int64(r & uint64(0xFF))  # int64, as the layer index zig_slow is also called with
    v = int64(r) >> 11
    x = float(v) * w[idx]
    return x, abs(v) < k[idx], idx, v


@njit(inline="always")
def zig_slow(x, idx, v, t0, t1, t2, t3, k, w, f):  # pragma: no cover - compiled
    """A draw rejected by the fast path: wedge test (layers ≥ 1) or tail (layer 0) with the
    tail stream; when the wedge test rejects, a fresh ziggurat draw from the tail stream.
    Returns ``(x, t0, t1, t2, t3)``."""
    while True:
        if idx == 0:
            while True:
                u1, t0, t1, t2, t3 = next_u64(t0, t1, t2, t3)
                u2, t0, t1, t2, t3 = next_u64(t0, t1, t2, t3)
                xx = -math.log1p(-u64_to_unit(u1)) / ZIG_R
                yy = -math.log1p(-u64_to_unit(u2))
                if yy + yy > xx * xx:
                    if v < 0:
                        return -(ZIG_R + xx), t0, t1, t2, t3
                    return ZIG_R + xx, t0, t1, t2, t3
        u, t0, t1, t2, t3 = next_u64(t0, t1, t2, t3)
        if (f[idx - 1] - f[idx]) * u64_to_unit(u) + f[idx] < math.exp(-0.5 * x * x):
            return x, t0, t1, t2, t3
        r, t0, t1, t2, t3 = next_u64(t0, t1, t2, t3)
        x, ok, idx, v = zig_fast(r, k, w)
        if ok:
            return x, t0, t1, t2, t3


def lane_states(states: np.ndarray) -> np.ndarray:
    """The main streams' states of a chunk as ``(4, LANES)`` uint64, one row per state word
    (the layout the SIMD step reads).

    Parameters
    ----------
    states : np.ndarray
        The chunk's stream states [-] (:func:`stream_states`); rows ``0 … LANES−1`` are used.
    """
    return np.ascontiguousarray(states[:LANES].T)


# ------------------------------------------------------------------------------------------------
# plain twins
# ------------------------------------------------------------------------------------------------
class Xoshiro256pp:
    """Plain Python xoshiro256++ stream (the reference of the compiled one).

    Parameters
    ----------
    state : sequence of 4 int
        The 256-bit state as four unsigned 64-bit words (a row of :func:`stream_states`).
    """

    def __init__(self, state) -> None:
        self.s = [int(x) & _MASK for x in state]

    def next(self) -> int:
        """The next 64-bit output (an int in ``[0, 2⁶⁴)``)."""
        s = self.s
        x = (s[0] + s[3]) & _MASK
        r = ((((x << 23) | (x >> 41)) & _MASK) + s[0]) & _MASK
        t = (s[1] << 17) & _MASK
        s[2] ^= s[0]
        s[3] ^= s[1]
        s[1] ^= s[2]
        s[0] ^= s[3]
        s[2] ^= t
        s[3] = ((s[3] << 45) | (s[3] >> 19)) & _MASK
        return r

    def unit(self) -> float:
        """Uniform in ``[0, 1)``: the top 53 bits times 2⁻⁵³."""
        return (self.next() >> 11) * _INV_2_53


def _fast_ref(r: int, t: ZigguratTables) -> tuple[float, bool, int, int]:
    idx = r & 0xFF
    v = (r - (1 << 64) if r >> 63 else r) >> 11
    x = float(v) * float(t.w[idx])
    return x, abs(v) < int(t.k[idx]), idx, v


def reference_normals(seed: int | np.random.SeedSequence, n: int) -> np.ndarray:
    """Plain twin of :func:`gearte.tolerance.montecarlo.standard_normals`: sample ``j`` from
    main stream ``j % LANES`` (:func:`reference_normal`), rejections from the tail stream, one
    sample at a time.

    Parameters
    ----------
    seed : int or SeedSequence
        Seed of the streams (:func:`stream_states`).
    n : int
        How many numbers [-].
    """
    st = stream_states(seed)
    mains = [Xoshiro256pp(row) for row in st[:LANES]]
    tail = Xoshiro256pp(st[TAIL])
    t = ziggurat_tables()
    return np.array([reference_normal(mains[j % LANES], tail, t) for j in range(n)])


def reference_normal(
    main: Xoshiro256pp, tail: Xoshiro256pp, tables: ZigguratTables | None = None
) -> float:
    """One standard normal [-], plain Python: one number of ``main``, rejections from ``tail``.

    Parameters
    ----------
    main, tail : Xoshiro256pp
        The main and the tail streams.
    tables : ZigguratTables, optional
        :func:`ziggurat_tables` (computed when omitted).
    """
    t = tables if tables is not None else ziggurat_tables()
    x, ok, idx, v = _fast_ref(main.next(), t)
    while not ok:
        if idx == 0:
            while True:
                xx = -math.log1p(-tail.unit()) / ZIG_R
                yy = -math.log1p(-tail.unit())
                if yy + yy > xx * xx:
                    return -(ZIG_R + xx) if v < 0 else ZIG_R + xx
        f = t.f
        if (float(f[idx - 1]) - float(f[idx])) * tail.unit() + float(f[idx]) < math.exp(
            -0.5 * x * x
        ):
            return x
        x, ok, idx, v = _fast_ref(tail.next(), t)
    return x
