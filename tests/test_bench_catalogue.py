"""One definition per catalogue quantity (issue 17 item 2): the virtual test and a measured file
give the same numbers when fed the same curve; the definitions on curves with known answers."""

from __future__ import annotations

import numpy as np
import pytest

from gearte.errors import ParameterError
from gearte.io.bench import HysteresisCurve, read_hysteresis, write_hysteresis
from gearte.io.case_file import load_case
from gearte.models.catalogue import (
    branch_directions,
    forward_backward_difference,
    hysteresis_values,
    hysteresis_values_many,
    split_branches,
    te_peak_to_peak,
    torsional_rigidity_error,
)
from gearte.models.rv_catalogue import catalogue_values
from gearte.studies.rv_reducer import build_reducer

TR = 784e3  # [N·mm]


def _loop(k=1e6, play=2e-4, friction=5e-5, n=101, virgin=True):
    """Analytic loop: θ = T/k ± play/2 (sign of T) ∓ friction/2 (rising/falling torque)."""
    down = np.linspace(TR, -TR, n)
    up = down[::-1]
    parts_t = [np.linspace(0, TR, n)[1:]] if virgin else []
    t = np.concatenate([*parts_t, down, up])
    d = np.concatenate([*(np.ones(n - 1),) * virgin, -np.ones(n), np.ones(n)]).astype(int)
    ang = t / k + 0.5 * play * np.where(t > 0, 1, np.where(t < 0, -1, -d)) - 0.5 * friction * d
    return t, ang, d


def test_definitions_on_an_analytic_loop():
    k, play, fr = 1.2e6, 2e-4, 5e-5
    t, a, _ = _loop(k, play, fr)
    hv = hysteresis_values(t, a, TR)
    assert hv.torsional_rigidity == pytest.approx(k, rel=1e-12)
    assert hv.lost_motion == pytest.approx(0.06 * TR / k + play, rel=1e-12)
    # loop width at zero = play + friction width; backlash = that less the width at ±T_r/2
    assert hv.hysteresis_loss == pytest.approx(play + fr, rel=1e-9)
    assert hv.backlash == pytest.approx(play, rel=1e-9)
    hv5 = hysteresis_values(t, a, TR, lost_motion_fraction=0.05)
    assert hv5.lost_motion == pytest.approx(0.10 * TR / k + play, rel=1e-12)


def test_many_curves_at_once_equal_one_curve_at_a_time():
    """hysteresis_values_many (the batched yield read-out) gives each curve's
    hysteresis_values: loops of different rigidity, play and friction on one torque grid, a
    short sweep (read at its own peak) and a marked branch order."""
    rng = np.random.default_rng(4)
    ks, plays, fr = rng.uniform(0.8e6, 1.5e6, 5), rng.uniform(0, 3e-4, 5), rng.uniform(0, 8e-5, 5)
    curves = [_loop(k, p, f, n=37) for k, p, f in zip(ks, plays, fr, strict=True)]
    t, _, d = curves[0]
    angles = np.array([c[1] for c in curves])
    for torque, direction in ((t, None), (0.985 * t, d)):
        many = hysteresis_values_many(torque, angles, TR, direction=direction,
                                      lost_motion_fraction=0.05)  # fmt: skip
        for i, a in enumerate(angles):
            one = hysteresis_values(torque, a, TR, direction=direction, lost_motion_fraction=0.05)
            for name in ("torsional_rigidity", "lost_motion", "backlash", "hysteresis_loss"):
                assert many[name][i] == pytest.approx(getattr(one, name), rel=1e-12, abs=1e-18)


def test_branch_inference_matches_marked_branches_with_noisy_torque():
    t, a, d = _loop()
    rng = np.random.default_rng(1)
    noisy = t + rng.normal(0, 2e-3 * TR, t.size)
    inferred = branch_directions(noisy)
    # away from the two turning points every sample gets its marked branch
    assert np.mean(inferred == d) > 0.97
    b1 = split_branches(t, a, TR, d)
    b2 = split_branches(t, a, TR)
    np.testing.assert_array_equal(b1.asc_angle, b2.asc_angle)


