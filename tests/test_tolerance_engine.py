"""The general tolerance engine: distributions, stacks, Monte-Carlo, contributions."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy import stats

from gearte.errors import ParameterError
from gearte.tolerance.contributions import pareto, sobol_indices, variance_shares
from gearte.tolerance.distributions import (
    Constant,
    Empirical,
    Normal,
    RadialPhase,
    Rayleigh,
    Truncated,
    Uniform,
)
from gearte.tolerance.montecarlo import (
    kernel_samples,
    linear_stack_reference,
    monte_carlo,
    process_capability,
    reduce_samples,
    standard_normals,
)
from gearte.tolerance.stackup import Contributor, FunctionStack, LinearStack, z_for_confidence
from jiang2024_data import bevel_pair, spur_pair

DISTS = [
    Normal.from_limits(-30.0, -19.0),
    Uniform(-1.0, 3.0),
    Rayleigh.from_tolerance(27.0),
    RadialPhase(Rayleigh(4.5)),
    RadialPhase(Uniform(0.0, 2.0)),
    Truncated(Normal(0.0, 1.0), -1.0, 2.0),
    Truncated(Rayleigh(1.0), 0.5, 3.0),
    Empirical([1.0, 2.0, 2.5, 4.0, 7.0]),
    Constant(3.0),
]


@pytest.mark.parametrize("d", DISTS, ids=lambda d: type(d).__name__)
def test_distribution_moments_match_samples(d):
    x = d.sample(np.random.default_rng(1), 200_000)
    se = math.sqrt(d.variance / x.size) if d.variance > 0 else 1e-12
    assert x.mean() == pytest.approx(d.mean, abs=5 * se + 1e-12)
    if d.variance > 0:
        assert x.var() == pytest.approx(d.variance, rel=0.02)
    lo, hi = d.limits
    if isinstance(d, Uniform | Truncated | Empirical | Constant):  # bounded supports
        assert x.min() >= lo - 1e-12 and x.max() <= hi + 1e-12


def test_normal_from_limits_uses_range_over_six():
    d = Normal.from_limits(-32.0, -21.0)
    assert d.mean == pytest.approx(-26.5)
    assert d.sd == pytest.approx(11 / 6)
    assert d.limits == (-32.0, -21.0)


def test_rayleigh_projection_is_normal_with_scale():
    d = RadialPhase(Rayleigh(2.0))
    assert d.variance == pytest.approx(4.0)  # E[r²]/2 = σx²
    x = d.sample(np.random.default_rng(2), 100_000)
    assert stats.kstest(x / 2.0, "norm").pvalue > 1e-3


def test_truncated_normal_matches_scipy():
    d = Truncated(Normal(1.0, 2.0), -1.0, 2.5)
    ref = stats.truncnorm((-1.0 - 1.0) / 2.0, (2.5 - 1.0) / 2.0, loc=1.0, scale=2.0)
    assert d.mean == pytest.approx(ref.mean(), rel=1e-8)
    assert d.variance == pytest.approx(ref.var(), rel=1e-8)


def test_empirical_resamples_only_measured_values():
    vals = [3.0, 4.0, 4.0, 9.0]
    d = Empirical(vals)
    x = d.sample(np.random.default_rng(0), 1000)
    assert set(np.unique(x)) <= set(vals)
    assert d.variance == pytest.approx(np.var(vals))


# -- bad input ------------------------------------------------------------------------------------
def test_inverted_limits_name_the_field():
    with pytest.raises(ParameterError, match="driven.thickness") as e:
        Normal.from_limits(-21.0, -32.0, field="driven.thickness")
    assert "inverted" in str(e.value)
    with pytest.raises(ParameterError, match="inverted"):
        Uniform(2.0, 1.0)
    with pytest.raises(ParameterError, match="lower < upper"):
        Truncated(Normal(0, 1), 1.0, 1.0)


def test_negative_tolerance_and_clearance_rejected():
    with pytest.raises(ParameterError, match="centre_distance_tol"):
        Normal.from_tolerance(-0.02, field="centre_distance_tol")
    from gearte.models.backlash import SpurGear, SpurPair

    g = SpurGear(28, -0.019, -0.030, 0.027)
    with pytest.raises(ParameterError, match="bearing_clearance"):
        SpurPair(g, g, 2.5, 0.35, 0.02, (-0.002, 0.03), 0.008)
    with pytest.raises(ParameterError, match="centre_distance_tol"):
        SpurPair(g, g, 2.5, 0.35, -0.02, (0.002, 0.03), 0.008)
    with pytest.raises(ParameterError, match="driving.thickness"):
        SpurPair(SpurGear(28, -0.030, -0.019, 0.027), g, 2.5, 0.35, 0.02, (0.002, 0.03), 0.008)


def test_rayleigh_scale_must_be_positive():
    with pytest.raises(ParameterError, match="scale"):
        Rayleigh(0.0)
    with pytest.raises(ParameterError, match="scale"):
        Rayleigh(-1.0)
    with pytest.raises(ParameterError, match="driven.radial_composite_tol"):
        Rayleigh.from_tolerance(0.0, field="driven.radial_composite_tol")


def test_case_file_bad_inputs_name_the_field():
    import tomllib

    from gearte.cases import case_path
    from gearte.errors import CaseFileError
    from gearte.io.case_file import load_case

    base = tomllib.loads(case_path("jiang2024_spur_pair").read_text())
    bad = dict(base)
    bad["pair"] = {**base["pair"], "bearing_clearance_min_um": -2.0}
    with pytest.raises(CaseFileError, match="bearing_clearance_min_um"):
        load_case(bad)
    bad["pair"] = {
        **base["pair"],
        "driving": {**base["pair"]["driving"], "thickness_lower_um": -10.0},
    }
    with pytest.raises(CaseFileError, match="inverted limits: thickness_lower_um"):
        load_case(bad)
    bad["pair"] = {
        **base["pair"],
        "driven": {**base["pair"]["driven"], "radial_composite_tol_um": 0.0},
    }
    with pytest.raises(CaseFileError, match="radial_composite_tol_um"):
        load_case(bad)


# -- stacks ---------------------------------------------------------------------------------------
def _mixed_stack():
    return LinearStack(
        [
            Contributor("n", Normal.from_limits(-30.0, -19.0), -0.94),
            Contributor("e", RadialPhase(Rayleigh.from_tolerance(27.0)), 0.684),
            Contributor("p", RadialPhase(Rayleigh(3.0), polar=True), 0.5),
            Contributor("u", Uniform(0.0, 1.0), 1.0),
            Contributor("r", Rayleigh(2.0), -1.0),
            Contributor("m", Empirical([1.0, 2.0, 3.0, 5.0]), 2.0),
            Contributor("c", Constant(1.5), 1.0),
        ],
        3.0,
    )


def test_linear_stack_worst_case_rss_statistical():
    st = LinearStack(
        [
            Contributor("a", Normal.from_limits(-1.0, 1.0), 2.0),
            Contributor("b", Uniform(0.0, 4.0), -1.0),
        ],
        10.0,
    )
    assert st.mean == pytest.approx(10.0 - 2.0)
    assert st.variance == pytest.approx(4 * (2 / 6) ** 2 + 16 / 12)
    assert st.worst_case() == pytest.approx((10 - 2 - 4, 10 + 2 - 0))
    half = math.hypot(2.0, 2.0)
    assert st.rss() == pytest.approx((8 - half, 8 + half))
    z = z_for_confidence(0.9973)
    assert z == pytest.approx(3.0, abs=1e-3)
    assert st.statistical_limits(0.9973) == pytest.approx(
        (st.mean - z * st.sd, st.mean + z * st.sd)
    )


def test_function_stack_linearisation_and_mc():
    cs = [Contributor("x", Normal(2.0, 0.1)), Contributor("y", Normal(3.0, 0.2))]
    fs = FunctionStack(lambda v: v["x"] * v["y"], cs, name="xy")
    lin = fs.linearised()
    assert lin.mean == pytest.approx(6.0)
    assert lin.sensitivities == pytest.approx([3.0, 2.0], rel=1e-6)
    r = monte_carlo(fs, 400_000, seed=5, chunk_size=100_000)
    exact_var = (2**2 * 0.2**2) + (3**2 * 0.1**2) + (0.1**2 * 0.2**2)
    assert r.engine == "numpy"
    assert abs(r.mean - 6.0) < 3 * r.std_error
    assert r.sd**2 == pytest.approx(exact_var, rel=0.02)


# -- compiled kernel vs plain reference ---------------------------------------------------
def test_kernel_samples_identical_to_python_loop():
    st = _mixed_stack()
    a = kernel_samples(st, 3, 2000)
    b = linear_stack_reference(st, 3, 2000)
    np.testing.assert_array_equal(a, b)


def test_kernel_reduction_equals_numpy_twin():
    st = _mixed_stack()
    n = 5000
    r = monte_carlo(st, n, seed=9, chunk_size=n, nbins=50, lower_spec=20.0, upper_spec=40.0)
    from gearte.execution import spawn_seeds

    y = linear_stack_reference(st, spawn_seeds(9, 1)[0], n)
    lo, hi = st.mean - 8 * st.sd, st.mean + 8 * st.sd
    twin = reduce_samples(
        y, shift=st.mean, lo=lo, hi=hi, nbins=50, lsl=20.0, usl=40.0, keep=100_000
    )
    assert r.engine == "numba"
    np.testing.assert_array_equal(r.hist_counts, twin.counts)
    assert r.mean == pytest.approx(st.mean + twin.s1 / n, rel=1e-12)
    assert r.min == twin.min and r.max == twin.max
    assert r.below_fraction == twin.below / n and r.above_fraction == twin.above / n
    np.testing.assert_array_equal(r.samples, y)
    np.testing.assert_allclose(r.percentiles[50.0], np.percentile(y, 50), atol=16 * st.sd / 50)


def test_kernel_reduction_exact_with_limits_on_sample_values():
    """The kernel's vectorised reduction against the numpy twin with the spec limits on sample
    values (one sample sits exactly on each limit and must count as in spec): out-of-spec
    counts, extremes and histogram equal, the pairwise block sums to rounding; full blocks and
    a partial one."""
    from gearte.execution import spawn_seeds

    st = spur_pair().backlash_stack()
    n = 3 * 1024 + 77  # full blocks and a partial one
    y = kernel_samples(st, spawn_seeds(5, 1)[0], n)
    lsl, usl = float(np.sort(y)[40]), float(np.sort(y)[-300])
    r = monte_carlo(st, n, seed=5, chunk_size=n, nbins=64, lower_spec=lsl, upper_spec=usl)
    lo, hi = st.mean - 8 * st.sd, st.mean + 8 * st.sd
    twin = reduce_samples(y, shift=st.mean, lo=lo, hi=hi, nbins=64, lsl=lsl, usl=usl, keep=0)
    assert (r.below_fraction * n, r.above_fraction * n) == (twin.below, twin.above) == (40, 299)
    np.testing.assert_array_equal(r.hist_counts, twin.counts)
    assert (r.min, r.max) == (twin.min, twin.max)
    assert r.mean == pytest.approx(st.mean + twin.s1 / n, rel=1e-13)
    assert r.sd == pytest.approx(math.sqrt((twin.s2 - twin.s1**2 / n) / (n - 1)), rel=1e-12)


def test_kernel_int32_counts_flushed_into_int64_equal_the_compiled_kernel(monkeypatch):
    """The kernel counts into int32 and adds them into the int64 totals every ``_FLUSH``
    samples: its plain-Python run with a flush every 1500 samples gives the compiled kernel's
    statistics and histogram exactly (5000 samples: several flushes and a partial block)."""
    import gearte.tolerance.montecarlo as mc
    from gearte.tolerance.rng import lane_states, stream_states

    st = spur_pair().backlash_stack()
    ki = mc._KernelInput.of(st)
    s = stream_states(4)
    lo, hi = st.mean - 8 * st.sd, st.mean + 8 * st.sd
    args = (s, lane_states(s), 5000, *ki.args(), st.mean, lo, hi, 64, st.mean, np.inf, 3)
    compiled = mc._linear_stack_kernel(*args)
    monkeypatch.setattr(mc, "_FLUSH", 1500)
    plain = mc._linear_stack_kernel.py_func(*args)
    assert plain[:6] == compiled[:6]
    np.testing.assert_array_equal(plain[6], compiled[6])
    assert plain[6].sum() == 5000


def _polar(stack):
    cs = [
        Contributor(c.name, RadialPhase(c.distribution.magnitude, polar=True), c.sensitivity)
        if isinstance(c.distribution, RadialPhase)
        else c
        for c in stack.contributors
    ]
    return LinearStack(cs, stack.constant)


def test_rayleigh_phase_normal_identity_in_kernel():
    # the kernel draws r·sin φ of a Rayleigh radius as the equivalent normal; the polar draw
    # (Rayleigh magnitude, uniform phase) must give the same distribution
    st = spur_pair().backlash_stack()
    a = monte_carlo(st, 400_000, seed=3)
    b = monte_carlo(_polar(st), 400_000, seed=3)
    assert abs(a.mean - b.mean) < 4 * math.hypot(a.std_error, b.std_error)
    assert a.sd == pytest.approx(b.sd, rel=0.01)
    xa = kernel_samples(st, 0, 100_000)
    xb = kernel_samples(_polar(st), 1, 100_000)
    assert stats.ks_2samp(xa, xb).pvalue > 1e-3


def test_numpy_engine_agrees_statistically_with_kernel():
    st = _mixed_stack()
    a = monte_carlo(st, 300_000, seed=1, engine="numba")
    b = monte_carlo(st, 300_000, seed=1, engine="numpy")
    se = math.hypot(a.std_error, b.std_error)
    assert abs(a.mean - b.mean) < 4 * se
    assert a.sd == pytest.approx(b.sd, rel=0.01)


# -- Monte-Carlo vs analytic, both paper pairs ----------------------------------------------------
@pytest.mark.parametrize("make", [spur_pair, bevel_pair], ids=["spur", "bevel"])
def test_monte_carlo_agrees_with_analytic_stack(make):
    pair = make()
    st = pair.backlash_stack()
    r = monte_carlo(st, 1_000_000, seed=2024, lower_spec=pair.min_backlash_limit)
    assert r.n == 1_000_000 and r.engine == "numba"
    assert abs(r.mean - st.mean) < 3 * r.std_error
    assert r.sd == pytest.approx(st.sd, rel=0.02)
    # percentiles of a (nearly) normal stack sit at mean ∓ 3σ
    assert r.percentiles[0.135] == pytest.approx(st.mean - 3 * st.sd, abs=0.1 * st.sd)
    assert r.percentiles[99.865] == pytest.approx(st.mean + 3 * st.sd, abs=0.1 * st.sd)
    assert r.cpk == pytest.approx((st.mean - pair.min_backlash_limit) / (3 * st.sd), rel=0.02)


def test_seed_reproducible_and_worker_independent():
    from gearte.studies import RunOptions

    st = spur_pair().backlash_stack()
    a = monte_carlo(st, 200_000, seed=7, chunk_size=50_000, options=RunOptions(workers=1))
    b = monte_carlo(st, 200_000, seed=7, chunk_size=50_000, options=RunOptions(workers=2))
    c = monte_carlo(st, 200_000, seed=8, chunk_size=50_000)
    assert (a.mean, a.sd, a.min, a.max) == (b.mean, b.sd, b.min, b.max)
    np.testing.assert_array_equal(a.hist_counts, b.hist_counts)
    assert a.mean != c.mean


def test_memory_bounded_kept_samples():
    st = spur_pair().backlash_stack()
    r = monte_carlo(st, 300_000, seed=1, chunk_size=100_000, keep=1000)
    assert r.samples.size == 1000 and r.n == 300_000
    assert r.hist_counts.sum() == 300_000


def test_out_of_spec_and_capability():
    st = LinearStack([Contributor("z", Normal(0.0, 1.0))])
    r = monte_carlo(st, 1_000_000, seed=4, lower_spec=-2.0, upper_spec=2.0)
    p = 2 * stats.norm.sf(2.0)
    assert r.out_of_spec_fraction == pytest.approx(p, abs=4 * math.sqrt(p / 1e6))
    assert r.cp == pytest.approx(4 / 6, rel=0.01)
    assert process_capability(1.0, 1.0, None, 4.0) == (None, pytest.approx(1.0))
    with pytest.raises(ParameterError, match="spec"):
        monte_carlo(st, 100, lower_spec=1.0, upper_spec=0.0)
    with pytest.raises(ParameterError, match="samples"):
        monte_carlo(st, 1)


# -- contributions --------------------------------------------------------------------------------
def test_sobol_on_interaction_model():
    # y = 2 x1 + x2 x3 with standard normals: V = 4 + 1, S1 = 0.8, S2 = S3 = 0, ST2 = ST3 = 0.2
    cs = [Contributor(n, Normal(0.0, 1.0)) for n in ("x1", "x2", "x3")]
    fs = FunctionStack(lambda v: 2 * v["x1"] + v["x2"] * v["x3"], cs)
    s = sobol_indices(fs, 40_000, seed=2)
    assert s.first_order["x1"] == pytest.approx(0.8, abs=0.03)
    assert s.first_order["x2"] == pytest.approx(0.0, abs=0.03)
    assert s.total["x2"] == pytest.approx(0.2, abs=0.02)
    assert s.total["x3"] == pytest.approx(0.2, abs=0.02)


def test_variance_shares_and_pareto():
    st = LinearStack([Contributor("a", Normal(0, 1.0), 1.0), Contributor("b", Normal(0, 1.0), 2.0)])
    sh = variance_shares(st)
    assert sh == pytest.approx({"a": 0.2, "b": 0.8})
    assert [p[0] for p in pareto(sh)] == ["b", "a"]
    with pytest.raises(ParameterError, match="zero variance"):
        variance_shares(LinearStack([Contributor("c", Constant(1.0))]))


def test_nonlinear_spur_model_as_function_stack():
    # eqs. 2-13 with eccentricity magnitudes and phases as separate contributors: a nonlinear
    # stack. MC must agree with the linear stack. Sobol: E[e sin φ | e] = 0, so e alone has no
    # first-order effect; E[e sin φ | φ] = σx√(π/2) sin φ, so φ alone explains π/4 of the pair's
    # share; the rest is interaction
    from gearte.models.backlash import spur_normal_backlash

    p = spur_pair()
    a = p.pressure_angle
    g1, g2 = p.driving, p.driven
    phase = Uniform(0.0, 2 * math.pi)
    cs = [
        Contributor("dEs1", Normal.from_limits(g1.thickness_lower, g1.thickness_upper)),
        Contributor("dEs2", Normal.from_limits(g2.thickness_lower, g2.thickness_upper)),
        Contributor("dfa", Normal.from_tolerance(p.centre_distance_tol)),
        Contributor("e1", Rayleigh.from_tolerance(g1.radial_composite_tol)),
        Contributor("phi1", phase),
        Contributor("e2", Rayleigh.from_tolerance(g2.radial_composite_tol)),
        Contributor("phi2", phase),
        Contributor("db", Normal.from_limits(*p.bearing_clearance)),
        Contributor("S", Rayleigh.from_tolerance(p.runout)),
        Contributor("phib", phase),
    ]
    fs = FunctionStack(lambda v: spur_normal_backlash(**v, alpha=a), cs, name="spur jn")
    lin = p.backlash_stack()
    r = monte_carlo(fs, 400_000, seed=12, chunk_size=100_000)
    assert abs(r.mean - lin.mean) < 3 * r.std_error
    assert r.sd == pytest.approx(lin.sd, rel=0.02)
    s = sobol_indices(fs, 20_000, seed=1)
    assert s.first_order["e2"] == pytest.approx(0.0, abs=0.03)
    share_e2 = variance_shares(lin)["driven gear eccentricity"]
    assert s.first_order["phi2"] == pytest.approx(math.pi / 4 * share_e2, abs=0.03)
    # total indices: ST_φ = E[e²]/2 / σx² · share = share; ST_e = E[sin²φ]·Var(e)/σx² · share
    assert s.total["phi2"] == pytest.approx(share_e2, abs=0.03)
    assert s.total["e2"] == pytest.approx((1 - math.pi / 4) * share_e2, abs=0.02)
    assert s.first_order["dfa"] == pytest.approx(variance_shares(lin)["centre distance"], abs=0.03)


def test_kernel_draws_one_normal_per_sample_for_the_gaussian_group():
    """Independent normal contributors are summed exactly into one normal: a stack of normals
    (and Rayleigh x uniform-phase terms, their exact normal equivalent) costs one standard
    normal per sample, with the group's mean Σ s μ and standard deviation sqrt(Σ (s σ)²)."""
    st = spur_pair().backlash_stack()
    codes, params, sens, _ = st.kernel_arrays()
    assert set(codes.tolist()) <= {0, 3}
    y = kernel_samples(st, 11, 10_000)
    z = standard_normals(11, 10_000)
    np.testing.assert_allclose(y, st.mean + st.sd * z, rtol=0, atol=1e-12 * st.sd)


