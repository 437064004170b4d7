"""The generic production-yield engine: tolerance laws, yield with CI, Cpk, worst samples,
Sobol indices, linear prediction and allocation, on models whose answers are known."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy import stats

from gearte.errors import ParameterError
from gearte.tolerance.allocation import CostModel, allocate
from gearte.tolerance.yield_contributions import linear_prediction, sobol_tolerances
from gearte.tolerance.yield_mc import (
    CorrelatedGroup,
    SpecLimit,
    Tolerance,
    ToleranceSet,
    clopper_pearson_interval,
    redraw_sample,
    run_yield,
    wilson_interval,
)


class Linear:
    """y = 2 a + 3 b + 1 (picklable model)."""

    def __call__(self, e):
        return {"y": 2.0 * e["a"] + 3.0 * e["b"] + 1.0}


class Product:
    """y = a·b: no first-order effect of either, total 1 each (Sobol 1993 textbook case)."""

    def __call__(self, e):
        return {"y": e["a"] * e["b"]}


class Smooth:
    """A non-linear but smooth model with a radial error (eccentricity with phase)."""

    def __call__(self, e):
        ecc = e["ecc"] * np.cos(e["ecc_phase_rad"] + 0.3)
        return {
            "y": np.sin(1.0 + e["a"]) + 0.5 * (e["b"] + 2.0) ** 2 + 4.0 * ecc,
            "ecc_x": e["ecc"] * np.cos(e["ecc_phase_rad"]),
        }


def _lin_set(ta=0.03, tb=0.02):
    return ToleranceSet(
        (Tolerance("a", "normal", ta), Tolerance("b", "normal", tb)),
    )


def test_zero_tolerances_give_the_deterministic_value_exactly():
    r = run_yield(
        Smooth(),
        ToleranceSet(
            (
                Tolerance("a", "normal", 0.0),
                Tolerance("b", "uniform", 0.0),
                Tolerance("ecc", "rayleigh", 0.0, phase=True),
            )
        ),
        [SpecLimit("y", upper=10.0)],
        1000,
        seed=3,
        chunk_size=300,
    )
    expected = math.sin(1.0) + 0.5 * 4.0
    st = r.quantities["y"].stats
    assert st.min == expected and st.max == expected
    assert r.yield_ == 1.0


def test_yield_of_a_linear_stack_matches_the_normal_probability():
    """y ~ N(1, (2·0.01)² + (3·0.02/3)²); spec y ≤ 1.03: P = Φ(0.03/σ)."""
    sd = math.hypot(2 * 0.01, 3 * 0.02 / 3)
    r = run_yield(Linear(), _lin_set(), [SpecLimit("y", upper=1.03)], 40_000, seed=1)
    p = stats.norm.cdf(0.03 / sd)
    assert r.ci[0] <= p <= r.ci[1]
    assert r.quantities["y"].stats.sd == pytest.approx(sd, rel=0.02)
    assert r.cpk == pytest.approx(0.03 / (3 * sd), rel=0.03)


def test_worst_samples_are_reproducible_from_seed_and_index():
    ts = _lin_set()
    r = run_yield(Linear(), ts, [SpecLimit("y", -1, 1.02)], 5000, seed=9, chunk_size=700)
    assert len(r.worst) == 5
    assert r.worst[0]["margin"] <= r.worst[-1]["margin"]
    for w in r.worst:
        again = redraw_sample(ts, 9, 700, w["sample"], 5000)
        assert again == w["errors"]
        assert Linear()(again)["y"] == pytest.approx(w["values"]["y"])


def test_same_result_on_one_thread_and_two_threads():
    ts = _lin_set()
    spec = [SpecLimit("y", upper=1.03)]

    class Opt:
        def __init__(self, w):
            self.workers, self.scheduler, self.progress = w, None, False

    a = run_yield(Linear(), ts, spec, 9000, seed=4, chunk_size=1000, options=Opt(1))
    b = run_yield(Linear(), ts, spec, 9000, seed=4, chunk_size=1000, options=Opt(2))
    assert a.passed == b.passed
    assert a.quantities["y"].stats.as_tuple() == b.quantities["y"].stats.as_tuple()
    assert a.worst == b.worst


def test_tolerance_laws_have_their_stated_sigma():
    rng = np.random.default_rng(0)
    z = rng.standard_normal(200_000)
    cases = [
        (Tolerance("x", "normal", 0.03), 0.01),
        (Tolerance("x", "uniform", 0.03), 0.03 / math.sqrt(3)),
        (Tolerance("x", "truncated_normal", 0.03, sigmas=2.0), None),
        (Tolerance("x", "rayleigh", 0.03), None),
        (Tolerance("x", "empirical", 0.03, values=(-0.03, -0.01, 0.0, 0.02)), None),
    ]
    for t, sd in cases:
        v = t.transform(z)
        assert np.std(v) == pytest.approx(t.sd, rel=0.01), t.kind
        if sd is not None:
            assert t.sd == pytest.approx(sd)
    ray = Tolerance("x", "rayleigh", 0.03).transform(z)
    assert np.mean(ray <= 0.03) == pytest.approx(0.9973, abs=0.001)  # the tolerance is 99.73 %
    tr = Tolerance("x", "truncated_normal", 0.03, sigmas=2.0).transform(z)
    assert tr.min() >= -0.03 and tr.max() <= 0.03


def test_correlated_group_has_the_stated_correlation():
    ts = ToleranceSet(
        tuple(Tolerance(f"p{i}", "normal", 0.01) for i in range(3)),
        groups=(CorrelatedGroup("batch", ("p0", "p1"), 0.6),),
    )
    e = ts.sample(np.random.default_rng(2), 100_000)
    assert np.corrcoef(e["p0"], e["p1"])[0, 1] == pytest.approx(0.6, abs=0.01)
    assert abs(np.corrcoef(e["p0"], e["p2"])[0, 1]) < 0.01
    assert np.std(e["p0"]) == pytest.approx(0.01 / 3, rel=0.01)


def test_binomial_intervals_textbook_values():
    """Wilson 95 % of 81/263: (0.2553, 0.3662) and Clopper–Pearson of 0/10: (0, 0.3085)."""
    lo, hi = wilson_interval(81, 263)
    assert (lo, hi) == pytest.approx((0.2553, 0.3662), abs=1e-4)
    assert clopper_pearson_interval(0, 10) == pytest.approx((0.0, 0.3085), abs=1e-4)


def test_sobol_of_a_linear_model_equals_the_variance_shares():
    r = sobol_tolerances(Linear(), _lin_set(), ["y"], n=4000, seed=1, bootstrap=100)["y"]
    va, vb = (2 * 0.01) ** 2, (3 * 0.02 / 3) ** 2
    for k, share in (("a", va / (va + vb)), ("b", vb / (va + vb))):
        assert r.first_ci[k][0] - 0.02 <= share <= r.first_ci[k][1] + 0.02
        assert r.total[k] == pytest.approx(share, abs=0.03)


class OffsetLinear:
    """y = 2 a + 3 b + 1000: a mean ~10⁵ σ away from zero (a joint's lost motion beside its
    small spread)."""

    def __call__(self, e):
        return {"y": 2.0 * e["a"] + 3.0 * e["b"] + 1000.0}


def test_sobol_first_order_does_not_depend_on_the_quantitys_mean():
    """The first-order estimator is centred (Saltelli 2010): adding 1000 to a linear model with
    σ_y ≈ 0.02 changes its indices by round-off only, not by the mean's sampling noise."""
    ts = _lin_set()
    r0 = sobol_tolerances(Linear(), ts, ["y"], n=2000, seed=3, bootstrap=0)["y"]
    r1 = sobol_tolerances(OffsetLinear(), ts, ["y"], n=2000, seed=3, bootstrap=0)["y"]
    for k in ("a", "b"):
        assert r1.first[k] == pytest.approx(r0.first[k], abs=1e-6)
        assert r1.total[k] == pytest.approx(r0.total[k], abs=1e-6)


