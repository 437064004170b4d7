"""Recording of the RV dynamics (issue 12): memory independent of the duration, full-rate
statistics and envelope, the spectrum's sampling rule, and the batch's shared stability limit.

The model is Li et al. 2023's prototype (paper 004) with the Table 3 errors; nothing here is
fitted to the paper.
"""

import numpy as np
import pytest

from gearte.models.rv_dynamics import RVDynamicModel
from gearte.runners.rv_dynamics_sim import (
    RECORD_POINTS,
    TRACE_POINTS,
    default_step,
    dte_spectrum,
    ode_system,
    simulate_dte,
)
from gearte.solvers.ode import _rk4_amp, integrate, rk4_stability_limit
from gearte.studies._rv_dynamics import DTEOptions
from li2023_data import li2023_parameters, table3_errors


@pytest.fixture(scope="module")
def model():
    m = RVDynamicModel(li2023_parameters(modified=True, cycloid_stiffness="mean"))
    return m.with_errors(table3_errors("all"))


@pytest.fixture(scope="module")
def start(model):
    q = model.static_equilibrium(0.0)
    return ode_system(model), np.concatenate([q, 0 * q]), default_step(model)


def test_recorded_rows_do_not_grow_with_duration(model):
    """Twice and eight times the span keep the same number of rows: the last record_points
    rows of states and the last trace_points samples of the DTE."""
    kw = dict(settle_s=0.01, record_points=48, trace_points=64, envelope_points=32)
    short = simulate_dte(model, 0.02, **kw)
    long = simulate_dte(model, 0.08, **kw)
    for r, end in ((short, 0.03), (long, 0.09)):
        assert r.t.size == r.dte.size == 64
        assert r.states.shape[0] == r.states_t.size == 48
        assert r.envelope.shape == (32, 2) and r.envelope_t.size == 32
        assert not r.covers_span and not r.states_cover_span
        assert end - r.record_dt < r.t[-1] <= end + 1e-12  # the last rows
        assert r.states_t[-1] == r.t[-1]
        np.testing.assert_array_equal(r.states_t, r.t[-48:])
    assert long.solver.records > 3 * short.solver.records
    np.testing.assert_allclose(np.diff(long.t), long.record_dt, rtol=1e-9)


def test_window_is_the_tail_of_the_full_record(start):
    """A ring buffer of 50 rows hands back exactly the last 50 rows of the full record, and the
    statistics (from every step) do not depend on what is recorded."""
    system, y0, dt = start
    kw = dict(method="rk4", dt=dt, t_settle=40 * dt, record_dt=3 * dt, record_states=[0, 5, 61])
    full = integrate(system, y0, (0.0, 400 * dt), **kw)
    tail = integrate(system, y0, (0.0, 400 * dt), record_window=50, **kw)
    assert full.records == tail.records == full.t.size > 50
    np.testing.assert_array_equal(tail.t, full.t[-50:])
    np.testing.assert_array_equal(tail.output, full.output[-50:])
    np.testing.assert_array_equal(tail.states, full.states[-50:])
    assert tail.stats == full.stats
    np.testing.assert_array_equal(tail.y_final, full.y_final)
    both = integrate(system, y0, (0.0, 400 * dt), record_window=30, output_window=80, **kw)
    np.testing.assert_array_equal(both.t, full.t[-80:])
    np.testing.assert_array_equal(both.output, full.output[-80:])
    np.testing.assert_array_equal(both.states_t, full.t[-30:])
    np.testing.assert_array_equal(both.states, full.states[-30:])


@pytest.mark.parametrize("method", ["rk4", "dopri5"])
def test_envelope_and_stats_are_the_full_rate_extremes(start, method):
    """Recorded at every step (RK4) or every recording instant (DOPRI5), the output's buckets'
    extremes are the envelope and its overall extremes the peak-to-peak."""
    system, y0, dt = start
    span, settle, n_env = (0.0, 301 * dt), 20 * dt, 7
    extra = {"rtol": 1e-8, "atol": 1e-12} if method == "dopri5" else {}
    r = integrate(
        system,
        y0,
        span,
        method=method,
        dt=dt,
        t_settle=settle,
        record_dt=dt,
        envelope_points=n_env,
        **extra,
    )
    o = r.output
    b = (np.arange(o.size) * n_env) // o.size
    for k in range(n_env):
        assert r.envelope[k, 0] == o[b == k].min()
        assert r.envelope[k, 1] == o[b == k].max()
        assert r.t[b == k][0] <= r.envelope_t[k] <= r.t[b == k][-1]
    assert r.stats["min"] == o.min() and r.stats["max"] == o.max()
    assert r.stats["count"] == o.size


