"""Property-based checks of the stack and chain algebra (hypothesis)."""

from __future__ import annotations

import math

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from gearte.models.lost_motion import (
    chain_lost_motion,
    motor_ratios,
    shim_backlash_reduction,
    shim_thickness,
    stage_transfer_factors,
)
from gearte.tolerance.contributions import variance_shares
from gearte.tolerance.distributions import Normal, Uniform
from gearte.tolerance.stackup import Contributor, LinearStack

finite = st.floats(-100, 100, allow_nan=False)
positive = st.floats(0.01, 50, allow_nan=False)


@st.composite
def stacks(draw):
    k = draw(st.integers(1, 6))
    cs = []
    for i in range(k):
        lo = draw(finite)
        w = draw(positive)
        d = Normal.from_limits(lo, lo + w) if draw(st.booleans()) else Uniform(lo, lo + w)
        cs.append(Contributor(f"c{i}", d, draw(st.floats(-5, 5).filter(lambda x: abs(x) > 1e-3))))
    return LinearStack(cs, draw(finite))


@settings(max_examples=60, deadline=None)
@given(stacks())
def test_shares_sum_to_one_and_rss_inside_worst_case(s):
    assert math.isclose(sum(variance_shares(s).values()), 1.0, rel_tol=1e-12)
    wlo, whi = s.worst_case()
    rlo, rhi = s.rss()
    assert wlo <= rlo + 1e-9 and rhi <= whi + 1e-9
    assert wlo <= s.mean <= whi


@settings(max_examples=60, deadline=None)
@given(st.lists(st.floats(0.1, 200), min_size=1, max_size=6), st.data())
def test_chain_is_linear_and_transfer_consistent(ratios, data):
    n = len(ratios)
    e = np.array(data.draw(st.lists(st.floats(0, 1e-2), min_size=n, max_size=n)))
    f = stage_transfer_factors(ratios)
    m = motor_ratios(ratios)
    # a stage's error seen at the joint times the whole chain's ratio = seen at the motor
    assert np.allclose(f * np.prod(ratios), m)
    assert math.isclose(
        float(chain_lost_motion(2 * e, ratios)),
        2 * float(chain_lost_motion(e, ratios)),
        rel_tol=1e-12,
        abs_tol=1e-18,
    )
    assert math.isclose(f[-1], 1.0)


@settings(max_examples=60, deadline=None)
@given(st.floats(0.02, 0.2), st.floats(0.001, 0.019), st.floats(0.2, 0.6))
def test_shim_undoes_the_requested_reduction(current, target, alpha):
    t = shim_thickness(current, target, alpha)
    assert math.isclose(float(shim_backlash_reduction(t, alpha)), current - target, rel_tol=1e-12)