def test_grouped_normal_draw_matches_per_contributor_numpy_draws():
    """The grouped kernel draw and the numpy engine's contributor-by-contributor draws give the
    same distribution for a mixed stack (two-sample KS, 200 000 samples each)."""
    st = _mixed_stack()
    a = kernel_samples(st, 21, 200_000)
    b = st.sample(np.random.default_rng(22), 200_000)
    assert stats.ks_2samp(a, b).pvalue > 1e-3


def test_kernel_moments_of_a_mixed_stack_match_the_closed_form():
    """Every law the kernel draws outside the Gaussian group (uniform, Rayleigh, polar
    Rayleigh × sin(uniform phase), empirical resampling, constant) and the group itself: the
    Monte-Carlo mean and variance of the mixed stack over 2·10⁶ samples match the exact
    ``Σ sᵢ μᵢ + c`` and ``Σ sᵢ² σᵢ²`` within 5 standard errors (the variance's from the
    sample fourth moment)."""
    st = _mixed_stack()
    n = 2_000_000
    y = kernel_samples(st, 17, n)
    d = y - st.mean
    m4 = float(np.mean(d**4))
    var = float(np.var(y))
    assert abs(y.mean() - st.mean) < 5 * math.sqrt(st.sd**2 / n)
    assert abs(var - st.sd**2) < 5 * math.sqrt((m4 - var**2) / n)
    r = monte_carlo(st, n, seed=17, chunk_size=500_000)
    assert abs(r.mean - st.mean) < 5 * r.std_error
    assert abs(r.sd**2 - st.sd**2) < 5 * math.sqrt((m4 - var**2) / n)


def test_kernel_specialisation_without_other_draws_only_for_all_normal_stacks():
    """An all-normal stack (the Jiang 2024 spur pair) passes ``others=None`` to the kernel — a
    specialisation compiled without the other laws' draws (docs/numba.md) — and gives the same
    samples as the same stack with a zero constant contributor added, which runs the general
    specialisation (a constant adds ``0.0`` to each sample, exactly); ``compile_general_kernel``
    (run by ``gearte warm-cache``) compiles the general one for a stack with a uniform term."""
    import gearte.tolerance.montecarlo as mc

    st = spur_pair().backlash_stack()
    assert mc._KernelInput.of(st).args()[6] is None
    with_zero = LinearStack([*st.contributors, Contributor("zero", Constant(0.0), 1.0)])
    assert mc._KernelInput.of(with_zero).args()[6].tolist() == [len(st.contributors)]
    np.testing.assert_array_equal(kernel_samples(st, 8, 3000), kernel_samples(with_zero, 8, 3000))
    mc.compile_general_kernel()
    general = [s for s in mc._linear_stack_kernel.signatures if "none" not in str(s[9]).lower()]
    assert general and all(s == general[0] for s in general)
