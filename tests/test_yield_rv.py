"""The RV reducer through the yield engine: each sample one assembled reducer."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

import gearte
from gearte.geometry.rv import ManufacturingErrors
from gearte.models.rv_catalogue import catalogue_values
from gearte.runners.yield_models import RVReducerYield, rv_error_keys
from gearte.studies.rv_reducer import build_reducer
from gearte.tolerance.yield_mc import SpecLimit, Tolerance, ToleranceSet, run_yield
from gearte.units import rad_to_arcmin


@pytest.fixture(scope="module")
def rv():
    red = build_reducer(gearte.load_case("han2023_rv110e").reducer)
    return red, RVReducerYield(red, positions=36)


def test_rv_zero_tolerances_give_the_deterministic_catalogue_values_exactly(rv):
    red, model = rv
    keys = rv_error_keys(red)
    ts = ToleranceSet(
        tuple(Tolerance(k, "rayleigh", 0.0, phase=True, family="cam") for k in keys["cam"])
        + tuple(
            Tolerance(k, "normal", 0.0, family="pins.radius_errors")
            for k in keys["pins.radius_errors"]
        )
    )
    r = run_yield(model, ts, [SpecLimit("lost_motion [arcmin]", upper=1.0)], 2, seed=0)
    # a drawn error replaces the measured one: the deterministic reducer has zero cam errors
    e = red.errors
    red0 = red.with_errors(
        ManufacturingErrors(e.planet, e.disc_bore, np.zeros_like(e.cam), e.carrier_bore)
    )
    red0 = red0.replace(pins=replace(red0.pins, radius_errors=np.zeros(red0.pins.count)))
    cv = catalogue_values(red0)
    st = r.quantities["lost_motion [arcmin]"].stats
    assert st.min == st.max == pytest.approx(float(rad_to_arcmin(cv.lost_motion)), rel=1e-12)


def test_rv_drawn_errors_change_the_reducer_as_keyed(rv):
    red, model = rv
    e = {"cam.c1.d2": 10.0, "cam.c1.d2_phase_rad": np.pi / 2, "pins.radius_errors.p3": -2.0}
    r = model.reducer_for(e)
    np.testing.assert_allclose(r.errors.cam[0, 1], [0.0, 0.01], atol=1e-15)
    assert r.pins.radius_errors[2] == pytest.approx(-0.002)
    # errors not drawn keep the reducer's measured values
    np.testing.assert_array_equal(r.errors.planet, red.errors.planet)


@pytest.mark.slow
def test_rv_samples_give_every_catalogue_quantity(rv):
    red, model = rv
    keys = rv_error_keys(red)
    ts = ToleranceSet(
        tuple(Tolerance(k, "rayleigh", 5.0, phase=True, family="cam") for k in keys["cam"])
    )
    r = run_yield(model, ts, [SpecLimit("angular_te [arcmin]", upper=1.0)], 4, seed=3, chunk_size=2)
    names = {
        "lost_motion [arcmin]",
        "torsional_rigidity [Nm/arcmin]",
        "backlash [arcmin]",
        "hysteresis_loss [arcmin]",
        "angular_te [arcmin]",
        "loaded_te [arcmin]",
        "peak_pin_load [N]",
        "max_contact_pressure [MPa]",
    }
    assert names <= set(r.quantities)
    assert r.quantities["angular_te [arcmin]"].stats.sd > 0


def test_rv_reducer_case_yield_analysis_and_runnable_worst_case(tmp_path):
    """han2023_rv110e_yield with 4 samples and no Sobol: the result names issue 14 requires,
    and the worst reducer written as a case file gives the same lost motion when run alone."""
    import json
    import tomllib

    from gearte.cases import case_path
    from gearte.io.case_file import load_case_dict
    from gearte.studies import RunOptions

    data = tomllib.loads(case_path("han2023_rv110e_yield").read_text())
    data["analyses"]["yield"].update(samples=4, chunk_size=2, sobol_samples=0, keep_worst=1)
    res = gearte.run_case(load_case_dict(data, name="rv_yield"), RunOptions(progress=False))
    gearte.write_outputs(res, tmp_path / "out")
    v = json.loads((tmp_path / "out" / "results.json").read_text())["analyses"]["yield"]["values"]
    for k in ("yield", "yield_ci_low", "yield_ci_high", "cpk"):
        assert k in v
    worst = v["worst_samples"][0]
    alone = gearte.run_case(gearte.load_case(tmp_path / "out" / "worst_sample_1.toml"))
    lm = alone["catalogue"]["lost_motion [arcmin]"]
    assert lm == pytest.approx(worst["values"]["lost_motion [arcmin]"], rel=1e-6)


def test_rv_planet_eccentricity_tolerance_from_its_iso1328_grade(tmp_path):
    """grade = 6 on planet_base_circle: planet m 1.5, z 40 → d 60 mm; F_pT = (0.12 + 0.55·√60 +
    1.05 + 12)·√2 = 24.65 µm, F_rT = 0.9·F_pT = 22.19 → 22 µm; eccentricity tolerance F_rT/2 =
    11 µm (by hand from ISO 1328-1:2013 eq. 6 and the rounding rule)."""
    import tomllib

    from gearte.cases import case_path
    from gearte.io.case_file import load_case_dict
    from gearte.studies import RunOptions

    data = tomllib.loads(case_path("han2023_rv110e_yield").read_text())
    data["analyses"]["yield"].update(samples=2, chunk_size=2, sobol_samples=0, keep_worst=0)
    data["analyses"]["yield"]["spec"] = {}
    res = gearte.run_case(load_case_dict(data, name="rv_grade"), RunOptions(progress=False))
    assert res["yield"]["tolerances"]["planet_base_circle"]["tolerance"] == 11.0


def _hu_modified_with_eccentricities():
    """hu2020_rv80e_modified_reducer (modified profile: every pin has a clearance) with two
    nominal eccentricity errors of 10 µm, so that its TE has one clear maximum and minimum."""
    red = build_reducer(gearte.load_case("hu2020_rv80e_modified_reducer").reducer)
    keys = rv_error_keys(red)
    big = ("carrier_crank_bore.c1", "cam.c2.d1")
    tols = tuple(
        Tolerance(k, "normal", 0.3, nominal=10.0 if k in big else 0.0, family=fam)
        for fam in ("cam", "carrier_crank_bore", "disc_crank_bore", "planet_base_circle")
        for k in keys[fam]
    )
    return red, ToleranceSet(tols)


@pytest.mark.slow
def test_rv_small_tolerances_mc_sigma_of_te_within_3_percent_of_first_order():
    """Eccentricity tolerances ±0.3 µm (σ 0.1 µm) around a nominal reducer: the Monte-Carlo σ
    of angular (unloaded) TE and loaded TE from 2000 reducers is within 3 % of the first-order
    prediction Σ (∂y/∂x σ)² (central differences of ±1 tolerance; measured +0.8 % and +0.7 %).

    Lost motion is left out: it is the gap between the first pins to close in either direction,
    a minimum over the pins, not differentiable where the closing pin changes, and the
    first-order σ misses by more than 3 % at any scale. Measured in the modified stage (2000
    reducers, seeds 5 and 6): Monte-Carlo σ / first-order σ = 1.05 at ±0.3 µm (where lost
    motion's σ, 3e-5 arcmin, is also near the solver's resolution: a step of 0.3 tolerance moves
    the first-order σ by 40 %), 1.16 at ±1 µm, 0.87 at ±3 µm. (This test asserted 3 % for lost
    motion too when it was written; the slow suite found it failing at b1759aa, after the model
    had gained the stiffness chain and the true contact point. In han2023_rv110e, with pins at
    zero clearance, it missed by -7 %.)"""
    from gearte.tolerance.yield_contributions import linear_prediction

    red, ts = _hu_modified_with_eccentricities()
    model = RVReducerYield(red, positions=12)
    qs = ["angular_te [arcmin]", "loaded_te [arcmin]"]
    lin = linear_prediction(model, ts, qs, step=1.0)
    r = run_yield(model, ts, [], 2000, seed=5, chunk_size=500)
    for q in qs:
        assert r.quantities[q].stats.sd == pytest.approx(lin[q].sd, rel=0.03), q


def test_rv_zero_tolerances_give_the_per_case_te_and_catalogue_values():
    """All tolerances zero: every sample is the nominal reducer, bit for bit, and equals the
    per-case analyses (catalogue test, load sharing at the TE positions) of that reducer to the
    per-case solver's own accuracy (its secant fixed point stops at 1e-9)."""
    from gearte.models.rv_load_sharing import load_sharing

    red, ts = _hu_modified_with_eccentricities()
    ts0 = ToleranceSet(tuple(replace(t, tolerance=0.0) for t in ts.tolerances))
    model = RVReducerYield(red, positions=12)
    r = run_yield(model, ts0, [], 3, seed=2)
    nominal = model.reducer_for({k: float(v[0]) for k, v in ts0.nominal_values(1).items()})
    cv = catalogue_values(nominal, turning_points=(1.0, -1.0), steps_per_segment=2)
    te = load_sharing(nominal, 1e-3 * model.te_torque, model.theta).output_error
    expected = {
        "lost_motion [arcmin]": float(rad_to_arcmin(cv.lost_motion)),
        "angular_te [arcmin]": float(rad_to_arcmin(np.ptp(te))),
    }
    for q, v in expected.items():
        st = r.quantities[q].stats
        assert st.min == st.max, q
        assert st.min == pytest.approx(v, rel=1e-9), q