def test_envelope_of_a_coarse_record_catches_the_extremes_between_samples(model):
    """The DTE recorded every ~50 steps misses peaks; the envelope (every step) does not."""
    r = simulate_dte(model, 0.05, settle_s=0.01, record_dt=50 * default_step(model))
    assert r.envelope[:, 1].max() - r.envelope[:, 0].min() == pytest.approx(
        r.peak_to_peak, rel=1e-12
    )
    assert r.dte.max() - r.dte.min() < r.peak_to_peak


def test_default_record_covers_the_default_dte_and_one_output_revolution(model):
    """The defaults change nothing: a whole default span and one output revolution of the
    paper's reducer at 1500 rpm, recorded every 1e-4 s, fit in the default window (so the
    trace, trajectories and spectrum are those of the whole span, as before issue 12)."""
    assert DTEOptions().record_points == RECORD_POINTS
    assert DTEOptions().trace_points == TRACE_POINTS
    d = DTEOptions()
    rev = 1.0 / model.params.frequencies()["output rotation"]
    rows = int((rev + d.record_dt_s) / d.record_dt_s) + 1
    assert RECORD_POINTS >= rows > int(d.duration_s / d.record_dt_s)
    r = simulate_dte(model, d.duration_s, settle_s=d.settle_s, record_dt=d.record_dt_s)
    every = simulate_dte(
        model,
        d.duration_s,
        settle_s=d.settle_s,
        record_dt=d.record_dt_s,
        record_points=None,
        trace_points=None,
    )
    assert r.covers_span and r.states_cover_span
    for name in ("t", "dte", "states", "states_t"):
        np.testing.assert_array_equal(getattr(r, name), getattr(every, name))
    assert r.peak_to_peak == every.peak_to_peak


def test_default_recording_rate_keeps_the_reported_spectrum_free_of_aliases(model):
    """The spectrum is computed from the DTE recorded every record_dt (every third step here):
    content above its Nyquist frequency would fold back onto the reported band. Recorded at
    every step instead, the same span shows < 1 % of the smallest reported peak above that
    Nyquist frequency, and the same labelled peaks (frequency within one bin, amplitude within
    5 %: the two windows differ by part of a step, which moves the bins)."""
    src = model.params.frequencies()
    dec = simulate_dte(model, 0.5, settle_s=0.1)
    full = simulate_dte(model, 0.5, settle_s=0.1, record_dt=default_step(model))
    _, _, p_dec = dte_spectrum(dec.t, dec.dte, src)
    f_full, s_full, p_full = dte_spectrum(full.t, full.dte, src)
    nyquist = 0.5 / dec.record_dt
    smallest = min(p["amplitude [arcsec]"] for p in p_dec)
    assert s_full[f_full > nyquist].max() < 0.01 * smallest
    for a, b in zip(p_dec, p_full, strict=True):
        assert a["source"] == b["source"]
        assert abs(a["frequency [Hz]"] - b["frequency [Hz]"]) <= 1.0 / dec.recorded_span
        assert a["amplitude [arcsec]"] == pytest.approx(b["amplitude [arcsec]"], rel=0.05)


def test_windowed_spectrum_of_a_long_span_keeps_its_peaks(model):
    """A span longer than the window: the spectrum is that of the last window (resolution
    1/window, here 4.8 Hz against 2.6 Hz) and finds the same four largest sources as the whole
    span recorded, their amplitudes within 10 % (Hann scalloping: the bins differ)."""
    src = model.params.frequencies()
    win = simulate_dte(model, 0.4, settle_s=0.1, trace_points=2000)
    whole = simulate_dte(model, 0.4, settle_s=0.1, trace_points=None)
    assert win.t.size == 2000 and whole.t.size > 3800
    assert win.recorded_span == pytest.approx(2000 * win.record_dt)
    _, _, p_win = dte_spectrum(win.t, win.dte, src)
    _, _, p_whole = dte_spectrum(whole.t, whole.dte, src)
    for a, b in zip(p_win[:4], p_whole[:4], strict=True):
        assert a["source"] == b["source"]
        assert a["amplitude [arcsec]"] == pytest.approx(b["amplitude [arcsec]"], rel=0.1)
    assert p_win[0]["source"] == "involute mesh"  # identical errors on all parts cancel
    assert win.peak_to_peak == whole.peak_to_peak


def test_record_points_must_be_sensible(model):
    from gearte.errors import ParameterError

    with pytest.raises(ParameterError, match="record_points"):
        simulate_dte(model, 0.01, settle_s=0.01, record_points=3)