def test_sobol_of_a_product_is_all_interaction():
    r = sobol_tolerances(Product(), _lin_set(0.03, 0.03), ["y"], n=4000, seed=2)["y"]
    for k in ("a", "b"):
        assert abs(r.first[k]) < 0.06
        assert r.total[k] == pytest.approx(1.0, abs=0.08)


def test_small_tolerances_mc_sigma_within_3_percent_of_first_order_prediction():
    ts = ToleranceSet(
        (
            Tolerance("a", "normal", 0.003),
            Tolerance("b", "uniform", 0.002),
            Tolerance("ecc", "rayleigh", 0.002, phase=True),
        )
    )
    lin = linear_prediction(Smooth(), ts, ["y"])["y"]
    r = run_yield(Smooth(), ts, [], 40_000, seed=5)
    assert r.quantities["y"].stats.sd == pytest.approx(lin.sd, rel=0.03)
    assert sum(lin.share.values()) == pytest.approx(1.0)


def test_allocation_meets_target_in_a_fresh_run_and_is_locally_optimal():
    ts = _lin_set(0.05, 0.05)
    spec = [SpecLimit("y", 0.95, 1.05)]
    costs = {"a": CostModel(1.0, 0.02, 1.0), "b": CostModel(1.0, 0.01, 1.0)}
    al = allocate(Linear(), ts, spec, costs, 0.99, n=6000, seed=3, verify_n=20_000)
    assert al.verified.seed != 3
    assert al.verified.yield_ >= 0.99
    assert al.locally_optimal
    for k, y in al.loosening_yields.items():
        assert y is None or wilson_interval(round(y * 6000), 6000)[0] < 0.99, k