def test_han2023_yield_sobol_totals_sum_below_1_5_and_the_grid_error_is_reported():
    """han2023_rv110e_yield at its Sobol samples (100 base samples, scrambled Sobol' points,
    factors = tolerance families): the total indices of lost motion sum to ≤ 1.5 (plain
    Monte-Carlo points gave 3.35) and every first-order index is ≤ its total up to the
    intervals. The TE's grid of 36 positions, checked on the run's first 16 samples against
    360: it under-estimates the angular TE (a superset grid can only raise a peak-to-peak),
    reported as ``te_discretisation_error [arcsec]`` and warned about (> 2 %)."""
    import tomllib

    from gearte.cases import case_path
    from gearte.io.case_file import load_case_dict
    from gearte.studies import RunOptions

    data = tomllib.loads(case_path("han2023_rv110e_yield").read_text())
    assert data["analyses"]["yield"]["sobol_samples"] == 100
    data["analyses"]["yield"].update(samples=16, chunk_size=16, keep_worst=0, grid_check_samples=16)
    res = gearte.run_case(load_case_dict(data, name="rv_sobol"), RunOptions(progress=False))
    v = res["yield"]
    assert v["sobol_sampling"] == "qmc" and v["sobol_samples"] == 100
    assert sum(v["sobol_total"].values()) <= 1.5
    for k, s in v["sobol_first"].items():
        assert s <= v["sobol_total_ci"][k][1] + 1e-12
    grid = v["discretisation_error"]["angular_te [arcmin]"]
    assert (grid["positions"], grid["refined_positions"], grid["samples"]) == (36, 360, 16)
    assert v["te_discretisation_error [arcsec]"] == pytest.approx(grid["mean"] * 60.0)
    assert grid["mean"] > 0 and grid["relative_mean"] > 0.02
    assert any("angular_te" in w and "under-estimate" in w for w in res.warnings)