def test_sweep_short_of_rated_torque_is_a_named_error():
    t, a, _ = _loop()
    with pytest.raises(ValueError, match="rated torque"):
        hysteresis_values(0.5 * t, a, TR)
    # a peak 1 % short of T_r is read at its own peak (no extrapolation)
    hv = hysteresis_values(0.99 * t, a * 0.99, TR)
    assert hv.torsional_rigidity == pytest.approx(1e6, rel=1e-9)


def test_te_peak_to_peak_and_forward_backward_difference():
    pos = np.linspace(0, 2 * np.pi, 400, endpoint=False)
    fwd = 1e-5 * np.sin(3 * pos)
    bwd_pos = pos[::-1] + 0.5 * (pos[1] - pos[0])
    bwd = 1e-5 * np.sin(3 * bwd_pos) - 4e-5
    assert te_peak_to_peak(fwd) == pytest.approx(2e-5, rel=1e-3)
    diff = forward_backward_difference(pos, fwd, bwd_pos, bwd)
    assert diff.mean() == pytest.approx(4e-5, rel=1e-3)
    assert np.ptp(diff) < 2e-7


@pytest.fixture(scope="module")
def rv80e():
    return build_reducer(load_case("hu2020_rv80e_initial_reducer").reducer)


def test_virtual_test_and_measured_file_give_the_same_catalogue_numbers(rv80e, tmp_path):
    """The virtual loop written as a bench file and read back: same numbers to 1e-9."""
    cat = catalogue_values(rv80e, lost_motion_fraction=0.05)
    curve = HysteresisCurve("virtual", cat.loop.torque, cat.loop.angle, cat.loop_direction)
    for marked in (True, False):  # marked branches, and branches inferred from the torque
        p = tmp_path / f"virtual_{marked}.csv"
        write_hysteresis(p, curve, with_branch=marked)
        meas = read_hysteresis(p)
        hv = hysteresis_values(
            meas.torque, meas.angle, rv80e.rated_torque, direction=meas.branch,
            lost_motion_fraction=0.05,
        )  # fmt: skip
        assert hv.torsional_rigidity == pytest.approx(cat.torsional_rigidity, rel=1e-9)
        for name in ("lost_motion", "backlash", "hysteresis_loss"):
            assert getattr(hv, name) == pytest.approx(getattr(cat, name), rel=1e-9, abs=1e-15)
    assert cat.backlash > 0 and cat.hysteresis_loss == pytest.approx(cat.backlash, rel=1e-6)


def test_rigidity_standard_error_matches_the_scatter_of_noisy_sweeps():
    """torsional_rigidity_error (linear propagation of the readings' angle and torque noise
    through the definition) against the scatter of the definition over 400 noisy copies of a
    stiffening loop (θ ∝ T^0.9, play, friction): within 12 % (the Monte-Carlo sd of a sd from 400
    draws is 3.5 %); with the torque noise left out of the propagation it is too small."""
    rng = np.random.default_rng(7)
    n = 121
    t = np.concatenate([np.linspace(TR, -TR, n), np.linspace(-TR, TR, n)])
    d = np.concatenate([-np.ones(n), np.ones(n)]).astype(int)
    u = t + d * 0.01 * TR  # friction: the reducer sees T ∓ T_fr

    def angle(torque):
        return 2e-3 * np.sign(torque) * np.abs(torque / TR) ** 0.9 + 1e-4 * np.tanh(torque / 1e3)

    sig_a, sig_t = 2e-6, 2e-3 * TR  # torque noise chosen large enough to matter
    ks = []
    for _ in range(400):
        noisy_t = t + rng.normal(0.0, sig_t, t.size)
        ks.append(hysteresis_values(noisy_t, angle(u) + rng.normal(0.0, sig_a, t.size), TR,
                                    direction=d).torsional_rigidity)  # fmt: skip
    se = torsional_rigidity_error(t, angle(u), TR, sig_a, torque_std=sig_t, direction=d)
    assert se == pytest.approx(np.std(ks), rel=0.12)
    assert torsional_rigidity_error(t, angle(u), TR, sig_a, direction=d) < 0.85 * np.std(ks)
    with pytest.raises(ParameterError, match="angle_std"):
        torsional_rigidity_error(t, angle(u), TR, -1.0)