def test_bad_inputs_name_the_field():
    with pytest.raises(ParameterError, match="a.kind"):
        Tolerance("a", "gauss", 0.1)
    with pytest.raises(ParameterError, match="b.tolerance"):
        Tolerance("b", "normal", -1.0)
    with pytest.raises(ParameterError, match="spec.y"):
        SpecLimit("y")
    with pytest.raises(ParameterError, match="spec.z"):
        run_yield(Linear(), _lin_set(), [SpecLimit("z", upper=1.0)], 10)


class SumOfFour:
    """y = p1 + p2 + p3 + q: a family 'pins' of three errors and one other error."""

    def __call__(self, e):
        return {"y": e["p1"] + e["p2"] + e["p3"] + e["q"]}


def test_family_sobol_and_linear_share_group_members_and_groups_name_families():
    pins = tuple(Tolerance(f"p{i}", "normal", 0.03, family="pins") for i in (1, 2, 3))
    ts = ToleranceSet(pins + (Tolerance("q", "normal", 0.03),))
    r = sobol_tolerances(SumOfFour(), ts, ["y"], n=4000, seed=3, bootstrap=0)["y"]
    assert set(r.total) == {"pins", "q"}
    assert r.total["pins"] == pytest.approx(0.75, abs=0.04)  # 3 σ² of 4 σ²
    lin = linear_prediction(SumOfFour(), ts, ["y"])["y"]
    assert lin.share == pytest.approx({"pins": 0.75, "q": 0.25})
    # one ground batch: the family as a correlated group; widths set per family
    grouped = ToleranceSet(ts.tolerances, (CorrelatedGroup("batch", ("pins",), 1.0),))
    e = grouped.sample(np.random.default_rng(1), 1000)
    assert np.array_equal(e["p1"], e["p3"])
    assert grouped.with_tolerances({"pins": 0.06})["p2"].tolerance == 0.06


def test_chunk_result_is_o1_in_samples_past_the_kept_head():
    """Issue 14, bounded memory: a chunk past the run's first ``keep_head`` samples returns
    counts, moment sums and its ``keep_worst`` worst samples only — the same size (pickled, as
    Dask ships it) for 100 or 20 000 samples; the head is still the run's first samples."""
    import pickle

    from gearte.execution import seeded_chunks
    from gearte.tolerance.yield_mc import _chunk, _Shared

    ts = _lin_set()
    spec = (SpecLimit("y", upper=1.03),)
    sizes = {}
    for n in (100, 20_000):
        shared = _Shared(Linear(), ts, spec, 3, 50, {"y": 0.03}, n)
        late = seeded_chunks(3 * n, n, 1)[2]  # starts past the 50 kept samples
        p = _chunk(late, shared)
        assert p.n == n and p.head["y"].size == 0 and len(p.worst) == 3
        sizes[n] = len(pickle.dumps(p))
    assert sizes[20_000] <= sizes[100] + 64  # (row indices pickle in a few more bytes)
    r = run_yield(Linear(), ts, list(spec), 1000, seed=2, chunk_size=30, keep_head=50)
    first = ts.sample(seeded_chunks(1000, 30, 2)[0].rng(), 30)
    assert r.head["y"].size == 50
    np.testing.assert_array_equal(r.head["y"][:30], Linear()(first)["y"])