def test_rv_worst_sample_file_is_the_sampled_reducer_and_gives_the_sampled_values():
    """The worst sample's case file is written by the rv_reducer family's ``to_sections`` from
    the sample's reducer: read back it is that reducer (every field and array), and the yield
    model's per-sample path on it gives every sampled quantity (the batch solver's values, equal
    to round-off: seen ≤ 3e-13 relative, the backlash, a difference of two angles)."""
    import tomllib

    from gearte.cases import case_path
    from gearte.families import get_family
    from gearte.io.case_file import load_case_dict
    from gearte.studies import RunOptions
    from rv_sections import assert_same_reducer

    data = tomllib.loads(case_path("han2023_rv110e_yield").read_text())
    data["analyses"]["yield"].update(
        samples=4, chunk_size=4, sobol_samples=0, keep_worst=1, grid_check_samples=0
    )
    case = load_case_dict(data, name="rv_worst")
    y = gearte.run_case(case, RunOptions(progress=False))["yield"]
    worst = y.values["worst_samples"][0]
    exported = load_case_dict(tomllib.loads(y.files["worst_sample_1.toml"]), name="worst")
    red = get_family("rv_reducer").to_object(exported)
    model = RVReducerYield(build_reducer(case.reducer), positions=case.analyses.yield_.positions)
    assert_same_reducer(red, model.reducer_for(worst["errors"]))
    again = model.one(red)
    for q, v in worst["values"].items():
        assert again[q] == pytest.approx(v, rel=1e-9), q