def _limit_one_by_one(eigenvalues):
    """Plain twin of rk4_stability_limit: one eigenvalue at a time (the pre-issue-12 loop)."""
    limits = []
    for lm in np.asarray(eigenvalues, dtype=complex):
        if abs(lm) == 0:
            continue
        s = np.linspace(1e-6, 3.5, 3501) / abs(lm)
        bad = np.nonzero(_rk4_amp(s * lm) > 1.0 + 1e-12)[0]
        if bad.size == 0:
            limits.append(3.5 / abs(lm))
        elif bad[0] == 0:
            limits.append(2.0 * np.sqrt(2.0) / abs(lm))
        else:
            lo, hi = s[bad[0] - 1], s[bad[0]]
            for _ in range(60):
                mid = 0.5 * (lo + hi)
                lo, hi = (lo, mid) if _rk4_amp(mid * lm) > 1.0 + 1e-12 else (mid, hi)
            limits.append(lo)
    return min(limits)


def test_vectorised_stability_limit_matches_the_loop(model):
    ev = model.damped_eigenvalues(mesh="max")
    assert rk4_stability_limit(ev) == pytest.approx(_limit_one_by_one(ev), rel=1e-13)
    mixed = np.array([-3.0 + 40j, -3.0 - 40j, 25j, -25j, -7.0, 0.0, 2.0 + 1j])
    assert rk4_stability_limit(mixed) == pytest.approx(_limit_one_by_one(mixed), rel=1e-13)


def test_batch_system_carries_its_stability_limit(model):
    """The system a batch ships to its workers holds the RK4 limit (no worker recomputes it),
    from eigenvalues the model computes once and shares with its error variants."""
    system = ode_system(model)
    assert system.stability_limit == rk4_stability_limit(system.stability_eigenvalues)
    assert ode_system(model).stability_eigenvalues is system.stability_eigenvalues
    other = model.with_errors(table3_errors("first"))
    assert other.damped_eigenvalues(mesh="max") is system.stability_eigenvalues
    assert not system.stability_eigenvalues.flags.writeable


def test_dopri5_window_is_the_tail_of_its_full_record(start):
    system, y0, dt = start
    kw = dict(method="dopri5", t_settle=40 * dt, record_dt=3 * dt, rtol=1e-8, atol=1e-12)
    full = integrate(system, y0, (0.0, 400 * dt), **kw)
    tail = integrate(system, y0, (0.0, 400 * dt), record_window=20, **kw)
    assert full.records == tail.records == full.t.size > 20
    np.testing.assert_array_equal(tail.t, full.t[-20:])
    np.testing.assert_array_equal(tail.output, full.output[-20:])
    assert tail.stats == full.stats


def _dte_case(**dte) -> dict:
    import tomllib

    from gearte.cases import case_path

    data = tomllib.loads(case_path("li2023_rv").read_text())
    data["analyses"] = {"dte": {"duration_s": 0.05, "settle_s": 0.02, **dte}}
    return data


def test_study_record_points_bound_the_trace_and_zero_keeps_every_row():
    """`[analyses.dte] trace_points` / `record_points`: short windows give the spectrum and
    trajectories of the last rows (the values and notes say so); 0 keeps every row;
    peak-to-peak is the same."""
    from gearte.io.case_file import load_case_dict
    from gearte.studies import RunOptions, run_case

    opts = RunOptions(progress=False, workers=1)
    win = run_case(load_case_dict(_dte_case(trace_points=100, record_points=50)), opts)["dte"]
    every = run_case(load_case_dict(_dte_case(trace_points=0, record_points=0)), opts)["dte"]
    r_win, r_all = win.data["dte"], every.data["dte"]
    assert r_win.t.size == 100 and not r_win.covers_span
    assert r_win.states.shape[0] == 50 and not r_win.states_cover_span
    assert r_all.covers_span and r_all.t.size == r_all.solver.records > 400
    assert r_all.states_cover_span
    assert win.values["spectrum_window [s]"] == pytest.approx(100 * r_win.record_dt)
    assert every.values["spectrum_window [s]"] == pytest.approx(r_all.t.size * r_all.record_dt)
    assert win.values["spectrum_nyquist [Hz]"] == pytest.approx(0.5 / r_win.record_dt)
    assert any("trace_points" in n and "record_points" in n for n in win.notes)
    assert not any("over the last" in n for n in every.notes)
    p2p = "dte_peak_to_peak [arcsec]"
    assert win.values[p2p] == every.values[p2p]


def test_study_refuses_a_negative_record_points():
    from gearte.errors import CaseFileError
    from gearte.io.case_file import load_case_dict

    with pytest.raises(CaseFileError, match="record_points"):
        load_case_dict(_dte_case(record_points=-1))
    with pytest.raises(CaseFileError, match="trace_points"):
        load_case_dict(_dte_case(trace_points=-1))
