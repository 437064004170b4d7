"""Load series (TE traces against torque) → rigidity, lost motion, hysteresis, backlash with
intervals, per speed and oil temperature; the definitions of gearte.models.catalogue."""

from __future__ import annotations

import json

import numpy as np
import pytest

from gearte.errors import ParameterError
from gearte.models.catalogue import load_series_values
from gearte.models.orders import mean_standard_error, order_spectrum
from gearte.studies import RunOptions, run_case
from gearte.units import arcsec_to_rad

NAMES = ("bench_torsional_rigidity [N*m/arcmin]", "bench_lost_motion [arcmin]",
         "bench_hysteresis [arcmin]", "bench_backlash [arcmin]")  # fmt: skip


def test_linear_running_curve_gives_back_its_constants():
    """D = b + 2 T/K (play b, linear stiffness K): the definitions return K, b + 2 f T_r/K, b, b."""
    tr, k, b, f = 784e3, 1.2e8, 3e-4, 0.03
    t = np.array([0.0, f * tr, 100e3, 0.5 * tr, tr])
    v = load_series_values(t, b + 2 * t / k, tr, lost_motion_fraction=f)
    assert v.torsional_rigidity == pytest.approx(k, rel=1e-12)
    assert v.lost_motion == pytest.approx(b + 2 * f * tr / k, rel=1e-12)
    assert v.hysteresis == pytest.approx(b, rel=1e-12)
    assert v.backlash == pytest.approx(b, rel=1e-9)
    assert v.interpolated == () and v.missing == {}


def test_a_series_short_of_the_needed_torques_says_what_is_missing():
    tr = 784e3
    t = np.array([100e3, 200e3, 300e3])
    v = load_series_values(t, 1e-4 + t / 1e8, tr)
    assert np.isnan(v.lost_motion) and np.isnan(v.hysteresis)
    assert "lost_motion" in v.missing and "hysteresis" in v.missing
    assert v.rigidity_range == (150e3, 300e3)  # read at its own peak, nothing extrapolated
    with pytest.raises(ParameterError):
        load_series_values([-1.0, 2.0], [0.0, 1.0], tr)


def test_mean_standard_error_from_the_noise_floor():
    rng = np.random.default_rng(3)
    n, sigma = 4000, arcsec_to_rad(0.3)
    pos = 2 * np.pi * np.arange(n) / n
    est = []
    for _ in range(40):
        te = 1e-5 * np.cos(40 * pos) + rng.normal(0, sigma, n)
        _, amp, _ = order_spectrum(pos, te)
        est.append(mean_standard_error(amp))
    assert np.mean(est) == pytest.approx(sigma / np.sqrt(n), rel=0.05)


def test_bundled_series_gives_the_catalogue_names_per_speed_and_temperature():
    """The bundled SYNTHETIC series (examples/synthetic_rv_bench, truth.json from the script
    that generated it): every (speed, temperature) series carries the four quantities with
    their intervals, and each lies within 3 half-widths of the known value."""
    from gearte.cases import case_path

    res = run_case("synthetic_rv_bench", RunOptions(progress=False)).to_dict()
    rows = res["analyses"]["load_series"]["values"]["series"]
    truth_path = case_path("synthetic_rv_bench").parent / "synthetic_rv_bench" / "truth.json"
    truth = json.loads(truth_path.read_text(encoding="utf-8"))["load_series"]
    assert len(rows) == 4 == len(truth)
    for row in rows:
        want = next(t for t in truth if t["speed [rpm]"] == row["speed [rpm]"]
                    and t["oil_temperature [°C]"] == row["oil_temperature [°C]"])  # fmt: skip
        for name in NAMES:
            base, unit = name.split(" ")
            lo, hi = row[f"{base}_ci_low {unit}"], row[f"{base}_ci_high {unit}"]
            assert lo < row[name] < hi
            assert abs(row[name] - want[name]) <= 3 * 0.5 * (hi - lo), (name, row, want)
        assert row["interpolated"] == []
    # the trend the synthetic truth carries: more running friction in cold oil
    cold = [r for r in rows if r["oil_temperature [°C]"] == 20.0]
    warm = [r for r in rows if r["oil_temperature [°C]"] == 40.0]
    assert min(r[NAMES[2]] for r in cold) > max(r[NAMES[2]] for r in warm)


def _series(rng, tr, samples=2000):
    """A synthetic brake series: running curve θ(T) = (b/2) tanh((T + T_run)/T_b) + c (T+T_run)^0.9
    with noise 0.3″ and 2^21-count quantisation; returns torques, traces and the exact values."""
    b, t_run, t_b, c = arcsec_to_rad(70.0), 8e3, 3e3, 2.2e-9 * 784e3**0.1
    q = 2 * np.pi / 2**21

    def theta(t):
        return 0.5 * b * np.tanh((t + t_run) / t_b) + c * (t + t_run) ** 0.9

    torques = np.array([0.0, 0.03 * tr, 100e3, 0.5 * tr, 0.75 * tr, tr])
    pos = 2 * np.pi * np.arange(samples) / samples
    d_est, se = [], []
    for t in torques:
        means, ses = [], []
        for d in (1, -1):
            te = 3e-5 + d * theta(t) + 2e-5 * np.cos(40 * pos + d) + rng.normal(
                0, arcsec_to_rad(0.3), samples)  # fmt: skip
            te = q * np.round(te / q)
            _, amp, _ = order_spectrum(pos, te)
            means.append(amp[0])
            ses.append(mean_standard_error(amp))
        d_est.append(means[0] - means[1])
        se.append(np.hypot(*ses))
    k = tr / (2 * theta(tr) - 2 * theta(0.5 * tr))
    lm = 2 * theta(0.03 * tr)
    truth = {"torsional_rigidity": k, "lost_motion": lm, "hysteresis": 2 * theta(0.0),
             "backlash": lm - 2 * 0.03 * tr / k}  # fmt: skip
    return torques, np.array(d_est), np.array(se), truth


@pytest.mark.slow
def test_load_series_interval_coverage_over_40_seeds():
    """95 % intervals of the four quantities hold the exact value in >= 90 % of 40 seeded
    synthetic series (measured: printed)."""
    tr = 784e3
    hits, total = 0, 0
    for seed in range(40):
        t, d, se, truth = _series(np.random.default_rng(seed), tr)
        v = load_series_values(t, d, tr, standard_error=se)
        for name, want in truth.items():
            lo, hi = v.ci[name]
            hits += lo <= want <= hi
            total += 1
    print(f"load-series coverage {hits}/{total} = {hits / total:.3f}")
    assert hits / total >= 0.9
