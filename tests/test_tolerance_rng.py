"""The Monte-Carlo kernel's own generator (issue 12): xoshiro256++ streams and a ziggurat normal.

The compiled generator is checked against its plain Python twin bit for bit, and its normals
against the exact normal law (moments, Kolmogorov–Smirnov, tail masses) with a check that a
known-bad ziggurat (the fast path without its rejections) fails the same test.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy import stats

from gearte.tolerance.montecarlo import standard_normals
from gearte.tolerance.rng import (
    STREAMS,
    ZIG_R,
    Xoshiro256pp,
    reference_normals,
    stream_states,
    ziggurat_tables,
)


def _normality_failures(z: np.ndarray) -> list[str]:
    """Which exact properties of N(0, 1) the sample ``z`` violates, at about 5 standard errors
    (the KS test at p < 1e-4): mean, variance, skewness, excess kurtosis, KS distance, and the
    masses beyond 2, 3 and the ziggurat's tail start r = 3.654 (binomial standard errors)."""
    n = z.size
    out = []
    if abs(z.mean()) > 5 / math.sqrt(n):
        out.append(f"mean {z.mean():.2e}")
    if abs(z.var() - 1) > 5 * math.sqrt(2 / n):
        out.append(f"variance {z.var():.5f}")
    if abs(stats.skew(z)) > 5 * math.sqrt(6 / n):
        out.append(f"skewness {stats.skew(z):.4f}")
    if abs(stats.kurtosis(z)) > 5 * math.sqrt(24 / n):
        out.append(f"kurtosis {stats.kurtosis(z):.4f}")
    ks = stats.kstest(z, "norm")
    if ks.pvalue < 1e-4:
        out.append(f"KS p {ks.pvalue:.2e}")
    for a in (2.0, 3.0, ZIG_R):
        p = 2 * stats.norm.sf(a)
        k = np.count_nonzero(np.abs(z) > a)
        if abs(k - n * p) > 5 * math.sqrt(n * p * (1 - p)):
            out.append(f"mass beyond {a:.3f}: {k} vs {n * p:.1f}")
    return out


def test_standard_normals_pass_exact_normal_law_checks():
    """10⁶ normals of the compiled ziggurat: mean 0, variance 1, skewness 0, excess kurtosis 0,
    KS against Φ, and the masses beyond 2, 3 and r (the tail method's domain) all within
    5 standard errors of the exact values."""
    z = standard_normals(2024, 1_000_000)
    assert _normality_failures(z) == []


def test_a_bad_ziggurat_fails_the_normality_checks():
    """The checks have power: the ziggurat's fast path accepted without its wedge and tail
    rejections (a classic implementation error: ~1.2 % of draws wrong) is rejected."""
    t = ziggurat_tables()
    r = np.random.default_rng(1).integers(0, 2**64, size=1_000_000, dtype=np.uint64)
    idx = (r & np.uint64(0xFF)).astype(np.intp)
    v = (r.view(np.int64) >> 11).astype(float)
    bad = v * t.w[idx]
    assert _normality_failures(bad) != []


def test_compiled_normals_identical_to_plain_python_twin():
    """Compiled xoshiro256++ + ziggurat (16 main streams stepped side by side) and the plain
    Python twin (Python integers, one sample at a time) give the same bits over 20 000 draws,
    including draws in the tail beyond r (the exact tail method) and a last, partial block."""
    n = 20_000 + 5
    z = standard_normals(7, n)
    np.testing.assert_array_equal(z, reference_normals(7, n))
    assert np.count_nonzero(np.abs(z) > ZIG_R) >= 1


def test_uniform_outputs_are_uniform_and_streams_independent():
    """The 53-bit uniforms of a stream pass KS against U(0, 1); two chunk seeds (children of
    one SeedSequence) give uncorrelated normals."""
    s = Xoshiro256pp(stream_states(3)[2])
    u = np.array([s.unit() for _ in range(50_000)])
    assert stats.kstest(u, "uniform").pvalue > 1e-4
    kids = np.random.SeedSequence(5).spawn(2)
    a, b = standard_normals(kids[0], 200_000), standard_normals(kids[1], 200_000)
    assert abs(np.corrcoef(a, b)[0, 1]) < 5 / math.sqrt(200_000)
    assert not np.array_equal(a[:10], b[:10])


def test_stream_states_depend_on_the_seed_only():
    a = stream_states(np.random.SeedSequence(11))
    assert a.shape == (STREAMS, 4) and a.dtype == np.uint64
    np.testing.assert_array_equal(a, stream_states(11))
    assert not np.array_equal(a, stream_states(12))


@pytest.mark.parametrize("i", [1, 2, 128, 255])
def test_ziggurat_layers_have_equal_area(i):
    """Every layer above the base of the 256-layer ziggurat has the area
    v = 0.00492867323399 of Marsaglia & Tsang (2000): x_i·(f(x_{i−1}) − f(x_i)), with
    x_i = w_i·2⁵² and f(x_0) = 1."""
    t = ziggurat_tables()
    x = t.w * 2.0**52
    assert x[i] * (t.f[i - 1] - t.f[i]) == pytest.approx(0.00492867323399, rel=1e-9)
